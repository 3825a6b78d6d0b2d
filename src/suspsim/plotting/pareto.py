"""Error against cost per validation case (the speed-against-error study), no file I/O."""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import xarray as xr
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

#: Colours of the swept axes (base in black); other axes cycle through the rest.
_AXIS_COLOURS = {"base": "black", "resolution": "tab:blue", "dt_coefficient": "tab:orange",
                 "wi_target": "tab:green", "kernel": "tab:red", "side": "tab:purple",
                 "width": "tab:purple", "units": "tab:brown", "transient": "tab:pink",
                 "jitter": "tab:cyan", "several": "tab:olive"}


def _axis_of(configuration: str) -> str:
    """The axis a configuration varies ("base", one axis, or "several")."""
    if configuration == "base":
        return "base"
    axes = {part.split("-", 1)[0] for part in configuration.split("+")}
    return axes.pop() if len(axes) == 1 else "several"


def plot_pareto(datasets: Sequence[xr.Dataset], *, columns: int = 3) -> Figure:
    """One log-log panel per case: error against CPU time, coloured by the axis each
    configuration varies, a bar up to the error bound (``error_bound``: + 2 standard errors),
    the Pareto front of the bound as a step line; failed configurations counted in the
    title."""
    n = len(datasets)
    cols = min(columns, n)
    rows = math.ceil(n / cols)
    fig = Figure(figsize=(4.2 * cols, 3.4 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False).ravel()
    for ax, ds in zip(axes, datasets):
        cost, error = ds["cpu_time"].values, ds["error"].values
        bound = ds["error_bound"].values
        names = [str(c) for c in ds["configuration"].values]
        groups: dict[str, list[int]] = {}
        for k, name in enumerate(names):
            groups.setdefault(_axis_of(name), []).append(k)
        for axis, members in groups.items():
            ax.errorbar(cost[members], error[members], yerr=[0 * error[members],
                        bound[members] - error[members]], fmt="o", ms=4, label=axis,
                        color=_AXIS_COLOURS.get(axis), zorder=3, elinewidth=0.8)
        front = np.flatnonzero(ds["pareto"].values == 1)
        front = front[np.argsort(cost[front])]
        if front.size:
            ax.step(cost[front], bound[front], where="post", color="0.5", lw=1, zorder=2,
                    label="Pareto front (error bound)")
        failed = int(np.sum(ds["failure"].values != ""))
        title = ds.attrs.get("description", ds.attrs.get("case", ""))
        ax.set_title(title + (f" ({failed} blew up)" if failed else ""), fontsize=9)
        ax.set_xscale("log")
        ax.set_yscale("log")
        for axis in (ax.xaxis, ax.yaxis):
            # 1-2-5 labels, so an axis spanning less than a decade still has some
            axis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
            axis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("CPU time, one thread [s]")
        ax.set_ylabel("error against the reference [1]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="best")
    for ax in axes[n:]:
        ax.set_visible(False)
    return fig
