"""Make docs/figures/shape_comparison.png: sand grains against spheres at equal φ and γ̇.

    python docs/figures/make_shape_comparison.py \
        [results/spheres/linear_polymer/summary.nc results/sand/linear_polymer/summary.nc]

Reads the summaries of the `spheres` and `sand` studies (run them first:
`snakemake --cores 2 --configfile config/studies/{spheres,sand}.yaml`), draws
:func:`suspsim.plotting.shapes.plot_shape_comparison` and prints η_r of both and their ratio
(:func:`suspsim.plotting.shapes.shape_ratio`) at each common φ > 0 and γ̇.
"""
import argparse
from pathlib import Path

import xarray as xr

from suspsim.io.atomic import save_figure
from suspsim.plotting.shapes import plot_shape_comparison, relative_viscosity_table, shape_ratio

OUTPUT = Path(__file__).resolve().with_name("shape_comparison.png")
DEFAULTS = ("results/spheres/linear_polymer/summary.nc", "results/sand/linear_polymer/summary.nc")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spheres", nargs="?", default=DEFAULTS[0])
    parser.add_argument("sand", nargs="?", default=DEFAULTS[1])
    args = parser.parse_args()
    with xr.open_dataset(args.spheres) as spheres, xr.open_dataset(args.sand) as sand:
        spheres, sand = spheres.load(), sand.load()
    save_figure(plot_shape_comparison({"spheres": spheres, "sand grains": sand}), OUTPUT)
    ratio = shape_ratio(sand, spheres)
    a, b = relative_viscosity_table(spheres), relative_viscosity_table(sand)
    print(f"{OUTPUT}\n| φ | γ̇ [1/s] | η_r spheres | η_r sand | sand/spheres |\n|---|---|---|---|---|")
    for phi in ratio["phi"].values:
        for rate in ratio["shear_rate"].values:
            at = dict(phi=phi, shear_rate=rate)
            r = ratio.sel(**at)
            print(f"| {phi:g} | {rate:g} | {float(a['relative_viscosity'].sel(**at)):.3f} ± "
                  f"{float(a['relative_viscosity_error'].sel(**at)):.3f} | "
                  f"{float(b['relative_viscosity'].sel(**at)):.3f} ± "
                  f"{float(b['relative_viscosity_error'].sel(**at)):.3f} | "
                  f"{float(r['ratio']):.3f} ± {float(r['ratio_error']):.3f} |")


if __name__ == "__main__":
    main()
