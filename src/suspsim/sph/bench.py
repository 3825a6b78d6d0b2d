"""Benchmark of the full SPH step (density, gradient, normalisation and force passes).

The issue's performance scene: a 3D periodic Lees–Edwards Couette box of side 20 h at number
density 4.096 per h³ (32³ = 32,768 particles, jittered simple-cubic lattice), Lucy kernel,
default numerics (bulk correction and dissipation normalisation on); other sizes k³ in a box
of side k/1.6 h for the scaling with N (``suspsim bench --particles``). Scenes:

- ``fluid-newtonian``: μ = 1, γ̇ = 0.0244 (particle Reynolds number ρ γ̇ h²/μ = 0.1);
- ``fluid-newtonian-unnormalised``: the same fluid without the dissipation normalisation
  (``numerics.viscous_normalisation: false``; bulk correction kept): the work of a plain SPH
  viscous loop such as LAMMPS's Morris pair style, for a like-for-like comparison. Its viscosity
  error is larger (SPEC §2.3: the discrete fourth moment falls short of its continuum value);
  the bench reports it;
- ``fluid-papanastasiou``: μ_pl = 0.01, μ_0 = 0.99, M = 100 (seed 000: μ_0/μ_pl = 99), γ̇ = 0.01;
- ``suspension-newtonian``: the Newtonian fluid with spheres of radius 2.5 h at φ = 0.4 (the
  bodies' shell particles count as particles; the start's relaxation is cut to 100 steps, a
  benchmark measures cost, not physics; its default sound speed and step are the dense
  suspension's, ``timestep.crowding_factor``, so per unit strain it takes 1.3 × the fluid's
  steps);
- ``suspension-papanastasiou``: the Papanastasiou fluid with the same spheres (adds the
  shear-rate pass and its smoothing, ``terms.rate_smoothing``);
- ``dst-2d``: the 2D Wyart–Cates solver between walls (:mod:`suspsim.dst.bench`; a different
  solver, which reports speed and memory only).

:func:`benchmark` times ``n_steps`` steps after :data:`WARM_UP` untimed steps and
reports particle-steps per second (N × steps / wall time), neighbour-list rebuilds included,
and the error reached (see :func:`benchmark`). :func:`paired_cost` (``suspsim bench
--against-fluid``) times a suspension scene against its fluid in one process, alternating
slices of steps, so that a shared machine's changing load falls on both.
"""
from __future__ import annotations

import time

import numba
import numpy as np

from suspsim.dst.bench import SCENE as DST_SCENE
from suspsim.dst.bench import benchmark_dst
from suspsim.scene import scene_from_dict
from suspsim.sph.density import body_particle_density, mass_density, summation_density
from suspsim.sph.simulation import SUPPORT, Simulation
from suspsim.sph.terms.force_pass import force_finish, force_sums
from suspsim.sph.terms.rate_smoothing import RATE_WIDTH, smoothed_rate_viscosity
from suspsim.sph.terms.velocity_pass import (_dissipation_sums, _gradient_finish, _gradient_sums,
                                             _normalisation_finish)
from suspsim.sph.terms.viscous import spin_bulk_coefficient
from suspsim.threads import use_threads
from suspsim.timing import best_times

#: Untimed steps before timing: compilation, and the first relaxation of the jittered lattice
#: (density error ≈ 14 % at step 5, ≈ 1 % from step ~50 on).
WARM_UP = 50
#: Lattice sites of the standard box (32³; side 20 h).
PARTICLES = 32768
#: Stress samples taken across the timed steps.
SAMPLES = 20
#: Scenes of :func:`benchmark` (fluid, shear rate, inclusions; the box is common).
SCENES = {
    "fluid-newtonian": ({"law": "newtonian", "params": {"mu": 1.0}}, 0.0244, {}),
    "fluid-newtonian-unnormalised": ({"law": "newtonian", "params": {"mu": 1.0}}, 0.0244, {}),
    "fluid-papanastasiou": ({"law": "papanastasiou",
                             "params": {"mu_pl": 0.01, "mu_0": 0.99, "M": 100.0}}, 0.01, {}),
    "suspension-newtonian": ({"law": "newtonian", "params": {"mu": 1.0}}, 0.0244,
                             {"phi": 0.4, "radius": 2.5}),
    "suspension-papanastasiou": ({"law": "papanastasiou",
                                  "params": {"mu_pl": 0.01, "mu_0": 0.99, "M": 100.0}}, 0.01,
                                 {"phi": 0.4, "radius": 2.5}),
}

#: Each suspension scene and the fluid it is suspended in (:func:`paired_cost`).
SUSPENDING_FLUID = {"suspension-newtonian": "fluid-newtonian",
                    "suspension-papanastasiou": "fluid-papanastasiou"}


def lattice_side(particles: int) -> float:
    """Box side [h] of a k × k × k lattice of ``particles`` = k³ sites at number density 4.096
    per h³ (lattice spacing 1/1.6 h): k/1.6. Raises ValueError unless ``particles`` is a cube
    of k ≥ 20 (a box of at least 12.5 h, which holds the suspension scenes' spheres)."""
    k = round(particles ** (1.0 / 3.0))
    if k ** 3 != particles or k < 20:
        raise ValueError(f"particles must be a cube k^3 with k >= 20 (e.g. 8000, 32768, "
                         f"262144, 1000000), got {particles}")
    return k / 1.6


def benchmark_scene(scene_name: str, particles: int = PARTICLES):
    """The validated scene of ``scene_name`` (see :data:`SCENES`) in the box of
    :func:`lattice_side` (``particles`` lattice sites; bodies' shells change the count)."""
    try:
        fluid, rate, inclusions = SCENES[scene_name]
    except KeyError:
        raise ValueError(f"unknown benchmark scene {scene_name!r}; known: "
                         f"{', '.join(SCENES)}") from None
    side = lattice_side(particles)
    numerics = ({"viscous_normalisation": False} if scene_name.endswith("-unnormalised")
                else {})
    return scene_from_dict({
        "dimension": 3, "box": [side, side, side], "number_density": 4.096, "kernel": "lucy",
        "fluid": fluid, "flow": {"type": "couette", "shear_rate": rate},
        "run": {"strain": 1.0, "start": "linear"}, "inclusions": inclusions, "numerics": numerics,
        "lattice": {"jitter": 0.0 if inclusions else 0.1, "relax_max_steps": 100}, "seed": 1})


def benchmark(scene_name: str, n_steps: int, threads: int, particles: int = PARTICLES) -> dict:
    """Time ``n_steps`` full steps of ``scene_name`` on ``threads`` threads (box of
    ``particles`` lattice sites, :func:`benchmark_scene`).

    Returns {scene, n_particles, threads, steps, wall_time_s, particle_steps_per_s, rebuilds,
    dt, sound_speed, viscosity_error, density_error, rebuild_share (of the timed wall time),
    bytes_per_particle (``Simulation.memory_bytes``), pass_ms (:func:`pass_times`)}.
    The error reached: viscosity_error is ⟨σ_xy⟩/(μ(γ̇) γ̇) − 1 over 20 samples spread across
    the timed steps (the run starts from the linear profile, and a sheared lattice makes the
    stress oscillate by ±7 % with period one strain unit, so this is the solver's error over
    the window — 500 steps are one strain unit of the Papanastasiou scene — not a steady-state
    measurement: ``suspsim run`` makes that); density_error the largest |ρ/ρ_eq − 1| seen.
    Sampling is not timed.
    """
    threads = int(min(threads, numba.config.NUMBA_NUM_THREADS))
    if scene_name == DST_SCENE:
        return benchmark_dst(n_steps, threads, particles, WARM_UP)
    scene = benchmark_scene(scene_name, particles)
    sim = Simulation(scene, threads=threads)
    sim.advance(WARM_UP)
    builds, rebuild_seconds = sim.rebuild_count, sim.rebuild_seconds
    samples = min(SAMPLES, n_steps)
    wall, stresses, density_error = 0.0, [], 0.0
    for k in range(samples):
        steps = (k + 1) * n_steps // samples - k * n_steps // samples
        start = time.perf_counter()
        sim.advance(steps)
        wall += time.perf_counter() - start
        sample = sim.sample()
        stresses.append(sample["shear_stress"])
        density_error = max(density_error, sample["density_error"])
    rate = scene.flow.shear_rate
    viscosity = float(scene.fluid.law.viscosity(rate))
    passes = pass_times(sim)
    return {"scene": scene_name, "n_particles": sim.n_particles, "threads": threads,
            "steps": int(n_steps), "wall_time_s": wall,
            "particle_steps_per_s": sim.n_particles * n_steps / wall,
            "rebuilds": sim.rebuild_count - builds, "dt": sim.dt, "sound_speed": sim.sound_speed,
            "viscosity_error": float(np.mean(stresses)) / (viscosity * rate) - 1.0,
            "density_error": density_error,
            "rebuild_share": (sim.rebuild_seconds - rebuild_seconds) / wall,
            "bytes_per_particle": sim.memory_bytes() / sim.n_particles,
            "pass_ms": {name: 1e3 * seconds for name, seconds in passes.items()}}


def pass_times(sim: Simulation, repeats: int = 5) -> dict[str, float]:
    """Best-of-``repeats`` wall time [s] of each compiled pass of one step on ``sim``'s state.

    The passes run in step order on the current positions and velocities (the state is
    recomputed, not advanced): density (with the pair table), body density (with bodies),
    gradient sums and finish, the rate smoothing (non-Newtonian scenes that smooth the rate),
    dissipation sums and normalisation finish (when the scene normalises), force sums and
    finish. Their sum is the step without drift, kick, rebuilds and the bodies' own work.
    """
    use_threads(sim.threads)
    box, tb, nl = sim._box, sim._table, sim._nlist
    law = sim.scene.fluid.law
    shear_ly = sim._rate * box[1]
    calls = {"density": lambda: (
        summation_density(sim._x, box, sim._offset(sim.time), nl.start, nl.image_start,
                          nl.neighbours, sim._kernel, SUPPORT, sim._rho, tb.pair_start,
                          tb.pair_end, tb.pair_j, tb.pair_geometry, tb.pair_cross, tb.pair_image,
                          sim._scratch_1, sim._bounds),
        mass_density(sim._rho, sim._mass, sim._volume))}
    if sim.bodies is not None:
        n = sim.n_particles
        calls["body density"] = lambda: body_particle_density(
            tb.pair_start, tb.pair_end, tb.pair_j, tb.pair_geometry, sim._body_of, sim._kernel,
            SUPPORT, sim._rho, sim._rho_eq, sim.sound_speed ** 2, sim._mass, sim._mu_hat,
            sim._grad_acc[:3 * n], sim._scratch_15[:, :3 * n], sim._bounds, sim._volume)
    if sim._velocity_gradient:
        calls["gradient sums"] = lambda: _gradient_sums(
            tb.pair_start, tb.pair_end, tb.pair_j, tb.pair_geometry, tb.pair_cross, tb.pair_image,
            sim._v, sim._volume, shear_ly, sim.scene.dimension, sim._grad_acc, sim._scratch_15,
            sim._bounds)
        calls["gradient finish"] = lambda: _gradient_finish(
            sim._grad_acc, sim.scene.dimension, law.code, law.packed, sim._newtonian,
            sim._normalise, sim._beta, sim._spin_correction, sim._body_of, sim._gradient,
            sim._inverse_moment, sim._moment_trace, sim._gdot, sim._mu, sim._strain,
            sim._dissipation)
    if sim._velocity_gradient and sim._smooth_rate and not sim._newtonian:
        n = sim.n_particles
        calls["rate smoothing"] = lambda: smoothed_rate_viscosity(
            tb.pair_start, tb.pair_end, tb.pair_j, tb.pair_geometry, sim._kernel, SUPPORT,
            sim._volume, sim._gradient, sim._body_of, law.code, law.packed,
            sim._grad_acc[:RATE_WIDTH * n], sim._scratch_15, sim._bounds, sim._gdot, sim._mu)
    if sim._normalise:
        if sim._alpha != 0.0:
            calls["dissipation sums"] = lambda: _dissipation_sums(
                tb.pair_start, tb.pair_end, tb.pair_j, tb.pair_geometry, sim._volume, sim._strain,
                sim._diss_acc, sim._scratch_1, sim._bounds)
        calls["normalisation finish"] = lambda: _normalisation_finish(
            sim._diss_acc, sim._dissipation, sim._gradient, sim._moment_trace, sim._mu,
            sim._alpha, sim._beta, sim._spin_correction, sim.scene.dimension, sim._body_of,
            sim._factor, sim._mu_hat)
    calls["force sums"] = lambda: force_sums(
        tb.pair_start, tb.pair_end, tb.pair_j, tb.pair_geometry, tb.pair_cross, tb.pair_image,
        sim._v, sim._rho, sim._volume, sim._mu_hat, sim._mass, sim._rho_eq, sim.sound_speed ** 2,
        sim._alpha, sim._beta, sim._bulk_factor, sim._bulk_gradient, shear_ly, sim._body_of,
        sim._body_spin, sim._spin_correction,
        spin_bulk_coefficient(sim._spin_correction, sim.scene.dimension), sim._gradient,
        sim._pressure, sim._spin, sim._force_acc, sim._force_scratch, sim._bounds, sim._virial)
    calls["force finish"] = lambda: force_finish(
        sim._force_acc, sim._x, sim._rho, sim._inverse_moment, sim._gradient, sim._mass,
        sim._bulk_gradient, sim._body_force, box[1], sim._a_new)
    return best_times(calls, repeats)


def paired_cost(scene_name: str, n_steps: int, threads: int, rounds: int,
                particles: int = PARTICLES) -> dict:
    """The cost of a step per particle of the suspension scene ``scene_name`` against its
    fluid's (:data:`SUSPENDING_FLUID`): both simulations are built and warmed up
    (:data:`WARM_UP` steps), then ``rounds`` times each advances ``n_steps``/``rounds`` steps,
    one after the other, each slice timed (single runs seconds apart moved by ±10–25 % on a
    shared 2-core machine).

    Returns {scene, fluid, n_particles, fluid_n_particles, threads, steps, rounds,
    cost_ratio (the suspension's wall time per particle-step over the fluid's, all slices
    summed), slice_ratios (the same per round), particle_steps_per_s,
    fluid_particle_steps_per_s}.
    """
    try:
        fluid_name = SUSPENDING_FLUID[scene_name]
    except KeyError:
        raise ValueError(f"{scene_name!r} is not a suspension scene; known: "
                         f"{', '.join(SUSPENDING_FLUID)}") from None
    threads = int(min(threads, numba.config.NUMBA_NUM_THREADS))
    sims = [Simulation(benchmark_scene(name, particles), threads=threads)
            for name in (fluid_name, scene_name)]
    for sim in sims:
        sim.advance(WARM_UP)
    walls = np.zeros((rounds, 2))
    steps = np.diff(np.linspace(0, n_steps, rounds + 1).astype(int))
    for k in range(rounds):
        for s, sim in enumerate(sims):
            start = time.perf_counter()
            sim.advance(int(steps[k]))
            walls[k, s] = time.perf_counter() - start
    counts = np.array([sim.n_particles for sim in sims], dtype=float)
    per_particle_step = walls / (counts * steps[:, None])
    total = walls.sum(axis=0) / (counts * n_steps)
    return {"scene": scene_name, "fluid": fluid_name, "n_particles": sims[1].n_particles,
            "fluid_n_particles": sims[0].n_particles, "threads": threads,
            "steps": int(n_steps), "rounds": int(rounds),
            "cost_ratio": float(total[1] / total[0]),
            "slice_ratios": (per_particle_step[:, 1] / per_particle_step[:, 0]).tolist(),
            "particle_steps_per_s": float(1.0 / total[1]),
            "fluid_particle_steps_per_s": float(1.0 / total[0])}
