"""The ``dst`` study's figures from ``flow_curves.nc`` (:mod:`suspsim.stages.dst_gather`).

* ``flow_curves``: one column per non-locality, every φ's domain averages (⟨γ̇⟩, ⟨σ⟩) over
  its steady Wyart–Cates curve, residuals ⟨γ̇⟩/γ̇_WC − 1 below (seed 002 Fig. 3; drawn by
  :func:`suspsim.plotting.dst.draw_flow_curves` from :func:`flow_curve_view`);
* ``particles``: the particle scatter of one run per non-locality (Fig. 4 d–f,
  :func:`suspsim.plotting.dst.plot_particle_scatter`);
* ``splitting``: ψ1, ψ2 against q with the lever rule at zero non-locality (Fig. 5,
  :func:`suspsim.plotting.dst.plot_branch_split` on :func:`splitting_view`);
* ``bands``: the f fields and the correlation length (Fig. 4 g–i,
  :func:`suspsim.plotting.dst.plot_bands`).

The particle, band and splitting figures take the configured φ and the imposed stress of that φ
nearest (in log) to the configured stress (:func:`figure_point`).
"""
from __future__ import annotations

import logging
import os
from typing import Mapping

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from ..errors import InputError
from ..io.atomic import save_figure
from ..plotting.dst import draw_flow_curves, plot_bands, plot_branch_split, plot_particle_scatter

log = logging.getLogger(__name__)

#: The non-locality of the splitting figure (seed 002 Fig. 5: the local model).
SPLITTING_NONLOCALITY_ALPHA = 0.0
#: Fluid attributes a flow-curve view carries (suspsim.plotting.dst.steady_law).
_FLUID = ("eta_s", "phi_m", "phi_0", "sigma_star", "beta")


def figure_point(data: xr.Dataset, phi: float, stress: float) -> tuple[float, int]:
    """(φ, stress index) of the figures: ``phi`` (must be a study φ) and the index of the
    imposed stress nearest to ``stress`` in log. InputError when ``phi`` is not studied."""
    phis = data["phi"].values
    match = np.nonzero(np.isclose(phis, phi, rtol=1e-9, atol=0.0))[0]
    if match.size == 0:
        raise InputError("dst.figure.phi", f"phi = {phi} is not one of the study's volume "
                         f"fractions {phis.tolist()}", key="phi")
    chosen = float(phis[match[0]])
    stresses = data["imposed_stress"].sel(phi=chosen).values
    return chosen, int(np.nanargmin(np.abs(np.log(stresses / stress))))


def flow_curve_view(data: xr.Dataset, phi: float, nonlocality: str) -> xr.Dataset:
    """One flow curve (φ, non-locality) of the gathered study in the layout of
    :func:`suspsim.dst.study.flow_curve` (dimension ``stress``, the fluid as attributes)."""
    curve = data.sel(phi=phi, nonlocality=nonlocality)
    names = ("shear_rate", "shear_rate_stderr", "measured_stress", "measured_stress_stderr",
             "wyart_cates_shear_rate", "q", "psi1", "psi1_stderr", "psi2", "psi2_stderr",
             "psi_sum", "lever_rule", "wall_shear_rate")
    view = xr.Dataset({name: ("stress", curve[name].values, curve[name].attrs)
                       for name in names},
                      coords={"stress": ("stress", curve["imposed_stress"].values,
                                         curve["imposed_stress"].attrs)})
    view.attrs = {**{k: data.attrs[k] for k in _FLUID}, "phi": float(phi),
                  "alpha": float(curve["alpha"]), "n_x": data.attrs["n_x"],
                  "n_y": data.attrs["n_y"]}
    return view


def splitting_view(data: xr.Dataset, phi: float) -> xr.Dataset:
    """The zero-non-locality runs of ``phi`` on its unstable branch (0 < q < 1), for
    :func:`suspsim.plotting.dst.plot_branch_split`. InputError without such runs."""
    local = [str(n) for n, a in zip(data["nonlocality"].values, data["alpha"].values)
             if a == SPLITTING_NONLOCALITY_ALPHA]
    if not local:
        raise InputError("dst.nonlocalities", "the splitting figure needs a non-locality with "
                         "alpha = 0 (zero)", key="nonlocalities")
    view = flow_curve_view(data, phi, local[0])
    view = view.isel(stress=np.nonzero((view["q"].values > 0) & (view["q"].values < 1))[0])
    if view.sizes["stress"] == 0:
        raise InputError("dst.figure.phi", f"phi = {phi} has no imposed stress on an unstable "
                         "branch: choose a DST volume fraction", key="phi")
    return view


def plot_flow_curve_grid(data: xr.Dataset) -> Figure:
    """Flow curves, one column per non-locality, every φ in each (module docstring)."""
    names = [str(n) for n in data["nonlocality"].values]
    fig = Figure(figsize=(5.0 * len(names), 7.2), layout="constrained")
    axes = fig.subplots(2, len(names), height_ratios=(3, 1), squeeze=False)
    for k, name in enumerate(names):
        views = [flow_curve_view(data, float(phi), name) for phi in data["phi"].values]
        alpha = float(data["alpha"].sel(nonlocality=name))
        draw_flow_curves(axes[0, k], axes[1, k], views,
                         title=f"{name} non-locality, α = {alpha:g} L_y²σ*/η_s")
    fig.suptitle(f"Stress-controlled 2D SPH (markers) vs steady Wyart–Cates (lines), "
                 f"{data.attrs['n_x']} × {data.attrs['n_y']} particles", fontsize="medium")
    return fig


def write_dst_figures(flow_curves_nc: str | os.PathLike, outputs: Mapping[str, str], *,
                      phi: float, stress: float) -> None:
    """Draw the figures named in ``outputs`` (keys ``flow_curves``, ``particles``,
    ``splitting``, ``bands`` -> paths) and save each atomically."""
    try:
        data = xr.load_dataset(flow_curves_nc)
    except (OSError, ValueError) as err:
        raise InputError(str(flow_curves_nc), f"cannot read the flow curves: {err}") from err
    chosen, index = figure_point(data, phi, stress)
    log.info("figures at phi %g, sigma_in %.4g (index %d)", chosen,
             float(data["imposed_stress"].sel(phi=chosen)[index]), index)
    draw = {"flow_curves": lambda: plot_flow_curve_grid(data),
            "particles": lambda: plot_particle_scatter(data, chosen, index),
            "splitting": lambda: plot_branch_split(splitting_view(data, chosen)),
            "bands": lambda: plot_bands(data, chosen, index)}
    for name, path in outputs.items():
        if name not in draw:
            raise ValueError(f"unknown dst figure {name!r}; known: {', '.join(draw)}")
        save_figure(draw[name](), path)
        log.info("wrote %s", path)
