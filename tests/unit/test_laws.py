"""Constitutive laws (SPEC §1.1): limits, positivity, monotone stress, compiled form."""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from suspsim.rheology import laws
from suspsim.rheology.laws import (LAW_SPECS, carreau_yasuda, cross, herschel_bulkley, make_law,
                                   newtonian, papanastasiou, power_law, relaxation_factor,
                                   three_component, viscosity_kernel)

RATES = np.logspace(-6, 6, 121)

# (law, zero-rate viscosity, infinite-rate asymptote as a function of γ̇) from the closed forms.
LIMITS = [
    (newtonian(2.0), 2.0, lambda g: 2.0),
    (power_law(3.0, 0.4, gdot_min=1e-4), 3.0 * 1e-4 ** -0.6, lambda g: 3.0 * g ** -0.6),
    (cross(10.0, 0.01, 2.0, 0.8), 10.0, lambda g: 0.01 + 9.99 * (2 * g) ** -0.8),
    (carreau_yasuda(10.0, 0.01, 2.0, 2.0, 0.3), 10.0, lambda g: 0.01 + 9.99 * (2 * g) ** -0.7),
    (papanastasiou(1.0, 99.0, 100.0), 100.0, lambda g: 1.0 + 0.99 / g),
    (herschel_bulkley(5.0, 2.0, 0.5, 1e3, gdot_min=1e-5), 5e3 + 2.0 * 1e-5 ** -0.5,
     lambda g: 5.0 / g + 2.0 * g ** -0.5),
    (three_component(5.0, 0.5, 0.1, 1e3), 5e3 + 0.1, lambda g: 5.0 / g * (1 + (g / 0.5) ** 0.5) + 0.1),
]


@pytest.mark.parametrize("law, mu_zero, asymptote", LIMITS, ids=lambda x: getattr(x, "name", ""))
def test_zero_and_infinite_rate_limits(law, mu_zero, asymptote):
    assert law.viscosity(0.0) == pytest.approx(mu_zero, rel=1e-12)
    assert law.viscosity(1e-16) == pytest.approx(mu_zero, rel=1e-6)
    for g in (1e7, 1e9):
        assert law.viscosity(g) == pytest.approx(asymptote(g), rel=1e-6)


def test_limiting_viscosities_of_plateau_laws():
    assert cross(10.0, 0.01, 2.0, 0.8).viscosity(1e15) == pytest.approx(0.01, rel=1e-3)
    assert carreau_yasuda(10.0, 0.01, 2.0, 2.0, 0.3).viscosity(1e15) == pytest.approx(0.01, rel=1e-3)
    assert papanastasiou(1.0, 99.0, 100.0).viscosity(1e15) == pytest.approx(1.0, rel=1e-12)


@pytest.mark.parametrize("law", [case[0] for case in LIMITS], ids=lambda law: law.name)
def test_yield_stress_laws_stress_tends_to_yield_stress(law):
    if not law.spec.has_yield_stress:
        assert law.yield_stress == 0.0
        return
    # Regularised: below 1/M the stress falls linearly to zero.
    assert np.all(law.stress(np.array([1e-9, 1e-7])) < law.yield_stress * 1e-3)
    # As M → ∞ at fixed yield stress, τ(γ̇ → 0+) → τ_y (the ideal yield-stress fluid).
    stiff_params = {**law.params, "M": 1e9}
    if law.name == "papanastasiou":
        stiff_params["mu_0"] = law.yield_stress * 1e9
    stiff = make_law(law.name, stiff_params)
    assert stiff.yield_stress == pytest.approx(law.yield_stress)
    assert stiff.stress(1e-6) == pytest.approx(law.yield_stress, rel=2e-3)


def test_papanastasiou_yield_stress_and_bingham_regime():
    law = papanastasiou(mu_pl=1.0, mu_0=99.0, M=100.0)
    assert law.yield_stress == pytest.approx(0.99)
    # Well above 1/M the stress is Bingham: τ_y + μ_pl γ̇.
    g = np.array([1.0, 10.0])
    assert np.allclose(law.stress(g), 0.99 + g, rtol=1e-12, atol=1e-12)


def test_relaxation_factor_series_and_expm1_agree():
    for x in (0.0, 1e-12, 1e-9, 5e-9, 2e-8, 1e-6, 1e-3, 1.0, 50.0, 800.0):
        exact = 1.0 if x == 0 else float(-np.expm1(-x) / x)
        assert relaxation_factor(x) == pytest.approx(exact, rel=1e-14)


def _random_law(draw):
    name = draw(st.sampled_from(sorted(LAW_SPECS)))
    spec = LAW_SPECS[name]
    params = {}
    for p in spec.parameters:
        if not p.fitted:
            continue
        if p.log:
            params[p.name] = 10 ** draw(st.floats(-3, 3))
        else:
            params[p.name] = draw(st.floats(p.lower, p.upper))
    if name in ("cross", "carreau_yasuda"):
        params["mu_inf"] = min(params["mu_inf"], params["mu_0"])
    return make_law(name, params)


@settings(max_examples=300, deadline=None)
@given(st.data())
def test_viscosity_positive_finite_and_stress_monotone(data):
    law = _random_law(data.draw)
    mu = law.viscosity(RATES)
    assert np.all(np.isfinite(mu)) and np.all(mu > 0)
    tau = law.stress(RATES)
    assert np.all(np.diff(tau) >= -1e-12 * tau[1:])
    # Shear-thinning laws never increase their viscosity with rate. (The regularised
    # three-component law is not among them: its viscosity rises slightly near γ̇ ~ 1/M when
    # γ̇_c is comparable to 1/M; only its stress is monotone.)
    if law.name == "papanastasiou" or (law.name in ("power_law", "herschel_bulkley")
                                       and law.params["n"] <= 1):
        assert np.all(np.diff(mu) <= 1e-12 * mu[:-1])


@pytest.mark.parametrize("law", [case[0] for case in LIMITS], ids=lambda law: law.name)
def test_compiled_kernel_matches_vectorised_form(law):
    p = law.packed
    assert p.shape == (laws.MAX_PARAMETERS,)
    scalar = np.array([viscosity_kernel(law.code, p, g) for g in RATES])
    assert np.array_equal(scalar, law.viscosity(RATES))


def test_closed_forms():
    g = np.logspace(-3, 3, 13)
    assert np.allclose(cross(10, 0.01, 2, 0.8).viscosity(g), 0.01 + 9.99 / (1 + (2 * g) ** 0.8), rtol=1e-14)
    assert np.allclose(carreau_yasuda(10, 0.01, 2, 2, 0.3).viscosity(g),
                       0.01 + 9.99 * (1 + (2 * g) ** 2) ** (-0.7 / 2), rtol=1e-14)
    assert np.allclose(herschel_bulkley(5, 2, 0.5, 1e3).stress(g),
                       5 * (1 - np.exp(-1e3 * g)) + 2 * g ** 0.5, rtol=1e-13)
    assert np.allclose(three_component(5, 0.5, 0.1, 1e3).stress(g),
                       5 * (1 - np.exp(-1e3 * g)) * (1 + np.sqrt(g / 0.5)) + 0.1 * g, rtol=1e-13)


def test_is_newtonian_lets_scenes_skip_the_shear_rate_pass():
    assert newtonian(1.0).is_newtonian
    assert power_law(1.0, 1.0).is_newtonian
    assert not papanastasiou(1.0, 99.0, 100.0).is_newtonian


@pytest.mark.parametrize("name, params, message", [
    ("papanastasiu", {}, "unknown law"),
    ("newtonian", {}, "missing parameter mu"),
    ("newtonian", {"mu": 1.0, "nu": 2.0}, "unknown parameter"),
    ("power_law", {"K": 1.0, "n": -0.5}, "outside"),
    ("newtonian", {"mu": "thick"}, "not a number"),
    ("papanastasiou", {"mu_pl": 1.0, "mu_0": 1.0, "M": 0.0}, "M must be > 0"),
])
def test_invalid_parameters_are_named(name, params, message):
    with pytest.raises(ValueError, match=message):
        make_law(name, params)


def test_to_dict_round_trip():
    law = herschel_bulkley(5.0, 2.0, 0.5, 1e3)
    d = law.to_dict()
    again = make_law(d["law"], d["params"])
    assert again == law and math.isclose(again.viscosity(0.3), law.viscosity(0.3))
