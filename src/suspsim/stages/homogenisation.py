"""Stage 2a: the homogenisation estimate of the suspension viscosity from the fitted matrix law.

Chateau, Ovarlez & Trung (2008) predict the viscosity of rigid spheres at volume fraction φ in a
generalized-Newtonian matrix μ_m(γ̇) from the Newtonian relative viscosity g(φ) (SPEC §1.2):

    η(φ, γ̇) = g(φ) μ_m(γ̇ sqrt(g(φ)/(1 − φ))),

with g from Krieger–Dougherty, g = (1 − φ/φ_m)^(−2.5 φ_m). It is the reference every SPH
prediction is plotted against; it needs nothing but the matrix fit, so a study has a prediction
before any simulation runs.

Symbols: φ volume fraction [1]; φ_m maximum packing fraction [1]; γ̇ macroscopic shear rate
[1/s]; μ_m matrix viscosity [Pa s]; η suspension viscosity [Pa s]; η_r = η/μ_m(γ̇) [1].
"""
from __future__ import annotations

import json
import os
from datetime import datetime, timezone
from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from ..errors import InputError
from ..io.atomic import atomic_path, save_figure
from ..io.provenance import provenance
from ..rheology.laws import make_law
from ..rheology.suspension import (chateau_ovarlez_trung_viscosity, krieger_dougherty,
                                   local_shear_rate_factor)

#: Maximum packing fraction of g(φ) [choice]: Mahaut et al., J. Rheol. 52, 287 (2008), fitted
#: their beads-in-yield-stress-fluid data with Krieger–Dougherty and φ_m ≈ 0.57, as did
#: Chateau et al. (2008) when testing this estimate.
DEFAULT_PHI_MAX = 0.57

REFERENCES = (
    "Chateau, Ovarlez & Trung, J. Rheol. 52, 489 (2008) (homogenisation estimate); "
    "Krieger & Dougherty, Trans. Soc. Rheol. 3, 137 (1959) (g(phi)); "
    "Mahaut, Chateau, Coussot & Ovarlez, J. Rheol. 52, 287 (2008) (phi_max = 0.57)")


def homogenisation_estimate(fit: Mapping, volume_fractions: Sequence[float],
                            shear_rates: Sequence[float], *,
                            phi_max: float = DEFAULT_PHI_MAX) -> xr.Dataset:
    """Suspension viscosity η(φ, γ̇) [Pa s] predicted from a matrix fit (a ``fit.json`` dict).

    Returns a Dataset on dims (``volume_fraction``, ``shear_rate``) with
    ``suspension_viscosity`` [Pa s], ``relative_viscosity`` η/μ_m(γ̇) [1],
    ``matrix_viscosity(shear_rate)`` [Pa s], ``newtonian_relative_viscosity(volume_fraction)``
    g(φ) [1] and ``local_shear_rate_factor(volume_fraction)`` sqrt(g/(1 − φ)) [1].
    """
    law = make_law(fit["law"], fit["params"])
    phi = np.asarray(volume_fractions, dtype=float)
    rate = np.asarray(shear_rates, dtype=float)
    if np.any(phi >= phi_max):
        raise ValueError(f"volume fractions must stay below phi_max = {phi_max}; got {phi.max():g}")
    g = krieger_dougherty(phi, phi_max)
    eta = np.array([chateau_ovarlez_trung_viscosity(law.viscosity, rate, p, gp)
                    for p, gp in zip(phi, g)]).reshape(phi.size, rate.size)
    matrix = law.viscosity(rate)
    prov = provenance()
    dims = ("volume_fraction", "shear_rate")
    return xr.Dataset(
        {
            "suspension_viscosity": (dims, eta, {
                "units": "Pa s", "long_name": "suspension viscosity, Chateau-Ovarlez-Trung estimate"}),
            "relative_viscosity": (dims, eta / matrix, {
                "units": "1", "long_name": "suspension viscosity over matrix viscosity at the same rate"}),
            "matrix_viscosity": ("shear_rate", matrix, {
                "units": "Pa s", "long_name": f"fitted matrix viscosity ({law.name})"}),
            "newtonian_relative_viscosity": ("volume_fraction", np.asarray(g, dtype=float), {
                "units": "1", "long_name": "relative viscosity g in a Newtonian matrix, Krieger-Dougherty"}),
            "local_shear_rate_factor": ("volume_fraction",
                                        np.asarray(local_shear_rate_factor(phi, g), dtype=float), {
                "units": "1", "long_name": "mean local over macroscopic shear rate sqrt(g/(1-phi))"}),
        },
        coords={
            "volume_fraction": ("volume_fraction", phi, {"units": "1", "long_name": "solid volume fraction"}),
            "shear_rate": ("shear_rate", rate, {"units": "s-1", "long_name": "macroscopic shear rate"}),
        },
        attrs={
            "Conventions": "CF-1.10",
            "title": "Homogenisation estimate of the suspension viscosity from the matrix fit",
            "source": f"suspsim {prov['suspsim_version']} (git {prov['git_sha']})",
            "history": f"{datetime.now(timezone.utc).isoformat(timespec='seconds')} suspsim",
            "references": REFERENCES,
            "phi_max": phi_max,
            "matrix_fit": json.dumps(dict(fit), ensure_ascii=False),
        },
    )


def write_homogenisation(fit_json: str | os.PathLike, out_nc: str | os.PathLike, *,
                         volume_fractions: Sequence[float], shear_rates: Sequence[float] | None = None,
                         n_rates: int = 61, phi_max: float = DEFAULT_PHI_MAX,
                         out_plot: str | os.PathLike | None = None) -> xr.Dataset:
    """Read a fit report, write the estimate as netCDF (and a figure), both atomically.

    ``shear_rates`` defaults to ``n_rates`` log-spaced rates over the fit's measured range.
    """
    try:
        with open(fit_json, encoding="utf-8") as fh:
            fit = json.load(fh)
        rates = (np.geomspace(*fit["shear_rate_range"], n_rates) if shear_rates is None
                 else np.asarray(shear_rates, dtype=float))
        dataset = homogenisation_estimate(fit, volume_fractions, rates, phi_max=phi_max)
    except (OSError, json.JSONDecodeError, KeyError, ValueError, TypeError) as err:
        raise InputError(fit_json, f"cannot build the homogenisation estimate: {err}") from None
    if out_plot is not None:
        from ..plotting.suspension import plot_homogenisation

        save_figure(plot_homogenisation(dataset), out_plot)
    with atomic_path(out_nc) as tmp:
        dataset.to_netcdf(tmp, engine="netcdf4",
                          encoding={name: {"_FillValue": None} for name in dataset.coords})
    return dataset
