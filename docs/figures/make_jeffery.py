"""One spheroid in simple shear against Jeffery's orbit, over resolutions and aspect ratios.

    python docs/figures/make_jeffery.py [--aspects 1.5 2] [--radii 2.5 3.75] [--strain 10]
        [--threads 2] [--set KEY=VALUE ...]

Each run starts the spheroid's long axis along the gradient (α = 90°) and shears it for the
strain given, in the box of ``validation.jeffery.spheroid_box`` with the defaults of a suspension
scene (``--set`` overrides scene keys, e.g. ``numerics.spin_correction=false``). The table gives
the fit of dα/dγ = −½ (k − λ_h cos 2α): the rotation coupling k (Jeffery: 1), the shape factor
λ_h against Jeffery's λ = (r² − 1)/(r² + 1), the hydrodynamic aspect ratio r_h it implies, the
strain the first half turn took (Jeffery: π (r + 1/r)) and the largest out-of-plane component
of the axis. Prints a Markdown table; writes nothing.
"""
import argparse
import math
import time

import numpy as np

from suspsim.validation.jeffery import fit_orbit, jeffery_lambda, spheroid_run
from suspsim.validation.suspension import parse_overrides


def half_turn(strain: np.ndarray, angle: np.ndarray) -> float:
    """Strain at which α first reaches α(0) − π, linearly interpolated (nan if it does not)."""
    target = angle[0] - math.pi
    below = np.flatnonzero(angle <= target)
    if len(below) == 0:
        return math.nan
    k = below[0]
    return float(np.interp(target, angle[k - 1:k + 1][::-1], strain[k - 1:k + 1][::-1]))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--aspects", type=float, nargs="+", default=[2.0])
    parser.add_argument("--radii", type=float, nargs="+", default=[2.5, 3.75],
                        help="volume-equivalent radii [h]")
    parser.add_argument("--strain", type=float, default=10.0)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="scene override, e.g. numerics.spin_correction=false")
    args = parser.parse_args()
    overrides = parse_overrides(args.set)
    print("| r | a [h] | k | λ_h (Jeffery λ) | r_h | half turn (Jeffery) | max |p_z| | "
          "particles | wall [s] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for aspect in args.aspects:
        for radius in args.radii:
            started = time.perf_counter()
            run = spheroid_run(aspect, radius, args.strain, threads=args.threads,
                               overrides=overrides)
            fit = fit_orbit(run.strain, run.angle)
            print(f"| {aspect:g} | {radius:g} | {fit.coupling:.3f} | {fit.shape_factor:.3f} "
                  f"({jeffery_lambda(aspect):.3f}) | {fit.aspect:.3f} | "
                  f"{half_turn(run.strain, run.angle):.2f} "
                  f"({math.pi * (aspect + 1.0 / aspect):.2f}) | "
                  f"{np.abs(run.out_of_plane).max():.3f} | {run.n_particles} | "
                  f"{time.perf_counter() - started:.0f} |", flush=True)


if __name__ == "__main__":
    main()
