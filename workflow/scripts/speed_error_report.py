"""Snakemake shim for rule speed_error_report: the Pareto figure and the cost table."""
import logging
import sys

import matplotlib

matplotlib.use("Agg")

from suspsim.errors import SuspsimError  # noqa: E402
from suspsim.stages.speed_error import write_speed_error_report  # noqa: E402

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_speed_error_report(snakemake.input.cases, snakemake.output.figure,
                             snakemake.output.table)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"speed_error_report: {err}")
