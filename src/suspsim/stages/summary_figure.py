"""Stage 5: the summary figure of a material, simulation against the fitted law and experiment.

Reads ``summary.nc`` (:mod:`suspsim.stages.gather`), the matrix fit and rheometer file, and
optionally the homogenisation estimate, and draws :func:`suspsim.plotting.summary.plot_summary`.
"""
from __future__ import annotations

import logging
import os

import xarray as xr

from ..errors import InputError
from ..io.atomic import save_figure
from ..io.netcdf import read_run
from ..rheology.laws import make_law
from ..rheology.readers import read_flow_curve
from .simulate import read_fit

log = logging.getLogger(__name__)


def write_summary_figure(summary_nc: str | os.PathLike, out_plot: str | os.PathLike, *,
                         fit_json: str | os.PathLike, matrix_file: str | os.PathLike,
                         sample: str | None = None,
                         estimate_nc: str | os.PathLike | None = None) -> None:
    """Draw the summary figure and save it atomically (format by suffix).

    Raises InputError for an unreadable summary, fit report, rheometer file or estimate.
    """
    from ..plotting.summary import plot_summary

    summary = _read(summary_nc, "summary")
    fit = read_fit(fit_json)
    data = read_flow_curve(matrix_file, sample=sample)
    estimate = _read(estimate_nc, "homogenisation estimate") if estimate_nc else None
    figure = plot_summary(summary, law=make_law(fit["law"], fit["params"]),
                          measured=(data["shear_rate"].to_numpy(), data["viscosity"].to_numpy()),
                          estimate=estimate)
    save_figure(figure, out_plot)
    log.info("wrote %s", out_plot)


def _read(path: str | os.PathLike, what: str) -> xr.Dataset:
    try:
        return read_run(path)
    except InputError as err:
        raise InputError(path, f"cannot read the {what}: {err.problem}") from None
