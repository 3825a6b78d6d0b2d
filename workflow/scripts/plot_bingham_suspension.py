"""Snakemake shim for rule plot_bingham_suspension: calls
suspsim.stages.bingham_suspension_figures.write_suspension_figure."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.bingham_suspension_figures import write_suspension_figure

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_suspension_figure(snakemake.input.suspension, snakemake.output.figure)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"plot_bingham_suspension: {err}")
