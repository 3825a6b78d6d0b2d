"""Errors of SPH fluid runs against exact flows (SPEC §6.1, §6.2), shared by the validation
tests and the speed-against-error study (:mod:`suspsim.convergence`).

- Couette (SPEC §6.1): the measured viscosity σ_xy/γ̇ against the law's μ(γ̇). The stress is
  averaged over whole strain units after a transient, since a sheared lattice makes it
  oscillate with period one strain unit; the standard error is that of the strain-unit means.
- Poiseuille (SPEC §6.2, split force): the time-averaged velocity profile, one bin per lattice
  row (bins misaligned with the rows alias the layering into the profile), against the
  reference solution; the error is the L2 norm of the difference over the bins divided by the
  reference's peak |u|. Rows sliding past each other make the flow rate oscillate with period
  about spacing/u_max, so the average spans many samples of the last ``averaging`` time.

Symbols: σ_xy shear stress [m h^(2−d) τ^-2]; γ̇ shear rate [τ^-1]; μ viscosity
[m h^(2−d) τ^-1]; u_x velocity [h τ^-1]; g body-force acceleration [h τ^-2]; ρ mass density
[m h^-d]; L_y box height [h].
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from suspsim.errors import NumericalError
from suspsim.reference.poiseuille import force_density_for_bingham, split_force_poiseuille_profile
from suspsim.rheology.laws import make_law

#: Stress samples per strain unit in a Couette reading [choice: resolves the lattice ripple].
SAMPLES_PER_UNIT = 50
#: Profile samples over the averaging window of a Poiseuille reading [choice].
PROFILE_SAMPLES = 40
#: Number densities of the validation channels [h^-d]: 3D 4.096 (a 16-cube lattice per 10 h),
#: 2D 16 (at 6.25 the Newtonian profile is 5.6 % off; ``tests/validation/test_sph_flows.py``).
DENSITY_3D, DENSITY_2D_POISEUILLE = 4.096, 16.0


@dataclass(frozen=True)
class Reading:
    """A measured error: ``value`` [1] (signed for Couette, an L2 norm for Poiseuille) and its
    statistical standard error ``stderr`` [1] (NaN where none is estimated)."""

    value: float
    stderr: float


def _require_health(sim) -> None:
    ok, message = sim.health()
    if not ok:
        raise NumericalError(message)


def _chunks(steps: int, size: int) -> list[int]:
    """``steps`` split into runs of ``size`` and the remainder."""
    return [size] * (steps // size) + ([steps % size] if steps % size else [])


def couette_viscosity_ratio(sim, *, transient: float = 1.0, units: int = 3,
                            on_sample: Callable[[Any], None] | None = None) -> Reading:
    """σ_xy/(μ(γ̇) γ̇) − 1 of a Couette ``sim`` (a fresh
    :class:`~suspsim.sph.simulation.Simulation`) averaged over ``units`` whole strain units
    after ``transient`` strain units; ``stderr`` is the standard deviation of the strain-unit
    means over √units. Raises NumericalError if the run left its health limits.
    ``on_sample(sim)``, if given, is called every sampling stride from the start, the transient
    included, to watch the run (it may raise to stop a run that went wrong)."""
    ratios = couette_stress_ratios(sim, ("shear_stress",), transient=transient, units=units,
                                   on_sample=on_sample)
    return Reading(ratios["shear_stress"].value - 1.0, ratios["shear_stress"].stderr)


def couette_stress_ratios(sim, names: tuple[str, ...], *, transient: float = 1.0,
                          units: int = 3, on_sample: Callable[[Any], None] | None = None
                          ) -> dict[str, Reading]:
    """Each stress ``names`` of ``sim.sample()`` (e.g. ``shear_stress``, ``particle_stress``)
    over μ(γ̇) γ̇, averaged as :func:`couette_viscosity_ratio` averages σ_xy, with the
    strain-unit standard error."""
    scene = sim.scene
    rate = scene.flow.shear_rate
    per_unit = max(1, int(round(1.0 / (rate * sim.dt))))
    stride = max(1, per_unit // SAMPLES_PER_UNIT)
    transient_steps = int(round(transient * per_unit))
    for chunk in (_chunks(transient_steps, stride) if on_sample else [transient_steps]):
        sim.advance(chunk)
        if on_sample is not None:
            on_sample(sim)
    per_block = per_unit // stride
    stresses = np.empty((len(names), units * per_block))
    for k in range(stresses.shape[1]):
        sim.advance(stride)
        sample = sim.sample()
        stresses[:, k] = [sample[name] for name in names]
        if on_sample is not None:
            on_sample(sim)
    _require_health(sim)
    expected = float(scene.fluid.law.viscosity(rate)) * rate
    blocks = stresses.reshape(len(names), units, per_block).mean(axis=2) / expected
    stderr = (blocks.std(axis=1, ddof=1) / np.sqrt(units) if units > 1
              else np.full(len(names), np.nan))
    return {name: Reading(float(blocks[n].mean()), float(stderr[n]))
            for n, name in enumerate(names)}


def poiseuille_mean_profile(sim, *, run_time: float, averaging: float
                            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(bin centres y [h], SPH profile u_x [h τ^-1], reference u_x [h τ^-1]) of a split-force
    Poiseuille ``sim``: the profile averaged over the last ``averaging`` [τ] of ``run_time`` [τ]
    (counted from the simulation's current time), one bin per lattice row, and SPEC §6.2 at
    the bin centres. Raises NumericalError if the run left its health limits."""
    scene = sim.scene
    height = scene.box[1]
    bins = int(round(height * scene.number_density ** (1.0 / scene.dimension)))
    sim.advance(int((run_time - averaging) / sim.dt))
    stride = max(1, int(averaging / sim.dt) // PROFILE_SAMPLES)
    mean = np.zeros(bins)
    for _ in range(PROFILE_SAMPLES):
        sim.advance(stride)
        # Before binning: positions that went NaN would fail there with a bare ValueError.
        _require_health(sim)
        profile = sim.profiles(bins)
        mean += profile["velocity_profile"] / PROFILE_SAMPLES
    ref = split_force_poiseuille_profile(scene.fluid.law, scene.density * scene.flow.body_force,
                                         height, profile["y"])
    return profile["y"], mean, ref


def l2_peak_error(profile, reference) -> float:
    """L2 norm of ``profile`` − ``reference`` over the bins divided by the reference's peak
    |u| [1] (both u_x in the same units)."""
    profile, reference = np.asarray(profile), np.asarray(reference)
    return float(np.sqrt(np.mean((profile - reference) ** 2)) / np.max(np.abs(reference)))


def poiseuille_profile_error(sim, *, run_time: float, averaging: float) -> Reading:
    """L2/peak error (:func:`l2_peak_error`) of the profile of :func:`poiseuille_mean_profile`
    against SPEC §6.2. Raises NumericalError if the run left its limits."""
    _, mean, ref = poiseuille_mean_profile(sim, run_time=run_time, averaging=averaging)
    return Reading(l2_peak_error(mean, ref), float("nan"))


def start_from_newtonian_profile(sim, *, threads: int | None = None):
    """A new simulation of ``sim``'s Poiseuille scene restarted with u_x = the split-force
    Newtonian profile scaled to the flow rate of the scene's law (SPEC §6.2), through the
    public state/from_state round trip: the shape then settles in the yielded layers'
    diffusion time instead of the whole channel's flow-rate time."""
    from suspsim.sph.simulation import Simulation

    scene = sim.scene
    height = scene.box[1]
    force_density = scene.density * scene.flow.body_force
    fine = np.linspace(0.0, height, 4001)
    law = scene.fluid.law
    newtonian = make_law("newtonian", {"mu": float(law.viscosity(1.0))})
    scale = (np.mean(np.abs(split_force_poiseuille_profile(law, force_density, height, fine)))
             / np.mean(np.abs(split_force_poiseuille_profile(newtonian, force_density, height,
                                                             fine))))
    state = sim.state()
    state["velocities"][:, 0] = scale * split_force_poiseuille_profile(
        newtonian, force_density, height, state["positions"][:, 1])
    return Simulation.from_state(scene, state, threads=threads or sim.threads)


def channel_error(law: str, params: dict, g: float, dim: int, density: float, height: float,
                  t_run: float, t_avg: float, *, lateral: float | None = None,
                  newtonian_start: bool = False, numerics: dict | None = None,
                  threads: int = 2) -> float:
    """L2/peak error [1] of the split-force Poiseuille profile of ``law`` (``params``) at body
    acceleration ``g`` [h τ⁻²], averaged over the last ``t_avg`` of ``t_run`` [τ]
    (:func:`poiseuille_profile_error`), in a box ``height`` [h] high (two channels of width
    height/2) and ``lateral`` [h] across (default 5 in 3D, 8 in 2D) at ``density`` [h^-d],
    from a lattice jittered by 0.1 spacing. ``newtonian_start``: from the Newtonian profile
    of the reference's flow rate (:func:`start_from_newtonian_profile`) instead of rest;
    ``numerics``: scene keys of the ``numerics`` block."""
    from suspsim.scene import scene_from_dict
    from suspsim.sph.simulation import Simulation

    lateral = lateral or (5.0 if dim == 3 else 8.0)
    box = [lateral, height, lateral] if dim == 3 else [lateral, height]
    scene = scene_from_dict({"dimension": dim, "box": box, "number_density": density,
                             "fluid": {"law": law, "params": params},
                             "flow": {"type": "poiseuille", "body_force": g},
                             "run": {"time": t_run}, "lattice": {"jitter": 0.1},
                             "numerics": dict(numerics or {})})
    sim = Simulation(scene, threads=threads)
    if newtonian_start:
        sim = start_from_newtonian_profile(sim)
    return poiseuille_profile_error(sim, run_time=t_run, averaging=t_avg).value


def newtonian_channel_error(dim: int, density: float, **kwargs) -> float:
    """:func:`channel_error` of the Newtonian channel of the validation tests: W = 5 h,
    g = 0.01 h τ⁻², μ = 1.25 ρ (Re = ρ u_max W/μ ≈ 0.1), three viscous times ρ W²/μ, the last
    one averaged."""
    height, g = 10.0, 0.01
    mu = 1.25 * density
    t_visc = density * (height / 2) ** 2 / mu
    return channel_error("newtonian", {"mu": mu}, g, dim, density, height, 3 * t_visc, t_visc,
                         **kwargs)


def bingham_law(density: float) -> dict[str, float]:
    """Seed 000's Papanastasiou law with μ_pl = 20 per unit of 3D density 4.096 (so a 2D run at
    n = 16 is the same dimensionless problem: equal ρ/μ_pl, time step and Reynolds number)."""
    mu_pl = 20.0 * density / DENSITY_3D
    return {"mu_pl": mu_pl, "mu_0": 99.0 * mu_pl, "M": 100.0}


def bingham_channel_error(bingham: float, dim: int, height: float, t_run: float, t_avg: float,
                          **kwargs) -> float:
    """:func:`channel_error` of :func:`bingham_law` at Bingham number ``bingham`` (defined in
    ``reference.poiseuille``) in channels of width W = height/2 [h]; ``t_run``, ``t_avg`` [τ]
    (the viscous time of a 5 h channel is t_visc = ρ (5 h)²/μ_pl = 5.12 τ)."""
    density = DENSITY_3D if dim == 3 else DENSITY_2D_POISEUILLE
    params = bingham_law(density)
    force = force_density_for_bingham(make_law("papanastasiou", params), height / 2, bingham)
    return channel_error("papanastasiou", params, force / density, dim, density, height, t_run,
                         t_avg, **kwargs)
