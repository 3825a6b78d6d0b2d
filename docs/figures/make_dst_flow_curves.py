"""Make docs/figures/dst_flow_curves.{nc,png}: stress-controlled DST flow curves (issue 5).

    python docs/figures/make_dst_flow_curves.py [--threads N] [--count N] [--lattice NX NY]
    python docs/figures/make_dst_flow_curves.py --plot-only   # redraw from the .nc

A documented script until the workflow wiring lands. For φ = 0.48 (CST), 0.50 and 0.54 (DST)
with strong non-locality (α = 0.02 L_y²σ*/η_s, seed 002's 1e−5 m²/s) runs
:func:`suspsim.dst.study.flow_curve` — the set-up and equilibration of
``tests/validation/test_dst.py`` — at ``--count`` imposed stresses per φ from
:func:`suspsim.dst.study.spanning_stresses` (0.2–40 σ*, a third of them on the unstable branch
between σ_β and σ_α), draws them with :func:`suspsim.plotting.dst.plot_flow_curves`, and
prints γ̇/γ̇_WC per point and the total wall time. Scaled units: L_y = η_s = σ* = 1.

Output: ``dst_flow_curves.nc`` (netCDF4, one group ``phi-<φ>`` per volume fraction holding
that flow-curve Dataset; the root group has the global attributes) and
``dst_flow_curves.png``, both written atomically.
"""
import argparse
import logging
import time
from pathlib import Path

from suspsim.dst.parameters import WyartCatesFluid
from suspsim.dst.study import SEED_002, STRONG_NONLOCALITY, flow_curve, spanning_stresses
from suspsim.io.atomic import save_figure
from suspsim.io.grouped import read_grouped, write_grouped
from suspsim.plotting.dst import plot_flow_curves

HERE = Path(__file__).resolve().parent
NETCDF, FIGURE = HERE / "dst_flow_curves.nc", HERE / "dst_flow_curves.png"
VOLUME_FRACTIONS = (0.48, 0.50, 0.54)


def write_groups(path, datasets, total_wall_time):
    """One netCDF4 group per dataset (``phi-<φ>``) under a root group of global attributes."""
    write_grouped(path, {_group(d): d for d in datasets},
                  title="Stress-controlled 2D SPH DST flow curves (Wyart-Cates), strong "
                        "non-locality",
                  module="docs/figures/make_dst_flow_curves.py",
                  attrs={"wall_time_s": total_wall_time})


def _group(data):
    return f"phi-{data.attrs['phi']:.2f}"


def _table(data):
    a = data.attrs
    turning = (f"sigma_beta {a['sigma_beta']:.4g}, sigma_alpha {a['sigma_alpha']:.4g}"
               if a["regime"] != "CST" else "no turning points")
    print(f"\nphi = {a['phi']:.2f} ({a['regime']}, {turning}), {a['n_x']} x {a['n_y']} fluid "
          f"particles, wall {a['wall_time_s']:.0f} s")
    print("  sigma_in   gdot_WC      <gdot>/gdot_WC  +- stderr  V_w/L_y/gdot_WC"
          "  <sigma>/sigma_in  branch")
    for k in range(data.sizes["stress"]):
        p = data.isel(stress=k)
        s, rate = float(p["stress"]), float(p["wyart_cates_shear_rate"])
        branch = ("unstable" if a["regime"] != "CST" and a["sigma_beta"] < s < a["sigma_alpha"]
                  else "stable")
        print(f"  {s:8.4g}   {rate:10.4g}   {float(p['shear_rate']) / rate:12.4f}"
              f"   {float(p['shear_rate_stderr']) / rate:8.1e}"
              f"   {float(p['wall_shear_rate']) / rate:13.4f}"
              f"   {float(p['measured_stress']) / s:15.4f}  {branch}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=1, help="solver threads (default 1)")
    parser.add_argument("--count", type=int, default=12, help="stresses per phi (default 12)")
    parser.add_argument("--lattice", type=int, nargs=2, default=(14, 20),
                        metavar=("NX", "NY"), help="fluid particles (default 14 20)")
    parser.add_argument("--plot-only", action="store_true",
                        help="redraw the figure and table from the existing .nc, no runs")
    args = parser.parse_args()
    if args.plot_only:
        datasets = list(read_grouped(NETCDF, "the DST flow curves").values())
        for data in datasets:
            _table(data)
        save_figure(plot_flow_curves(datasets), FIGURE)
        print(f"\nwrote {FIGURE}")
        return
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s", datefmt="%H:%M:%S")
    start = time.perf_counter()
    datasets = []
    for phi in VOLUME_FRACTIONS:
        fluid = WyartCatesFluid(eta_s=1.0, phi=phi, sigma_star=1.0, alpha=STRONG_NONLOCALITY,
                                **SEED_002)
        datasets.append(flow_curve(phi, spanning_stresses(fluid, args.count),
                                   alpha=STRONG_NONLOCALITY, lattice=tuple(args.lattice),
                                   threads=args.threads))
        _table(datasets[-1])
    total = time.perf_counter() - start
    write_groups(NETCDF, datasets, total)
    save_figure(plot_flow_curves(datasets), FIGURE)
    print(f"\ntotal wall time {total:.0f} s ({sum(d.sizes['stress'] for d in datasets)} runs, "
          f"threads {args.threads}); wrote {NETCDF} and {FIGURE}")


if __name__ == "__main__":
    main()
