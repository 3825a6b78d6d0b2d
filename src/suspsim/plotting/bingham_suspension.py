"""Seed 000 Fig. 3: a suspension of spheres in a Papanastasiou matrix over the rate x = Mγ̇."""
from __future__ import annotations

import xarray as xr
from matplotlib.figure import Figure

from ..analysis.seeds import seed_mean


def plot_bingham_suspension(data: xr.Dataset) -> Figure:
    """Two panels from the file of :mod:`suspsim.stages.bingham_suspension_gather`.

    (a) As seed 000 plots it: viscosity over the matrix's plastic (infinite-rate) viscosity
    against x, the matrix law μ_m/μ_pl as a line and the suspension η/μ_pl as points with
    their errors (seed mean, :func:`~suspsim.analysis.seeds.seed_mean`).
    (b) η/μ_m(γ̇) against x with the Chateau–Ovarlez–Trung estimate (line, band from g ± its
    error) and the Newtonian g (horizontal line, its error shaded).
    """
    fig = Figure(figsize=(11, 4.4), layout="constrained")
    ax_a, ax_b = fig.subplots(1, 2)
    x, fine = data["rate"].values, data["rate_fine"].values
    ax_a.plot(fine, data["matrix_plastic_ratio_fine"].values, "-", color="k", lw=1.5,
              label="matrix μ_m/μ_pl (Papanastasiou)")
    mean, error = seed_mean(data, "plastic_relative_viscosity")
    ax_a.errorbar(x, mean.values, yerr=error.values, fmt="o", color="C0", capsize=3,
                  label=f"suspension η/μ_pl, φ = {data.attrs['volume_fraction']:g}")
    ax_a.set(xscale="log", yscale="log", xlabel="dimensionless shear rate x = Mγ̇ [1]",
             ylabel="viscosity / μ_pl [1]",
             title=f"(a) μ_0/μ_pl = {data.attrs['viscosity_ratio']:g}")
    g = float(data["newtonian_relative_viscosity_mean"])
    g_err = float(data["newtonian_relative_viscosity_mean_stderr"])
    ax_b.axhspan(g - g_err, g + g_err, color="0.5", alpha=0.25, lw=0)
    ax_b.axhline(g, color="0.3", ls="--", lw=1.2, label=f"Newtonian matrix g = {g:.3g} ± "
                                                      f"{g_err:.2g}")
    ax_b.fill_between(fine, data["cot_relative_viscosity_fine_low"].values,
                      data["cot_relative_viscosity_fine_high"].values, color="C1", alpha=0.3,
                      lw=0)
    ax_b.plot(fine, data["cot_relative_viscosity_fine"].values, "-", color="C1", lw=1.5,
              label="Chateau–Ovarlez–Trung g μ_m(γ̇√(g/(1−φ)))/μ_m(γ̇)")
    mean, error = seed_mean(data, "relative_viscosity")
    ax_b.errorbar(x, mean.values, yerr=error.values, fmt="o", color="C0", capsize=3,
                  label="SPH η/μ_m(γ̇)")
    ax_b.set(xscale="log", xlabel="dimensionless shear rate x = Mγ̇ [1]",
             ylabel="relative viscosity η/μ_m(γ̇) [1]", title="(b) against the matrix at the "
                                                              "same rate")
    ax_b.set_ylim(bottom=0.0)
    for ax in (ax_a, ax_b):
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=8)
    return fig
