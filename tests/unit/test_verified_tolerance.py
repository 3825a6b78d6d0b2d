"""The verified tolerance picker (suspsim.convergence.picker.verified_pick): runs candidates
until a measured error meets the tolerance, recalibrating the model on each miss; and
``suspsim run --tolerance`` built on it (suspsim.convergence.tolerance.run_verified). The runs
here are stand-ins whose measured error is set (a known multiple of the model's, or a known
sequence), so what each attempt must be is known exactly."""
import json
import math

import numpy as np
import pytest
import yaml

from suspsim.cli import main
from suspsim.convergence import error_model as em
from suspsim.convergence import picker as pk
from suspsim.convergence import tolerance as tl
from suspsim.convergence.cases import get_case
from suspsim.errors import InputError, NumericalError
from suspsim.io.netcdf import read_run, write_run
from suspsim.reference.poiseuille import split_force_poiseuille_profile
from suspsim.run import RunInterrupted
from suspsim.scene import scene_from_dict

CASE = "couette_newtonian_3d"


@pytest.fixture(scope="module")
def rows():
    """(settings, drivers, uninflated model error, expected cost), cheapest first."""
    model = em.load_model()
    return sorted(((s, d, model.model_error(d), c)
                   for s, d, _, c in pk.evaluate(get_case(CASE), model)), key=lambda r: r[3])


def runner(factor, blow_up_above=math.inf, log=None):
    """A run whose measured bound is ``factor`` × the model error; inf (a blow-up) where
    C_Δx ≥ ``blow_up_above``; CPU time = the model's expected cost."""
    model = em.load_model()
    case = get_case(CASE)

    def run(settings):
        d = em.drivers(case.build(settings), settings)
        if log is not None:
            log.append(d)
        measured = (math.inf if d.courant >= blow_up_above
                    else factor * model.model_error(d))
        return measured, model.expected_cost(d), None
    return run


def cheapest(rows, limit, courant_cap=math.inf):
    return next(r for r in rows if r[2] <= limit and r[1].courant < courant_cap)


def test_a_model_that_over_predicts_takes_one_run(rows):
    attempts = pk.verified_pick(get_case(CASE), 0.05, runner(0.6))
    assert len(attempts) == 1
    assert attempts[0].settings == cheapest(rows, 0.05)[0]
    assert attempts[0].measured <= 0.05


@pytest.mark.parametrize("position", [0.2, 0.8])
def test_an_under_predicting_model_is_calibrated_by_its_first_miss(rows, position):
    """Measured = k E, with k between ε/E_first (the first run, E ≤ ε, misses) and ε/E_min
    (some candidate still meets): the first miss's ratio k then picks the cheapest candidate
    with k E ≤ ε, which meets, as a model inflated by k would have."""
    first = cheapest(rows, 0.05)
    smallest = min(r[2] for r in rows)
    factor = (0.05 / first[2]) ** (1 - position) * (0.05 / smallest) ** position
    attempts = pk.verified_pick(get_case(CASE), 0.05, runner(factor))
    assert attempts[0].settings == first[0]
    assert attempts[0].measured > 0.05
    assert len(attempts) == 2
    assert attempts[1].calibration == pytest.approx(factor)
    assert attempts[1].settings == cheapest(rows, 0.05 / factor)[0]
    assert attempts[1].measured <= 0.05


def test_a_blow_up_caps_the_time_step_of_the_next_attempt(rows):
    first = cheapest(rows, 0.05)
    seen = []
    attempts = pk.verified_pick(get_case(CASE), 0.05,
                                runner(0.6, blow_up_above=first[1].courant, log=seen))
    assert attempts[0].blew_up
    assert len(attempts) == 2
    assert seen[1].courant < first[1].courant
    assert attempts[1].settings == cheapest(rows, 0.05, first[1].courant)[0]
    assert attempts[1].record()["measured_error"] <= 0.05
    assert attempts[0].record()["measured_error"] is None


def test_every_miss_names_the_attempts():
    with pytest.raises(InputError, match="not met.*measured.*calibration"):
        pk.verified_pick(get_case(CASE), 0.05, runner(1e3))
    with pytest.raises(InputError, match="not met.*blew up"):
        pk.verified_pick(get_case(CASE), 0.05, runner(0.5, blow_up_above=0.0))
    with pytest.raises(InputError, match="relative error in"):
        pk.verified_pick(get_case(CASE), 1.5, runner(1.0))


def test_attempts_grow_dearer_and_stop_at_the_cap():
    with pytest.raises(InputError, match=r"not met \([^;()]* measured\); the smallest"):
        pk.verified_pick(get_case(CASE), 0.05, runner(1e3), max_attempts=1)
    model = em.load_model()
    costs = [model.expected_cost(a.drivers) for a in
             pk.verified_pick(get_case(CASE), 0.02, runner(2.0))]
    assert costs == sorted(costs)


COUETTE = {"dimension": 2, "box": [10, 10], "number_density": 6.25,
           "fluid": {"law": "papanastasiou", "params": {"mu_pl": 2.0, "mu_0": 198.0, "M": 100.0}},
           "flow": {"type": "couette", "shear_rate": 0.1}, "run": {"strain": 4}}


def couette_series(scene, unit_means, per_unit=20):
    """Run data of a Couette ``scene`` whose shear stress is μ(γ̇)γ̇ × ``unit_means[k]`` over
    strain unit k (counted from 0, the first one the transient)."""
    rate = scene.flow.shear_rate
    stress = float(scene.fluid.law.viscosity(rate)) * rate
    strain = np.arange(1, per_unit * len(unit_means) + 1) / per_unit
    unit = np.ceil(strain - 1e-9).astype(int) - 1
    return {"time": strain / rate, "strain": strain,
            "shear_stress": stress * np.asarray(unit_means)[unit],
            "viscosity": stress / rate * np.mean(unit_means[1:]), "viscosity_stderr": 0.0}


class FakeRun:
    """Stand-in for run_scene: writes a run file whose viscosity is the law's × (1 + e), e the
    next of ``errors`` (the last one repeats; None: a blow-up, "stop": a run interrupted by a
    signal); counts its calls."""

    def __init__(self, *errors):
        self.errors, self.calls = list(errors), []

    def __call__(self, scene, path, *, resume, threads, extra_attrs):
        self.calls.append((scene, resume))
        error = self.errors.pop(0) if len(self.errors) > 1 else self.errors[0]
        if error is None:
            raise NumericalError("density error 0.31 exceeds run.max_density_error")
        if error == "stop":
            raise RunInterrupted("stopped by signal 15", 15)
        write_run(path, couette_series(scene, np.full(4, 1 + error)),
                  {"wall_time_s": 1.0, "completed": 1, "reynolds_number": 0.1, "mach_number": 0.01,
                   "particle_steps_per_s": 1e6, **extra_attrs}, scene)
        return path


def test_run_verified_keeps_the_first_run_that_meets(tmp_path):
    out = tmp_path / "run.nc"
    fake = FakeRun(0.08, -0.01)
    attempts = tl.run_verified(scene_from_dict(COUETTE), 0.05, out, run=fake)
    assert [a.measured for a in attempts] == pytest.approx([0.08, 0.01])
    assert attempts[1].calibration == pytest.approx(0.08 / attempts[0].model_error)
    attrs = read_run(out).attrs
    assert attrs["tolerance_mode"] == "verified"
    assert attrs["measured_error"] == pytest.approx(0.01)
    assert attrs["expected_error"] == pytest.approx(attempts[1].calibration
                                                    * attempts[1].model_error)
    record = json.loads(attrs["tolerance_attempts"])
    assert [r["measured_error"] for r in record] == pytest.approx([0.08, 0.01])
    assert json.loads(attrs["tolerance_settings"])["side"] == attempts[1].settings["side"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]


def test_run_verified_resumes_without_rerunning_a_finished_attempt(tmp_path):
    out = tmp_path / "run.nc"
    with pytest.raises(RunInterrupted):
        tl.run_verified(scene_from_dict(COUETTE), 0.05, out, run=FakeRun(0.08, "stop"))
    assert not out.exists() and tl.attempt_path(out, 1).exists()
    again = FakeRun(0.0)
    attempts = tl.run_verified(scene_from_dict(COUETTE), 0.05, out, run=again, resume=True)
    assert [a.measured for a in attempts] == pytest.approx([0.08, 0.0])
    # attempt 1 read back, attempt 2 run once (no checkpoint of it to resume from)
    assert [resume for _, resume in again.calls] == [False]
    assert out.exists() and not tl.attempt_path(out, 1).exists()


def test_run_verified_blow_up_moves_to_a_smaller_step(tmp_path):
    out = tmp_path / "run.nc"
    attempts = tl.run_verified(scene_from_dict(COUETTE), 0.05, out, run=FakeRun(None, 0.0))
    assert attempts[0].blew_up and not attempts[1].blew_up
    assert attempts[1].drivers.courant < attempts[0].drivers.courant
    assert json.loads(read_run(out).attrs["tolerance_attempts"])[0]["measured_error"] is None


def test_measured_error_of_a_channel_is_the_profile_error(tmp_path):
    scene = scene_from_dict({"dimension": 2, "box": [8, 10], "number_density": 16.0,
                             "fluid": {"law": "newtonian", "params": {"mu": 20.0}},
                             "flow": {"type": "poiseuille", "body_force": 0.01},
                             "run": {"time": 10.0}})
    y = (np.arange(20) + 0.5) / 2
    exact = split_force_poiseuille_profile(scene.fluid.law, scene.density * 0.01, 10.0, y)
    path = tmp_path / "c.nc"
    write_run(path, {"y": y, "velocity_profile": 1.03 * exact}, {"wall_time_s": 1.0,
                                                                 "completed": 1}, scene)
    peak = abs(exact).max()
    rms = math.sqrt(((0.03 * exact) ** 2).mean())
    assert tl.measured_error(scene, read_run(path)) == pytest.approx(rms / peak)


def test_measured_error_of_a_couette_is_that_of_the_strain_unit_means(tmp_path):
    """As the cases measure it: unit means 1.01, 1.03, 1.02 after one unit of transient
    (which reads 1.5, discarded) → |1.02 − 1| + 2 × 0.01/√3."""
    scene = scene_from_dict({**COUETTE, "run": {"strain": 4, "transient": 1}})
    path = tmp_path / "c.nc"
    write_run(path, couette_series(scene, [1.5, 1.01, 1.03, 1.02]),
              {"wall_time_s": 1.0, "completed": 1}, scene)
    assert tl.measured_error(scene, read_run(path)) == pytest.approx(0.02 + 0.02 / math.sqrt(3))


def test_cli_tolerance_names_the_missed_attempts(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(tl, "run_scene", FakeRun(0.5))
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump(COUETTE))
    out = tmp_path / "run.nc"
    assert main(["-q", "run", str(scene), "--out", str(out), "--tolerance", "0.05"]) == 1
    assert "not met" in capsys.readouterr().err
    assert not out.exists()
    monkeypatch.setattr(tl, "run_scene", FakeRun(0.01))
    assert main(["-q", "run", str(scene), "--out", str(out), "--tolerance", "0.05"]) == 0
    assert "attempt 1" in capsys.readouterr().out
    assert read_run(out).attrs["measured_error"] == pytest.approx(0.01)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc", "scene.yaml"]
