"""When a neighbour list (``neighbours``) must be rebuilt: the step's test of the list.

Rebuild criterion [derived]: write the displacement since the build as the affine part of the
LE shear plus a rest, d_i = A y_i^b ê_x + d̃_i, with A = ∫γ̇ dt the strain since the build (the
image offset moved by A L_y). Every image vector then obeys r(t) = S r^b + d̃_i − d̃_j with
S = I + A ê_x ê_y, so a pair that was beyond r_c at the build is still beyond h while
|d̃|₁st + |d̃|₂nd ≤ σ_min(S) r_c − h, σ_min = √(1 + A²/4) − |A|/2. With A = 0 this is the usual
"two largest displacements ≤ skin"; under steady shear only the non-affine motion counts.
When the bound fails, :func:`list_outdated` checks the few particles with |d̃| above half the
margin pair by pair against the present positions; every pair of the others still obeys it.
Conversely a particle i now within h of j was within (h + |d̃_i| + |d̃_j|)/σ_min of it at
the build, so i's partners are searched only in the build's cells around its reference
position.

Symbols: h kernel support radius, r_c = h + skin the list cutoff, d̃ a displacement since
the build less the affine shear [length]; A the strain since the build [1].
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from suspsim.sph.boundaries import minimum_image_3d


@njit(cache=True)
def _outlier_margin(positions, reference, strain, cutoff, skin, y_origin, outliers,
                    displacement):
    """(margin, found, two_largest, largest) of the criterion (module docstring): ``found``
    counts the particles with |d̃| > margin/2, the first ``outliers.shape[0]`` of them are
    written into ``outliers`` and their |d̃| into ``displacement``; ``two_largest`` is
    |d̃|₁st + |d̃|₂nd (inf for a NaN position), ``largest`` |d̃|₁st."""
    a = abs(strain)
    margin = (math.sqrt(1.0 + 0.25 * a * a) - 0.5 * a) * cutoff - (cutoff - skin)
    half2 = 0.25 * margin * margin if margin > 0.0 else 0.0
    first2 = 0.0
    second2 = 0.0
    found = 0
    for i in range(positions.shape[0]):
        dx = positions[i, 0] - reference[i, 0] - strain * (reference[i, 1] - y_origin)
        dy = positions[i, 1] - reference[i, 1]
        dz = positions[i, 2] - reference[i, 2]
        d2 = dx * dx + dy * dy + dz * dz
        if d2 != d2:
            return margin, found, math.inf, math.inf
        if d2 > half2:
            if found < outliers.shape[0]:
                outliers[found] = i
                displacement[found] = math.sqrt(d2)
            found += 1
        if d2 > second2:
            if d2 > first2:
                second2 = first2
                first2 = d2
            else:
                second2 = d2
    return margin, found, math.sqrt(first2) + math.sqrt(second2), math.sqrt(first2)


@njit(cache=True)
def needs_rebuild(positions, reference, strain, cutoff, skin, y_origin=0.0):
    """True when a pair beyond r_c at the last build may now be closer than h = r_c − skin.

    Criterion (module docstring): |d̃|₁st + |d̃|₂nd > σ_min(A) r_c − h with
    d̃ = r − r^b − A (y^b − y_0) ê_x and σ_min = √(1 + A²/4) − |A|/2; ``strain`` A = ∫γ̇ dt
    since the build (0 without shear); ``y_origin`` y_0 the height at rest in the imposed flow
    γ̇ (y − y_0) (a uniform translation leaves pair vectors unchanged, so any y_0 is exact;
    the right one keeps the mean flow from counting as displacement). Positions must not have
    been wrapped since the build (a wrapped particle shows a box-sized displacement and simply
    forces a rebuild).
    """
    margin, _, two_largest, _ = _outlier_margin(positions, reference, strain, cutoff, skin,
                                                y_origin, np.empty(0, dtype=np.int64),
                                                np.empty(0))
    return margin <= 0.0 or two_largest > margin


#: Most particles moved beyond half the margin that :func:`list_outdated` checks pair by pair
#: before it asks for a rebuild [choice]. Measured in the φ = 0.4 benchmark suspension (29,210
#: particles, two threads; a build 4.4 ms): after a build the bound holds for 8 steps, then
#: the outliers grow from 1 to 17, 146, 494, 1,117 and 5,000 over steps 9, 12, 15, 17, 19 and
#: 25, where the list first misses a pair; checking them costs about 0.5 µs each (the build's
#: cells around each), so the list lives 10 steps with at most 16 checked, 14 with 128, 16 with
#: 512 and 18 with 1,024, and build plus checks average 0.45, 0.33, 0.31 and 0.33 ms a step.
#: Not 512: with 256 and 512 the reduced two-sphere sliding test (tests/validation/
#: test_squeeze.py) read 0.88 and 0.73 of theory at gaps of 0.12–0.2 h, with 0–128 and 2,048
#: 0.96–1.07 (seven runs), though every kept list was complete (898 steps checked against
#: every pair); the gap holds about one particle, whose path the rebuild times change.
MAX_CHECKED_OUTLIERS = 128
#: Most distances the fallback of boxes too small for the cell search (fewer cells across than
#: an outlier's reach spans) may compute before a rebuild is cheaper [choice]: about the
#: candidate distances of a build of the benchmark box.
MAX_SCANNED = 1 << 22


@njit(cache=True)
def _is_listed(i, j, start, neighbours):
    """Whether the half list holds the pair (i, j)."""
    lo, hi = min(i, j), max(i, j)
    for s in range(start[lo], start[lo + 1]):
        if neighbours[s] == hi:
            return True
    return False


@njit(cache=True)
def _cell_span(centre, reach, length, n):
    """(first, count) of the cells of length/n covering [centre − reach, centre + reach]
    (first may lie outside [0, n): the caller takes images); count 0 if they would wrap onto
    themselves. One cell when n = 1 (a 2D scene's z)."""
    if n == 1:
        return 0, 1
    size = length / n
    first = int(math.floor((centre - reach) / size))
    count = int(math.floor((centre + reach) / size)) - first + 1
    return first, (count if count <= n else 0)


@njit(inline="always", cache=True)
def _missed(i, j, g, positions, box, offset, h2, start, neighbours, group):
    """Whether particle j, not i and not of i's group g (−1: none), is now within h of i (LE
    minimum image at ``offset``; ``h2`` = h²) without its pair in the half list."""
    if j == i or (g >= 0 and group[j] == g):
        return False
    dx, dy, dz, _ = minimum_image_3d(positions[i, 0] - positions[j, 0],
                                     positions[i, 1] - positions[j, 1],
                                     positions[i, 2] - positions[j, 2],
                                     box[0], box[1], box[2], offset)
    return (dx * dx + dy * dy + dz * dz < h2
            and not _is_listed(i, np.int64(j), start, neighbours))


@njit(cache=True)
def _missed_anywhere(i, positions, box, offset, h, start, neighbours, group):
    """:func:`_missed_near` over every particle: for boxes too small for its cells."""
    g = group[i] if group.shape[0] > 0 else -1
    missed = 0
    for j in range(positions.shape[0]):
        missed += _missed(i, j, g, positions, box, offset, h * h, start, neighbours, group)
    return missed


@njit(cache=True)
def _missed_near(i, positions, reference, reach, box, offset, build_offset, cells, cell_start,
                 h, start, neighbours, group):
    """Particles now within h of particle i (LE minimum image at ``offset``) whose pair the half
    list lacks, searched among the particles whose reference position lies within ``reach`` of
    i's (the build's cells, its LE offset ``build_offset``); pairs inside one group are never
    listed and not counted. Returns −1 when the cells cannot cover ``reach`` (a span of more
    cells than the box has)."""
    lx, ly, lz = box[0], box[1], box[2]
    nx, ny, nz = cells[0], cells[1], cells[2]
    xb = reference[i, 0]
    y_first, y_count = _cell_span(reference[i, 1], reach, ly, ny)
    z_first, z_count = _cell_span(reference[i, 2], reach, lz, nz)
    if y_count == 0 or z_count == 0:
        return -1
    g = group[i] if group.shape[0] > 0 else -1
    h2 = h * h
    missed = 0
    for ry in range(y_first, y_first + y_count):
        n = -1 if ry < 0 else (1 if ry >= ny else 0)
        wy = ry - n * ny
        # j's image in this y row sits at x_j + n Δ_b (+ m L_x): cover [x_b − reach, x_b + reach].
        x_first, x_count = _cell_span(xb - n * build_offset, reach, lx, nx)
        if x_count == 0:
            return -1
        for rx in range(x_first, x_first + x_count):
            wx = rx % nx
            for rz in range(z_first, z_first + z_count):
                c = (wx * ny + wy) * nz + rz % nz
                for j in range(cell_start[c], cell_start[c + 1]):
                    missed += _missed(i, j, g, positions, box, offset, h2, start, neighbours,
                                      group)
    return missed


@njit(cache=True, parallel=True)
def _any_missed(outliers, found, displacement, largest, sigma, positions, reference, box,
                offset, build_offset, cells, cell_start, h, start, neighbours, group):
    """Whether one of the ``found`` outliers misses a pair (:func:`_missed_near` with reach
    (h + |d̃_i| + |d̃|_max)/σ_min, module docstring; :func:`_missed_anywhere` where the cells
    cannot cover it, unless that scan would exceed :data:`MAX_SCANNED` distances)."""
    scan = found * positions.shape[0] <= MAX_SCANNED
    bad = 0
    for k in prange(found):
        i = outliers[k]
        reach = (h + displacement[k] + largest) / sigma + 1e-9 * box[0]
        missed = _missed_near(i, positions, reference, reach, box, offset, build_offset, cells,
                              cell_start, h, start, neighbours, group)
        if missed < 0:
            missed = (_missed_anywhere(i, positions, box, offset, h, start, neighbours, group)
                      if scan else 1)
        bad += missed > 0
    return bad > 0


@njit(cache=True)
def list_outdated(positions, reference, strain, cutoff, skin, y_origin, box, offset, cells,
                  cell_start, start, neighbours, group, max_checked):
    """True when the half list built from ``reference`` may lack a pair now closer than h.

    :func:`needs_rebuild`'s bound first: if |d̃|₁st + |d̃|₂nd stays within the margin no pair
    can be missing. Otherwise the particles with |d̃| above half the margin (at most
    ``max_checked``; more ask for a rebuild) are checked at the current LE offset ``offset``
    [h]: a rebuild is due only if one of them is now within h of a particle it is not listed
    with. Every pair of the others moved apart by at most the margin, so the bound covers them.
    An outlier i's partners now within h were, at the build, within
    (h + |d̃_i| + |d̃|_max)/σ_min of it (module docstring), so only the build's cells
    (``cells``, ``cell_start``; ``reference`` is in their order) around its reference position
    are searched: a few hundred distances each. In a sheared suspension fluid particles
    squeezed out of the gaps between bodies set the two largest displacements while the
    99.9th percentile is half as large: the bound alone holds for 8 steps, the list for 25
    (:data:`MAX_CHECKED_OUTLIERS`). ``group`` as in ``neighbours.build_neighbour_list``
    (empty: no groups). Every argument is required, so that numba compiles one signature
    (``neighbours.build_neighbour_list``); callers pass :data:`MAX_CHECKED_OUTLIERS`.
    """
    outliers = np.empty(max_checked, dtype=np.int64)
    displacement = np.empty(max_checked)
    margin, found, two_largest, largest = _outlier_margin(
        positions, reference, strain, cutoff, skin, y_origin, outliers, displacement)
    if margin <= 0.0 or two_largest == math.inf:
        return True
    if two_largest <= margin:
        return False
    if found > max_checked:
        return True
    a = abs(strain)
    sigma = math.sqrt(1.0 + 0.25 * a * a) - 0.5 * a
    build_offset = (offset - strain * box[1]) % box[0]
    return _any_missed(outliers, found, displacement, largest, sigma, positions, reference, box,
                       offset, build_offset, cells, cell_start, cutoff - skin, start, neighbours,
                       group)
