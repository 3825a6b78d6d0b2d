"""Snakemake shim for rule speed_error_gather: calls suspsim.stages.speed_error.gather_case."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.speed_error import gather_case

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    gather_case(snakemake.wildcards.case, snakemake.input.records, snakemake.output.case)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"speed_error_gather: {err}")
