"""The ``flows`` study's figures from ``flows.nc`` (:mod:`suspsim.stages.flows_gather`).

* ``startup``: seed 000 Fig. 1, the Couette start-up profiles against the 1D reference
  (:func:`suspsim.plotting.startup.plot_startup`);
* ``poiseuille``: seed 000 Fig. 2, the channel profiles per Bingham number against the
  numerical solution (:func:`suspsim.plotting.poiseuille.plot_poiseuille`).
"""
from __future__ import annotations

import logging
import os

from ..errors import InputError
from ..io.atomic import save_figure
from ..plotting.poiseuille import plot_poiseuille
from ..plotting.startup import plot_startup
from .flows_gather import read_flows

log = logging.getLogger(__name__)

#: Figure name -> drawing function of its group.
FIGURES = {"startup": plot_startup, "poiseuille": plot_poiseuille}


def write_flows_figure(flows_nc: str | os.PathLike, name: str,
                       path: str | os.PathLike) -> None:
    """Draw figure ``name`` (``startup`` or ``poiseuille``) from the group of that name of
    ``flows_nc`` and save it atomically to ``path``. InputError when the file has no such
    group; ValueError for an unknown name."""
    if name not in FIGURES:
        raise ValueError(f"unknown flows figure {name!r}; known: {', '.join(FIGURES)}")
    parts = read_flows(flows_nc)
    if name not in parts:
        raise InputError(str(flows_nc), f"no {name} group (groups: {', '.join(parts)})")
    save_figure(FIGURES[name](parts[name]), path)
    log.info("wrote %s", path)
