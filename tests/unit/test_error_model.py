"""The error model and its domain, the tolerance picker (suspsim.convergence.error_model, picker)
and the tolerance set-up of `suspsim run --tolerance` (suspsim.convergence.tolerance); its fit:
``test_error_fit``."""
import json
import math
from pathlib import Path

import pytest

import suspsim.run as run_module
from suspsim.cli import main
from suspsim.convergence import error_model as em
from suspsim.convergence import picker as pk
from suspsim.convergence.cases import get_case
from suspsim.convergence.tolerance import choose, scene_case
from suspsim.errors import InputError
from suspsim.io.netcdf import read_run
from suspsim.scene import scene_from_dict
from test_error_fit import EXPONENTS, TRUE
from test_run_loop import FakeSimulation

def test_packaged_model_loads_with_provenance():
    model = em.load_model()
    assert model.inflation >= 1.0
    assert {"datasets", "date", "command", "training_cases"} <= set(model.provenance)
    # the blind held-out sets (docs/figures/error_model/run_holdout_blind_3.sh, _4, _5, _6);
    # the earlier ones (run_holdout_blind.sh, run_holdout_blind_2.sh) are training data
    held_out = {"couette_papanastasiou_bn3_2d", "poiseuille_bingham4_3d",
                "poiseuille_newtonian_re0.25_2d", "couette_papanastasiou_bn20_2d",
                "poiseuille_bingham6_3d", "poiseuille_newtonian_re0.25_3d",
                "couette_papanastasiou_bn6_2d", "poiseuille_bingham8_3d",
                "poiseuille_newtonian_re1_2d", "couette_papanastasiou_bn45_2d",
                "poiseuille_bingham2.5_3d", "poiseuille_bingham9_3d",
                "poiseuille_newtonian_re0.5_3d"}
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
                 "--tolerance", "0.05", "--no-verify"]) == 0
    attrs = read_run(out).attrs
    assert attrs["tolerance"] == 0.05
    assert attrs["tolerance_mode"] == "bound"
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


def test_rate_dependent_law_gets_its_own_time_step_range():
    """The example Papanastasiou Couette (viscous-limited, Re_p 0.007): C_ν = 0.2 measured 21 %
    off, 0.1 within 0.7 %; the picker must stay in the rate-dependent law's measured range."""
    chosen, choice, _ = choose(scene_from_dict(COUETTE), 0.05)
    model = em.load_model()
    assert choice.drivers.courant <= model.bounds["courant_couette_rate_dependent_3d"][1]
    assert choice.settings["dt_coefficient"] <= 0.1


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
