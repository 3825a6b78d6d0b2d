"""Validation cases of the speed-against-error study: a scene built from numerical settings
(the sweep axes) and the error of its run against an exact reference.

A case fixes the physics in dimensionless form and lets the numerics vary, so every
configuration solves the same problem:

- ``resolution`` q = h/Δx [1], lattice sites per support radius along a line; the number
  density is n = q^d, snapped so the box (or channel) holds a whole number of rows:
  q ← round(L q)/L for the case's reference length L. Viscosities scale with ρ = n m (fixed
  kinematic viscosity ν = μ/ρ), so the flow, its time scales and its Reynolds numbers do not
  change with q;
- ``dt_coefficient`` C [1] in δt ≤ C ρ h²/μ_max (``numerics.dt_viscous_coefficient``);
- ``wi_target`` Wi = μγ̇/(ρc²) [1], which sets the artificial sound speed
  (``numerics.wi_target``; smaller Wi, faster sound, smaller step);
- ``kernel`` lucy or quintic;
- ``jitter`` [lattice spacings] of the start (0.1 by default, as the validations: a start off
  the lattice; 0 keeps the ordered lattice, on which SPH operators are most accurate);
- case axes: the Couette box side, the channel width, the averaging length.

Couette (SPEC §6.1): particle Reynolds number ρ γ̇ h²/μ(γ̇) = 0.1, γ̇ = 0.01 τ⁻¹ for the
Newtonian case; Papanastasiou with seed 000's μ_0/μ_pl = 99, M = 100 τ and Bingham number
Bn = μ_0/(M μ_pl γ̇). Error: |σ_xy/(μ(γ̇)γ̇) − 1| over whole strain units after one unit of
transient (``validation.flows``).

Poiseuille (SPEC §6.2, split force): width W = L_y/2 [h], lateral sides at least 3.75 h (3D) or 8 h
(2D), rounded up to whole rows. Newtonian: ν = 1.25 h²/τ, u_max = g W²/(8ν) kept at its W = 5 h
value (g = 0.01 h τ⁻² there, Re = u_max W/ν = 0.1; a case at another Re scales g), run 3 t_ν,
t_ν = W²/ν, the last t_ν averaged. Bingham (Papanastasiou,
μ_0/μ_pl = 99, M = 100, ν_pl = 20/4.096 h²/τ): the body force of the Bingham number
(``reference.poiseuille``), started from the Newtonian profile of equal flow rate, run 0.8 t_pl and
the last 0.2 t_pl averaged, t_pl = W²/ν_pl. Error: L2/peak of the averaged profile.

The registry :data:`CASES` also holds the DST cases (:mod:`.dst_cases`) and the dilute
suspension (:mod:`.suspension_cases`); :mod:`.case_base` holds what every kind shares.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping

from suspsim.convergence.case_base import WARM_UP_STEPS, Axis, CaseSettings, Run
from suspsim.convergence.dst_cases import (DSTChannelCase, DSTPointCase, dst_channel,
                                           dst_flow_curve_point)
from suspsim.convergence.suspension_cases import DiluteSuspensionCase, dilute_suspension
from suspsim.errors import InputError
from suspsim.reference.poiseuille import force_density_for_bingham
from suspsim.rheology.laws import make_law
from suspsim.scene import Scene, scene_from_dict
from suspsim.validation.flows import (Reading, couette_viscosity_ratio,
                                      poiseuille_profile_error, start_from_newtonian_profile)

#: Particle Reynolds number ρ γ̇ h²/μ(γ̇) of the Couette cases (as the validation tests).
COUETTE_REYNOLDS = 0.1
#: Imposed rate of the Newtonian Couette cases [τ⁻¹].
COUETTE_RATE = 0.01
#: Seed 000's Papanastasiou ratio μ_0/μ_pl and regularisation M [τ].
PAPANASTASIOU_RATIO, PAPANASTASIOU_M = 99.0, 100.0
#: Kinematic viscosity of the Newtonian channel [h² τ⁻¹] and its force at W = 5 h [h τ⁻²].
CHANNEL_NU, CHANNEL_FORCE, CHANNEL_WIDTH = 1.25, 0.01, 5.0
#: Reynolds number u_max W/ν of that channel at W = 5 h [1] (g W²/(8ν) × W/ν = 0.1).
CHANNEL_REYNOLDS = 0.1
#: Kinematic plastic viscosity of the Bingham channel [h² τ⁻¹] (the validation's μ_pl = 20 at
#: n = 4.096).
BINGHAM_NU = 20.0 / 4.096
#: Default lattice jitter [spacings] (a start off the lattice, as the validations).
JITTER = 0.1


def _common_axes(resolution: float) -> tuple[Axis, ...]:
    return (Axis("resolution", resolution, "1", "lattice sites per support radius h/dx"),
            Axis("dt_coefficient", 0.05, "1", "C in the viscous step limit C rho h^2/mu_max"),
            Axis("wi_target", 1e-3, "1", "Weissenberg-like number mu gdot/(rho c^2) of the "
                                         "sound speed"),
            Axis("kernel", "lucy", "1", "SPH kernel (lucy or quintic)"),
            Axis("jitter", JITTER, "1", "random displacement of the start lattice [spacings]"))


@dataclass(frozen=True)
class Case(CaseSettings):
    """An SPH fluid case: ``scene(settings)`` → scene dict, ``measure(sim, settings)`` →
    :class:`~suspsim.validation.flows.Reading` of the error on a fresh simulation
    (``restart(sim)`` first replaces the start where the case needs one)."""

    name: str
    description: str
    reference: str
    axes: tuple[Axis, ...]
    scene: Callable[[Mapping[str, Any]], dict]
    measure: Callable[[Any, Mapping[str, Any]], Reading]
    restart: Callable[[Any], Any] | None = field(default=None)

    def build(self, settings: Mapping[str, Any]) -> Scene:
        """The validated scene of ``settings`` (a full set, see :meth:`settings`)."""
        return scene_from_dict(self.scene(settings), source=f"case {self.name}")

    def warm_up(self, settings: Mapping[str, Any], threads: int) -> None:
        """Two steps of the same scene (and restart), so compiled code is loaded."""
        from suspsim.sph.simulation import Simulation

        warm = Simulation(self.build(settings), threads=threads)
        warm.advance(WARM_UP_STEPS)
        if self.restart is not None:
            self.restart(warm).advance(WARM_UP_STEPS)

    def execute(self, settings: Mapping[str, Any], threads: int) -> Run:
        """Build, (re)start and measure one simulation of ``settings``."""
        from suspsim.sph.simulation import Simulation

        t0 = time.perf_counter()
        scene = self.build(settings)
        sim = Simulation(scene, threads=threads)
        if self.restart is not None:
            sim = self.restart(sim)
        t1 = time.perf_counter()
        reading = self.measure(sim, settings)
        return Run(reading, sim.n_particles, sim.step_count, sim.dt, sim.sound_speed,
                   scene.number_density, scene.number_density ** (1.0 / scene.dimension),
                   t1 - t0, time.perf_counter() - t1)


def snapped_resolution(resolution: float, length: float) -> float:
    """q rounded so that ``length`` [h] holds a whole number (≥ 3) of lattice rows."""
    rows = max(3, int(round(resolution * length)))
    return rows / length


def _start_and_numerics(settings) -> dict:
    """The scene's ``lattice`` and ``numerics`` blocks of the common axes."""
    return {"lattice": {"jitter": float(settings["jitter"])},
            "numerics": {"dt_viscous_coefficient": float(settings["dt_coefficient"]),
                         "wi_target": float(settings["wi_target"])}}


def _couette_scene(dim: int, law: str, params_of_density: Callable[[float], dict],
                   rate: float) -> Callable[[Mapping[str, Any]], dict]:
    def scene(settings):
        side = float(settings["side"])
        q = snapped_resolution(float(settings["resolution"]), side)
        density = q ** dim
        strain = float(settings["transient"]) + int(settings["units"])
        return {"dimension": dim, "box": [side] * dim, "number_density": density,
                "kernel": settings["kernel"],
                "fluid": {"law": law, "params": params_of_density(density)},
                "flow": {"type": "couette", "shear_rate": rate},
                "run": {"strain": strain, "threads": 1},
                **_start_and_numerics(settings)}
    return scene


def _couette_measure(sim, settings) -> Reading:
    return couette_viscosity_ratio(sim, transient=float(settings["transient"]),
                                   units=int(settings["units"]))


def _couette_axes(dim: int) -> tuple[Axis, ...]:
    return _common_axes(1.6 if dim == 3 else 2.5) + (
        Axis("side", 7.5 if dim == 3 else 10.0, "h", "box side"),
        Axis("transient", 1.0, "1", "strain units discarded"),
        Axis("units", 3, "1", "strain units averaged"))


def newtonian_couette(dim: int = 3) -> Case:
    """Newtonian Couette at Re_p = 0.1 (μ = ρ γ̇ h²/Re_p)."""
    def params(density):
        return {"mu": density * COUETTE_RATE / COUETTE_REYNOLDS}
    return Case(f"couette_newtonian_{dim}d", f"Newtonian Couette ({dim}D), Re_p = 0.1",
                "sigma_xy = mu gdot (SPEC 6.1)", _couette_axes(dim),
                _couette_scene(dim, "newtonian", params, COUETTE_RATE), _couette_measure)


def papanastasiou_couette(bingham: float = 9.9, dim: int = 3) -> Case:
    """Papanastasiou Couette (μ_0/μ_pl = 99, M = 100) at Bingham number ``bingham``, Re_p = 0.1
    at the imposed rate γ̇ = (μ_0/μ_pl)/(M Bn)."""
    rate = PAPANASTASIOU_RATIO / (PAPANASTASIOU_M * bingham)
    x = PAPANASTASIOU_M * rate
    relative = 1.0 + PAPANASTASIOU_RATIO * -math.expm1(-x) / x

    def params(density):
        mu_pl = density * rate / (COUETTE_REYNOLDS * relative)
        return {"mu_pl": mu_pl, "mu_0": PAPANASTASIOU_RATIO * mu_pl, "M": PAPANASTASIOU_M}
    return Case(f"couette_papanastasiou_bn{bingham:g}_{dim}d",
                f"Papanastasiou Couette ({dim}D), Bn = {bingham:g}, Re_p = 0.1",
                "sigma_xy = mu(gdot) gdot (SPEC 6.1)", _couette_axes(dim),
                _couette_scene(dim, "papanastasiou", params, rate), _couette_measure)


def _channel_axes(dim: int) -> tuple[Axis, ...]:
    return _common_axes(1.6 if dim == 3 else 4.0) + (
        Axis("width", CHANNEL_WIDTH, "h", "channel width W = L_y/2"),)


def _channel_box(settings, dim: int) -> tuple[list[float], float]:
    height = 2.0 * float(settings["width"])
    q = snapped_resolution(float(settings["resolution"]), height)
    lateral = math.ceil((3.75 if dim == 3 else 8.0) * q) / q
    box = [lateral, height, lateral] if dim == 3 else [lateral, height]
    return box, q ** dim


def newtonian_poiseuille(dim: int = 3, reynolds: float = CHANNEL_REYNOLDS) -> Case:
    """Newtonian split-force Poiseuille, ν = 1.25, u_max kept at its W = 5 h value, the channel
    Reynolds number ``reynolds`` = u_max W/ν at W = 5 h (0.1: g = 0.01 there)."""
    def scene(settings):
        box, density = _channel_box(settings, dim)
        width = float(settings["width"])
        g = (CHANNEL_FORCE * (reynolds / CHANNEL_REYNOLDS)
             * (CHANNEL_WIDTH / width) ** 2)
        t_visc = width ** 2 / CHANNEL_NU
        return {"dimension": dim, "box": box, "number_density": density,
                "kernel": settings["kernel"],
                "fluid": {"law": "newtonian", "params": {"mu": CHANNEL_NU * density}},
                "flow": {"type": "poiseuille", "body_force": g},
                "run": {"time": 3.0 * t_visc, "threads": 1},
                **_start_and_numerics(settings)}

    def measure(sim, settings):
        t_visc = float(settings["width"]) ** 2 / CHANNEL_NU
        return poiseuille_profile_error(sim, run_time=3.0 * t_visc, averaging=t_visc)
    tag = "" if reynolds == CHANNEL_REYNOLDS else f"_re{reynolds:g}"
    return Case(f"poiseuille_newtonian{tag}_{dim}d",
                f"Newtonian Poiseuille ({dim}D), Re = {reynolds:g} at W = 5 h",
                "parabolic split-force profile (SPEC 6.2)", _channel_axes(dim), scene, measure)


def bingham_poiseuille(bingham: float = 1.0, dim: int = 3) -> Case:
    """Papanastasiou split-force Poiseuille at Bingham number ``bingham``, started from the
    Newtonian profile of equal flow rate."""
    def law(density):
        mu_pl = BINGHAM_NU * density
        return {"mu_pl": mu_pl, "mu_0": PAPANASTASIOU_RATIO * mu_pl, "M": PAPANASTASIOU_M}

    def scene(settings):
        box, density = _channel_box(settings, dim)
        width = float(settings["width"])
        force = force_density_for_bingham(make_law("papanastasiou", law(density)), width,
                                          bingham)
        t_pl = width ** 2 / BINGHAM_NU
        return {"dimension": dim, "box": box, "number_density": density,
                "kernel": settings["kernel"],
                "fluid": {"law": "papanastasiou", "params": law(density)},
                "flow": {"type": "poiseuille", "body_force": force / density},
                "run": {"time": 0.8 * t_pl, "threads": 1},
                **_start_and_numerics(settings)}

    def measure(sim, settings):
        t_pl = float(settings["width"]) ** 2 / BINGHAM_NU
        return poiseuille_profile_error(sim, run_time=0.8 * t_pl, averaging=0.2 * t_pl)
    return Case(f"poiseuille_bingham{bingham:g}_{dim}d",
                f"Bingham Poiseuille ({dim}D), Bn = {bingham:g}",
                "plug-flow split-force profile (SPEC 6.2)", _channel_axes(dim), scene, measure,
                restart=start_from_newtonian_profile)


#: Any kind of case: an SPH fluid case, a DST flow-curve point or channel, a dilute suspension.
AnyCase = Case | DSTPointCase | DSTChannelCase | DiluteSuspensionCase

#: The registered cases by name.
CASES: dict[str, AnyCase] = {case.name: case for case in (
    newtonian_couette(3), newtonian_couette(2), papanastasiou_couette(9.9, 3),
    papanastasiou_couette(99.0, 3), newtonian_poiseuille(3), newtonian_poiseuille(2),
    bingham_poiseuille(1.0, 3), bingham_poiseuille(3.0, 3), bingham_poiseuille(5.0, 3),
    bingham_poiseuille(10.0, 3),
    # the held-out set of docs/figures/error_model/run_holdout_blind.sh (training data since
    # run_holdout_blind_2.sh)
    papanastasiou_couette(9.9, 2), bingham_poiseuille(7.0, 3), newtonian_poiseuille(3, 1.0),
    # the blind held-out set of docs/figures/error_model/run_holdout_blind_2.sh (training data
    # since run_holdout_blind_3.sh)
    papanastasiou_couette(30.0, 3), newtonian_poiseuille(2, 0.5), bingham_poiseuille(2.0, 3),
    # the blind held-out set of docs/figures/error_model/run_holdout_blind_3.sh: never fitted on
    papanastasiou_couette(3.0, 2), bingham_poiseuille(4.0, 3), newtonian_poiseuille(2, 0.25),
    # the blind held-out set of docs/figures/error_model/run_holdout_blind_4.sh: never fitted on
    papanastasiou_couette(20.0, 2), bingham_poiseuille(6.0, 3), newtonian_poiseuille(3, 0.25),
    # the blind held-out set of docs/figures/error_model/run_holdout_blind_5.sh (the verified
    # picker): never fitted on
    papanastasiou_couette(6.0, 2), bingham_poiseuille(8.0, 3), newtonian_poiseuille(2, 1.0),
    # the blind held-out set of docs/figures/error_model/run_holdout_blind_6.sh: never fitted on
    papanastasiou_couette(45.0, 2), bingham_poiseuille(2.5, 3), bingham_poiseuille(9.0, 3),
    newtonian_poiseuille(3, 0.5),
    dst_flow_curve_point(0.54, 2.5), dst_flow_curve_point(0.50, 1.0), dst_channel(0.54, 10.0),
    dilute_suspension(0.03))}


def get_case(name: str) -> AnyCase:
    """The registered case ``name``; an unknown name is an InputError listing them."""
    try:
        return CASES[name]
    except KeyError:
        raise InputError("speed_error", f"unknown case '{name}'; known: {', '.join(CASES)}",
                         key=name) from None
