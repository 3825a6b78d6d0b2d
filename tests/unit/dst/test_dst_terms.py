"""Terms of the 2D DST solver (SPEC §5.1, §1.3): EOS, pair terms, shear rate, Wyart–Cates."""
import math

import pytest

from suspsim.dst.terms import (continuity_pair, laplacian_pair, microstructure_rate,
                               morris_viscous_pair, pressure_pair, shear_rate_2d,
                               suspension_viscosity, tait_density, tait_pressure)
from suspsim.rheology.wyart_cates import wc_frictional_fraction, wc_viscosity
from suspsim.sph.kernels import quintic_f_2d


@pytest.mark.parametrize("rho", [950.0, 1000.0, 1012.5])
def test_tait_round_trip_and_background(rho):
    p = tait_pressure(rho, 1000.0, 0.1, 0.3)
    assert tait_density(p, 1000.0, 0.1, 0.3) == pytest.approx(rho, rel=1e-12)
    assert tait_pressure(1000.0, 1000.0, 0.1, 0.3) == pytest.approx(0.3, abs=1e-15)
    # dp/dρ = c² at ρ0
    eps = 1e-6
    slope = (tait_pressure(1000.0 + eps, 1000.0, 0.1, 0.0)
             - tait_pressure(1000.0 - eps, 1000.0, 0.1, 0.0)) / (2 * eps)
    assert slope == pytest.approx(0.01, rel=1e-6)


def test_tait_density_clamped_below_floor():
    assert tait_density(-1e9, 1000.0, 0.1, 0.0) == 0.0


def test_pair_terms_antisymmetric_and_zero_beyond_support():
    h_sl = 0.1
    x, y = 0.07, -0.05
    r2 = x * x + y * y
    F = quintic_f_2d(math.sqrt(r2), h_sl)
    vx, vy = 0.3, -0.2
    m = 2.0
    # momentum of the pair: m a_i + m a_j = 0 for pressure and viscous terms
    s_ij = pressure_pair(m, 1.0, 1.0, 2.0, 1.1, F)
    s_ji = pressure_pair(m, 2.0, 1.1, 1.0, 1.0, F)
    assert s_ij * x + s_ji * (-x) == pytest.approx(0.0, abs=1e-14)
    v_ij = morris_viscous_pair(m, 1.0, 3.0, 1.0, 1.1, r2, F, h_sl)
    v_ji = morris_viscous_pair(m, 3.0, 1.0, 1.1, 1.0, r2, F, h_sl)
    assert v_ij * vx + v_ji * (-vx) == pytest.approx(0.0, abs=1e-14)
    assert v_ij < 0.0  # drags i towards j's velocity
    # continuity: symmetric in (i, j), and the Laplacian conserves f for equal volumes
    assert continuity_pair(m, vx, vy, x, y, F) == pytest.approx(
        continuity_pair(m, -vx, -vy, -x, -y, F))
    assert laplacian_pair(0.5, 1.0, 3.0, r2, F, h_sl) == pytest.approx(
        -laplacian_pair(0.5, 3.0, 1.0, r2, F, h_sl))
    F_out = quintic_f_2d(3.0 * h_sl, h_sl)
    assert F_out == 0.0
    assert morris_viscous_pair(m, 1.0, 1.0, 1.0, 1.0, 0.09, F_out, h_sl) == 0.0


def test_shear_rate_is_sqrt_2DD():
    assert shear_rate_2d(0.0, 2.5, 0.0, 0.0) == pytest.approx(2.5)     # simple shear
    assert shear_rate_2d(0.0, 1.0, -1.0, 0.0) == pytest.approx(0.0)    # rigid rotation
    assert shear_rate_2d(0.5, 0.0, 0.0, -0.5) == pytest.approx(1.0)    # planar extension 2ε


def test_viscosity_matches_rheology_and_flags_jamming():
    for f in (0.0, 0.3, 1.0):
        assert suspension_viscosity(f, 1e-3, 0.54, 0.562, 0.693) == pytest.approx(
            wc_viscosity(f, 1e-3, 0.54, 0.562, 0.693), rel=1e-14)
    # frictional packing at φ > φ_m jams once f is large
    assert suspension_viscosity(1.0, 1e-3, 0.58, 0.562, 0.693) == -1.0
    assert suspension_viscosity(0.0, 1e-3, 0.58, 0.562, 0.693) > 0.0
    # seed 002: frictional/frictionless ratio ≈ 32 at φ = 0.54
    ratio = (suspension_viscosity(1.0, 1.0, 0.54, 0.562, 0.693)
             / suspension_viscosity(0.0, 1.0, 0.54, 0.562, 0.693))
    assert ratio == pytest.approx(652.6 / 20.5, rel=2e-3)


def test_microstructure_rate_vanishes_at_steady_fraction():
    eta, gdot = 0.05, 0.2
    f_hat = wc_frictional_fraction(eta * gdot, 0.005, 2.0)
    assert microstructure_rate(f_hat, gdot, eta, 1.0, 0.005, 2.0, 0.0, 7.0) == 0.0
    rate = microstructure_rate(0.1, gdot, eta, 3.0, 0.005, 2.0, 1e-5, 2.0)
    assert rate == pytest.approx(3.0 * gdot * (f_hat - 0.1) + 2e-5, rel=1e-12)
