"""Snakemake shim for rule simulate_bingham_suspension: calls
suspsim.stages.bingham_suspension.simulate_suspension."""
import logging
import os
import sys

# Set before numba is first imported, so its thread pool is exactly the job's threads.
os.environ["NUMBA_NUM_THREADS"] = str(snakemake.threads)

from suspsim.errors import SuspsimError  # noqa: E402
from suspsim.stages.bingham_suspension import simulate_suspension  # noqa: E402

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    simulate_suspension(snakemake.params.job, snakemake.input.packing, snakemake.output.run,
                        threads=snakemake.threads)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"simulate_bingham_suspension: {err}")
