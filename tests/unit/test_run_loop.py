"""The run loop with a fake solver: output, averages, resume after a signal, blow-up, progress."""
import dataclasses
import io
import math
import os
import signal

import numpy as np
import pytest

import suspsim.run as run_module
from suspsim.errors import InputError, NumericalError
from suspsim.io.checkpoint import load_checkpoint
from suspsim.io.netcdf import read_run
from suspsim.progress import NullProgress, ProgressReporter, format_duration
from suspsim.run import RunInterrupted, checkpoint_path, run_scene
from suspsim.scene import scene_from_dict

MU, RATE = 2.0, 0.5
COUETTE = dict(dimension=2, box=[4, 4], number_density=4,
               fluid={"law": "newtonian", "params": {"mu": MU}},
               flow={"type": "couette", "shear_rate": RATE},
               run={"strain": 20, "transient": 4, "output_interval": 0.05}, seed=3)
POISEUILLE = dict(COUETTE, flow={"type": "poiseuille", "body_force": 1e-3},
                  run={"time": 20, "output_interval": 0.1})
COMPARED_ATTRIBUTES = ("n_particles", "n_steps", "reynolds_number", "mach_number", "dt",
                       "sound_speed", "completed")


class FakeSimulation:
    """Cheap deterministic stand-in for :class:`suspsim.sph.simulation.Simulation`.

    σ_xy(t) = μγ̇(1 − e^(−t/τ_r)) + x_n, with x an AR(1) noise per step (coefficient ``a``,
    stationary standard deviation ``noise``) driven by a seeded sequence, so any split of
    ``advance`` calls gives the same bits. Options (class attributes, set in subclasses):
    ``blowup_step`` makes health fail from that step on; ``signal_at`` = (step, signum) sends
    that signal to this process when the step is reached.
    """

    dt, sound_speed, relaxation_time = 0.01, 10.0, 0.5
    a, noise = math.exp(-1 / 50), 0.1
    blowup_step = None
    signal_at = None

    def __init__(self, scene, *, threads=None):
        self.scene, self.threads = scene, threads
        self.n_particles = math.prod(scene.lattice_counts)
        self.step_count, self.time, self.x = 0, 0.0, 0.0
        n = round(scene.total_time / self.dt) + 1
        self._kicks = np.random.default_rng(scene.seed).standard_normal(n)

    @property
    def strain(self):
        return self.scene.flow.shear_rate * self.time if self.scene.flow.type == "couette" else 0.0

    def advance(self, n_steps):
        scale = self.noise * math.sqrt(1 - self.a**2)
        for _ in range(n_steps):
            self.x = self.a * self.x + scale * self._kicks[self.step_count]
            self.step_count += 1
            self.time = self.step_count * self.dt
            if self.signal_at and self.step_count == self.signal_at[0]:
                os.kill(os.getpid(), self.signal_at[1])

    def _broken(self):
        return self.blowup_step is not None and self.step_count >= self.blowup_step

    def health(self):
        if self._broken():
            return False, ("density error 0.31 exceeds run.max_density_error 0.05; lower run.dt "
                           "or raise run.sound_speed")
        return True, "ok"

    def sample(self):
        relaxed = 1 - math.exp(-self.time / self.relaxation_time)
        return {"shear_stress": MU * RATE * relaxed + self.x, "pressure": 1.0 + 0.1 * self.x,
                "kinetic_energy": 0.5 * self.x**2,
                "density_error": 0.31 if self._broken() else 0.001,
                "mach": 0.01 + 0.01 * abs(self.x)}

    def profiles(self, bins):
        height = self.scene.box[1]
        y = (np.arange(bins) + 0.5) * height / bins
        if self.scene.flow.type == "couette":
            velocity = RATE * (y - height / 2) + self.x
        else:
            velocity = 0.3 * np.sin(2 * np.pi * y / height) + 0.01 * self.x
        return {"y": y, "velocity_profile": velocity, "viscosity_profile": np.full(bins, MU),
                "shear_rate_profile": RATE + 0.1 * self.x + 0 * y,
                "density_profile": np.full(bins, self.scene.density)}

    def state(self):
        return {"clock": {"step_count": self.step_count, "time": self.time}, "x": self.x,
                "kicks": self._kicks}

    @classmethod
    def from_state(cls, scene, state, *, threads=None):
        sim = cls(scene, threads=threads)
        sim.step_count, sim.time = state["clock"]["step_count"], state["clock"]["time"]
        sim.x, sim._kicks = state["x"], state["kicks"]
        return sim


def fake(**options):
    """A FakeSimulation subclass with ``options`` as class attributes."""
    return type("ConfiguredFake", (FakeSimulation,), options)


class Ticker:
    """A clock that advances ``tick`` seconds per reading (the loop then paces one step)."""

    def __init__(self, tick=1.0):
        self.now, self.tick = 0.0, tick

    def __call__(self):
        self.now += self.tick
        return self.now


def scene(base=COUETTE, **run):
    built = scene_from_dict(base)
    return dataclasses.replace(built, run=dataclasses.replace(built.run, **run)) if run else built


def run(tmp_path, name="run.nc", the_scene=None, factory=FakeSimulation, **kwargs):
    kwargs.setdefault("progress", NullProgress())
    return run_scene(the_scene or scene(), tmp_path / name, simulation_factory=factory, **kwargs)


def assert_same_results(a, b):
    assert set(a.variables) == set(b.variables)
    for name in a.variables:
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
        assert a[name].attrs == b[name].attrs
    for name in COMPARED_ATTRIBUTES:
        assert a.attrs[name] == b.attrs[name], name


def test_output_holds_series_profiles_averages_and_attributes(tmp_path):
    out = run(tmp_path)
    result = read_run(out)
    for name in ("shear_stress", "pressure", "kinetic_energy", "density_error", "mach", "strain"):
        assert result[name].dims == ("time",) and result[name].attrs["units"] == "1"
    for name in ("velocity_profile", "viscosity_profile", "shear_rate_profile", "density_profile"):
        assert result[name].dims == ("y",) and result[name].shape == (4,)
    assert result["shear_stress"].attrs["simulation_units"] == "m tau-2"
    assert result["viscosity"].attrs["simulation_units"] == "m tau-1"
    assert result["velocity_profile"].attrs["simulation_units"] == "h tau-1"
    assert result.sizes["time"] == 400 and result["time"].values[-1] == pytest.approx(40.0)
    assert result["strain"].values[-1] == pytest.approx(20.0)
    attrs = result.attrs
    assert (attrs["n_particles"], attrs["n_steps"], attrs["completed"]) == (64, 4000, 1)
    assert (attrs["dt"], attrs["sound_speed"]) == (0.01, 10.0)
    assert attrs["wall_time_s"] > 0 and attrs["particle_steps_per_s"] > 0
    # Couette: U = γ̇ L_y/2 = 1, L = L_y/2 = 2, ρ = 4, μ = 2 → Re = 4.
    assert attrs["reynolds_number"] == pytest.approx(4.0)
    assert attrs["mach_number"] == pytest.approx(result["mach"].values.max())
    np.testing.assert_allclose(result["viscosity_profile"], MU)
    np.testing.assert_allclose(result["density_profile"], 4.0)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc"]


def test_viscosity_and_its_error_for_the_fake(tmp_path):
    result = read_run(run(tmp_path))
    strain, stress = result["strain"].values, result["shear_stress"].values
    steady = strain > 4 + 1e-9
    assert steady.sum() == 320
    viscosity, stderr = float(result["viscosity"]), float(result["viscosity_stderr"])
    # 16 strain units in 8 blocks of 2, every steady sample used.
    assert viscosity == pytest.approx(stress[steady].mean() / RATE, rel=1e-12)
    # The fake's noise sampled every 10 steps is AR(1) with φ = a^10: known error of the mean.
    phi = FakeSimulation.a**10
    expected = FakeSimulation.noise * math.sqrt((1 + phi) / (1 - phi) / 320) / RATE
    assert 0.5 * expected < stderr < 1.6 * expected
    assert abs(viscosity - MU) < 4 * expected


def test_a_window_under_8_strain_units_falls_back_to_blocking(tmp_path, caplog):
    caplog.set_level("WARNING", logger="suspsim.analysis.steady")
    short = scene(dict(COUETTE, run={"strain": 10, "transient": 4, "output_interval": 0.05}))
    result = read_run(run(tmp_path, the_scene=short))
    assert "fewer than 8 strain units" in caplog.text and "run.transient" in caplog.text
    stress = result["shear_stress"].values[result["strain"].values > 4 + 1e-9]
    assert float(result["viscosity"]) == pytest.approx(stress.mean() / RATE, rel=1e-12)
    assert 0 < float(result["viscosity_stderr"]) < 0.2


def test_poiseuille_has_no_single_viscosity(tmp_path):
    result = read_run(run(tmp_path, the_scene=scene(POISEUILLE)))
    assert "viscosity" not in result and "viscosity_stderr" not in result and "strain" not in result
    # L = L_y/4 = 1, U = largest |v_x| of the steady profile, μ = 2, ρ = 4.
    speed = np.abs(result["velocity_profile"].values).max()
    assert result.attrs["reynolds_number"] == pytest.approx(4 * speed * 1 / MU)
    assert result.sizes["time"] == 200


@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_resume_after_a_signal_gives_the_same_output(tmp_path, signum, code):
    reference = read_run(run(tmp_path, "reference.nc"))
    handlers = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    out, ckpt = tmp_path / "run.nc", checkpoint_path(tmp_path / "run.nc")
    with pytest.raises(RunInterrupted) as caught:
        # One step per advance: the stop falls between two samples (1234 is not a multiple of 10).
        run(tmp_path, factory=fake(signal_at=(1234, signum)), clock=Ticker(1.0))
    message = str(caught.value)
    assert caught.value.exit_code == code
    assert "interrupted at strain 6.17 (step 1234)" in message and "--resume" in message
    assert str(ckpt) in message and ckpt.exists() and not out.exists()
    assert (signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)) == handlers
    state, meta = load_checkpoint(ckpt, scene())
    assert state["sim/clock/step_count"] == 1234 and meta["step"] == 1234
    assert run(tmp_path, resume=True) == out
    assert not ckpt.exists()
    assert_same_results(read_run(out), reference)


def test_periodic_checkpoints_leave_the_result_unchanged(tmp_path, monkeypatch):
    reference = read_run(run(tmp_path, "reference.nc"))
    saved = []
    original = run_module.save_checkpoint
    monkeypatch.setattr(run_module, "save_checkpoint",
                        lambda *a, **k: (saved.append(a[0]), original(*a, **k)))
    out = run(tmp_path, the_scene=scene(checkpoint_interval_s=0.05), clock=Ticker(0.01))
    assert len(saved) > 10 and not checkpoint_path(out).exists()
    assert_same_results(read_run(out), reference)


def test_blow_up_stops_with_the_message_and_keeps_the_last_good_checkpoint(tmp_path):
    out, ckpt = tmp_path / "run.nc", checkpoint_path(tmp_path / "run.nc")
    with pytest.raises(NumericalError) as caught:
        run(tmp_path, the_scene=scene(checkpoint_interval_s=0.5), factory=fake(blowup_step=2505),
            clock=Ticker(1e-3))
    message = str(caught.value)
    assert "run.max_density_error" in message and "[strain 12.55]" in message
    assert f"last good checkpoint is kept at {ckpt}" in message
    assert not out.exists() and ckpt.exists()
    state, _ = load_checkpoint(ckpt, scene())
    assert state["sim/clock/step_count"] < 2505
    assert sorted(p.name for p in tmp_path.iterdir()) == [ckpt.name]


def test_blow_up_before_any_checkpoint_says_so(tmp_path):
    with pytest.raises(NumericalError, match="no checkpoint had been written yet"):
        run(tmp_path, factory=fake(blowup_step=100))
    assert list(tmp_path.iterdir()) == []


def test_bad_scene_is_an_input_error_and_writes_nothing(tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text("dimension: 2\nbox: [4, 4]\nnumber_density: 4\n"
                    "fluid: {law: newtonian, params: {mu: 1}}\n"
                    "flow: {type: couette, shear_rate: 0}\nrun: {strain: 5}\n")
    with pytest.raises(InputError, match=r"scene.yaml:5 \[key 'flow.shear_rate'\]"):
        run_scene(path, tmp_path / "run.nc", simulation_factory=FakeSimulation,
                  progress=NullProgress())
    assert [p.name for p in tmp_path.iterdir()] == ["scene.yaml"]


def test_checkpoint_rules_without_and_with_resume(tmp_path):
    with pytest.raises(InputError, match="no checkpoint here"):
        run(tmp_path, resume=True)
    with pytest.raises(RunInterrupted):
        run(tmp_path, factory=fake(signal_at=(500, signal.SIGTERM)))
    with pytest.raises(InputError, match="add --resume"):
        run(tmp_path)
    other = dict(COUETTE, fluid={"law": "newtonian", "params": {"mu": 3.0}})
    with pytest.raises(InputError, match="different scene"):
        run(tmp_path, the_scene=scene(other), resume=True)


def test_the_real_solver_resumes_bit_for_bit(tmp_path):
    from suspsim.sph.simulation import Simulation

    class Stopped(Simulation):
        def advance(self, n_steps):
            before = self.step_count
            super().advance(n_steps)
            if before < 300 <= self.step_count:
                os.kill(os.getpid(), signal.SIGTERM)

    tiny = scene(dict(COUETTE, run={"strain": 6, "transient": 1}))
    reference = read_run(run(tmp_path, "reference.nc", tiny, Simulation, threads=1))
    with pytest.raises(RunInterrupted, match=r"\(step 300\)"):
        run(tmp_path, the_scene=tiny, factory=Stopped, threads=1, clock=Ticker(1.0))
    assert_same_results(read_run(run(tmp_path, the_scene=tiny, factory=Simulation, resume=True,
                                     threads=1)), reference)


def test_progress_on_a_terminal_rewrites_one_line(tmp_path):
    stream = io.StringIO()
    run(tmp_path, progress=ProgressReporter(stream=stream, tty=True, clock=Ticker(0.05)))
    text = stream.getvalue()
    assert text.startswith("\rstrain 0/20 (0 %)") and text.endswith("\n")
    assert text.count("\n") == 1 and text.count("\r") > 10
    last = text.rstrip().rsplit("\r", 1)[1]
    assert last.startswith("strain 20/20 (100 %)") and "steps/s" in last and "ETA 0:00:00" in last


def test_progress_elsewhere_logs_every_tenth(tmp_path, caplog):
    caplog.set_level("INFO", logger="suspsim.progress")
    stream = io.StringIO()
    run(tmp_path, progress=ProgressReporter(stream=stream, tty=False, clock=Ticker(1e-3)))
    lines = [r.getMessage() for r in caplog.records if r.name == "suspsim.progress"]
    assert stream.getvalue() == "" and 10 <= len(lines) <= 12
    assert lines[0].startswith("strain 0/20") and lines[-1].startswith("strain 20/20 (100 %)")
    assert all("steps/s" in line and "ETA" in line for line in lines)


def test_progress_log_every_30_seconds_when_slow(caplog):
    caplog.set_level("INFO", logger="suspsim.progress")
    clock = Ticker(10.0)
    reporter = ProgressReporter(stream=io.StringIO(), tty=False, clock=clock)
    reporter.begin(100.0, "time")
    for step in range(10):
        reporter.update(step * 0.1, step, 1000)  # 0.1 % per update, 10 s apart
    assert len(caplog.records) == 4  # at 10 s, then every 30 s
    assert caplog.records[-1].getMessage() == "time 0.9/100 (1 %)  0.1 steps/s  ETA 2:45:10"


def test_format_duration():
    assert format_duration(3725.4) == "1:02:05" and format_duration(float("nan")) == "?"
