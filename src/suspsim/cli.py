"""The ``suspsim`` command line: ``suspsim fit FILE [--law NAME|auto] [--sample ID] [--out F] [--plot F]``.

Also ``suspsim run SCENE.yaml --out RUN.nc [--resume] [--threads N]`` (an SPH run, see
:mod:`suspsim.run`) and ``suspsim bench [--scene NAME] [--threads N] [--steps K] [--json]``.

Exit codes: 0 success; 1 user or input error (one line on stderr naming the file, the place
in it and the problem; no output written); 2 numerical failure (the last good checkpoint is
kept); 128 + signal for a run stopped by a signal after saving its checkpoint (130 SIGINT,
143 SIGTERM; ``--resume`` continues it).
"""
from __future__ import annotations

import argparse
import logging
import platform
import sys
from typing import Sequence

from . import __version__
from .errors import InputError, NumericalError, SuspsimError

log = logging.getLogger("suspsim")


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="suspsim", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"suspsim {__version__}")
    parser.add_argument("-q", "--quiet", action="store_true", help="log warnings and errors only")
    sub = parser.add_subparsers(dest="command", required=True)

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

    run = sub.add_parser("run", help="run an SPH scene and write its results as netCDF")
    run.add_argument("scene", help="scene file (YAML)")
    run.add_argument("--out", required=True, help="output netCDF file; its checkpoint is "
                     "OUT.ckpt.npz beside it until the run completes")
    run.add_argument("--resume", action="store_true", help="continue an interrupted run from "
                     "its checkpoint")
    run.add_argument("--threads", type=_positive_int, help="worker threads (default: the "
                     "scene's run.threads)")

    bench = sub.add_parser("bench", help="measure the solver's speed on standard scenes")
    bench.add_argument("--scene", choices=BENCH_SCENES, help="one scene (default: all)")
    bench.add_argument("--threads", type=_positive_int, help="worker threads (default: every "
                       "thread numba may use)")
    bench.add_argument("--steps", type=_positive_int, default=200, help="time steps to time "
                       "(default: 200)")
    bench.add_argument("--json", action="store_true", help="print one JSON object per scene")
    return parser


#: Scenes of ``suspsim bench`` (defined in :mod:`suspsim.sph.bench`).
BENCH_SCENES = ("fluid-newtonian", "fluid-papanastasiou")
_BENCH_COLUMNS = (("scene", "scene", "{}"), ("particles", "n_particles", "{}"),
                  ("threads", "threads", "{}"), ("steps", "steps", "{}"),
                  ("wall s", "wall_time_s", "{:.3g}"),
                  ("particle-steps/s", "particle_steps_per_s", "{:.3g}"),
                  ("rebuilds", "rebuilds", "{}"),
                  ("viscosity error", "viscosity_error", "{:+.2%}"),
                  ("density error", "density_error", "{:.2%}"),
                  ("rebuild share", "rebuild_share", "{:.1%}"),
                  ("bytes/particle", "bytes_per_particle", "{:.0f}"))


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
    from .run import run_scene
    from .scene import load_scene

    scene = load_scene(args.scene)
    out = run_scene(scene, args.out, resume=args.resume, threads=args.threads)
    result = read_run(out)
    if "viscosity" in result:
        print(f"viscosity {float(result['viscosity']):.6g} ± "
              f"{float(result['viscosity_stderr']):.2g} "
              f"[{result['viscosity'].attrs.get('simulation_units', '1')}]")
    print(f"Reynolds number {result.attrs['reynolds_number']:.3g}, largest Mach number "
          f"{result.attrs['mach_number']:.3g}, {result.attrs['particle_steps_per_s']:.3g} "
          f"particle-steps/s; wrote {out}")
    return 0


def _cmd_bench(args) -> int:
    import json

    from .sph.bench import benchmark

    if args.threads is None:
        import numba

        args.threads = numba.config.NUMBA_NUM_THREADS
    results = []
    for name in [args.scene] if args.scene else BENCH_SCENES:
        result = benchmark(name, args.steps, args.threads)
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


_COMMANDS = {"fit": _cmd_fit, "run": _cmd_run, "bench": _cmd_bench}


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
