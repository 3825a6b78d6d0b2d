"""Snakemake shim for rule gather_dst_channel: calls
suspsim.stages.dst_channel_gather.write_channel_sets."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.dst_channel_gather import write_channel_sets

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
files = {}
for name, path in zip(snakemake.params.sets, snakemake.input.runs):
    files.setdefault(name, []).append(path)
try:
    write_channel_sets(files, snakemake.output.channel, command="snakemake rule gather_dst_channel")
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"gather_dst_channel: {err}")
