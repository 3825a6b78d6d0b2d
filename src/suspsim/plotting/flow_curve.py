"""Flow-curve figure: measured τ(γ̇) and μ(γ̇) with a fitted constitutive law, log-log axes."""
from __future__ import annotations

import logging

import numpy as np
from matplotlib.figure import Figure

from suspsim.rheology.laws import LAW_SPECS

logger = logging.getLogger(__name__)

#: Plain-text symbols of the law parameters for legends (units come from ``LAW_SPECS``).
SYMBOLS = {"mu": "μ", "K": "K", "n": "n", "mu_0": "μ₀", "mu_inf": "μ∞", "lam": "λ", "m": "m",
           "a": "a", "mu_pl": "μ_pl", "M": "M", "tau_y": "τ_y", "gdot_c": "γ̇_c",
           "eta_bg": "η_bg"}
#: The fitted line spans the data range widened by this factor at each end.
EXTEND = 2.0


def describe_fit(result) -> str:
    """'law: symbol = value unit, …' for the fitted parameters (fixed ones omitted)."""
    units = {p.name: p.unit for p in LAW_SPECS[result.law].parameters}
    parts = []
    for name, value in result.params.items():
        if name in result.fixed:
            continue
        unit = "" if units[name] == "1" else f" {units[name]}"
        parts.append(f"{SYMBOLS.get(name, name)} = {value:.3g}{unit}")
    return f"{result.law}: " + ", ".join(parts)


def plot_fit(shear_rate, shear_stress, result, ax=None, label=None) -> Figure:
    """Plot data and fitted law; returns the Figure.

    Parameters
    ----------
    shear_rate, shear_stress : array-like
        Measured shear rates [1/s] and stresses [Pa] (markers).
    result : suspsim.rheology.fitting.FitResult
        The fit, drawn as a line over the data range widened ×2 at each end.
    ax : matplotlib.axes.Axes, optional
        Draw only the stress panel into this axes; by default a new Figure with two panels,
        stress τ [Pa] and viscosity μ = τ/γ̇ [Pa s] against γ̇ [1/s].
    label : str, optional
        Legend label of the data (default: ``result.source`` or "data").
    """
    rate = np.asarray(shear_rate, dtype=float)
    stress = np.asarray(shear_stress, dtype=float)
    if ax is None:
        fig = Figure(figsize=(10.0, 4.2), layout="constrained")
        axes = fig.subplots(1, 2)
    else:
        fig, axes = ax.figure, [ax]
    law = result.constitutive_law()
    lo, hi = float(rate.min()) / EXTEND, float(rate.max()) * EXTEND
    line_rate = np.logspace(np.log10(lo), np.log10(hi), 200)
    data_label = label or result.source or "data"
    fit_label = describe_fit(result)
    panels = [(stress, law.stress(line_rate), "shear stress τ [Pa]"),
              (stress / rate, law.viscosity(line_rate), "viscosity μ [Pa s]")]
    for axis, (measured, model, ylabel) in zip(axes, panels):
        axis.loglog(rate, measured, "o", markersize=4, markerfacecolor="none", label=data_label)
        axis.loglog(line_rate, model, "-", linewidth=1.5, label=fit_label)
        axis.set_xlabel("shear rate γ̇ [1/s]")
        axis.set_ylabel(ylabel)
        axis.grid(True, which="major", alpha=0.3)
    axes[0].legend(fontsize="small", loc="best")
    title = f"RMS log10 residual {result.rms_log_residual:.3g} decades ({result.n_points} points)"
    if ax is None:
        fig.suptitle(f"{result.source} — {title}" if result.source else title)
    else:
        ax.set_title(title)
    logger.debug("plotted %s fit of %s", result.law, result.source)
    return fig
