"""How sheared bodies line up and share the stress, over the strain window of one run.

    python docs/figures/make_grain_alignment.py [--shape sand] [--phi 0.5] [--seed 1]
        [--box 16.875] [--strain 1 3] [--parts 3] [--set KEY=VALUE ...]

One run of :func:`suspsim.validation.suspension.suspension_scene` (a = 2.5 h, the Newtonian
matrix), sampled 50 times per strain unit after the transient. The window is cut into
``--parts`` equal parts; for each it prints the means of σ_xy/(μγ̇) (η_r), the bodies'
stresslets (their particles' forces moved to the centres) and the lubrication and repulsion
part of it over μγ̇, the lubricated pairs per step, the bodies' spin Ω_z/(−γ̇/2), the nematic
order S of their long axes and the director's angle from the flow direction towards the
gradient [degrees] (``analysis.orientation``; for spheres the axes are arbitrary, so S and the
director mean nothing). One thread; prints a Markdown table and writes nothing.
"""
import argparse
import math

import numpy as np

from suspsim.analysis.orientation import nematic_order
from suspsim.bodies.lubrication_pass import PAIRS
from suspsim.sph.terms.force_pass import VXY
from suspsim.validation.suspension import (RATE, add_run_options, overrides_text,
                                           parse_overrides, sampled_run, suspension_scene)

RADIUS = 2.5


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shape", default="sand", choices=("sphere", "sand"))
    parser.add_argument("--phi", type=float, default=0.5)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--box", type=float, default=16.875, help="cube side [h]")
    parser.add_argument("--parts", type=int, default=3, help="parts of the window")
    add_run_options(parser, units=3.0)
    args = parser.parse_args()
    transient, units = args.strain
    overrides = parse_overrides(args.set)
    scene = suspension_scene(shape=args.shape, phi=args.phi, radius=RADIUS, box=args.box,
                             seed=args.seed, strain=transient + units, overrides=overrides)
    rows = []
    for sim in sampled_run(scene, transient=transient, units=units):
        scale = float(sim.scene.fluid.law.viscosity(RATE)) * RATE * sim.scene.volume
        sample = sim.sample()
        order, director = nematic_order(sim.bodies.rotations()[:, :, 0])
        director = director if director[0] >= 0.0 else -director
        rows.append((sim.strain, sample["shear_stress"] * sim.scene.volume / scale,
                     -sim._body_virial[VXY] / scale, -sim._lubrication_virial[VXY] / scale,
                     sim._lubrication_stats[PAIRS], sample["body_spin"], order,
                     math.degrees(math.atan2(director[1], director[0]))))
    data = np.array(rows)
    print(f"{args.shape}, φ = {args.phi}, seed {args.seed}, box {args.box} h, a = {RADIUS} h, "
          f"strain {transient:g} + {units:g}{overrides_text(overrides)}\n"
          "| strain | η_r | stresslets | lubrication | pairs | spin | S | director [°] |\n"
          "|---|---|---|---|---|---|---|---|")
    for part in np.array_split(data, args.parts):
        m = part.mean(axis=0)
        print(f"| {part[0, 0]:.2f}–{part[-1, 0]:.2f} | {m[1]:.3f} | {m[2]:.3f} | {m[3]:.3f} | "
              f"{m[4]:.1f} | {m[5]:.2f} | {m[6]:.2f} | {m[7]:.0f} |")
    m = data.mean(axis=0)
    print(f"| all | {m[1]:.3f} | {m[2]:.3f} | {m[3]:.3f} | {m[4]:.1f} | {m[5]:.2f} | "
          f"{m[6]:.2f} | {m[7]:.0f} |")


if __name__ == "__main__":
    main()
