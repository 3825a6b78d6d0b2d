"""Kernels: normalisation and moments by quadrature, support, F = −W'/r, continuity (SPEC §2.1)."""
import math

import numpy as np
import pytest
from scipy import integrate

from suspsim.sph import kernels as K

# (code, dimension, knots of the piecewise polynomial in units of the support radius h)
KERNELS = [
    (K.LUCY_2D, 2, (1.0,)),
    (K.LUCY_3D, 3, (1.0,)),
    (K.QUINTIC_1D, 1, (1 / 3, 2 / 3, 1.0)),
    (K.QUINTIC_2D, 2, (1 / 3, 2 / 3, 1.0)),
    (K.QUINTIC_3D, 3, (1 / 3, 2 / 3, 1.0)),
]
IDS = ["lucy-2d", "lucy-3d", "quintic-1d", "quintic-2d", "quintic-3d"]
H = 1.3  # support radius; not 1, so that wrong powers of h show


def radial(fun, knots, power):
    """∫_0^h fun(r) r^power dr, split at the kernel's knots (pieces are polynomials)."""
    edges = [0.0, *(k * H for k in knots)]
    return sum(integrate.quad(lambda r: fun(r) * r ** power, a, b, epsabs=1e-13, epsrel=1e-12)[0]
               for a, b in zip(edges[:-1], edges[1:]))


def sphere(g, dim):
    """∫ g(n) dΩ over the unit sphere S^(dim−1), by quadrature."""
    if dim == 1:
        return g(np.array([1.0])) + g(np.array([-1.0]))
    if dim == 2:
        return integrate.quad(lambda t: g(np.array([math.cos(t), math.sin(t)])), 0, 2 * math.pi,
                              epsabs=1e-13)[0]

    def integrand(p, t):
        st = math.sin(t)
        return g(np.array([st * math.cos(p), st * math.sin(p), math.cos(t)])) * st

    return integrate.dblquad(integrand, 0, math.pi, 0, 2 * math.pi, epsabs=1e-12)[0]


def w_of(code):
    return lambda r: K.kernel_w(code, r, H)


def f_of(code):
    return lambda r: K.kernel_f(code, r, H)


@pytest.mark.parametrize("code,dim,knots", KERNELS, ids=IDS)
def test_normalisation(code, dim, knots):
    total = radial(w_of(code), knots, dim - 1) * sphere(lambda n: 1.0, dim)
    assert total == pytest.approx(1.0, abs=1e-10)


@pytest.mark.parametrize("code,dim,knots", KERNELS, ids=IDS)
def test_second_moment_is_identity(code, dim, knots):
    # ∫F x_i x_j dV = ∫F r^(d+1) dr ∮ n_i n_j dΩ
    r_part = radial(f_of(code), knots, dim + 1)
    for i in range(dim):
        for j in range(dim):
            value = r_part * sphere(lambda n: n[i] * n[j], dim)
            assert value == pytest.approx(float(i == j), abs=1e-9)


@pytest.mark.parametrize("code,dim,knots", KERNELS, ids=IDS)
def test_fourth_moments(code, dim, knots):
    # ∫F x_i x_j x_k x_l / r² dV = (δ_ij δ_kl + δ_ik δ_jl + δ_il δ_jk)/(d + 2)
    r_part = radial(f_of(code), knots, dim + 1)
    assert r_part * sphere(lambda n: n[0] ** 4, dim) == pytest.approx(3 / (dim + 2), abs=1e-9)
    if dim > 1:
        value = r_part * sphere(lambda n: n[0] ** 2 * n[1] ** 2, dim)
        assert value == pytest.approx(1 / (dim + 2), abs=1e-9)
        assert r_part * sphere(lambda n: n[0] ** 3 * n[1], dim) == pytest.approx(0, abs=1e-9)


@pytest.mark.parametrize("code,dim,knots", KERNELS, ids=IDS)
def test_zero_at_and_beyond_support(code, dim, knots):
    for r in (H, H * (1 + 1e-12), 1.5 * H, 10 * H):
        assert K.kernel_w(code, r, H) == 0.0
        assert K.kernel_f(code, r, H) == 0.0
    assert K.kernel_w(code, 0.999 * H, H) > 0.0
    assert K.kernel_f(code, 0.999 * H, H) > 0.0


@pytest.mark.parametrize("code,dim,knots", KERNELS, ids=IDS)
def test_f_is_minus_dw_dr_over_r(code, dim, knots):
    step = 1e-6 * H
    for r in np.linspace(0.01, 0.99, 23) * H:
        slope = (K.kernel_w(code, r + step, H) - K.kernel_w(code, r - step, H)) / (2 * step)
        assert K.kernel_f(code, r, H) == pytest.approx(-slope / r, rel=1e-6, abs=1e-9)


@pytest.mark.parametrize("code,dim,knots", KERNELS, ids=IDS)
def test_continuous_at_knots_and_finite_at_zero(code, dim, knots):
    eps = 1e-9 * H
    for knot in knots:
        r = knot * H
        for fn in (K.kernel_w, K.kernel_f):
            assert fn(code, r - eps, H) == pytest.approx(fn(code, r + eps, H), abs=1e-6)
    assert np.isfinite(K.kernel_f(code, 0.0, H)) and K.kernel_f(code, 0.0, H) > 0
    assert K.kernel_f(code, 1e-12, H) == pytest.approx(K.kernel_f(code, 0.0, H), rel=1e-9)


def test_scalar_functions_match_dispatch_and_papers():
    r = 0.37 * H
    q = r / H
    assert K.lucy_w_3d(r, H) == pytest.approx(105 / (16 * math.pi * H**3) * (1 + 3 * q) * (1 - q) ** 3)
    assert K.lucy_f_3d(r, H) == pytest.approx(315 / (4 * math.pi * H**5) * (1 - q) ** 2)
    assert K.lucy_w_2d(r, H) == pytest.approx(5 / (math.pi * H**2) * (1 + 3 * q) * (1 - q) ** 3)
    assert K.lucy_f_2d(r, H) == pytest.approx(60 / (math.pi * H**4) * (1 - q) ** 2)
    h_sl = H / 3
    assert K.kernel_w(K.QUINTIC_3D, r, H) == K.quintic_w_3d(r, h_sl)
    assert K.kernel_f(K.QUINTIC_2D, r, H) == K.quintic_f_2d(r, h_sl)
    s = r / h_sl
    shape = (3 - s) ** 5 - 6 * (2 - s) ** 5 + (15 * (1 - s) ** 5 if s < 1 else 0.0)
    assert K.quintic_w_1d(r, h_sl) == pytest.approx(shape / (120 * h_sl))


def test_kernel_code():
    assert K.kernel_code("Lucy", 3) == K.LUCY_3D
    assert K.kernel_code("quintic", 1) == K.QUINTIC_1D
    with pytest.raises(ValueError, match="lucy 2D"):
        K.kernel_code("lucy", 1)
