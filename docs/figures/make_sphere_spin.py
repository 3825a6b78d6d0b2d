"""Spin of torque-free spheres in simple shear against γ̇/2.

    python docs/figures/make_sphere_spin.py [--phi 0.03] [--box 12.5] [--radius 2.5]
        [--seeds 1] [--strain 1 2] [--set KEY=VALUE ...]

A torque-free sphere in Stokes shear flow u = γ̇ y e_x turns with the fluid's rotation,
Ω = −γ̇/2 e_z; in a dilute periodic array its images change that by O(φ). Spheres of radius a
(``--radius``, default 2.5 h; the packer scales them to the exact φ) in the Newtonian matrix of
:mod:`suspsim.validation.suspension`, sampled 50 times per strain unit after the transient:
prints the mean Ω/(γ̇/2) over bodies and samples (x, y, z components) and the range of the
bodies' own mean Ω_z/(γ̇/2). One thread per run; writes nothing.
"""
import argparse
import time

import numpy as np

from suspsim.validation.suspension import (RATE, add_run_options, overrides_text,
                                           parse_overrides, sampled_run, suspension_scene)

RADIUS = 2.5


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phi", type=float, default=0.03)
    parser.add_argument("--box", type=float, default=12.5, help="cube side [h]")
    parser.add_argument("--radius", type=float, default=RADIUS, help="sphere radius a [h]")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1])
    add_run_options(parser, units=2.0, example=", e.g. numerics.shifting=0")
    args = parser.parse_args()
    transient, units = args.strain
    overrides = parse_overrides(args.set)
    settings = overrides_text(overrides)
    print(f"φ = {args.phi}, box {args.box} h, a = {args.radius} h, γ̇ = {RATE}, strain "
          f"{transient:g} + {units:g}{settings}\n| seed | bodies | mean Ω/(γ̇/2) (x, y, z) | "
          f"bodies' Ω_z/(γ̇/2) | CPU [s] |\n|---|---|---|---|---|", flush=True)
    for seed in args.seeds:
        started = time.process_time()
        scene = suspension_scene(phi=args.phi, radius=args.radius, box=args.box, seed=seed,
                                 strain=transient + units, overrides=overrides)
        spins = np.array([sim.bodies.angular_velocities() / (0.5 * RATE)
                          for sim in sampled_run(scene, transient=transient, units=units)])
        mean = spins.mean(axis=(0, 1))
        own = spins[:, :, 2].mean(axis=0)
        print(f"| {seed} | {spins.shape[1]} | {mean[0]:+.3f}, {mean[1]:+.3f}, {mean[2]:+.3f} | "
              f"{own.min():+.3f} … {own.max():+.3f} | {time.process_time() - started:.0f} |",
              flush=True)


if __name__ == "__main__":
    main()
