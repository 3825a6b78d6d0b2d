"""Configurations of a speed-against-error study, their records as one Dataset per case, the
Pareto front of error against cost, and the table of what accuracy costs what.

A study names, per case, values for some of the case's axes (:mod:`.cases`). ``one_at_a_time``
runs the case's defaults ("base") and each listed value with every other axis at its default
(one axis varied at a time: what each setting costs and buys); ``grid`` runs every
combination. The cost of a configuration is its CPU time on one thread (``cpu_time``, [s]),
which equals the wall time on an idle core and, unlike it, does not grow when other jobs
share the machine; ``wall_time`` is kept beside it. A configuration meets a target error ε when
its ``error_bound`` = error + 2 × its statistical standard error (the error itself where none
is estimated) is at most ε: a Couette reading of 0.4 % ± 0.3 % does not show 1 %. The Pareto
front is taken on the same bound.
"""
from __future__ import annotations

import itertools
import json
from typing import Any, Iterable, Mapping, Sequence

import numpy as np
import xarray as xr

from suspsim.convergence.cases import AnyCase
from suspsim.errors import InputError

SWEEPS = ("one_at_a_time", "grid")
#: Standard errors added to a measured error for the bound a target is checked against [choice:
#: about 95 % one-sided].
STDERR_FACTOR = 2.0
#: Targets of the cost table: relative errors [1].
TABLE_TARGETS = (0.10, 0.05, 0.02, 0.01)

#: Units and long names of a record's measured quantities (the axes carry their own).
MEASURED = {
    "error": ("1", "error against the reference (|viscosity ratio - 1| or L2/peak)"),
    "signed_error": ("1", "signed error (viscosity ratio - 1, or L2/peak)"),
    "error_stderr": ("1", "standard error of the error (statistical; NaN if not estimated)"),
    "wall_time": ("s", "wall time of set-up and run"),
    "cpu_time": ("s", "CPU time of set-up and run (the cost axis)"),
    "setup_time": ("s", "wall time of the set-up"),
    "n_particles": ("1", "number of SPH particles"),
    "n_steps": ("1", "number of time steps"),
    "particle_steps_per_s": ("s-1", "particle-steps per second of the run"),
    "dt": ("tau", "time step in simulation units"),
    "sound_speed": ("h tau-1", "artificial sound speed in simulation units"),
    "number_density": ("1", "particles per h^dimension after snapping"),
    "resolution_used": ("1", "lattice sites per support radius after snapping"),
    "threads": ("1", "solver threads"),
}


def configurations(case: AnyCase, values: Mapping[str, Sequence[Any]],
                   sweep: str = "one_at_a_time") -> list[dict[str, Any]]:
    """The overrides of each configuration (``{}`` is the case's defaults), without repeats.

    ``tolerance: [ε, ...]`` among the values adds, for each ε, the configuration the error
    model's inflated bound picks for that relative error (:func:`.picker.pick`; an unreachable
    ε is an InputError), so a study measures what ``suspsim run --tolerance --no-verify``
    would run (the verified mode's attempts depend on the runs: :mod:`.holdout`)."""
    if sweep not in SWEEPS:
        raise InputError("speed_error", f"sweep must be one of {', '.join(SWEEPS)}, not '{sweep}'",
                         key="speed_error.sweep")
    values = dict(values)
    tolerances = values.pop("tolerance", [])
    defaults = case.settings()
    for axis in values:
        case.settings({axis: defaults.get(axis)})
    if sweep == "grid":
        axes = list(values)
        combos = [dict(zip(axes, combo)) for combo in itertools.product(*values.values())]
    else:
        combos = [{}] + [{axis: value} for axis, listed in values.items() for value in listed]
    if tolerances:
        from suspsim.convergence.picker import pick

        combos += [pick(case, float(tol)).settings for tol in tolerances]
    out, seen = [], set()
    for combo in combos:
        overrides = {k: v for k, v in combo.items() if v != defaults[k]}
        key = configuration_id(overrides)
        if key not in seen:
            seen.add(key)
            out.append(overrides)
    return out


def configuration_id(overrides: Mapping[str, Any]) -> str:
    """A file-name-safe name of a configuration: ``base`` or ``axis-value+axis-value``."""
    if not overrides:
        return "base"
    return "+".join(f"{axis}-{_tag(overrides[axis])}" for axis in sorted(overrides))


def _tag(value) -> str:
    return f"{value:g}" if isinstance(value, (int, float)) else str(value)


def case_dataset(case: AnyCase, records: Iterable[Mapping[str, Any]]) -> xr.Dataset:
    """The records of one case on dimension ``configuration`` (named by :func:`configuration_id`
    of their overrides); a failed configuration has NaN measurements and its message in
    ``failure``. Units on every variable; the Pareto front as ``pareto`` (1 on the front)."""
    records = list(records)
    defaults = case.settings()
    ids = [configuration_id({k: r[k] for k in defaults if r[k] != defaults[k]}) for r in records]
    data = {}
    for axis in case.axes:
        values = [r[axis.name] for r in records]
        data[axis.name] = ("configuration", np.asarray(values, dtype=object if isinstance(
            axis.default, str) else float), {"units": axis.unit, "long_name": axis.description,
                                              "default": str(axis.default)})
    for name, (unit, long_name) in MEASURED.items():
        data[name] = ("configuration", np.array([float(r.get(name, np.nan)) for r in records]),
                      {"units": unit, "long_name": long_name})
    data["failure"] = ("configuration", np.array([r.get("failure", "") for r in records],
                                                 dtype=object),
                       {"long_name": "health-check message of a configuration that blew up"})
    ds = xr.Dataset(data, coords={"configuration": ("configuration", np.array(ids, dtype=object),
                                                    {"long_name": "changed settings"})})
    ds["error_bound"] = ("configuration", error_bound(ds["error"].values,
                                                      ds["error_stderr"].values),
                         {"units": "1", "long_name": f"error + {STDERR_FACTOR:g} standard errors"})
    ds["pareto"] = ("configuration", pareto_front(ds["cpu_time"].values,
                                                  ds["error_bound"].values).astype(np.int8),
                    {"units": "1", "long_name": "1 on the Pareto front of error against cost"})
    ds.attrs.update(case=case.name, description=case.description, reference=case.reference,
                    defaults=json.dumps(defaults), cost="cpu_time")
    return ds


def error_bound(error, stderr):
    """|error| + :data:`STDERR_FACTOR` standard errors [1] (a NaN standard error, where none is
    estimated, counts as 0); scalars or arrays."""
    return np.abs(error) + STDERR_FACTOR * np.nan_to_num(stderr, nan=0.0)


def pareto_front(cost: np.ndarray, error: np.ndarray) -> np.ndarray:
    """Boolean mask of the non-dominated points: no other point has cost ≤ and error ≤ with one
    of them strictly less. NaN points (failed runs) are never on the front."""
    cost, error = np.asarray(cost, float), np.asarray(error, float)
    finite = np.isfinite(cost) & np.isfinite(error)
    front = np.zeros(cost.shape, dtype=bool)
    best = np.inf
    for i in sorted(np.flatnonzero(finite), key=lambda k: (cost[k], error[k])):
        if error[i] < best:
            front[i] = True
            best = error[i]
    return front


def cheapest_meeting(ds: xr.Dataset, target: float) -> int | None:
    """Index of the cheapest configuration whose error bound is ≤ ``target``, or None."""
    ok = np.flatnonzero(ds["error_bound"].values <= target)
    if ok.size == 0:
        return None
    return int(ok[np.argmin(ds["cpu_time"].values[ok])])


def cost_table(datasets: Sequence[xr.Dataset], targets: Sequence[float] = TABLE_TARGETS) -> str:
    """Markdown table: for each case and target error, the cheapest measured configuration
    whose error bound meets it, its error (± stderr), cost and throughput."""
    lines = ["| case | error ≤ | cheapest configuration | error | CPU time [s] | particles "
             "| M particle-steps/s |", "|---|---|---|---|---|---|---|"]
    for ds in datasets:
        for target in targets:
            k = cheapest_meeting(ds, target)
            if k is None:
                lines.append(f"| {ds.attrs['case']} | {target * 100:g}% | none measured | | | | |")
                continue
            row = ds.isel(configuration=k)
            stderr = float(row["error_stderr"])
            error = f"{float(row['error']):.2%}" + (f" ± {stderr:.2%}" if np.isfinite(stderr)
                                                   else "")
            lines.append(f"| {ds.attrs['case']} | {target * 100:g}% "
                         f"| {row['configuration'].item()} | {error} "
                         f"| {float(row['cpu_time']):.3g} | {int(row['n_particles'])} "
                         f"| {float(row['particle_steps_per_s']) / 1e6:.2f} |")
    return "\n".join(lines) + "\n"
