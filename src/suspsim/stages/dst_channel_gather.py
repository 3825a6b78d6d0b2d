"""Gathering and figures of the ``dst`` study's channel flows (seed 002 Fig. 7–8).

:func:`write_channel_sets` gathers the one-force runs of :mod:`suspsim.stages.dst_channel`
into one netCDF4 file with a group per run set (:func:`write_groups`, read back by
:func:`read_groups`), and :func:`write_channel_figures` draws the profiles (Fig. 7) of the
first set at the ``profile_forces`` and the mean velocity against force of every set (Fig. 8),
each against the local ODE and the inverse-biviscous model. Scaled units as
:mod:`suspsim.dst.study`.
"""
from __future__ import annotations

import json
import logging
import os
from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from ..errors import InputError
from ..io.atomic import save_figure
from ..io.grouped import read_grouped, write_grouped
from ..plotting.dst_channel import plot_channel_flow, plot_channel_profiles
from .dst_gather import load_runs

log = logging.getLogger(__name__)


def gather_channel_set(runs: Sequence[xr.Dataset], sources: Sequence[str]) -> xr.Dataset:
    """One set's runs (force order) as one Dataset on ``force_ratio``; the attributes of the
    first run with the summed ``wall_time_s`` and every force in ``configuration``.

    Raises InputError (naming the file) when a run's fluid, lattice or heights differ from
    the first run's.
    """
    first = runs[0]
    keys = ("phi", "phi_m", "phi_0", "alpha", "beta", "K_f", "n_x", "n_y", "protocol")
    for run, source in zip(runs[1:], sources[1:]):
        differ = [k for k in keys if run.attrs.get(k) != first.attrs.get(k)]
        if differ or not np.array_equal(run["y"].values, first["y"].values):
            raise InputError(source, f"run differs from {sources[0]} in "
                             f"{', '.join(differ) or 'its heights y'}: not one run set")
    data = xr.concat(runs, dim="force_ratio", data_vars="minimal", coords="minimal",
                     combine_attrs="override")
    configuration = {**json.loads(first.attrs["configuration"]),
                     "force_ratios": data["force_ratio"].values.tolist()}
    data.attrs.update(wall_time_s=float(sum(r.attrs["wall_time_s"] for r in runs)),
                      configuration=json.dumps(configuration), run_files=" ".join(sources))
    return data


def write_channel_sets(run_files: Mapping[str, Sequence[str | os.PathLike]],
                       out_nc: str | os.PathLike, *, command: str | None = None) -> None:
    """Gather ``run_files`` (set name -> run files in force order) into ``out_nc``: a root
    group of global attributes (``groups`` lists the sets) and one group per set."""
    datasets = {}
    for name, files in run_files.items():
        datasets[name] = gather_channel_set(load_runs(files), [str(p) for p in files])
    write_groups(out_nc, datasets, command=command)
    log.info("wrote %s: %s", out_nc, ", ".join(f"{n} ({d.sizes['force_ratio']} forces)"
                                               for n, d in datasets.items()))


def write_groups(path: str | os.PathLike, datasets: Mapping[str, xr.Dataset], *,
                 command: str | None = None) -> None:
    """One netCDF4 group per run set under a root group of global attributes (CF
    ``Conventions``, ``title``, ``source``, ``history``, ``groups``, ``wall_time_s`` [s],
    ``completed`` and the provenance), written atomically."""
    phis = sorted({float(d.attrs["phi"]) for d in datasets.values()})
    write_grouped(path, datasets, command=command, module="suspsim.stages.dst_channel",
                  title="2D SPH channel flow of a Wyart-Cates suspension at phi = "
                        f"{', '.join(f'{p:g}' for p in phis)} against the local ODE and the "
                        "inverse-biviscous model",
                  attrs={"wall_time_s": float(sum(d.attrs["wall_time_s"]
                                                  for d in datasets.values()))})


def read_groups(path: str | os.PathLike) -> dict[str, xr.Dataset]:
    """The run sets of a file of :func:`write_groups`, by name (InputError naming the file)."""
    return read_grouped(path, "the channel sets")


def write_channel_figures(channel_nc: str | os.PathLike, outputs: Mapping[str, str], *,
                          profile_forces: Sequence[float]) -> None:
    """Draw ``outputs`` (keys ``profiles``: Fig. 7 of the first set at ``profile_forces``;
    ``flow``: Fig. 8 of every set) from a file of :func:`write_groups`, each atomically."""
    datasets = read_groups(channel_nc)
    draw = {"profiles": lambda: plot_channel_profiles(next(iter(datasets.values())),
                                                      profile_forces),
            "flow": lambda: plot_channel_flow(list(datasets.values()))}
    for name, path in outputs.items():
        if name not in draw:
            raise ValueError(f"unknown channel figure {name!r}; known: {', '.join(draw)}")
        save_figure(draw[name](), path)
        log.info("wrote %s", path)
