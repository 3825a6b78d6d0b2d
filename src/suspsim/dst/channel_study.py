"""DST channel flow against driving force (SPEC §5.7; seed 002 Fig. 7–8; issue 5).

:func:`channel_sweep` runs one :class:`DSTSimulation` with a :class:`Channel` per driving force
F H/σ* and returns an :class:`xarray.Dataset` on the dimensions ``force_ratio`` and ``y``:
SPH mean velocity and row-averaged velocity and f profiles beside the local-model ODE
(:mod:`suspsim.reference.dst_channel`) and the inverse-biviscous model
(:mod:`suspsim.reference.inverse_biviscous`); :func:`channel_dataset` builds it from
per-force records, so plots can be tested on synthetic data.

Scaled units as :mod:`suspsim.dst.study` (L_y = η_s = σ* = 1): velocities in σ* L_y/η_s
(0.05 m/s for seed 002), times in η_s/σ* (0.2 s). The force per volume is F = 2 (F H/σ*) σ*/L_y
and the body acceleration g = F/ρ.

Two protocols (``protocol``; default ``"momentum"`` for α = 0, ``"relaxed"`` for α > 0):

* ``"momentum"`` — the validation test's (``test_local_dst_channel_matches_reference``):
  ρ = 1, start from rest with f = f̂(F |H − y|) (the local steady state of the imposed stress)
  and run one momentum time ρ L_y²/η(f = 0), after which the slowest velocity mode has decayed
  to e^(−π²). The microstructure is not waited for (its relaxation time 1/(K_f γ̇) is 30–70
  time units); ``fraction_residual`` = rms(f̂(σ_i) − f_i) measures how far the SPH stress
  leaves f from steady. This is the local model with f at its steady value.
* ``"relaxed"`` — f must reach its own steady state, which with non-locality differs from
  f̂(σ): start and run one momentum time as above, then advance in chunks of
  ``chunk_strain``/(K_f ⟨γ̇⟩) and accumulate the microstructure strain s = K_f ∫⟨γ̇⟩ dt (the
  uniform part of f − f_steady decays like e^(−s)); stop once s ≥ ``min_strain`` and the
  mean velocity changed by less than ``tolerance`` (relative) over the last unit of s, or at
  ``max_strain``. The final change is stored (``mean_velocity_drift``). ρ = 2000 by
  default: a parallel steady flow does not depend on ρ, which sets only the momentum time
  ρ L_y²/(π² η(0)) ≈ 10 against the microstructure time 1/(K_f ⟨γ̇⟩) ≈ 40–60 at
  F H/σ* = 3 [measured, α = 0.02, 14 × 20: the mean velocity at t = 150 was 0.0054929 at
  ρ = 2000 and 0.0054963 at ρ = 205 (0.06 %), reached in 8.3 times fewer steps]. The sound
  speed is the Morris value for the velocity scale 2 max(u_max) of the two reference models
  (the solver's default bound F H²/(2η(0)) is 30 times the real velocity at F H/σ* = 100
  and would make the sound step bind).
"""
from __future__ import annotations

import logging
import math
import time as wallclock

import numpy as np
import xarray as xr

from suspsim.dst.parameters import Channel, Geometry, Numerics, WyartCatesFluid
from suspsim.dst.simulation import DSTSimulation
from suspsim.dst.study import LOCAL, SEED_002, _attrs, study_attributes
from suspsim.errors import InputError
from suspsim.reference.dst_channel import (dst_channel_fraction, dst_channel_mean_velocity,
                                           dst_channel_profile)
from suspsim.reference.inverse_biviscous import InverseBiviscous

log = logging.getLogger(__name__)

MOMENTUM, RELAXED = "momentum", "relaxed"
#: Density of each protocol [σ* L_y² η_s⁻² · time²/length², i.e. scaled]; see the module.
DENSITY = {MOMENTUM: 1.0, RELAXED: 2000.0}

_VELOCITY = "sigma_star L_y eta_s-1"
_TIME = "eta_s sigma_star-1"
_PROFILE = ("force_ratio", "y")

#: name -> (long_name, simulation_units or None, comment or None); every output variable.
CHANNEL_VARIABLES = {
    "force_ratio": ("driving force F H/sigma* (wall stress over onset stress)", None, None),
    "y": ("height above the bottom wall (centre of a particle row)", "L_y", None),
    "mean_velocity": ("SPH gap-averaged velocity <v_x> at the end of the run", _VELOCITY,
                      None),
    "local_mean_velocity": ("gap-averaged velocity of the local Wyart-Cates model (ODE, SPEC "
                            "5.7)", _VELOCITY, None),
    "inverse_biviscous_mean_velocity": ("gap-averaged velocity of the inverse-biviscous model",
                                        _VELOCITY, "critical_rate in the global attributes"),
    "velocity": ("SPH velocity v_x averaged over a particle row", _VELOCITY, None),
    "fraction": ("SPH fraction of frictional contacts f averaged over a particle row", None,
                 None),
    "shear_rate": ("SPH shear-rate magnitude averaged over a particle row", "sigma_star eta_s-1",
                   None),
    "local_velocity": ("velocity u(y) of the local Wyart-Cates model (ODE)", _VELOCITY, None),
    "local_fraction": ("steady fraction f_hat(F |H - y|) of the local model", None, None),
    "inverse_biviscous_velocity": ("velocity u(y) of the inverse-biviscous model", _VELOCITY,
                                   None),
    "velocity_l2_error": ("rms over particles of v_x - u_ODE(y), over max u_ODE", None,
                          "the L2 error relative to the peak of the issue"),
    "mean_velocity_error": ("mean_velocity / local_mean_velocity - 1", None, None),
    "fraction_residual": ("rms over particles of f_hat(sigma_i) - f_i at the end", None,
                          "sigma_i = eta_i gdot_i, the SPH stress"),
    "microstructure_strain": ("K_f times the time integral of the domain-averaged shear rate",
                              None, None),
    "mean_velocity_drift": ("relative change of mean_velocity over the last unit of "
                            "microstructure_strain", None, "NaN for the momentum protocol"),
    "density": ("reference density rho0 of the run", "sigma_star L_y2 eta_s-2", None),
    "sound_speed": ("artificial sound speed", _VELOCITY, None),
    "steps": ("predictor-corrector steps of the run", None, None),
    "simulated_time": ("simulated time at the end of the run", _TIME, None),
    "reynolds_number": ("Reynolds number rho0 <v_x> L_y/eta(f=0) at the end", None, None),
    "mach_number": ("Mach number max|v|/c at the end", None, None),
    "wall_time": ("wall-clock time of the run (set-up and stepping)", None, None),
}


def channel_fluid(phi: float, alpha: float = LOCAL, *, phi_m: float = SEED_002["phi_m"],
                  phi_0: float = SEED_002["phi_0"], beta: float = SEED_002["beta"],
                  K_f: float = SEED_002["K_f"]) -> WyartCatesFluid:
    """The fluid of a sweep in scaled units (η_s = σ* = 1), seed 002 defaults."""
    return WyartCatesFluid(eta_s=1.0, phi=phi, phi_m=phi_m, phi_0=phi_0, sigma_star=1.0,
                           beta=beta, K_f=K_f, alpha=alpha)


def channel_sweep(phi: float, force_ratios, *, alpha: float = LOCAL,
                  lattice: tuple[int, int] = (14, 20), threads: int = 1,
                  protocol: str | None = None, density: float | None = None,
                  min_strain: float = 3.0, max_strain: float = 12.0, tolerance: float = 1e-3,
                  chunk_strain: float = 0.25, critical_rate: float | None = None,
                  phi_m: float = SEED_002["phi_m"], phi_0: float = SEED_002["phi_0"],
                  beta: float = SEED_002["beta"], K_f: float = SEED_002["K_f"]) -> xr.Dataset:
    """Channel flow of a Wyart–Cates suspension at ``phi`` for each F H/σ* in ``force_ratios``.

    Parameters
    ----------
    phi : solid volume fraction φ [1], 0 < φ < φ_m (the ODE needs a flowing upper branch).
    force_ratios : F H/σ* [1], positive (one run each, in the given order).
    alpha : diffusivity of f [L_y² σ*/η_s] (0: local; ``study.STRONG_NONLOCALITY`` = 0.02).
    lattice : fluid particles (n_x periodic, n_y across the gap); rows give the profiles.
    threads : numba threads per run.
    protocol : ``"momentum"`` or ``"relaxed"`` (module docstring); None: momentum for α = 0.
    density : ρ0 (default :data:`DENSITY` of the protocol).
    min_strain, max_strain, tolerance, chunk_strain : stopping rule of ``"relaxed"``.
    critical_rate : γ̇_c of the inverse-biviscous model [σ*/η_s] (default: the front-selected
        rate, :func:`~suspsim.reference.inverse_biviscous.front_selected_rate`).
    phi_m, phi_0, beta, K_f : the rest of the fluid (seed 002 defaults).

    Returns the Dataset of :func:`channel_dataset`. Raises InputError for bad parameters and
    NumericalError (from the solver) when a run blows up.
    """
    ratios = np.atleast_1d(np.asarray(force_ratios, dtype=float))
    if ratios.ndim != 1 or ratios.size == 0 or np.any(~(ratios > 0)) \
            or np.any(~np.isfinite(ratios)):
        raise InputError("channel_sweep", f"force_ratios must be positive numbers, got "
                         f"{ratios.tolist()}", key="force_ratios")
    protocol = (MOMENTUM if alpha == 0.0 else RELAXED) if protocol is None else protocol
    if protocol not in (MOMENTUM, RELAXED):
        raise InputError("channel_sweep", f"protocol must be '{MOMENTUM}' or '{RELAXED}', got "
                         f"{protocol!r}", key="protocol")
    if not (0.0 < min_strain <= max_strain and 0.0 < chunk_strain <= 1.0 and tolerance > 0):
        raise InputError("channel_sweep", "need 0 < min_strain <= max_strain, 0 < chunk_strain"
                         " <= 1 and tolerance > 0", key="min_strain")
    if not phi < phi_m:
        raise InputError("channel_sweep", f"phi = {phi} must lie below phi_m = {phi_m} (a "
                         "flowing frictional branch)", key="phi")
    fluid = channel_fluid(phi, alpha, phi_m=phi_m, phi_0=phi_0, beta=beta, K_f=K_f)
    geometry = Geometry(int(lattice[0]), int(lattice[1]), 1.0)
    law = fluid.steady_law()
    model = _model(law, critical_rate)
    settings = {"protocol": protocol, "threads": int(threads),
                "density": float(DENSITY[protocol] if density is None else density),
                "min_strain": float(min_strain), "max_strain": float(max_strain),
                "tolerance": float(tolerance), "chunk_strain": float(chunk_strain)}
    records = [_run(fluid, law, model, geometry, float(r), **settings) for r in ratios]
    return channel_dataset(fluid, geometry, ratios, records, settings,
                           critical_rate=model.critical_rate)


def _model(law, critical_rate):
    """The inverse-biviscous comparison model; InputError when γ̇_c has no default."""
    try:
        return InverseBiviscous.from_wyart_cates(law, critical_rate)
    except ValueError as error:
        raise InputError("channel_sweep", f"{error}; give critical_rate",
                         key="critical_rate") from None


def _run(fluid, law, model, geometry, ratio, *, protocol, threads, density, min_strain,
         max_strain, tolerance, chunk_strain) -> dict:
    """One channel run; the record of :func:`channel_dataset`."""
    start = wallclock.perf_counter()
    gap = geometry.gap
    force = 2.0 * ratio * fluid.sigma_star / gap
    if protocol == MOMENTUM:
        numerics = Numerics(density=density)
    else:
        peak = max(float(dst_channel_profile(law, force, gap, gap / 2.0)),
                   float(model.channel_profile(force, gap, gap / 2.0)))
        tol = Numerics().density_tolerance
        sound = max(20.0 * peak, math.sqrt(force * gap / 2.0 / (density * tol)),
                    math.sqrt(force / density * gap / tol))
        numerics = Numerics(density=density, sound_speed=sound)
    sim = DSTSimulation(fluid, Channel(force / density), geometry, numerics, threads=threads)
    strain, drift = 0.0, math.nan
    # one momentum time first: the flow starts from rest, so ⟨γ̇⟩ means nothing before it
    sim.advance(2 ** 62, until=density * gap ** 2 / fluid.viscosity(0.0))
    if protocol == RELAXED:
        history = [(0.0, sim.sample()["mean_velocity"])]
        while True:
            rate = max(sim.sample()["shear_rate"], 1e-12)
            t0 = sim.time
            sim.advance(2 ** 62, until=t0 + chunk_strain / (fluid.K_f * rate))
            sample = sim.sample()
            strain += fluid.K_f * 0.5 * (rate + sample["shear_rate"]) * (sim.time - t0)
            history.append((strain, sample["mean_velocity"]))
            earlier = [u for s, u in history if s <= strain - 1.0]
            if earlier:
                drift = sample["mean_velocity"] / earlier[-1] - 1.0
            if strain >= max_strain or (strain >= min_strain and abs(drift) < tolerance):
                break
    snap = sim.snapshot()
    rows = sim.profiles(geometry.n_y)
    exact = dst_channel_profile(law, force, gap, snap["y"])
    speed = np.sqrt(snap["v_x"] ** 2 + snap["v_y"] ** 2)
    mean = float(snap["v_x"].mean())
    record = {
        "y": rows["y"], "velocity": rows["velocity"], "fraction": rows["fraction"],
        "shear_rate": rows["shear_rate"], "mean_velocity": mean,
        "velocity_l2_error": float(np.sqrt(np.mean((snap["v_x"] - exact) ** 2))
                                   / np.max(np.abs(exact))),
        "fraction_residual": float(np.sqrt(np.mean(
            (law.frictional_fraction(snap["stress"]) - snap["f"]) ** 2))),
        "microstructure_strain": strain if protocol == RELAXED else math.nan,
        "mean_velocity_drift": drift, "density": density, "sound_speed": sim.sound_speed,
        "steps": sim.steps, "simulated_time": sim.time,
        "reynolds_number": density * mean * gap / fluid.viscosity(0.0),
        "mach_number": float(speed.max()) / sim.sound_speed,
        "n_particles": sim.n_particles, "wall_time": wallclock.perf_counter() - start}
    log.info("phi %g alpha %g F H/sigma* %g (%s): <v_x> %.5g vs ODE %.5g (%+.2f %%), L2/peak "
             "%.4f, strain %.2f, drift %.1e, %d steps, %.1f s", fluid.phi, fluid.alpha, ratio,
             protocol, mean, dst_channel_mean_velocity(law, force, gap),
             100 * (mean / dst_channel_mean_velocity(law, force, gap) - 1),
             record["velocity_l2_error"], strain, drift, sim.steps, record["wall_time"])
    return record


def channel_dataset(fluid: WyartCatesFluid, geometry: Geometry, force_ratios, records,
                    settings: dict, *, critical_rate: float | None = None,
                    command: str | None = None) -> xr.Dataset:
    """The channel Dataset on (``force_ratio``, ``y``) from one record (dict) per force.

    Each record holds the SPH variables of :data:`CHANNEL_VARIABLES` (profiles as arrays over
    the rows ``y``, the same in every record) and ``n_particles``; the reference variables
    are computed here from ``fluid`` (local ODE) and the inverse-biviscous model with
    ``critical_rate`` (default front-selected). ``settings`` holds the protocol and its
    parameters. Global attributes: :func:`suspsim.dst.study.study_attributes`, plus the
    inverse-biviscous ``critical_rate``, ``low_viscosity``, ``high_viscosity``,
    ``lower_stress`` and ``upper_stress``.
    """
    ratios = np.asarray(force_ratios, dtype=float)
    if len(records) != ratios.size:
        raise ValueError(f"{len(records)} records for {ratios.size} forces")
    law = fluid.steady_law()
    model = _model(law, critical_rate)
    gap = geometry.gap
    y = np.asarray(records[0]["y"], dtype=float)
    forces = 2.0 * ratios * fluid.sigma_star / gap
    computed = {
        "local_mean_velocity": np.array([dst_channel_mean_velocity(law, f, gap)
                                         for f in forces]),
        "inverse_biviscous_mean_velocity": np.array([float(model.channel_mean_velocity(f, gap))
                                                     for f in forces]),
        "local_velocity": np.array([dst_channel_profile(law, f, gap, y) for f in forces]),
        "local_fraction": np.array([dst_channel_fraction(law, f, gap, y) for f in forces]),
        "inverse_biviscous_velocity": np.array([model.channel_profile(f, gap, y)
                                                for f in forces])}
    data = {}
    for name in CHANNEL_VARIABLES:
        if name in ("force_ratio", "y", "mean_velocity_error"):
            continue
        if name in computed:
            values = computed[name]
        elif name in ("velocity", "fraction", "shear_rate"):
            values = np.array([np.asarray(r[name], dtype=float) for r in records])
        else:
            values = np.array([float(r.get(name, math.nan)) for r in records])
        if name == "steps":
            values = values.astype(np.int64)
        dims = _PROFILE if np.ndim(values) == 2 else "force_ratio"
        data[name] = (dims, values, _attrs_of(name))
    data["mean_velocity_error"] = (
        "force_ratio", data["mean_velocity"][1] / computed["local_mean_velocity"] - 1.0,
        _attrs_of("mean_velocity_error"))
    dataset = xr.Dataset(data, coords={
        "force_ratio": ("force_ratio", ratios, _attrs_of("force_ratio")),
        "y": ("y", y, _attrs_of("y"))})
    biviscous = {"critical_rate": model.critical_rate, "low_viscosity": model.low_viscosity,
                 "high_viscosity": model.high_viscosity, "lower_stress": model.lower_stress,
                 "upper_stress": model.upper_stress}
    units = {"critical_rate": "sigma_star eta_s-1", "low_viscosity": "eta_s",
             "high_viscosity": "eta_s", "lower_stress": "sigma_star",
             "upper_stress": "sigma_star", "density": "sigma_star L_y2 eta_s-2"}
    dataset.attrs = study_attributes(
        fluid, geometry, records, settings, command=command,
        title=f"{geometry.dimension}D SPH channel flow of a Wyart-Cates suspension, "
              f"phi = {fluid.phi:g}, alpha = {fluid.alpha:g}",
        source="suspsim.dst.channel_study.channel_sweep", extra=biviscous, extra_units=units,
        configuration={"force_ratios": ratios.tolist()})
    return dataset


def _attrs_of(name: str) -> dict[str, str]:
    """CF ``units`` ("1" in scaled units, "s" for wall_time), ``long_name``, ...: as study."""
    return _attrs(name, CHANNEL_VARIABLES)
