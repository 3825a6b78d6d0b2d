"""Stage 4: gather a material's run files into one ``summary.nc`` on (phi, shear_rate, seed).

Each simulate run file (:mod:`suspsim.stages.simulate`) carries its physical results as 0-d
variables with φ, γ̇ and seed as scalar coordinates; :func:`gather_runs` lifts each to a 1×1×1
cell and merges them with xarray (outer join), so a missing combination is NaN and the grid need
not be complete. Variables and their units come from
:data:`~suspsim.io.study_variables.STUDY_VARIABLES`: suspension and relative viscosity with their
standard errors [Pa s, 1], the matrix viscosity of the fitted law [Pa s], wall time [s], the
resolution (particles, box side, number density, strain), Re, Mach and the unit scales (SPEC §7),
and the inclusions' radius [h], packing seed, body count and physical radius [m] (NaN at φ = 0).
The inclusion settings every run with inclusions shares (shape, radius, polydispersity, size
ratio, gap, friction, rolling friction) become the attributes ``inclusions`` (JSON) and
``inclusion_shape``.

Summary statistics over seeds (mean and spread) belong to the reader; the summary keeps every run.
"""
from __future__ import annotations

import json
import logging
import os
from datetime import datetime, timezone
from typing import Iterable, Sequence

import numpy as np
import xarray as xr

from ..errors import InputError
from ..io.atomic import atomic_path
from ..io.netcdf import read_run
from ..io.provenance import provenance
from ..io.study_variables import STUDY_VARIABLES, SUMMARY_DIMS

log = logging.getLogger(__name__)

#: Variables of the summary that depend on the shear rate only (the fitted law at γ̇).
RATE_ONLY = ("matrix_viscosity",)


def gather_runs(runs: Iterable[xr.Dataset], *, material: str | None = None,
                sources: Sequence[str] | None = None) -> xr.Dataset:
    """Merge run datasets into one summary on :data:`SUMMARY_DIMS` (module docstring).

    ``sources`` names each run for error messages (default its position). Raises InputError
    for a run without the physical results, two runs of the same (φ, γ̇, seed), runs of
    different matrix fits or inclusion settings, or no run at all.
    """
    cells, fits, inclusions = [], set(), set()
    runs = list(runs)
    sources = list(sources) if sources is not None else [f"run {i}" for i in range(len(runs))]
    if not runs:
        raise InputError(material or "gather", "no run files to gather")
    seen: dict[tuple, str] = {}
    for source, run in zip(sources, runs):
        missing = [name for name in STUDY_VARIABLES if name not in run.variables]
        if missing:
            raise InputError(source, f"not a simulate run file: missing {', '.join(missing)}")
        key = tuple(float(run[d]) for d in SUMMARY_DIMS)
        if key in seen:
            raise InputError(source, f"same (phi, shear_rate, seed) = {key} as {seen[key]}")
        seen[key] = source
        fits.add(run.attrs.get("matrix_fit", ""))
        if run.attrs.get("inclusions"):
            inclusions.add(run.attrs["inclusions"])
        cells.append(_cell(run))
    if len(fits) > 1:
        raise InputError(material or "gather", "the runs come from different matrix fits; "
                         "re-run the simulate stage after the fit changed")
    if len(inclusions) > 1:
        raise InputError(material or "gather", "the runs have different inclusion settings "
                         f"({'; '.join(sorted(inclusions))}); re-run the pack and simulate "
                         "stages after they changed")
    settings = inclusions.pop() if inclusions else ""
    summary = xr.merge(cells, join="outer", compat="no_conflicts", combine_attrs="drop")
    summary = summary.sortby(list(SUMMARY_DIMS))
    summary = summary.assign_coords(seed=summary["seed"].astype(np.int64))
    for name in [*summary.variables]:
        summary[name].attrs = STUDY_VARIABLES[name].attrs()
    prov = provenance()
    summary.attrs = {
        "Conventions": "CF-1.10",
        "title": f"suspsim study summary{f' of {material}' if material else ''}: simulated "
                 "suspension viscosity on (phi, shear_rate, seed)",
        "source": f"suspsim {prov['suspsim_version']} (git {prov['git_sha']})",
        "history": f"{datetime.now(timezone.utc).isoformat(timespec='seconds')} suspsim gather "
                   f"of {len(runs)} run(s)",
        "material": material or "",
        "matrix_fit": fits.pop(),
        "inclusions": settings,
        "inclusion_shape": json.loads(settings)["shape"] if settings else "none",
        "n_runs": len(runs),
        "runs": json.dumps([os.path.basename(s) for s in sources]),
    }
    return summary


def write_summary(run_files: Sequence[str | os.PathLike], out_nc: str | os.PathLike, *,
                  material: str | None = None) -> xr.Dataset:
    """Read the run files, gather them (:func:`gather_runs`) and write ``out_nc`` atomically."""
    names = [str(p) for p in run_files]
    summary = gather_runs((read_run(p) for p in names), material=material, sources=names)
    with atomic_path(out_nc) as tmp:
        summary.to_netcdf(tmp, engine="netcdf4",
                          encoding={name: {"_FillValue": None} for name in summary.coords})
    log.info("gathered %d run(s) into %s: phi %s, shear rates %s 1/s, seeds %s", len(names),
             out_nc, summary["phi"].values.tolist(), summary["shear_rate"].values.tolist(),
             summary["seed"].values.tolist())
    return summary


def _cell(run: xr.Dataset) -> xr.Dataset:
    """One run as a 1×1×1 cell of the summary (matrix viscosity on shear_rate alone)."""
    names = [n for n in STUDY_VARIABLES if n not in SUMMARY_DIMS]
    data = run[names]
    data = data.drop_vars([c for c in data.coords if c not in SUMMARY_DIMS])
    cell = data.expand_dims(list(SUMMARY_DIMS))
    for name in RATE_ONLY:
        cell[name] = cell[name].isel(phi=0, seed=0, drop=True)
    return cell
