"""The error model, its fit and cost model, the tolerance picker (suspsim.convergence.error_model,
error_fit, picker) and the tolerance set-up of `suspsim run --tolerance`
(suspsim.convergence.tolerance)."""
import json
import math
from pathlib import Path

import numpy as np
import pytest

import suspsim.run as run_module
from suspsim.cli import main
from suspsim.convergence import error_fit as ef
from suspsim.convergence import error_model as em
from suspsim.convergence import picker as pk
from suspsim.convergence.cases import get_case
from suspsim.convergence.tolerance import choose, scene_case
from suspsim.errors import InputError
from suspsim.io.netcdf import read_run
from suspsim.scene import scene_from_dict
from test_run_loop import FakeSimulation

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
        points.append((d, sum(model.terms(d).values())))
    return points


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


def test_packaged_model_loads_with_provenance():
    model = em.load_model()
    assert model.inflation >= 1.0
    assert {"datasets", "date", "command", "training_cases"} <= set(model.provenance)
    # the blind held-out set (docs/figures/error_model/run_holdout_blind_3.sh); the earlier
    # ones (run_holdout_blind.sh, run_holdout_blind_2.sh) are training data
    held_out = {"couette_papanastasiou_bn3_2d", "poiseuille_bingham4_3d",
                "poiseuille_newtonian_re0.25_2d"}
    assert not held_out & set(model.provenance["training_cases"])
    assert {"couette_papanastasiou_bn9.9_2d", "poiseuille_bingham7_3d",
            "poiseuille_newtonian_re1_3d", "couette_papanastasiou_bn30_3d",
            "poiseuille_newtonian_re0.5_2d", "poiseuille_bingham2_3d"
            } <= set(model.provenance["training_cases"])
    # the Re = 0.5 blow-up caps the 2D channel's time step below it
    assert model.provenance["unsafe_courant"]["poiseuille_newtonian_2d"] == pytest.approx(
        0.666, abs=1e-3)
    assert model.bounds["courant_poiseuille_newtonian_2d"][1] < 0.666
    assert model.provenance["inflation_method"] == "leave-one-case-out"
    # one inflation per flow and dimension, the global one their largest
    assert set(model.class_inflation) == {"couette_2d", "couette_3d", "poiseuille_2d",
                                          "poiseuille_3d"}
    assert max(model.class_inflation.values()) == model.inflation


@pytest.mark.parametrize("case", ["couette_newtonian_3d", "poiseuille_bingham1_3d"])
def test_tighter_tolerance_is_never_cheaper(case):
    costs, errors = [], []
    for tol in (0.2, 0.1, 0.05, 0.03, 0.02):
        try:
            choice = pk.pick(get_case(case), tol)
        except InputError:
            break
        assert choice.expected_error <= pk.SAFETY * tol
        costs.append(choice.expected_cost)
        errors.append(choice.expected_error)
    assert len(costs) >= 2
    assert all(b >= a for a, b in zip(costs, costs[1:]))


def test_pick_is_the_cheapest_feasible_candidate():
    case = get_case("couette_newtonian_3d")
    choice = pk.pick(case, 0.05)
    rows = pk.evaluate(case, em.load_model())
    feasible = [cost for _, _, err, cost in rows if err <= pk.SAFETY * 0.05]
    assert choice.expected_cost == pytest.approx(min(feasible))


def test_unreachable_tolerance_raises_with_smallest_error():
    with pytest.raises(InputError, match="not reachable.*smallest expected error"):
        pk.pick(get_case("couette_newtonian_3d"), 1e-4)
    with pytest.raises(InputError, match="relative error in"):
        pk.pick(get_case("couette_newtonian_3d"), 0.0)


def test_drivers_of_a_case_match_its_scene():
    case = get_case("poiseuille_bingham1_3d")
    settings = case.settings()
    d = em.drivers(case.build(settings), settings)
    # Bn = 2ξ/(1 − ξ)² = 1 → ξ = 2 − √3; the sheared width W(1 − ξ)
    assert d.length == pytest.approx(5.0 * (math.sqrt(3) - 1), rel=1e-6)
    assert d.n_particles == 576 and d.resolution == pytest.approx(1.6)
    # the measured base run took 39999 steps (DOCS speed_error table)
    assert abs(d.n_steps - 40000) <= 2



def test_plug_time_step_term_only_in_yield_stress_channels():
    case = get_case("poiseuille_bingham5_3d")
    settings = case.settings({"dt_coefficient": 0.4, "width": 7.5})
    d = em.drivers(case.build(settings), settings)
    # Bn = 2ξ/(1 − ξ)² = 5 → 5ξ² − 12ξ + 5 = 0
    xi = (12.0 - math.sqrt(44.0)) / 10.0
    assert d.plug == pytest.approx(xi, rel=1e-6)
    exponents = {"p_3d": 1.0, "r": 1.0, "s": 2.0, "t": 1.0, "u": 1.0}
    plug_term = em.features(d, exponents)["courant_plug_3d"]
    assert plug_term == pytest.approx(d.courant ** 2 * xi / (1.0 - xi), rel=1e-6)
    newtonian = get_case("poiseuille_newtonian_3d")
    d_newtonian = em.drivers(newtonian.build(newtonian.settings()), newtonian.settings())
    assert d_newtonian.plug == 0.0
    assert "courant_plug_3d" not in em.features(d_newtonian, exponents)

COUETTE = {"dimension": 3, "box": [10, 10, 10], "number_density": 4.096,
           "fluid": {"law": "papanastasiou", "params": {"mu_pl": 10.0, "mu_0": 990.0, "M": 100.0}},
           "flow": {"type": "couette", "shear_rate": 0.1}, "run": {"strain": 12}}
CHANNEL = {"dimension": 3, "box": [3.75, 10, 3.75], "number_density": 4.096,
           "fluid": {"law": "newtonian", "params": {"mu": 5.12}},
           "flow": {"type": "poiseuille", "body_force": 0.01}, "run": {"time": 60.0}}


def test_couette_scene_keeps_its_physics():
    scene = scene_from_dict(COUETTE)
    chosen, choice, attrs = choose(scene, 0.05)
    law0, law1 = scene.fluid.law, chosen.fluid.law
    scale = chosen.density / scene.density
    assert attrs["tolerance_stress_scale"] == pytest.approx(scale)
    for rate in (0.01, 0.1, 1.0):   # same kinematic law: μ/ρ unchanged
        assert law1.viscosity(rate) / chosen.density == pytest.approx(
            law0.viscosity(rate) / scene.density)
    assert chosen.flow.shear_rate == scene.flow.shear_rate
    assert chosen.box[1] == choice.settings["side"]
    assert chosen.run.strain == 1.0 + choice.settings["units"]


def test_channel_scene_keeps_reynolds_and_time_scale():
    scene = scene_from_dict(CHANNEL)
    chosen, choice, _ = choose(scene, 0.05)
    s = scene.box[1] / chosen.box[1]           # old h per new h
    nu0 = scene.fluid.law.viscosity(1.0) / scene.density
    nu1 = chosen.fluid.law.viscosity(1.0) / chosen.density
    assert nu1 == pytest.approx(nu0 / s ** 2)   # ν in new h²/τ
    assert chosen.flow.body_force == pytest.approx(scene.flow.body_force / s)
    # t_ν = W²/ν and Re ∝ g W³/ν² unchanged
    w0, w1 = scene.box[1] / 2, chosen.box[1] / 2
    assert w1 ** 2 / nu1 == pytest.approx(w0 ** 2 / nu0)
    assert chosen.flow.body_force * w1 ** 3 / nu1 ** 2 == pytest.approx(
        scene.flow.body_force * w0 ** 3 / nu0 ** 2)
    assert chosen.run.time == scene.run.time


def test_case_scene_gives_the_case_choice():
    """The adapter on a case's own scene chooses the same drivers as the case."""
    case = get_case("couette_newtonian_3d")
    scene = case.build(case.settings())
    by_case = pk.pick(case, 0.05)
    by_scene = pk.pick(scene_case(scene), 0.05)
    for name in ("resolution", "length", "wi", "units", "n_particles", "n_steps"):
        assert getattr(by_scene.drivers, name) == pytest.approx(getattr(by_case.drivers, name))


def write(tmp_path, data, name="scene.yaml"):
    import yaml

    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def test_cli_tolerance_writes_choice_attributes(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(run_module, "_solver", lambda: FakeSimulation)
    out = tmp_path / "run.nc"
    assert main(["-q", "run", str(write(tmp_path, COUETTE)), "--out", str(out),
                 "--tolerance", "0.05"]) == 0
    attrs = read_run(out).attrs
    assert attrs["tolerance"] == 0.05
    assert 0 < attrs["expected_error"] <= pk.SAFETY * 0.05
    assert attrs["expected_cost_s"] > 0
    settings = json.loads(attrs["tolerance_settings"])
    assert {"resolution", "dt_coefficient", "wi_target", "side", "units"} <= set(settings)
    provenance = json.loads(attrs["error_model"])
    assert "training_cases" in provenance
    # the inflation applied is the 3D Couette class's, not the global one
    assert provenance["inflation"] == em.load_model().class_inflation["couette_3d"]
    assert "expected error" in capsys.readouterr().out


def test_cli_tolerance_rejects_suspensions(tmp_path, capsys):
    data = {**COUETTE, "inclusions": {"shape": "sphere", "phi": 0.1, "radius": 2.0}}
    out = tmp_path / "run.nc"
    assert main(["-q", "run", str(write(tmp_path, data)), "--out", str(out),
                 "--tolerance", "0.05"]) == 1
    assert "--tolerance supports SPH fluid scenes" in capsys.readouterr().err
    assert not out.exists()


def test_cli_tolerance_rejects_dst_scenes(tmp_path, capsys):
    scene = Path(__file__).parents[2] / "config" / "scenes" / "dst_stress_couette.yaml"
    out = tmp_path / "run.nc"
    assert main(["-q", "run", str(scene), "--out", str(out), "--tolerance", "0.05"]) == 1
    assert "--tolerance supports SPH fluid scenes" in capsys.readouterr().err
    assert not out.exists()


def test_cli_tolerance_unreachable_exits_1(tmp_path, capsys):
    out = tmp_path / "run.nc"
    assert main(["-q", "run", str(write(tmp_path, COUETTE)), "--out", str(out),
                 "--tolerance", "1e-5"]) == 1
    assert "not reachable" in capsys.readouterr().err
    assert not out.exists()


def test_study_tolerance_key_adds_the_picked_configuration():
    from suspsim.convergence.study import configurations

    case = get_case("couette_newtonian_3d")
    picked = pk.pick(case, 0.05).settings
    defaults = case.settings()
    out = configurations(case, {"tolerance": [0.05], "side": [10.0]})
    assert {k: v for k, v in picked.items() if v != defaults[k]} in out
    assert {"side": 10.0} in out and {} in out
    with pytest.raises(InputError, match="not reachable"):
        configurations(case, {"tolerance": [1e-5]})


def test_split_force_channel_needs_even_rows():
    """Odd row counts across L_y put a row on the force's sign change (module docstring)."""
    base = dict(flow="poiseuille", dimension=2, resolution=3.0, length=3.0, wi=1e-3,
                courant=0.1, units=0.0, n_particles=100, n_steps=100)
    assert em.regular(em.Drivers(**base, rows=30))
    assert not em.regular(em.Drivers(**base, rows=15))
    assert em.regular(em.Drivers(**{**base, "flow": "couette"}, rows=0))
    assert not em.regular(em.Drivers(**{**base, "resolution": 2.0}, rows=30))
    case = get_case("poiseuille_newtonian_2d")
    settings = case.settings({"resolution": 3.0, "width": 2.5})     # 15 rows across L_y = 5 h
    assert not em.regular(em.drivers(case.build(settings), settings))


def test_narrow_sheared_layer_is_outside_the_model():
    """ℓ = W (1 − ξ) below MIN_SHEARED_WIDTH: the Bn = 10 channel at W = 5 h (ℓ = 1.79 h)
    measured 31–35 %; at W = 7.5 h (ℓ = 2.69 h) 6.4–8.9 %."""
    case = get_case("poiseuille_bingham10_3d")
    narrow, wide = case.settings({"width": 5.0}), case.settings({"width": 7.5})
    d_narrow = em.drivers(case.build(narrow), narrow)
    d_wide = em.drivers(case.build(wide), wide)
    assert d_narrow.length < em.MIN_SHEARED_WIDTH < d_wide.length
    assert not em.regular(d_narrow) and em.regular(d_wide)


def test_yield_term_is_a_power_of_the_bingham_number():
    """y Bn^u, zero without a yield stress and absent from Couette."""
    base = dict(flow="poiseuille", dimension=3, resolution=1.6, length=4.0, wi=1e-3,
                courant=0.1, units=0.0, n_particles=100, n_steps=100, rows=24)
    exponents = {"p_3d": 1.0, "r": 2.0, "s": 1.0, "t": 1.0, "u": 0.5}
    features = em.features(em.Drivers(**base, bingham=9.0, plug=0.6), exponents)
    assert features["yield_poiseuille"] == pytest.approx(3.0)
    assert em.features(em.Drivers(**base), exponents)["yield_poiseuille"] == 0.0
    couette = em.Drivers(**{**base, "flow": "couette", "rows": 0, "units": 3.0})
    assert "yield_poiseuille" not in em.features(couette, exponents)


def test_bingham_number_bounded_by_the_trained_range():
    """Bn above the largest trained one is outside the domain (no extrapolation of the yield
    term); a smaller one, down to the Newtonian Bn = 0, is inside."""
    base = dict(flow="poiseuille", dimension=3, resolution=1.6, length=4.0, wi=1e-3,
                courant=0.1, units=0.0, n_particles=100, n_steps=100, rows=24)
    bounds = {"resolution_poiseuille_3d": [1.6, 2.4], "inverse_length_poiseuille": [0.1, 0.5],
              "wi": [1e-3, 1e-2], "courant_poiseuille_rate_dependent_3d": [0.1, 1.0],
              "courant_poiseuille_newtonian_3d": [0.1, 1.0], "bingham_poiseuille": [0.0, 5.0],
              "stepsupport_poiseuille_rate_dependent_3d": [0.01, 1.0],
              "stepsupport_poiseuille_newtonian_3d": [0.01, 1.0]}
    model = em.ErrorModel({}, {}, 1.0, bounds, {})
    assert model.in_domain(em.Drivers(**base, bingham=3.0, newtonian=False, plug=0.45))
    assert model.in_domain(em.Drivers(**base))
    assert not model.in_domain(em.Drivers(**base, bingham=7.0, newtonian=False, plug=0.59))
    packaged = em.load_model()
    assert packaged.bounds["bingham_poiseuille"][1] == pytest.approx(10.0)


def test_step_on_the_support_radius_bounds_the_domain():
    """A channel step inside the measured C_Δx range but past the measured δt μ_max/(ρh²) =
    C_Δx/q² is outside: the 3D Newtonian channel blew up at δt ν/h² = 0.1 (q = 1.6, C_Δx = 0.26)
    and ran at 0.05 with q = 2.4 (C_Δx = 0.29)."""
    base = dict(flow="poiseuille", dimension=3, length=4.0, wi=1e-3, units=0.0, n_particles=100,
                n_steps=100, rows=24)
    bounds = {"resolution_poiseuille_3d": [1.6, 2.4], "inverse_length_poiseuille": [0.1, 0.5],
              "wi": [1e-3, 1e-2], "courant_poiseuille_newtonian_3d": [0.1, 0.3],
              "stepsupport_poiseuille_newtonian_3d": [0.04, 0.068],
              "bingham_poiseuille": [0.0, 5.0]}
    model = em.ErrorModel({}, {}, 1.0, bounds, {})
    assert model.in_domain(em.Drivers(**base, resolution=2.4, courant=0.29))
    assert model.in_domain(em.Drivers(**base, resolution=1.6, courant=0.17))
    assert not model.in_domain(em.Drivers(**base, resolution=1.6, courant=0.256))
    packaged = em.load_model()
    assert packaged.bounds["stepsupport_poiseuille_newtonian_3d"][1] < 0.1


def test_flow_term_per_dimension_falls_back_to_the_largest_measured():
    model = em.ErrorModel({"flow_poiseuille_3d": 0.3, "flow_poiseuille_2d": 0.1,
                           "flow_couette_3d": 0.02}, {}, 1.0, {}, {})
    assert model._coefficient("flow_poiseuille_2d") == 0.1
    assert model._coefficient("flow_couette_2d") == 0.02
    with pytest.raises(InputError, match="no measured coefficient"):
        em.ErrorModel({"flow_couette_3d": 0.02}, {}, 1.0, {}, {})._coefficient(
            "flow_poiseuille_2d")


def test_blow_up_caps_the_domain_even_where_the_finished_runs_fit_badly(monkeypatch):
    """A blow-up at a geometry that finished at a smaller step caps C_Δx, even when that
    geometry's finished runs lie above OUTLIER_RATIO × the first fit (the 2D channel at q = 2.4,
    W = 2.5 h blew up at C_Δx = 0.80 and ran at 0.25)."""
    points = synthetic_points(np.random.default_rng(5))
    d0 = next(d for d, _ in points if d.flow == "couette")
    model = em.ErrorModel(TRUE, EXPONENTS, 1.0, {}, {})
    poor = em.Drivers(**{**d0.__dict__, "courant": 0.1})
    blown = em.Drivers(**{**d0.__dict__, "courant": 0.8})
    records = points + [(poor, 10 * sum(model.terms(poor).values())), (blown, math.nan)]
    fake_points = [(d, b, 1e-6 * d.work, "synthetic") for d, b in records]
    monkeypatch.setattr(ef, "training_points", lambda datasets: fake_points)
    # the exponents are known: the test is of the time-step cap, not of the exponent search
    monkeypatch.setattr(ef, "EXPONENTS", {**{k: (v,) for k, v in EXPONENTS.items()},
                                          "t": (1.0,)})
    fitted = ef.fit([])
    assert fitted.provenance["unsafe_courant"] == {"couette_newtonian_3d": pytest.approx(0.8)}


def test_timestep_outlier_caps_the_domain(monkeypatch):
    """A run far above the model whose geometry ran well at a smaller step caps C_Δx."""
    rng = np.random.default_rng(4)
    points = synthetic_points(rng)
    d0 = next(d for d, _ in points if d.flow == "couette")
    model = em.ErrorModel(TRUE, EXPONENTS, 1.0, {}, {})
    calm = em.Drivers(**{**d0.__dict__, "courant": 0.1})
    wild = em.Drivers(**{**d0.__dict__, "courant": 0.9})
    records = points + [(calm, sum(model.terms(calm).values())),
                        (wild, 20 * sum(model.terms(wild).values()))]

    fake_points = [(d, b, 1e-6 * d.work, "synthetic") for d, b in records]
    monkeypatch.setattr(ef, "training_points", lambda datasets: fake_points)
    # the exponents are known: the test is of the time-step cap, not of the exponent search
    monkeypatch.setattr(ef, "EXPONENTS", {**{k: (v,) for k, v in EXPONENTS.items()},
                                          "t": (1.0,)})
    fitted = ef.fit([])
    assert fitted.provenance["unsafe_courant"] == {"couette_newtonian_3d": pytest.approx(0.9)}
    assert fitted.bounds["courant_couette_newtonian_3d"][1] < 0.9
    assert fitted.inflation < 1.5


def test_rate_dependent_law_gets_its_own_time_step_range():
    """The example Papanastasiou Couette (viscous-limited, Re_p 0.007): C_ν = 0.2 measured 21 %
    off, 0.1 within 0.7 %; the picker must stay in the rate-dependent law's measured range."""
    chosen, choice, _ = choose(scene_from_dict(COUETTE), 0.05)
    model = em.load_model()
    assert choice.drivers.courant <= model.bounds["courant_couette_rate_dependent_3d"][1]
    assert choice.settings["dt_coefficient"] <= 0.1


def fit_known_exponents(monkeypatch, records):
    """fit() on (drivers, bound) ``records`` at the exponents of TRUE (the tests are of the
    inflation, not of the exponent search)."""
    fake_points = [(d, b, 1e-6 * d.work, "synthetic") for d, b in records]
    monkeypatch.setattr(ef, "training_points", lambda datasets: fake_points)
    monkeypatch.setattr(ef, "EXPONENTS", {**{k: (v,) for k, v in EXPONENTS.items()},
                                          "t": (1.0,)})
    return ef.fit([])


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


def test_class_without_training_points_takes_the_global_inflation():
    model = em.ErrorModel(TRUE, EXPONENTS, 2.5, {}, {}, class_inflation={"couette_3d": 1.2})
    couette = em.Drivers("couette", 3, 1.6, 5.0, 1e-3, 0.1, 3.0, 100, 100)
    channel = em.Drivers("poiseuille", 3, 1.6, 5.0, 1e-3, 0.1, 0.0, 100, 100, rows=24)
    assert model.expected_error(couette) == pytest.approx(1.2 * sum(
        model.terms(couette).values()))
    assert model.expected_error(channel) == pytest.approx(2.5 * sum(
        model.terms(channel).values()))


def test_model_json_of_format_1_is_read_with_the_global_inflation(tmp_path):
    """A model written before per-class inflation (no ``format``, no ``class_inflation``)
    inflates every class by its ``inflation``; an unknown format is a clear error."""
    data = em.load_model().to_json()
    assert data["format"] == em.FORMAT
    old = {k: v for k, v in data.items() if k not in ("format", "class_inflation")}
    model = em.ErrorModel.from_json(old)
    d = em.Drivers("poiseuille", 2, 3.0, 5.0, 1e-3, 0.1, 0.0, 100, 100, rows=30)
    assert model.inflation_of(d) == data["inflation"]
    path = tmp_path / "model.json"
    path.write_text(json.dumps({**data, "format": 99}))
    with pytest.raises(InputError, match="format 99"):
        em.load_model.__wrapped__(str(path))


def known_grid(monkeypatch):
    """The exponent grid reduced to TRUE's exponents (the tests are of the inflation and the
    time-step margin, not of the exponent search)."""
    monkeypatch.setattr(ef, "EXPONENTS", {**{k: (v,) for k, v in EXPONENTS.items()},
                                          "t": (1.0,)})


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
        (small, sum(model.terms(small).values()), 1e-6 * small.work, "b"),
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
