"""Hand-run micro benchmark of the neighbour list and the density pass (not a test).

The performance target's scene: a 3D periodic Lees–Edwards box of 32,768 particles (32³
jittered simple-cubic lattice), side 20 h, number density 4.096 per h³ (≈ 17 neighbours within
the Lucy support h), LE offset 3.3 h (not a multiple of the cell size). Times are the minimum
over interleaved repeats (the median is printed too: shared machines are noisy).

Run::

    PYTHONPATH=src python -m suspsim.sph.bench_density [--skin 0.2] [--repeats 20]

"Particle-steps/s" below is N / (time of this pass alone); a full step adds the shear-rate and
force passes.
"""
from __future__ import annotations

import argparse
import time

import numba
import numpy as np

from suspsim.sph import kernels
from suspsim.sph.boundaries import wrap_particles
from suspsim.sph.density import allocate_pair_table, summation_density, summation_density_serial
from suspsim.sph.list_validity import needs_rebuild
from suspsim.sph.neighbours import (allocate_neighbour_list, apply_permutation,
                                    build_neighbour_list, sort_by_cell)


def benchmark_box(n_side=32, length=20.0, jitter=0.1, seed=1):
    """Positions (n_side³, 3) of a simple-cubic lattice jittered by ±jitter spacings, and box."""
    rng = np.random.default_rng(seed)
    spacing = length / n_side
    axis = (np.arange(n_side) + 0.5) * spacing
    positions = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3)
    positions += rng.uniform(-jitter, jitter, positions.shape) * spacing
    return positions, np.array([length, length, length])


def _timed(functions, rounds, repeats):
    """{name: (min, median)} seconds, rounds interleaved so drifts hit every entry alike."""
    samples = {name: [] for name in functions}
    for _ in range(rounds):
        for name, function in functions.items():
            function()
            for _ in range(repeats):
                t = time.perf_counter()
                function()
                samples[name].append(time.perf_counter() - t)
    return {name: (min(s), float(np.median(s))) for name, s in samples.items()}


def run_benchmark(skin=0.2, support=1.0, offset=3.3, repeats=20, rounds=3,
                  thread_counts=(1, 2)):
    """Time sort, build, rebuild check and density pass; returns a dict of results."""
    thread_counts = [t for t in thread_counts if t <= numba.config.NUMBA_NUM_THREADS]
    positions, box = benchmark_box()
    n = len(positions)
    velocities = np.zeros_like(positions)
    nlist = allocate_neighbour_list(n, box, support, skin, 3, n / np.prod(box))
    wrap_particles(positions, velocities, box, offset, 0.0)
    sort_by_cell(positions, box, nlist.cells, nlist.cell_of, nlist.order, nlist.cell_start)
    unsorted = positions.copy()
    apply_permutation(unsorted, nlist.order, positions)
    build_args = (positions, box, offset, nlist.cutoff, nlist.cells, nlist.cell_start,
                  nlist.start, nlist.image_start, nlist.neighbours)
    _, n_pairs = build_neighbour_list(*build_args)
    table = allocate_pair_table(n, len(nlist.neighbours))
    density = np.empty(n)
    list_args = (positions, box, offset, nlist.start, nlist.image_start, nlist.neighbours,
                 kernels.LUCY_3D, support, density, table.pair_start, table.pair_end, table.pair_j,
                 table.pair_geometry, table.pair_cross, table.pair_image)
    reference = positions.copy()
    scratch = {t: np.empty((t - 1, n)) for t in thread_counts}
    bounds = np.empty(max(thread_counts) + 1, dtype=np.int64)

    def on(threads, function, *args):
        def run():
            numba.set_num_threads(threads)
            function(*args)
        return run

    functions = {
        "sort by cell + permute (N, 3)": on(1, lambda: (
            sort_by_cell(unsorted, box, nlist.cells, nlist.cell_of, nlist.order,
                         nlist.cell_start),
            apply_permutation(unsorted, nlist.order, positions))),
        "needs_rebuild": on(1, needs_rebuild, positions, reference, 0.01, nlist.cutoff, skin),
        "density, serial function": on(1, summation_density_serial, *list_args),
    }
    for t in thread_counts:
        functions[f"neighbour build, {t} thread(s)"] = on(t, build_neighbour_list, *build_args)
        functions[f"density, {t} chunk(s) on {t} thread(s)"] = on(
            t, summation_density, *list_args, scratch[t], bounds)
    times = _timed(functions, rounds, repeats)
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    within = int((table.pair_end - nlist.start[:-1]).sum())
    return {"particles": n, "pairs_listed": int(n_pairs), "pairs_within_h": within,
            "cells": nlist.cells.tolist(), "skin": skin, "times": times}


def main(argv=None):
    """Print the benchmark table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skin", type=float, default=0.2, help="Verlet skin [h]")
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    result = run_benchmark(skin=args.skin, repeats=args.repeats, rounds=args.rounds)
    n, listed = result["particles"], result["pairs_listed"]
    print(f"N = {n}, cells {result['cells']}, skin {result['skin']} h: "
          f"{listed / n:.2f} listed pairs and {result['pairs_within_h'] / n:.2f} pairs within h "
          "per particle (half list)")
    print(f"{'':40s} {'min ms':>8s} {'median':>8s} {'ns/listed pair':>15s} "
          f"{'M particle-steps/s':>19s}")
    for name, (best, median) in result["times"].items():
        per_pair = f"{best / listed * 1e9:.2f}" if "density" in name else ""
        print(f"{name:40s} {best * 1e3:8.3f} {median * 1e3:8.3f} {per_pair:>15s} "
              f"{n / best / 1e6:19.1f}")


if __name__ == "__main__":
    main()
