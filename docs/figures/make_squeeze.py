"""Make docs/figures/squeeze_force.{nc,png}: resolved SPH squeeze force between two spheres.

    python docs/figures/make_squeeze.py [--threads N] [--reduced] [--no-large]
        [--no-half-speed] [--set numerics.KEY=VALUE ...] [--slide K] [--phases P]
    python docs/figures/make_squeeze.py --plot-only    # redraw from the .nc

Runs :func:`suspsim.validation.squeeze.squeeze_study` for a = 2.5 h (box 25 × 20 × 20 h,
Re = 0.05, and the same at half the speed for the quasi-steady check, skipped with
--no-half-speed, which writes nothing) and a = 4 h (box 32 × 25 × 25 h, Re = 0.1; skipped
with --no-large), draws them with
:func:`suspsim.plotting.squeeze.plot_squeeze` and prints the table s, F/F_theory and the
recommended cutoff gap, and the resolved force plus the lubrication correction at the cutoff
the scene applies (auto: ``scene_rules.AUTO_CUTOFF_GAP_CORRECTED``). --reduced: the test's small
case only, printed and not written. The runs are kept in ``squeeze_force.nc`` (netCDF4
groups, one per run, named by its label). ``--set`` takes
numerics keys of the runs' scenes (VALUE as JSON, e.g. ``numerics.shifting=100``); such runs
print their tables and write no file. ``--slide K``: the spheres also slide past each other at
±K U while they approach (``squeeze_run``'s ``slide_ratio``; K = 1 is a pair at 45° in the
compressional quadrant of a shear), at Re = 0.05 only; the table adds the sliding force over
Jeffrey–Onishi's Y^A, and nothing is written. ``--phases P``: every approach runs at P
shifts of the pair against the fluid's start lattice (``squeeze.lattice_shifts``), the ratios
are the means over them, and the table adds each ratio's range over the phases.
"""
import argparse
import json
from pathlib import Path

import xarray as xr

from suspsim.io.atomic import atomic_path, save_figure
from suspsim.plotting.squeeze import plot_squeeze
from suspsim.validation.squeeze import lattice_shifts, squeeze_study, stokes_drag

OUTPUT = Path(__file__).resolve().with_name("squeeze_force.png")
NETCDF = OUTPUT.with_suffix(".nc")


def _table(data, title):
    a = data.attrs
    print(f"\n{title}: a = {a['radius']:g} h, box {[float(b) for b in a['box']]} h, "
          f"U = {a['speed']:.4g}, "
          f"Re = {a['particle_reynolds_number']:g}, a_h/a = {a['hydrodynamic_radius_ratio']:.3f}"
          f", {a['n_particles']} particles, wall {a['squeeze_wall_time_s']:.0f} s + "
          f"{a['drag_wall_time_s']:.0f} s; cutoff gap s_c = {a['cutoff_gap']:.3g} h")
    print(f"lubrication correction at the scene's cutoff {a['lubrication_cutoff_gap']:.3g} h")
    sliding = data["ratio_sliding"].values if "ratio_sliding" in data else None
    phases = data.sizes.get("phase", 1)
    if phases > 1:
        shifts = [round(float(x), 4) for x in data["phase"].values]
        print(f"means over {phases} lattice phases (shifts {shifts} h); [range over them]")
    print("   s [h]   F/(6pi mu a U)   F/F_th(a_h)   F/F_th(a)   +lub./F_th(a)   box/free"
          + ("   sliding/F_th(a)" if sliding is not None else ""))
    for k, (s, n, r, rn, rc, c) in enumerate(zip(
            data["gap"].values, data["normalised_force"].values, data["ratio"].values,
            data["ratio_nominal"].values, data["ratio_combined"].values,
            data["image_correction"].values)):
        line = f"  {s:6.3f}   {n:12.4g}   {r:11.3f}   {rn:9.3f}   {rc:13.3f}   {c:8.3f}"
        if phases > 1:
            line += _range(data["phase_ratio_nominal"].values[:, k])
        if sliding is not None:
            line += f"   {sliding[k]:15.3f}"
            if phases > 1:
                line += _range(data["phase_ratio_sliding"].values[:, k])
        print(line)


def _range(values) -> str:
    return f" [{min(values):.2f}, {max(values):.2f}]"


def _save(runs, labels) -> None:
    """All runs into :data:`NETCDF`, one group per run (``box`` as a variable: netCDF
    attributes hold no arrays of that kind), written atomically."""
    groups = {}
    for k, (data, label) in enumerate(zip(runs, labels)):
        data = data.copy()
        data.attrs = {key: (list(map(float, value)) if key == "box" else value)
                      for key, value in data.attrs.items()}
        data.attrs["label"] = label
        groups[f"run{k}"] = data
    with atomic_path(NETCDF) as tmp:
        xr.DataTree.from_dict(groups).to_netcdf(tmp, engine="netcdf4")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=1, help="solver threads (default 1)")
    parser.add_argument("--reduced", action="store_true", help="the test's reduced case")
    parser.add_argument("--no-large", action="store_true", help="skip a = 4 h")
    parser.add_argument("--plot-only", action="store_true", help=f"redraw from {NETCDF.name}")
    parser.add_argument("--set", action="append", default=[], metavar="numerics.KEY=VALUE",
                        help="a numerics key of every run (repeatable; nothing is written)")
    parser.add_argument("--slide", type=float, default=0.0, metavar="K",
                        help="slide at +-K U while approaching (nothing is written)")
    parser.add_argument("--no-half-speed", action="store_true",
                        help="skip the quasi-steady check at Re = 0.025 (nothing is written)")
    parser.add_argument("--phases", type=int, default=1, metavar="P",
                        help="run each approach at P shifts against the start lattice")
    args = parser.parse_args()
    if args.phases < 1:
        parser.error(f"--phases {args.phases}: give at least 1")
    numerics = {}
    for item in args.set:
        key, _, value = item.partition("=")
        if not key.startswith("numerics.") or not value:
            parser.error(f"--set {item}: give numerics.KEY=VALUE")
        numerics[key.removeprefix("numerics.")] = json.loads(value)
    common = {"threads": args.threads, "numerics": numerics or None,
              "shifts": lattice_shifts(args.phases)}
    slide = {"slide_ratio": args.slide} if args.slide > 0 else {}
    runs, labels = [], []
    if args.plot_only:
        with xr.open_datatree(NETCDF) as tree:
            for node in tree.children.values():
                runs.append(node.to_dataset().load())
                labels.append(node.attrs["label"])
    elif args.reduced:
        runs.append(squeeze_study(2.5, (20.0, 15.0, 15.0), reynolds=0.1, end_gap=0.1,
                                  **common, **slide))
        labels.append("a = 2.5 h, reduced")
    else:
        box = (25.0, 20.0, 20.0)
        drag = stokes_drag(2.5, box, reynolds=0.05, threads=args.threads,
                           numerics=numerics or None)
        for reynolds in (0.05,) if args.slide > 0 or args.no_half_speed else (0.05, 0.025):
            runs.append(squeeze_study(2.5, box, reynolds=reynolds, drag=drag, **common,
                                      **slide))
            labels.append(f"a = 2.5 h, Re = {reynolds:g}")
        if not args.no_large:
            runs.append(squeeze_study(4.0, (32.0, 25.0, 25.0), reynolds=0.1, **common,
                                      **slide))
            labels.append("a = 4 h, Re = 0.1")
    for data, label in zip(runs, labels):
        _table(data, label)
    if numerics or args.reduced or args.slide > 0 or args.no_half_speed:
        return
    if not args.plot_only:
        _save(runs, labels)
    save_figure(plot_squeeze(runs, labels=labels), OUTPUT)
    print(f"\nwrote {OUTPUT}")


if __name__ == "__main__":
    main()
