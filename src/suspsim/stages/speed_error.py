"""The speed-against-error study as pipeline stages (issue 7; the study module is
:mod:`suspsim.convergence.study`).

- :func:`measure_configuration`: one configuration of a case → a netCDF record (0-d
  variables with units; a configuration that blows up is a record too, with NaN measurements
  and the health message in ``failure``: an unstable setting is a result of the study);
- :func:`gather_case`: a case's records → ``<case>.nc`` on dimension ``configuration`` with
  the Pareto front;
- :func:`write_speed_error_report`: every case file → the error-against-cost figure and the
  Markdown table of the cheapest configuration per target error.
"""
from __future__ import annotations

import json
import logging
import os
from typing import Any, Mapping, Sequence

import numpy as np
import xarray as xr

from ..convergence.cases import get_case
from ..convergence.measure import run_configuration
from ..convergence.study import MEASURED, case_dataset, cost_table
from ..errors import InputError, NumericalError
from ..io.atomic import atomic_path, save_figure
from ..io.provenance import provenance

log = logging.getLogger(__name__)


def measure_configuration(case_name: str, overrides: Mapping[str, Any],
                          out: str | os.PathLike, *, threads: int = 1) -> dict[str, Any]:
    """Run one configuration and write its record to ``out`` (netCDF, atomically)."""
    case = get_case(case_name)
    try:
        record = run_configuration(case, overrides, threads=threads)
    except NumericalError as err:
        log.warning("%s %s blew up: %s", case_name, dict(overrides), err)
        record = {**case.settings(overrides), "failure": str(err), "threads": threads}
    units = {axis.name: axis.unit for axis in case.axes}
    data = {}
    for name, value in record.items():
        unit = units.get(name) or MEASURED.get(name, ("1", ""))[0]
        data[name] = ((), value if isinstance(value, str) else float(value), {"units": unit})
    ds = xr.Dataset(data)
    ds.attrs.update(case=case_name, overrides=json.dumps(dict(overrides)), **provenance())
    with atomic_path(out) as tmp:
        ds.to_netcdf(tmp)
    return record


def read_record(path: str | os.PathLike) -> dict[str, Any]:
    """A record written by :func:`measure_configuration` as a dict of Python values."""
    with xr.open_dataset(path) as ds:
        if "case" not in ds.attrs:
            raise InputError(path, "not a speed_error record (no 'case' attribute)")
        return {name: (ds[name].item() if ds[name].dtype.kind in "OSU"
                       else float(ds[name])) for name in ds.data_vars}


def gather_case(case_name: str, files: Sequence[str | os.PathLike],
                out: str | os.PathLike) -> xr.Dataset:
    """The case's records → one Dataset on ``configuration`` (atomically to ``out``)."""
    case = get_case(case_name)
    records = []
    for path in files:
        record = read_record(path)
        for axis in case.axes:
            if isinstance(axis.default, int) and not isinstance(axis.default, bool):
                record[axis.name] = int(record[axis.name])
        records.append(record)
    ds = case_dataset(case, records)
    ds.attrs.update(**provenance())
    with atomic_path(out) as tmp:
        ds.to_netcdf(tmp)
    return ds


def write_speed_error_report(case_files: Sequence[str | os.PathLike],
                             figure: str | os.PathLike, table: str | os.PathLike) -> None:
    """The Pareto figure and the cost table of every case file."""
    from ..plotting.pareto import plot_pareto

    datasets = [xr.load_dataset(path) for path in case_files]
    save_figure(plot_pareto(datasets), figure)
    text = cost_table(datasets)
    with atomic_path(table) as tmp:
        tmp.write_text(text, encoding="utf-8")
    failed = sum(int(np.sum(ds["failure"].values != "")) for ds in datasets)
    log.info("speed_error report: %d cases, %d failed configurations", len(datasets), failed)
