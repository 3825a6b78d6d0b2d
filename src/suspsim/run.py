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

The loop itself (:func:`drive`) is shared with the DST solver (:mod:`suspsim.dst.run`): it
asks a *schedule* when to sample and stop — here :class:`Plan`, in steps; there, in simulated
time — and a simulation for ``advance``, ``step_count``, ``health``, ``state``.

Output (:mod:`suspsim.io.netcdf`): the time series, the steady-window profiles, and for couette
``viscosity`` = ⟨σ_xy⟩/γ̇ with ``viscosity_stderr`` from
:func:`~suspsim.analysis.steady.steady_mean` (batch means over ≥ 8 blocks of whole strain
units); with inclusions also ``phi``, ``suspension_viscosity`` (the same ⟨σ_xy⟩/γ̇),
``matrix_viscosity_at_rate`` μ(γ̇) of the scene's law and ``relative_viscosity`` (± stderr)
η_r = ⟨σ_xy⟩/(γ̇ μ(γ̇)) (SPEC §3.5), the series ``particle_stress`` (the bodies' share of σ_xy),
and in a Newtonian matrix Batchelor's split of η_r (:func:`_batchelor_split`). A poiseuille
flow has no single viscosity: both are omitted (its viscosity lives in
``viscosity_profile``). The Reynolds number's scales are those of :mod:`suspsim.analysis.steady`.
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any, Callable

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

    # The schedule protocol of drive(): progress in steps, samples at whole multiples.
    def finished(self, sim) -> bool:
        return sim.step_count >= self.total_steps

    def advance(self, sim, n_steps: int) -> None:
        """At most ``n_steps``, never past the next sample."""
        sim.advance(min(n_steps, self.next_sample(sim.step_count) - sim.step_count))

    def sample_due(self, sim, record: "Record") -> bool:
        return sim.step_count == self.next_sample(sim.step_count - 1)

    def expected_steps(self, sim) -> int:
        return self.total_steps


class Record:
    """The loop's accumulators: time series and profile sums over the steady window.

    ``sample_names`` and ``profile_names`` (class attributes) are the registry names kept;
    ``optional_names`` those kept when the samples have them; a solver with other diagnostics
    subclasses with its own.
    """

    sample_names: tuple[str, ...] = SAMPLE_NAMES
    optional_names: tuple[str, ...] = ()
    profile_names: tuple[str, ...] = PROFILE_NAMES

    def __init__(self, series: dict[str, np.ndarray] | None = None,
                 sums: dict[str, np.ndarray] | None = None, n_profiles: int = 0):
        names = ("step", "time", "strain", *self.sample_names, *self.optional_names)
        self.series = {k: list((series or {}).get(k, ())) for k in names}
        self.sums = dict(sums or {})
        self.n_profiles = int(n_profiles)

    @property
    def n_samples(self) -> int:
        return len(self.series["step"])

    def add_sample(self, step: int, time_: float, strain: float, scalars: dict[str, float]) -> None:
        for name, value in (("step", step), ("time", time_), ("strain", strain)):
            self.series[name].append(value)
        for name in self.sample_names:
            self.series[name].append(float(scalars[name]))
        for name in self.optional_names:
            if name in scalars:
                self.series[name].append(float(scalars[name]))

    @property
    def recorded_names(self) -> tuple[str, ...]:
        """``sample_names`` and the ``optional_names`` every sample had."""
        return self.sample_names + tuple(name for name in self.optional_names
                                         if self.series[name]
                                         and len(self.series[name]) == self.n_samples)

    def add_profiles(self, profiles: dict[str, np.ndarray]) -> None:
        self.sums["y"] = np.asarray(profiles["y"], dtype=float)
        for name in self.profile_names:
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


class SuspensionRecord(Record):
    """A run with inclusions: :class:`Record` with the bodies' share of σ_xy and their spin as
    well, and the nematic order of grains (``Simulation.sample``)."""

    sample_names = SAMPLE_NAMES + ("particle_stress", "body_spin")
    optional_names = ("body_order",)


def run_scene(scene: Scene | str | PathLike, out_path: str | PathLike, *, resume: bool = False,
              threads: int | None = None, progress: ProgressReporter | None = None,
              simulation_factory=None, clock=time.monotonic,
              extra_attrs: dict[str, Any] | None = None) -> Path:
    """Run ``scene`` (a Scene or a scene file) to the end and write ``out_path``; return it.

    ``threads`` overrides ``run.threads``; ``extra_attrs`` are added to the output's run
    attributes (registry names, e.g. the tolerance set-up of
    :mod:`suspsim.convergence.tolerance`); ``progress`` defaults to a reporter on stderr;
    ``simulation_factory`` is the Simulation class (default :mod:`suspsim.sph.simulation`),
    called as ``factory(scene, threads=)`` or ``factory.from_state(scene, state, threads=)``.
    Raises InputError (unusable scene, checkpoint missing or of another scene, a stale
    checkpoint without ``resume``), NumericalError (blow-up) or :class:`RunInterrupted`.
    """
    started = clock()
    scene = scene if isinstance(scene, Scene) else load_scene(scene)
    out, ckpt = Path(out_path), checkpoint_path(out_path)
    threads = scene.run.threads if threads is None else threads
    record_class = SuspensionRecord if scene.inclusions.present else Record
    sim, record, wall_before = start_simulation(scene, ckpt, resume,
                                                simulation_factory or _solver(), threads,
                                                record_class)
    plan = Plan.for_scene(scene, sim.dt)
    log.info("%d particles, dt %.4g tau, sound speed %.4g h/tau: %d steps, a sample every %d, "
             "checkpoint %s", sim.n_particles, sim.dt, sim.sound_speed, plan.total_steps,
             plan.steps_per_sample, ckpt)
    strain_run = scene.run.strain is not None
    segment = Segment(scene=scene, ckpt=ckpt, progress=progress or ProgressReporter(),
                      clock=clock, started=started, wall_before=wall_before,
                      checkpoint_interval_s=scene.run.checkpoint_interval_s,
                      unit="strain" if strain_run else "time", length=scene.run.length,
                      done=lambda sim: sim.strain if strain_run else sim.time)

    def take_sample(sim, record: Record, check: Callable[[], None]) -> None:
        scalars = sim.sample()
        record.add_sample(sim.step_count, sim.time, sim.strain, scalars)
        check()
        if plan.is_steady(sim.step_count):
            record.add_profiles(sim.profiles(scene.run.profile_bins))

    wall = drive(sim, record, plan, take_sample, segment)
    _write_output(out, scene, sim, record, plan, wall, extra_attrs or {})
    ckpt.unlink(missing_ok=True)
    return out


@dataclass(frozen=True)
class Segment:
    """What :func:`drive` needs besides the simulation, for one segment of a run.

    ``scene`` (anything with ``to_dict()``, hashed into the checkpoint), ``ckpt`` the
    checkpoint path, ``clock`` wall seconds, ``started`` its reading at the segment's start,
    ``wall_before`` [s] the wall time of earlier segments, ``unit`` and ``length`` of the run
    (strain or time) and ``done(sim)`` how far it is in that unit.
    """

    scene: Any
    ckpt: Path
    progress: ProgressReporter
    clock: Callable[[], float]
    started: float
    wall_before: float
    checkpoint_interval_s: float
    unit: str
    length: float
    done: Callable[[Any], float]

    def wall_time(self) -> float:
        """Wall seconds of this and the earlier segments."""
        return self.wall_before + self.clock() - self.started


def drive(sim, record: Record, schedule, take_sample, segment: Segment) -> float:
    """Advance ``sim`` to the end of ``schedule``; return the wall time of all segments [s].

    ``schedule`` has ``finished(sim)``, ``advance(sim, n)`` (at most n steps, none past the
    next sample), ``sample_due(sim, record)`` and ``expected_steps(sim)`` (for the ETA);
    ``take_sample(sim, record, check)`` records a sample and calls ``check()`` (the health
    check) before anything that a failed state would spoil. Order per piece: advance about
    :data:`POLL_S` wall seconds, sample if due, report progress, save and stop on a signal,
    checkpoint when due. A NumericalError from ``advance`` gets the place and the checkpoint
    note of a failed health check.
    """
    ckpt, clock, progress = segment.ckpt, segment.clock, segment.progress
    progress.begin(segment.length, segment.unit)

    def here() -> str:
        return f"{segment.unit} {segment.done(sim):.4g}"

    def report(force: bool = False) -> None:
        progress.update(segment.done(sim), sim.step_count, schedule.expected_steps(sim),
                        force=force)

    def save() -> None:
        _check_health(sim, here(), ckpt, before_checkpoint=True)
        meta = {"wall_time_s": segment.wall_time(), "step": sim.step_count}
        state = {**_flatten(sim.state(), "sim/"), **_flatten(record.to_state(), "run/")}
        save_checkpoint(ckpt, state, meta, scene=segment.scene)

    pace = _Pace(clock)
    last_save = clock()
    with graceful_interrupt() as stop:
        report(force=True)
        try:
            while not schedule.finished(sim):
                try:
                    pace.advance(sim, lambda n: schedule.advance(sim, n))
                except NumericalError as err:
                    raise _failure(str(err), here(), ckpt) from None
                if schedule.sample_due(sim, record):
                    take_sample(sim, record, lambda: _check_health(sim, here(), ckpt))
                report()
                if stop.requested:
                    save()
                    raise RunInterrupted(f"interrupted at {here()} (step {sim.step_count}); "
                                         f"checkpoint saved to {ckpt}; resume with --resume",
                                         stop.signum)
                if clock() - last_save >= segment.checkpoint_interval_s:
                    save()
                    last_save = clock()
            report(force=True)
        finally:
            progress.close()
    return segment.wall_time()


def start_simulation(scene, ckpt: Path, resume: bool, factory, threads: int | None,
                     record_class: type[Record] = Record):
    """The simulation, the accumulators and the wall time of earlier segments [s].

    ``factory(scene, threads=)`` builds a fresh simulation, ``factory.from_state(scene, state,
    threads=)`` one from a checkpoint's state.
    """
    if resume:
        state, meta = load_checkpoint(ckpt, scene)
        sim = factory.from_state(scene, _unflatten(_strip(state, "sim/")), threads=threads)
        log.info("resuming from %s at step %d", ckpt, sim.step_count)
        record = record_class.from_state(_unflatten(_strip(state, "run/")))
        return sim, record, float(meta["wall_time_s"])
    if ckpt.exists():
        raise InputError(ckpt, "an interrupted run left this checkpoint; add --resume to "
                         "continue it, or delete it to start afresh")
    return factory(scene, threads=threads), record_class(), 0.0


class _Pace:
    """Chooses step counts so that one ``advance`` call lasts about :data:`POLL_S`."""

    def __init__(self, clock):
        self.clock, self.steps = clock, 1

    def advance(self, sim, advance: Callable[[int], None]) -> None:
        """Call ``advance(n)`` (which may take fewer than n steps) and adapt n to the speed."""
        before = sim.step_count
        t0 = self.clock()
        advance(self.steps)
        elapsed = self.clock() - t0
        n = max(1, sim.step_count - before)
        # Grow at most eightfold: the first calls may include compilation.
        wanted = n * POLL_S / elapsed if elapsed > 0 else 8 * n
        self.steps = max(1, min(int(wanted), 8 * n))


def _check_health(sim, where: str, ckpt: Path, *, before_checkpoint: bool = False) -> None:
    ok, message = sim.health()
    if not ok:
        raise _failure(message, where, ckpt, before_checkpoint=before_checkpoint)


def _failure(message: str, where: str, ckpt: Path, *,
             before_checkpoint: bool = False) -> NumericalError:
    kept = (f"the last good checkpoint is kept at {ckpt} for inspection; after changing the "
            f"setting, --resume continues from it" if ckpt.exists()
            else "no checkpoint had been written yet")
    note = ", not checkpointed" if before_checkpoint else ""
    return NumericalError(f"{message} [{where}{note}]; {kept}")


def _write_output(out: Path, scene: Scene, sim, record: Record, plan: Plan, wall: float,
                  extra_attrs: dict[str, Any]) -> None:
    series = record.arrays()
    data: dict[str, Any] = {"time": series["time"],
                            **{k: series[k] for k in record.recorded_names}}
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
            split = ""
            if scene.fluid.law.is_newtonian:
                data.update(_batchelor_split(series, steady, scene.flow.shear_rate * matrix))
                split = (f"; from the bodies' share {data['particle_relative_viscosity']:.4g}, "
                         f"the fluid's error {data['fluid_stress_error']:+.3g}")
            log.info("phi %.4g: relative viscosity %.4g ± %.2g%s", data["phi"],
                     data["relative_viscosity"], data["relative_viscosity_stderr"], split)
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
    attrs.update(extra_attrs)
    write_run(out, data, attrs, scene)
    log.info("wrote %s (Re %.3g, max Mach %.3g)", out, attrs["reynolds_number"],
             attrs["mach_number"])


def _batchelor_split(series: dict[str, np.ndarray], steady: np.ndarray,
                     scale: float) -> dict[str, float]:
    """A Newtonian matrix's η_r from the bodies' share of the stress alone, and the fluid's.

    Batchelor (1970, J. Fluid Mech. 41, 545): in a Newtonian matrix of viscosity μ the bulk
    stress is σ = −p I + 2μE + (1/V) Σ_B S_B, the fluid's share exactly 2μE however the bodies
    move, so ``particle_relative_viscosity`` = 1 + ⟨σ^p_xy⟩/(μγ̇) (σ^p the series
    ``particle_stress``) leaves out the discrete fluid's own error, which
    ``fluid_stress_error`` = ⟨σ_xy − σ^p_xy⟩/(μγ̇) − 1 reports (0 in the continuum). Both ± the
    batch-means standard error; ``scale`` = μγ̇ [stress]. A shear-thinning matrix has no such
    split (its fluid share depends on the local rates), so only Newtonian runs write them.
    """
    strain = series["strain"][steady]
    particle = steady_mean(strain, series["particle_stress"][steady])
    fluid = steady_mean(strain, series["shear_stress"][steady]
                        - series["particle_stress"][steady])
    return {"particle_relative_viscosity": 1.0 + particle.mean / scale,
            "particle_relative_viscosity_stderr": particle.stderr / scale,
            "fluid_stress_error": fluid.mean / scale - 1.0,
            "fluid_stress_error_stderr": fluid.stderr / scale}


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
