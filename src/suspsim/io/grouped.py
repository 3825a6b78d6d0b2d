"""netCDF4 files of named parts: a root group of global attributes and one group per part.

Used where a study gathers runs of different shapes into one file (the DST channel sets, the
flows study's start-up and channels). The root carries CF ``Conventions``, ``title``,
``source``, ``history`` (time and command), ``groups`` (the part names, space-separated),
``completed`` and the provenance of :func:`suspsim.io.provenance.provenance`; the file is
written atomically.
"""
from __future__ import annotations

import os
import shlex
import sys
from datetime import datetime, timezone
from typing import Any, Mapping

import xarray as xr

from ..errors import InputError
from .atomic import atomic_path
from .provenance import provenance


def write_grouped(path: str | os.PathLike, datasets: Mapping[str, xr.Dataset], *, title: str,
                  module: str, command: str | None = None,
                  attrs: Mapping[str, Any] | None = None) -> None:
    """Write ``datasets`` as groups of ``path`` under the root attributes of the module
    docstring (``module`` the writing module, ``attrs`` more root attributes); coordinates
    get no fill value."""
    prov = provenance()
    command = shlex.join(sys.argv) if command is None else command
    root = xr.Dataset(attrs={
        "Conventions": "CF-1.10", "title": title,
        "source": f"suspsim {prov['suspsim_version']} (git {prov['git_sha']}), {module}",
        "history": f"{datetime.now(timezone.utc).isoformat(timespec='seconds')}: {command}",
        "groups": " ".join(datasets), **(attrs or {}), "completed": 1, **prov})
    with atomic_path(path) as tmp:
        root.to_netcdf(tmp, mode="w", engine="netcdf4")
        for name, data in datasets.items():
            encoding = {c: {"_FillValue": None} for c in data.coords}
            data.to_netcdf(tmp, mode="a", group=name, engine="netcdf4", encoding=encoding)


def read_grouped(path: str | os.PathLike, what: str) -> dict[str, xr.Dataset]:
    """The parts of a file of :func:`write_grouped` by name; InputError naming the file and
    ``what`` it should hold when it cannot be read."""
    try:
        with xr.open_dataset(path) as root:
            groups = root.attrs["groups"].split()
        return {g: xr.load_dataset(path, group=g) for g in groups}
    except (OSError, ValueError, KeyError) as err:
        raise InputError(str(path), f"cannot read {what}: {err}") from err
