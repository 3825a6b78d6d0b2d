"""The ``suspsim`` command line: ``suspsim fit FILE [--law NAME|auto] [--sample ID] [--out F] [--plot F]``.

Also ``suspsim run SCENE.yaml --out RUN.nc [--resume] [--threads N] [--tolerance EPS
[--no-verify]]`` (an SPH run, see :mod:`suspsim.run`, or a DST run of a wyart_cates scene, see
:mod:`suspsim.dst.run`; ``--tolerance`` chooses the numerics from the error model and checks
the runs against the exact solution, :mod:`suspsim.convergence.tolerance`),
``suspsim bench [--scene NAME] [--threads N] [--steps K] [--particles N] [--against-fluid
[--rounds R]] [--json]`` and
``suspsim pack --shape sphere|sand --phi PHI --radius A --box LX LY LZ --out PACK.nc
[--polydispersity S] [--seed N] ...`` (a random packing, see :mod:`suspsim.bodies.packing`).

Exit codes: 0 success; 1 user or input error (one line on stderr naming the file, the place
in it and the problem, or the bad command-line option; no output written); 2 numerical
failure (the last good checkpoint is kept; a packing that cannot be reached writes nothing);
128 + signal for a run stopped by a signal after saving its checkpoint (130 SIGINT, 143 SIGTERM;
``--resume`` continues it).
"""
from __future__ import annotations

import argparse
import json
import logging
import platform
import sys
from typing import Sequence

from . import __version__
from .errors import InputError, NumericalError, SuspsimError

log = logging.getLogger("suspsim")


class _Parser(argparse.ArgumentParser):
    """argparse with the exit code of a user error (1, not argparse's 2, which means a
    numerical failure here) and a one-line message instead of usage + message."""

    def error(self, message: str):
        self.exit(1, f"{self.prog}: error: {message}\n")


def _build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="suspsim", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"suspsim {__version__}")
    parser.add_argument("-q", "--quiet", action="store_true", help="log warnings and errors only")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    fit = sub.add_parser("fit", help="fit a constitutive law to a rheometer flow curve")
    fit.add_argument("file", help="rheometer export (CSV/TXT in any common layout, TRIOS .xls/.xlsx, "
                     "Anton Paar RheoCompass, HAAKE RheoWin)")
    fit.add_argument("--law", default="auto", help="law name, or auto to choose by information "
                     "criterion (default: auto)")
    fit.add_argument("--sample", help="sample to fit when the file holds several")
    fit.add_argument("--criterion", default="bic", choices=("bic", "aic", "aicc"),
                     help="information criterion for --law auto (default: bic)")
    fit.add_argument("--out", help="write the fit as JSON (SI units)")
    fit.add_argument("--plot", help="write a figure of data and fit (.png, .pdf, .svg)")

    run = sub.add_parser("run", help="run an SPH or DST scene and write its results as netCDF")
    run.add_argument("scene", help="scene file (YAML)")
    run.add_argument("--out", required=True, help="output netCDF file; its checkpoint is "
                     "OUT.ckpt.npz beside it until the run completes")
    run.add_argument("--resume", action="store_true", help="continue an interrupted run from "
                     "its checkpoint")
    run.add_argument("--threads", type=_positive_int, help="worker threads (default: the "
                     "scene's run.threads)")
    run.add_argument("--tolerance", type=float, help="relative error to meet: the scene gives "
                     "the physics, the measured error model chooses resolution, time step, "
                     "sound speed, box side or channel width and averaging; the runs are "
                     "measured against the flow's exact solution until one meets it, each "
                     "missed one recalibrating the model (SPH fluid couette/poiseuille scenes; "
                     "see suspsim.convergence.tolerance)")
    run.add_argument("--no-verify", action="store_true", help="with --tolerance: one run of "
                     "the cheapest set-up whose inflated model bound meets the tolerance, not "
                     "measured")

    bench = sub.add_parser("bench", help="measure the solver's speed on standard scenes")
    bench.add_argument("--scene", choices=BENCH_SCENES, help="one scene (default: all)")
    bench.add_argument("--threads", type=_positive_int, help="worker threads (default: every "
                       "thread numba may use)")
    bench.add_argument("--steps", type=_positive_int, default=200, help="time steps to time "
                       "(default: 200)")
    bench.add_argument("--particles", type=_lattice_count, default=32768,
                       help="lattice sites of the box, a cube k^3 (box side k/1.6 h; default: "
                       "32768, the 20 h box; dst-2d: about this many fluid particles); for "
                       "the scaling with N")
    bench.add_argument("--against-fluid", action="store_true", help="time each suspension "
                       "scene against its fluid in one process, alternating --rounds slices "
                       "of the --steps, and report the cost of a step per particle relative "
                       "to the fluid's")
    bench.add_argument("--rounds", type=_positive_int, default=10, help="slices of "
                       "--against-fluid (default: 10)")
    bench.add_argument("--json", action="store_true", help="print one JSON object per scene")

    pack = sub.add_parser("pack", help="pack random non-overlapping spheres or sand grains in a "
                          "periodic box and write them as netCDF")
    pack.add_argument("--shape", required=True, choices=("sphere", "sand"), help="body shape")
    pack.add_argument("--phi", required=True, type=float, help="volume fraction, exact "
                      "(tested up to 0.55 for spheres, 0.50 for sand)")
    pack.add_argument("--radius", required=True, type=float, help="mean (volume-equivalent) "
                      "radius [h]")
    pack.add_argument("--box", required=True, type=float, nargs=3, metavar=("LX", "LY", "LZ"),
                      help="box lengths [h]")
    pack.add_argument("--out", required=True, help="output netCDF file")
    pack.add_argument("--polydispersity", type=float, default=0.0, help="coefficient of "
                      "variation of the radii, truncated lognormal (default: 0)")
    pack.add_argument("--size-ratio", type=float, default=5.0, help="largest/smallest radius "
                      "bound, at most 5 (default: 5)")
    pack.add_argument("--seed", type=int, default=0, help="random seed (default: 0)")
    pack.add_argument("--min-gap", type=float, help="smallest gap between bodies [h] "
                      "(default: 1e-3 x radius)")
    pack.add_argument("--max-steps", type=int, help="relaxation step budget "
                      "(default: 200000 for spheres, 20000 for sand)")
    pack.add_argument("--degree", type=int, help="sand: spherical-harmonic degree (default: 20)")
    pack.add_argument("--roughness", type=float, help="sand: rms radius deviation of degrees "
                      ">= 3, relative (default: 0.02)")
    pack.add_argument("--elongation", type=float, nargs=2, metavar=("LOW", "HIGH"),
                      help="sand: range of the elongation L/W (default: 1.2 1.6)")
    return parser


#: Scenes of ``suspsim bench`` (defined in :mod:`suspsim.sph.bench`).
BENCH_SCENES = ("fluid-newtonian", "fluid-newtonian-unnormalised", "fluid-papanastasiou",
                "suspension-newtonian", "suspension-papanastasiou", "dst-2d")
_BENCH_COLUMNS = (("scene", "scene", "{}"), ("particles", "n_particles", "{}"),
                  ("threads", "threads", "{}"), ("steps", "steps", "{}"),
                  ("wall s", "wall_time_s", "{:.3g}"),
                  ("particle-steps/s", "particle_steps_per_s", "{:.3g}"),
                  ("rebuilds", "rebuilds", "{}"),
                  ("viscosity error", "viscosity_error", "{:+.2%}"),
                  ("density error", "density_error", "{:.2%}"),
                  ("rebuild share", "rebuild_share", "{:.1%}"),
                  ("bytes/particle", "bytes_per_particle", "{:.0f}"))


def _lattice_count(text: str) -> int:
    from .sph.bench import lattice_side

    value = _positive_int(text)
    try:
        lattice_side(value)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None
    return value


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text}")
    return value


def _cmd_fit(args) -> int:
    from .stages.fit import fit_matrix_file, format_fit_table

    result = fit_matrix_file(args.file, law=args.law, sample=args.sample, criterion=args.criterion,
                             out_json=args.out, out_plot=args.plot)
    print(format_fit_table(result))
    return 0


def _cmd_run(args) -> int:
    from .io.netcdf import read_run
    from .scene import Scene, load_any_scene

    scene = load_any_scene(args.scene)
    if args.tolerance is not None:
        from .convergence import tolerance

        if not isinstance(scene, Scene):
            raise InputError(args.scene, tolerance.SUPPORTED)
        if args.no_verify:
            from .run import run_scene

            scene, choice, attrs = tolerance.choose(scene, args.tolerance)
            print(f"tolerance {args.tolerance:g}: {attrs['tolerance_settings']}; expected error "
                  f"{choice.expected_error:.3g}, expected cost {choice.expected_cost:.3g} s CPU "
                  f"({choice.drivers.n_particles} particles, {choice.drivers.n_steps} steps)")
            out = run_scene(scene, args.out, resume=args.resume, threads=args.threads,
                            extra_attrs=attrs)
        else:
            attempts = tolerance.run_verified(scene, args.tolerance, args.out,
                                              resume=args.resume, threads=args.threads)
            for k, a in enumerate(attempts, 1):
                print(f"tolerance {args.tolerance:g}, attempt {k}: {json.dumps(a.settings)}; "
                      f"expected error {a.calibration * a.model_error:.3g}, measured "
                      + ("blew up" if a.blew_up else f"{a.measured:.3g}")
                      + f", {a.cpu_time:.3g} s CPU")
            out = args.out
    elif isinstance(scene, Scene):
        from .run import run_scene

        out = run_scene(scene, args.out, resume=args.resume, threads=args.threads)
    else:
        from .dst.run import run_dst_scene

        out = run_dst_scene(scene, args.out, resume=args.resume, threads=args.threads)
    result = read_run(out)
    if "viscosity" in result:
        print(f"viscosity {float(result['viscosity']):.6g} ± "
              f"{float(result['viscosity_stderr']):.2g} "
              f"[{result['viscosity'].attrs.get('simulation_units', '1')}]")
    if "imposed_stress" in result:
        print(f"flow-curve point: shear rate {_value(result, 'mean_shear_rate')}, stress "
              f"{_value(result, 'mean_stress')} at imposed stress "
              f"{float(result['imposed_stress']):.6g} (Wyart-Cates shear rate "
              f"{float(result['wyart_cates_shear_rate']):.6g})")
    if "reference_bulk_velocity" in result:
        print(f"bulk velocity {_value(result, 'mean_bulk_velocity')} (local-model reference "
              f"{float(result['reference_bulk_velocity']):.6g})")
    print(f"Reynolds number {result.attrs['reynolds_number']:.3g}, largest Mach number "
          f"{result.attrs['mach_number']:.3g}, {result.attrs['particle_steps_per_s']:.3g} "
          f"particle-steps/s; wrote {out}")
    return 0


def _value(result, name: str) -> str:
    """``mean ± stderr [units]`` of a steady-window mean in a run file."""
    units = result[name].attrs.get("simulation_units", result[name].attrs.get("units", "1"))
    return (f"{float(result[name]):.6g} ± {float(result[f'{name}_stderr']):.2g} [{units}]")


def _cmd_bench(args) -> int:
    import json

    from .sph.bench import SUSPENDING_FLUID, benchmark, paired_cost

    if args.threads is None:
        import numba

        args.threads = numba.config.NUMBA_NUM_THREADS
    if args.against_fluid:
        if args.rounds > args.steps:
            raise InputError("--rounds", f"{args.rounds} exceeds --steps {args.steps}: each "
                             "round times at least one step")
        if args.scene not in (None, *SUSPENDING_FLUID):
            raise InputError("--scene", f"--against-fluid takes a suspension scene "
                             f"({', '.join(SUSPENDING_FLUID)}), not {args.scene}")
        scenes = [args.scene] if args.scene else list(SUSPENDING_FLUID)
        for name in scenes:
            result = paired_cost(name, args.steps, args.threads, args.rounds, args.particles)
            print(json.dumps(result) if args.json else
                  f"{name}: a step per particle costs {result['cost_ratio']:.2f} x "
                  f"{result['fluid']}'s ({result['threads']} thread(s), {result['steps']} "
                  f"steps each in {result['rounds']} alternating slices; slices "
                  f"{min(result['slice_ratios']):.2f}-{max(result['slice_ratios']):.2f}; "
                  f"{result['particle_steps_per_s']:.3g} against "
                  f"{result['fluid_particle_steps_per_s']:.3g} particle-steps/s)", flush=True)
        return 0
    results = []
    for name in [args.scene] if args.scene else BENCH_SCENES:
        result = benchmark(name, args.steps, args.threads, args.particles)
        if args.json:
            print(json.dumps(result), flush=True)
        results.append(result)
    if not args.json:
        rows = [[title for title, _, _ in _BENCH_COLUMNS]]
        rows += [[fmt.format(r[key]) if key in r else "-" for _, key, fmt in _BENCH_COLUMNS]
                 for r in results]
        widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
        for row in rows:
            print("  ".join(cell.rjust(width) for cell, width in zip(row, widths)))
        for r in results:
            if "pass_ms" in r:
                print(f"{r['scene']} pass times [ms]: "
                      + ", ".join(f"{k} {v:.2f}" for k, v in r["pass_ms"].items()))
    return 0


#: Packing parameters (Python API names) and the options that set them.
_PACK_OPTIONS = {"volume_fraction": "--phi", "radius": "--radius", "box": "--box",
                 "shape": "--shape", "polydispersity": "--polydispersity",
                 "size_ratio": "--size-ratio", "seed": "--seed", "min_gap": "--min-gap",
                 "max_steps": "--max-steps", "degree": "--degree", "roughness": "--roughness",
                 "elongation_range": "--elongation"}
_SAND_ONLY = ("degree", "roughness", "elongation_range")


def _cmd_pack(args) -> int:
    from .stages.pack import describe_packing, pack_to_file

    options = {"polydispersity": args.polydispersity, "size_ratio": args.size_ratio,
               "seed": args.seed, "min_gap": args.min_gap, "max_steps": args.max_steps,
               "degree": args.degree, "roughness": args.roughness,
               "elongation_range": args.elongation}
    options = {name: value for name, value in options.items() if value is not None}
    if args.shape == "sphere":
        for name in _SAND_ONLY:
            if name in options:
                raise InputError(_PACK_OPTIONS[name], "applies to --shape sand only")
    if args.elongation is not None:
        options["elongation_range"] = tuple(args.elongation)
    try:
        packing = pack_to_file(args.out, args.shape, args.box, args.phi, args.radius, **options)
    except InputError as err:
        raise InputError(_PACK_OPTIONS.get(err.source, err.source), err.problem) from None
    print(describe_packing(packing, args.phi, args.out))
    return 0


_COMMANDS = {"fit": _cmd_fit, "run": _cmd_run, "bench": _cmd_bench, "pack": _cmd_pack}


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    args = _build_parser().parse_args(argv)
    logging.basicConfig(level=logging.WARNING if args.quiet else logging.INFO,
                        format="%(asctime)s %(levelname)s %(name)s: %(message)s", stream=sys.stderr)
    log.info("suspsim %s: %s on %s, Python %s", __version__,
             " ".join(sys.argv if argv is None else ["suspsim", *argv]), platform.node(),
             platform.python_version())
    try:
        return _COMMANDS[args.command](args)
    except InputError as err:
        print(f"suspsim: error: {err}", file=sys.stderr)
        return 1
    except NumericalError as err:
        print(f"suspsim: numerical failure: {err}", file=sys.stderr)
        return 2
    except OSError as err:
        print(f"suspsim: error: {err}", file=sys.stderr)
        return 1
    except SuspsimError as err:
        # A run stopped on a signal after saving its checkpoint (suspsim.run.RunInterrupted).
        print(f"suspsim: {err}", file=sys.stderr)
        return getattr(err, "exit_code", 1)
    except KeyboardInterrupt:
        print("suspsim: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
