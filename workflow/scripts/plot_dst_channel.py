"""Snakemake shim for rule plot_dst_channel: calls
suspsim.stages.dst_channel_gather.write_channel_figures."""
import logging
import sys

from suspsim.errors import SuspsimError
from suspsim.stages.dst_channel_gather import write_channel_figures

logging.basicConfig(filename=snakemake.log[0], filemode="w", level=logging.INFO,
                    format="%(asctime)s %(levelname)s %(name)s: %(message)s")
try:
    write_channel_figures(snakemake.input.channel, dict(snakemake.output.items()),
                          profile_forces=snakemake.params.profile_forces)
except SuspsimError as err:
    logging.getLogger("suspsim").error("%s", err)
    sys.exit(f"plot_dst_channel: {err}")
