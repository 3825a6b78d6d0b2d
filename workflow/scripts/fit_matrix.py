"""Snakemake shim for rule fit_matrix: calls suspsim.stages.fit.fit_matrix_file."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.fit import fit_matrix_file

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    fit_matrix_file(snakemake.input.matrix, law=snakemake.params.law, sample=snakemake.params.sample,
                    candidates=snakemake.params.candidates, criterion=snakemake.params.criterion,
                    out_json=snakemake.output.fit, out_plot=snakemake.output.figure)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"fit_matrix: {err}")
