"""The run loop of ``suspsim run``: advance a simulation, sample, average, checkpoint, write.

Step order (:func:`run_scene`). The run takes ``total_steps = round(total_time/dt)`` steps. It
samples every ``steps_per_sample = round(output_interval_time/dt)`` steps and once more at the
end: the scalars of ``Simulation.sample()`` become time series; ``health()`` is checked; after
the transient (samples at steps > ``round(transient_time/dt)``; the last sample always counts)
the instantaneous profiles of ``Simulation.profiles(run.profile_bins)`` are summed. Between
samples the simulation advances in pieces of about :data:`POLL_S` wall seconds so that a
SIGTERM/SIGINT is honoured quickly and checkpoints keep their wall-clock cadence.

Checkpoints. ``RUN.nc.ckpt.npz`` beside the output holds the simulation's state and the loop's
accumulators (time series, profile sums, wall time), so ``--resume`` gives the same output bit
for bit (except wall-time attributes and history). It is written every
``run.checkpoint_interval_s`` wall seconds (health checked first) and on SIGTERM/SIGINT, and
removed once the output is written. An interrupted run raises :class:`RunInterrupted`
(exit code 128 + signal: 130 for SIGINT, 143 for SIGTERM); a blow-up raises
:class:`~suspsim.errors.NumericalError` naming the limit and keeps the last good checkpoint.

Output (:mod:`suspsim.io.netcdf`): the time series, the steady-window profiles, and for couette
``viscosity`` = ⟨σ_xy⟩/γ̇ with ``viscosity_stderr`` from
:func:`~suspsim.analysis.steady.steady_mean` (batch means over ≥ 8 blocks of whole strain
units); with inclusions also ``phi``, ``suspension_viscosity`` (the same ⟨σ_xy⟩/γ̇),
``matrix_viscosity_at_rate`` μ(γ̇) of the scene's law and ``relative_viscosity`` (± stderr)
η_r = ⟨σ_xy⟩/(γ̇ μ(γ̇)) (SPEC §3.5). A poiseuille flow has no single viscosity: both are omitted (its viscosity lives in
``viscosity_profile``). The Reynolds number's scales are those of :mod:`suspsim.analysis.steady`.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from .analysis.steady import reynolds_number, steady_mean
from .errors import InputError, NumericalError, SuspsimError
from .io.checkpoint import graceful_interrupt, load_checkpoint, save_checkpoint
from .io.netcdf import write_run
from .progress import ProgressReporter
from .scene import Scene, load_scene

log = logging.getLogger(__name__)

#: Scalars of ``Simulation.sample()`` written as time series (registry names).
SAMPLE_NAMES = ("shear_stress", "pressure", "kinetic_energy", "density_error", "mach")
#: Profiles of ``Simulation.profiles()`` averaged over the steady window (registry names).
PROFILE_NAMES = ("velocity_profile", "viscosity_profile", "shear_rate_profile", "density_profile")
CHECKPOINT_SUFFIX = ".ckpt.npz"
#: Wall seconds between polls for a stop request or a due checkpoint [choice].
POLL_S = 0.5


class RunInterrupted(SuspsimError):
    """A run stopped on a signal after saving its checkpoint; ``exit_code`` = 128 + signal."""

    def __init__(self, message: str, signum: int):
        super().__init__(message)
        self.signum = signum
        self.exit_code = 128 + int(signum)


def checkpoint_path(out_path: str | PathLike) -> Path:
    """The checkpoint of the run writing ``out_path``: ``out_path`` + ``.ckpt.npz``."""
    return Path(f"{out_path}{CHECKPOINT_SUFFIX}")


@dataclass(frozen=True)
class Plan:
    """The step counts of a run: total, between samples, and of the discarded transient."""

    total_steps: int
    steps_per_sample: int
    transient_steps: int

    @classmethod
    def for_scene(cls, scene: Scene, dt: float) -> "Plan":
        total = max(1, round(scene.total_time / dt))
        return cls(total, min(total, max(1, round(scene.output_interval_time / dt))),
                   round(scene.transient_time / dt))

    def next_sample(self, step: int) -> int:
        """The step of the first sample after ``step``."""
        return min((step // self.steps_per_sample + 1) * self.steps_per_sample, self.total_steps)

    def is_steady(self, step: int) -> bool:
        return step > self.transient_steps or step == self.total_steps


class Record:
    """The loop's accumulators: time series and profile sums over the steady window."""

    def __init__(self, series: dict[str, np.ndarray] | None = None,
                 sums: dict[str, np.ndarray] | None = None, n_profiles: int = 0):
        names = ("step", "time", "strain", *SAMPLE_NAMES)
        self.series = {k: list((series or {}).get(k, ())) for k in names}
        self.sums = dict(sums or {})
        self.n_profiles = int(n_profiles)

    def add_sample(self, step: int, time_: float, strain: float, scalars: dict[str, float]) -> None:
        for name, value in (("step", step), ("time", time_), ("strain", strain)):
            self.series[name].append(value)
        for name in SAMPLE_NAMES:
            self.series[name].append(float(scalars[name]))

    def add_profiles(self, profiles: dict[str, np.ndarray]) -> None:
        self.sums["y"] = np.asarray(profiles["y"], dtype=float)
        for name in PROFILE_NAMES:
            value = np.asarray(profiles[name], dtype=float)
            self.sums[name] = self.sums[name] + value if name in self.sums else value.copy()
        self.n_profiles += 1

    def arrays(self) -> dict[str, np.ndarray]:
        return {k: np.asarray(v, dtype=np.int64 if k == "step" else float)
                for k, v in self.series.items()}

    def to_state(self) -> dict[str, Any]:
        return {"series": self.arrays(), "sums": dict(self.sums), "n_profiles": self.n_profiles}

    @classmethod
    def from_state(cls, state: dict[str, Any]) -> "Record":
        return cls(state["series"], state.get("sums"), state["n_profiles"])


def run_scene(scene: Scene | str | PathLike, out_path: str | PathLike, *, resume: bool = False,
              threads: int | None = None, progress: ProgressReporter | None = None,
              simulation_factory=None, clock=time.monotonic) -> Path:
    """Run ``scene`` (a Scene or a scene file) to the end and write ``out_path``; return it.

    ``threads`` overrides ``run.threads``; ``progress`` defaults to a reporter on stderr;
    ``simulation_factory`` is the Simulation class (default :mod:`suspsim.sph.simulation`),
    called as ``factory(scene, threads=)`` or ``factory.from_state(scene, state, threads=)``.
    Raises InputError (unusable scene, checkpoint missing or of another scene, a stale
    checkpoint without ``resume``), NumericalError (blow-up) or :class:`RunInterrupted`.
    """
    started = clock()
    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    out, ckpt = Path(out_path), checkpoint_path(out_path)
    threads = scene.run.threads if threads is None else threads
    sim, record, wall_before = _start(scene, ckpt, resume, simulation_factory or _solver(), threads)
    plan = Plan.for_scene(scene, sim.dt)
    log.info("%d particles, dt %.4g tau, sound speed %.4g h/tau: %d steps, a sample every %d, "
             "checkpoint %s", sim.n_particles, sim.dt, sim.sound_speed, plan.total_steps,
             plan.steps_per_sample, ckpt)
    progress = progress or ProgressReporter()
    strain_run = scene.run.strain is not None
    progress.begin(scene.run.length, "strain" if strain_run else "time")

    def done() -> float:
        return sim.strain if strain_run else sim.time

    def where() -> str:
        return f"{progress.unit} {done():.4g} (step {sim.step_count})"

    def save() -> None:
        _check_health(sim, f"{progress.unit} {done():.4g}", ckpt, before_checkpoint=True)
        meta = {"wall_time_s": wall_before + clock() - started, "step": sim.step_count}
        state = {**_flatten(sim.state(), "sim/"), **_flatten(record.to_state(), "run/")}
        save_checkpoint(ckpt, state, meta, scene=scene)

    pace = _Pace(clock)
    last_save = clock()
    with graceful_interrupt() as stop:
        progress.update(done(), sim.step_count, plan.total_steps, force=True)
        try:
            while sim.step_count < plan.total_steps:
                target = plan.next_sample(sim.step_count)
                pace.advance(sim, target - sim.step_count)
                if sim.step_count == target:
                    _take_sample(sim, record, plan, scene, ckpt, f"{progress.unit} {done():.4g}")
                progress.update(done(), sim.step_count, plan.total_steps)
                if stop.requested:
                    save()
                    raise RunInterrupted(f"interrupted at {where()}; checkpoint saved to {ckpt}; "
                                         f"resume with --resume", stop.signum)
                if clock() - last_save >= scene.run.checkpoint_interval_s:
                    save()
                    last_save = clock()
            progress.update(done(), sim.step_count, plan.total_steps, force=True)
        finally:
            progress.close()
    wall = wall_before + clock() - started
    _write_output(out, scene, sim, record, plan, wall)
    ckpt.unlink(missing_ok=True)
    return out


def _start(scene: Scene, ckpt: Path, resume: bool, factory, threads: int | None):
    """The simulation, the accumulators and the wall time of earlier segments [s]."""
    if resume:
        state, meta = load_checkpoint(ckpt, scene)
        sim = factory.from_state(scene, _unflatten(_strip(state, "sim/")), threads=threads)
        log.info("resuming from %s at step %d", ckpt, sim.step_count)
        return sim, Record.from_state(_unflatten(_strip(state, "run/"))), float(meta["wall_time_s"])
    if ckpt.exists():
        raise InputError(ckpt, "an interrupted run left this checkpoint; add --resume to "
                         "continue it, or delete it to start afresh")
    return factory(scene, threads=threads), Record(), 0.0


class _Pace:
    """Chooses step counts so that one ``advance`` call lasts about :data:`POLL_S`."""

    def __init__(self, clock):
        self.clock, self.steps = clock, 1

    def advance(self, sim, remaining: int) -> None:
        n = min(remaining, self.steps)
        t0 = self.clock()
        sim.advance(n)
        elapsed = self.clock() - t0
        # Grow at most eightfold: the first calls may include compilation.
        wanted = n * POLL_S / elapsed if elapsed > 0 else 8 * n
        self.steps = max(1, min(int(wanted), 8 * n))


def _take_sample(sim, record: Record, plan: Plan, scene: Scene, ckpt: Path, where: str) -> None:
    scalars = sim.sample()
    record.add_sample(sim.step_count, sim.time, sim.strain, scalars)
    _check_health(sim, where, ckpt)
    if plan.is_steady(sim.step_count):
        record.add_profiles(sim.profiles(scene.run.profile_bins))


def _check_health(sim, where: str, ckpt: Path, *, before_checkpoint: bool = False) -> None:
    ok, message = sim.health()
    if ok:
        return
    kept = (f"the last good checkpoint is kept at {ckpt} for inspection; after changing the "
            f"setting, --resume continues from it" if ckpt.exists()
            else "no checkpoint had been written yet")
    note = ", not checkpointed" if before_checkpoint else ""
    raise NumericalError(f"{message} [{where}{note}]; {kept}")


def _write_output(out: Path, scene: Scene, sim, record: Record, plan: Plan, wall: float) -> None:
    series = record.arrays()
    data: dict[str, Any] = {"time": series["time"], **{k: series[k] for k in SAMPLE_NAMES}}
    if scene.flow.type == "couette":
        data["strain"] = series["strain"]
        steady = np.array([plan.is_steady(int(s)) for s in series["step"]], dtype=bool)
        estimate = steady_mean(series["strain"][steady], series["shear_stress"][steady])
        data["viscosity"] = estimate.mean / scene.flow.shear_rate
        data["viscosity_stderr"] = estimate.stderr / scene.flow.shear_rate
        log.info("viscosity %.6g ± %.2g (%s, %d blocks of %g, %d samples)", data["viscosity"],
                 data["viscosity_stderr"], estimate.method, estimate.n_blocks,
                 estimate.block_size, estimate.n_used)
        if scene.inclusions.present:
            matrix = float(scene.fluid.law.viscosity(scene.flow.shear_rate))
            data.update(phi=float(sim.packing_phi), suspension_viscosity=data["viscosity"],
                        matrix_viscosity_at_rate=matrix,
                        relative_viscosity=data["viscosity"] / matrix,
                        relative_viscosity_stderr=data["viscosity_stderr"] / matrix)
    data["y"] = record.sums["y"]
    for name in PROFILE_NAMES:
        data[name] = record.sums[name] / record.n_profiles
    speed = sim.n_particles * sim.step_count / wall if wall > 0 else math.nan
    attrs = {"n_particles": sim.n_particles, "n_steps": sim.step_count, "wall_time_s": wall,
             "particle_steps_per_s": speed,
             "reynolds_number": reynolds_number(scene, data["velocity_profile"]),
             "mach_number": float(np.max(series["mach"])), "completed": True,
             "dt": sim.dt, "sound_speed": sim.sound_speed}
    if getattr(sim, "bodies", None) is not None:
        attrs.update(n_bodies=sim.bodies.count, n_body_particles=sim.n_body_particles)
    write_run(out, data, attrs, scene)
    log.info("wrote %s (Re %.3g, max Mach %.3g)", out, attrs["reynolds_number"],
             attrs["mach_number"])


def _strip(state: dict[str, Any], prefix: str) -> dict[str, Any]:
    return {k[len(prefix):]: v for k, v in state.items() if k.startswith(prefix)}


def _flatten(state: dict[str, Any], prefix: str) -> dict[str, Any]:
    """Nested mappings to one level with '/'-joined keys (a checkpoint holds flat arrays)."""
    out: dict[str, Any] = {}
    for key, value in state.items():
        if isinstance(value, dict):
            out.update(_flatten(value, f"{prefix}{key}/"))
        else:
            out[f"{prefix}{key}"] = value
    return out


def _unflatten(flat: dict[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in flat.items():
        *parents, leaf = key.split("/")
        node = out
        for part in parents:
            node = node.setdefault(part, {})
        node[leaf] = value
    return out


def _solver():
    """The real solver class, imported on first use (numba compilation is slow to load)."""
    from .sph.simulation import Simulation

    return Simulation
