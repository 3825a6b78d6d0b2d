"""Benchmark of the full SPH step (density, gradient, normalisation and force passes).

The issue's performance scene: a 3D periodic Lees–Edwards Couette box of side 20 h at number
density 4.096 per h³ (32³ = 32,768 particles, jittered simple-cubic lattice), Lucy kernel,
default numerics (bulk correction and dissipation normalisation on). Two fluids:

- ``fluid-newtonian``: μ = 1, γ̇ = 0.0244 (particle Reynolds number ρ γ̇ h²/μ = 0.1);
- ``fluid-papanastasiou``: μ_pl = 0.01, μ_0 = 0.99, M = 100 (seed 000: μ_0/μ_pl = 99), γ̇ = 0.01.

:func:`benchmark` times ``n_steps`` steps after one warm-up step (compilation excluded) and
reports particle-steps per second (N × steps / wall time), neighbour-list rebuilds included.
"""
from __future__ import annotations

import time

import numba

from suspsim.scene import scene_from_dict
from suspsim.sph.simulation import Simulation

#: Scenes of :func:`benchmark` (fluid and shear rate; the box is common).
SCENES = {
    "fluid-newtonian": ({"law": "newtonian", "params": {"mu": 1.0}}, 0.0244),
    "fluid-papanastasiou": ({"law": "papanastasiou",
                             "params": {"mu_pl": 0.01, "mu_0": 0.99, "M": 100.0}}, 0.01),
}


def benchmark_scene(scene_name: str):
    """The validated scene of ``scene_name`` (see :data:`SCENES`)."""
    try:
        fluid, rate = SCENES[scene_name]
    except KeyError:
        raise ValueError(f"unknown benchmark scene {scene_name!r}; known: "
                         f"{', '.join(SCENES)}") from None
    return scene_from_dict({
        "dimension": 3, "box": [20.0, 20.0, 20.0], "number_density": 4.096, "kernel": "lucy",
        "fluid": fluid, "flow": {"type": "couette", "shear_rate": rate},
        "run": {"strain": 1.0, "start": "linear"}, "lattice": {"jitter": 0.1}, "seed": 1})


def benchmark(scene_name: str, n_steps: int, threads: int) -> dict:
    """Time ``n_steps`` full steps of ``scene_name`` on ``threads`` threads.

    Returns {scene, n_particles, threads, steps, wall_time_s, particle_steps_per_s, rebuilds,
    dt, sound_speed}.
    """
    threads = int(min(threads, numba.config.NUMBA_NUM_THREADS))
    sim = Simulation(benchmark_scene(scene_name), threads=threads)
    sim.advance(1)
    builds = sim.rebuild_count
    start = time.perf_counter()
    sim.advance(n_steps)
    wall = time.perf_counter() - start
    return {"scene": scene_name, "n_particles": sim.n_particles, "threads": threads,
            "steps": int(n_steps), "wall_time_s": wall,
            "particle_steps_per_s": sim.n_particles * n_steps / wall,
            "rebuilds": sim.rebuild_count - builds, "dt": sim.dt, "sound_speed": sim.sound_speed}
