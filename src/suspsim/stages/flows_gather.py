"""Gathering of the ``flows`` study (seed 000 Figs. 1 and 2, :mod:`suspsim.stages.flows`).

:func:`write_flows` writes one netCDF4 file with a root group of global attributes and a group
per part: ``startup`` (the start-up run as it is) and ``poiseuille`` (the channel runs on a
``bingham`` dimension, :func:`gather_poiseuille`); :func:`read_flows` reads it back.
Simulation units as :mod:`suspsim.io.variables`.
"""
from __future__ import annotations

import logging
import os
from typing import Sequence

import numpy as np
import xarray as xr

from ..errors import InputError
from ..io.grouped import read_grouped, write_grouped
from ..io.variables import simulation_units

log = logging.getLogger(__name__)

#: Groups of the gathered file, in this order.
GROUPS = ("startup", "poiseuille")
#: Per-run attributes of a channel run that become variables on ``bingham``: name -> (powers
#: of (h, m, τ, h^d), :func:`~suspsim.io.variables.simulation_units`, and long_name).
RUN_VARIABLES = {
    "newtonian_velocity": ((1, 0, -1, 0), "centre-line velocity F W^2/(8 mu_pl) of the "
                                          "Newtonian fluid mu_pl under the run's force"),
    "force_density": ((1, 1, -2, -1), "driving force density F = rho g"),
    "yield_stress": ((2, 1, -2, -1), "yield stress tau_y = mu_0/M of the law (0: Newtonian)"),
    "regularisation_time": ((0, 0, 1, 0), "Papanastasiou regularisation time M (NaN: "
                                          "Newtonian)"),
    "profile_error": ((0, 0, 0, 0), "L2 norm of SPH - reference over the bins over the "
                                    "reference's peak |u|"),
}
#: Attributes every channel run of one gathered file must share.
SHARED = ("dimension", "number_density", "channel_width", "lateral_side", "plastic_viscosity",
          "channel_reynolds_number", "start", "run_time", "averaging_time")


def _load(path: str | os.PathLike) -> xr.Dataset:
    try:
        return xr.load_dataset(path)
    except (OSError, ValueError) as err:
        raise InputError(str(path), f"cannot read the run: {err}") from err


def gather_poiseuille(runs: Sequence[xr.Dataset], sources: Sequence[str]) -> xr.Dataset:
    """The channel runs as one Dataset on ``bingham`` (the runs' order), their per-run
    attributes as variables (:data:`RUN_VARIABLES`) and ``run_files``; the shared attributes
    are the first run's.

    Raises InputError (naming the file) when a run's channel, heights or run length differ
    from the first run's (:data:`SHARED`).
    """
    first = runs[0]
    for run, source in zip(runs[1:], sources[1:]):
        differ = [k for k in SHARED if run.attrs.get(k) != first.attrs.get(k)]
        if differ or not np.array_equal(run["y"].values, first["y"].values):
            raise InputError(source, f"channel run differs from {sources[0]} in "
                             f"{', '.join(differ) or 'its heights y'}: not one figure's set")
    dim = int(first.attrs["dimension"])
    per_run = []
    for run in runs:
        run = run.expand_dims(bingham=[float(run.attrs["bingham_number"])])
        for name, (powers, long_name) in RUN_VARIABLES.items():
            units = simulation_units(powers, dim)
            attrs = {"units": "1", **({"simulation_units": units} if units != "1" else {})}
            run[name] = ("bingham", [float(run.attrs[name])], {**attrs, "long_name": long_name})
        run["wall_time"] = ("bingham", [float(run.attrs["wall_time_s"])],
                            {"units": "s", "long_name": "wall time of the run"})
        per_run.append(run)
    data = xr.concat(per_run, dim="bingham", data_vars="minimal", coords="minimal",
                     combine_attrs="override")
    data["bingham"].attrs.update(units="1", long_name="Bingham number tau_y/(mu_pl gdot_c) of "
                                 "the channel (reference.poiseuille)")
    per_run_attrs = ("bingham_number", "law", "newtonian_velocity_comment", "wall_time_s",
                     "n_particles", "dt", "sound_speed", "steps", *RUN_VARIABLES)
    for name in (*per_run_attrs, *(k for k in first.attrs if k.startswith("law_"))):
        data.attrs.pop(name, None)
    data.attrs.update(laws=" ".join(str(r.attrs["law"]) for r in runs),
                      run_files=" ".join(sources))
    return data


def write_flows(out_nc: str | os.PathLike, *, startup: str | os.PathLike | None = None,
                poiseuille: Sequence[str | os.PathLike] = (), command: str | None = None) -> None:
    """Gather the start-up run file ``startup`` and the channel run files ``poiseuille`` (the
    figure's Bn order) into ``out_nc``, written atomically: a root group of global attributes
    (CF ``Conventions``, ``title``, ``source``, ``history``, ``groups``, provenance) and one
    group per part present. InputError when neither is given or a file cannot be read."""
    datasets = {}
    if startup is not None:
        datasets["startup"] = _load(startup)
        datasets["startup"].attrs["run_file"] = str(startup)
    if poiseuille:
        sources = [str(p) for p in poiseuille]
        datasets["poiseuille"] = gather_poiseuille([_load(p) for p in sources], sources)
    if not datasets:
        raise InputError("flows", "nothing to gather: neither startup.strains nor "
                         "poiseuille.binghams lists a run")
    write_grouped(out_nc, datasets, command=command, module="suspsim.stages.flows",
                  title="Seed 000 Figs. 1-2: SPH start-up of Couette flow and split-force "
                        "Poiseuille flow of a Papanastasiou fluid against 1D numerical solutions")
    log.info("wrote %s: %s", out_nc, ", ".join(datasets))


def read_flows(path: str | os.PathLike) -> dict[str, xr.Dataset]:
    """The parts of a file of :func:`write_flows`, by group name (InputError naming the file)."""
    return read_grouped(path, "the flows study")
