"""Gathering run files into summary.nc, and the summary figure, on synthetic runs (no SPH)."""
import json

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

from suspsim.errors import InputError
from suspsim.io.study_variables import STUDY_VARIABLES, SUMMARY_DIMS
from suspsim.plotting.shapes import plot_shape_comparison, shape_ratio
from suspsim.analysis.seeds import seed_mean
from suspsim.plotting.summary import plot_relative_viscosity_vs_phi, plot_summary, plot_viscosity
from suspsim.rheology.laws import make_law
from suspsim.stages.gather import gather_runs, write_summary
from suspsim.stages.homogenisation import homogenisation_estimate
from suspsim.stages.pack import Particles
from suspsim.stages.simulate import Resolution, simulation_scene, with_physical_results
from suspsim.stages.summary_figure import estimate_by_phi

FIT = {"law": "cross", "params": {"mu_0": 50.0, "mu_inf": 0.02, "lam": 2.5, "m": 0.8},
       "source": "synthetic"}
LAW = make_law(FIT["law"], FIT["params"])
RESOLUTION = Resolution(box=5, number_density=4.096, strain=10, transient=2)


def fake_run(rate, seed, factor=1.0, stderr=0.002, phi=0.0, fit=FIT):
    """A run dataset whose simulated viscosity is ``factor`` × the law at the simulated rate."""
    scene, mapping = simulation_scene(LAW, rate, volume_fraction=0.0, seed=seed,
                                      resolution=RESOLUTION)
    mu_sim = float(scene.fluid.law.viscosity(mapping.simulation_shear_rate))
    run = xr.Dataset({"viscosity": ((), factor * mu_sim),
                      "viscosity_stderr": ((), stderr * mu_sim)},
                     attrs={"mach_number": 1e-3, "wall_time_s": 12.0, "n_particles": 512,
                            "reynolds_number": 0.6})
    out = with_physical_results(run, mapping, scene=scene, volume_fraction=0.0, seed=seed,
                                resolution=RESOLUTION, fit=fit)
    return out.assign_coords(phi=out["phi"] * 0 + phi) if phi else out


def fake_suspension_run(rate, seed, phi, factor, particles=Particles(radius=1.0)):
    """A run at φ > 0 as run_scene writes it: its own φ and viscosities in simulation units."""
    scene, mapping = simulation_scene(LAW, rate, volume_fraction=phi, seed=seed,
                                      resolution=RESOLUTION, particles=particles)
    mu_sim = float(scene.fluid.law.viscosity(mapping.simulation_shear_rate))
    run = xr.Dataset({"viscosity": ((), factor * mu_sim),
                      "viscosity_stderr": ((), 0.01 * mu_sim), "phi": ((), phi),
                      "suspension_viscosity": ((), factor * mu_sim),
                      "relative_viscosity": ((), factor),
                      "relative_viscosity_stderr": ((), 0.01),
                      "matrix_viscosity_at_rate": ((), mu_sim)},
                     attrs={"mach_number": 1e-3, "wall_time_s": 12.0, "n_particles": 480,
                            "reynolds_number": 0.6, "n_bodies": 3})
    return with_physical_results(run, mapping, scene=scene, volume_fraction=phi, seed=seed,
                                 resolution=RESOLUTION, fit=FIT)


def test_physical_results_of_one_run():
    run = fake_run(2.0, 1, factor=0.99)
    assert float(run["relative_viscosity"]) == pytest.approx(0.99, rel=1e-12)
    assert float(run["relative_viscosity_stderr"]) == pytest.approx(0.002, rel=1e-12)
    assert float(run["matrix_viscosity"]) == pytest.approx(float(LAW.viscosity(2.0)))
    assert float(run["suspension_viscosity"]) == pytest.approx(0.99 * float(LAW.viscosity(2.0)))
    assert float(run["shear_rate"]) == 2.0 and int(run["seed"]) == 1
    assert run.attrs["unit_mach_number"] == 1e-3
    assert json.loads(run.attrs["resolution"])["box"] == 5
    for name in STUDY_VARIABLES:
        assert run[name].attrs["units"] and run[name].attrs["long_name"]


def test_physical_results_of_a_suspension_run_replace_its_simulation_unit_ones():
    run = fake_suspension_run(2.0, 3, 0.2, 1.7)
    assert float(run["phi"]) == 0.2 and run["phi"].attrs["units"] == "1"
    assert float(run["relative_viscosity"]) == pytest.approx(1.7, rel=1e-12)
    assert float(run["suspension_viscosity"]) == pytest.approx(1.7 * float(LAW.viscosity(2.0)))
    assert run["suspension_viscosity"].attrs["units"] == "Pa s"
    assert float(run["body_count"]) == 3 and float(run["packing_seed"]) == 3
    assert float(run["inclusion_radius"]) == 1.0 == float(run["reynolds_length"])
    assert np.isnan(float(run["particle_radius"]))
    assert json.loads(run.attrs["inclusions"]) == {"shape": "sphere", "radius": 1.0,
                                                   "polydispersity": 0.0, "size_ratio": 5.0,
                                                   "min_gap": 0.05, "friction": 0.0,
                                                   "rolling_friction": 0.0}
    alone = fake_run(2.0, 3)
    assert alone.attrs["inclusions"] == "" and alone.attrs["inclusion_shape"] == "none"
    assert float(alone["body_count"]) == 0 and np.isnan(float(alone["inclusion_radius"]))
    assert float(alone["reynolds_length"]) == 1.0


def test_gather_carries_the_inclusion_settings_and_refuses_mixed_ones():
    summary = gather_runs([fake_run(1.0, 1), fake_suspension_run(1.0, 1, 0.2, 1.5)])
    assert summary.attrs["inclusion_shape"] == "sphere"
    assert json.loads(summary.attrs["inclusions"])["radius"] == 1.0
    radius = summary["inclusion_radius"].sel(shear_rate=1.0, seed=1)
    assert np.isnan(float(radius.sel(phi=0.0))) and float(radius.sel(phi=0.2)) == 1.0
    assert summary["inclusion_radius"].attrs["simulation_units"] == "h"
    with pytest.raises(InputError, match="different inclusion settings"):
        gather_runs([fake_suspension_run(1.0, 1, 0.2, 1.5),
                     fake_suspension_run(1.0, 1, 0.1, 1.2, Particles(radius=1.2))])


def test_gather_builds_the_grid_with_units_and_nan_for_missing_runs():
    runs = [fake_run(r, s, factor=1 + 0.01 * s) for r in (0.1, 10.0) for s in (1, 2)]
    runs.append(fake_run(10.0, 1, factor=2.0, phi=0.2))
    summary = gather_runs(runs, material="m")
    assert dict(summary.sizes) == {"phi": 2, "shear_rate": 2, "seed": 2}
    assert summary["seed"].dtype == np.int64
    assert summary["matrix_viscosity"].dims == ("shear_rate",)
    assert summary["suspension_viscosity"].dims == SUMMARY_DIMS
    eta_r = summary["relative_viscosity"]
    assert float(eta_r.sel(phi=0.0, shear_rate=0.1, seed=2)) == pytest.approx(1.02)
    assert float(eta_r.sel(phi=0.2, shear_rate=10.0, seed=1)) == pytest.approx(2.0)
    assert np.isnan(float(eta_r.sel(phi=0.2, shear_rate=0.1, seed=1)))
    for name in summary.variables:
        assert summary[name].attrs["units"] == STUDY_VARIABLES[name].units
    assert summary["shear_rate"].attrs["units"] == "s-1"
    assert summary.attrs["n_runs"] == 5
    assert json.loads(summary.attrs["matrix_fit"])["law"] == "cross"


def test_gather_refuses_duplicates_foreign_files_and_mixed_fits():
    with pytest.raises(InputError, match="same"):
        gather_runs([fake_run(1.0, 1), fake_run(1.0, 1)], sources=["a.nc", "b.nc"])
    with pytest.raises(InputError, match="not a simulate run file"):
        gather_runs([xr.Dataset({"viscosity": ((), 1.0)})])
    other = dict(FIT, params=dict(FIT["params"], mu_0=60.0))
    with pytest.raises(InputError, match="different matrix fits"):
        gather_runs([fake_run(1.0, 1), fake_run(2.0, 1, fit=other)])
    with pytest.raises(InputError, match="no run files"):
        gather_runs([])


def test_write_summary_round_trip_and_no_partial_output(tmp_path):
    files = []
    for rate in (0.5, 5.0):
        path = tmp_path / f"phi-0_rate-{rate:g}_seed-1.nc"
        fake_run(rate, 1).to_netcdf(path)
        files.append(path)
    out = tmp_path / "summary.nc"
    write_summary(files, out, material="m")
    with xr.open_dataset(out) as ds:
        assert ds["shear_rate"].values.tolist() == [0.5, 5.0]
        assert json.loads(ds.attrs["runs"]) == [f.name for f in files]
    (tmp_path / "broken.nc").write_text("not netcdf")
    with pytest.raises(InputError):
        write_summary([files[0], tmp_path / "broken.nc"], tmp_path / "bad.nc")
    assert not (tmp_path / "bad.nc").exists()


def test_seed_mean_combines_run_errors_and_seed_spread():
    runs = [fake_run(1.0, s, factor=f, stderr=0.01) for s, f in ((1, 0.98), (2, 1.02))]
    mean, error = seed_mean(gather_runs(runs), "relative_viscosity")
    assert float(mean.squeeze()) == pytest.approx(1.0)
    expected = np.sqrt(2 * 0.01 ** 2 / 4 + np.var([0.98, 1.02], ddof=1) / 2)
    assert float(error.squeeze()) == pytest.approx(expected)


def test_summary_figure_draws_runs_law_measurements_and_estimate():
    summary = gather_runs([fake_run(r, 1) for r in (0.1, 1.0, 10.0)]
                          + [fake_run(1.0, 1, factor=1.5, phi=0.2)], material="m")
    rates = np.geomspace(0.01, 100, 9)
    estimate = xr.Dataset({"suspension_viscosity": (("volume_fraction", "shear_rate"),
                                                     np.vstack([1.3 * LAW.viscosity(rates)] * 2))},
                          coords={"volume_fraction": [0.1, 0.2], "shear_rate": rates})
    fig = plot_summary(summary, law=LAW, measured=(rates, LAW.viscosity(rates)), estimate=estimate)
    assert isinstance(fig, Figure) and len(fig.axes) == 3
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert "matrix (measured)" in labels and "matrix (cross fit)" in labels
    assert "φ = 0.2 homogenisation estimate" in labels
    assert not any("φ = 0.1" in label for label in labels)
    alone = plot_viscosity(summary)
    assert isinstance(alone, Figure) and len(alone.axes) == 1


def test_relative_viscosity_against_phi_beside_the_estimate_at_each_simulated_rate():
    runs = [fake_run(r, 1) for r in (0.1, 10.0)]
    runs += [fake_suspension_run(r, 1, phi, 1 + 3 * phi) for r in (0.1, 10.0) for phi in (0.1, 0.3)]
    summary = gather_runs(runs, material="m")
    coarse = homogenisation_estimate(FIT, [0.1, 0.2, 0.3, 0.4], np.geomspace(0.01, 100, 9),
                                     phi_max=0.57)
    fine = estimate_by_phi(FIT, summary, coarse)
    assert fine["shear_rate"].values.tolist() == [0.1, 10.0]
    assert fine["volume_fraction"].values[0] == 0.0
    assert fine["volume_fraction"].values[-1] == pytest.approx(0.44)
    fig = plot_relative_viscosity_vs_phi(summary, estimate=fine)
    ax = fig.axes[0]
    labels = [line.get_label() for line in ax.get_lines()]
    assert "γ̇ = 10 1/s, homogenisation estimate" in labels
    assert "Krieger–Dougherty g(φ) (Newtonian matrix)" in labels
    curve = next(line for line in ax.get_lines()
                 if line.get_label() == "γ̇ = 0.1 1/s, homogenisation estimate")
    expected = fine["relative_viscosity"].sel(shear_rate=0.1).values
    np.testing.assert_allclose(curve.get_ydata(), expected)
    # From the coarse estimate, interpolated in log rate (10 1/s is on its grid: exact).
    fig = plot_relative_viscosity_vs_phi(summary, estimate=coarse)
    curve = next(line for line in fig.axes[0].get_lines()
                 if line.get_label() == "γ̇ = 10 1/s, homogenisation estimate")
    assert curve.get_xdata().tolist() == [0.0, 0.1, 0.2, 0.3, 0.4]
    exact = homogenisation_estimate(FIT, [0.3], [10.0], phi_max=0.57)["relative_viscosity"]
    assert curve.get_ydata()[3] == pytest.approx(float(exact.squeeze()), rel=1e-9)


def test_shape_ratio_and_comparison_figure_of_two_studies():
    spheres = gather_runs([fake_run(r, 1) for r in (0.1, 10.0)]
                          + [fake_suspension_run(r, 1, phi, 1 + 3 * phi)
                             for r in (0.1, 10.0) for phi in (0.1, 0.3)], material="m")
    sand = gather_runs([fake_suspension_run(r, 1, phi, 1 + 4 * phi)
                        for r in (10.0, 100.0) for phi in (0.1, 0.3)], material="m")
    ratio = shape_ratio(sand, spheres)
    assert ratio["shear_rate"].values.tolist() == [10.0]
    assert ratio["phi"].values.tolist() == [0.1, 0.3]
    expected = np.array([1.4 / 1.3, 2.2 / 1.9])
    np.testing.assert_allclose(ratio["ratio"].squeeze("shear_rate").values, expected, rtol=1e-12)
    # independent errors of 0.01 on each η_r, in quadrature relative to each
    relative = np.hypot(0.01 / np.array([1.4, 2.2]), 0.01 / np.array([1.3, 1.9]))
    np.testing.assert_allclose(ratio["ratio_error"].squeeze("shear_rate").values,
                               expected * relative, rtol=1e-12)
    fig = plot_shape_comparison({"spheres": spheres, "sand": sand})
    assert len(fig.axes) == 1 and fig.axes[0].get_title() == "γ̇ = 10 1/s"
    with pytest.raises(ValueError, match="no shear rate"):
        plot_shape_comparison({"spheres": spheres.sel(shear_rate=[0.1]), "sand": sand})
