"""Snakemake shim for rule gather_flows: calls suspsim.stages.flows_gather.write_flows."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.flows_gather import write_flows

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_flows(snakemake.output.flows, startup=snakemake.input.startup or None,
                poiseuille=list(snakemake.input.poiseuille), command="snakemake rule gather_flows")
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"gather_flows: {err}")
