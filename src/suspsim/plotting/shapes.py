"""Particle shapes compared: the relative viscosity of two or more studies (spheres, sand grains)
at equal volume fraction and shear rate (seed 000 Fig. 6: sand reads above spheres).

Input: gathered summaries (:func:`suspsim.stages.gather.gather_runs`, dims phi, shear_rate,
seed), keyed by a label ("spheres", "sand"). η_r and its error are the means over seeds of
:func:`~suspsim.analysis.seeds.seed_mean`. The ratio of two studies' η_r at equal (φ, γ̇)
carries the error

    s_ratio = ratio · sqrt((s_a/η_a)² + (s_b/η_b)²)    (independent runs).

Each panel is one shear rate common to the studies: η_r against φ per study, over the band of
the published fits for spheres in a Newtonian fluid
(:func:`~suspsim.rheology.suspension.published_envelope`). No file I/O here.
"""
from __future__ import annotations

from typing import Mapping

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ..analysis.seeds import seed_mean
from ..rheology.suspension import published_envelope

#: Largest φ the published band is drawn to [1] (the fits are meant for φ ≤ 0.5).
BAND_MAX_PHI = 0.5
#: Markers of the studies in order.
MARKERS = ("o", "s", "^", "D")


def relative_viscosity_table(summary: xr.Dataset) -> xr.Dataset:
    """η_r [1] and its error (``relative_viscosity``, ``relative_viscosity_error``), dims phi and
    shear_rate: the seed means of ``summary``."""
    mean, error = seed_mean(summary, "relative_viscosity")
    out = xr.Dataset({"relative_viscosity": mean, "relative_viscosity_error": error})
    for name in out:
        out[name].attrs["units"] = "1"
    return out


def shape_ratio(numerator: xr.Dataset, denominator: xr.Dataset) -> xr.Dataset:
    """η_r of ``numerator`` over η_r of ``denominator`` (summaries) at their common φ > 0 and
    shear rates, with its error (module docstring): variables ``ratio``, ``ratio_error`` [1]."""
    a, b = relative_viscosity_table(numerator), relative_viscosity_table(denominator)
    a, b = xr.align(a, b, join="inner")
    a, b = (t.sel(phi=t["phi"] > 0) for t in (a, b))
    ratio = a["relative_viscosity"] / b["relative_viscosity"]
    error = ratio * np.sqrt((a["relative_viscosity_error"] / a["relative_viscosity"]) ** 2
                            + (b["relative_viscosity_error"] / b["relative_viscosity"]) ** 2)
    return xr.Dataset({"ratio": ratio.assign_attrs(units="1"),
                       "ratio_error": error.assign_attrs(units="1")})


def plot_shape_comparison(summaries: Mapping[str, xr.Dataset]) -> Figure:
    """η_r [1] against φ [1], one panel per shear rate common to all ``summaries`` (labelled by
    their keys), over the published band (module docstring)."""
    tables = {label: relative_viscosity_table(s) for label, s in summaries.items()}
    rates = sorted(set.intersection(*(set(t["shear_rate"].values.tolist())
                                      for t in tables.values())))
    if not rates:
        raise ValueError("the summaries share no shear rate")
    fig = Figure(figsize=(4.2 * len(rates), 4.0), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(rates), sharey=True))
    top = max(float(t["phi"].max()) for t in tables.values())
    band_phi = np.linspace(0.0, min(BAND_MAX_PHI, top + 0.05), 100)
    low, high = published_envelope(band_phi)
    for ax, rate in zip(axes, rates):
        ax.fill_between(band_phi, low, high, color="0.85",
                        label="published fits, spheres in a Newtonian fluid")
        for i, (label, table) in enumerate(tables.items()):
            at = table.sel(shear_rate=rate)
            ax.errorbar(at["phi"].values, at["relative_viscosity"].values,
                        yerr=at["relative_viscosity_error"].values, fmt=MARKERS[i % len(MARKERS)],
                        color=f"C{i}", mfc="none" if i else None, ms=6, capsize=3,
                        label=f"{label}, SPH")
        ax.set(title=f"γ̇ = {rate:g} 1/s", xlabel="volume fraction φ [1]")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("relative viscosity η/μ_matrix(γ̇) [1]")
    axes[0].legend(fontsize=8)
    return fig
