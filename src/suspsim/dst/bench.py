"""``suspsim bench --scene dst-2d``: the cost of a step of the 2D Wyart–Cates DST solver.

The scene is ``config/scenes/dst_stress_couette.yaml`` (seed 002's stress-controlled shear of a
φ = 0.54 suspension on the unstable branch, σ = 2.5 σ*, strong non-locality, walls at y = 0 and
the gap) on a finer lattice: box [3.2, 1] gaps, ``resolution`` fluid particles across the gap,
chosen so that the fluid holds about the requested number of particles (3.2 r² ≈ N, r a
multiple of 5 so the lattice fits the box; 32,768 → r = 100, 32,000 fluid particles). The
solver adapts its step every step and rebuilds its lists inside the compiled loop, so the
figure is whole steps: particle-steps/s counts fluid and wall particles. The compiled loop has
no timer, so the cost of its parts is timed outside it on the state after the timed steps
(:func:`pass_times`).
"""
from __future__ import annotations

import math
import time

import numpy as np

from suspsim.dst import integrator as _int
from suspsim.dst.scene import dst_scene_from_dict
from suspsim.threads import use_threads
from suspsim.timing import best_times

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


def pass_times(sim, repeats: int = 5) -> dict[str, float]:
    """Best-of-``repeats`` wall time [s] of each part of one rate evaluation on ``sim``'s
    current state, on copies of its work arrays (the run is not changed): the list build
    (forced), the per-particle state (η, p), the wall and fluid pair passes, and the finish
    (γ̇, σ, Df/Dt, the wall's acceleration). A step evaluates twice (predictor–corrector);
    the list build runs only when a particle has moved half the skin."""
    use_threads(sim.threads)
    cfg = sim.config
    x, v, rho, f = sim.positions_all, sim.velocity_all, sim.rho_all.copy(), sim.f_all
    buf = _int.Buffers(*(a.copy() for a in sim._buffers))
    lists = _int.ListArrays(*(a.copy() for a in sim._lists))
    wall = sim.wall.copy()

    def build():
        lists.force_rebuild[0] = 1
        return _int.refresh_list(cfg, x, lists)

    calls = {"list build": build,
             "viscosity and pressure": lambda: _int.particle_state(cfg, v, rho, f, buf),
             "pair passes": lambda: _int.pair_passes(cfg, x, v, rho, f, wall, buf, lists),
             "finish": lambda: _int.finish_rates(cfg, f, wall, buf)}
    return best_times(calls, repeats)


def benchmark_dst(n_steps: int, threads: int, particles: int, warm_up: int) -> dict:
    """Time ``n_steps`` steps of the DST scene after ``warm_up`` untimed ones (compilation,
    the start's transient). Returns {scene, n_particles, threads, steps, wall_time_s,
    particle_steps_per_s, dt (the last step), rebuilds, rebuild_share, bytes_per_particle,
    pass_ms (:func:`pass_times`, with "update and checks": the step's remainder, the timed
    wall time per step less two evaluations and its share of builds)}. rebuild_share is the
    builds during the timed steps times the timed build, over the timed wall time (an
    estimate: the loop rebuilds inside compiled code)."""
    sim = dst_bench_scene(particles).build(threads=threads)
    sim.advance(warm_up)
    builds = sim.rebuild_count
    start = time.perf_counter()
    sim.advance(n_steps)
    wall = time.perf_counter() - start
    rebuilds = sim.rebuild_count - builds
    passes = pass_times(sim)
    build_share = rebuilds * passes["list build"] / wall
    evaluation = sum(t for name, t in passes.items() if name != "list build")
    passes["update and checks"] = max(
        0.0, wall / n_steps - 2.0 * evaluation - rebuilds * passes["list build"] / n_steps)
    return {"scene": SCENE, "n_particles": sim.n_particles, "threads": sim.threads,
            "steps": int(n_steps), "wall_time_s": wall,
            "particle_steps_per_s": sim.n_particles * n_steps / wall, "dt": sim.last_dt,
            "rebuilds": rebuilds, "rebuild_share": build_share,
            "bytes_per_particle": array_bytes(sim) / sim.n_particles,
            "pass_ms": {name: 1e3 * seconds for name, seconds in passes.items()}}
