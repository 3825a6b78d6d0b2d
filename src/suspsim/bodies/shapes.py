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
from numba import njit

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
    grid = sh.gauss_grid(degree, 5 * degree + 2)
    r = sh.synthesize(coefficients, grid).ravel()
    w = grid.weights.ravel()
    u = grid.directions.reshape(-1, 3)
    vol = float((r ** 3 * w).sum() / 3.0)
    centroid = (r ** 4 * w) @ u / (4.0 * vol)
    second = (u * (r ** 5 * w)[:, None]).T @ u / 5.0
    inertia_origin = np.trace(second) * np.eye(3) - second
    shift = centroid @ centroid * np.eye(3) - np.outer(centroid, centroid)
    inertia = inertia_origin - vol * shift
    return MassProperties(vol, centroid, inertia)


def volume(coefficients: np.ndarray) -> float:
    """Exact volume ⅓∫r³dΩ [length³]."""
    degree = sh.degree_of(coefficients)
    grid = sh.gauss_grid(degree, 3 * degree)
    return float((sh.synthesize(coefficients, grid) ** 3 * grid.weights).sum() / 3.0)


def radius_bounds(coefficients: np.ndarray, oversampling: int = 8) -> tuple[float, float]:
    """Rigorous bounds (r_lo ≤ min r, max r ≤ r_hi) [length] of the radius function.

    r is sampled on a Gauss grid ``oversampling`` times finer than the degree needs; between
    nodes r cannot exceed the sampled extreme by more than ½δ²·Σ_n n²‖r_n‖∞, with δ the largest
    angular distance to a node and ‖r_n‖∞ ≤ √((2n+1)/(4π)) ‖a_n‖₂ (Bernstein's inequality on a
    great circle through the extremum, where the first derivative vanishes), plus a bound on
    the rounding of the synthesis. ``r_hi`` is the support radius used for neighbour search:
    no point of the body lies farther from the origin.
    """
    degree = sh.degree_of(coefficients)
    grid = sh.gauss_grid(degree, oversampling * max(degree, 4))
    r = sh.synthesize(coefficients, grid)
    theta = np.arccos(grid.x)
    d_theta = np.max(np.abs(np.diff(theta)))
    d_phi = grid.phi[1] - grid.phi[0]
    # Between rings a point is within half a cell diagonal of a node; a pole is one ring gap
    # away from every node of the nearest ring.
    delta = max(0.5 * math.hypot(d_theta, d_phi), math.pi - theta.max(), theta.min())
    n, _ = sh.coefficient_degree(degree)
    norms = np.sqrt(np.bincount(n, weights=coefficients ** 2))
    curvature_bound = np.sum(np.arange(degree + 1) ** 2 * np.sqrt((2 * np.arange(degree + 1) + 1)
                                                                  / (4 * math.pi)) * norms)
    # Rounding of the synthesis: a few ulps of the largest possible |r| = Σ_n ‖r_n‖∞.
    rounding = 64 * np.finfo(float).eps * np.sum(np.sqrt((2 * np.arange(degree + 1) + 1)
                                                          / (4 * math.pi)) * norms)
    slack = 0.5 * delta ** 2 * curvature_bound + rounding
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
    alpha, beta = sh.recurrence_tables(degree)
    n = np.arange(degree + 1, dtype=np.float64)[:, None]
    m = np.arange(degree + 1, dtype=np.float64)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        lower = np.sqrt((2 * n + 1) * (n * n - m * m) / (2 * n - 1))
    lower = np.where(n > m, lower, 0.0)
    out = np.empty((6, len(theta)))
    _derivatives_many(np.ascontiguousarray(a, dtype=np.float64), alpha, beta, lower,
                      np.asarray(theta, dtype=np.float64), np.asarray(phi, dtype=np.float64), out)
    return list(out)


@njit(cache=True)
def _derivatives_many(a, alpha, beta, lower, theta, phi, out):
    degree = alpha.shape[0] - 1
    root2 = math.sqrt(2.0)
    for i in range(theta.shape[0]):
        x, s = math.cos(theta[i]), math.sin(theta[i])
        c1, s1 = math.cos(phi[i]), math.sin(phi[i])
        cos_m, sin_m = 1.0, 0.0
        p_mm = 1.0 / math.sqrt(4.0 * math.pi)
        r = r_t = r_p = r_tt = r_tp = r_pp = 0.0
        for m in range(degree + 1):
            if m > 0:
                p_mm *= math.sqrt((2 * m + 1) / (2 * m)) * s
                cos_m, sin_m = cos_m * c1 - sin_m * s1, sin_m * c1 + cos_m * s1
            weight = 1.0 if m == 0 else root2
            p_prev = 0.0
            p = p_mm
            for n in range(m, degree + 1):
                if n == m + 1:
                    p_prev, p = p, math.sqrt(2 * m + 3) * x * p
                elif n > m + 1:
                    p_prev, p = p, alpha[n, m] * (x * p - beta[n, m] * p_prev)
                dp = (n * x * p - lower[n, m] * p_prev) / s
                d2p = -(x / s) * dp - (n * (n + 1) - m * m / (s * s)) * p
                k = n * n + n
                even = weight * (a[k + m] * cos_m + a[k - m] * sin_m)
                odd = weight * m * (a[k - m] * cos_m - a[k + m] * sin_m)
                r += p * even
                r_t += dp * even
                r_tt += d2p * even
                r_p += p * odd
                r_tp += dp * odd
                r_pp -= m * m * p * even
        out[0, i], out[1, i], out[2, i] = r, r_t, r_p
        out[3, i], out[4, i], out[5, i] = r_tt, r_tp, r_pp


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
