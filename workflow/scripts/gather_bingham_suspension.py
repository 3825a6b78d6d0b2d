"""Snakemake shim for rule gather_bingham_suspension: calls
suspsim.stages.bingham_suspension_gather.write_suspension."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.bingham_suspension_gather import write_suspension

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_suspension(snakemake.output.suspension, snakemake.params.block,
                     list(snakemake.input.newtonian), list(snakemake.input.runs),
                     command="snakemake rule gather_bingham_suspension")
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"gather_bingham_suspension: {err}")
