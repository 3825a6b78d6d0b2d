"""DST flow-curve Dataset layout and figure, on synthetic records built from the steady law."""
import io
import math

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from suspsim.dst import Geometry, WyartCatesFluid
from suspsim.dst.study import (FLOW_CURVE_VARIABLES, SEED_002, STRONG_NONLOCALITY,
                               flow_curve_dataset, spanning_stresses)
from suspsim.errors import InputError
from suspsim.plotting.dst import plot_flow_curves

SETTINGS = {"epsilon": 0.1, "equilibration_strain": 1.5, "averaging_strain": 1.5,
            "samples": 16, "n_blocks": 8, "threads": 1}


def fluid(phi):
    return WyartCatesFluid(eta_s=1.0, phi=phi, sigma_star=1.0, alpha=STRONG_NONLOCALITY,
                           **SEED_002)


def synthetic(phi, count=6, offset=0.02):
    """The layout of ``flow_curve``: 'SPH' γ̇ = (1 + offset) γ̇_WC, ⟨σ⟩ = σ_in."""
    f = fluid(phi)
    stresses = spanning_stresses(f, count)
    records = []
    for s in stresses:
        rate = f.shear_rate(s)
        records.append({"shear_rate": (1 + offset) * rate, "shear_rate_stderr": 0.01 * rate,
                        "wall_shear_rate": rate, "wall_shear_rate_stderr": 0.01 * rate,
                        "measured_stress": s, "measured_stress_stderr": 0.01 * s,
                        "frictional_fraction": f.frictional_fraction(s), "steps": 10,
                        "wall_time": 0.5, "n_particles": 392})
    return flow_curve_dataset(f, Geometry(14, 20, 1.0), stresses, records, SETTINGS,
                              command="test")


def test_dataset_has_cf_metadata_and_the_steady_law(tmp_path):
    data = synthetic(0.54)
    assert set(data.variables) == set(FLOW_CURVE_VARIABLES)
    for name in data.variables:
        assert {"units", "long_name"} <= set(data[name].attrs), name
    assert data["wall_time"].attrs["units"] == "s"
    assert data["shear_rate"].attrs["simulation_units"] == "sigma_star eta_s-1"
    expected = [fluid(0.54).shear_rate(s) for s in data["stress"].values]
    np.testing.assert_allclose(data["wyart_cates_shear_rate"].values, expected, rtol=1e-12)
    a = data.attrs
    assert a["Conventions"] == "CF-1.10" and a["regime"] == "DST" and a["completed"] == 1
    assert a["sigma_beta"] < a["sigma_alpha"] and a["wall_time_s"] == pytest.approx(3.0)
    assert a["alpha"] == STRONG_NONLOCALITY and a["n_y"] == 20
    assert math.isnan(synthetic(0.48).attrs["sigma_alpha"])
    data.to_netcdf(tmp_path / "curve.nc", engine="netcdf4")  # every attribute is writable
    with xr.open_dataset(tmp_path / "curve.nc") as back:
        assert back["steps"].dtype == np.int64 and back.attrs["sigma_beta"] == a["sigma_beta"]


def test_spanning_stresses_cross_both_turning_points():
    for phi in (0.50, 0.54):
        turning = fluid(phi).steady_law().turning_points()
        stresses = spanning_stresses(fluid(phi), 12)
        assert stresses.size == 12 and np.all(np.diff(stresses) > 0)
        inside = (stresses > turning.sigma_beta) & (stresses < turning.sigma_alpha)
        assert inside.sum() == 4 and stresses[0] == pytest.approx(0.2)
        assert stresses[-1] == pytest.approx(40.0)
    np.testing.assert_allclose(spanning_stresses(fluid(0.48), 5), np.geomspace(0.2, 40, 5))
    with pytest.raises(InputError):
        spanning_stresses(fluid(0.5), 2)


def test_plot_flow_curves_draws_points_curves_and_turning_points():
    datasets = [synthetic(phi) for phi in (0.48, 0.50, 0.54)]
    fig = plot_flow_curves(datasets)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    ax, lower = fig.axes
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    # One errorbar set per phi, at the measured (gdot, sigma).
    assert len(ax.containers) == 3
    for container, data in zip(ax.containers, datasets):
        np.testing.assert_allclose(container.lines[0].get_xdata(), data["shear_rate"].values)
        np.testing.assert_allclose(container.lines[0].get_ydata(),
                                   data["measured_stress"].values)
    colours = {tuple(c.lines[0].get_color()) for c in ax.containers}
    assert len(colours) == 3
    # Turning points: none for CST, two for each DST curve, at the law's values.
    markers = [line for line in ax.get_lines() if line.get_marker() == "^" and
               len(line.get_xdata()) == 1]
    expected = []
    for data in datasets[1:]:
        turning = fluid(data.attrs["phi"]).steady_law().turning_points()
        expected += [(turning.gdot_max, turning.sigma_beta), (turning.gdot_min,
                                                             turning.sigma_alpha)]
    got = [(float(m.get_xdata()[0]), float(m.get_ydata()[0])) for m in markers]
    np.testing.assert_allclose(sorted(got), sorted(expected), rtol=1e-12)
    # The S-curve is parametric in sigma: gdot(sigma) along each solid+dashed pair.
    curve = next(line for line in ax.get_lines() if line.get_linestyle() == "-"
                 and len(line.get_xdata()) > 100)
    sigma, rate = np.asarray(curve.get_ydata()), np.asarray(curve.get_xdata())
    finite = np.isfinite(rate)
    np.testing.assert_allclose(rate[finite], [fluid(0.48).shear_rate(s) for s in sigma[finite]],
                               rtol=1e-12)
    # Residual panel: gdot/gdot_WC - 1 = the synthetic offset.
    for container in lower.containers:
        np.testing.assert_allclose(container.lines[0].get_ydata(), 0.02, rtol=1e-9)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "φ = 0.54 (DST)" in labels and "φ = 0.48 (CST)" in labels
    fig.savefig(io.BytesIO(), format="png")
    single = plot_flow_curves(datasets[2], residuals=False)
    assert len(single.axes) == 1


def test_branch_split_figure_and_input_checks():
    """plot_branch_split draws a synthetic stress_splitting Dataset; stresses outside the
    unstable range and a CST φ are rejected before any run."""
    from suspsim.dst.study import SPLITTING_VARIABLES, stress_splitting
    from suspsim.plotting.dst import plot_branch_split

    f = fluid(0.54)
    law = f.steady_law()
    tp = law.turning_points()
    stresses = np.array([1.2, 2.0, 3.0])
    rate = 0.8 * law.shear_rate(stresses)
    lever = law.lever_rule(stresses, rate)
    values = {name: np.full(3, 0.01) for name in SPLITTING_VARIABLES if name != "stress"}
    values.update(q=(stresses - tp.sigma_beta) / (tp.sigma_alpha - tp.sigma_beta),
                  psi1=lever, psi2=1 - lever - 0.02, psi_sum=np.full(3, 0.98),
                  lever_rule=lever)
    base = synthetic(0.54)
    data = xr.Dataset({k: ("stress", v) for k, v in values.items()},
                      coords={"stress": stresses}, attrs=base.attrs)
    fig = plot_branch_split(data)
    assert isinstance(fig, Figure)
    fig.savefig(io.BytesIO(), format="png")
    with pytest.raises(InputError):
        stress_splitting(0.54, [0.5])
    with pytest.raises(InputError):
        stress_splitting(0.48, [1.0])
