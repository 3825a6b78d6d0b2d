"""Snakemake shim for rule pack: calls suspsim.stages.pack.write_study_packing."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.pack import write_study_packing

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_study_packing(snakemake.output.packing,
                        volume_fraction=snakemake.params.volume_fraction,
                        seed=snakemake.params.seed, box=snakemake.params.box,
                        particles=snakemake.params.particles)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"pack: {err}")
