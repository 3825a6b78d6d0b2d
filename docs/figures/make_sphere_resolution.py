"""Dense spheres at increasing resolution: η_r against the sphere radius in kernel units.

    python docs/figures/make_sphere_resolution.py [--phi 0.4] [--radii 2.5 3.333 4.167]
        [--seeds 1] [--box-per-radius 6] [--strain 1 4] [--set KEY=VALUE ...]

At a = 2.5 h the dense suspensions read below the published envelope (README, Suspensions),
and at φ = 0.3 a = 3.33 h read 15–35 % higher: the near field of a crowd is under-resolved.
This measures how η_r converges with a/h at fixed φ and fixed box/a (``--box-per-radius``,
default 6: the same number of spheres, about 21 at φ = 0.4, so only the resolution changes;
5 at φ = 0.03 is the Einstein test's one sphere; the side rounded to whole lattice spacings),
in the Newtonian matrix of
:mod:`suspsim.validation.suspension`, one thread per run. Prints a Markdown table (η_r ± the
strain-unit standard error, CPU time, particles) and writes nothing else; a run that stops on
its health limits is reported with the reason and the next one starts. ``--set`` takes a
scene key for every run (e.g. ``inclusions.lubrication.friction=0.5``).
"""
import argparse

from suspsim.errors import NumericalError
from suspsim.rheology.suspension import published_envelope
from suspsim.validation.suspension import (NUMBER_DENSITY, add_run_options, overrides_text,
                                           parse_overrides, relative_viscosity)

BOX_PER_RADIUS = 6.0
SPACING = NUMBER_DENSITY ** (-1.0 / 3.0)
"""Lattice spacing [h]."""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phi", type=float, default=0.4)
    parser.add_argument("--radii", type=float, nargs="+", default=[2.5, 3.333, 4.167])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1])
    parser.add_argument("--box-per-radius", type=float, default=BOX_PER_RADIUS)
    add_run_options(parser)
    args = parser.parse_args()
    transient, units = args.strain[0], int(args.strain[1])
    overrides = parse_overrides(args.set)
    settings = overrides_text(overrides)
    low, high = published_envelope(args.phi)
    print(f"φ = {args.phi} (published envelope {low:.2f}–{high:.2f}), box "
          f"{args.box_per_radius:g} a, strain {transient:g} + {units}{settings}\n"
          "| a [h] | box [h] | seed | φ packed | η_r | CPU [s] | particles |\n"
          "|---|---|---|---|---|---|---|", flush=True)
    for radius in args.radii:
        for seed in args.seeds:
            box = SPACING * round(args.box_per_radius * radius / SPACING)
            try:
                r = relative_viscosity(phi=args.phi, radius=radius, box=box, seed=seed,
                                       transient=transient, units=units, overrides=overrides)
            except NumericalError as err:
                print(f"| {radius:g} | {box:g} | {seed} | | stopped: {err} | | |", flush=True)
                continue
            print(f"| {radius:g} | {box:g} | {seed} | {r.phi:.3f} | {r.relative_viscosity:.3f} "
                  f"± {r.stderr:.3f} | {r.cpu_time:.0f} | {r.n_particles} |", flush=True)


if __name__ == "__main__":
    main()
