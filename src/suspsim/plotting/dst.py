"""DST flow-curve figure: stress-controlled SPH points against the steady Wyart–Cates S-curve."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib import colormaps
from matplotlib.figure import Figure

from suspsim.rheology.wyart_cates import WyartCates

#: Points of each parametric S-curve.
CURVE_POINTS = 400


def steady_law(data: xr.Dataset) -> WyartCates:
    """The steady law of a flow-curve Dataset, from its attributes."""
    a = data.attrs
    return WyartCates(a["eta_s"], a["phi"], a["phi_m"], a["phi_0"], a["sigma_star"], a["beta"])


def plot_flow_curves(datasets, *, labels=None, residuals: bool = True) -> Figure:
    """σ against γ̇ (log–log), one colour per dataset (one φ each).

    ``datasets``: outputs of :func:`suspsim.dst.study.flow_curve` (a Dataset or a sequence).
    Lines: the steady Wyart–Cates curve γ̇(σ) drawn parametrically in σ over the stresses of
    the data (a factor 1.5 beyond each end), dashed where it is unstable
    (d ln γ̇/d ln σ < 0); open triangles: its turning points (σ_β, γ̇_max) and
    (σ_α, γ̇_min) (none for CST; σ_α is left out where γ̇_min = 0, φ ≥ φ_m). Markers:
    measured domain averages (⟨γ̇⟩, ⟨σ⟩) with standard-error bars. With ``residuals`` a lower
    panel shows ⟨γ̇⟩/γ̇_WC(σ_in) − 1 against the imposed stress, dotted lines at the turning
    stresses. ``labels``: legend entries (default φ and the regime). No file I/O.
    """
    if isinstance(datasets, xr.Dataset):
        datasets = [datasets]
    if residuals:
        fig = Figure(figsize=(6.4, 7.2), layout="constrained")
        ax, lower = fig.subplots(2, 1, height_ratios=(3, 1))
    else:
        fig = Figure(figsize=(6.4, 5.2), layout="constrained")
        ax, lower = fig.subplots(), None
    draw_flow_curves(ax, lower, datasets, labels=labels)
    return fig


def draw_flow_curves(ax, lower, datasets, *, labels=None, title: str | None = None) -> None:
    """Draw :func:`plot_flow_curves` into ``ax`` (and the residuals into ``lower`` unless None).

    ``title`` replaces the default title (which names the non-localities α of the data).
    """
    colours = [colormaps["tab10"](k % 10) for k in range(len(datasets))]
    for k, (data, colour) in enumerate(zip(datasets, colours)):
        law = steady_law(data)
        stress = data["stress"].values
        label = (labels[k] if labels is not None
                 else f"φ = {data.attrs['phi']:.2f} ({data.attrs.get('regime', law.regime())})")
        sigma = np.geomspace(stress.min() / 1.5, stress.max() * 1.5, CURVE_POINTS)
        rate = np.asarray(law.shear_rate(sigma), dtype=float)
        with np.errstate(invalid="ignore"):
            unstable = np.asarray(law.log_slope(sigma)) < 0
        stable_rate = np.where(unstable, np.nan, rate)
        unstable_rate = np.where(unstable | np.roll(unstable, 1) | np.roll(unstable, -1),
                                 rate, np.nan)
        ax.plot(stable_rate, sigma, "-", color=colour, lw=1.3)
        ax.plot(unstable_rate, sigma, "--", color=colour, lw=1.1)
        turning = law.turning_points()
        if turning is not None:
            for s, g in ((turning.sigma_beta, turning.gdot_max),
                         (turning.sigma_alpha, turning.gdot_min)):
                if np.isfinite(s) and g > 0:
                    ax.plot(g, s, "^", ms=8, mfc="none", mec=colour, mew=1.3)
                if np.isfinite(s) and lower is not None:
                    lower.axvline(s, color=colour, ls=":", lw=0.9)
        ax.errorbar(data["shear_rate"].values, data["measured_stress"].values,
                    xerr=_values(data, "shear_rate_stderr"),
                    yerr=_values(data, "measured_stress_stderr"), fmt="o", ms=4,
                    color=colour, capsize=2, label=label)
        if lower is not None:
            reference = data["wyart_cates_shear_rate"].values
            error = _values(data, "shear_rate_stderr")
            lower.errorbar(stress, data["shear_rate"].values / reference - 1.0,
                           yerr=None if error is None else error / reference, fmt="o-",
                           ms=4, lw=0.8, color=colour, capsize=2)
    ax.plot([], [], "k-", lw=1.3, label="Wyart–Cates, stable")
    ax.plot([], [], "k--", lw=1.1, label="Wyart–Cates, unstable (dlnγ̇/dlnσ < 0)")
    ax.plot([], [], "k^", ms=8, mfc="none", label="turning points σ_β, σ_α")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("shear rate ⟨γ̇⟩ [σ*/η_s]")
    ax.set_ylabel("shear stress ⟨σ⟩ [σ*]")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize="small", loc="lower right")
    alphas = sorted({float(d.attrs["alpha"]) for d in datasets})
    ax.set_title(title or ("Stress-controlled 2D SPH (markers) vs steady Wyart–Cates (lines)\n"
                           "non-locality α = " + ", ".join(f"{a:g}" for a in alphas)
                           + " L_y²σ*/η_s"), fontsize="medium")
    if lower is not None:
        lower.axhline(0.0, color="0.5", lw=0.8)
        lower.set_xscale("log")
        lower.set_xlabel("imposed stress σ_in [σ*]")
        lower.set_ylabel("⟨γ̇⟩/γ̇_WC(σ_in) − 1 [1]")
        lower.set_title("relative deviation (dotted: turning points)", fontsize="small")
        lower.grid(True, alpha=0.3)


def _values(data: xr.Dataset, name: str) -> np.ndarray | None:
    """The variable's values, or None (no error bars) when the Dataset lacks it."""
    return data[name].values if name in data else None


def plot_branch_split(data: xr.Dataset) -> Figure:
    """Branch shares ψ1 (circles) and ψ2 (triangles) against q, with the lever rule (Fig. 5).

    ``data``: output of :func:`suspsim.dst.study.stress_splitting`. Lines: the vertical-split
    lever rule at the Wyart–Cates rate γ̇_WC(σ_in) (seed 002's Fig. 5 prediction), ψ1 solid
    and ψ2 = 1 − ψ1 dashed, drawn over 0 < q < 1. Open squares: the lever rule at the measured
    common rate V_w/L_y of each run. Markers with batch-means error bars: the measured ψ1, ψ2;
    crosses: ψ1 + ψ2. No file I/O.
    """
    law = steady_law(data)
    turning = law.turning_points()
    sb, sa = turning.sigma_beta, turning.sigma_alpha
    q_line = np.linspace(0.005, 0.995, CURVE_POINTS)
    sigma = sb + q_line * (sa - sb)
    lever = np.asarray(law.lever_rule(sigma, np.asarray(law.shear_rate(sigma))), dtype=float)
    fig = Figure(figsize=(6.4, 4.8), layout="constrained")
    ax = fig.subplots()
    ax.plot(q_line, lever, "k-", lw=1.2, label="lever rule at γ̇_WC(σ_in): ψ1")
    ax.plot(q_line, 1.0 - lever, "k--", lw=1.2, label="lever rule at γ̇_WC(σ_in): ψ2 = 1 − ψ1")
    q = data["q"].values
    ax.plot(q, data["lever_rule"].values, "s", ms=7, mfc="none", mec="tab:red",
            label="lever rule at measured V_w/L_y: ψ1")
    ax.errorbar(q, data["psi1"].values, yerr=_values(data, "psi1_stderr"), fmt="o",
                color="k", ms=5, capsize=2, label="SPH ψ1 (σ_i < σ_β)")
    ax.errorbar(q, data["psi2"].values, yerr=_values(data, "psi2_stderr"), fmt="^",
                color="k", ms=5, capsize=2, label="SPH ψ2 (σ_i > σ_α)")
    ax.plot(q, data["psi_sum"].values, "x", color="0.4", ms=6, label="SPH ψ1 + ψ2")
    ax.set_xlim(0.0, 1.0)
    ax.set_ylim(0.0, 1.05)
    ax.set_xlabel("q = (σ_in − σ_β)/(σ_α − σ_β) [1]")
    ax.set_ylabel("branch share [1]")
    a = data.attrs
    ax.set_title(f"Stress splitting, local model (α = {a['alpha']:g}), φ = {a['phi']:.2f}, "
                 f"{a['n_x']} × {a['n_y']} particles", fontsize="medium")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="small", loc="center left")
    return fig


# ------------------------------------------------------------------ the dst study's figures
def _curve(ax, data: xr.Dataset, phi: float) -> None:
    """The steady Wyart–Cates curve of ``phi`` from a gathered study (solid stable, dashed
    unstable) and its turning stresses (dotted)."""
    rate = data["curve_shear_rate"].sel(phi=phi).values
    sigma = data["curve_stress"].values
    unstable = data["curve_log_slope"].sel(phi=phi).values < 0
    ax.plot(np.where(unstable, np.nan, rate), sigma, "k-", lw=1.2, label="Wyart–Cates, stable")
    ax.plot(np.where(unstable | np.roll(unstable, 1) | np.roll(unstable, -1), rate, np.nan),
            sigma, "k--", lw=1.0, label="Wyart–Cates, unstable")
    for name in ("sigma_beta", "sigma_alpha"):
        value = float(data[name].sel(phi=phi))
        if np.isfinite(value):
            ax.axhline(value, color="0.5", ls=":", lw=0.8)


def plot_particle_scatter(data: xr.Dataset, phi: float, index: int) -> Figure:
    """Every particle's (γ̇_i, σ_i) over the steady curve, one panel per non-locality (seed 002
    Fig. 4 d–f).

    ``data``: the gathered dst study (:func:`suspsim.stages.dst_gather.gather_flow_curves`);
    the run at ``phi`` and stress index ``index``. Dots: the final snapshot's particles,
    coloured by f; star: that run's domain average (⟨γ̇⟩, ⟨σ⟩); open circles: the domain
    averages of the other stresses of ``phi``; dotted: σ_β, σ_α. Log–log (particles with
    γ̇_i = 0 or σ_i = 0 are left out). No file I/O.
    """
    names = list(data["nonlocality"].values)
    fig = Figure(figsize=(4.2 * len(names) + 0.8, 4.4), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(names), sharex=True, sharey=True))
    point = data.sel(phi=phi).isel(stress_index=index)
    dots = None
    for ax, name in zip(axes, names):
        run = point.sel(nonlocality=name)
        _curve(ax, data, phi)
        rate, sigma = run["particle_shear_rate"].values, run["particle_stress"].values
        keep = (rate > 0) & (sigma > 0)
        dots = ax.scatter(rate[keep], sigma[keep], c=run["particle_frictional_fraction"].values[
            keep], s=7, cmap="viridis", vmin=0.0, vmax=1.0, label="particles (final snapshot)")
        curve = data.sel(phi=phi, nonlocality=name)
        ax.plot(curve["shear_rate"].values, curve["measured_stress"].values, "o", ms=5,
                mfc="none", mec="tab:blue", label="domain averages, all σ_in")
        ax.plot(float(run["shear_rate"]), float(run["measured_stress"]), "*", ms=14,
                color="tab:red", mec="k", label="domain average, this run")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.grid(True, alpha=0.3)
        ax.set_xlabel("shear rate γ̇ [σ*/η_s]")
        ax.set_title(f"{name} (α = {float(run['alpha']):g}): ψ1 = {float(run['psi1']):.2f}, "
                     f"ψ2 = {float(run['psi2']):.2f}", fontsize="medium")
    axes[0].set_ylabel("shear stress σ [σ*]")
    axes[0].legend(fontsize="x-small", loc="upper left")
    fig.colorbar(dots, ax=list(axes), label="frictional fraction f [1]", shrink=0.9)
    fig.suptitle(f"Particles over the flow curve, φ = {phi:.2f}, σ_in = "
                 f"{float(point['imposed_stress']):.3g} σ*", fontsize="medium")
    return fig


def plot_bands(data: xr.Dataset, phi: float, index: int) -> Figure:
    """The f field of the final snapshot per non-locality (seed 002 Fig. 4 g–i) and the band
    criterion against the imposed stress.

    Top row: f(x, y) at ``phi`` and stress index ``index``, one square per particle (x periodic
    over L_x, walls at y = 0 and 1), each panel with its own colour range, titled with the
    correlation length ξ in lattice spacings Δx and the spread of f — from the band runs
    (``band_*``, their own lattice) when ``data`` has them, else from the study's runs. Bottom:
    ξ/Δx of every study run at ``phi`` against σ_in, one line per non-locality, the band runs'
    ξ as stars, the unstable range σ_β < σ_in < σ_α shaded
    (:func:`suspsim.stages.dst_gather.correlation_length`). No file I/O.
    """
    spacing = 1.0 / int(data.attrs["n_y"])
    banded = "band_nonlocality" in data.coords
    if banded:
        names = [str(n) for n in data["band_nonlocality"].values]
        lattice = (data.attrs["band_n_x"], data.attrs["band_n_y"])
        band_spacing = 1.0 / int(lattice[1])
        fields = [{key: data[f"band_{key}"].sel(band_nonlocality=name).values
                   for key in ("particle_x", "particle_y", "particle_frictional_fraction",
                               "correlation_length", "frictional_fraction_spread")}
                  for name in names]
        stress = float(data["band_stress"])
    else:
        names = [str(n) for n in data["nonlocality"].values]
        lattice, band_spacing = (data.attrs["n_x"], data.attrs["n_y"]), spacing
        point = data.sel(phi=phi).isel(stress_index=index)
        fields = [{key: point[key].sel(nonlocality=name).values
                   for key in ("particle_x", "particle_y", "particle_frictional_fraction",
                               "correlation_length", "frictional_fraction_spread")}
                  for name in names]
        stress = float(point["imposed_stress"])
    fig = Figure(figsize=(max(4.2 * len(names), 9.0), 7.6), layout="constrained")
    grid = fig.add_gridspec(2, len(names), height_ratios=(1.3, 1))
    for k, (name, field) in enumerate(zip(names, fields)):
        ax = fig.add_subplot(grid[0, k])
        dots = ax.scatter(field["particle_x"], field["particle_y"],
                          c=field["particle_frictional_fraction"], cmap="viridis", marker="s",
                          s=max(4.0, 2000.0 / field["particle_x"].size))
        fig.colorbar(dots, ax=ax, label="f [1]", shrink=0.8)
        ax.set_aspect("equal")
        ax.set_ylim(0.0, 1.0)
        ax.set_xlabel("x [L_y]")
        ax.set_ylabel("y [L_y]")
        alpha = float(data["alpha"].sel(nonlocality=name))
        ax.set_title(f"{name} (α = {alpha:g}): ξ = "
                     f"{float(field['correlation_length']) / band_spacing:.2f} Δx\n"
                     f"std f = {float(field['frictional_fraction_spread']):.3f}",
                     fontsize="medium")
    lower = fig.add_subplot(grid[1, :])
    curves = data.sel(phi=phi)
    colours = {}
    for name in data["nonlocality"].values:
        curve = curves.sel(nonlocality=name)
        line, = lower.plot(curve["imposed_stress"].values,
                           curve["correlation_length"].values / spacing, "o-", ms=4,
                           label=f"{name}, {data.attrs['n_x']} × {data.attrs['n_y']}")
        colours[str(name)] = line.get_color()
    if banded:
        for name, field in zip(names, fields):
            lower.plot(stress, float(field["correlation_length"]) / band_spacing, "*", ms=13,
                       mec="k", color=colours.get(name, "k"),
                       label=f"{name}, {lattice[0]} × {lattice[1]} (band run)")
    sb, sa = float(data["sigma_beta"].sel(phi=phi)), float(data["sigma_alpha"].sel(phi=phi))
    if np.isfinite(sb) and np.isfinite(sa):
        lower.axvspan(sb, sa, color="0.9", label="unstable branch σ_β < σ_in < σ_α")
    lower.axvline(stress, color="tab:red", ls=":", lw=1.0, label="the runs above")
    lower.set_xscale("log")
    lower.set_xlabel("imposed stress σ_in [σ*]")
    lower.set_ylabel("correlation length ξ of f [Δx]")
    lower.grid(True, alpha=0.3)
    lower.legend(fontsize="x-small", ncol=2)
    fig.suptitle(f"Microstructure f at φ = {phi:.2f}, σ_in = {stress:.3g} σ*, "
                 f"{lattice[0]} × {lattice[1]} particles", fontsize="medium")
    return fig
