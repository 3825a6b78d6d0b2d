"""DST channel Dataset layout and figures, on synthetic records built from the local ODE."""
import io

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from suspsim.dst import Geometry
from suspsim.dst.channel_study import (CHANNEL_VARIABLES, channel_dataset, channel_fluid,
                                       channel_sweep)
from suspsim.dst.study import STRONG_NONLOCALITY
from suspsim.errors import InputError
from suspsim.plotting.dst_channel import plot_channel_flow, plot_channel_profiles
from suspsim.reference.dst_channel import (dst_channel_fraction, dst_channel_mean_velocity,
                                           dst_channel_profile)
from suspsim.reference.inverse_biviscous import front_selected_rate

RATIOS = np.array([1.0, 6.0, 10.0, 100.0])
SETTINGS = {"protocol": "momentum", "threads": 1, "density": 1.0, "min_strain": 3.0,
            "max_strain": 12.0, "tolerance": 1e-3, "chunk_strain": 0.25}


def synthetic(offset=0.02, alpha=0.0, **fractions):
    """The layout of ``channel_sweep``: 'SPH' u = (1 + offset) u_ODE, f = f̂ on 6 rows."""
    fluid = channel_fluid(0.54, alpha, **fractions)
    law = fluid.steady_law()
    geometry = Geometry(14, 6, 1.0)
    y = (np.arange(6) + 0.5) / 6
    records = []
    for ratio in RATIOS:
        force = 2.0 * ratio
        records.append({
            "y": y, "velocity": (1 + offset) * dst_channel_profile(law, force, 1.0, y),
            "fraction": dst_channel_fraction(law, force, 1.0, y),
            "shear_rate": np.full(6, 0.01),
            "mean_velocity": (1 + offset) * dst_channel_mean_velocity(law, force, 1.0),
            "velocity_l2_error": offset, "fraction_residual": 0.0,
            "microstructure_strain": np.nan, "mean_velocity_drift": np.nan, "density": 1.0,
            "sound_speed": 1.0, "steps": 10, "simulated_time": 0.05, "reynolds_number": 1e-3,
            "mach_number": 0.01, "n_particles": 196, "wall_time": 0.5})
    return channel_dataset(fluid, geometry, RATIOS, records, SETTINGS, command="test")


def test_dataset_has_cf_metadata_and_the_references(tmp_path):
    data = synthetic()
    assert set(data.variables) == set(CHANNEL_VARIABLES)
    for name in data.variables:
        assert {"units", "long_name"} <= set(data[name].attrs), name
    assert data["wall_time"].attrs["units"] == "s"
    assert data["mean_velocity"].attrs["simulation_units"] == "sigma_star L_y eta_s-1"
    assert data["velocity"].dims == ("force_ratio", "y")
    np.testing.assert_allclose(data["mean_velocity_error"], 0.02, rtol=1e-12)
    np.testing.assert_allclose(data["velocity"], 1.02 * data["local_velocity"], rtol=1e-12)
    law = channel_fluid(0.54).steady_law()
    a = data.attrs
    assert a["critical_rate"] == front_selected_rate(law)
    assert a["lower_stress"] == pytest.approx(a["low_viscosity"] * a["critical_rate"])
    assert a["gdot_min"] < a["critical_rate"] < a["gdot_max"]
    assert a["Conventions"] == "CF-1.10" and a["completed"] == 1 and a["protocol"] == "momentum"
    assert a["wall_time_s"] == pytest.approx(2.0)
    data.to_netcdf(tmp_path / "channel.nc", engine="netcdf4")   # every attribute is writable
    with xr.open_dataset(tmp_path / "channel.nc") as back:
        assert back["steps"].dtype == np.int64 and back.attrs["phi_0"] == a["phi_0"]


def test_inverse_biviscous_columns_follow_the_attributes():
    data = synthetic()
    a = data.attrs
    # far above σ_2: ū = F H²/(3η_2) + γ̇_c (σ_2² − σ_1²)/(6 H F²) with F = 2 F H/σ*, H = 1/2
    force = 2 * 100.0
    expected = (force / 12 / a["high_viscosity"]
                + a["critical_rate"] * (a["upper_stress"] ** 2 - a["lower_stress"] ** 2)
                / (3 * force ** 2))
    assert float(data["inverse_biviscous_mean_velocity"].sel(force_ratio=100.0)) == \
        pytest.approx(expected, rel=1e-12)


def test_profiles_figure_has_a_column_per_force():
    fig = plot_channel_profiles([synthetic(), synthetic(0.05, STRONG_NONLOCALITY)])
    assert isinstance(fig, Figure)
    axes = fig.get_axes()
    assert len(axes) == 6
    assert [ax.get_title() for ax in axes[:3]] == [f"F H/σ* = {r:g}" for r in (1, 10, 100)]
    # top panels: ODE, inverse-biviscous and one marker set per dataset
    assert len(axes[0].get_lines()) == 4
    assert "2.00%, 5.00%" in axes[0].texts[0].get_text()
    fig.savefig(io.BytesIO(), format="png")


def test_flow_figure_groups_parameter_sets_into_columns():
    sets = [synthetic(), synthetic(0.05, STRONG_NONLOCALITY),
            synthetic(phi_m=0.56, phi_0=0.64)]
    fig = plot_channel_flow(sets, labels=["local", "strong", "Fig. 8 local"])
    axes = fig.get_axes()
    assert len(axes) == 4
    top_left, top_right = axes[0], axes[1]
    labels = [t.get_text() for t in top_left.get_legend().get_texts()]
    assert labels[2:] == ["local", "strong"]
    assert [t.get_text() for t in top_right.get_legend().get_texts()][2:] == ["Fig. 8 local"]
    marker = top_left.get_lines()[-1]
    np.testing.assert_allclose(marker.get_xdata(), RATIOS)
    fig.savefig(io.BytesIO(), format="png")


def test_sweep_rejects_bad_input():
    with pytest.raises(InputError, match="force_ratios"):
        channel_sweep(0.54, [1.0, -2.0])
    with pytest.raises(InputError, match="protocol"):
        channel_sweep(0.54, [1.0], protocol="fast")
    with pytest.raises(InputError, match="critical_rate"):
        channel_sweep(0.48, [1.0], lattice=(14, 6))
