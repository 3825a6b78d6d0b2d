"""Real spherical harmonics: evaluation, synthesis on a Gauss grid, exact projection, rotation.

A star-shaped body's radius is a band-limited function on the unit sphere (SPEC §4;
Garboczi 2002),

    r(θ, φ) = Σ_{n=0}^{N} Σ_{m=−n}^{n} a_nm Y_nm(θ, φ),

in the orthonormal real basis (∫ Y_nm Y_n'm' dΩ = δ_nn' δ_mm'; no Condon–Shortley phase)

    Y_n0 = P̄_n^0(cos θ),  Y_nm = √2 P̄_n^m(cos θ) cos mφ,  Y_n,−m = √2 P̄_n^m(cos θ) sin mφ
    (m > 0),

with P̄_n^m the associated Legendre functions normalised so that 2π ∫_{−1}^{1} (P̄_n^m)² dx = 1,
computed by the standard stable recurrence (Holmes & Featherstone, J. Geodesy 76, 279 (2002)):

    P̄_0^0 = 1/√(4π),  P̄_m^m = √((2m+1)/(2m)) sin θ P̄_{m−1}^{m−1},  P̄_{m+1}^m = √(2m+3) x P̄_m^m,
    P̄_n^m = α_nm (x P̄_{n−1}^m − β_nm P̄_{n−2}^m),
    α_nm = √((4n²−1)/(n²−m²)),  β_nm = √(((n−1)²−m²)/(4(n−1)²−1)).

Coefficients are stored flat, a[n² + n + m], (N+1)² of them (:func:`coefficient_index`).

Gauss grid: n_θ Gauss–Legendre nodes in x = cos θ and n_φ equispaced φ integrate
x^p cos(kφ) exactly for p ≤ 2n_θ − 1 and |k| < n_φ. A product of q functions of degree ≤ N is
a polynomial of degree ≤ qN on the sphere, so :func:`gauss_grid` with ``exact_degree = qN``
gives its integral to round-off: volume (q = 3), centroid (4 + 1), inertia (5 + 2) and the
projection that rotates a shape (2) are exact, not approximations.
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np
from numba import njit

__all__ = ["GaussGrid", "coefficient_count", "coefficient_degree", "coefficient_index",
           "degree_of", "evaluate", "evaluate_one", "gauss_grid", "legendre", "project",
           "recurrence_tables", "rotate_coefficients", "synthesize"]


def coefficient_count(degree: int) -> int:
    """Number of coefficients of an expansion up to ``degree``: (N + 1)²."""
    return (degree + 1) ** 2


def coefficient_index(n: int, m: int) -> int:
    """Flat index of a_nm: n² + n + m."""
    return n * n + n + m


def degree_of(coefficients) -> int:
    """Degree N of a flat coefficient array of length (N + 1)² (ValueError otherwise)."""
    size = np.shape(coefficients)[-1]
    degree = math.isqrt(size) - 1
    if (degree + 1) ** 2 != size:
        raise ValueError(f"{size} coefficients is not (N + 1)^2 for an integer degree N")
    return degree


def coefficient_degree(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """(n, m) of every flat index up to ``degree``, as two int arrays."""
    n = np.concatenate([np.full(2 * k + 1, k) for k in range(degree + 1)])
    m = np.concatenate([np.arange(-k, k + 1) for k in range(degree + 1)])
    return n, m


def legendre(degree: int, x: np.ndarray) -> np.ndarray:
    """P̄_n^m(x) for 0 ≤ m ≤ n ≤ N, an array (N + 1, N + 1, len(x)) indexed [n, m]; 0 if m > n."""
    x = np.asarray(x, dtype=np.float64)
    s = np.sqrt(np.maximum(0.0, 1.0 - x * x))
    p = np.zeros((degree + 1, degree + 1) + x.shape)
    p[0, 0] = 1.0 / math.sqrt(4.0 * math.pi)
    for m in range(degree + 1):
        if m > 0:
            p[m, m] = math.sqrt((2 * m + 1) / (2 * m)) * s * p[m - 1, m - 1]
        if m + 1 <= degree:
            p[m + 1, m] = math.sqrt(2 * m + 3) * x * p[m, m]
        for n in range(m + 2, degree + 1):
            alpha = math.sqrt((4 * n * n - 1) / (n * n - m * m))
            beta = math.sqrt(((n - 1) ** 2 - m * m) / (4 * (n - 1) ** 2 - 1))
            p[n, m] = alpha * (x * p[n - 1, m] - beta * p[n - 2, m])
    return p


@dataclass(frozen=True)
class GaussGrid:
    """A Gauss–Legendre × equispaced grid on the unit sphere with its quadrature weights.

    ``x`` (n_θ,) nodes in cos θ, ``phi`` (n_φ,), ``weights`` (n_θ, n_φ) with Σ weights = 4π,
    ``directions`` (n_θ, n_φ, 3) unit vectors. For synthesis and projection as matrix products:
    ``legendre`` (n_θ, K) holds P̄_n^|m|(x) of every flat index, ``trig`` (2N+1, n_φ) the
    φ-factors of m = −N..N (√2 sin|m|φ, 1, √2 cos mφ) and ``order`` (K,) the row of ``trig``
    (m + N) of every flat index. Shared by a cache: treat as read-only.
    """

    degree: int
    x: np.ndarray
    phi: np.ndarray
    weights: np.ndarray
    directions: np.ndarray
    legendre: np.ndarray
    trig: np.ndarray
    order: np.ndarray


@functools.lru_cache(maxsize=32)
def gauss_grid(degree: int, exact_degree: int) -> GaussGrid:
    """Grid for expansions up to ``degree`` whose quadrature is exact up to ``exact_degree``."""
    n_theta = exact_degree // 2 + 1
    n_phi = exact_degree + 1
    x, w = np.polynomial.legendre.leggauss(n_theta)
    phi = 2.0 * math.pi * np.arange(n_phi) / n_phi
    s = np.sqrt(1.0 - x * x)
    directions = np.stack([s[:, None] * np.cos(phi)[None, :], s[:, None] * np.sin(phi)[None, :],
                           np.broadcast_to(x[:, None], (n_theta, n_phi))], axis=-1)
    weights = np.outer(w, np.full(n_phi, 2.0 * math.pi / n_phi))
    n, m = coefficient_degree(degree)
    table = legendre(degree, x)
    m_signed = np.arange(-degree, degree + 1)[:, None]
    trig = np.where(m_signed > 0, math.sqrt(2.0) * np.cos(m_signed * phi),
                    np.where(m_signed < 0, math.sqrt(2.0) * np.sin(-m_signed * phi), 1.0))
    return GaussGrid(degree, x, phi, weights, directions, table[n, np.abs(m)].T.copy(), trig,
                     m + degree)


def synthesize(coefficients: np.ndarray, grid: GaussGrid) -> np.ndarray:
    """r on the grid, (n_θ, n_φ): Σ a_nm Y_nm, as a Legendre sum per (θ, m) then a Fourier sum.

    Coefficients beyond the grid's degree are ignored.
    """
    size = min(len(coefficients), grid.legendre.shape[1])
    selector = np.zeros((size, grid.trig.shape[0]))
    selector[np.arange(size), grid.order[:size]] = 1.0
    return ((grid.legendre[:, :size] * coefficients[:size]) @ selector) @ grid.trig


def project(values: np.ndarray, grid: GaussGrid) -> np.ndarray:
    """Coefficients a_nm = ∫ f Y_nm dΩ up to ``grid.degree`` of ``values`` (n_θ, n_φ) on the grid.

    Exact when f is band-limited to degree D and the grid's quadrature is exact to D + N.
    """
    fourier = (values * grid.weights) @ grid.trig.T
    return (grid.legendre * fourier[:, grid.order]).sum(axis=0)


def evaluate(coefficients: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """r(u) = Σ a_nm Y_nm(u) at unit vectors ``directions`` (..., 3), exact (no table)."""
    u = np.asarray(directions, dtype=np.float64)
    flat = u.reshape(-1, 3)
    out = np.empty(len(flat))
    alpha, beta = recurrence_tables(degree_of(coefficients))
    _evaluate_many(np.ascontiguousarray(coefficients, dtype=np.float64), alpha, beta, flat, out)
    return out.reshape(u.shape[:-1])


def recurrence_tables(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """α_nm and β_nm of the Legendre recurrence (module docstring), arrays (N + 1, N + 1)."""
    n = np.arange(degree + 1, dtype=np.float64)[:, None]
    m = np.arange(degree + 1, dtype=np.float64)[None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        alpha = np.sqrt((4 * n * n - 1) / (n * n - m * m))
        beta = np.sqrt(((n - 1) ** 2 - m * m) / (4 * (n - 1) ** 2 - 1))
    valid = n >= m + 2
    return np.where(valid, alpha, 0.0), np.where(valid, beta, 0.0)


@njit(cache=True)
def evaluate_one(a, degree, alpha, beta, ux, uy, uz):
    """r(u) = Σ a_nm Y_nm(u) at one unit vector (compiled, no allocation).

    ``alpha``, ``beta`` from :func:`recurrence_tables`. With q_n^m = P̄_n^m / sin^m θ, which obeys
    the same recurrence in x = u_z, and (c_m, s_m) = sin^m θ (cos mφ, sin mφ) = (Re, Im)
    (u_x + i u_y)^m, every term is q_n^m (c_m, s_m): no angles, no special case at the poles.
    """
    x = uz
    c_m, s_m = 1.0, 0.0
    q_mm = 1.0 / math.sqrt(4.0 * math.pi)
    root2 = math.sqrt(2.0)
    total = 0.0
    for m in range(degree + 1):
        if m > 0:
            q_mm *= math.sqrt((2 * m + 1) / (2 * m))
            c_m, s_m = c_m * ux - s_m * uy, c_m * uy + s_m * ux
        # At m = 0, s_m = 0, so the sine term adds nothing.
        wc = c_m if m == 0 else root2 * c_m
        ws = root2 * s_m
        k = m * m + 2 * m
        total += q_mm * (a[k] * wc + a[k - 2 * m] * ws)
        if m == degree:
            break
        q_prev2 = q_mm
        q_prev = math.sqrt(2 * m + 3) * x * q_mm
        k = (m + 1) * (m + 1) + (m + 1)
        total += q_prev * (a[k + m] * wc + a[k - m] * ws)
        for n in range(m + 2, degree + 1):
            q = alpha[n, m] * (x * q_prev - beta[n, m] * q_prev2)
            q_prev2, q_prev = q_prev, q
            k = n * n + n
            total += q * (a[k + m] * wc + a[k - m] * ws)
    return total


@njit(cache=True)
def _evaluate_many(a, alpha, beta, u, out):
    degree = alpha.shape[0] - 1
    for i in range(u.shape[0]):
        out[i] = evaluate_one(a, degree, alpha, beta, u[i, 0], u[i, 1], u[i, 2])


def rotate_coefficients(coefficients: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Coefficients of the same body expressed in a frame rotated by ``rotation`` (3 × 3).

    A point x of the old frame has coordinates R x in the new one, so r_new(u) = r_old(Rᵀu).
    Computed by exact projection on a Gauss grid of degree 2N (rotation keeps the degree).
    """
    degree = degree_of(coefficients)
    grid = gauss_grid(degree, 2 * degree)
    old_directions = grid.directions @ np.asarray(rotation, dtype=np.float64)
    return project(evaluate(coefficients, old_directions), grid)
