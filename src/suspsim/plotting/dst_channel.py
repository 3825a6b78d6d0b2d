"""DST channel figures: profiles against the local ODE (Fig. 7) and mean velocity against force
(Fig. 8), from Datasets of :func:`suspsim.dst.channel_study.channel_sweep`. No file I/O."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure

from suspsim.plotting.dst import steady_law
from suspsim.reference.dst_channel import (dst_channel_fraction, dst_channel_mean_velocity,
                                           dst_channel_profile)
from suspsim.reference.inverse_biviscous import InverseBiviscous

#: Forces of each reference curve (log-spaced over the data, a factor 1.5 beyond each end).
CURVE_POINTS = 60
#: Heights of each reference profile.
PROFILE_POINTS = 61
MARKERS = "osD^v"


def _label(data: xr.Dataset) -> str:
    a = data.attrs
    kind = "local" if a["alpha"] == 0 else f"α = {a['alpha']:g}"
    return f"SPH {kind} ({a['protocol']}, {a['n_x']} × {a['n_y']})"


def _model(data: xr.Dataset) -> InverseBiviscous:
    a = data.attrs
    return InverseBiviscous(a["low_viscosity"], a["high_viscosity"], a["critical_rate"])


def _as_list(datasets):
    return [datasets] if isinstance(datasets, xr.Dataset) else list(datasets)


def plot_channel_profiles(datasets, force_ratios=(1.0, 10.0, 100.0), *, labels=None) -> Figure:
    """Velocity (top row) and f (bottom row) across the gap at each F H/σ* in ``force_ratios``.

    ``datasets``: one or more channel Datasets of the same fluid parameters (φ, φ_m, φ_0, β).
    Lines, on a fine grid: the local Wyart–Cates ODE u(y) and f̂(F |H − y|) (SPEC §5.7) and the
    inverse-biviscous u(y) (dashed). Markers: SPH row averages of each dataset; each top
    panel lists the datasets' L2 errors relative to the peak (``velocity_l2_error``).
    ``labels``: legend entries (default from α, protocol and lattice).
    """
    datasets = _as_list(datasets)
    ratios = [float(r) for r in force_ratios]
    fig = Figure(figsize=(3.6 * len(ratios), 7.0), layout="constrained")
    axes = fig.subplots(2, len(ratios), squeeze=False, sharex=True)
    colours = [colormaps["tab10"](k % 10) for k in range(len(datasets))]
    first = datasets[0]
    law, model = steady_law(first), _model(first)
    gap = float(first.attrs["gap"])
    y_fine = np.linspace(0.0, gap, PROFILE_POINTS)
    names = [labels[k] if labels is not None else _label(d) for k, d in enumerate(datasets)]
    for col, ratio in enumerate(ratios):
        force = 2.0 * ratio * first.attrs["sigma_star"] / gap
        top, bottom = axes[0, col], axes[1, col]
        top.plot(y_fine, dst_channel_profile(law, force, gap, y_fine), "k-", lw=1.3,
                 label="local Wyart–Cates (ODE)")
        top.plot(y_fine, model.channel_profile(force, gap, y_fine), "k--", lw=1.0,
                 label=f"inverse-biviscous, γ̇_c = {model.critical_rate:.3g} σ*/η_s")
        bottom.plot(y_fine, dst_channel_fraction(law, force, gap, y_fine), "k-", lw=1.3,
                    label="local f̂(F |H − y|)")
        errors = []
        for k, (data, colour) in enumerate(zip(datasets, colours)):
            point = data.sel(force_ratio=ratio)
            marker = MARKERS[k % len(MARKERS)]
            top.plot(data["y"].values, point["velocity"].values, marker, ms=4, mfc="none",
                     color=colour, label=names[k])
            bottom.plot(data["y"].values, point["fraction"].values, marker, ms=4, mfc="none",
                        color=colour)
            errors.append(f"{float(point['velocity_l2_error']):.2%}")
        top.text(0.5, 0.03, "L2/peak vs ODE: " + ", ".join(errors), transform=top.transAxes,
                 ha="center", fontsize="x-small")
        top.set_title(f"F H/σ* = {ratio:g}", fontsize="medium")
        top.set_ylim(bottom=0.0)
        top.set_ylabel("velocity u [σ* L_y/η_s]")
        bottom.set_ylabel("frictional fraction f [1]")
        bottom.set_xlabel("y [L_y]")
        bottom.set_ylim(-0.03, 1.03)
        for ax in (top, bottom):
            ax.grid(True, alpha=0.3)
    handles, texts = axes[0, 0].get_legend_handles_labels()
    extra = axes[1, 0].get_legend_handles_labels()
    fig.legend(handles + extra[0], texts + extra[1], loc="outside lower center", ncol=3,
               fontsize="small")
    a = first.attrs
    fig.suptitle(f"DST channel, φ = {a['phi']:g} (φ_m = {a['phi_m']:g}, φ_0 = {a['phi_0']:g}, "
                 f"β = {a['beta']:g}): SPH row averages vs the local ODE", fontsize="medium")
    return fig


def plot_channel_flow(datasets, *, labels=None) -> Figure:
    """Mean velocity ū against F H/σ* (log–log), one column per fluid parameter set.

    ``datasets``: channel Datasets; those with the same (φ, φ_m, φ_0, β) share a column.
    Lines: the local Wyart–Cates ODE ū (solid; its fall between the turning stresses is the
    flow reduction) and the inverse-biviscous ū (dashed), over the forces of the data;
    dotted verticals: F H = σ_β, σ_α (turning points) and σ_1, σ_2 (the plateau's ends).
    Markers: SPH ``mean_velocity``. Lower row: SPH / local ODE − 1. ``labels``: legend
    entries, one per dataset (default from α, protocol and lattice).
    """
    datasets = _as_list(datasets)
    keys = []
    for data in datasets:
        key = tuple(data.attrs[k] for k in ("phi", "phi_m", "phi_0", "beta"))
        if key not in keys:
            keys.append(key)
    fig = Figure(figsize=(5.6 * len(keys), 6.8), layout="constrained")
    axes = fig.subplots(2, len(keys), squeeze=False, height_ratios=(3, 1))
    colours = [colormaps["tab10"](k % 10) for k in range(len(datasets))]
    for col, key in enumerate(keys):
        ax, lower = axes[0, col], axes[1, col]
        members = [k for k, d in enumerate(datasets)
                   if tuple(d.attrs[n] for n in ("phi", "phi_m", "phi_0", "beta")) == key]
        first = datasets[members[0]]
        law, model = steady_law(first), _model(first)
        gap = float(first.attrs["gap"])
        ratios = np.concatenate([datasets[k]["force_ratio"].values for k in members])
        curve = np.geomspace(ratios.min() / 1.5, ratios.max() * 1.5, CURVE_POINTS)
        forces = 2.0 * curve * first.attrs["sigma_star"] / gap
        ax.plot(curve, [dst_channel_mean_velocity(law, f, gap) for f in forces], "k-", lw=1.3,
                label="local Wyart–Cates (ODE)")
        ax.plot(curve, model.channel_mean_velocity(forces, gap), "k--", lw=1.1,
                label=f"inverse-biviscous, γ̇_c = {model.critical_rate:.3g} σ*/η_s")
        a = first.attrs
        for stress, style in ((a["sigma_beta"], ":"), (a["sigma_alpha"], ":"),
                              (model.lower_stress, "-."), (model.upper_stress, "-.")):
            if np.isfinite(stress):
                for axis in (ax, lower):
                    axis.axvline(stress / a["sigma_star"], color="0.6", ls=style, lw=0.8)
        for k in members:
            data = datasets[k]
            name = labels[k] if labels is not None else _label(data)
            marker = MARKERS[k % len(MARKERS)]
            ax.plot(data["force_ratio"].values, data["mean_velocity"].values, marker, ms=5,
                    mfc="none", color=colours[k], label=name)
            lower.plot(data["force_ratio"].values, data["mean_velocity_error"].values,
                       marker + "-", ms=4, lw=0.8, mfc="none", color=colours[k])
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylabel("mean velocity ū [σ* L_y/η_s]")
        ax.set_title(f"φ = {key[0]:g}, φ_m = {key[1]:g}, φ_0 = {key[2]:g}, β = {key[3]:g}\n"
                     "dotted: σ_β, σ_α; dash-dotted: σ_1, σ_2 (as F H)", fontsize="medium")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize="x-small", loc="upper left")
        lower.axhline(0.0, color="0.5", lw=0.8)
        lower.set_xscale("log")
        lower.set_xlabel("driving force F H/σ* [1]")
        lower.set_ylabel("ū_SPH/ū_ODE − 1 [1]")
        lower.grid(True, alpha=0.3)
    return fig
