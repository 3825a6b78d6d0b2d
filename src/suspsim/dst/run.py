"""``suspsim run`` for DST scenes: the run loop of :mod:`suspsim.run` on a :class:`DSTSimulation`.

The loop (:func:`suspsim.run.drive`: pacing, progress, SIGTERM/SIGINT, checkpoints, health)
is the SPH runs' own; what differs is the schedule. The DST step adapts to the state every
step (SPEC §5.2), so samples are set in simulated time: sample k (k = 1 … K) falls on the first
step at or past min(k Δt_out, T), T the run's time (``run.time``, or ``run.strain``/γ̇_WC),
whatever the pieces the loop advances in (:meth:`DSTSimulation.advance` ``until``), so a
resumed run repeats an uninterrupted one bit for bit. Samples after the transient
(t > ``run.transient``, and the last) form the steady window.

Per sample: ``wall_velocity``, ``wall_shear_rate``, domain averages ``stress`` ⟨η γ̇⟩,
``shear_rate`` ⟨γ̇⟩, ``frictional_fraction`` ⟨f⟩, ``bulk_velocity`` ⟨v_x⟩, ``density_error``,
``mach``, and the branch fractions ψ1, ψ2 (SPEC §5.6) as ``lower_branch_fraction``,
``upper_branch_fraction``; in the steady window the profiles over y (velocity, f, stress, γ̇,
η; bins over [0, L_y], the walls' y). Output (registry :mod:`suspsim.io.dst_variables`): those
time series; their steady-window means ``mean_<name>`` with ``mean_<name>_stderr`` — batch
means over ≥ 8 blocks of whole strain units for stress_couette (a sheared lattice repeats with
period one strain, as in :mod:`suspsim.analysis.steady`), Flyvbjerg–Petersen blocking for
channel or shorter windows; the mean profiles; for stress_couette the flow-curve point
(``mean_shear_rate``, ``mean_stress``) beside ``imposed_stress``, the Wyart–Cates
``wyart_cates_shear_rate`` γ̇_WC(σ_in) and f̂(σ_in), and q (``turning_point_position``); for
channel ``force_density`` and the local-model reference profile and mean velocity
(:mod:`suspsim.reference.dst_channel`; the parabola at φ = 0); and the final per-particle
snapshot (``particle_*``: x, y, v_x, f, γ̇, σ) for scatter plots over the flow curve.
"""
from __future__ import annotations

import logging
import math
import time as wallclock
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.blocking import MeanEstimate, blocking_mean, periodic_batch_means
from ..io.dst_variables import dst_registry
from ..io.netcdf import write_run
from ..progress import ProgressReporter
from ..run import Record, Segment, checkpoint_path, drive, start_simulation
from .parameters import StressCouette
from .scene import DSTScene, load_dst_scene

log = logging.getLogger(__name__)

#: Time-series names (registry :mod:`suspsim.io.dst_variables`).
SAMPLE_NAMES = ("wall_velocity", "wall_shear_rate", "stress", "shear_rate", "frictional_fraction",
                "bulk_velocity", "density_error", "mach", "lower_branch_fraction",
                "upper_branch_fraction")
#: Steady-window profiles: registry name -> key of DSTSimulation.profiles().
PROFILES = {"velocity_profile": "velocity", "frictional_fraction_profile": "fraction",
            "stress_profile": "stress", "shear_rate_profile": "shear_rate",
            "viscosity_profile": "viscosity"}
#: The final per-particle snapshot: registry name -> key of DSTSimulation.snapshot().
SNAPSHOT = {"particle_x": "x", "particle_y": "y", "particle_velocity_x": "v_x",
            "particle_frictional_fraction": "f", "particle_shear_rate": "shear_rate",
            "particle_stress": "stress"}
#: Time series averaged over the steady window (as mean_<name>, mean_<name>_stderr).
MEANS = ("stress", "shear_rate", "wall_shear_rate", "frictional_fraction", "bulk_velocity",
         "lower_branch_fraction", "upper_branch_fraction")
#: Strain period of a sheared lattice's oscillation (SPEC §2.3).
LATTICE_PERIOD_STRAIN = 1.0
#: Relative slack on sample times: a step landing within it of a time counts as reaching it.
TIME_TOLERANCE = 1e-10


class DSTRecord(Record):
    """The DST run's accumulators (:class:`suspsim.run.Record` with DST names)."""

    sample_names = SAMPLE_NAMES
    profile_names = tuple(PROFILES)


class TimeSchedule:
    """Samples in simulated time for :func:`suspsim.run.drive` (module docstring)."""

    def __init__(self, scene: DSTScene, record: DSTRecord):
        self.scene, self.record = scene, record
        self.total_time = scene.total_time
        self.interval = scene.output_interval_time
        self.transient_time = scene.transient_time
        self.n_samples = max(1, math.ceil(self.total_time / self.interval - 1e-9))
        self.rate = scene.nominal_shear_rate

    def sample_time(self, k: int) -> float:
        """Time of sample k (1-based), less the tolerance."""
        return min(k * self.interval, self.total_time) * (1 - TIME_TOLERANCE)

    def done(self, sim) -> float:
        """Progress in the run's unit: nominal strain γ̇_WC t or time."""
        return sim.time * self.rate if self.scene.run.strain is not None else sim.time

    def strain(self, sim) -> float:
        return sim.time * self.rate if self.rate is not None else 0.0

    def finished(self, sim) -> bool:
        return self.record.n_samples >= self.n_samples

    def advance(self, sim, n_steps: int) -> None:
        sim.advance(n_steps, until=self.sample_time(self.record.n_samples + 1))

    def sample_due(self, sim, record) -> bool:
        k = record.n_samples + 1
        return k <= self.n_samples and sim.time >= self.sample_time(k)

    def expected_steps(self, sim) -> int:
        dt = sim.last_dt or sim.dt
        return sim.step_count + max(0, math.ceil((self.total_time - sim.time) / dt))

    def is_steady(self, times: np.ndarray) -> np.ndarray:
        """Which samples (by time) belong to the steady window; the last one always does."""
        steady = np.asarray(times) > self.transient_time * (1 + TIME_TOLERANCE)
        if steady.size:
            steady[-1] = True
        return steady

    def take_sample(self, sim, record: DSTRecord, check) -> None:
        scalars = sim.sample()
        branches = sim.branch_statistics()
        scalars.update(frictional_fraction=scalars["fraction"],
                       bulk_velocity=scalars["mean_velocity"],
                       lower_branch_fraction=branches["psi1"],
                       upper_branch_fraction=branches["psi2"])
        record.add_sample(sim.step_count, sim.time, self.strain(sim), scalars)
        check()
        final = record.n_samples >= self.n_samples
        if final or sim.time > self.transient_time * (1 + TIME_TOLERANCE):
            profiles = sim.profiles(self.scene.run.profile_bins)
            record.add_profiles({"y": profiles["y"],
                                 **{name: profiles[key] for name, key in PROFILES.items()}})


class _Solver:
    """The factory protocol of :func:`suspsim.run.start_simulation` for DST scenes."""

    def __call__(self, scene: DSTScene, *, threads: int | None = None):
        return scene.build(threads=threads)

    def from_state(self, scene: DSTScene, state: dict, *, threads: int | None = None):
        sim = scene.build(threads=threads)
        sim.restore(state)
        return sim


def run_dst_scene(scene: DSTScene | str | PathLike, out_path: str | PathLike, *,
                  resume: bool = False, threads: int | None = None,
                  progress: ProgressReporter | None = None, simulation_factory=None,
                  clock=wallclock.monotonic) -> Path:
    """Run a DST scene (or scene file) to the end and write ``out_path``; return it.

    As :func:`suspsim.run.run_scene`: ``threads`` overrides ``run.threads``; checkpoints at
    ``out_path`` + ``.ckpt.npz``; raises InputError, NumericalError (blow-up, naming the
    setting; the last good checkpoint is kept) or :class:`suspsim.run.RunInterrupted`.
    ``simulation_factory`` defaults to building :class:`DSTSimulation` from the scene.
    """
    started = clock()
    scene = scene if isinstance(scene, DSTScene) else load_dst_scene(scene)
    out, ckpt = Path(out_path), checkpoint_path(out_path)
    threads = scene.run.threads if threads is None else threads
    sim, record, wall_before = start_simulation(scene, ckpt, resume,
                                                simulation_factory or _Solver(), threads,
                                                DSTRecord)
    schedule = TimeSchedule(scene, record)
    log.info("%d fluid + %d wall particles, rho0 %.4g, sound speed %.4g, %s flow: time %.4g "
             "in %d samples, checkpoint %s", sim.n_fluid, 2 * sim.n_wall, scene.numerics.density,
             sim.sound_speed, scene.flow_type, schedule.total_time, schedule.n_samples, ckpt)
    segment = Segment(scene=scene, ckpt=ckpt, progress=progress or ProgressReporter(),
                      clock=clock, started=started, wall_before=wall_before,
                      checkpoint_interval_s=scene.run.checkpoint_interval_s,
                      unit=scene.run.unit, length=scene.run.length, done=schedule.done)
    wall = drive(sim, record, schedule, schedule.take_sample, segment)
    write_dst_output(out, scene, sim, record, schedule, wall)
    ckpt.unlink(missing_ok=True)
    return out


def steady_estimate(strain: np.ndarray | None, values: np.ndarray) -> MeanEstimate:
    """Mean and standard error of a steady window: batch means over whole strain units when
    ``strain`` (increasing) spans ≥ 8 of them, else Flyvbjerg–Petersen blocking."""
    if strain is not None and strain.size >= 2 and np.all(np.diff(strain) > 0):
        estimate = periodic_batch_means(strain, values, LATTICE_PERIOD_STRAIN)
        if estimate is not None:
            return estimate
    return blocking_mean(values)


def write_dst_output(out: Path, scene: DSTScene, sim, record: DSTRecord,
                     schedule: TimeSchedule, wall: float) -> None:
    """The run file (module docstring) from the accumulators."""
    series = record.arrays()
    couette = isinstance(scene.flow, StressCouette)
    data: dict[str, Any] = {"time": series["time"], **{k: series[k] for k in SAMPLE_NAMES}}
    steady = schedule.is_steady(series["time"])
    strain = series["strain"][steady] if couette else None
    estimate = None
    for name in MEANS:
        values = series[name][steady]
        if not np.all(np.isfinite(values)):
            data[f"mean_{name}"] = data[f"mean_{name}_stderr"] = math.nan
            continue
        estimate = steady_estimate(strain, values)
        data[f"mean_{name}"], data[f"mean_{name}_stderr"] = estimate.mean, estimate.stderr
    data["y"] = record.sums["y"]
    for name in PROFILES:
        data[name] = record.sums[name] / record.n_profiles
    fluid, gap = scene.fluid, scene.geometry.gap
    turning = sim.turning_points()
    law = None if fluid.is_newtonian else fluid.steady_law()
    if couette:
        stress = scene.flow.stress
        data.update(strain=series["strain"], imposed_stress=stress,
                    wyart_cates_shear_rate=scene.nominal_shear_rate,
                    wyart_cates_frictional_fraction=fluid.frictional_fraction(stress),
                    turning_point_position=sim.branch_statistics()["q"])
    else:
        force = scene.numerics.density * scene.flow.body_force
        data["force_density"] = force
        data["reference_velocity_profile"], data["reference_bulk_velocity"] = \
            _channel_reference(law, fluid, force, gap, data["y"])
    snapshot = sim.snapshot()
    data["particle"] = np.arange(sim.n_fluid)
    for name, key in SNAPSHOT.items():
        data[name] = snapshot[key]
    speed = sim.n_particles * sim.step_count / wall if wall > 0 else math.nan
    velocity = float(np.nanmax(np.abs(data["velocity_profile"])))
    attrs = {"n_particles": sim.n_particles, "n_fluid_particles": sim.n_fluid,
             "n_wall_particles": 2 * sim.n_wall, "n_steps": sim.step_count,
             "wall_time_s": wall, "particle_steps_per_s": speed,
             "reynolds_number": (scene.numerics.density * velocity * gap
                                 / float(np.nanmin(data["viscosity_profile"]))),
             "mach_number": float(np.max(series["mach"])), "completed": True,
             "dt": sim.last_dt, "sound_speed": sim.sound_speed,
             "density": scene.numerics.density, "spacing": scene.geometry.spacing,
             "smoothing_length": scene.geometry.smoothing_length,
             "sigma_beta": turning.sigma_beta if turning is not None else math.nan,
             "sigma_alpha": turning.sigma_alpha if turning is not None else math.nan,
             "regime": "newtonian" if law is None else law.regime(),
             "averaging_method": estimate.method if estimate else "none",
             "averaging_blocks": estimate.n_blocks if estimate else 0}
    if couette:
        attrs["wall_mass"] = sim.config.wall_mass
    title = (f"suspsim DST run: {scene.flow_type} flow of a Wyart-Cates suspension between "
             f"walls, phi = {fluid.phi:g}, alpha = {fluid.alpha:g} ({scene.dimension}-D)")
    write_run(out, data, attrs, scene, title=title, registry=dst_registry(scene.units == "SI"))
    log.info("wrote %s (%s, %d blocks; Re %.3g, max Mach %.3g)", out, attrs["averaging_method"],
             attrs["averaging_blocks"], attrs["reynolds_number"], attrs["mach_number"])


def _channel_reference(law, fluid, force: float, gap: float, y: np.ndarray):
    """Local-model channel velocity at ``y`` and its mean (the parabola when Newtonian);
    NaN, with a warning, where the reference has no steady flow."""
    if law is None:
        profile = force * y * (gap - y) / (2.0 * fluid.eta_s)
        return profile, force * gap ** 2 / (12.0 * fluid.eta_s)
    from ..reference.dst_channel import dst_channel_mean_velocity, dst_channel_profile

    try:
        return (dst_channel_profile(law, force, gap, y),
                dst_channel_mean_velocity(law, force, gap))
    except ValueError as err:
        log.warning("no local-model channel reference: %s", err)
        return np.full_like(y, math.nan), math.nan
