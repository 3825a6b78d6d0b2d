"""Where a suspension's shear stress comes from: the fluid's pressure pairs against the rest.

    python docs/figures/make_stress_split.py [--phi 0.1] [--box 15] [--seed 1] [--strain 1 4]
        [--set KEY=VALUE ...]

σ_xy/(μγ̇) of spheres a = 2.5 h in the Newtonian matrix of
:mod:`suspsim.validation.suspension`, averaged over 50 samples per strain unit after the
transient, split into: the pressure part of fluid–fluid pairs, Σ k_p r_x r_y over the pair
table (``terms.pressure.pressure_pair``), which a fluid with an isotropic pressure does not
have (a disordered SPH fluid's anisotropic structure gives it); the pressure part of
fluid–body pairs; all pair forces (pressure and viscous, body particles where they are); the
move of the body particles' forces to their body's centre (``bodies.coupling``, SPEC §3.5);
lubrication and repulsion; the kinetic rest. One thread; writes nothing.
"""
import argparse

import numpy as np
from numba import njit

from suspsim.sph.terms.force_pass import VXY
from suspsim.validation.suspension import (RATE, add_run_options, overrides_text,
                                           parse_overrides, sampled_run, suspension_scene)

RADIUS = 2.5


@njit(cache=True)
def pressure_virials(start, end, pair_j, geometry, pressure, body_of):
    """(Σ fluid–fluid, Σ fluid–body) of k_p r_x r_y over the half pair table, k_p =
    (P_i/ρ_i² + P_j/ρ_j²) m² F from the force pass's per-particle ``pressure`` terms."""
    fluid, mixed = 0.0, 0.0
    for i in range(start.shape[0]):
        for k in range(start[i], end[i]):
            j = pair_j[k]
            body_i, body_j = body_of[i] >= 0, body_of[j] >= 0
            if body_i and body_j:
                continue
            xy = (pressure[i] + pressure[j]) * geometry[k, 3] * geometry[k, 0] * geometry[k, 1]
            if body_i or body_j:
                mixed += xy
            else:
                fluid += xy
    return fluid, mixed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phi", type=float, default=0.1)
    parser.add_argument("--box", type=float, default=15.0, help="cube side [h]")
    parser.add_argument("--seed", type=int, default=1)
    add_run_options(parser, example=", e.g. numerics.wi_target=1e-4")
    args = parser.parse_args()
    transient, units = args.strain
    overrides = parse_overrides(args.set)
    scene = suspension_scene(phi=args.phi, radius=RADIUS, box=args.box, seed=args.seed,
                             strain=transient + units, overrides=overrides)
    rows = []
    for sim in sampled_run(scene, transient=transient, units=units):
        table = sim._table
        fluid, mixed = pressure_virials(table.pair_start, table.pair_end, table.pair_j,
                                        table.pair_geometry, sim._pressure, sim._body_of)
        rows.append([-sim.sample()["shear_stress"] * scene.volume, fluid, mixed,
                     sim._virial[:, VXY].sum(), sim._body_virial[VXY],
                     sim._lubrication_virial[VXY]])
    # σ_xy = −Π_xy and Π = (kinetic + virial)/V.
    total, fluid, mixed, pairs, centres, lubrication = (
        -np.mean(rows, axis=0) / (scene.volume * RATE * float(scene.fluid.law.viscosity(RATE))))
    settings = overrides_text(overrides)
    print(f"φ = {args.phi}, box {args.box} h, seed {args.seed}, strain {transient:g} + "
          f"{units:g}{settings}: σ_xy/(μγ̇) = {total:.4f}; fluid–fluid pressure {fluid:+.4f}, "
          f"fluid–body pressure {mixed:+.4f}; all pairs {pairs:.4f}, body particles to their "
          f"centres {centres:+.4f}, lubrication {lubrication:+.4f}, kinetic "
          f"{total - pairs - centres - lubrication:+.4f}")


if __name__ == "__main__":
    main()
