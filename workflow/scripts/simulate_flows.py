"""Snakemake shim for rules simulate_startup and simulate_poiseuille: calls
suspsim.stages.flows.simulate_startup or simulate_poiseuille (by the rule's name)."""
import logging
import os
import sys

# Set before numba is first imported, so its thread pool is exactly the job's threads.
os.environ["NUMBA_NUM_THREADS"] = str(snakemake.threads)

from suspsim.errors import SuspsimError  # noqa: E402
from suspsim.stages import flows  # noqa: E402

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
run = {"simulate_startup": flows.simulate_startup,
       "simulate_poiseuille": flows.simulate_poiseuille}[snakemake.rule]
try:
    run(snakemake.params.job, snakemake.output.run, threads=snakemake.threads)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"{snakemake.rule}: {err}")
