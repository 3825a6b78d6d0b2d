"""Exact overlap checks of a packing: sphere gaps, and grain gaps on densely sampled surfaces.

Spheres: the gap of a pair is |r_ij| − a_i − a_j under the minimum image, exact.

Grains (star-shaped, non-convex): a point p lies outside grain B enlarged by g exactly when
|p − R_B| ≥ r_B(û) + g, û the direction of p in B's body frame, with r_B the exact harmonic sum
(:func:`~suspsim.bodies.harmonics.evaluate_one`, no table). The *radial gap* of a pair is the
smallest |p − R_B| − r_B(û) over the sample points p of A's surface, and symmetrically. It is
checked on M quasi-uniform directions per grain (a Fibonacci lattice: z_k = 1 − (2k+1)/M,
φ_k = k·π(3 − √5)); the radial gap is an upper bound on the Euclidean gap, close to it where
the surface is nearly normal to the ray from the centre. A finite sample cannot exclude an
overlap thinner than its spacing; the spacing is √(4π/M) of the radius (0.06 at M = 4000), so
a missed lens is ≲ (0.06)²/8 ≈ 5e-4 of the radius deep, below the default working gap.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .harmonics import degree_of, evaluate, evaluate_one, recurrence_tables
from .pairs import build_pairs, minimum_image

__all__ = ["fibonacci_directions", "grain_gaps", "sphere_gaps"]


def fibonacci_directions(count: int) -> np.ndarray:
    """``count`` quasi-uniform unit vectors (count, 3) on the sphere (Fibonacci lattice)."""
    k = np.arange(count)
    z = 1.0 - (2.0 * k + 1.0) / count
    phi = k * math.pi * (3.0 - math.sqrt(5.0))
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=1)


def _pairs_within(positions, reach, box) -> np.ndarray:
    capacity = 16 * len(positions) + 16
    while True:
        pairs = np.empty((capacity, 2), np.int64)
        count = build_pairs(positions, reach, box, 0.0, pairs)
        if count <= capacity:
            return pairs[:count]
        capacity = count


def sphere_gaps(positions: np.ndarray, radii: np.ndarray, box: np.ndarray,
                within: float) -> np.ndarray:
    """Gaps |r_ij| − a_i − a_j [length] of every pair with a gap below ``within``."""
    positions = np.ascontiguousarray(positions, dtype=np.float64)
    box = np.asarray(box, dtype=np.float64)
    pairs = _pairs_within(positions, radii + 0.5 * within, box)
    d = positions[pairs[:, 0]] - positions[pairs[:, 1]]
    d -= box * np.rint(d / box)
    return np.linalg.norm(d, axis=1) - radii[pairs[:, 0]] - radii[pairs[:, 1]]


def grain_gaps(positions: np.ndarray, rotations: np.ndarray, coefficients: np.ndarray,
               support: np.ndarray, box: np.ndarray, points: int = 4000) -> np.ndarray:
    """Smallest radial gap [length] of every pair of grains whose support spheres intersect.

    ``rotations`` (G, 3, 3) map body to box frame, ``coefficients`` (G, K) the grains' exact
    radius expansions at their final size, ``support`` (G,) bounds of their radii.
    ``points`` sample directions per grain (module docstring). A pair none of whose sample
    points enters the other's support sphere gets +inf.
    """
    positions = np.ascontiguousarray(positions, dtype=np.float64)
    box = np.asarray(box, dtype=np.float64)
    coefficients = np.ascontiguousarray(coefficients, dtype=np.float64)
    pairs = _pairs_within(positions, np.asarray(support, dtype=np.float64), box)
    directions = fibonacci_directions(points)
    offsets = np.stack([(evaluate(a, directions)[:, None] * directions) @ r.T
                        for a, r in zip(coefficients, rotations)])
    to_body = np.ascontiguousarray(np.transpose(rotations, (0, 2, 1)))
    gaps = np.empty(len(pairs))
    alpha, beta = recurrence_tables(degree_of(coefficients))
    _grain_pair_gaps(positions, offsets, to_body, coefficients, alpha, beta, support, box, pairs,
                     gaps)
    return gaps


@njit(cache=True)
def _radial_gap(offsets_a, bx, by, bz, a_b, alpha, beta, to_body_b, support_b):
    smallest = np.inf
    for k in range(offsets_a.shape[0]):
        dx, dy, dz = bx + offsets_a[k, 0], by + offsets_a[k, 1], bz + offsets_a[k, 2]
        rho2 = dx * dx + dy * dy + dz * dz
        if rho2 >= support_b * support_b:
            continue
        rho = math.sqrt(rho2)
        if rho == 0.0:
            return -support_b
        ux = (to_body_b[0, 0] * dx + to_body_b[0, 1] * dy + to_body_b[0, 2] * dz) / rho
        uy = (to_body_b[1, 0] * dx + to_body_b[1, 1] * dy + to_body_b[1, 2] * dz) / rho
        uz = (to_body_b[2, 0] * dx + to_body_b[2, 1] * dy + to_body_b[2, 2] * dz) / rho
        radius = evaluate_one(a_b, alpha.shape[0] - 1, alpha, beta, ux, uy, uz)
        smallest = min(smallest, rho - radius)
    return smallest


@njit(cache=True)
def _grain_pair_gaps(positions, offsets, to_body, coefficients, alpha, beta, support, box, pairs,
                     gaps):
    for k in range(pairs.shape[0]):
        i, j = pairs[k, 0], pairs[k, 1]
        bx, by, bz = minimum_image(positions[i, 0] - positions[j, 0],
                                   positions[i, 1] - positions[j, 1],
                                   positions[i, 2] - positions[j, 2], box[0], box[1], box[2])
        gap_ij = _radial_gap(offsets[i], bx, by, bz, coefficients[j], alpha, beta, to_body[j],
                             support[j])
        gap_ji = _radial_gap(offsets[j], -bx, -by, -bz, coefficients[i], alpha, beta, to_body[i],
                             support[i])
        gaps[k] = min(gap_ij, gap_ji)
