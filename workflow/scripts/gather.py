"""Snakemake shim for rule gather: calls suspsim.stages.gather.write_summary."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.gather import write_summary

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_summary(snakemake.input.runs, snakemake.output.summary,
                  material=snakemake.wildcards.material)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"gather: {err}")
