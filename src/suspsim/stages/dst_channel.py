"""The ``dst`` study's channel flows (seed 002 Fig. 7–8): one run per (run set, driving force).

The ``dst.channel`` config block (``workflow/schemas/config.schema.yaml``) names run sets, each
a fluid (jamming fractions φ_m, φ_0 and non-locality α) at the block's φ, and the driving forces
F H/σ* they all run; β, K_f and, where a set gives none, φ_m and φ_0 are the ``dst.fluid``
block's. :func:`channel_jobs` expands it into jobs, :func:`simulate_channel_point`
runs one with :func:`suspsim.dst.channel_study.channel_sweep` (one force: the local model by
the momentum protocol, α > 0 by the microstructure-relaxed one, as the sweep chooses).
Gathering and figures live in :mod:`suspsim.stages.dst_channel_gather`, so that editing them
does not re-run the simulations (the rules' code fingerprints).

Scaled units as :mod:`suspsim.dst.study`: L_y = η_s = σ* = 1, α in L_y² σ*/η_s.
"""
from __future__ import annotations

import logging
import os
from dataclasses import dataclass
from typing import Any, Mapping

from ..dst.channel_study import channel_sweep
from ..errors import InputError
from ..io.atomic import atomic_path

log = logging.getLogger(__name__)

#: Coordinates written without a fill value (CF: coordinates have none).
COORDINATES = ("force_ratio", "y")


@dataclass(frozen=True)
class ChannelJob:
    """One channel run: the set's ``name``, the force's ``index`` in the config's list, the
    driving force ``force_ratio`` F H/σ* [1] and the sweep's keyword arguments ``sweep``."""

    name: str
    index: int
    force_ratio: float
    sweep: Mapping[str, Any]


def channel_jobs(settings: Mapping[str, Any]) -> list[ChannelJob]:
    """Every (set, force) run of the config's ``channel`` block, set by set in config order.

    Raises InputError for a repeated set name or force, or a profile force that is not run.
    """
    channel = settings.get("channel") or {}
    sets = channel.get("sets") or []
    if not sets:
        return []
    forces = [float(f) for f in channel["forces"]]
    if len(set(forces)) != len(forces):
        raise InputError("dst.channel.forces", f"a force is listed twice in {forces}",
                         key="forces")
    missing = [f for f in channel["profile_forces"] if float(f) not in forces]
    if missing:
        raise InputError("dst.channel.profile_forces", f"profile forces {missing} are not in "
                         f"forces {forces}", key="profile_forces")
    names = [entry["name"] for entry in sets]
    if len(set(names)) != len(names):
        raise InputError("dst.channel.sets", f"a set name is listed twice in {names}",
                         key="name")
    fluid, jobs = settings["fluid"], []
    for entry in sets:
        sweep = {"phi": float(channel["phi"]), "alpha": float(entry["alpha"]),
                 "phi_m": float(_given(entry.get("phi_m"), fluid["phi_m"])),
                 "phi_0": float(_given(entry.get("phi_0"), fluid["phi_0"])),
                 "beta": float(fluid["beta"]), "K_f": float(fluid["K_f"]),
                 "lattice": [int(n) for n in channel["lattice"]]}
        jobs += [ChannelJob(entry["name"], k, f, sweep) for k, f in enumerate(forces)]
    return jobs


def _given(value, default):
    return default if value is None else value


def find_channel_job(settings: Mapping[str, Any], name: str, index: int) -> ChannelJob:
    """The job of set ``name`` and force ``index``; InputError when the config has none."""
    for job in channel_jobs(settings):
        if job.name == name and job.index == index:
            return job
    raise InputError("dst.channel", f"no channel run {name!r} with force index {index}")


def simulate_channel_point(job: Mapping[str, Any], out_nc: str | os.PathLike, *,
                           threads: int = 1) -> None:
    """Run one channel job (``job``: ``force_ratio`` and the sweep's ``phi``, ``alpha``,
    ``phi_m``, ``phi_0``, ``lattice``) and write its one-force Dataset atomically."""
    sweep = {k: v for k, v in job.items() if k != "force_ratio"}
    data = channel_sweep(sweep.pop("phi"), [float(job["force_ratio"])], threads=threads,
                         **{**sweep, "lattice": tuple(sweep["lattice"])})
    with atomic_path(out_nc) as tmp:
        data.to_netcdf(tmp, engine="netcdf4", encoding=encoding())
    log.info("wrote %s: F H/sigma* %g, <v_x>/ODE - 1 = %+.2f %%, L2/peak %.2f %%, %.1f s",
             out_nc, float(job["force_ratio"]), 100 * float(data["mean_velocity_error"][0]),
             100 * float(data["velocity_l2_error"][0]), float(data["wall_time"][0]))


def encoding() -> dict:
    """netCDF encoding of a channel Dataset: no fill value on the coordinates."""
    return {name: {"_FillValue": None} for name in COORDINATES}
