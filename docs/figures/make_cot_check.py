"""Spheres in seed 000's Papanastasiou matrix against Chateau–Ovarlez–Trung, with or without
contact friction, over several packings.

    python docs/figures/make_cot_check.py [--friction 0.5] [--x 1] [--phi 0.4] [--seeds 1 2]
        [--strain 1 4] [--set KEY=VALUE ...]

For each packing seed: the Newtonian η_r g of spheres a = 2.5 h at ``--phi`` in the 16.875 h box
of ``make_shape_seeds.py`` (strain 1 + 4), run with the numerics a non-Newtonian matrix takes
(``numerics.shifting`` = ``scene_rules.AUTO_SHIFTING_NON_NEWTONIAN`` and the cutoff that
follows it, as ``stages.bingham_suspension``'s reference), then the same packing in seed 000's
Papanastasiou
matrix (μ_0/μ_pl = 99) at x = Mγ̇ = ``--x``, the law scaled so μ_m(γ̇) = 1
(``stages.bingham_suspension.matrix_law``); prints η/μ_m(γ̇), the estimate η_COT = g μ_m(γ̇
sqrt(g/(1 − φ))) and their ratio. ``--friction`` sets ``inclusions.lubrication.friction``
and each ``--set`` its scene key for both runs. One thread per run; writes nothing.
"""
import argparse

from suspsim.rheology.laws import make_law
from suspsim.rheology.suspension import chateau_ovarlez_trung_viscosity
from suspsim.scene_rules import AUTO_SHIFTING_NON_NEWTONIAN
from suspsim.stages.bingham_suspension import matrix_law
from suspsim.validation.suspension import (RATE, add_run_options, overrides_text,
                                           parse_overrides, relative_viscosity)

BOX = 16.875
RADIUS = 2.5


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--friction", type=float, default=0.0)
    parser.add_argument("--x", type=float, default=1.0)
    parser.add_argument("--phi", type=float, default=0.4)
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2])
    add_run_options(parser, example=", e.g. numerics.spin_correction=true")
    args = parser.parse_args()
    transient, units = args.strain[0], int(args.strain[1])
    shared = {"inclusions.lubrication.friction": args.friction, **parse_overrides(args.set)}
    newtonian = {"numerics.shifting": AUTO_SHIFTING_NON_NEWTONIAN, **shared}
    print(f"φ = {args.phi}, box {BOX} h, a = {RADIUS} h, strain {transient:g} + {units}"
          f"{overrides_text(newtonian)}", flush=True)
    name, params = matrix_law(args.x, 99.0, RATE)
    law = make_law(name, params)
    matrix = {**shared, "fluid": {"law": name, "params": dict(params)}}
    for seed in args.seeds:
        g, m = (relative_viscosity(phi=args.phi, radius=RADIUS, box=BOX, seed=seed,
                                   transient=transient, units=units, overrides=overrides)
                for overrides in (newtonian, matrix))
        cot = float(chateau_ovarlez_trung_viscosity(law.viscosity, RATE, args.phi,
                                                    g.relative_viscosity))
        print(f"friction {args.friction:g}, x {args.x:g}, seed {seed}: g "
              f"{g.relative_viscosity:.3f} ± {g.stderr:.3f}, eta_r {m.relative_viscosity:.3f} ± "
              f"{m.stderr:.3f}, COT {cot:.3f}, ratio {m.relative_viscosity / cot:.3f}",
              flush=True)


if __name__ == "__main__":
    main()
