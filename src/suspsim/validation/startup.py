"""Seed 000 Fig. 1: start-up of Couette flow of a Papanastasiou fluid from rest, SPH against 1D.

Set-up (seed 000, "Couette flow is studied for the model of Papanastasiou with a Bn = 0.1"): a
cubic Lees–Edwards box of side L, fluid at rest at t = 0, rate γ̇ imposed through the sheared
faces (SPEC §2.7). Law (SPEC §1.1) μ(γ̇) = μ_pl + μ_0 (1 − e^(−Mγ̇))/(Mγ̇) with seed 000's
μ_0/μ_pl = 99 and M = 100; the Bingham number Bn = μ_0/(M μ_pl γ̇) fixes the rate,
γ̇ = (μ_0/μ_pl)/(M Bn), and μ_pl follows from the particle Reynolds number
Re_p = ρ γ̇ h²/μ(γ̇) = 0.1 [choice, as the other validation runs: at Re ≪ 1 only the
dimensionless law matters, SPEC §7]. Early on, the fluid near the faces is sheared hard and thins
to ≈ μ_pl while the middle, at low rate, is ≈ 100 μ_pl and barely moves; the profile then
relaxes to the linear one.

Reference: the same law, density ρ, gap L and velocity jump V = γ̇ L in the 1D finite-volume
solution of :func:`suspsim.reference.couette_startup.couette_startup`, whose walls at ∓V/2 are
exactly the Lees–Edwards faces (see that module). The SPH profile is a bin mean of particle
velocities, one bin per lattice row (bins that split rows alias the layering into the profile),
compared with the mean of the reference over the same bin.

The box Reynolds number Re_L = ρ γ̇ L²/μ(γ̇) sets the length of the transient in strain: the
slowest mode of the late, nearly Newtonian flow decays over a strain Re_L/(4π²), 0.14 at
L = 7.5 h. Measured (seed 1, 3D, n = 4.096 per h³, jitter 0.1): the largest SPH − 1D difference
over bins is 1.6 % of V at strain 0.05, where the thinned layers are ≈ 1 h thick, and ≤ 0.9 %
from strain 0.1 on (L = 7.5 h); 2.1 % and ≤ 1 % at L = 5 h.

Symbols: L box side [h]; γ̇ imposed rate [τ^-1]; V = γ̇ L; ρ = n m density [m h^-3]; y height in
[0, L) [h]; v_x flow velocity [h τ^-1]; Bn Bingham number [1]; Re_p particle and Re_L box
Reynolds numbers [1].
"""
from __future__ import annotations

import math
import time as wallclock

import numpy as np
import xarray as xr

from suspsim.io.provenance import provenance
from suspsim.io.variables import UNIT_SYSTEM, simulation_units
from suspsim.reference.couette_startup import bin_means, cell_centres, couette_startup
from suspsim.scene import scene_from_dict
from suspsim.sph.simulation import Simulation

#: Seed 000's law: μ_0/μ_pl and M [τ].
VISCOSITY_RATIO = 99.0
REGULARISATION = 100.0
#: Particle Reynolds number ρ γ̇ h²/μ(γ̇) of the run [choice, module docstring].
PARTICLE_REYNOLDS = 0.1
#: Finite-volume cells of the reference per SPH bin (its error is ≲ 1e-4 V at 40, see the
#: unit test of the reference).
CELLS_PER_BIN = 40
#: Strains at which profiles are taken by default: early (front in the outer third), middle,
#: and late (linear).
DEFAULT_STRAINS = (0.05, 0.1, 0.2, 0.4, 1.0, 3.0)

REFERENCES = ("Martys, George, Chun & Lootens, Rheol. Acta 49, 1059 (2010), Fig. 1; "
              "Papanastasiou, J. Rheol. 31, 385 (1987) (regularised Bingham law)")

_VELOCITY = {"units": "1", "simulation_units": simulation_units((1, 0, -1, 0), 3)}


def papanastasiou_parameters(bingham: float, number_density: float) -> tuple[float, dict]:
    """(γ̇ [τ^-1], law parameters) of the module docstring for Bn and n [h^-3]."""
    rate = VISCOSITY_RATIO / (REGULARISATION * bingham)
    x = REGULARISATION * rate
    relative = 1.0 + VISCOSITY_RATIO * -math.expm1(-x) / x
    mu_pl = number_density * rate / (PARTICLE_REYNOLDS * relative)
    return rate, {"mu_pl": mu_pl, "mu_0": VISCOSITY_RATIO * mu_pl, "M": REGULARISATION}


def papanastasiou_startup(*, bingham: float = 0.1, side: float = 7.5,
                          number_density: float = 4.096, strains=DEFAULT_STRAINS,
                          jitter: float = 0.1, seed: int = 1,
                          threads: int | None = None) -> xr.Dataset:
    """SPH and 1D-reference velocity profiles of the start-up at the given ``strains``.

    ``side`` L [h] of the cubic box, ``number_density`` n [h^-3], ``jitter`` of the initial
    lattice [spacings], ``seed`` of the jitter, ``threads`` of the solver (None: the scene's
    default, every core). Returns a Dataset on (``strain``, ``y``) with ``velocity`` (SPH) and
    ``reference_velocity`` (1D, same bins) v_x [h τ^-1], ``reference_velocity_fine`` on the
    reference's cells (``y_fine``), ``time`` [τ]; attributes hold the law, rate, box, particle
    count, step, sound speed, wall time and provenance. Strains are those actually reached
    (whole steps), the first at or after each requested one.
    """
    rate, params = papanastasiou_parameters(bingham, number_density)
    scene = scene_from_dict({
        "dimension": 3, "box": [side] * 3, "number_density": number_density,
        "fluid": {"law": "papanastasiou", "params": params},
        "flow": {"type": "couette", "shear_rate": rate},
        "run": {"strain": float(max(strains)), "start": "rest"},
        "lattice": {"jitter": jitter}, "seed": seed})
    bins = scene.lattice_counts[1]
    started = wallclock.perf_counter()
    sim = Simulation(scene, threads=threads)
    reached, profiles = [], []
    for strain in sorted(strains):
        sim.advance(max(0, math.ceil(strain / (rate * sim.dt) - 1e-9) - sim.step_count))
        reached.append(sim.strain)
        profiles.append(sim.profiles(bins)["velocity_profile"])
    ok, message = sim.health()
    wall = wallclock.perf_counter() - started
    times = np.array(reached) / rate
    law = scene.fluid.law
    cells = bins * CELLS_PER_BIN
    fine = couette_startup(law, scene.density, side, rate * side, times, cells=cells)
    y = (np.arange(bins) + 0.5) * side / bins
    coords = {"strain": ("strain", np.array(reached), {"units": "1",
                                                       "long_name": "shear strain γ̇ t"}),
              "y": ("y", y, {"units": "1", "simulation_units": "h",
                             "long_name": "bin centre along the gradient direction"}),
              "y_fine": ("y_fine", cell_centres(side, cells),
                         {"units": "1", "simulation_units": "h",
                          "long_name": "cell centre of the 1D reference"})}
    data = {
        "time": ("strain", times, {"units": "1", "simulation_units": "tau",
                                   "long_name": "simulated time"}),
        "velocity": (("strain", "y"), np.array(profiles),
                     {**_VELOCITY, "long_name": "SPH flow velocity v_x, bin mean"}),
        "reference_velocity": (("strain", "y"), bin_means(fine, bins),
                               {**_VELOCITY, "long_name": "1D reference v_x, bin mean"}),
        "reference_velocity_fine": (("strain", "y_fine"), fine,
                                    {**_VELOCITY, "long_name": "1D reference v_x per cell"})}
    attrs = {"title": "Start-up of Lees-Edwards Couette flow of a Papanastasiou fluid from rest",
             "references": REFERENCES, "unit_system": UNIT_SYSTEM,
             "bingham_number": bingham, "shear_rate": rate, "box_side": side,
             "number_density": number_density, "density": scene.density,
             "particle_reynolds_number": PARTICLE_REYNOLDS,
             "box_reynolds_number": scene.density * rate * side ** 2 / float(law.viscosity(rate)),
             **{f"law_{k}": v for k, v in params.items()}, "law": "papanastasiou",
             "jitter": jitter, "seed": seed, "n_particles": sim.n_particles, "dt": sim.dt,
             "sound_speed": sim.sound_speed, "threads": sim.threads, "wall_time_s": wall,
             "health": message, "healthy": int(ok), "reference_cells": cells,
             **provenance()}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def profile_error(data: xr.Dataset) -> xr.DataArray:
    """max over bins of |v_SPH − v_ref|/(γ̇ L) [1] at each strain (L the box side)."""
    scale = data.attrs["shear_rate"] * data.attrs["box_side"]
    return (np.abs(data["velocity"] - data["reference_velocity"]) / scale).max("y")
