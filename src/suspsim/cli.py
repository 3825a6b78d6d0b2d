"""The ``suspsim`` command line: ``suspsim fit FILE [--law NAME|auto] [--sample ID] [--out F] [--plot F]``.

Exit codes: 0 success; 1 user or input error (one line on stderr naming the file, the place
in it and the problem; no output written); 2 numerical failure.
"""
from __future__ import annotations

import argparse
import logging
import platform
import sys
from typing import Sequence

from . import __version__
from .errors import InputError, NumericalError

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
    return parser


def _cmd_fit(args) -> int:
    from .stages.fit import fit_matrix_file, format_fit_table

    result = fit_matrix_file(args.file, law=args.law, sample=args.sample, criterion=args.criterion,
                             out_json=args.out, out_plot=args.plot)
    print(format_fit_table(result))
    return 0


_COMMANDS = {"fit": _cmd_fit}


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


if __name__ == "__main__":
    sys.exit(main())
