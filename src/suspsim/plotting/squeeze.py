"""Squeeze-force figure: resolved SPH force between two spheres against Jeffrey–Onishi theory."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure


def plot_squeeze(datasets, *, labels=None, threshold: float = 0.9) -> Figure:
    """Two panels against the nominal gap s [h] (log axis), one colour per dataset.

    ``datasets``: outputs of :func:`suspsim.validation.squeeze.squeeze_study` (a Dataset or a
    sequence). Top: F/(6πμaU) measured (markers) and the theory with the nominal radius a, which
    the Einstein coefficient calibrates (line; dashed: the drag's hydrodynamic radius a_h).
    Bottom: F_SPH/F_theory(a) with the ``threshold`` line and each run's recommended cutoff gap
    s_c marked; open squares: the same plus the lubrication correction the run's scene applies
    (``ratio_combined``, where the dataset has it); a shaded band: the range over the lattice
    phases of a run over several (``phase_ratio_nominal``).
    ``labels``: legend entries (default: a, a_h/a, U).
    """
    if isinstance(datasets, xr.Dataset):
        datasets = [datasets]
    fig = Figure(figsize=(6.4, 7.2), layout="constrained")
    top, bottom = fig.subplots(2, 1, sharex=True)
    colours = colormaps["viridis"](np.linspace(0.0, 0.8, max(len(datasets), 1)))
    for k, (data, colour) in enumerate(zip(datasets, colours)):
        a, speed, mu = data.attrs["radius"], data.attrs["speed"], data.attrs["viscosity"]
        scale = 6.0 * np.pi * mu * a * speed
        label = (labels[k] if labels is not None else
                 f"a = {a:g} h, a_h/a = {data.attrs['hydrodynamic_radius_ratio']:.3f}, "
                 f"U = {speed:.3g}")
        gap = data["gap"].values
        top.errorbar(gap, data["force"].values / scale, yerr=data["force_error"].values / scale,
                     fmt="o", ms=3, color=colour, label=f"SPH, {label}")
        top.plot(gap, data["theory_force_nominal"].values / scale, "-", color=colour, lw=1.2)
        top.plot(gap, data["theory_force"].values / scale, "--", color=colour, lw=0.8)
        bottom.plot(gap, data["ratio_nominal"].values, "o-", ms=3, color=colour, label=label)
        if data.sizes.get("phase", 1) > 1:
            phases = data["phase_ratio_nominal"].values
            bottom.fill_between(gap, np.nanmin(phases, axis=0), np.nanmax(phases, axis=0),
                                color=colour, alpha=0.2, lw=0)
        if "ratio_combined" in data:
            bottom.plot(gap, data["ratio_combined"].values, "s--", ms=3, mfc="none",
                        color=colour, lw=0.8)
        cutoff = data.attrs.get("cutoff_gap", np.nan)
        if np.isfinite(cutoff):
            bottom.axvline(cutoff, color=colour, ls=":", lw=1)
    top.plot([], [], "k-", lw=1.2, label="Jeffrey & Onishi, nominal radius a, box images")
    top.plot([], [], "k--", lw=0.8, label="the same, radius a_h of the drag")
    top.set_xscale("log")
    top.set_yscale("log")
    top.set_ylabel("squeeze force F/(6πμaU) [1]")
    top.legend(fontsize="small")
    bottom.axhline(1.0, color="0.5", lw=0.8)
    bottom.plot([], [], "ks--", ms=3, mfc="none", lw=0.8,
                label="with the lubrication correction at the scene's cutoff")
    bottom.axhline(threshold, color="0.3", ls=":", lw=0.8, label=f"{threshold:g} × theory")
    bottom.set_xlabel("surface gap s = r − 2a [h]")
    bottom.set_ylabel("F_SPH / F_theory(a) [1]")
    bottom.legend(fontsize="small")
    return fig
