"""Couette start-up figure (seed 000 Fig. 1): SPH velocity profiles against the 1D reference."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure

from suspsim.validation.startup import profile_error


def plot_startup(data: xr.Dataset, ax=None) -> Figure:
    """Velocity v_x/(γ̇ L) against the distance X/L from the zero-velocity plane, per strain.

    ``data`` is the output of :func:`suspsim.validation.startup.papanastasiou_startup`: SPH
    bin means as markers, the 1D finite-volume reference as lines of the same colour, the
    steady linear profile dotted. As in seed 000 Fig. 1 the velocity is normalised by the
    velocity difference across the box, V = γ̇ L; the legend gives each strain's largest
    SPH − 1D difference (:func:`~suspsim.validation.startup.profile_error`). ``ax``: draw
    into it, else a new Figure.
    """
    if ax is None:
        fig = Figure(figsize=(6.4, 4.8), layout="constrained")
        ax = fig.subplots()
    else:
        fig = ax.figure
    side, rate = data.attrs["box_side"], data.attrs["shear_rate"]
    scale = rate * side
    x = data["y"].values / side - 0.5
    x_fine = data["y_fine"].values / side - 0.5
    errors = profile_error(data).values
    colours = colormaps["viridis"](np.linspace(0.0, 0.9, data.sizes["strain"]))
    ax.plot([-0.5, 0.5], [-0.5, 0.5], ":", color="0.5", lw=1, label="steady (linear)")
    for k, (strain, colour) in enumerate(zip(data["strain"].values, colours)):
        ax.plot(x_fine, data["reference_velocity_fine"].values[k] / scale, "-", color=colour,
                lw=1.2)
        ax.plot(x, data["velocity"].values[k] / scale, "o", color=colour, ms=4,
                label=f"γ̇t = {strain:.2g}: max |Δv|/(γ̇L) = {errors[k]:.3f}")
    ax.set_xlabel("distance from the zero-velocity plane X/L [1]")
    ax.set_ylabel("velocity v_x/(γ̇ L) [1]")
    ax.set_xlim(-0.5, 0.5)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", loc="upper left")
    ax.set_title(f"Papanastasiou start-up, Bn = {data.attrs['bingham_number']:g}: SPH (markers, "
                 f"n = {data.attrs['number_density']:g}/h³, L = {side:g} h) vs 1D (lines)",
                 fontsize="medium")
    return fig
