"""Suspension-viscosity figures: η(γ̇) per volume fraction against the matrix, log-log axes."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.figure import Figure


def plot_homogenisation(dataset: xr.Dataset) -> Figure:
    """Two panels: suspension and matrix viscosity [Pa s] vs γ̇, and η/μ_m vs γ̇, one line per φ.

    ``dataset`` is the output of
    :func:`suspsim.stages.homogenisation.homogenisation_estimate`; no file I/O here.
    """
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    ax_eta, ax_rel = fig.subplots(1, 2)
    rate = dataset["shear_rate"].values
    ax_eta.plot(rate, dataset["matrix_viscosity"].values, color="k", lw=2, label="matrix (fit)")
    colours = [f"C{i}" for i in range(dataset.sizes["volume_fraction"])]
    for colour, phi in zip(colours, dataset["volume_fraction"].values):
        sel = dataset.sel(volume_fraction=phi)
        label = f"φ = {phi:.2f}"
        ax_eta.plot(rate, sel["suspension_viscosity"].values, color=colour, label=label)
        ax_rel.plot(rate, sel["relative_viscosity"].values, color=colour, label=label)
        ax_rel.axhline(float(sel["newtonian_relative_viscosity"]), color=colour, ls=":", lw=1)
    ax_eta.set(xscale="log", yscale="log", xlabel="shear rate γ̇ [1/s]", ylabel="viscosity [Pa s]")
    ax_rel.set(xscale="log", yscale="log", xlabel="shear rate γ̇ [1/s]",
               ylabel="relative viscosity η/μ_matrix(γ̇) [1]")
    ax_rel.set_ylim(bottom=min(1.0, float(np.nanmin(dataset["relative_viscosity"]))) * 0.9)
    for ax in (ax_eta, ax_rel):
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"Chateau–Ovarlez–Trung estimate, Krieger–Dougherty g(φ) with "
                 f"φ_m = {dataset.attrs['phi_max']:g} (dotted: Newtonian g)")
    return fig
