"""Study-summary figures: simulated suspension viscosity against the matrix and experiment.

Input is a gathered summary (:func:`suspsim.stages.gather.gather_runs`, dims phi, shear_rate,
seed). Each φ is one colour: the mean over seeds with an error bar combining the runs' standard
errors and the spread between seeds (:func:`suspsim.analysis.seeds.seed_mean`), drawn over the
fitted matrix law (line), the measured matrix points (open circles) and, for φ > 0, the
homogenisation estimate of the same φ (dashed) when one is given. The relative viscosity
η_r = η/μ_m(γ̇) is drawn against γ̇ per φ (φ = 0 checks the solver: 1) and against φ per γ̇, there
beside the estimate's η_r(φ) at each simulated rate (dashed, interpolated in log γ̇ when the
estimate's rates differ) and its Newtonian limit, Krieger–Dougherty g(φ) (dotted). No file I/O
here.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..analysis.seeds import seed_mean
from ..rheology.laws import ConstitutiveLaw

#: The fitted-law line spans the plotted rates widened by this factor at each end.
EXTEND = 2.0
#: Two volume fractions closer than this are the same φ when matching an estimate [1].
PHI_TOLERANCE = 1e-9
#: A simulated rate this close (relative) outside the estimate's rates is still inside [1].
RATE_TOLERANCE = 1e-9
#: Colour map of the shear rates in the η_r(φ) panel, low rate dark.
RATE_COLOURS = "viridis"


def plot_viscosity(summary: xr.Dataset, ax: Axes | None = None, *,
                   law: ConstitutiveLaw | None = None,
                   measured: tuple[Sequence[float], Sequence[float]] | None = None,
                   estimate: xr.Dataset | None = None) -> Figure:
    """Suspension viscosity [Pa s] vs shear rate [1/s] per φ, log-log (module docstring).

    ``law`` the fitted matrix law (SI); ``measured`` (shear rates [1/s], viscosities [Pa s]) of
    the matrix; ``estimate`` a homogenisation Dataset (dims volume_fraction, shear_rate).
    """
    fig, ax = _figure_and_axes(ax)
    rates = summary["shear_rate"].values
    span = [rates.min(), rates.max()]
    if measured is not None:
        m_rate, m_visc = (np.asarray(v, dtype=float) for v in measured)
        ax.plot(m_rate, m_visc, "o", color="0.55", mfc="none", ms=4, label="matrix (measured)")
        span = [min(span[0], m_rate.min()), max(span[1], m_rate.max())]
    if law is not None:
        line = np.geomspace(span[0] / EXTEND, span[1] * EXTEND, 200)
        ax.plot(line, law.viscosity(line), "-", color="k", lw=1.5, label=f"matrix ({law.name} fit)")
    mean, error = seed_mean(summary, "suspension_viscosity")
    for i, phi in enumerate(summary["phi"].values):
        colour = f"C{i}"
        ax.errorbar(rates, mean.sel(phi=phi).values, yerr=error.sel(phi=phi).values, fmt="s",
                    color=colour, ms=5, capsize=3, label=_phi_label(phi, summary))
        curve = _estimate_curve(estimate, phi)
        if curve is not None:
            ax.plot(curve["shear_rate"].values, curve.values, "--", color=colour, lw=1,
                    label=f"φ = {phi:g} homogenisation estimate")
    ax.set(xscale="log", yscale="log", xlabel="shear rate γ̇ [1/s]", ylabel="viscosity [Pa s]")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_relative_viscosity(summary: xr.Dataset, ax: Axes | None = None) -> Figure:
    """Relative viscosity η/μ_matrix(γ̇) [1] vs shear rate [1/s] per φ; 1 marked (φ = 0 check)."""
    fig, ax = _figure_and_axes(ax)
    rates = summary["shear_rate"].values
    mean, error = seed_mean(summary, "relative_viscosity")
    for i, phi in enumerate(summary["phi"].values):
        ax.errorbar(rates, mean.sel(phi=phi).values, yerr=error.sel(phi=phi).values, fmt="s",
                    color=f"C{i}", ms=5, capsize=3, label=_phi_label(phi, summary))
    ax.axhline(1.0, color="k", lw=1, ls=":")
    ax.set(xscale="log", xlabel="shear rate γ̇ [1/s]",
           ylabel="relative viscosity η/μ_matrix(γ̇) [1]")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def plot_relative_viscosity_vs_phi(summary: xr.Dataset, ax: Axes | None = None, *,
                                   estimate: xr.Dataset | None = None) -> Figure:
    """Relative viscosity η/μ_matrix(γ̇) [1] vs volume fraction φ [1], one colour per shear rate
    (from :data:`RATE_COLOURS`, so that they differ from the φ colours of the other panels).

    ``estimate`` a homogenisation Dataset (dims volume_fraction, shear_rate, with
    ``relative_viscosity`` and ``newtonian_relative_viscosity``), best on a fine φ grid: its
    η_r(φ) at each simulated rate is drawn dashed, g(φ) dotted (module docstring).
    """
    fig, ax = _figure_and_axes(ax)
    phis = summary["phi"].values
    mean, error = seed_mean(summary, "relative_viscosity")
    rates = summary["shear_rate"].values
    colours = colormaps[RATE_COLOURS](np.linspace(0.0, 0.85, rates.size))
    for rate, colour in zip(rates, colours):
        ax.errorbar(phis, mean.sel(shear_rate=rate).values,
                    yerr=error.sel(shear_rate=rate).values, fmt="o", color=colour, ms=5,
                    capsize=3, label=f"γ̇ = {rate:g} 1/s, SPH")
        curve = _estimate_at_rate(estimate, rate)
        if curve is not None:
            ax.plot(curve["volume_fraction"].values, curve.values, "--", color=colour, lw=1,
                    label=f"γ̇ = {rate:g} 1/s, homogenisation estimate")
    if estimate is not None and "newtonian_relative_viscosity" in estimate:
        g = estimate["newtonian_relative_viscosity"]
        ax.plot(g["volume_fraction"].values, g.values, ":", color="k", lw=1,
                label="Krieger–Dougherty g(φ) (Newtonian matrix)")
    ax.axhline(1.0, color="0.6", lw=0.8)
    ax.set(xlabel="volume fraction φ [1]", ylabel="relative viscosity η/μ_matrix(γ̇) [1]")
    ax.set_xlim(left=0.0)
    ax.set_ylim(bottom=0.0)
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=7)
    return fig


def plot_summary(summary: xr.Dataset, *, law: ConstitutiveLaw | None = None,
                 measured: tuple[Sequence[float], Sequence[float]] | None = None,
                 estimate: xr.Dataset | None = None,
                 estimate_by_phi: xr.Dataset | None = None) -> Figure:
    """Three panels: :func:`plot_viscosity` (with ``estimate``), :func:`plot_relative_viscosity`
    and :func:`plot_relative_viscosity_vs_phi` (with ``estimate_by_phi``, default ``estimate``)."""
    fig = Figure(figsize=(15, 4.4), layout="constrained")
    ax_eta, ax_rel, ax_phi = fig.subplots(1, 3)
    plot_viscosity(summary, ax_eta, law=law, measured=measured, estimate=estimate)
    plot_relative_viscosity(summary, ax_rel)
    plot_relative_viscosity_vs_phi(summary, ax_phi,
                                   estimate=estimate if estimate_by_phi is None
                                   else estimate_by_phi)
    material = summary.attrs.get("material")
    fig.suptitle(f"SPH simulations{f' of {material}' if material else ''}: "
                 f"{int(summary.attrs.get('n_runs', 0))} run(s), mean over seeds ± error")
    return fig


def _figure_and_axes(ax: Axes | None) -> tuple[Figure, Axes]:
    if ax is not None:
        return ax.figure, ax
    fig = Figure(figsize=(5.5, 4.2), layout="constrained")
    return fig, fig.subplots()


def _phi_label(phi: float, summary: xr.Dataset) -> str:
    seeds = int(summary["suspension_viscosity"].sel(phi=phi).notnull().any("shear_rate").sum())
    what = "matrix alone" if phi == 0 else "suspension"
    return f"φ = {phi:g}, SPH ({what}, {seeds} seed{'s' if seeds != 1 else ''})"


def _estimate_at_rate(estimate: xr.Dataset | None, rate: float) -> xr.DataArray | None:
    """The estimate's η_r(φ) at shear rate ``rate``, interpolated in log γ̇, with (0, 1)
    added when the estimate starts above φ = 0; None outside its rates or without one."""
    if estimate is None or "relative_viscosity" not in estimate:
        return None
    relative = estimate["relative_viscosity"]
    rates = relative["shear_rate"].values
    if not rates.min() * (1 - RATE_TOLERANCE) <= rate <= rates.max() * (1 + RATE_TOLERANCE):
        return None
    if rates.size == 1:
        curve = relative.isel(shear_rate=0, drop=True)
    else:
        logged = relative.assign_coords(shear_rate=np.log10(rates))
        curve = logged.interp(shear_rate=np.log10(rate)).drop_vars("shear_rate")
    curve = curve.sortby("volume_fraction")
    if curve["volume_fraction"].values[0] > 0:
        start = xr.DataArray([1.0], coords={"volume_fraction": [0.0]}, dims="volume_fraction")
        curve = xr.concat([start, curve], dim="volume_fraction")
    return curve


def _estimate_curve(estimate: xr.Dataset | None, phi: float) -> xr.DataArray | None:
    """The estimate's η(γ̇) at volume fraction ``phi``, or None (φ = 0 or not in it)."""
    if estimate is None or phi == 0:
        return None
    fractions = estimate["volume_fraction"].values
    match = np.flatnonzero(np.abs(fractions - phi) <= PHI_TOLERANCE)
    if match.size == 0:
        return None
    return estimate["suspension_viscosity"].isel(volume_fraction=int(match[0]))
