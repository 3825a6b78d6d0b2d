"""Packing files: netCDF (CF-1.10) with one row per body, written atomically.

Variables and attributes come from :data:`~suspsim.io.variables.PACKING_VARIABLES` and
:data:`~suspsim.io.variables.PACKING_ATTRIBUTES` (units "1" and the dimension in
``simulation_units``, as run files; lengths in h, the SPH kernel support radius). Dimensions:
``body``; ``axis`` (x, y, z); ``quaternion`` (w, x, y, z); ``coefficient`` (sand only, with the
degree and order of each coefficient). Global attributes add ``Conventions``, ``title``,
``source``, ``history``, ``references``, ``unit_system`` and the provenance of
:func:`~suspsim.io.provenance.provenance`.
"""
from __future__ import annotations

import os
import shlex
import sys
from datetime import datetime, timezone

import numpy as np
import xarray as xr

from ..bodies.harmonics import coefficient_degree, degree_of
from ..bodies.packing import Packing
from ..errors import InputError
from .atomic import atomic_path
from .provenance import provenance
from .variables import PACKING_ATTRIBUTES, PACKING_VARIABLES, UNIT_SYSTEM

__all__ = ["packing_dataset", "read_packing", "write_packing", "REFERENCES"]

REFERENCES = (
    "Garboczi, Cem. Concr. Res. 32, 1621-1638 (2002) (spherical-harmonic particle shapes); "
    "O'Hern, Silbert, Liu & Nagel, Phys. Rev. E 68, 011306 (2003) (soft-sphere quench); "
    "Bitzek, Koskinen, Gahler, Moseler & Gumbsch, Phys. Rev. Lett. 97, 170201 (2006) (FIRE)")

_DETAILS = ("smallest_gap", "relaxation_steps", "wall_time_s", "degree", "roughness",
            "spectral_exponent", "elongation_range", "relax_points", "check_points",
            "working_gap")


def write_packing(path: str | os.PathLike, packing: Packing, *, command: str | None = None) -> None:
    """Write ``packing`` to ``path`` (netCDF4) atomically: nothing appears under ``path``
    unless the whole file was written."""
    dataset = packing_dataset(packing, command=command)
    no_fill = {name: {"_FillValue": None} for name in dataset.variables}
    with atomic_path(path) as tmp:
        dataset.to_netcdf(tmp, engine="netcdf4", encoding=no_fill)


def packing_dataset(packing: Packing, *, command: str | None = None) -> xr.Dataset:
    """The packing as an :class:`xarray.Dataset` with registry metadata and global attributes."""
    data = {"centre": packing.centres, "orientation": packing.orientations,
            "radius": packing.radii, "volume": packing.volumes,
            "support_radius": packing.support_radii}
    if packing.coefficients is not None:
        degree, order = coefficient_degree(degree_of(packing.coefficients))
        data.update(shape_coefficient=packing.coefficients, coefficient_degree=degree,
                    coefficient_order=order)
    variables = {}
    for name, value in data.items():
        spec = PACKING_VARIABLES[name]
        variables[name] = xr.Variable(spec.dims, np.asarray(value), attrs=spec.attrs(3))
    coords = {"axis": ("axis", np.array(["x", "y", "z"])),
              "quaternion": ("quaternion", np.array(["w", "x", "y", "z"]))}
    return xr.Dataset(variables, coords=coords, attrs=_attributes(packing, command))


def _attributes(packing: Packing, command: str | None) -> dict:
    prov = provenance()
    when = datetime.now(timezone.utc).isoformat(timespec="seconds")
    command = shlex.join(sys.argv) if command is None else command
    values = {"shape": packing.shape, "volume_fraction": packing.volume_fraction,
              "seed": packing.seed, "box": packing.box, "body_count": packing.count,
              "polydispersity": packing.polydispersity, "size_ratio": packing.size_ratio,
              "min_gap": packing.min_gap,
              **{k: v for k, v in packing.details.items() if k in _DETAILS}}
    out = {"Conventions": "CF-1.10",
           "title": f"suspsim packing: {packing.count} {packing.shape} bodies at volume "
                    f"fraction {packing.volume_fraction:.6g}",
           "source": f"suspsim {prov['suspsim_version']} (git {prov['git_sha']})",
           "history": f"{when}: {command}", "references": REFERENCES, "unit_system": UNIT_SYSTEM}
    for name, value in values.items():
        out[name] = _typed(PACKING_ATTRIBUTES[name].type, value)
    return {**out, **prov}


def _typed(kind, value):
    if kind is tuple:
        return np.asarray(value, dtype=np.float64)
    return kind(value)


def read_packing(path: str | os.PathLike) -> Packing:
    """Load a packing file; raises :class:`InputError` if it is missing or not a packing."""
    try:
        with xr.open_dataset(path, engine="netcdf4") as dataset:
            dataset = dataset.load()
    except FileNotFoundError:
        raise InputError(path, "no such packing file") from None
    except (OSError, ValueError) as err:
        raise InputError(path, f"not a readable netCDF packing file ({err})") from None
    required = ("centre", "orientation", "radius", "volume", "support_radius")
    missing = [name for name in required if name not in dataset]
    missing += [name for name in ("shape", "seed", "box", "polydispersity", "size_ratio",
                                  "min_gap") if name not in dataset.attrs]
    if missing:
        raise InputError(path, f"not a suspsim packing file: {', '.join(missing)} missing")
    attrs = dataset.attrs
    coefficients = (dataset["shape_coefficient"].values if "shape_coefficient" in dataset
                    else None)
    details = {}
    for name in _DETAILS:
        if name in attrs:
            value = attrs[name]
            details[name] = (np.asarray(value).tolist() if PACKING_ATTRIBUTES[name].type is tuple
                             else PACKING_ATTRIBUTES[name].type(value))
    return Packing(str(attrs["shape"]), np.asarray(attrs["box"], dtype=np.float64),
                   dataset["centre"].values, dataset["orientation"].values,
                   dataset["radius"].values, dataset["volume"].values, coefficients,
                   dataset["support_radius"].values, int(attrs["seed"]),
                   float(attrs["polydispersity"]), float(attrs["size_ratio"]),
                   float(attrs["min_gap"]), details)
