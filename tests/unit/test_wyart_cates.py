"""Steady Wyart–Cates DST law against SPEC §1.3, its own derivatives and the numba kernels."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from suspsim.rheology.wyart_cates import (
    CST, DST, JAMMED_AT_HIGH_STRESS, WyartCates, wc_frictional_fraction, wc_viscosity)

SEED_002 = dict(eta_s=1e-3, phi_m=0.562, phi_0=0.693, sigma_star=0.005)


def seed_model(phi, beta=2.0):
    return WyartCates(phi=phi, beta=beta, **SEED_002)


def assert_printed(value, printed):
    """``value`` rounds to ``printed``: within half a unit of its last printed digit."""
    decimals = len(printed.split(".")[1])
    assert abs(value - float(printed)) <= 0.5 * 10.0 ** (-decimals) * (1 + 1e-9), (value, printed)


@pytest.mark.parametrize("phi, regime", [(0.48, CST), (0.50, DST), (0.54, DST)])
def test_spec_regimes(phi, regime):
    assert seed_model(phi).regime() == regime
    assert (seed_model(phi).turning_points() is None) == (regime == CST)
    assert seed_model(phi, beta=1.0).regime() == CST
    assert seed_model(phi, beta=1.0).turning_points() is None


def test_spec_viscosity_ratio():
    model = seed_model(0.54)
    assert model.viscosity_from_fraction(1.0) / model.eta_s == pytest.approx(652.6, rel=1e-3)
    assert model.viscosity_from_fraction(0.0) / model.eta_s == pytest.approx(20.5, rel=1e-3)
    assert model.viscosity_ratio() == pytest.approx(652.6 / 20.5, rel=2e-3)
    assert round(model.viscosity_ratio()) == 32


@pytest.mark.parametrize("phi, printed", [
    (0.50, ("0.00482", "0.252", "0.00936", "0.237")),
    (0.54, ("0.00380", "0.143", "0.0196", "0.0552")),
])
def test_spec_turning_points(phi, printed):
    points = seed_model(phi).turning_points()
    for value, text in zip(points, printed, strict=True):
        assert_printed(value, text)


@pytest.mark.parametrize("phi", [0.50, 0.54, 0.58])
def test_turning_points_are_stationary(phi):
    """Central differences of γ̇(σ) vanish at σ_β (and σ_α below φ_m) but not nearby."""
    model = seed_model(phi)
    points = model.turning_points()
    stresses = [points.sigma_beta] + ([points.sigma_alpha] if phi < model.phi_m else [])
    h = 1e-6
    for s in stresses:
        slope = (model.shear_rate(s * (1 + h)) - model.shear_rate(s * (1 - h))) / (2 * h * s)
        assert abs(slope * s / model.shear_rate(s)) < 1e-8
        assert abs(model.log_slope(1.2 * s)) > 1e-2
    assert points.gdot_max > points.gdot_min


@pytest.mark.parametrize("phi", [0.48, 0.50, 0.54, 0.58])
def test_log_slope_matches_finite_differences(phi):
    model = seed_model(phi)
    stress = np.geomspace(1e-4, 0.0125, 40)  # below σ_J = 0.013 Pa of φ = 0.58
    h = 1e-6
    log_rate = np.log(model.shear_rate(stress * (1 + h))) - np.log(model.shear_rate(stress * (1 - h)))
    numeric = log_rate / (math.log1p(h) - math.log1p(-h))
    np.testing.assert_allclose(model.log_slope(stress), numeric, rtol=1e-6, atol=1e-8)


def test_frictional_fraction_limits():
    model = seed_model(0.5)
    s_star = model.sigma_star
    assert model.frictional_fraction(0.0) == 0.0 and model.frictional_fraction(-1.0) == 0.0
    assert model.frictional_fraction(1e-3 * s_star) == 0.0  # exp(−10⁶)
    assert model.frictional_fraction(s_star) == pytest.approx(math.exp(-1.0), rel=1e-15)
    assert 1.0 - model.frictional_fraction(1e6 * s_star) == pytest.approx(1e-12, rel=1e-3)
    f = model.frictional_fraction(np.geomspace(0.1, 100.0, 200) * s_star)  # f[0] = e^(−100)
    assert np.all(np.diff(f) > 0) and f[0] < 1e-40 and f[-1] > 1 - 1e-3
    assert model.jamming_fraction(0.0) == model.phi_0 and model.jamming_fraction(1.0) == model.phi_m


def test_flow_curve_is_single_valued_in_stress():
    stress, rate = seed_model(0.54).flow_curve(1e-4, 1.0, 400)
    assert stress[0] == 1e-4 and stress[-1] == pytest.approx(1.0, rel=1e-15)
    assert np.all(np.diff(stress) > 0) and np.all(np.isfinite(rate)) and np.all(rate > 0)
    # σ(γ̇) is S-shaped: γ̇ = 0.1 1/s (between γ̇_min and γ̇_max) is reached at three stresses.
    assert np.count_nonzero(np.diff(np.sign(rate - 0.1))) == 3
    _, cst_rate = seed_model(0.48).flow_curve(1e-4, 1.0, 400)
    assert np.all(np.diff(cst_rate) > 0)


def test_jammed_at_high_stress():
    model = seed_model(0.58)
    sigma_j = model.jamming_stress()
    phi_j = model.jamming_fraction(model.frictional_fraction(sigma_j))
    assert phi_j == pytest.approx(0.58, rel=1e-14)
    assert model.regime() == JAMMED_AT_HIGH_STRESS and model.viscosity_ratio() == math.inf
    points = model.turning_points()
    assert points.sigma_alpha == sigma_j and points.gdot_min == 0.0
    assert points.sigma_beta < sigma_j and points.gdot_max > 0
    assert model.shear_rate(sigma_j * (1 + 1e-9)) == 0.0
    assert model.viscosity(10 * sigma_j) == math.inf
    assert model.shear_rate(sigma_j * (1 - 1e-3)) > 0
    assert np.isnan(model.log_slope(2 * sigma_j))
    at_phi_m = seed_model(0.562)
    assert at_phi_m.jamming_stress() == math.inf
    assert at_phi_m.turning_points().sigma_alpha == math.inf


@pytest.mark.parametrize("phi", [0.48, 0.50, 0.54, 0.58])
def test_numba_kernels_match_dataclass(phi):
    model = seed_model(phi)
    stress = np.concatenate([[-1.0, 0.0], np.geomspace(1e-5, 10.0, 300)])
    f = np.array([wc_frictional_fraction(s, model.sigma_star, model.beta) for s in stress])
    np.testing.assert_allclose(f, model.frictional_fraction(stress), rtol=1e-12, atol=0)
    eta = np.array([wc_viscosity(x, model.eta_s, phi, model.phi_m, model.phi_0) for x in f])
    np.testing.assert_allclose(eta, model.viscosity(stress), rtol=1e-12, atol=0)
    assert wc_viscosity(1.0, 1e-3, 0.6, 0.562, 0.693) == math.inf


@pytest.mark.parametrize("kwargs, match", [
    (dict(eta_s=0.0), "eta_s"), (dict(sigma_star=-1.0), "sigma_star"), (dict(beta=0.0), "beta"),
    (dict(phi=0.693), "phi < phi_0"), (dict(phi=0.0), "phi < phi_0"),
    (dict(phi_m=0.7), "phi_m < phi_0"), (dict(phi_0=1.2), "phi_0 <= 1"),
    (dict(sigma_star="abc"), "not a number"), (dict(eta_s=math.nan), "eta_s"),
])
def test_validation(kwargs, match):
    params = dict(SEED_002, phi=0.5) | kwargs
    with pytest.raises(ValueError, match=match):
        WyartCates(**params)


@st.composite
def models(draw):
    phi_m = draw(st.floats(0.40, 0.66))
    phi_0 = phi_m + draw(st.floats(0.01, 0.3))
    phi = draw(st.floats(0.2, 0.999)) * phi_0
    return WyartCates(eta_s=draw(st.floats(1e-4, 1.0)), phi=phi, phi_m=phi_m, phi_0=phi_0,
                      sigma_star=draw(st.floats(1e-3, 1e2)), beta=draw(st.floats(0.3, 5.0)))


@settings(max_examples=300, deadline=None)
@given(models())
def test_turning_points_bracket_negative_slope(model):
    points = model.turning_points()
    grid = model.sigma_star * np.geomspace(1e-3, 1e3, 1501)
    grid = grid[grid < model.jamming_stress()]
    slope = model.log_slope(grid)
    if points is None:
        assert np.all(slope > -1e-12)
        assert model.regime() in (CST, JAMMED_AT_HIGH_STRESS)
        return
    assert points.sigma_beta < points.sigma_alpha and points.gdot_max >= points.gdot_min
    inside = (grid > points.sigma_beta) & (grid < points.sigma_alpha)
    clear = np.abs(slope) > 1e-12
    np.testing.assert_array_equal((slope < 0)[clear], inside[clear])
    upper = min(points.sigma_alpha, model.jamming_stress())
    mid = math.sqrt(points.sigma_beta * upper) if upper < math.inf else 2 * points.sigma_beta
    assert model.shear_rate(mid) <= points.gdot_max
    assert model.log_slope(mid) < 0
    assert model.regime() == (DST if model.phi < model.phi_m else JAMMED_AT_HIGH_STRESS)


@pytest.mark.parametrize("phi", [0.50, 0.54])
def test_branch_stress_inverts_the_stable_branches(phi):
    """σ1 < σ_β and σ2 > σ_α solve γ̇(σ) = rate on the stable branches, for rates in
    (γ̇_min, γ̇_max); NaN outside each branch's range."""
    model = seed_model(phi)
    tp = model.turning_points()
    rates = np.linspace(tp.gdot_min, tp.gdot_max, 7)[1:-1]
    low, high = model.branch_stress(rates, "lower"), model.branch_stress(rates, "upper")
    assert np.all(low < tp.sigma_beta) and np.all(high > tp.sigma_alpha)
    np.testing.assert_allclose(model.shear_rate(low), rates, rtol=1e-12)
    np.testing.assert_allclose(model.shear_rate(high), rates, rtol=1e-12)
    assert np.all(model.log_slope(low) > 0) and np.all(model.log_slope(high) > 0)
    assert math.isnan(model.branch_stress(1.01 * tp.gdot_max, "lower"))
    assert math.isnan(model.branch_stress(0.99 * tp.gdot_min, "upper"))
    assert model.branch_stress(0.5 * tp.gdot_min, "lower") < tp.sigma_beta
    assert model.branch_stress(2.0 * tp.gdot_max, "upper") > tp.sigma_alpha
    with pytest.raises(ValueError):
        model.branch_stress(rates, "middle")


def test_branch_stress_without_turning_points_and_jammed():
    """CST: both branches are the single root; φ ≥ φ_m: no flowing upper branch."""
    cst = seed_model(0.48)
    rate = float(cst.shear_rate(3e-3))
    assert cst.branch_stress(rate, "lower") == pytest.approx(3e-3, rel=1e-12)
    assert cst.branch_stress(rate, "upper") == pytest.approx(3e-3, rel=1e-12)
    assert math.isnan(cst.lever_rule(3e-3, rate))
    jammed = seed_model(0.57)
    assert math.isnan(jammed.branch_stress(0.5 * jammed.turning_points().gdot_max, "upper"))


def test_lever_rule_conserves_the_mean_stress():
    """ψ1 σ1 + (1 − ψ1) σ2 = σ_in at the given rate; ψ1 → 1 at σ_in = σ1, 0 at σ2."""
    model = seed_model(0.54)
    tp = model.turning_points()
    sigma = np.linspace(tp.sigma_beta, tp.sigma_alpha, 6)[1:-1]
    rate = model.shear_rate(sigma)
    psi1 = model.lever_rule(sigma, rate)
    s1, s2 = model.branch_stress(rate, "lower"), model.branch_stress(rate, "upper")
    np.testing.assert_allclose(psi1 * s1 + (1 - psi1) * s2, sigma, rtol=1e-12)
    assert np.all((psi1 > 0) & (psi1 < 1))
    assert np.all(np.diff(psi1) < 0)  # more stress, more particles on the upper branch
    g = float(rate[1])
    assert model.lever_rule(model.branch_stress(g, "lower"), g) == pytest.approx(1.0)
    assert model.lever_rule(model.branch_stress(g, "upper"), g) == pytest.approx(0.0, abs=1e-12)
