"""Make docs/figures/dst_channel.{nc} and its PNGs: DST channel flow (seed 002 Fig. 7–8, issue 5).

    python docs/figures/make_dst_channel.py [--threads N] [--lattice NX NY] [--forces F ...]
                                            [--sets NAME ...]
    python docs/figures/make_dst_channel.py --plot-only   # redraw from the .nc

The dst study's channel rules (``dst.channel`` in ``config/studies/dst.yaml``) run the same
sets as one job per force; this script runs them in one process. At φ = 0.54 runs
:func:`suspsim.dst.channel_study.channel_sweep` over ``--forces`` (F H/σ*, default 12 values
0.5–200, denser between 1 and 10) for

* seed 002's jamming fractions (φ_m = 0.562, φ_0 = 0.693): the local model (α = 0, the
  validation test's momentum protocol), strong (α = 0.02) and moderate (α = 2e−5)
  non-locality (microstructure-relaxed protocol);
* its Fig. 8 pair (φ_m = 0.56, φ_0 = 0.64): the local model, and strong non-locality with
  ``--sets`` naming ``fig8-strong`` (not in the default: it alone costs 16 min on one
  shared core, the four default sets together 25 min; measured in one run of all five);

draws the profiles at F H/σ* = 1, 10, 100 of the seed-parameter runs
(:func:`suspsim.plotting.dst_channel.plot_channel_profiles`, Fig. 7) and the mean velocity
against force of every run with the local ODE and the inverse-biviscous model
(:func:`~suspsim.plotting.dst_channel.plot_channel_flow`, Fig. 8), and prints a table per run
and the total wall time. Scaled units: L_y = η_s = σ* = 1.

Output: ``dst_channel.nc`` (netCDF4, one group per run set, named in the root attribute
``groups``), ``dst_channel_profiles.png`` and ``dst_channel_flow.png``, all written
atomically.
"""
import argparse
import logging
import time
from pathlib import Path

from suspsim.dst.channel_study import channel_sweep
from suspsim.dst.study import LOCAL, MODERATE_NONLOCALITY, SEED_002, STRONG_NONLOCALITY
from suspsim.io.atomic import save_figure
from suspsim.plotting.dst_channel import plot_channel_flow, plot_channel_profiles
from suspsim.stages.dst_channel_gather import read_groups, write_groups

HERE = Path(__file__).resolve().parent
NETCDF = HERE / "dst_channel.nc"
PROFILES, FLOW = HERE / "dst_channel_profiles.png", HERE / "dst_channel_flow.png"
PHI = 0.54
FORCES = (0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 10.0, 20.0, 50.0, 100.0, 200.0)
PROFILE_FORCES = (1.0, 10.0, 100.0)
SEED = {"phi_m": SEED_002["phi_m"], "phi_0": SEED_002["phi_0"]}
FIG8 = {"phi_m": 0.56, "phi_0": 0.64}
#: group name -> (jamming fractions, α)
RUNS = {"seed-local": (SEED, LOCAL), "seed-strong": (SEED, STRONG_NONLOCALITY),
        "seed-moderate": (SEED, MODERATE_NONLOCALITY), "fig8-local": (FIG8, LOCAL),
        "fig8-strong": (FIG8, STRONG_NONLOCALITY)}
DEFAULT_SETS = ("seed-local", "seed-strong", "seed-moderate", "fig8-local")


def _table(name, data):
    a = data.attrs
    print(f"\n{name}: phi_m {a['phi_m']}, phi_0 {a['phi_0']}, alpha {a['alpha']:g} "
          f"({a['protocol']}), {a['n_x']} x {a['n_y']}, gamma_c {a['critical_rate']:.4g}, "
          f"wall {a['wall_time_s']:.0f} s")
    print("  F H/s*   u_SPH       u_ODE       SPH/ODE-1   u_IB        L2/peak  strain  "
          "drift     steps    wall [s]")
    for k in range(data.sizes["force_ratio"]):
        p = data.isel(force_ratio=k)
        print(f"  {float(p['force_ratio']):6g}   {float(p['mean_velocity']):.4e}  "
              f"{float(p['local_mean_velocity']):.4e}  {float(p['mean_velocity_error']):+8.2%}"
              f"   {float(p['inverse_biviscous_mean_velocity']):.4e}  "
              f"{float(p['velocity_l2_error']):7.2%}  {float(p['microstructure_strain']):6.2f}"
              f"  {float(p['mean_velocity_drift']):+.1e}  {int(p['steps']):7d}  "
              f"{float(p['wall_time']):7.1f}")


def _figures(datasets):
    # Fig. 7 shows one parameter set: seed 002's when it was run
    seed = [datasets[n] for n in datasets if n.startswith("seed-")] or [
        datasets[n] for n in datasets if n.startswith("fig8-")]
    save_figure(plot_channel_profiles(seed, PROFILE_FORCES), PROFILES)
    save_figure(plot_channel_flow(list(datasets.values())), FLOW)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=1, help="solver threads (default 1)")
    parser.add_argument("--lattice", type=int, nargs=2, default=(14, 20),
                        metavar=("NX", "NY"), help="fluid particles (default 14 20)")
    parser.add_argument("--forces", type=float, nargs="+", default=FORCES,
                        help="F H/sigma* values (must include 1 10 100 for the profiles)")
    parser.add_argument("--sets", nargs="+", choices=tuple(RUNS), default=DEFAULT_SETS,
                        help="run sets (default: " + " ".join(DEFAULT_SETS) + ")")
    parser.add_argument("--plot-only", action="store_true",
                        help="redraw the figures and tables from the existing .nc, no runs")
    args = parser.parse_args()
    if args.plot_only:
        datasets = read_groups(NETCDF)
        for name, data in datasets.items():
            _table(name, data)
        _figures(datasets)
        print(f"\nwrote {PROFILES} and {FLOW}")
        return
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(message)s", datefmt="%H:%M:%S")
    start = time.perf_counter()
    datasets = {}
    for name in args.sets:
        fractions, alpha = RUNS[name]
        datasets[name] = channel_sweep(PHI, args.forces, alpha=alpha,
                                       lattice=tuple(args.lattice), threads=args.threads,
                                       **fractions)
        _table(name, datasets[name])
    total = time.perf_counter() - start
    write_groups(NETCDF, datasets)
    _figures(datasets)
    runs = sum(d.sizes["force_ratio"] for d in datasets.values())
    print(f"\ntotal wall time {total:.0f} s ({runs} runs, threads {args.threads}); wrote "
          f"{NETCDF}, {PROFILES} and {FLOW}")


if __name__ == "__main__":
    main()
