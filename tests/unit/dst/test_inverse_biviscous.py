"""Inverse-biviscous flow curve and channel flow: closed forms against quadrature and limits."""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from suspsim.reference.inverse_biviscous import (InverseBiviscous, front_integral,
                                                 front_selected_rate)
from suspsim.rheology.wyart_cates import WyartCates

#: φ = 0.54 with seed 002's (φ_m, φ_0) and with its Fig. 8 pair, scaled η_s = σ* = 1.
SEED_LAW = WyartCates(1.0, 0.54, 0.562, 0.693, 1.0, 2.0)
FIG8_LAW = WyartCates(1.0, 0.54, 0.56, 0.64, 1.0, 2.0)
MODEL = InverseBiviscous(20.0, 650.0, 0.02)      # σ_1 = 0.4, σ_2 = 13
GAP = 1.0
#: F H from below σ_1 through the plateau to far above σ_2.
WALL_STRESSES = [0.1, 0.4, 1.0, 5.0, 13.0, 20.0, 200.0]
QUAD = {"epsabs": 0.0, "epsrel": 1e-13, "limit": 200}


def _quad(function, lower, upper, model):
    """∫ function over [lower, upper], split at the kinks σ_1, σ_2 of the flow curve."""
    edges = [lower] + [p for p in (model.lower_stress, model.upper_stress)
                       if lower < p < upper] + [upper]
    return sum(quad(function, a, b, **QUAD)[0] for a, b in zip(edges[:-1], edges[1:]))


def test_flow_curve_pieces_and_set_valued_inverse():
    m = MODEL
    assert (m.lower_stress, m.upper_stress) == pytest.approx((0.4, 13.0), rel=1e-15)
    sigma = np.array([0.0, 0.2, 0.4, 1.0, 13.0, 26.0])
    np.testing.assert_allclose(m.shear_rate(sigma), [0.0, 0.01, 0.02, 0.02, 0.02, 0.04],
                               rtol=1e-15)
    low, high = m.stress([0.01, 0.02, 0.04])
    np.testing.assert_allclose(low, [0.2, 0.4, 26.0], rtol=1e-15)
    np.testing.assert_allclose(high, [0.2, 13.0, 26.0], rtol=1e-15)
    # σ(γ̇(σ)) brackets σ everywhere: the inverse is the plateau interval at γ̇_c
    s = np.geomspace(1e-3, 100.0, 50)
    low, high = m.stress(m.shear_rate(s))
    assert np.all(low <= s * (1 + 1e-14)) and np.all(s <= high * (1 + 1e-14))
    with pytest.raises(ValueError):
        InverseBiviscous(650.0, 20.0, 0.02)
    with pytest.raises(ValueError):
        m.shear_rate(-1.0)


@pytest.mark.parametrize("wall_stress", WALL_STRESSES)
def test_closed_forms_match_quadrature(wall_stress):
    """G(s) = ∫γ̇ dσ, M(s) = ∫σγ̇ dσ, u(y) and ū against adaptive quadrature to 1e-10."""
    m = MODEL
    assert m.rate_integral(wall_stress) == pytest.approx(
        _quad(lambda s: float(m.shear_rate(s)), 0.0, wall_stress, m), rel=1e-12)
    assert m.stress_moment(wall_stress) == pytest.approx(
        _quad(lambda s: s * float(m.shear_rate(s)), 0.0, wall_stress, m), rel=1e-12)
    force = wall_stress / (GAP / 2)
    y = np.linspace(0.0, GAP, 23)
    # general channel integral u(y) = (1/F) ∫_{σ(y)}^{σ_w} γ̇ dσ, by quadrature
    numeric = [_quad(lambda s: float(m.shear_rate(s)), force * abs(GAP / 2 - yy), wall_stress,
                     m) / force for yy in y]
    np.testing.assert_allclose(m.channel_profile(force, GAP, y), numeric, rtol=1e-10,
                               atol=1e-14 * max(numeric))
    # the mean velocity two ways: ∫ u dy / d and M(F H)/(H F²)
    mean = quad(lambda yy: float(m.channel_profile(force, GAP, yy)), 0.0, GAP / 2,
                points=[GAP / 2 - m.upper_stress / force, GAP / 2 - m.lower_stress / force],
                **QUAD)[0] / (GAP / 2)
    assert m.channel_mean_velocity(force, GAP) == pytest.approx(mean, rel=1e-10)


def test_newtonian_limit():
    """η_1 = η_2 = η: any γ̇_c, u = F y (d − y)/(2η), ū = F H²/(3η)."""
    m = InverseBiviscous(3.0, 3.0, 0.7)
    force = 5.0
    y = np.linspace(0.0, GAP, 11)
    np.testing.assert_allclose(m.channel_profile(force, GAP, y), force * y * (GAP - y) / 6.0,
                               rtol=1e-13, atol=1e-16)
    assert m.channel_mean_velocity(force, GAP) == pytest.approx(force * 0.25 / 9.0, rel=1e-14)


def test_profile_is_continuous_at_the_breakpoints_and_the_plateau_has_slope_gdot_c():
    m = MODEL
    force = 40.0                                     # σ_w = 20 > σ_2: all three layers
    half = GAP / 2
    for sigma in (m.lower_stress, m.upper_stress):
        y0 = half - sigma / force
        eps = 1e-9
        below, at, above = m.channel_profile(force, GAP, [y0 - eps, y0, y0 + eps])
        assert abs(above - below) < 1e-8 * at
        assert (above - below) / (2 * eps) == pytest.approx(m.critical_rate, rel=1e-5)
        for s in (sigma * (1 - 1e-12), sigma * (1 + 1e-12)):
            assert float(m.rate_integral(s)) == pytest.approx(float(m.rate_integral(sigma)),
                                                              rel=1e-11)
            assert float(m.stress_moment(s)) == pytest.approx(float(m.stress_moment(sigma)),
                                                              rel=1e-11)
    # inside the plateau layer u is exactly linear with slope γ̇_c
    y = np.linspace(half - m.upper_stress / force, half - m.lower_stress / force, 9)[1:-1]
    slope = np.diff(m.channel_profile(force, GAP, y)) / np.diff(y)
    np.testing.assert_allclose(slope, m.critical_rate, rtol=1e-10)
    # and the layers outside have the Newtonian slopes σ/η
    y_wall = np.array([0.01, 0.02])
    slope = np.diff(m.channel_profile(force, GAP, y_wall))[0] / 0.01
    assert slope == pytest.approx(force * (half - 0.015) / m.high_viscosity, rel=1e-10)


def test_mean_velocity_rises_monotonically_with_force():
    """No flow reduction: dū/dF > 0 across σ_1 and σ_2 (module docstring)."""
    force = np.geomspace(0.01, 1e3, 2001)
    mean = MODEL.channel_mean_velocity(force, GAP)
    assert np.all(np.diff(mean) > 0)
    # the pieces' limits: Newtonian η_1 below σ_1, η_2 far above σ_2
    assert mean[0] == pytest.approx(0.01 * 0.25 / (3 * 20.0), rel=1e-14)
    big = 1e6
    assert float(MODEL.channel_mean_velocity(big, GAP)) == pytest.approx(
        big * 0.25 / (3 * 650.0), rel=1e-6)


@pytest.mark.parametrize("law", [SEED_LAW, FIG8_LAW])
def test_front_selected_rate_lies_between_the_turning_rates(law):
    """γ̇_min < γ̇_c < γ̇_max, the equal-area integral vanishes there and changes sign."""
    turning = law.turning_points()
    rate = front_selected_rate(law)
    assert turning.gdot_min < rate < turning.gdot_max
    assert abs(front_integral(law, rate)) < 1e-10
    assert front_integral(law, 0.5 * (turning.gdot_min + rate)) < 0.0
    assert front_integral(law, 0.5 * (turning.gdot_max + rate)) > 0.0
    model = InverseBiviscous.from_wyart_cates(law)
    assert model.low_viscosity == pytest.approx(float(law.viscosity_from_fraction(0.0)))
    assert model.high_viscosity == pytest.approx(float(law.viscosity_from_fraction(1.0)))
    assert model.critical_rate == rate


def test_front_integral_matches_its_definition_on_a_fine_grid():
    """I(γ̇) by quad against a 200 001-point trapezoid over [f_1, f_2]."""
    turning = SEED_LAW.turning_points()
    rate = 0.5 * (turning.gdot_min + turning.gdot_max)
    f1 = float(SEED_LAW.frictional_fraction(SEED_LAW.branch_stress(rate, "lower")))
    f2 = float(SEED_LAW.frictional_fraction(SEED_LAW.branch_stress(rate, "upper")))
    f = np.linspace(f1, f2, 200_001)
    reaction = SEED_LAW.frictional_fraction(SEED_LAW.viscosity_from_fraction(f) * rate) - f
    assert front_integral(SEED_LAW, rate) == pytest.approx(np.trapezoid(reaction, f),
                                                           rel=1e-8)


def test_front_selected_rate_needs_an_s_curve():
    with pytest.raises(ValueError, match="S-curve"):
        front_selected_rate(WyartCates(1.0, 0.48, 0.562, 0.693, 1.0, 2.0))
    with pytest.raises(ValueError, match="S-curve"):
        front_selected_rate(WyartCates(1.0, 0.57, 0.562, 0.693, 1.0, 2.0))
    assert math.isfinite(front_selected_rate(SEED_LAW))
