"""Full neighbour list of a slab: x (and z in 3D) periodic, y bounded (walls), with a skin.

A small dedicated list (the seed-000 list in :mod:`suspsim.sph.neighbours` is a half list for
fully periodic / Lees–Edwards boxes). Here every particle i lists all j ≠ i with
|x_ij| < r_c = 3 h_sl + skin (CSR: ``neighbours[start[i]:start[i + 1]]``), so a pass over i
writes only to i and runs race-free under ``prange``. Pair vectors take the periodic minimum
image in x only (:func:`pair_vector`; in 3D x and z, :func:`pair_vector_3d`); positions need
not be wrapped between builds. Rebuild when the largest displacement since the build (minimum
image) exceeds skin/2 (:func:`needs_rebuild`, :func:`needs_rebuild_3d`). The 2D and 3D builds
(:func:`build_list`, :func:`build_list_3d`) share the counting sort; each has its own scan, so
the 2D pair loop carries no third coordinate.

Symbols: L_x, L_z periodic lengths, y_lo/y_hi bounds of all particles (walls included), r_c
list cutoff, n_cx/n_cy/n_cz cells per direction (each ≥ r_c wide; n_cx, n_cz ≥ 3), all lengths
in [length].
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from suspsim.sph import JIT_OPTIONS

#: Error codes returned by the compiled build.
OK, PAIR_OVERFLOW = 0, 1


@njit(inline="always", **JIT_OPTIONS)
def pair_vector(xi, yi, xj, yj, lx):
    """x_ij = x_i − x_j with the periodic minimum image in x (period L_x); y is bounded."""
    dx = xi - xj
    dx -= lx * np.rint(dx / lx)
    return dx, yi - yj


@njit(inline="always", **JIT_OPTIONS)
def pair_vector_3d(xi, yi, zi, xj, yj, zj, lx, lz):
    """x_ij = x_i − x_j with the periodic minimum image in x and z (periods L_x, L_z)."""
    dx = xi - xj
    dx -= lx * np.rint(dx / lx)
    dz = zi - zj
    dz -= lz * np.rint(dz / lz)
    return dx, yi - yj, dz


@njit(cache=True)
def _cell_of(x, y, lx, y_lo, cell_x, cell_y, ncx, ncy):
    cx = int(math.floor((x - lx * math.floor(x / lx)) / cell_x))
    cy = int(math.floor((y - y_lo) / cell_y))
    cx = min(max(cx, 0), ncx - 1)
    cy = min(max(cy, 0), ncy - 1)
    return cx * ncy + cy


@njit(cache=True)
def _sort(cell_of, n_cells, order, cell_start):
    """Counting sort of particles by their cell ``cell_of`` (fills ``order``, ``cell_start``)."""
    n = cell_of.shape[0]
    cell_start[:] = 0
    for i in range(n):
        cell_start[cell_of[i] + 1] += 1
    for c in range(n_cells):
        cell_start[c + 1] += cell_start[c]
    fill = cell_start[:-1].copy()
    for i in range(n):
        c = cell_of[i]
        order[fill[c]] = i
        fill[c] += 1


@njit(parallel=True, cache=True)
def _scan(positions, lx, cutoff, ncx, ncy, cell_of, order, cell_start, start, neighbours,
          counting):
    """Count (``counting``) or write the neighbours of every particle."""
    n = positions.shape[0]
    rc2 = cutoff * cutoff
    for i in prange(n):
        c = cell_of[i]
        cx = c // ncy
        cy = c % ncy
        xi = positions[i, 0]
        yi = positions[i, 1]
        k = 0 if counting else start[i]
        for ox in range(-1, 2):
            wx = (cx + ox) % ncx
            for oy in range(-1, 2):
                wy = cy + oy
                if wy < 0 or wy >= ncy:
                    continue
                other = wx * ncy + wy
                for s in range(cell_start[other], cell_start[other + 1]):
                    j = order[s]
                    if j == i:
                        continue
                    dx, dy = pair_vector(xi, yi, positions[j, 0], positions[j, 1], lx)
                    if dx * dx + dy * dy < rc2:
                        if not counting:
                            neighbours[k] = j
                        k += 1
        if counting:
            start[i + 1] = k


@njit(cache=True)
def build_list(positions, lx, y_lo, y_hi, cutoff, start, neighbours, cell_of, order):
    """Build the CSR list into ``start`` (N + 1,) and ``neighbours`` (capacity,); returns
    (code, pairs): ``PAIR_OVERFLOW`` when the capacity is too small (pairs = slots needed)."""
    ncx = max(int(math.floor(lx / cutoff)), 3)
    ncy = max(int(math.floor((y_hi - y_lo) / cutoff)), 1)
    cell_x = lx / ncx
    cell_y = (y_hi - y_lo) / ncy * (1.0 + 1e-12)
    cell_start = np.zeros(ncx * ncy + 1, dtype=np.int64)
    for i in range(positions.shape[0]):
        cell_of[i] = _cell_of(positions[i, 0], positions[i, 1], lx, y_lo, cell_x, cell_y, ncx,
                              ncy)
    _sort(cell_of, ncx * ncy, order, cell_start)
    start[0] = 0
    _scan(positions, lx, cutoff, ncx, ncy, cell_of, order, cell_start, start, neighbours, True)
    for i in range(positions.shape[0]):
        start[i + 1] += start[i]
    total = start[positions.shape[0]]
    if total > neighbours.shape[0]:
        return PAIR_OVERFLOW, total
    _scan(positions, lx, cutoff, ncx, ncy, cell_of, order, cell_start, start, neighbours, False)
    return OK, total


@njit(cache=True)
def needs_rebuild(positions, reference, lx, skin):
    """True when some particle moved more than skin/2 since the build (minimum image in x)."""
    limit = 0.25 * skin * skin
    for i in range(positions.shape[0]):
        dx, dy = pair_vector(positions[i, 0], positions[i, 1], reference[i, 0], reference[i, 1],
                             lx)
        if dx * dx + dy * dy > limit:
            return True
    return False


@njit(cache=True)
def _cell_of_3d(x, y, z, lx, lz, y_lo, cell_x, cell_y, cell_z, ncx, ncy, ncz):
    cx = int(math.floor((x - lx * math.floor(x / lx)) / cell_x))
    cy = int(math.floor((y - y_lo) / cell_y))
    cz = int(math.floor((z - lz * math.floor(z / lz)) / cell_z))
    cx = min(max(cx, 0), ncx - 1)
    cy = min(max(cy, 0), ncy - 1)
    cz = min(max(cz, 0), ncz - 1)
    return (cx * ncy + cy) * ncz + cz


@njit(parallel=True, cache=True)
def _scan_3d(positions, lx, lz, cutoff, ncx, ncy, ncz, cell_of, order, cell_start, start,
             neighbours, counting):
    """Count (``counting``) or write the neighbours of every particle (3D)."""
    n = positions.shape[0]
    rc2 = cutoff * cutoff
    for i in prange(n):
        c = cell_of[i]
        cz = c % ncz
        cy = (c // ncz) % ncy
        cx = c // (ncz * ncy)
        xi = positions[i, 0]
        yi = positions[i, 1]
        zi = positions[i, 2]
        k = 0 if counting else start[i]
        for ox in range(-1, 2):
            wx = (cx + ox) % ncx
            for oy in range(-1, 2):
                wy = cy + oy
                if wy < 0 or wy >= ncy:
                    continue
                for oz in range(-1, 2):
                    wz = (cz + oz) % ncz
                    other = (wx * ncy + wy) * ncz + wz
                    for s in range(cell_start[other], cell_start[other + 1]):
                        j = order[s]
                        if j == i:
                            continue
                        dx, dy, dz = pair_vector_3d(xi, yi, zi, positions[j, 0],
                                                    positions[j, 1], positions[j, 2], lx, lz)
                        if dx * dx + dy * dy + dz * dz < rc2:
                            if not counting:
                                neighbours[k] = j
                            k += 1
        if counting:
            start[i + 1] = k


@njit(cache=True)
def build_list_3d(positions, lx, lz, y_lo, y_hi, cutoff, start, neighbours, cell_of, order):
    """:func:`build_list` for a 3D slab periodic in x (L_x) and z (L_z); same returns."""
    ncx = max(int(math.floor(lx / cutoff)), 3)
    ncy = max(int(math.floor((y_hi - y_lo) / cutoff)), 1)
    ncz = max(int(math.floor(lz / cutoff)), 3)
    cell_x = lx / ncx
    cell_y = (y_hi - y_lo) / ncy * (1.0 + 1e-12)
    cell_z = lz / ncz
    n_cells = ncx * ncy * ncz
    cell_start = np.zeros(n_cells + 1, dtype=np.int64)
    for i in range(positions.shape[0]):
        cell_of[i] = _cell_of_3d(positions[i, 0], positions[i, 1], positions[i, 2], lx, lz,
                                 y_lo, cell_x, cell_y, cell_z, ncx, ncy, ncz)
    _sort(cell_of, n_cells, order, cell_start)
    start[0] = 0
    _scan_3d(positions, lx, lz, cutoff, ncx, ncy, ncz, cell_of, order, cell_start, start,
             neighbours, True)
    for i in range(positions.shape[0]):
        start[i + 1] += start[i]
    total = start[positions.shape[0]]
    if total > neighbours.shape[0]:
        return PAIR_OVERFLOW, total
    _scan_3d(positions, lx, lz, cutoff, ncx, ncy, ncz, cell_of, order, cell_start, start,
             neighbours, False)
    return OK, total


@njit(cache=True)
def needs_rebuild_3d(positions, reference, lx, lz, skin):
    """:func:`needs_rebuild` in 3D (minimum image in x and z)."""
    limit = 0.25 * skin * skin
    for i in range(positions.shape[0]):
        dx, dy, dz = pair_vector_3d(positions[i, 0], positions[i, 1], positions[i, 2],
                                    reference[i, 0], reference[i, 1], reference[i, 2], lx, lz)
        if dx * dx + dy * dy + dz * dz > limit:
            return True
    return False
