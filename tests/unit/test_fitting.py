"""Flow-curve fitting: parameter recovery within standard errors on synthetic data, identifiability
of the regularisation M, information criteria, automatic law choice, errors, report and figure."""
import io
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.figure import Figure

from suspsim.errors import NumericalError
from suspsim.plotting.flow_curve import plot_fit
from suspsim.rheology import lsq, selection
from suspsim.rheology.fitting import (DEFAULT_CANDIDATES, FitResult, fit_flow_curve,
                                      validate_data)
from suspsim.rheology.guesses import initial_guess
from suspsim.rheology.laws import LAW_SPECS, make_law

N_POINTS = 40
NOISE = 0.02  # relative, multiplicative Gaussian
SEEDS = range(10)

# case: (law, true parameters, log10 of the rate range, is M identifiable from these rates?)
# Plateau cases include rates down to 1/(10 M), so the low-rate viscosity plateau is measured;
# "no plateau" cases start at 100/M, where the regularisation has no visible effect.
CASES = {
    "newtonian": ("newtonian", dict(mu=0.5), (-2, 3), None),
    "power_law": ("power_law", dict(K=3.0, n=0.45), (-2, 3), None),
    "cross": ("cross", dict(mu_0=10.0, mu_inf=0.1, lam=1.0, m=0.8), (-2, 3), None),
    "carreau_yasuda": ("carreau_yasuda", dict(mu_0=5.0, mu_inf=0.05, lam=2.0, a=2.0, n=0.4),
                       (-2, 3), None),
    "papanastasiou": ("papanastasiou", dict(mu_pl=0.1, mu_0=1000.0, M=100.0), (-3, 2), True),
    "herschel_bulkley": ("herschel_bulkley", dict(tau_y=10.0, K=2.0, n=0.5, M=100.0), (-3, 2),
                         True),
    "three_component": ("three_component", dict(tau_y=10.0, gdot_c=1.0, eta_bg=0.5, M=100.0),
                        (-3, 2), True),
    "papanastasiou no plateau": ("papanastasiou", dict(mu_pl=0.1, mu_0=1e5, M=1e4), (-2, 3),
                                 False),
    "herschel_bulkley no plateau": ("herschel_bulkley", dict(tau_y=10.0, K=2.0, n=0.5, M=1e4),
                                    (-2, 3), False),
    "three_component no plateau": ("three_component",
                                   dict(tau_y=10.0, gdot_c=1.0, eta_bg=0.5, M=1e4), (-2, 3), False),
}


def synthetic(law, params, decades, seed=None, noise=NOISE):
    """Flow curve of ``law`` at 40 log-spaced rates, with seeded multiplicative noise."""
    rate = np.logspace(*decades, N_POINTS)
    stress = make_law(law, params).stress(rate)
    if seed is not None:
        stress = stress * (1 + noise * np.random.default_rng(seed).standard_normal(rate.size))
    return rate, stress


@pytest.mark.parametrize("case", CASES)
def test_fit_recovers_parameters_within_two_standard_errors(case):
    law, true, decades, m_identifiable = CASES[case]
    hits, sq_residuals = {}, []
    for seed in SEEDS:
        rate, stress = synthetic(law, true, decades, seed)
        result = fit_flow_curve(rate, stress, law)
        assert result.law == law and result.n_points == N_POINTS
        if m_identifiable is not None:
            assert ("M" in result.fixed) is (not m_identifiable)
            assert result.notes[0].startswith("M fitted" if m_identifiable else "M fixed")
        if m_identifiable is False:
            assert result.params["M"] == pytest.approx(100.0 / rate.min())
            assert math.isnan(result.stderr["M"])
        fitted = [p for p in result.params if p not in result.fixed]
        assert set(fitted) == {p.name for p in LAW_SPECS[law].fitted_parameters} - set(result.fixed)
        for name in fitted:
            value, sigma = result.params[name], result.stderr[name]
            # Identified parameters: finite, non-zero and not absurdly large standard errors.
            assert math.isfinite(sigma) and 0.0 < sigma < abs(value), (seed, name, value, sigma)
            ok = abs(value - true[name]) <= 2.0 * sigma + 1e-12 * abs(true[name])
            hits[name] = hits.get(name, 0) + ok
        sq_residuals.append(result.rms_log_residual ** 2 * N_POINTS / (N_POINTS - len(fitted)))
    # With exact 95 % coverage of ±2σ, P(at most 7 hits of 10) ≈ 1 % per parameter.
    assert all(count >= 8 for count in hits.values()), hits
    # Pooled residual scatter is the noise: log10(1 + ε) has σ = 0.02/ln 10 (360 dof, ±3 σ).
    assert math.sqrt(np.mean(sq_residuals)) == pytest.approx(NOISE / math.log(10.0), rel=0.1)


@pytest.mark.parametrize("case", CASES)
def test_initial_guess_within_bounds_and_near_truth(case):
    law, true, decades, _ = CASES[case]
    rate, stress = synthetic(law, true, decades)
    guess = initial_guess(law, rate, stress)
    assert set(guess) == set(LAW_SPECS[law].parameter_names)
    for p in LAW_SPECS[law].parameters:
        assert p.lower <= guess[p.name] <= p.upper
    # The fit needs the right basin: the scale parameters start within a decade of the truth.
    for name in ("mu", "K", "mu_0", "tau_y"):
        if name in true:
            assert abs(math.log10(guess[name] / true[name])) < 1.0, (name, guess[name])


def test_guess_is_exact_for_power_law_and_newtonian_data():
    rate, stress = synthetic("power_law", dict(K=3.0, n=0.45), (-2, 3))
    guess = initial_guess("power_law", rate, stress)
    assert guess["K"] == pytest.approx(3.0) and guess["n"] == pytest.approx(0.45)
    rate, stress = synthetic("newtonian", dict(mu=0.5), (-2, 3))
    assert initial_guess("newtonian", rate, stress)["mu"] == pytest.approx(0.5)


def test_information_criteria_follow_their_definitions():
    rate, stress = synthetic("cross", CASES["cross"][1], (-2, 3), seed=3)
    for criterion in ("bic", "aic", "aicc"):
        r = fit_flow_curve(rate, stress, "cross", criterion=criterion)
        n, k = r.n_points, 4
        assert r.k == k and r.criterion == criterion
        assert r.rss == pytest.approx(n * r.rms_log_residual ** 2)
        assert r.aic == pytest.approx(n * math.log(r.rss / n) + 2 * k)
        assert r.bic == pytest.approx(n * math.log(r.rss / n) + k * math.log(n))
        assert r.aicc == pytest.approx(r.aic + 2 * k * (k + 1) / (n - k - 1))
        assert r.score() == getattr(r, criterion)


def test_unidentified_parameters_get_infinite_stderr_without_crashing():
    # Newtonian data: a Cross fit cannot locate λ or the exponent (μ_0 ≈ μ_inf).
    rate, stress = synthetic("newtonian", dict(mu=0.5), (-2, 3), seed=1)
    r = fit_flow_curve(rate, stress, "carreau_yasuda")
    assert r.rms_log_residual < 0.01
    assert any(not math.isfinite(s) or s > abs(r.params[p]) for p, s in r.stderr.items())


@pytest.mark.parametrize("law, params", [
    ("newtonian", dict(mu=0.5)),
    ("power_law", dict(K=3.0, n=0.45)),
    ("cross", dict(mu_0=10.0, mu_inf=0.1, lam=1.0, m=0.8)),
    ("herschel_bulkley", dict(tau_y=5.0, K=2.0, n=0.7, M=1e4)),
])
def test_auto_picks_the_generating_law_on_clean_data(law, params):
    rate, stress = synthetic(law, params, (-2, 3))
    r = fit_flow_curve(rate, stress, "auto")
    assert r.law == law, r.notes
    assert r.notes[0].startswith(f"auto: {law} chosen by BIC")
    assert [c["law"] for c in r.candidates] == list(DEFAULT_CANDIDATES)
    assert [c["law"] for c in r.candidates if c["won"]] == [law]
    if law == "power_law":
        # A yield-stress law on power-law data is degenerate and may not win.
        objection = {c["law"]: c["objection"] for c in r.candidates}["herschel_bulkley"]
        assert objection


@pytest.mark.slow
@pytest.mark.parametrize("law, params", [
    ("cross", dict(mu_0=10.0, mu_inf=0.1, lam=1.0, m=0.8)),
    ("herschel_bulkley", dict(tau_y=5.0, K=2.0, n=0.7, M=1e4)),
])
def test_auto_picks_the_generating_law_on_noisy_data(law, params):
    picks = [fit_flow_curve(*synthetic(law, params, (-2, 3), seed)).law for seed in range(5)]
    # Cross is nested in Carreau–Yasuda (a = 1 − n), which wins now and then by chance.
    assert picks.count(law) >= 4, picks


def _canned(law, params, data, bic):
    """A FitResult as if ``law`` had been fitted, with M fitted and ``gdot_min`` fixed."""
    fixed = {"gdot_min": params["gdot_min"]} if "gdot_min" in params else {}
    return FitResult(law=law, params=params, stderr={p: 0.1 for p in params},
                     rms_log_residual=0.01, n_points=data.n, shear_rate_range=(0.01, 1000.0),
                     source="", aic=bic, bic=bic, fixed=fixed, notes=())


def test_selection_rules_prefer_simpler_and_non_yield_laws_within_two(monkeypatch):
    rate = np.logspace(-2, 3, N_POINTS)
    hb = dict(tau_y=10.0, K=2.0, n=0.5, M=1e4, gdot_min=1e-6)
    data = validate_data(rate, make_law("herschel_bulkley", hb).stress(rate))
    canned = {"power_law": _canned("power_law", dict(K=1.0, n=0.5, gdot_min=1e-6), data, -100.0),
              "cross": _canned("cross", dict(mu_0=1.0, mu_inf=0.1, lam=1.0, m=0.5), data, -101.0),
              "herschel_bulkley": _canned("herschel_bulkley", hb, data, -101.5)}
    monkeypatch.setattr(selection, "fit_law", lambda name, *a, **k: canned[name])

    r = selection.select_law(data, ("power_law", "cross"))
    assert r.law == "power_law" and "fewer fitted parameters" in r.notes[0]
    r = selection.select_law(data, ("cross", "herschel_bulkley"))
    assert r.law == "cross" and "no yield stress" in r.notes[0]
    canned["herschel_bulkley"] = _canned("herschel_bulkley", hb, data, -104.0)
    r = selection.select_law(data, tuple(canned))
    assert r.law == "herschel_bulkley" and "next cross" in r.notes[0]


@pytest.mark.parametrize("law, params, objection", [
    # Plastic regime at the low-rate end, flow above it: a yield-stress fluid.
    ("herschel_bulkley", dict(tau_y=10.0, K=2.0, n=0.5, M=1e4, gdot_min=1e-6), None),
    # Measured plateau (1/M = 0.1 1/s inside the data), then a plastic regime and flow.
    ("herschel_bulkley", dict(tau_y=10.0, K=0.2, n=0.8, M=10.0, gdot_min=1e-6), None),
    # τ_y far below every measured stress: a power-law fluid.
    ("herschel_bulkley", dict(tau_y=1e-4, K=2.0, n=0.5, M=1e4, gdot_min=1e-6), "<<"),
    # μ_pl = 0: a viscosity plateau whose stress saturates at the highest rates, no flow after it
    # — a Cross fluid with m = 1 in disguise.
    ("papanastasiou", dict(mu_pl=1e-9, mu_0=1.0, M=0.01), "no plastic regime"),
])
def test_yield_stress_objection(law, params, objection):
    rate = np.logspace(-2, 3, N_POINTS)
    data = validate_data(rate, make_law(law, params).stress(rate))
    result = _canned(law, params, data, -100.0)
    found = selection.yield_stress_objection(result, data)
    assert found is None if objection is None else objection in found


@pytest.mark.parametrize("rate, stress, match", [
    ([1, 2, 3], [1, 2], "3 points but shear stress has 2"),
    ([1, 0, 3, 4, 5], [1, 2, 3, 4, 5], "shear rate must be finite and > 0"),
    ([1, 2, 3, 4, 5], [1, -2, 3, 4, 5], "shear stress must be finite and > 0"),
    ([1, 2, np.nan, 4, 5], [1, 2, 3, 4, 5], "shear rate"),
    ([1, 2, 3, 4, 5], [1, 2, np.inf, 4, 5], "shear stress"),
    ([[1, 2], [3, 4]], [[1, 2], [3, 4]], "one-dimensional"),
])
def test_bad_data_raise_value_error(rate, stress, match):
    with pytest.raises(ValueError, match=match):
        fit_flow_curve(rate, stress, "newtonian")


def test_too_few_points_unknown_law_criterion_or_candidate():
    rate, stress = synthetic("herschel_bulkley", CASES["herschel_bulkley"][1], (-2, 3))
    with pytest.raises(ValueError, match="needs at least 5 points; got 4"):
        fit_flow_curve(rate[:4], stress[:4], "herschel_bulkley")
    with pytest.raises(ValueError, match="too few points"):
        fit_flow_curve(rate[:1], stress[:1])
    with pytest.raises(ValueError, match="unknown law 'bingham'"):
        fit_flow_curve(rate, stress, "bingham")
    with pytest.raises(ValueError, match="unknown criterion"):
        fit_flow_curve(rate, stress, "newtonian", criterion="r2")
    with pytest.raises(ValueError, match="candidates"):
        fit_flow_curve(rate, stress, candidates=("newtonian", "bingham"))
    # Auto skips laws with too many parameters for the data and says so.
    r = fit_flow_curve(rate[:4], stress[:4])
    assert "carreau_yasuda skipped: 5 parameters need at least 6 points" in r.notes


@settings(max_examples=25, deadline=None)
@given(st.lists(st.floats(min_value=1e-3, max_value=1e3), min_size=5, max_size=12),
       st.integers(min_value=0, max_value=4), st.sampled_from([0.0, -1.0, math.nan, -math.inf]))
def test_any_non_positive_or_non_finite_value_is_rejected(values, where, bad):
    rate = np.array(values)
    stress = rate.copy()
    stress[where] = bad
    with pytest.raises(ValueError, match="shear stress must be finite and > 0"):
        fit_flow_curve(rate, stress, "newtonian")


def test_failure_of_every_start_raises_numerical_error_naming_the_law(monkeypatch):
    def broken(*args, **kwargs):
        raise ValueError("residuals are not finite in the initial point")

    monkeypatch.setattr(lsq, "least_squares", broken)
    rate, stress = synthetic("cross", CASES["cross"][1], (-2, 3))
    with pytest.raises(NumericalError, match="fitting cross failed from every start"):
        fit_flow_curve(rate, stress, "cross")
    with pytest.raises(NumericalError, match="every candidate law failed"):
        fit_flow_curve(rate, stress, candidates=("newtonian", "cross"))


def test_to_dict_is_strict_json_and_round_trips_the_law():
    rate, stress = synthetic("herschel_bulkley", dict(tau_y=5.0, K=2.0, n=0.7, M=1e4), (-2, 3),
                             seed=2)
    result = fit_flow_curve(rate, stress, source="synthetic.csv")
    d = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    assert set(d) == {"law", "params", "stderr", "rms_log_residual", "n_points",
                      "shear_rate_range", "source", "aic", "bic", "aicc", "fixed", "notes",
                      "candidates", "criterion", "residual_space"}
    assert d["law"] == "herschel_bulkley" and d["residual_space"] == "log10 stress"
    assert d["criterion"] == "bic" and d["source"] == "synthetic.csv"
    assert all(type(v) is float for v in d["params"].values())
    assert d["stderr"]["M"] is None and d["fixed"]["M"] == pytest.approx(100.0 / rate.min())
    assert sum(c["won"] for c in d["candidates"]) == 1
    law = make_law(d["law"], d["params"])
    np.testing.assert_allclose(law.viscosity(rate), result.constitutive_law().viscosity(rate),
                               rtol=1e-12)


def test_plot_fit_draws_two_log_log_panels():
    rate, stress = synthetic("cross", CASES["cross"][1], (-2, 3), seed=4)
    result = fit_flow_curve(rate, stress, "cross", source="cross.csv")
    fig = plot_fit(rate, stress, result)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    for ax in fig.axes:
        assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
        line_rate = ax.get_lines()[1].get_xdata()
        assert line_rate.min() < rate.min() and line_rate.max() > rate.max()
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend[0] == "cross.csv" and legend[1].startswith("cross: μ₀ = ") and "Pa s" in legend[1]
    assert "RMS" in fig.get_suptitle() and "cross.csv" in fig.get_suptitle()
    fig.savefig(io.BytesIO(), format="png")

    own = Figure()
    ax = own.subplots()
    assert plot_fit(rate, stress, result, ax=ax, label="mine") is own and len(own.axes) == 1
    assert ax.get_legend().get_texts()[0].get_text() == "mine"


def test_points_at_one_rate_that_disagree_are_flagged_not_dropped():
    rate = np.geomspace(0.1, 100.0, 12)
    stress = 2.0 * rate
    clean = fit_flow_curve(np.r_[rate, rate[3]], np.r_[stress, 1.3 * stress[3]], "newtonian")
    assert not [note for note in clean.notes if "copied" in note]
    bad = fit_flow_curve(np.r_[rate, rate[3]], np.r_[stress, 3.0 * stress[3]], "newtonian")
    flagged = [note for note in bad.notes if "copied" in note]
    assert len(flagged) == 1 and f"{rate[3]:.4g} 1/s" in flagged[0]
    assert bad.n_points == 13
