"""When a neighbour list (``neighbours``) must be rebuilt: the step's test of the list.

Rebuild criterion [derived]: write the displacement since the build as the affine part of the
LE shear plus a rest, d_i = A y_i^b ê_x + d̃_i, with A = ∫γ̇ dt the strain since the build (the
image offset moved by A L_y). Every image vector then obeys r(t) = S r^b + d̃_i − d̃_j with
S = I + A ê_x ê_y, so a pair that was beyond r_c at the build is still beyond h while
|d̃|₁st + |d̃|₂nd ≤ σ_min(S) r_c − h, σ_min = √(1 + A²/4) − |A|/2. With A = 0 this is the usual
"two largest displacements ≤ skin"; under steady shear only the non-affine motion counts.
When the bound fails, :func:`list_outdated` checks the few particles with |d̃| above half the
margin pair by pair against the present positions; every pair of the others still obeys it.

Symbols: h kernel support radius, r_c = h + skin the list cutoff, d̃ a displacement since
the build less the affine shear [length]; A the strain since the build [1].
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from suspsim.sph.boundaries import minimum_image_3d


@njit(cache=True)
def _outlier_margin(positions, reference, strain, cutoff, skin, y_origin, outliers):
    """(margin, found, two_largest) of the criterion (module docstring): ``found`` counts the
    particles with |d̃| > margin/2, the first ``outliers.shape[0]`` of them are written into
    ``outliers``; ``two_largest`` is |d̃|₁st + |d̃|₂nd (inf for a NaN position)."""
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
            return margin, found, math.inf
        if d2 > half2:
            if found < outliers.shape[0]:
                outliers[found] = i
            found += 1
        if d2 > second2:
            if d2 > first2:
                second2 = first2
                first2 = d2
            else:
                second2 = d2
    return margin, found, math.sqrt(first2) + math.sqrt(second2)


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
    margin, _, two_largest = _outlier_margin(positions, reference, strain, cutoff, skin,
                                             y_origin, np.empty(0, dtype=np.int64))
    return margin <= 0.0 or two_largest > margin


#: Most particles moved beyond half the margin that :func:`list_outdated` checks pair by pair
#: before it asks for a rebuild [choice]. Each costs one distance per particle; 16 of them
#: cost about a sixth of a build's candidate distances. In the φ = 0.4 benchmark suspension
#: (29,210 particles, 150 steps, two threads) the list was rebuilt 20 times by the bound alone,
#: 15, 14, 13 and 11 times with at most 8, 16, 32 and 128 checked (3 to 6 checked a step).
MAX_CHECKED_OUTLIERS = 16


@njit(cache=True)
def _is_listed(i, j, start, neighbours):
    """Whether the half list holds the pair (i, j)."""
    lo, hi = min(i, j), max(i, j)
    for s in range(start[lo], start[lo + 1]):
        if neighbours[s] == hi:
            return True
    return False


@njit(cache=True, parallel=True)
def _missed_pairs(i, positions, box, offset, h, start, neighbours, group):
    """Particles closer than h to particle i now (LE minimum image at ``offset``) whose pair
    with i the half list lacks; pairs inside one group are never listed and not counted."""
    g = group[i] if group.shape[0] > 0 else -1
    h2 = h * h
    missed = 0
    for j in prange(positions.shape[0]):
        if j == i or (g >= 0 and group[j] == g):
            continue
        dx, dy, dz, _ = minimum_image_3d(positions[i, 0] - positions[j, 0],
                                         positions[i, 1] - positions[j, 1],
                                         positions[i, 2] - positions[j, 2],
                                         box[0], box[1], box[2], offset)
        if (dx * dx + dy * dy + dz * dz < h2
                and not _is_listed(i, np.int64(j), start, neighbours)):
            missed += 1
    return missed


@njit(cache=True)
def list_outdated(positions, reference, strain, cutoff, skin, y_origin, box, offset, start,
                  neighbours, group, max_checked):
    """True when the half list built from ``reference`` may lack a pair now closer than h.

    :func:`needs_rebuild`'s bound first: if |d̃|₁st + |d̃|₂nd stays within the margin no pair
    can be missing. Otherwise the few particles with |d̃| above half the margin (at most
    ``max_checked``; more ask for a rebuild) are checked against every particle at the
    current LE offset ``offset`` [h]: a rebuild is due only if one of them is now within h of
    a particle it is not listed with. Every pair of the others moved apart by at most the
    margin, so the bound covers them. In a sheared suspension a handful of fluid particles
    (squeezed out of the gaps between bodies) set the two largest displacements while the
    99.9th percentile is half as large: the bound alone rebuilt every 7.5 steps where an
    exact test would have waited 21. ``group`` as in ``neighbours.build_neighbour_list`` (empty:
    no groups). Every argument is required, so that numba compiles one signature
    (``neighbours.build_neighbour_list``); callers pass :data:`MAX_CHECKED_OUTLIERS`.
    """
    outliers = np.empty(max_checked, dtype=np.int64)
    margin, found, two_largest = _outlier_margin(positions, reference, strain, cutoff, skin,
                                                 y_origin, outliers)
    if margin <= 0.0 or two_largest == math.inf:
        return True
    if two_largest <= margin:
        return False
    if found > max_checked:
        return True
    h = cutoff - skin
    for k in range(found):
        if _missed_pairs(outliers[k], positions, box, offset, h, start, neighbours, group) > 0:
            return True
    return False
