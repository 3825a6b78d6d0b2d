"""Snakemake shim for rule predict_homogenisation: calls suspsim.stages.homogenisation."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.homogenisation import write_homogenisation

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_homogenisation(snakemake.input.fit, snakemake.output.estimate,
                         volume_fractions=snakemake.params.volume_fractions,
                         phi_max=snakemake.params.phi_max, out_plot=snakemake.output.figure)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"predict_homogenisation: {err}")
