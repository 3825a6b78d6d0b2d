"""Star-shaped bodies from a spherical-harmonic radius: volume, mass properties, surface geometry.

A body is the set {ρ u : 0 ≤ ρ < r(u), |u| = 1} in its body frame, with
r(u) = Σ_{n≤N} Σ_m a_nm Y_nm(u) (real orthonormal harmonics, :mod:`~suspsim.bodies.harmonics`;
Garboczi, Cem. Concr. Res. 32, 1621 (2002)). A sphere of radius a is a_00 = 2√π a, all other
coefficients 0. Lengths are in [length], the project's unit h (SPH kernel support radius).

Mass properties for unit density, as surface integrals over the unit sphere (exact to round-off
on the Gauss grid of :func:`~suspsim.bodies.harmonics.gauss_grid`):

    V = ⅓ ∫ r³ dΩ,   c = (1/(4V)) ∫ r⁴ u dΩ,   J₀ = ⅕ ∫ r⁵ (I − u uᵀ) dΩ,
    J_c = J₀ − V (|c|² I − c cᵀ)  (inertia tensor about the centroid, [length⁵]).

Surface X(θ, φ) = r(θ, φ) u(θ, φ); with e_θ, e_φ the spherical unit vectors,

    X_θ = r_θ u + r e_θ,   X_φ = r_φ u + r sin θ e_φ,   n = X_θ × X_φ / |X_θ × X_φ| (outward),
    X_θθ = (r_θθ − r) u + 2 r_θ e_θ,
    X_θφ = r_θφ u + r_φ e_θ + (r_θ sin θ + r cos θ) e_φ,
    X_φφ = (r_φφ − r sin²θ) u − r sin θ cos θ e_θ + 2 r_φ sin θ e_φ.

First and second fundamental forms E, F, G and L = X_θθ·n, M = X_θφ·n, N = X_φφ·n give the
shape operator I⁻¹II, whose eigenvalues k (mean H = ½ tr, Gaussian K = det) give the principal
curvatures κ = −k, signed positive where the surface is convex seen from outside (a sphere of
radius a: κ₁ = κ₂ = 1/a). The derivatives of P̄_n^m in θ are

    ∂_θ P̄_n^m = [n x P̄_n^m − √((2n+1)(n²−m²)/(2n−1)) P̄_{n−1}^m] / sin θ,
    ∂²_θ P̄_n^m = −cot θ ∂_θ P̄_n^m − (n(n+1) − m²/sin²θ) P̄_n^m  (Legendre's equation),

singular at the poles, so (SPEC §4) points with |u_z| > 1/√2 are evaluated in a frame whose
pole is the x axis (coefficients rotated exactly), where sin θ ≥ 1/√2.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import harmonics as sh

__all__ = ["MassProperties", "SurfaceGeometry", "contains", "mass_properties", "radius_bounds",
           "sphere_coefficients", "surface_geometry", "surface_points", "volume"]

_SQRT_4PI = math.sqrt(4.0 * math.pi)
# Cyclic permutation (x, y, z) -> (y, z, x): the rotated frame's pole is the old x axis.
_POLE_SWAP = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])


def sphere_coefficients(radius: float, degree: int = 0) -> np.ndarray:
    """Coefficients of a sphere of ``radius`` [length]: a_00 = 2√π a, up to ``degree``."""
    a = np.zeros(sh.coefficient_count(degree))
    a[0] = _SQRT_4PI * radius
    return a


@dataclass(frozen=True)
class MassProperties:
    """Volume [length³], centroid (3,) [length] and inertia tensor about the centroid (3, 3)
    [length⁵] of a body of unit density, in its body frame."""

    volume: float
    centroid: np.ndarray
    inertia: np.ndarray


def mass_properties(coefficients: np.ndarray) -> MassProperties:
    """Exact volume, centroid and central inertia tensor (see the module docstring)."""
    degree = sh.degree_of(coefficients)
    grid = _moment_grid(degree)
    return _mass_properties_on(coefficients, grid)


def volume(coefficients: np.ndarray) -> float:
    """Exact volume ⅓∫r³dΩ [length³]."""
    degree = sh.degree_of(coefficients)
    grid = sh.gauss_grid(degree, 3 * degree)
    return float((sh.synthesize(coefficients, grid) ** 3 * grid.weights).sum() / 3.0)


def _moment_grid(degree: int) -> sh.GaussGrid:
    return sh.gauss_grid(degree, 5 * degree + 2)


def _mass_properties_on(coefficients, grid) -> MassProperties:
    r = sh.synthesize(coefficients, grid)
    w = grid.weights
    u = grid.directions
    vol = float((r ** 3 * w).sum() / 3.0)
    centroid = np.einsum("ij,ijk->k", r ** 4 * w, u) / (4.0 * vol)
    r5w = r ** 5 * w
    second = np.einsum("ij,ijk,ijl->kl", r5w, u, u) / 5.0
    inertia_origin = np.trace(second) * np.eye(3) - second
    inertia = inertia_origin - vol * (centroid @ centroid * np.eye(3) - np.outer(centroid, centroid))
    return MassProperties(vol, centroid, inertia)


def radius_bounds(coefficients: np.ndarray, oversampling: int = 4) -> tuple[float, float]:
    """Rigorous bounds (r_lo ≤ min r, max r ≤ r_hi) [length] of the radius function.

    r is sampled on a Gauss grid ``oversampling`` times finer than the degree needs; between
    nodes r cannot exceed the sampled extreme by more than ½δ²·Σ_n n²‖r_n‖∞, with δ the largest
    angular distance to a node and ‖r_n‖∞ ≤ √((2n+1)/(4π)) ‖a_n‖₂ (Bernstein's inequality on a
    great circle through the extremum, where the first derivative vanishes). ``r_hi`` is the
    support radius used for neighbour search: no point of the body lies farther from the origin.
    """
    degree = sh.degree_of(coefficients)
    grid = sh.gauss_grid(degree, oversampling * max(degree, 4))
    r = sh.synthesize(coefficients, grid)
    theta = np.arccos(grid.x)
    d_theta = np.max(np.abs(np.diff(np.concatenate([[math.pi], theta, [0.0]]))))
    d_phi = grid.phi[1] - grid.phi[0]
    delta = 0.5 * math.hypot(d_theta, d_phi)
    n, _ = sh.coefficient_degree(degree)
    norms = np.sqrt(np.bincount(n, weights=coefficients ** 2))
    curvature_bound = np.sum(np.arange(degree + 1) ** 2 * np.sqrt((2 * np.arange(degree + 1) + 1)
                                                                  / (4 * math.pi)) * norms)
    slack = 0.5 * delta ** 2 * curvature_bound
    return float(r.min() - slack), float(r.max() + slack)


def surface_points(coefficients: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """Surface points r(u) u (..., 3) [length] along unit vectors ``directions`` (body frame)."""
    u = np.asarray(directions, dtype=np.float64)
    return sh.evaluate(coefficients, u)[..., None] * u


def contains(coefficients: np.ndarray, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """True where a body-frame point lies strictly inside the body enlarged radially by
    ``margin`` [length]: |p| < r(p/|p|) + margin (the origin is inside)."""
    p = np.asarray(points, dtype=np.float64)
    rho = np.linalg.norm(p, axis=-1)
    safe = np.where(rho[..., None] > 0.0, p / np.where(rho > 0.0, rho, 1.0)[..., None],
                    np.array([0.0, 0.0, 1.0]))
    return rho < sh.evaluate(coefficients, safe) + margin


@dataclass(frozen=True)
class SurfaceGeometry:
    """Surface geometry at M directions (body frame).

    points (M, 3) [length]; normals (M, 3) outward unit normals; curvatures (M, 2) principal
    curvatures κ₁ ≥ κ₂ [1/length], positive where convex; directions (M, 2, 3) the unit principal
    directions (tangent, orthogonal, t₂ = n × t₁; arbitrary at umbilics such as a sphere).
    """

    points: np.ndarray
    normals: np.ndarray
    curvatures: np.ndarray
    directions: np.ndarray


def surface_geometry(coefficients: np.ndarray, directions: np.ndarray) -> SurfaceGeometry:
    """Surface points, outward normals, principal curvatures and directions along unit vectors."""
    u = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    u = u / np.linalg.norm(u, axis=1)[:, None]
    polar = np.abs(u[:, 2]) > math.sqrt(0.5)
    out = [np.empty((len(u), 3)), np.empty((len(u), 3)), np.empty((len(u), 2)),
           np.empty((len(u), 2, 3))]
    parts = ((~polar, np.asarray(coefficients, dtype=np.float64), np.eye(3)),
             (polar, sh.rotate_coefficients(coefficients, _POLE_SWAP), _POLE_SWAP))
    for mask, a, frame in parts:
        if not mask.any():
            continue
        results = _geometry_away_from_poles(a, u[mask] @ frame.T)
        # Vectors come back in the evaluation frame; x_body = frameᵀ x_frame.
        out[0][mask] = results[0] @ frame
        out[1][mask] = results[1] @ frame
        out[2][mask] = results[2]
        out[3][mask] = results[3] @ frame
    return SurfaceGeometry(*out)


def _radius_derivatives(a: np.ndarray, theta: np.ndarray, phi: np.ndarray):
    """r, r_θ, r_φ, r_θθ, r_θφ, r_φφ at (θ, φ) with sin θ bounded away from 0."""
    degree = sh.degree_of(a)
    x, s = np.cos(theta), np.sin(theta)
    p = sh.legendre(degree, x)
    n_all = np.arange(degree + 1)[:, None, None]
    m_all = np.arange(degree + 1)[None, :, None]
    p_lower = np.zeros_like(p)
    p_lower[1:] = p[:-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = np.sqrt(np.maximum(0.0, (2 * n_all + 1) * (n_all ** 2 - m_all ** 2)
                                    / (2 * n_all - 1.0)))
    factor = np.nan_to_num(factor)
    dp = (n_all * x * p - factor * p_lower) / s
    d2p = -(x / s) * dp - (n_all * (n_all + 1) - m_all ** 2 / s ** 2) * p
    values = [np.zeros_like(x) for _ in range(6)]
    for m in range(degree + 1):
        n = np.arange(m, degree + 1)
        weight = 1.0 if m == 0 else math.sqrt(2.0)
        cos_m, sin_m = weight * np.cos(m * phi), weight * np.sin(m * phi)
        a_c = a[n * n + n + m]
        a_s = a[n * n + n - m] if m > 0 else np.zeros_like(a_c)
        for k, table in ((0, p), (1, dp), (3, d2p)):
            c = a_c @ table[m:, m]
            s_ = a_s @ table[m:, m]
            values[k] += c * cos_m + s_ * sin_m
            if k == 0:
                values[2] += m * (s_ * cos_m - c * sin_m)
                values[5] += -m * m * (c * cos_m + s_ * sin_m)
            elif k == 1:
                values[4] += m * (s_ * cos_m - c * sin_m)
    return values


def _col(values: np.ndarray) -> np.ndarray:
    """A per-point scalar as a column, to scale (M, 3) vectors."""
    return values[:, None]


def _geometry_away_from_poles(a: np.ndarray, u: np.ndarray):
    theta = np.arccos(np.clip(u[:, 2], -1.0, 1.0))
    phi = np.arctan2(u[:, 1], u[:, 0])
    r, r_t, r_p, r_tt, r_tp, r_pp = _radius_derivatives(a, theta, phi)
    st, ct, sp, cp = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
    e_r = np.stack([st * cp, st * sp, ct], axis=1)
    e_t = np.stack([ct * cp, ct * sp, -st], axis=1)
    e_p = np.stack([-sp, cp, np.zeros_like(sp)], axis=1)
    x_t = _col(r_t) * e_r + _col(r) * e_t
    x_p = _col(r_p) * e_r + _col(r * st) * e_p
    x_tt = _col(r_tt - r) * e_r + _col(2 * r_t) * e_t
    x_tp = _col(r_tp) * e_r + _col(r_p) * e_t + _col(r_t * st + r * ct) * e_p
    x_pp = _col(r_pp - r * st ** 2) * e_r - _col(r * st * ct) * e_t + _col(2 * r_p * st) * e_p
    normal = np.cross(x_t, x_p)
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    e_ff, f_ff, g_ff = (x_t * x_t).sum(1), (x_t * x_p).sum(1), (x_p * x_p).sum(1)
    l_sf, m_sf, n_sf = (x_tt * normal).sum(1), (x_tp * normal).sum(1), (x_pp * normal).sum(1)
    # Second fundamental form in the orthonormal tangent basis t_a = X_θ/|X_θ|, t_b = n × t_a:
    # with the Cholesky factor J = [[l11, l21], [0, l22]] of the first form (X_θ = l11 t_a,
    # X_φ = l21 t_a + l22 t_b), A = J⁻ᵀ II J⁻¹ is symmetric and its eigenvalues are found
    # without the cancellation of H ± √(H² − K) (exact umbilics at a sphere).
    l11 = np.sqrt(e_ff)
    l21 = f_ff / l11
    l22 = np.sqrt(g_ff - l21 ** 2)
    ia, ib, id_ = 1.0 / l11, -l21 / (l11 * l22), 1.0 / l22
    a11 = l_sf * ia ** 2
    a12 = ia * (l_sf * ib + m_sf * id_)
    a22 = ib * (l_sf * ib + m_sf * id_) + id_ * (m_sf * ib + n_sf * id_)
    mean = 0.5 * (a11 + a22)
    root = np.hypot(0.5 * (a11 - a22), a12)
    # Shape-operator eigenvalues k = mean ± root; convex-positive curvatures are κ = −k.
    curvatures = np.stack([root - mean, -root - mean], axis=1)
    psi = 0.5 * np.arctan2(2.0 * a12, a11 - a22)
    t_a = x_t / _col(l11)
    t_b = np.cross(normal, t_a)
    # κ₁ = −(mean − root) belongs to the smaller eigenvalue, eigenvector (−sin ψ, cos ψ).
    t1 = _col(-np.sin(psi)) * t_a + _col(np.cos(psi)) * t_b
    t2 = np.cross(normal, t1)
    points = _col(r) * e_r
    return points, normal, curvatures, np.stack([t1, t2], axis=1)
