"""Exact resistance of two equal rigid spheres in Stokes flow: Jeffrey & Onishi's X^A (squeeze)
and Y^A (sliding) functions, for comparison with the resolved SPH force (SPEC §3.3).

Twin-multipole coefficients f_k(λ) = 2^k Σ_q P_{1,k−q,q} λ^q (Jeffrey & Onishi 1984, J. Fluid
Mech. 139, 261, Eq. 3.15), from the recurrences for P, V (and Q for Y^A) as printed in
Townsend (arXiv:1802.08226), which corrects JO's typographical errors:

* X^A (JO Eqs. 3.6–3.9): P_{n,p,q} = Σ_{s=1}^{q} C(n+s, n) [n(2n+1)(2ns − n − s + 2)/(2(n+1)
  (2s−1)(n+s)) P_{s,q−s,p−n+1} − n(2n−1)/(2(n+1)) P_{s,q−s,p−n−1} − n(4n²−1)/(2(n+1)(2s+1))
  V_{s,q−s−2,p−n+1}], V_{n,p,q} = P_{n,p,q} − 2n/((n+1)(2n+3)) Σ_s C(n+s, n) P_{s,q−s,p−n−1},
  P_{n,0,0} = V_{n,0,0} = δ_{1n}.
* Y^A (JO Eqs. 4.6–4.11): P_{n,p,q} = Σ_s C(n+s, n+1) [(2n+1)/(2(n+1)) (3(n+s) − (ns+1)(2ns −
  s − n + 2))/(s(n+s)(2s−1)) P_{s,q−s,p−n+1} + n(2n−1)/(2(n+1)) P_{s,q−s,p−n−1} + n(4n²−1)/
  (2(n+1)(2s+1)) V_{s,q−s−2,p−n+1} − 2(4n²−1)/(3(n+1)) Q_{s,q−s−1,p−n+1}], V_{n,p,q} =
  P_{n,p,q} + 2n/((n+1)(2n+3)) Σ_s C(n+s, n+1) P_{s,q−s,p−n−1}, Q_{n,p,q} = Σ_s C(n+s, n+1)
  [s/(n+1) Q_{s,q−s−1,p−n} − 3/(2ns(n+1)) P_{s,q−s,p−n}], P_{n,0,0} = V_{n,0,0} = δ_{1n},
  Q_{n,0,0} = 0.

Both are summed in JO's uniformly valid form (Eqs. 3.20–3.21 and 4.15–4.16, Townsend's
corrected version): the singular g₁/ξ + g₂ ln(1/ξ) + g₃ ξ ln(1/ξ) behaviour (SPEC §3.3 table;
g₁ = 0 for Y^A) in closed form plus the rapidly convergent remainder of the reflection series,
accurate from contact to infinity. Normalisation of Kim & Karrila for λ = 1: the force on
sphere 1 is F₁ = −6πμa (X11A dd + Y11A (I − dd))·U₁ − 6πμa (X12A dd + Y12A (I − dd))·U₂ for
spheres that do not turn. Distances are JO's t = 2r/(a₁ + a₂) (r/a for equal spheres).
"""
from __future__ import annotations

import functools

import numpy as np
from numba import njit

__all__ = ["SERIES_TERMS", "sliding_resistance", "squeeze_resistance", "xa_coefficients",
           "xa_functions", "ya_coefficients", "ya_functions"]

#: Terms of the twin-multipole sums [choice: converged to < 1e-6 for ξ ≥ 0.01].
SERIES_TERMS = 160


@njit(cache=True)
def _xa_table(m):
    """P_{n,p,q} of the X^A recurrence (module docstring) for n ≤ m, p + q ≤ m."""
    size = m + 2
    p_ = np.zeros((size, size, size))
    v_ = np.zeros((size, size, size))
    p_[1, 0, 0] = 1.0
    v_[1, 0, 0] = 1.0
    for total in range(1, m + 1):
        for q in range(total + 1):
            p = total - q
            for n in range(1, m + 1):
                acc = 0.0
                acc_v = 0.0
                c1 = n * (2.0 * n + 1.0) / (2.0 * (n + 1.0))
                c2 = -n * (2.0 * n - 1.0) / (2.0 * (n + 1.0))
                c3 = -n * (4.0 * n * n - 1.0) / (2.0 * (n + 1.0))
                binomial = 1.0
                for s in range(1, q + 1):
                    binomial *= (n + s) / s          # C(n+s, n)
                    up, down = p - n + 1, p - n - 1
                    if up >= 0:
                        acc += binomial * c1 * (2.0 * n * s - n - s + 2.0) / (
                            (2.0 * s - 1.0) * (n + s)) * p_[s, q - s, up]
                        if q - s - 2 >= 0:
                            acc += binomial * c3 / (2.0 * s + 1.0) * v_[s, q - s - 2, up]
                    if down >= 0:
                        acc += binomial * c2 * p_[s, q - s, down]
                        acc_v += binomial * p_[s, q - s, down]
                p_[n, p, q] = acc
                v_[n, p, q] = acc - 2.0 * n / ((n + 1.0) * (2.0 * n + 3.0)) * acc_v
    return p_


@njit(cache=True)
def _ya_table(m):
    """P_{n,p,q} of the Y^A recurrence (module docstring) for n ≤ m, p + q ≤ m."""
    size = m + 2
    p_ = np.zeros((size, size, size))
    v_ = np.zeros((size, size, size))
    q_ = np.zeros((size, size, size))
    p_[1, 0, 0] = 1.0
    v_[1, 0, 0] = 1.0
    for total in range(1, m + 1):
        for q in range(total + 1):
            p = total - q
            for n in range(1, m + 1):
                acc_p = 0.0
                acc_v = 0.0
                acc_q = 0.0
                c1 = (2.0 * n + 1.0) / (2.0 * (n + 1.0))
                c2 = n * (2.0 * n - 1.0) / (2.0 * (n + 1.0))
                c3 = n * (4.0 * n * n - 1.0) / (2.0 * (n + 1.0))
                c4 = -2.0 * (4.0 * n * n - 1.0) / (3.0 * (n + 1.0))
                binomial = 1.0
                for s in range(1, q + 1):
                    if s > 1:
                        binomial *= (n + s) / (s - 1.0)      # C(n+s, n+1)
                    up, down, level = p - n + 1, p - n - 1, p - n
                    if up >= 0:
                        acc_p += binomial * c1 * (3.0 * (n + s) - (n * s + 1.0) * (
                            2.0 * n * s - s - n + 2.0)) / (s * (n + s) * (2.0 * s - 1.0)) \
                            * p_[s, q - s, up]
                        if q - s - 2 >= 0:
                            acc_p += binomial * c3 / (2.0 * s + 1.0) * v_[s, q - s - 2, up]
                        if q - s - 1 >= 0:
                            acc_p += binomial * c4 * q_[s, q - s - 1, up]
                    if down >= 0:
                        acc_p += binomial * c2 * p_[s, q - s, down]
                        acc_v += binomial * p_[s, q - s, down]
                    if level >= 0:
                        if q - s - 1 >= 0:
                            acc_q += binomial * s / (n + 1.0) * q_[s, q - s - 1, level]
                        acc_q -= binomial * 3.0 / (2.0 * n * s * (n + 1.0)) * p_[s, q - s, level]
                p_[n, p, q] = acc_p
                v_[n, p, q] = acc_p + 2.0 * n / ((n + 1.0) * (2.0 * n + 3.0)) * acc_v
                q_[n, p, q] = acc_q
    return p_


def _coefficients(table, size_ratio, terms):
    out = np.zeros(terms + 1)
    for k in range(terms + 1):
        out[k] = 2.0 ** k * sum(table[1, k - q, q] * size_ratio ** q for q in range(k + 1))
    return out


@functools.lru_cache(maxsize=4)
def xa_coefficients(size_ratio: float = 1.0, terms: int = SERIES_TERMS) -> np.ndarray:
    """f_k(λ) of X^A, k = 0 … terms (JO Eq. 3.15)."""
    return _coefficients(_xa_table(terms), size_ratio, terms)


@functools.lru_cache(maxsize=4)
def ya_coefficients(size_ratio: float = 1.0, terms: int = SERIES_TERMS) -> np.ndarray:
    """f_k(λ) of Y^A, k = 0 … terms (defined as JO Eq. 3.15, from the Y^A recurrence)."""
    return _coefficients(_ya_table(terms), size_ratio, terms)


def _xa_singular(lam):
    return (2.0 * lam ** 2 / (1 + lam) ** 3,
            lam * (1 + 7 * lam + lam ** 2) / (5.0 * (1 + lam) ** 3),
            (1 + 18 * lam - 29 * lam ** 2 + 18 * lam ** 3 + lam ** 4) / (42.0 * (1 + lam) ** 3))


def _ya_singular(lam):
    return (0.0,
            4.0 * lam * (2 + lam + 2 * lam ** 2) / (15.0 * (1 + lam) ** 3),
            2.0 * (16 - 45 * lam + 58 * lam ** 2 - 45 * lam ** 3 + 16 * lam ** 4)
            / (375.0 * (1 + lam) ** 3))


def _uniform_sum(distance, f, g1, g2, g3, size_ratio, terms):
    """(F11, F12) of the uniformly valid form for coefficients f and singular parts g."""
    t = np.asarray(distance, dtype=float)
    if np.any(t <= 2.0):
        raise ValueError("the spheres overlap (t = 2r/(a1+a2) must exceed 2)")
    u = 2.0 / t
    arg = 1.0 - u * u
    f11 = np.zeros_like(t)
    f12 = np.zeros_like(t)
    for m in range(1, terms + 1):
        m1 = -2.0 if m == 2 else m - 2.0
        coefficient = 2.0 ** -m * (1.0 + size_ratio) ** -m * f[m] - g1 - 2.0 / m * g2
        coefficient += 4.0 / (m * m1) * g3
        if m % 2 == 0:
            f11 += coefficient * u ** m
        else:
            f12 += coefficient * u ** m
    f11 += g1 / arg - g2 * np.log(arg) - g3 * arg * np.log(arg) + f[0] - g1
    log_term = np.log((t + 2.0) / (t - 2.0))
    f12 += u * g1 / arg + g2 * log_term + g3 * arg * log_term + 4.0 * g3 / t
    return f11, -f12


def xa_functions(distance, size_ratio: float = 1.0, terms: int = SERIES_TERMS):
    """(X11A, X12A) at dimensionless centre distance t = 2r/(a₁ + a₂) > 2."""
    f = xa_coefficients(float(size_ratio), terms)
    return _uniform_sum(distance, f, *_xa_singular(size_ratio), size_ratio, terms)


def ya_functions(distance, size_ratio: float = 1.0, terms: int = SERIES_TERMS):
    """(Y11A, Y12A) at dimensionless centre distance t = 2r/(a₁ + a₂) > 2."""
    f = ya_coefficients(float(size_ratio), terms)
    return _uniform_sum(distance, f, *_ya_singular(size_ratio), size_ratio, terms)


def squeeze_resistance(gap, radius: float):
    """X11A − X12A for equal spheres of ``radius`` at surface gap ``gap`` [h]: the free-space
    squeeze force is 6πμ a U (X11A − X12A) for velocities ±U along the line of centres."""
    x11, x12 = xa_functions(2.0 + np.asarray(gap, dtype=float) / radius)
    return x11 - x12


def sliding_resistance(gap, radius: float):
    """Y11A − Y12A for equal spheres of ``radius`` at surface gap ``gap`` [h]: the free-space
    sliding force is 6πμ a U (Y11A − Y12A) for velocities ±U normal to the line of centres,
    the spheres held from turning."""
    y11, y12 = ya_functions(2.0 + np.asarray(gap, dtype=float) / radius)
    return y11 - y12
