"""Candidate body pairs in a periodic box: cell list, minimum image, Verlet skin (compiled).

Every body i has a reach ρ_i [length] (sphere: radius + half the gap; grain: support radius +
half the gap); a pair is listed when its minimum-image distance is below ρ_i + ρ_j + skin.
Bodies may cross the faces of the box [0, L_x) × [0, L_y) × [0, L_z) (positions are not
wrapped; the minimum image handles them), which is all a Lees–Edwards box at zero strain
offset needs. The minimum image is the only image considered, so callers require
2 (ρ_max + ρ_max + skin) ≤ min L (checked by the packers).

Cells are at least 2ρ_max + skin wide; a direction with fewer than 3 cells uses a single cell
(so no pair is visited twice), which makes tiny boxes O(N²) and large ones O(N). The list is a
fixed-capacity (capacity, 2) int64 array; :func:`build_pairs` returns the number of pairs found,
and a number above the capacity means the caller must allocate more and rebuild (only the first
``capacity`` pairs were stored).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["build_pairs", "minimum_image"]


@njit(cache=True, inline="always")
def minimum_image(dx, dy, dz, lx, ly, lz):
    """The periodic image of (dx, dy, dz) nearest the origin."""
    return (dx - lx * np.rint(dx / lx), dy - ly * np.rint(dy / ly), dz - lz * np.rint(dz / lz))


@njit(cache=True)
def bin_by_cell(positions, box, cells):
    """(cell_of, start, members): each point's cell of a ``cells`` (3,) grid over the periodic
    ``box`` (wrapped), and the points of cell c as members[start[c]:start[c + 1]]."""
    n = positions.shape[0]
    n_cells = cells[0] * cells[1] * cells[2]
    cell_of = np.empty(n, np.int64)
    for i in range(n):
        index = 0
        for d in range(3):
            f = positions[i, d] / box[d]
            f -= math.floor(f)
            index = index * cells[d] + min(int(f * cells[d]), cells[d] - 1)
        cell_of[i] = index
    start = np.zeros(n_cells + 1, np.int64)
    for i in range(n):
        start[cell_of[i] + 1] += 1
    for c in range(n_cells):
        start[c + 1] += start[c]
    fill = start[:-1].copy()
    members = np.empty(n, np.int64)
    for i in range(n):
        members[fill[cell_of[i]]] = i
        fill[cell_of[i]] += 1
    return cell_of, start, members


@njit(cache=True)
def build_pairs(positions, reach, box, skin, pairs):
    """Fill ``pairs`` with (i, j), i < j, of minimum-image distance < reach_i + reach_j + skin.

    Returns the number of pairs found (may exceed ``len(pairs)``: overflow, see module doc).
    """
    n = positions.shape[0]
    width = 2.0 * reach.max() + skin
    cells = np.empty(3, np.int64)
    for d in range(3):
        c = int(math.floor(box[d] / width))
        cells[d] = c if c >= 3 else 1
    spread = np.minimum(cells - 1, 1)
    cell_of, start, members = bin_by_cell(positions, box, cells)
    capacity = pairs.shape[0]
    count = 0
    lx, ly, lz = box[0], box[1], box[2]
    for i in range(n):
        cz = cell_of[i] % cells[2]
        cy = (cell_of[i] // cells[2]) % cells[1]
        cx = cell_of[i] // (cells[2] * cells[1])
        for ox in range(-spread[0], spread[0] + 1):
            for oy in range(-spread[1], spread[1] + 1):
                for oz in range(-spread[2], spread[2] + 1):
                    c = (((cx + ox) % cells[0]) * cells[1] + (cy + oy) % cells[1]) * cells[2] \
                        + (cz + oz) % cells[2]
                    for k in range(start[c], start[c + 1]):
                        j = members[k]
                        if j <= i:
                            continue
                        dx, dy, dz = minimum_image(positions[i, 0] - positions[j, 0],
                                                   positions[i, 1] - positions[j, 1],
                                                   positions[i, 2] - positions[j, 2], lx, ly, lz)
                        cut = reach[i] + reach[j] + skin
                        if dx * dx + dy * dy + dz * dz < cut * cut:
                            if count < capacity:
                                pairs[count, 0] = i
                                pairs[count, 1] = j
                            count += 1
    return count
