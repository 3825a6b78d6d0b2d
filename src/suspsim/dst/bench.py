"""``suspsim bench --scene dst-2d``: the cost of a step of the 2D Wyart–Cates DST solver.

The scene is ``config/scenes/dst_stress_couette.yaml`` (seed 002's stress-controlled shear of a
φ = 0.54 suspension on the unstable branch, σ = 2.5 σ*, strong non-locality, walls at y = 0 and
the gap) on a finer lattice: box [3.2, 1] gaps, ``resolution`` fluid particles across the gap,
chosen so that the fluid holds about the requested number of particles (3.2 r² ≈ N, r a
multiple of 5 so the lattice fits the box; 32,768 → r = 100, 32,000 fluid particles). The
solver adapts its step every step and rebuilds its lists inside the compiled loop, so the
figure is whole steps: particle-steps/s counts fluid and wall particles.
"""
from __future__ import annotations

import math
import time

import numpy as np

from suspsim.dst.scene import dst_scene_from_dict

#: Name of the scene in ``suspsim bench``.
SCENE = "dst-2d"
#: Periodic length in gaps [1].
LENGTH = 3.2


def dst_bench_scene(particles: int):
    """The benchmark DST scene with about ``particles`` fluid particles (module docstring)."""
    resolution = max(5, 5 * round(math.sqrt(particles / LENGTH) / 5))
    return dst_scene_from_dict({
        "dimension": 2, "box": [LENGTH, 1.0], "resolution": resolution,
        "fluid": {"law": "wyart_cates", "params": {
            "eta_s": 1.0, "phi": 0.54, "phi_m": 0.562, "phi_0": 0.693, "sigma_star": 1.0,
            "beta": 2.0, "K_f": 1.0, "alpha": 0.02}},
        "flow": {"type": "stress_couette", "stress": 2.5}, "run": {"strain": 3.0}})


def array_bytes(obj, seen=None) -> int:
    """Bytes of the numpy arrays held by ``obj``'s attributes and tuples, each buffer once."""
    seen = set() if seen is None else seen
    if isinstance(obj, np.ndarray):
        owner = obj if obj.base is None else obj.base
        if id(owner) in seen:
            return 0
        seen.add(id(owner))
        return int(owner.nbytes)
    if isinstance(obj, tuple):
        return sum(array_bytes(item, seen) for item in obj)
    if hasattr(obj, "__dict__") and not isinstance(obj, type):
        return sum(array_bytes(value, seen) for value in vars(obj).values())
    return 0


def benchmark_dst(n_steps: int, threads: int, particles: int, warm_up: int) -> dict:
    """Time ``n_steps`` steps of the DST scene after ``warm_up`` untimed ones (compilation,
    the start's transient). Returns {scene, n_particles, threads, steps, wall_time_s,
    particle_steps_per_s, dt (the last step), bytes_per_particle}."""
    sim = dst_bench_scene(particles).build(threads=threads)
    sim.advance(warm_up)
    start = time.perf_counter()
    sim.advance(n_steps)
    wall = time.perf_counter() - start
    return {"scene": SCENE, "n_particles": sim.n_particles, "threads": sim.threads,
            "steps": int(n_steps), "wall_time_s": wall,
            "particle_steps_per_s": sim.n_particles * n_steps / wall, "dt": sim.last_dt,
            "bytes_per_particle": array_bytes(sim) / sim.n_particles}
