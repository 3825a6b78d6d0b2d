"""Snakemake shim for rule speed_error_measure: calls suspsim.stages.speed_error."""
import logging
import os
import sys

# Set before numba is first imported, so its thread pool is exactly the job's threads.
os.environ["NUMBA_NUM_THREADS"] = str(snakemake.threads)

from suspsim.errors import SuspsimError  # noqa: E402
from suspsim.stages.speed_error import measure_configuration  # noqa: E402

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    measure_configuration(snakemake.wildcards.case, snakemake.params.overrides,
                          snakemake.output.record, threads=snakemake.threads)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"speed_error_measure: {err}")
