"""Fitting the error model (suspsim.convergence.error_fit): coefficients and exponents of a
known model recovered, the cost law, the time-step caps and margin, the per-class and
cross-validated inflation."""
import math

import numpy as np
import pytest

from suspsim.convergence import error_fit as ef
from suspsim.convergence import error_model as em

EXPONENTS = {"p_2d": 2.0, "p_3d": 1.5, "r": 2.5, "s": 2.0, "u": 0.5}
TRUE = {"disc_stress_3d": 0.02, "disc_profile_3d": 0.03, "flow_poiseuille_3d": 0.4,
        "flow_couette_3d": 0.0, "wi": 0.5, "courant_3d": 0.01, "stat_3d": 0.002,
        "yield_poiseuille": 0.003}


def synthetic_points(rng):
    """Drivers over the grid's ranges (3D Couette and Poiseuille) and the exact model's bound."""
    points = []
    for _ in range(120):
        flow = rng.choice(["couette", "poiseuille"])
        d = em.Drivers(flow, 3, rng.uniform(1.5, 3.5), rng.uniform(2.0, 10.0),
                       10 ** rng.uniform(-3, -2), rng.uniform(0.05, 1.0),
                       float(rng.integers(2, 7)) if flow == "couette" else 0.0, 1000, 1000,
                       0.0 if flow == "couette" else rng.uniform(0.0, 5.0), 0 if flow == "couette"
                       else 2 * int(rng.integers(5, 20)))
        model = em.ErrorModel(TRUE, EXPONENTS, 1.0, {}, {})
        points.append((d, model.model_error(d)))
    return points


def fit_known_exponents(monkeypatch, records):
    """fit() on (drivers, bound) ``records`` at the exponents of TRUE (the tests are of the
    inflation and the time-step cap, not of the exponent search)."""
    fake_points = [(d, b, 1e-6 * d.work, "synthetic") for d, b in records]
    monkeypatch.setattr(ef, "training_points", lambda datasets: fake_points)
    known_grid(monkeypatch)
    return ef.fit([])


def known_grid(monkeypatch):
    """The exponent grid reduced to TRUE's exponents (the tests are of the inflation and the
    time-step margin, not of the exponent search)."""
    monkeypatch.setattr(ef, "EXPONENTS", {**{k: (v,) for k, v in EXPONENTS.items()},
                                          "t": (1.0,)})


def test_fit_recovers_known_coefficients():
    points = synthetic_points(np.random.default_rng(1))
    coef, loss = ef.fit_coefficients(points, EXPONENTS)
    assert loss < 1e-20
    for name, value in TRUE.items():
        assert coef[name] == pytest.approx(value, rel=1e-6, abs=1e-12), name


def test_exponent_search_finds_the_true_exponents(monkeypatch):
    monkeypatch.setattr(ef, "EXPONENTS", {"p_2d": (2.0,), "p_3d": (1.0, 1.5, 3.0),
                                          "r": (1.0, 2.5, 4.0), "s": (1.0, 2.0),
                                          "u": (0.5, 1.0)})
    coef, exponents, score = ef._fit_exponents(synthetic_points(np.random.default_rng(2)))
    assert exponents == EXPONENTS
    assert score == pytest.approx(0.0, abs=1e-9)


def test_cost_fit_recovers_power_law():
    rng = np.random.default_rng(3)
    points = []
    for _ in range(40):
        d = em.Drivers("couette", 3, rng.uniform(1.5, 3.5), 5.0, 1e-3, 0.1, 3.0,
                       int(rng.integers(300, 20000)), int(rng.integers(300, 40000)))
        points.append((d, 2e-7 * d.work ** 0.95))
    cost = ef.fit_cost(points)
    assert cost["alpha"] == pytest.approx(0.95, rel=1e-9)
    assert cost["k_3d"] == pytest.approx(2e-7, rel=1e-6)


def test_blow_up_caps_the_domain_even_where_the_finished_runs_fit_badly(monkeypatch):
    """A blow-up at a geometry that finished at a smaller step caps C_Δx, even when that
    geometry's finished runs lie above OUTLIER_RATIO × the first fit (the 2D channel at q = 2.4,
    W = 2.5 h blew up at C_Δx = 0.80 and ran at 0.25)."""
    points = synthetic_points(np.random.default_rng(5))
    d0 = next(d for d, _ in points if d.flow == "couette")
    model = em.ErrorModel(TRUE, EXPONENTS, 1.0, {}, {})
    poor = em.Drivers(**{**d0.__dict__, "courant": 0.1})
    blown = em.Drivers(**{**d0.__dict__, "courant": 0.8})
    records = points + [(poor, 10 * model.model_error(poor)), (blown, math.nan)]
    fitted = fit_known_exponents(monkeypatch, records)
    assert fitted.provenance["unsafe_courant"] == {"couette_newtonian_3d": pytest.approx(0.8)}


def test_timestep_outlier_caps_the_domain(monkeypatch):
    """A run far above the model whose geometry ran well at a smaller step caps C_Δx."""
    rng = np.random.default_rng(4)
    points = synthetic_points(rng)
    d0 = next(d for d, _ in points if d.flow == "couette")
    model = em.ErrorModel(TRUE, EXPONENTS, 1.0, {}, {})
    calm = em.Drivers(**{**d0.__dict__, "courant": 0.1})
    wild = em.Drivers(**{**d0.__dict__, "courant": 0.9})
    records = points + [(calm, model.model_error(calm)),
                        (wild, 20 * model.model_error(wild))]
    fitted = fit_known_exponents(monkeypatch, records)
    assert fitted.provenance["unsafe_courant"] == {"couette_newtonian_3d": pytest.approx(0.9)}
    assert fitted.bounds["courant_couette_newtonian_3d"][1] < 0.9
    assert fitted.inflation < 1.5


def test_one_flow_with_large_ratios_does_not_inflate_the_other(monkeypatch):
    """The channel's measurements scatter up to 5× the true model, the Couette's within ±10 %:
    the fit leans to the channel's upper envelope but its largest ratio stays above 1.5 (1.65),
    while the Couette class keeps its own (1.08); the inflated model bounds every training
    point by its own class's inflation."""
    rng = np.random.default_rng(6)
    records = [(d, bound * (rng.uniform(1.0, 5.0) if d.flow == "poiseuille"
                            else rng.uniform(0.9, 1.1)))
               for d, bound in synthetic_points(rng)]
    fitted = fit_known_exponents(monkeypatch, records)
    assert set(fitted.class_inflation) == {"couette_3d", "poiseuille_3d"}
    assert fitted.class_inflation["couette_3d"] < 1.2
    assert fitted.class_inflation["poiseuille_3d"] > 1.5
    assert fitted.inflation == max(fitted.class_inflation.values())
    for d, bound in records:
        assert fitted.expected_error(d) >= bound * (1 - 1e-9)
        assert fitted.inflation_of(d) == fitted.class_inflation[f"{d.flow}_3d"]


def test_held_out_case_sets_its_class_inflation(monkeypatch):
    """Four cases on the exact model, a fifth channel case measuring 2× it: left out, the
    other cases fit the exact coefficients, so the fifth case's held-out ratio is exactly 2
    and becomes the channel's inflation (above its in-sample maximum, which the fit leans
    towards); the Couette class, exact everywhere, stays near 1, and the in-sample
    inflation is kept as the floor."""
    known_grid(monkeypatch)
    rng = np.random.default_rng(7)
    records = []
    for i, (d, bound) in enumerate(synthetic_points(rng) + synthetic_points(rng)):
        case = f"case{i % 4}"
        if d.flow == "poiseuille" and i % 5 == 0:
            case, bound = "doubled", 2.0 * bound
        records.append((d, bound, 1e-6 * d.work, case))
    held = ef.held_out_ratios(records)
    top, top_case = max(held["poiseuille_3d"])
    assert top == pytest.approx(2.0, rel=1e-6)
    assert top_case == "doubled"
    assert max(r for r, _ in held["couette_3d"]) == pytest.approx(1.0, abs=0.1)
    fitted = ef.fit_points(records)
    in_sample = fitted.residuals["in_sample_class_inflation"]
    assert in_sample["poiseuille_3d"] < 2.0
    assert fitted.class_inflation["poiseuille_3d"] == pytest.approx(2.0, rel=1e-6)
    assert fitted.class_inflation["couette_3d"] == pytest.approx(
        max(in_sample["couette_3d"], max(r for r, _ in held["couette_3d"])))
    assert fitted.inflation == max(fitted.class_inflation.values())
    for d, bound, _, _ in records:
        assert fitted.expected_error(d) >= bound * (1 - 1e-9)


def test_cross_validated_inflation_is_floored_by_the_in_sample_one():
    held = {"couette_3d": [(1.3, "a"), (0.8, "b")], "poiseuille_3d": [(1.1, "c")]}
    out = ef.cross_validated_inflation({"couette_3d": 1.2, "poiseuille_3d": 1.5,
                                        "poiseuille_2d": 1.1}, held)
    assert out == {"couette_3d": 1.3, "poiseuille_3d": 1.5, "poiseuille_2d": 1.1}


def test_neighbouring_exponents_are_one_grid_step_each_side():
    grid = ef.neighbouring_exponents({"p_2d": 0.5, "p_3d": 2.0, "r": 4.0, "s": 4.0, "t": 2.0,
                                      "u": 0.75})
    assert grid["p_2d"] == (0.5, 1.0)
    assert grid["p_3d"] == (1.5, 2.0, 3.0)
    assert grid["r"] == (3.0, 4.0)
    assert grid["u"] == (0.5, 0.75, 1.0)


def test_stability_margin_from_a_blow_up_inside_the_calm_range():
    """The 2D channel's case: calm runs up to C_Δx = 0.70, a blow-up at 0.80 (above the calm
    range) and one at 0.67 (inside it, below the other failure): margin 0.67/0.70; a run that
    finished far off the model (not a blow-up) sets none."""
    inliers = [em.Drivers("poiseuille", 2, 3.0, 5.0, 1e-3, c, 0.0, 100, 100, rows=30)
               for c in (0.3, 0.5, 0.7)]
    key = "poiseuille_newtonian_2d"
    assert ef.stability_margin(inliers, [(key, 0.8, True)]) == 1.0
    assert ef.stability_margin(inliers, [(key, 0.8, True), (key, 0.67, True)]) == \
        pytest.approx(0.67 / 0.7)
    assert ef.stability_margin(inliers, [(key, 0.67, False)]) == 1.0
    assert ef.stability_margin(inliers, [("couette_newtonian_2d", 0.2, True)]) == 1.0


def test_blow_up_inside_the_calm_range_shortens_every_time_step_range(monkeypatch):
    """A blow-up at a geometry that finished at a smaller step, inside the calm range of the
    other runs of its class, caps the class below it and shortens every class's upper C_Δx by
    the ratio of the blow-up to the calm edge."""
    known_grid(monkeypatch)
    points = synthetic_points(np.random.default_rng(5))
    d0 = next(d for d, _ in points if d.flow == "couette")
    calm_edge = max(d.courant for d, _ in points if d.flow == "couette")
    model = em.ErrorModel(TRUE, EXPONENTS, 1.0, {}, {})
    small = em.Drivers(**{**d0.__dict__, "courant": 0.05})
    blown = em.Drivers(**{**d0.__dict__, "courant": 0.9 * calm_edge})
    records = [(d, b, 1e-6 * d.work, "a") for d, b in points] + [
        (small, model.model_error(small), 1e-6 * small.work, "b"),
        (blown, math.nan, math.nan, "b")]
    fitted = ef.fit_points(records, cross_validate=False)
    margin = fitted.provenance["courant_margin"]
    assert fitted.provenance["unsafe_courant"] == {"couette_newtonian_3d": 0.9 * calm_edge}
    calm_below = max(d.courant for d, _ in points
                     if d.flow == "couette" and d.courant < 0.9 * calm_edge)
    assert margin == pytest.approx(0.9 * calm_edge / calm_edge)
    assert fitted.bounds["courant_couette_newtonian_3d"][1] == pytest.approx(margin * calm_below)
    channel_edge = max(d.courant for d, _ in points if d.flow == "poiseuille")
    assert fitted.bounds["courant_poiseuille_newtonian_3d"][1] == pytest.approx(
        margin * channel_edge)
