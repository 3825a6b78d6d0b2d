"""The ``bingham_suspension`` study's figure (seed 000 Fig. 3) from ``suspension.nc``
(:mod:`suspsim.stages.bingham_suspension_gather`,
:func:`suspsim.plotting.bingham_suspension.plot_bingham_suspension`)."""
from __future__ import annotations

import logging
import os

from ..io.atomic import save_figure
from ..plotting.bingham_suspension import plot_bingham_suspension
from .bingham_suspension_gather import read_suspension

log = logging.getLogger(__name__)


def write_suspension_figure(suspension_nc: str | os.PathLike, path: str | os.PathLike) -> None:
    """Draw the figure of ``suspension_nc`` and save it atomically to ``path`` (InputError
    naming the file when it cannot be read)."""
    save_figure(plot_bingham_suspension(read_suspension(suspension_nc)), path)
    log.info("wrote %s", path)
