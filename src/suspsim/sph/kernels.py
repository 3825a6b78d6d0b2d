"""Smoothing kernels W(r) and F(r) = −W'(r)/r, so that ∇W = −r F (SPEC §2.1).

Each kernel is a pair of small ``@njit`` scalar functions ``w(r, h)`` and ``f(r, h)``, written
branch-free (max(1 − q, 0) makes them exactly 0 beyond the support; this saved ≈ 0.9 of 5.3 ns
per pair, a mispredicted branch for every skin pair). Compiled pair loops select the kernel
with one integer code (:data:`LUCY_3D`, ...) through :func:`kernel_w` / :func:`kernel_f`.
These are inlined (``inline="always"``); a pass calls its loop once per code with the code as
a constant, so the dispatch folds away and the loop runs at the speed of a hard-coded kernel
(4.4 ns per pair; with the code a runtime value inside the loop 6.3 ns). Through the dispatch
functions **h is always the support radius** (SPEC convention); the quintic spline's own scalar
functions take its smoothing length h_sl = h/3.

Symbols:

====== ======================================================= ==========
symbol meaning                                                 unit
====== ======================================================= ==========
r      distance between two particles |r_pq|                   [length]
h      support radius (kernel is zero for r ≥ h)               [length]
h_sl   quintic-spline smoothing length, support 3 h_sl         [length]
q      r/h (Lucy) or r/h_sl (quintic)                          1
W      kernel value, ∫W dV = 1                                 [length]^−d
F      −(dW/dr)/r, ∇W = −r F, ∫F r r dV = I                    [length]^−(d+2)
d      dimension                                               1
====== ======================================================= ==========

Moments (checked in ``tests/unit/sph/test_kernels.py``): ∫W dV = 1, ∫F x_i x_j dV = δ_ij,
∫F x_i x_j x_k x_l / r² dV = (δ_ij δ_kl + δ_ik δ_jl + δ_il δ_jk)/(d + 2).

References: L. B. Lucy (1977), Astron. J. 82, 1013; Martys et al. (2010), Rheol. Acta 49, 1059,
appendix (seed 000/001); J. P. Morris, P. J. Fox, Y. Zhu (1997), J. Comput. Phys. 136, 214
(quintic spline).
"""
from __future__ import annotations

import math

from numba import njit

from suspsim.sph import JIT_OPTIONS

#: Integer kernel codes for compiled loops (kernel and dimension in one number).
LUCY_2D, LUCY_3D, QUINTIC_1D, QUINTIC_2D, QUINTIC_3D = range(5)

_CODES = {("lucy", 2): LUCY_2D, ("lucy", 3): LUCY_3D, ("quintic", 1): QUINTIC_1D,
          ("quintic", 2): QUINTIC_2D, ("quintic", 3): QUINTIC_3D}


def kernel_code(name: str, dimension: int) -> int:
    """Integer code of kernel ``name`` ('lucy' or 'quintic') in ``dimension`` (1, 2, 3)."""
    try:
        return _CODES[(name.lower(), int(dimension))]
    except KeyError:
        known = ", ".join(f"{n} {d}D" for n, d in _CODES)
        raise ValueError(f"no kernel {name!r} in {dimension}D; known: {known}") from None


# ---------------------------------------------------------------------------------------------
# Lucy kernel, support h. Branch-free: s = max(1 − r/h, 0) makes W = F = 0 exactly for r ≥ h
# and saves a mispredicted branch per skin pair (measured ≈ 0.9 ns of 5.3 ns per pair).

@njit(**JIT_OPTIONS)
def lucy_w_3d(r, h):
    """W(r) = 105/(16π h³) (1 + 3r/h)(1 − r/h)³ for r < h, else 0 [Lucy 1977; Martys 2010 App.]."""
    q = r / h
    s = max(1.0 - q, 0.0)
    return 105.0 / (16.0 * math.pi * h * h * h) * (1.0 + 3.0 * q) * s * s * s


@njit(**JIT_OPTIONS)
def lucy_f_3d(r, h):
    """F(r) = −W'/r = 315/(4π h⁵)(1 − r/h)² for r < h, else 0 [Martys 2010 App.]."""
    s = max(1.0 - r / h, 0.0)
    h2 = h * h
    return 315.0 / (4.0 * math.pi * h2 * h2 * h) * s * s


@njit(**JIT_OPTIONS)
def lucy_w_2d(r, h):
    """W(r) = 5/(π h²)(1 + 3r/h)(1 − r/h)³ for r < h, else 0 [SPEC §2.1, derived]."""
    q = r / h
    s = max(1.0 - q, 0.0)
    return 5.0 / (math.pi * h * h) * (1.0 + 3.0 * q) * s * s * s


@njit(**JIT_OPTIONS)
def lucy_f_2d(r, h):
    """F(r) = −W'/r = 60/(π h⁴)(1 − r/h)² for r < h, else 0 [SPEC §2.1, derived]."""
    s = max(1.0 - r / h, 0.0)
    h2 = h * h
    return 60.0 / (math.pi * h2 * h2) * s * s


# ---------------------------------------------------------------------------------------------
# Quintic spline, smoothing length h_sl, support 3 h_sl

@njit(**JIT_OPTIONS)
def quintic_shape(q):
    """(3 − q)⁵₊ − 6(2 − q)⁵₊ + 15(1 − q)⁵₊, the quintic spline's shape [Morris et al. 1997]."""
    a = max(3.0 - q, 0.0)
    b = max(2.0 - q, 0.0)
    c = max(1.0 - q, 0.0)
    a2 = a * a
    b2 = b * b
    c2 = c * c
    return a2 * a2 * a - 6.0 * b2 * b2 * b + 15.0 * c2 * c2 * c


@njit(**JIT_OPTIONS)
def quintic_shape_slope(q):
    """−(d shape/dq)/q = 5[(3 − q)⁴₊ − 6(2 − q)⁴₊ + 15(1 − q)⁴₊]/q, finite at q = 0.

    For q < 1 the bracket is 24q − 24q³ + 10q⁴ (expanded), whose ratio 24 − 24q² + 10q³ has no
    0/0 at r = 0 and no cancellation at small q; beyond, the bracket over q is evaluated as is.
    """
    a = max(3.0 - q, 0.0)
    b = max(2.0 - q, 0.0)
    a2 = a * a
    b2 = b * b
    if q < 1.0:
        return 5.0 * (24.0 - 24.0 * q * q + 10.0 * q * q * q)
    return 5.0 * (a2 * a2 - 6.0 * b2 * b2) / q


@njit(**JIT_OPTIONS)
def quintic_w_1d(r, h_sl):
    """W(r) = shape(r/h_sl)/(120 h_sl), support 3 h_sl [Morris et al. 1997, Eq. 26]."""
    return quintic_shape(r / h_sl) / (120.0 * h_sl)


@njit(**JIT_OPTIONS)
def quintic_f_1d(r, h_sl):
    """F(r) = −W'/r = slope(r/h_sl)/(120 h_sl³) [derived from Morris et al. 1997]."""
    return quintic_shape_slope(r / h_sl) / (120.0 * h_sl * h_sl * h_sl)


@njit(**JIT_OPTIONS)
def quintic_w_2d(r, h_sl):
    """W(r) = 7 shape(r/h_sl)/(478π h_sl²), support 3 h_sl [Morris et al. 1997]."""
    return 7.0 * quintic_shape(r / h_sl) / (478.0 * math.pi * h_sl * h_sl)


@njit(**JIT_OPTIONS)
def quintic_f_2d(r, h_sl):
    """F(r) = −W'/r = 7 slope(r/h_sl)/(478π h_sl⁴) [derived from Morris et al. 1997]."""
    h2 = h_sl * h_sl
    return 7.0 * quintic_shape_slope(r / h_sl) / (478.0 * math.pi * h2 * h2)


@njit(**JIT_OPTIONS)
def quintic_w_3d(r, h_sl):
    """W(r) = shape(r/h_sl)/(120π h_sl³), support 3 h_sl [Morris et al. 1997]."""
    return quintic_shape(r / h_sl) / (120.0 * math.pi * h_sl * h_sl * h_sl)


@njit(**JIT_OPTIONS)
def quintic_f_3d(r, h_sl):
    """F(r) = −W'/r = slope(r/h_sl)/(120π h_sl⁵) [derived from Morris et al. 1997]."""
    h2 = h_sl * h_sl
    return quintic_shape_slope(r / h_sl) / (120.0 * math.pi * h2 * h2 * h_sl)


# ---------------------------------------------------------------------------------------------
# Dispatch for compiled loops: h is the support radius for every kernel. With a constant code
# the tests fold away; the h-only factors are hoisted out of the pair loop ('arcp').

@njit(inline="always", **JIT_OPTIONS)
def kernel_w(kernel, r, h):
    """W(r) of kernel code ``kernel`` with support radius ``h`` (0 for r ≥ h)."""
    if kernel == LUCY_3D:
        return lucy_w_3d(r, h)
    if kernel == LUCY_2D:
        return lucy_w_2d(r, h)
    if kernel == QUINTIC_3D:
        return quintic_w_3d(r, h / 3.0)
    if kernel == QUINTIC_2D:
        return quintic_w_2d(r, h / 3.0)
    return quintic_w_1d(r, h / 3.0)


@njit(inline="always", **JIT_OPTIONS)
def kernel_f(kernel, r, h):
    """F(r) = −W'(r)/r of kernel code ``kernel`` with support radius ``h`` (0 for r ≥ h)."""
    if kernel == LUCY_3D:
        return lucy_f_3d(r, h)
    if kernel == LUCY_2D:
        return lucy_f_2d(r, h)
    if kernel == QUINTIC_3D:
        return quintic_f_3d(r, h / 3.0)
    if kernel == QUINTIC_2D:
        return quintic_f_2d(r, h / 3.0)
    return quintic_f_1d(r, h / 3.0)
