"""Snakemake shim for rule simulate: calls suspsim.stages.simulate.simulate_run."""
import logging
import os
import sys

# Set before numba is first imported, so its thread pool is exactly the job's threads.
os.environ["NUMBA_NUM_THREADS"] = str(snakemake.threads)

from suspsim.errors import SuspsimError  # noqa: E402
from suspsim.stages.simulate import simulate_run  # noqa: E402

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    simulate_run(snakemake.input.fit, snakemake.output.run,
                 shear_rate=snakemake.params.shear_rate,
                 volume_fraction=snakemake.params.volume_fraction, seed=snakemake.params.seed,
                 resolution=snakemake.params.resolution, numerics=snakemake.params.numerics,
                 threads=snakemake.threads,
                 particles=snakemake.params.particles, packing=snakemake.input.packing or None)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"simulate: {err}")
