"""Sand grains against spheres at equal φ over several packings, in a Newtonian matrix.

    python docs/figures/make_shape_seeds.py [--phi 0.3] [--seeds 1 2 3] [--strain 1 4]
        [--box 16.875] [--radius 2.5] [--shapes sphere sand] [--set KEY=VALUE ...]

The sand and spheres studies compare one packing per φ, in different boxes (15 h and 16.875 h)
and a thinning matrix. This isolates the shape: both shapes in the same 16.875 h box (the sand
study's, which holds a grain's reach of 1.63 a), the same volume-equivalent radius a = 2.5 h,
the Newtonian matrix of :mod:`suspsim.validation.suspension`, and packing seeds 1, 2, 3 for
each. η_r = σ_xy/(μγ̇) is averaged over whole strain units after the transient; the spread of
the packings' η_r gives the error of their mean, and sand/spheres is the ratio of the means
(errors in quadrature). Beside η_r each run reports η_r^p = 1 + σ^p_xy/(μγ̇) from the bodies'
share of the stress alone (Batchelor 1970; ``run._batchelor_split``), which leaves out the
discrete fluid's error, and its health: the largest density error, the smallest gap between
surfaces [h] and the largest body speed relative to the flow over the wall speed, all over the
samples; and, after the transient, the bodies' mean spin Ω_z/(−γ̇/2) and the nematic order S of
the grains' long axes (``analysis.orientation``). A run that leaves its health limits stops at
that sample with the reason, is reported and left out of the means. ``--box`` takes another side
(a multiple of the lattice spacing 0.625 h, see ``scene_rules.lattice_mismatch``) and
``--radius`` another a (a finer body; the box must hold 6.5 a for sand). One thread
per run; prints a Markdown table and writes nothing else.
"""
import argparse
import math
import time

import numpy as np

from suspsim.errors import NumericalError
from suspsim.validation.suspension import (RATE, add_run_options, overrides_text,
                                           parse_overrides, relative_viscosity)

BOX = 16.875
RADIUS = 2.5


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phi", type=float, default=0.3)
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--box", type=float, default=BOX, help=f"cube side [h] (default {BOX})")
    parser.add_argument("--radius", type=float, default=RADIUS,
                        help=f"volume-equivalent radius a [h] (default {RADIUS})")
    add_run_options(parser, example=", e.g. run.dt=0.1 or inclusions.lubrication.repulsion=1e5")
    parser.add_argument("--shapes", nargs="+", default=["sphere", "sand"],
                        choices=("sphere", "sand"))
    args = parser.parse_args()
    transient, units = args.strain[0], int(args.strain[1])
    overrides = parse_overrides(args.set)
    means = {}
    settings = overrides_text(overrides)
    print(f"φ = {args.phi}, box {args.box} h, a = {args.radius} h, μ = 1, γ̇ = {RATE}, strain "
          f"{transient:g} + {units}{settings}\n| shape | seed | η_r | η_r^p | CPU [s] | "
          f"density error | smallest gap [h] | body speed / wall speed | spin | order S |\n"
          f"|---|---|---|---|---|---|---|---|---|---|",
          flush=True)
    for shape in args.shapes:
        values = []
        for seed in args.seeds:
            started = time.process_time()
            try:
                r = relative_viscosity(shape=shape, phi=args.phi, radius=args.radius, box=args.box,
                                       seed=seed, transient=transient, units=units,
                                       overrides=overrides)
            except NumericalError as err:
                print(f"| {shape} | {seed} | stopped: {err} | | "
                      f"{time.process_time() - started:.0f} | | | | | |", flush=True)
                continue
            values.append(r.relative_viscosity)
            print(f"| {shape} | {seed} | {r.relative_viscosity:.3f} ± {r.stderr:.3f} | "
                  f"{r.particle_relative_viscosity:.3f} ± {r.particle_stderr:.3f} | "
                  f"{r.cpu_time:.0f} | {r.density_error:.3f} | {r.smallest_gap:.3f} | "
                  f"{r.body_speed:.2f} | {r.spin:.2f} | {r.order:.2f} |", flush=True)
        if not values:
            continue
        sem = np.std(values, ddof=1) / math.sqrt(len(values)) if len(values) > 1 else math.nan
        means[shape] = (float(np.mean(values)), float(sem))
        print(f"| {shape} | mean | {means[shape][0]:.3f} ± {means[shape][1]:.3f} | | | | | | | |",
              flush=True)
    if "sphere" in means and "sand" in means:
        (s, ds), (g, dg) = means["sphere"], means["sand"]
        ratio = g / s
        print(f"sand/spheres = {ratio:.3f} ± {ratio * math.hypot(ds / s, dg / g):.3f}")


if __name__ == "__main__":
    main()
