"""Run outputs as CF-1.10 netCDF: every variable's metadata from :mod:`suspsim.io.variables`.

A run file holds the time series (dimension ``time``), the profiles (dimension ``y``) and the
averaged scalars of one run, in simulation units (see :data:`~suspsim.io.variables.UNIT_SYSTEM`),
plus global attributes: ``Conventions``, ``title``, ``source`` (version and git commit),
``history``, ``references``, ``unit_system``, ``scene`` (the complete scene as JSON), ``seed``,
the provenance of :func:`~suspsim.io.provenance.provenance` and the run attributes of
:data:`~suspsim.io.variables.RUN_ATTRIBUTES` (``wall_time_s`` and ``completed`` required).
Another solver's runs (:mod:`suspsim.dst.run`) pass their own :class:`Registry`.
"""
from __future__ import annotations

import json
import os
import shlex
import sys
from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Any, Callable, Mapping

import numpy as np
import xarray as xr

from ..errors import InputError
from .atomic import atomic_path
from .provenance import provenance
from .variables import REQUIRED_RUN_ATTRIBUTES, RUN_ATTRIBUTES, UNIT_SYSTEM, VARIABLES

__all__ = ["build_dataset", "provenance", "read_run", "write_run", "Registry", "REFERENCES"]

REFERENCES = (
    "Martys, George, Chun & Lootens, Rheol. Acta 49, 1059-1069 (2010), "
    "doi:10.1007/s00397-010-0480-7 (SPH with a spatially varying viscosity); "
    "Espanol & Revenga, Phys. Rev. E 67, 026705 (2003) (SPH viscous terms); "
    "Lucy, Astron. J. 82, 1013 (1977) (kernel); "
    "Groot & Warren, J. Chem. Phys. 107, 4423 (1997) (integrator); "
    "Lees & Edwards, J. Phys. C 5, 1921 (1972) (sheared periodic boundaries); "
    "Morris, Fox & Zhu, J. Comput. Phys. 136, 214 (1997) (sound speed, time step)")


@dataclass(frozen=True)
class Registry:
    """What a run file may hold: ``variables`` (name -> spec with ``dims`` and
    ``is_coordinate``), ``variable_attrs(spec)`` its netCDF attributes, the global
    ``attributes`` (name -> :class:`~suspsim.io.variables.Attribute`), ``references`` and
    ``unit_system`` texts."""

    variables: Mapping[str, Any]
    variable_attrs: Callable[[Any], dict]
    attributes: Mapping[str, Any]
    references: str
    unit_system: str


def sph_registry(dimension: int) -> Registry:
    """The SPH solver's registry (:mod:`suspsim.io.variables`) for a ``dimension``-D run."""
    return Registry(VARIABLES, lambda spec: spec.attrs(dimension), RUN_ATTRIBUTES, REFERENCES,
                    UNIT_SYSTEM)


def write_run(path: str | os.PathLike, data: Mapping[str, Any], attrs: Mapping[str, Any],
              scene: Mapping[str, Any], *, command: str | None = None,
              title: str | None = None, registry: Registry | None = None) -> None:
    """Write one run's results to ``path`` (netCDF4) atomically; see :func:`build_dataset`.

    Coordinates get no ``_FillValue`` (CF: coordinate values are never missing); data
    variables use NaN for missing values.
    """
    dataset = build_dataset(data, attrs, scene, command=command, title=title, registry=registry)
    no_fill = {name: {"_FillValue": None} for name in dataset.coords}
    with atomic_path(path) as tmp:
        dataset.to_netcdf(tmp, engine="netcdf4", encoding=no_fill)


def build_dataset(data: Mapping[str, Any], attrs: Mapping[str, Any], scene: Mapping[str, Any], *,
                  command: str | None = None, title: str | None = None,
                  registry: Registry | None = None) -> xr.Dataset:
    """The run as an :class:`xarray.Dataset` with registry metadata and global attributes.

    Parameters
    ----------
    data : arrays or scalars keyed by registry names, coordinates (``time``, ``y``) included
        for every dimension used; values in simulation units.
    attrs : run attributes keyed by :data:`RUN_ATTRIBUTES` names (bools become 0/1).
    scene : the complete scene: a :class:`~suspsim.scene.Scene` or its ``to_dict()``.
    command : the command line for ``history`` (default: this process's ``sys.argv``).
    title : default: a description of the scene's flow and law.
    registry : the variables and attributes allowed (default: the SPH solver's,
        :func:`sph_registry`).

    Raises
    ------
    ValueError : a name missing from the registry, wrong dimensions or attribute types, a
        dimension without its coordinate, a required attribute missing (programming errors).
    """
    scene = scene.to_dict() if hasattr(scene, "to_dict") else scene
    registry = registry or sph_registry(int(scene["dimension"]))
    unknown = sorted(set(data) - set(registry.variables))
    if unknown:
        raise ValueError(f"variables not in the output registry: {', '.join(unknown)}")
    coords, variables = {}, {}
    for name, value in data.items():
        spec = registry.variables[name]
        array = np.asarray(value, dtype=float)
        if array.ndim != len(spec.dims):
            raise ValueError(f"{name} has {array.ndim} dimension(s); the registry says {spec.dims}")
        target = coords if spec.is_coordinate else variables
        target[name] = xr.Variable(spec.dims, array, attrs=registry.variable_attrs(spec))
    missing = sorted({d for name in variables for d in registry.variables[name].dims}
                     - set(coords))
    if missing:
        raise ValueError(f"dimension(s) {', '.join(missing)} used without their coordinate")
    return xr.Dataset(variables, coords=coords,
                      attrs=_global_attributes(attrs, scene, registry, command=command,
                                               title=title))


def read_run(path: str | os.PathLike) -> xr.Dataset:
    """Load a run file fully into memory and close it; raises :class:`InputError` if unreadable."""
    try:
        with xr.open_dataset(path, engine="netcdf4", decode_times=False,
                             decode_timedelta=False) as dataset:
            return dataset.load()
    except FileNotFoundError:
        raise InputError(path, "no such run file") from None
    except (OSError, ValueError) as err:
        raise InputError(path, f"not a readable netCDF run file ({err})") from None


def _global_attributes(attrs, scene, registry: Registry, *, command, title) -> dict[str, Any]:
    unknown = sorted(set(attrs) - set(registry.attributes))
    if unknown:
        raise ValueError(f"run attributes not in the registry: {', '.join(unknown)}")
    missing = [name for name in REQUIRED_RUN_ATTRIBUTES if name not in attrs]
    if missing:
        raise ValueError(f"required run attribute(s) missing: {', '.join(missing)}")
    prov = provenance()
    when = datetime.now(timezone.utc).isoformat(timespec="seconds")
    command = shlex.join(sys.argv) if command is None else command
    out = {"Conventions": "CF-1.10", "title": title or _default_title(scene),
           "source": f"suspsim {prov['suspsim_version']} (git {prov['git_sha']})",
           "history": f"{when}: {command}", "references": registry.references,
           "unit_system": registry.unit_system, "scene": json.dumps(scene, ensure_ascii=False),
           **({"seed": int(scene["seed"])} if "seed" in scene else {}), **prov}
    for name, value in attrs.items():
        out[name] = _typed_attribute(name, value, registry.attributes[name].type)
    return out


def _typed_attribute(name: str, value, kind: type) -> int | float | str:
    if kind is str:
        return str(value)
    if isinstance(value, (bool, np.bool_)) or kind is float:
        return kind(value)
    if float(value) != int(value):
        raise ValueError(f"run attribute {name} must be an integer, got {value!r}")
    return int(value)


def _default_title(scene) -> str:
    return (f"suspsim SPH run: {scene['flow']['type']} flow of a {scene['fluid']['law']} fluid "
            f"({scene['dimension']}-D)")
