"""Split-force Poiseuille figure (seed 000 Fig. 2): SPH profiles for several Bingham numbers
against the numerical solution."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure


def half_channel(y, velocity, width: float) -> tuple[np.ndarray, np.ndarray]:
    """Both halves of the split-force box folded onto one channel: (X/W [1], u_x) with X the
    distance from the centre line, W the channel width [h], ``y`` heights in [0, 2W) [h].
    The upper half flows the other way (u(2W − y) = −u(y)), so its velocity is negated."""
    y, velocity = np.asarray(y, dtype=float), np.asarray(velocity, dtype=float)
    upper = y >= width
    x = np.where(upper, y - 1.5 * width, y - 0.5 * width) / width
    return x, np.where(upper, -velocity, velocity)


def plot_poiseuille(data: xr.Dataset, ax=None) -> Figure:
    """Velocity u_x/U_N against X/W for each Bingham number of ``data`` (the ``poiseuille``
    group of :func:`suspsim.stages.flows_gather.write_flows`): the numerical solution as lines,
    the SPH bin means of both halves of the box as open markers, each normalised by the
    Newtonian centre-line velocity under the run's force, U_N = F W²/(8 μ_pl), so Bn = 0 is the
    parabola of peak 1 (seed 000's normalisation by the Bn = 0 maximum). The legend gives each
    run's L2/peak error. ``ax``: draw into it, else a new Figure."""
    if ax is None:
        fig = Figure(figsize=(6.4, 4.8), layout="constrained")
        ax = fig.subplots()
    else:
        fig = ax.figure
    width = float(data.attrs["channel_width"])
    colours = colormaps["viridis"](np.linspace(0.0, 0.9, data.sizes["bingham"]))
    fine = data["y_fine"].values <= width
    for k, (bingham, colour) in enumerate(zip(data["bingham"].values, colours)):
        run = data.isel(bingham=k)
        scale = float(run["newtonian_velocity"])
        ax.plot(data["y_fine"].values[fine] / width - 0.5,
                run["reference_velocity_fine"].values[fine] / scale, "-", color=colour, lw=1.2)
        x, u = half_channel(data["y"].values, run["velocity"].values, width)
        ax.plot(x, u / scale, "o", mfc="none", color=colour, ms=4,
                label=f"Bn = {bingham:g}: L2/peak = {100 * float(run['profile_error']):.1f} %")
    ax.set_xlabel("distance from the centre line X/W [1]")
    ax.set_ylabel("velocity u_x/U_N [1] (U_N: Newtonian maximum)")
    ax.set_xlim(-0.5, 0.5)
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    # Between the Bn = 1 plateau and the flatter plugs, clear of every curve.
    ax.legend(fontsize="small", loc="center", bbox_to_anchor=(0.5, 0.37))
    dim = int(data.attrs["dimension"])
    ax.set_title(f"Split-force Poiseuille, Papanastasiou: SPH (markers, {dim}D, "
                 f"n = {data.attrs['number_density']:g}/h{'²' if dim == 2 else '³'}, "
                 f"W = {width:g} h) vs numerical (lines)", fontsize="medium")
    return fig
