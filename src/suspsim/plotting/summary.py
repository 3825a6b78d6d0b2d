"""Study-summary figures: simulated suspension viscosity against the matrix and experiment.

Input is a gathered summary (:func:`suspsim.stages.gather.gather_runs`, dims phi, shear_rate,
seed). Each φ is one colour: the mean over seeds with an error bar combining the runs' standard
errors and the spread between seeds,

    η̄ = (1/n) Σ η_i,    s² = (1/n²) Σ s_i² + Var_seeds(η)/n    (Var = 0 for one seed),

drawn over the fitted matrix law (line), the measured matrix points (open circles) and, for φ > 0,
the homogenisation estimate of the same φ (dashed) when one is given. No file I/O here.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from ..rheology.laws import ConstitutiveLaw

#: The fitted-law line spans the plotted rates widened by this factor at each end.
EXTEND = 2.0
#: Two volume fractions closer than this are the same φ when matching an estimate [1].
PHI_TOLERANCE = 1e-9


def seed_mean(summary: xr.Dataset, name: str) -> tuple[xr.DataArray, xr.DataArray]:
    """Mean of ``name`` over seeds and its error (module docstring); NaN runs are skipped."""
    values, errors = summary[name], summary[f"{name}_stderr"]
    n = values.notnull().sum("seed")
    mean = values.mean("seed")
    spread = values.var("seed", ddof=1).fillna(0.0) if summary.sizes["seed"] > 1 else 0.0 * mean
    error = np.sqrt((errors ** 2).sum("seed") / n ** 2 + spread / n)
    return mean.where(n > 0), error.where(n > 0)


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


def plot_summary(summary: xr.Dataset, *, law: ConstitutiveLaw | None = None,
                 measured: tuple[Sequence[float], Sequence[float]] | None = None,
                 estimate: xr.Dataset | None = None) -> Figure:
    """Two panels: :func:`plot_viscosity` and :func:`plot_relative_viscosity`."""
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    ax_eta, ax_rel = fig.subplots(1, 2)
    plot_viscosity(summary, ax_eta, law=law, measured=measured, estimate=estimate)
    plot_relative_viscosity(summary, ax_rel)
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


def _estimate_curve(estimate: xr.Dataset | None, phi: float) -> xr.DataArray | None:
    """The estimate's η(γ̇) at volume fraction ``phi``, or None (φ = 0 or not in it)."""
    if estimate is None or phi == 0:
        return None
    fractions = estimate["volume_fraction"].values
    match = np.flatnonzero(np.abs(fractions - phi) <= PHI_TOLERANCE)
    if match.size == 0:
        return None
    return estimate["suspension_viscosity"].isel(volume_fraction=int(match[0]))
