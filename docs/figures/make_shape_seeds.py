"""Sand grains against spheres at equal φ over several packings, in a Newtonian matrix.

    python docs/figures/make_shape_seeds.py [--phi 0.3] [--seeds 1 2 3] [--strain 1 4]

The sand and spheres studies compare one packing per φ, in different boxes (15 h and 16.875 h)
and a thinning matrix. This isolates the shape: both shapes in the same 16.875 h box (the sand
study's, which holds a grain's reach of 1.63 a), the same volume-equivalent radius a = 2.5 h,
the Newtonian matrix of :mod:`suspsim.validation.suspension`, and packing seeds 1, 2, 3 for
each. η_r = σ_xy/(μγ̇) is averaged over whole strain units after the transient; the spread of
the packings' η_r gives the error of their mean, and sand/spheres is the ratio of the means
(errors in quadrature). One thread per run; prints a Markdown table and writes nothing else.
"""
import argparse
import math

import numpy as np

from suspsim.validation.suspension import RATE, relative_viscosity

BOX = 16.875
RADIUS = 2.5


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phi", type=float, default=0.3)
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--strain", type=float, nargs=2, default=[1.0, 4.0],
                        metavar=("TRANSIENT", "UNITS"))
    args = parser.parse_args()
    transient, units = args.strain[0], int(args.strain[1])
    means = {}
    print(f"φ = {args.phi}, box {BOX} h, a = {RADIUS} h, μ = 1, γ̇ = {RATE}, strain "
          f"{transient:g} + {units}\n| shape | seed | η_r | CPU [s] |\n|---|---|---|---|",
          flush=True)
    for shape in ("sphere", "sand"):
        values = []
        for seed in args.seeds:
            r = relative_viscosity(shape=shape, phi=args.phi, radius=RADIUS, box=BOX, seed=seed,
                                   transient=transient, units=units)
            values.append(r.relative_viscosity)
            print(f"| {shape} | {seed} | {r.relative_viscosity:.3f} ± {r.stderr:.3f} | "
                  f"{r.cpu_time:.0f} |", flush=True)
        sem = np.std(values, ddof=1) / math.sqrt(len(values)) if len(values) > 1 else math.nan
        means[shape] = (float(np.mean(values)), float(sem))
        print(f"| {shape} | mean | {means[shape][0]:.3f} ± {means[shape][1]:.3f} | |",
              flush=True)
    (s, ds), (g, dg) = means["sphere"], means["sand"]
    ratio = g / s
    print(f"sand/spheres = {ratio:.3f} ± {ratio * math.hypot(ds / s, dg / g):.3f}")


if __name__ == "__main__":
    main()
