"""Snakemake shim for rule plot_summary: calls suspsim.stages.summary_figure."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.summary_figure import write_summary_figure

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_summary_figure(snakemake.input.summary, snakemake.output.figure,
                         fit_json=snakemake.input.fit, matrix_file=snakemake.input.matrix,
                         sample=snakemake.params.sample, estimate_nc=snakemake.input.estimate)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"plot_summary: {err}")
