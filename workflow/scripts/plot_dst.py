"""Snakemake shim for rule plot_dst: calls suspsim.stages.dst_figures.write_dst_figures."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.dst_figures import write_dst_figures

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_dst_figures(snakemake.input.flow_curves, dict(snakemake.output.items()),
                      phi=snakemake.params.figure["phi"],
                      stress=snakemake.params.figure["stress"])
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"plot_dst: {err}")
