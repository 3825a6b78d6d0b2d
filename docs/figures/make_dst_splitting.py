"""Make docs/figures/dst_splitting.{nc,png}: stress splitting of the local DST model (issue 5).

    python docs/figures/make_dst_splitting.py [--threads N] [--lattice NX NY] [--stresses ...]
    python docs/figures/make_dst_splitting.py --plot-only   # redraw from the .nc

A documented script until the workflow wiring lands (seed 002 Fig. 5). For φ = 0.54 with zero
non-locality (α = 0) runs :func:`suspsim.dst.study.stress_splitting` at imposed stresses inside
the unstable range σ_β = 0.761σ* < σ_in < σ_α = 3.92σ* (its docstring gives the perturbed start,
the sound speed and the 20 + 20 strain units of equilibration and averaging), draws ψ1, ψ2
against q with the lever rule through :func:`suspsim.plotting.dst.plot_branch_split`, and prints
the table. Scaled units: L_y = η_s = σ* = 1.

Output: ``dst_splitting.nc`` (netCDF4, the Dataset on ``stress``) and ``dst_splitting.png``,
both written atomically.
"""
import argparse
import logging
from pathlib import Path

import xarray as xr

from suspsim.dst.study import stress_splitting
from suspsim.io.atomic import atomic_path, save_figure
from suspsim.plotting.dst import plot_branch_split

HERE = Path(__file__).resolve().parent
NETCDF, FIGURE = HERE / "dst_splitting.nc", HERE / "dst_splitting.png"
PHI = 0.54
STRESSES = (2.0, 2.8)  # 3.5 blew up (density error), 1.2 took 641 s: see the report


def _table(data):
    a = data.attrs
    print(f"\nphi = {a['phi']:.2f}, alpha = {a['alpha']:g}, {a['n_x']} x {a['n_y']} fluid "
          f"particles, wall {a['wall_time_s']:.0f} s")
    print("  sigma_in   q      psi1 +- se      psi2 +- se     sum    lever(V_w)  "
          "psi1-lever +- se   lever(WC)  V_w/L_y/gdot_WC")
    for k in range(data.sizes["stress"]):
        p = {name: float(v) for name, v in data.isel(stress=k).data_vars.items()}
        s = float(data["stress"][k])
        print(f"  {s:6.3g}  {p['q']:5.3f}  {p['psi1']:.3f} +- {p['psi1_stderr']:.3f}"
              f"  {p['psi2']:.3f} +- {p['psi2_stderr']:.3f}  {p['psi_sum']:.3f}"
              f"  {p['lever_rule']:9.3f}  {p['psi1_minus_lever']:+.3f} +- "
              f"{p['psi1_minus_lever_stderr']:.3f}  {p['wyart_cates_lever_rule']:9.3f}"
              f"  {p['wall_shear_rate'] / p['wyart_cates_shear_rate']:.3f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=1, help="solver threads (default 1)")
    parser.add_argument("--lattice", type=int, nargs=2, default=(14, 12),
                        metavar=("NX", "NY"), help="fluid particles (default 14 12)")
    parser.add_argument("--stresses", type=float, nargs="+", default=STRESSES,
                        help="imposed stresses in sigma* (default %(default)s)")
    parser.add_argument("--plot-only", action="store_true",
                        help="redraw the figure and table from the existing .nc, no runs")
    args = parser.parse_args()
    if args.plot_only:
        data = xr.load_dataset(NETCDF)
    else:
        logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s",
                            datefmt="%H:%M:%S")
        data = stress_splitting(PHI, args.stresses, lattice=tuple(args.lattice),
                                threads=args.threads)
        with atomic_path(NETCDF) as tmp:
            data.to_netcdf(tmp, engine="netcdf4", encoding={"stress": {"_FillValue": None}})
    _table(data)
    save_figure(plot_branch_split(data), FIGURE)
    print(f"\nwrote {FIGURE}" + ("" if args.plot_only else f" and {NETCDF}"))


if __name__ == "__main__":
    main()
