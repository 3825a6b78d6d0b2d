"""Snakemake shim for rule plot_flows: calls suspsim.stages.flows_figures.write_flows_figure
for each figure the rule outputs."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.flows_figures import write_flows_figure

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    for name, path in snakemake.output.items():
        write_flows_figure(snakemake.input.flows, name, path)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"plot_flows: {err}")
