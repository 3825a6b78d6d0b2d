"""The ``flows`` study (issue 6): seed 000's Figs. 1 and 2 as workflow jobs.

- Start-up (Fig. 1): one Lees–Edwards Couette start-up of a Papanastasiou fluid from rest,
  :func:`suspsim.validation.startup.papanastasiou_startup` (its docstring has the set-up and the
  1D reference), run by :func:`simulate_startup`.
- Poiseuille (Fig. 2): one split-force channel per Bingham number, run by
  :func:`simulate_poiseuille` and measured by
  :func:`suspsim.validation.flows.poiseuille_mean_profile` against SPEC §6.2.

Channel set-up (:func:`poiseuille_scene`). Seed 000's law μ = μ_pl + μ_0 (1 − e^(−Mγ̇))/(Mγ̇)
with μ_0/μ_pl = 99; Bn = τ_y/(μ_pl γ̇_c), γ̇_c = U/(W/2), U the ideal (M → ∞) fluid's
centre-line velocity (:mod:`suspsim.reference.poiseuille`). Every channel has the same width W,
plastic viscosity μ_pl = ν_pl ρ and channel Reynolds number Re = ρ U W/μ_pl [choice: the
dimensionless problem is then fixed by Bn, μ_0/μ_pl and Re, and the runs differ in Bn only]:
U = Re ν_pl/W, τ_y = Bn μ_pl γ̇_c, μ_0 = 99 μ_pl, M = μ_0/τ_y, and the driving force density
F from :func:`~suspsim.reference.poiseuille.force_density_for_bingham`. Bn = 0 is the
Newtonian fluid μ = μ_pl at F = 8 μ_pl U/W². At Bn = 10, W = 15 h, Re = 2.28 this is the 2D
validation run of ``tests/validation/test_sph_flows.py`` (there M = 100 τ, here 100.04 τ).
Seed 000 normalises every profile by the maximum of the Bn = 0 flow under the same force; the
equivalent here, where each Bn has its own force, is the Newtonian centre-line velocity at the
run's force, U_N = F W²/(8 μ_pl) (stored per run as ``newtonian_velocity``).

Gathering lives in :mod:`suspsim.stages.flows_gather` and the figures in
:mod:`suspsim.stages.flows_figures`, so that editing them does not re-run the simulations
(the rules' code fingerprints).

Symbols and units (simulation units, :mod:`suspsim.io.variables`): W channel width = L_y/2 [h];
ρ = n m density [m h^-d] (m = 1); ν_pl kinematic plastic viscosity [h² τ^-1]; U, U_N
velocities [h τ^-1]; F force density [m h^(1-d) τ^-2]; τ_y yield stress [m h^(2-d) τ^-2];
M regularisation time [τ]; t_pl = W²/ν_pl the plastic viscous time [τ].
"""
from __future__ import annotations

import logging
import math
import os
import time as wallclock
from typing import Any, Mapping

import numpy as np
import xarray as xr

from ..errors import InputError, NumericalError
from ..io.atomic import atomic_path
from ..io.provenance import provenance
from ..io.variables import UNIT_SYSTEM, simulation_units
from ..reference.poiseuille import force_density_for_bingham, split_force_poiseuille_profile
from ..rheology.laws import make_law
from ..scene import scene_from_dict
from ..validation.flows import (l2_peak_error, poiseuille_mean_profile,
                                start_from_newtonian_profile)
from ..validation.startup import (REFERENCES, VISCOSITY_RATIO, papanastasiou_startup,
                                  profile_error)

log = logging.getLogger(__name__)

#: Points of the fine reference profile across the box height [choice: smooth lines].
FINE_POINTS = 801


def startup_job(settings: Mapping[str, Any]) -> dict | None:
    """The start-up run's settings (``bingham``, ``side``, ``number_density``, ``strains``,
    ``jitter``, ``seed``) from the ``flows`` config block; None without strains (no run)."""
    startup = settings.get("startup") or {}
    strains = [float(s) for s in startup.get("strains") or []]
    if not strains:
        return None
    if len(set(strains)) != len(strains):
        raise InputError("flows.startup.strains", f"a strain is listed twice in {strains}",
                         key="strains")
    return {"bingham": float(startup["bingham"]), "side": float(startup["side"]),
            "number_density": float(startup["number_density"]), "strains": sorted(strains),
            "jitter": float(startup["jitter"]), "seed": int(startup["seed"])}


def poiseuille_jobs(settings: Mapping[str, Any]) -> list[dict]:
    """One channel run's settings per Bingham number of the ``flows.poiseuille`` block, in
    config order: ``bingham`` and the block's shared keys (see the config schema).

    Raises InputError for a repeated Bingham number or an averaging window longer than the run.
    """
    block = settings.get("poiseuille") or {}
    binghams = [float(b) for b in block.get("binghams") or []]
    if len(set(binghams)) != len(binghams):
        raise InputError("flows.poiseuille.binghams", f"a Bingham number is listed twice in "
                         f"{binghams}", key="binghams")
    if binghams and not 0 < float(block["averaging"]) <= float(block["run_time"]):
        raise InputError("flows.poiseuille.averaging", f"averaging {block['averaging']} must "
                         f"lie in (0, run_time = {block['run_time']}]", key="averaging")
    shared = {"dimension": int(block.get("dimension", 2)),
              **{key: float(block[key]) for key in ("number_density", "width", "lateral",
                                                    "reynolds", "plastic_viscosity",
                                                    "run_time", "averaging", "jitter")},
              "start": str(block["start"]), "seed": int(block["seed"])}
    return [{"bingham": b, **shared} for b in binghams]


def find_poiseuille_job(settings: Mapping[str, Any], bingham: float) -> dict:
    """The channel run of ``bingham``; InputError when the config has none."""
    for job in poiseuille_jobs(settings):
        if math.isclose(job["bingham"], float(bingham), rel_tol=1e-12, abs_tol=0.0):
            return job
    raise InputError("flows.poiseuille.binghams", f"no channel run at Bn = {bingham}")


def channel_law(job: Mapping[str, Any]) -> tuple[str, dict, float, float]:
    """(law name, law params, force density F [m h^(1-d) τ^-2], U_N [h τ^-1]) of one channel
    run (module docstring): the Newtonian fluid at Bn = 0, else Papanastasiou."""
    width, bingham = float(job["width"]), float(job["bingham"])
    mu_pl = float(job["plastic_viscosity"]) * float(job["number_density"])
    velocity = float(job["reynolds"]) * float(job["plastic_viscosity"]) / width
    if bingham == 0:
        force = 8.0 * mu_pl * velocity / width ** 2
        return "newtonian", {"mu": mu_pl}, force, velocity
    yield_stress = bingham * mu_pl * 2.0 * velocity / width
    mu_0 = VISCOSITY_RATIO * mu_pl
    params = {"mu_pl": mu_pl, "mu_0": mu_0, "M": mu_0 / yield_stress}
    force = force_density_for_bingham(make_law("papanastasiou", params), width, bingham)
    return "papanastasiou", params, force, force * width ** 2 / (8.0 * mu_pl)


def plastic_time(job: Mapping[str, Any]) -> float:
    """t_pl = W²/ν_pl [τ] of one channel run, the unit of its ``run_time`` and ``averaging``."""
    return float(job["width"]) ** 2 / float(job["plastic_viscosity"])


def poiseuille_scene(job: Mapping[str, Any]) -> dict:
    """The scene dict of one channel run: box L_y = 2W high and ``lateral`` [h] across, run for
    ``run_time`` t_pl."""
    dim, width, lateral = int(job["dimension"]), float(job["width"]), float(job["lateral"])
    law, params, force, _ = channel_law(job)
    box = [lateral, 2.0 * width] + [lateral] * (dim - 2)
    return {"dimension": dim, "box": box, "number_density": float(job["number_density"]),
            "fluid": {"law": law, "params": params},
            "flow": {"type": "poiseuille", "body_force": force / float(job["number_density"])},
            "run": {"time": float(job["run_time"]) * plastic_time(job)},
            "lattice": {"jitter": float(job["jitter"])}, "seed": int(job["seed"])}


def simulate_startup(job: Mapping[str, Any], out_nc: str | os.PathLike, *,
                     threads: int = 1) -> None:
    """Run the start-up of ``job`` (:func:`startup_job`) and write its Dataset atomically.

    Raises NumericalError, writing nothing, when the run ended outside its health limits (as
    the channel runs do): its profiles would be a blow-up's."""
    data = papanastasiou_startup(threads=threads, **job)
    if not data.attrs["healthy"]:
        raise NumericalError(f"start-up at Bn {job['bingham']:g}: {data.attrs['health']}")
    with atomic_path(out_nc) as tmp:
        data.to_netcdf(tmp, engine="netcdf4")
    errors = ", ".join(f"{s:.3g}: {100 * e:.2f} %" for s, e in
                       zip(data["strain"].values, profile_error(data).values))
    log.info("wrote %s: %d particles, %.1f s; max |v_SPH - v_1D|/(gdot L) by strain: %s",
             out_nc, data.attrs["n_particles"], data.attrs["wall_time_s"], errors)


def simulate_poiseuille(job: Mapping[str, Any], out_nc: str | os.PathLike, *,
                        threads: int = 1) -> None:
    """Run one channel of ``job`` (:func:`poiseuille_jobs`) from rest or from the Newtonian
    profile of equal flow rate (``start``), and write its profile Dataset atomically: the SPH
    bin means and the reference at the bins (``y``) and on a fine grid (``y_fine``)."""
    from ..sph.simulation import Simulation

    scene = scene_from_dict(poiseuille_scene(job), source=f"flows channel Bn = {job['bingham']}")
    started = wallclock.perf_counter()
    sim = Simulation(scene, threads=threads)
    if job["start"] == "newtonian":
        sim = start_from_newtonian_profile(sim)
    y, velocity, reference = poiseuille_mean_profile(
        sim, run_time=scene.total_time, averaging=float(job["averaging"]) * plastic_time(job))
    wall = wallclock.perf_counter() - started
    data = channel_dataset(job, scene, y, velocity, reference)
    data.attrs.update(n_particles=sim.n_particles, dt=sim.dt, sound_speed=sim.sound_speed,
                      steps=sim.step_count, threads=sim.threads, wall_time_s=wall)
    with atomic_path(out_nc) as tmp:
        data.to_netcdf(tmp, engine="netcdf4")
    log.info("wrote %s: Bn %g, L2/peak %.2f %%, %d particles, %d steps, %.1f s", out_nc,
             job["bingham"], 100 * data.attrs["profile_error"], sim.n_particles,
             sim.step_count, wall)


def channel_dataset(job: Mapping[str, Any], scene, y, velocity, reference) -> xr.Dataset:
    """The Dataset of one channel run from its bin centres ``y`` [h] and the SPH and reference
    profiles [h τ^-1] at them; the attributes hold the law (μ_pl [m h^(2-d) τ^-1], τ_y
    [m h^(2-d) τ^-2], M [τ], NaN for the Newtonian), force, U_N, Re, the L2/peak error
    (:func:`~suspsim.validation.flows.l2_peak_error`) and the provenance."""
    dim = scene.dimension
    law, params, force, newtonian_velocity = channel_law(job)
    height = scene.box[1]
    y_fine = np.linspace(0.0, height, FINE_POINTS)
    fine = split_force_poiseuille_profile(scene.fluid.law, force, height, y_fine)
    speed = {"units": "1", "simulation_units": simulation_units((1, 0, -1, 0), dim)}
    length = {"units": "1", "simulation_units": "h"}
    coords = {"y": ("y", np.asarray(y), {**length, "long_name": "bin centre along the "
                                                                 "gradient direction"}),
              "y_fine": ("y_fine", y_fine, {**length, "long_name": "height of the fine "
                                                                   "reference profile"})}
    data = {"velocity": ("y", np.asarray(velocity), {**speed, "long_name": "SPH flow velocity "
                                                     "u_x, bin and time mean"}),
            "reference_velocity": ("y", np.asarray(reference), {
                **speed, "long_name": "reference u_x at the bin centres (SPEC 6.2)"}),
            "reference_velocity_fine": ("y_fine", fine, {
                **speed, "long_name": "reference u_x on the fine grid (SPEC 6.2)"})}
    attrs = {"title": "Split-force Poiseuille flow of a Papanastasiou fluid against the "
                      "numerical solution",
             "references": REFERENCES, "unit_system": UNIT_SYSTEM,
             "bingham_number": float(job["bingham"]), "law": law,
             **{f"law_{k}": float(v) for k, v in params.items()},
             "dimension": dim, "number_density": scene.number_density,
             "density": scene.density, "channel_width": 0.5 * height,
             "lateral_side": float(job["lateral"]), "channel_reynolds_number": job["reynolds"],
             "plastic_viscosity": float(job["plastic_viscosity"]) * scene.density,
             "yield_stress": params["mu_0"] / params["M"] if law == "papanastasiou" else 0.0,
             "regularisation_time": params.get("M", float("nan")),
             "force_density": force, "newtonian_velocity": newtonian_velocity,
             "newtonian_velocity_comment": "centre-line velocity F W^2/(8 mu_pl) of the "
                                           "Newtonian fluid mu_pl under the run's force [h tau-1]",
             "run_time": scene.total_time,
             "averaging_time": float(job["averaging"]) * plastic_time(job),
             "start": job["start"], "jitter": float(job["jitter"]), "seed": int(job["seed"]),
             "profile_error": l2_peak_error(velocity, reference), **provenance()}
    return xr.Dataset(data, coords=coords, attrs=attrs)
