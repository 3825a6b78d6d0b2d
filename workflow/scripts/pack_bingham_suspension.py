"""Snakemake shim for rule pack_bingham_suspension: calls
suspsim.stages.bingham_suspension.pack_seed."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.bingham_suspension import pack_seed

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    pack_seed(snakemake.params.settings, snakemake.params.seed, snakemake.output.packing)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"pack_bingham_suspension: {err}")
