"""Snakemake shim for rule gather_dst: calls suspsim.stages.dst_gather.write_flow_curves."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.dst_gather import write_flow_curves

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_flow_curves(snakemake.input.runs, snakemake.output.flow_curves,
                      snakemake.params.settings, band_files=snakemake.input.bands)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"gather_dst: {err}")
