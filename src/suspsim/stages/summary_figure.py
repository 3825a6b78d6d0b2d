"""Stage 5: the summary figure of a material, simulation against the fitted law and experiment.

Reads ``summary.nc`` (:mod:`suspsim.stages.gather`), the matrix fit and rheometer file, and
optionally the homogenisation estimate, and draws :func:`suspsim.plotting.summary.plot_summary`.
The η_r(φ) panel takes the estimate recomputed from the fit (:func:`estimate_by_phi`) on a fine
φ grid at exactly the simulated rates, with the estimate file's φ_m, so its curves are smooth
and need no interpolation in γ̇.
"""
from __future__ import annotations

import logging
import os

import numpy as np
import xarray as xr

from ..errors import InputError
from ..io.atomic import save_figure
from ..io.netcdf import read_run
from ..rheology.laws import make_law
from ..rheology.readers import read_flow_curve
from .homogenisation import homogenisation_estimate
from .simulate import read_fit

#: Points of the fine φ grid of the η_r(φ) panel's estimate [choice].
PHI_POINTS = 60
#: The grid ends this far below φ_m, where g(φ) diverges [1] [choice].
PHI_MAX_MARGIN = 0.05

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
    fine = None if estimate is None else estimate_by_phi(fit, summary, estimate)
    figure = plot_summary(summary, law=make_law(fit["law"], fit["params"]),
                          measured=(data["shear_rate"].to_numpy(), data["viscosity"].to_numpy()),
                          estimate=estimate, estimate_by_phi=fine)
    save_figure(figure, out_plot)
    log.info("wrote %s", out_plot)


def estimate_by_phi(fit: dict, summary: xr.Dataset, estimate: xr.Dataset) -> xr.Dataset:
    """The homogenisation estimate at the summary's shear rates on :data:`PHI_POINTS` volume
    fractions from 0 to 10 % past the largest simulated or estimated φ, but at most
    φ_m − :data:`PHI_MAX_MARGIN` (φ_m from ``estimate``)."""
    phi_max = float(estimate.attrs["phi_max"])
    largest = max(float(summary["phi"].max()), float(estimate["volume_fraction"].max()))
    upper = min(1.1 * largest, phi_max - PHI_MAX_MARGIN)
    return homogenisation_estimate(fit, np.linspace(0.0, upper, PHI_POINTS),
                                   summary["shear_rate"].values, phi_max=phi_max)


def _read(path: str | os.PathLike, what: str) -> xr.Dataset:
    try:
        return read_run(path)
    except InputError as err:
        raise InputError(path, f"cannot read the {what}: {err.problem}") from None
