"""Closest points of two sand grains and the osculating spheres that stand in for them there.

Lubrication and repulsion act at the closest points of two surfaces (SPEC §3.3–3.4; seed 000:
"local surface properties (surface normals, principal curvature) ... to better estimate
lubrication forces"). A grain's volume-equivalent sphere is a poor stand-in: two elongated
grains side by side have centre distance < a1 + a2 while their surfaces are apart.

**Surface sample** (:func:`grain_surfaces`, once per run). Per grain, M Fibonacci directions
(:func:`~suspsim.bodies.overlap.fibonacci_directions`) give surface points p, outward normals n,
principal curvatures κ₁ ≥ κ₂ and first principal directions e₁
(:func:`~suspsim.bodies.shapes.surface_geometry`), stored in the grain's **principal frame
relative to its centre of mass** — the frame of :class:`~suspsim.bodies.system.RigidBodies`:
p' = P (p − X), with P the packing-to-principal rotation and X the lattice centre of mass
(:mod:`~suspsim.bodies.construction`). The radius r(û) of the packing frame is looked up in a
cube-map table (:mod:`~suspsim.bodies.radius_table`, ~1e-4 of the radius).

**Closest points** (:func:`grain_pair_contact`, every step and close pair). With Q the rotation
(principal → box) of each grain, every sample point x = R_A + Q_A p'_k of A that lies within
B's support sphere enlarged by the cutoff gets its *radial gap* to B, |x − C_B| − r_B(û)
(C_B B's centroid, û the direction of x − C_B in B's packing frame,
:mod:`~suspsim.bodies.overlap`); the sample point with the smallest is A's contact point p_A, and
symmetrically p_B on B. The radial gap exceeds the Euclidean gap by 1/cos α (α the angle of the
normal to the radius); it only picks the points.

**Osculating spheres** [choice]. At each contact point the grain is replaced by the sphere of
its local mean-curvature radius R = 2/(κ₁ + κ₂), clamped to [``radius_range``] (by default
[¼ a, 2 a_support], a the volume-equivalent radius: the lower bound keeps the sharpest bumps
of degree-20 grains from dominating, the upper one stands for flat (κ₁ + κ₂ → 0) and concave
(κ₁ + κ₂ < 0) points, where a sphere of 2 a_support is a near-plane), centred at c = p − R n;
it touches the grain at p with the same normal and, to second order, the same mean curvature.
The **gap** s = |c_A − c_B| − R_A − R_B and the **normal** d = (c_B − c_A)/|c_B − c_A| are
those of the two virtual spheres: when p_A, p_B are the true closest points, c_A, p_A, p_B, c_B
are collinear and s = |p_B − p_A| exactly; a sample offset δ along the surface errs by
≈ |κ₁ − κ₂| δ²/4 (δ ≤ half the sample spacing √(4π/M) r). One contact per pair: the grains
of :mod:`~suspsim.bodies.grains` are convex up to their small roughness.

Symbols: R centre of mass [h]; Q, P rotations; p, c points [h]; n, d, e₁ unit vectors;
κ principal curvature [h⁻¹]; R_osc osculating radius [h]; s gap [h].
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from suspsim.sph import JIT_OPTIONS

from .overlap import fibonacci_directions
from .radius_table import DEFAULT_TABLE_CELLS, build_table, table_error, table_radius
from .shapes import surface_geometry

__all__ = ["CONTACT_WIDTH", "DEFAULT_SURFACE_POINTS", "GrainSurfaces", "grain_pair_contact",
           "grain_surfaces", "osculating_radius"]

#: Sample directions per grain [choice]: spacing √(4π/M) r = 0.2 h at r = 2.5 h, so a contact
#: point is off by ≤ 0.1 h along the surface and the gap by ≲ |κ₁ − κ₂| (0.1 h)²/4 ≈ 1e-3 h.
DEFAULT_SURFACE_POINTS = 2000
#: Columns of a contact record (:func:`grain_pair_contact`): c_A (3) and c_B (3) box-frame
#: centres of the osculating spheres relative to their grain's centre of mass [h], R_A, R_B [h],
#: gap s [h], sample indices k_A, k_B (as floats).
CONTACT_WIDTH = 11
C_A, C_B, RADIUS_A, RADIUS_B, GAP, INDEX_A, INDEX_B = 0, 3, 6, 7, 8, 9, 10


@dataclass(frozen=True)
class GrainSurfaces:
    """Surface samples of G grains, principal frame relative to the centre of mass
    (module docstring).

    points, normals, first_directions (G, M, 3) [h], 1, 1; curvatures (G, M, 2) κ₁ ≥ κ₂
    [h⁻¹]; osculating (G, M) clamped osculating radii [h]; principal_curvatures (G, M, 2)
    κ₁, κ₂ clamped to [1/R_max, 1/R_min] [h⁻¹] (for SPEC §3.4); tables (G, 6, c+1, c+1) radius
    tables of the packing frame [h]; table_errors (G,) their largest error [h]; centroids
    (G, 3) the packing-frame origin in the principal frame relative to the centre of mass [h];
    to_packing (G, 3, 3) P (packing = Pᵀ principal); reach (G,) support radius about the
    centroid [h]; radius_range (G, 2) [h].
    """

    points: np.ndarray
    normals: np.ndarray
    first_directions: np.ndarray
    curvatures: np.ndarray
    osculating: np.ndarray
    principal_curvatures: np.ndarray
    tables: np.ndarray
    table_errors: np.ndarray
    centroids: np.ndarray
    to_packing: np.ndarray
    reach: np.ndarray
    radius_range: np.ndarray


@njit(**JIT_OPTIONS)
def osculating_radius(k1, k2, r_min, r_max):
    """R = 2/(κ₁ + κ₂) [h] clamped to [r_min, r_max]; flat and concave points (κ₁ + κ₂ ≤ 2/r_max)
    get r_max (module docstring)."""
    total = k1 + k2
    if total <= 2.0 / r_max:
        return r_max
    return min(max(2.0 / total, r_min), r_max)


def grain_surfaces(coefficients: np.ndarray, radii: np.ndarray, support_radii: np.ndarray,
                   centre_shift: np.ndarray, body_to_principal: np.ndarray, *,
                   points: int = DEFAULT_SURFACE_POINTS, cells: int = DEFAULT_TABLE_CELLS,
                   radius_range: tuple[float, float] = (0.25, 2.0)) -> GrainSurfaces:
    """Surface samples of grains with packing-frame ``coefficients`` (G, K) [h],
    volume-equivalent ``radii`` and ``support_radii`` (G,) [h], lattice centres of mass
    ``centre_shift`` (G, 3) [h] and rotations ``body_to_principal`` (G, 3, 3)
    (:class:`~suspsim.bodies.construction.BodyParticles`). ``radius_range`` (low, high): the
    osculating radii are clamped to [low · a, high · a_support]."""
    coefficients = np.asarray(coefficients, dtype=np.float64)
    directions = fibonacci_directions(points)
    count = len(coefficients)
    out = {name: np.empty((count, points, 3)) for name in ("points", "normals", "first")}
    curvatures = np.empty((count, points, 2))
    tables = []
    errors = np.empty(count)
    bounds = np.column_stack([radius_range[0] * np.asarray(radii, dtype=float),
                              radius_range[1] * np.asarray(support_radii, dtype=float)])
    for g in range(count):
        geometry = surface_geometry(coefficients[g], directions)
        rot = np.asarray(body_to_principal[g], dtype=float)
        out["points"][g] = (geometry.points - centre_shift[g]) @ rot.T
        out["normals"][g] = geometry.normals @ rot.T
        out["first"][g] = geometry.directions[:, 0] @ rot.T
        curvatures[g] = geometry.curvatures
        tables.append(build_table(coefficients[g], cells))
        errors[g] = table_error(coefficients[g], tables[-1])
    osculating = np.empty((count, points))
    for g in range(count):
        total = curvatures[g].sum(axis=1)
        flat = total <= 2.0 / bounds[g, 1]
        osculating[g] = np.where(flat, bounds[g, 1],
                                 np.clip(2.0 / np.where(flat, 1.0, total), *bounds[g]))
    principal = np.clip(curvatures, 1.0 / bounds[:, 1, None, None], 1.0 / bounds[:, 0, None, None])
    centroids = -np.einsum("gij,gj->gi", body_to_principal, centre_shift)
    return GrainSurfaces(points=out["points"], normals=out["normals"],
                         first_directions=out["first"], curvatures=curvatures,
                         osculating=osculating, principal_curvatures=principal,
                         tables=np.ascontiguousarray(np.stack(tables)), table_errors=errors,
                         centroids=np.ascontiguousarray(centroids),
                         to_packing=np.ascontiguousarray(body_to_principal, dtype=float),
                         reach=np.asarray(support_radii, dtype=float).copy(),
                         radius_range=bounds)


@njit(**JIT_OPTIONS)
def _best_sample(points_a, rot_a, ox, oy, oz, table_b, to_packing_b, rot_b, centroid_b, reach_b):
    """(k, radial gap) of the sample point of A with the smallest radial gap to B.

    A's centre of mass is at the origin, B's at (ox, oy, oz) [h]; ``rot_*`` principal → box;
    B's centroid is at o + rot_b centroid_b. Points farther than ``reach_b`` from the centroid
    are skipped; (−1, inf) if none is within."""
    gx, gy, gz = centroid_b[0], centroid_b[1], centroid_b[2]
    cx = ox + rot_b[0, 0] * gx + rot_b[0, 1] * gy + rot_b[0, 2] * gz
    cy = oy + rot_b[1, 0] * gx + rot_b[1, 1] * gy + rot_b[1, 2] * gz
    cz = oz + rot_b[2, 0] * gx + rot_b[2, 1] * gy + rot_b[2, 2] * gz
    # box → packing frame of B: m = Pᵀ Qᵀ
    m = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            # (Pᵀ Qᵀ)[i, j] = Σ_k P[k, i] Q[j, k]
            m[i, j] = (to_packing_b[0, i] * rot_b[j, 0] + to_packing_b[1, i] * rot_b[j, 1]
                       + to_packing_b[2, i] * rot_b[j, 2])
    best, best_gap = -1, np.inf
    reach2 = reach_b * reach_b
    for k in range(points_a.shape[0]):
        px, py, pz = points_a[k, 0], points_a[k, 1], points_a[k, 2]
        dx = rot_a[0, 0] * px + rot_a[0, 1] * py + rot_a[0, 2] * pz - cx
        dy = rot_a[1, 0] * px + rot_a[1, 1] * py + rot_a[1, 2] * pz - cy
        dz = rot_a[2, 0] * px + rot_a[2, 1] * py + rot_a[2, 2] * pz - cz
        rho2 = dx * dx + dy * dy + dz * dz
        if rho2 >= reach2:
            continue
        rho = math.sqrt(rho2)
        if rho == 0.0:
            return k, -reach_b
        ux = (m[0, 0] * dx + m[0, 1] * dy + m[0, 2] * dz) / rho
        uy = (m[1, 0] * dx + m[1, 1] * dy + m[1, 2] * dz) / rho
        uz = (m[2, 0] * dx + m[2, 1] * dy + m[2, 2] * dz) / rho
        gap = rho - table_radius(table_b, ux, uy, uz)
        if gap < best_gap:
            best, best_gap = k, gap
    return best, best_gap


@njit(**JIT_OPTIONS)
def grain_pair_contact(a, b, r_ab, rot_a, rot_b, points, normals, osculating, tables,
                       to_packing, centroids, reach, cutoff_gap, out):
    """Closest points of grains ``a`` and ``b`` (indices into the :class:`GrainSurfaces`
    arrays) and their osculating spheres (module docstring).

    ``r_ab`` = R_a − R_b (3,) [h], centres of mass, minimum image; ``rot_a``, ``rot_b`` (3, 3)
    principal → box. Writes ``out`` (:data:`CONTACT_WIDTH`,): c_A − R_a, c_B − R_b (box frame),
    R_A, R_B, s, k_A, k_B. Returns False when no sample point of either grain is within the
    other's support radius + ``cutoff_gap`` (no contact; ``out`` untouched).
    """
    ka, _ = _best_sample(points[a], rot_a, -r_ab[0], -r_ab[1], -r_ab[2], tables[b],
                         to_packing[b], rot_b, centroids[b], reach[b] + cutoff_gap)
    kb, _ = _best_sample(points[b], rot_b, r_ab[0], r_ab[1], r_ab[2], tables[a],
                         to_packing[a], rot_a, centroids[a], reach[a] + cutoff_gap)
    if ka < 0 or kb < 0:
        return False
    ra = osculating[a, ka]
    rb = osculating[b, kb]
    for i in range(3):
        out[C_A + i] = (rot_a[i, 0] * (points[a, ka, 0] - ra * normals[a, ka, 0])
                        + rot_a[i, 1] * (points[a, ka, 1] - ra * normals[a, ka, 1])
                        + rot_a[i, 2] * (points[a, ka, 2] - ra * normals[a, ka, 2]))
        out[C_B + i] = (rot_b[i, 0] * (points[b, kb, 0] - rb * normals[b, kb, 0])
                        + rot_b[i, 1] * (points[b, kb, 1] - rb * normals[b, kb, 1])
                        + rot_b[i, 2] * (points[b, kb, 2] - rb * normals[b, kb, 2]))
    dx = r_ab[0] + out[C_A] - out[C_B]
    dy = r_ab[1] + out[C_A + 1] - out[C_B + 1]
    dz = r_ab[2] + out[C_A + 2] - out[C_B + 2]
    out[RADIUS_A] = ra
    out[RADIUS_B] = rb
    out[GAP] = math.sqrt(dx * dx + dy * dy + dz * dz) - ra - rb
    out[INDEX_A] = ka
    out[INDEX_B] = kb
    return True
