"""The dst study's stage code on synthetic data (no SPH run): points, scenes, the perturbed
start, the band criterion, gathering and figures (suspsim.stages.dst, dst_gather, dst_figures)."""
import copy
import json
import math

import numpy as np
import pytest
import xarray as xr

from suspsim.dst.scene import dst_scene_from_dict
from suspsim.dst.study import MODERATE_NONLOCALITY, STRONG_NONLOCALITY, spanning_stresses
from suspsim.errors import InputError
from suspsim.stages.dst import (band_points, figure_index, find_point, nonlocalities,
                                phi_stresses, point_scene, study_fluid, study_points)
from suspsim.stages.dst_figures import (figure_point, flow_curve_view, splitting_view,
                                        write_dst_figures)
from suspsim.stages.dst_gather import correlation_length, gather_flow_curves, write_flow_curves

SETTINGS = {
    "volume_fractions": [0.48, 0.54],
    "nonlocalities": [
        {"name": "strong", "alpha": None, "equilibration_strain": 1.5, "averaging_strain": 1.5},
        {"name": "zero", "alpha": None, "equilibration_strain": 10, "averaging_strain": 10},
        {"name": "weak", "alpha": 1e-3, "equilibration_strain": 2, "averaging_strain": 4}],
    "stress_count": 4, "stress_range": [0.2, 40.0], "lattice": [13, 6],
    "momentum_time_ratio": 0.1, "perturbation": 0.01, "seed": 1,
    "fluid": {"phi_m": 0.562, "phi_0": 0.693, "beta": 2.0, "K_f": 1.0},
    "figure": {"phi": 0.54, "stress": 1.25}, "threads": 1,
    "stable_branch": {"equilibration_strain": 1.5, "averaging_strain": 1.0},
    "bands": {"nonlocalities": ["zero", "weak"], "lattice": [13, 9], "equilibration_strain": 3,
              "averaging_strain": 2}}


def test_points_cover_every_phi_nonlocality_and_spanning_stress_once():
    points = study_points(SETTINGS)
    assert len(points) == 2 * 3 * 4
    assert len({(p.phi, p.nonlocality.name, p.index) for p in points}) == len(points)
    alphas = {p.nonlocality.name: p.nonlocality.alpha for p in points}
    assert alphas == {"strong": STRONG_NONLOCALITY, "zero": 0.0, "weak": 1e-3}
    for phi in (0.48, 0.54):
        grid = spanning_stresses(study_fluid(SETTINGS, phi, 0.0), 4)
        assert [p.stress for p in points if p.phi == phi and p.nonlocality.name == "zero"] \
            == pytest.approx(grid.tolist())
    # at the DST phi, the grid crosses both turning points (one stress strictly between)
    turning = study_fluid(SETTINGS, 0.54, 0.0).steady_law().turning_points()
    inside = [s for s in phi_stresses(SETTINGS, 0.54)
              if turning.sigma_beta < s < turning.sigma_alpha]
    assert len(inside) == 1
    assert find_point(SETTINGS, 0.54, "weak", 3) == points[-1]
    # off the unstable branch a point runs at most the stable-branch strains
    for p in points:
        unstable = p.phi == 0.54 and turning.sigma_beta < p.stress < turning.sigma_alpha
        full = next(k for k in nonlocalities(SETTINGS) if k.name == p.nonlocality.name)
        assert (p.nonlocality.equilibration_strain, p.nonlocality.averaging_strain) == (
            (full.equilibration_strain, full.averaging_strain) if unstable
            else (min(full.equilibration_strain, 1.5), min(full.averaging_strain, 1.0)))
    with pytest.raises(InputError):
        find_point(SETTINGS, 0.50, "weak", 0)


def test_nonlocality_names_map_to_the_study_constants_and_bad_entries_fail():
    named = {"nonlocalities": [{"name": n, "equilibration_strain": 1, "averaging_strain": 1}
                               for n in ("strong", "moderate", "zero")]}
    assert [k.alpha for k in nonlocalities(named)] == [STRONG_NONLOCALITY,
                                                       MODERATE_NONLOCALITY, 0.0]
    unknown = {"nonlocalities": [{"name": "medium", "equilibration_strain": 1,
                                  "averaging_strain": 1}]}
    with pytest.raises(InputError, match="give its alpha"):
        nonlocalities(unknown)
    twice = {"nonlocalities": named["nonlocalities"] + named["nonlocalities"][:1]}
    with pytest.raises(InputError, match="twice"):
        nonlocalities(twice)


def test_point_scene_is_a_valid_dst_scene_with_the_study_set_up():
    point = find_point(SETTINGS, 0.54, "zero", 2)  # on the unstable branch
    scene = dst_scene_from_dict(point_scene(SETTINGS, point))
    assert (scene.geometry.n_x, scene.geometry.n_y) == (13, 6)
    assert scene.fluid.alpha == 0.0 and scene.flow.stress == pytest.approx(point.stress)
    assert (scene.run.strain, scene.run.transient) == (20.0, 10.0)
    rate = scene.fluid.shear_rate(point.stress)
    # epsilon = K_f gdot rho L_y^2/eta = 0.1 at the Wyart-Cates state
    assert scene.numerics.density * rate ** 2 / point.stress == pytest.approx(0.1)
    # the sound speed reaches the upper-branch stress at gdot_WC (a split particle's)
    law = scene.fluid.steady_law()
    upper = float(law.branch_stress(rate, "upper"))
    assert scene.numerics.sound_speed == pytest.approx(
        math.sqrt(upper / (scene.numerics.density * 0.01)))


def test_band_points_are_the_figure_point_on_the_band_lattice():
    index = figure_index(SETTINGS)
    stresses = phi_stresses(SETTINGS, 0.54)
    assert index == int(np.argmin(np.abs(np.log(stresses / 1.25))))
    bands = band_points(SETTINGS)
    assert [(p.phi, p.nonlocality.name, p.index) for p in bands] == [(0.54, "zero", index),
                                                                     (0.54, "weak", index)]
    assert bands[1].nonlocality.alpha == 1e-3 and bands[0].stress == stresses[index]
    scene = dst_scene_from_dict(point_scene(SETTINGS, bands[0], band=True))
    assert (scene.geometry.n_x, scene.geometry.n_y) == (13, 9)
    assert (scene.run.strain, scene.run.transient) == (5.0, 3.0)
    assert find_point(SETTINGS, 0.54, "weak", index, band=True) == bands[1]
    assert band_points({**SETTINGS, "bands": {**SETTINGS["bands"], "nonlocalities": []}}) == []
    with pytest.raises(InputError, match="not in dst.nonlocalities"):
        band_points({**SETTINGS, "bands": {**SETTINGS["bands"], "nonlocalities": ["other"]}})
    with pytest.raises(InputError, match="not one of the study's volume fractions"):
        figure_index({**SETTINGS, "figure": {"phi": 0.5, "stress": 1.25}})


def test_perturbed_start_has_the_requested_rms_and_is_reproducible():
    point = find_point(SETTINGS, 0.54, "zero", 2)  # unstable branch, f_hat = 0.71: no clipping
    data = point_scene(SETTINGS, point)
    f_hat = study_fluid(SETTINGS, 0.54, 0.0).frictional_fraction(point.stress)
    sims = [dst_scene_from_dict(data).build() for _ in range(2)]
    f = sims[0].f_all[:sims[0].n_fluid]
    assert np.array_equal(f, sims[1].f_all[:sims[1].n_fluid])
    # rms of N(0, 1) over 78 draws: 0.01 within its sampling spread (~8 %, 3 sigma 25 %)
    assert np.sqrt(np.mean((f - f_hat) ** 2)) == pytest.approx(0.01, rel=0.25)
    # the wall starts at the unperturbed Wyart-Cates rate
    assert sims[0].wall_velocity == pytest.approx(study_fluid(SETTINGS, 0.54, 0.0)
                                                  .shear_rate(point.stress))
    quiet = copy.deepcopy(data)
    quiet["run"]["perturbation"] = 0.0
    sim = dst_scene_from_dict(quiet).build()
    assert np.all(sim.f_all[:sim.n_fluid] == f_hat)


def _lattice(n_x, n_y):
    spacing = 1.0 / n_y
    x, y = np.meshgrid((np.arange(n_x) + 0.5) * spacing, (np.arange(n_y) + 0.5) * spacing,
                       indexing="ij")
    return x.ravel(), y.ravel(), spacing, n_x * spacing


def test_correlation_length_separates_particle_noise_from_bands():
    x, y, dx, period = _lattice(30, 12)
    rng = np.random.default_rng(3)
    noise = correlation_length(x, y, rng.standard_normal(x.size), period, dx)
    assert noise < dx  # uncorrelated: C(dx) ~ 0 already
    # bands along the flow direction x, alternating every w rows: xi grows with w
    widths = (2, 3, 4, 6)
    banded = [correlation_length(x, y, (np.floor(y / (w * dx)) % 2).astype(float), period, dx)
              for w in widths]
    assert all(a < b for a, b in zip(banded, banded[1:]))
    assert banded[0] > noise and banded[-1] > 3 * dx
    # bands with noise on top stay longer-ranged than the noise alone
    noisy = (np.floor(y / (3 * dx)) % 2) + 0.3 * rng.standard_normal(x.size)
    assert correlation_length(x, y, noisy, period, dx) > 1.5 * noise
    assert math.isnan(correlation_length(x, y, np.full(x.size, 0.4), period, dx))


def test_correlation_length_is_periodic_in_x():
    x, y, dx, period = _lattice(24, 8)
    field = np.cos(2 * np.pi * x / period) + 0.5 * np.sin(2 * np.pi * y)
    shifted = np.mod(x + 0.37 * period, period)
    assert correlation_length(shifted, y, field, period, dx) == pytest.approx(
        correlation_length(x, y, field, period, dx))
    with pytest.raises(ValueError):
        correlation_length(x, y[:-1], field, period, dx)


def fake_run(settings, point, deviation=0.01, psi=(0.3, 0.2), rng=None, band=False):
    """A run dataset of ``point`` laid out as suspsim.dst.run writes it: the domain-averaged
    rate is (1 + deviation) x the Wyart-Cates rate, the stress the imposed one."""
    rng = rng or np.random.default_rng(0)
    scene = dst_scene_from_dict(point_scene(settings, point, band=band))
    fluid = scene.fluid
    rate = fluid.shear_rate(point.stress)
    lattice = settings["bands"]["lattice"] if band else settings["lattice"]
    x, y, _, _ = _lattice(*lattice)
    n_y = lattice[1]
    turning = fluid.steady_law().turning_points()
    q = ((point.stress - turning.sigma_beta) / (turning.sigma_alpha - turning.sigma_beta)
         if turning else math.nan)
    data = {
        "mean_shear_rate": rate * (1 + deviation), "mean_shear_rate_stderr": 1e-4 * rate,
        "mean_stress": point.stress, "mean_stress_stderr": 1e-4 * point.stress,
        "mean_wall_shear_rate": rate * 0.9, "mean_wall_shear_rate_stderr": 1e-3 * rate,
        "mean_frictional_fraction": fluid.frictional_fraction(point.stress),
        "mean_lower_branch_fraction": psi[0], "mean_lower_branch_fraction_stderr": 0.01,
        "mean_upper_branch_fraction": psi[1], "mean_upper_branch_fraction_stderr": 0.01,
        "wyart_cates_shear_rate": rate,
        "wyart_cates_frictional_fraction": fluid.frictional_fraction(point.stress),
        "turning_point_position": q}
    variables = {k: ((), v) for k, v in data.items()}
    f = np.clip(fluid.frictional_fraction(point.stress) + 0.1 * rng.standard_normal(x.size),
                0, 1)
    for name, values in (("particle_x", x), ("particle_y", y),
                         ("particle_frictional_fraction", f),
                         ("particle_shear_rate", np.full(x.size, rate)),
                         ("particle_stress", np.array([fluid.viscosity(v) for v in f]) * rate)):
        variables[name] = ("particle", values)
    variables["frictional_fraction_profile"] = ("y", np.full(n_y, f.mean()))
    variables["stress_profile"] = ("y", np.full(n_y, point.stress))
    return xr.Dataset(variables, coords={"y": (np.arange(n_y) + 0.5) / n_y,
                                         "particle": np.arange(x.size)},
                      attrs={"scene": json.dumps(scene.to_dict()), "wall_time_s": 2.0,
                             "n_steps": 1000})


def _band_runs():
    """Band runs: f banded in rows of 3 for 'weak', particle noise for 'zero'."""
    runs = []
    for point in band_points(SETTINGS):
        run = fake_run(SETTINGS, point, band=True)
        y = run["particle_y"].values
        if point.nonlocality.name == "weak":
            run["particle_frictional_fraction"].values[:] = np.floor(y * 9 / 3) % 2
        runs.append(run)
    return runs


@pytest.fixture(scope="session")
def gathered():
    points = study_points(SETTINGS)
    return gather_flow_curves([fake_run(SETTINGS, p) for p in points], SETTINGS,
                              bands=_band_runs())


def test_gather_places_every_run_and_adds_the_steady_curve(gathered):
    data = gathered
    assert data["shear_rate"].dims == ("phi", "nonlocality", "stress_index")
    assert data.sizes == {"phi": 2, "nonlocality": 3, "stress_index": 4, "particle": 78,
                          "band_nonlocality": 2, "band_particle": 117,
                          "y": 6, "curve_point": 400}
    assert list(data["nonlocality"].values) == ["strong", "zero", "weak"]
    assert data["alpha"].values.tolist() == [STRONG_NONLOCALITY, 0.0, 1e-3]
    np.testing.assert_allclose(data["relative_deviation"].values, 0.01, rtol=1e-9)
    np.testing.assert_allclose(data["imposed_stress"].sel(phi=0.54).values,
                               phi_stresses(SETTINGS, 0.54))
    # the steady curve passes through every Wyart-Cates point: gdot(sigma) of each phi's law
    for phi in (0.48, 0.54):
        law = study_fluid(SETTINGS, phi, 0.0).steady_law()
        np.testing.assert_allclose(data["curve_shear_rate"].sel(phi=phi).values,
                                   law.shear_rate(data["curve_stress"].values))
    assert math.isnan(float(data["sigma_beta"].sel(phi=0.48)))  # CST
    # the lever rule at the measured wall rate on the unstable branch only
    point = data.sel(phi=0.54, nonlocality="zero")
    q = point["q"].values
    law = study_fluid(SETTINGS, 0.54, 0.0).steady_law()
    for k in range(4):
        expected = (float(law.lever_rule(point["imposed_stress"].values[k],
                                         point["wall_shear_rate"].values[k]))
                    if 0 < q[k] < 1 else math.nan)
        assert point["lever_rule"].values[k] == pytest.approx(expected, nan_ok=True)
    assert np.all(np.isfinite(data["correlation_length"].values))
    # band runs: their own lattice; banded f is longer-ranged than particle noise
    assert data["band_particle_x"].shape == (2, 13 * 9)
    band_xi = data["band_correlation_length"]
    assert float(band_xi.sel(band_nonlocality="weak")) > 2 * float(
        band_xi.sel(band_nonlocality="zero"))
    assert float(data["band_stress"]) == pytest.approx(phi_stresses(SETTINGS, 0.54)[
        figure_index(SETTINGS)])
    for name, variable in data.variables.items():
        if name not in ("nonlocality", "band_nonlocality"):
            assert "units" in variable.attrs and "long_name" in variable.attrs, name


def test_gather_rejects_runs_that_are_not_the_study_points():
    points = study_points(SETTINGS)
    runs = [fake_run(SETTINGS, p) for p in points]
    with pytest.raises(InputError, match="study points"):
        gather_flow_curves(runs[:-1], SETTINGS)
    runs[0], runs[1] = runs[1], runs[0]
    with pytest.raises(InputError, match="the study point is"):
        gather_flow_curves(runs, SETTINGS)


@pytest.fixture(scope="session")
def flow_curves_file(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dst")
    files = []
    for k, point in enumerate(study_points(SETTINGS)):
        files.append(folder / f"run{k}.nc")
        fake_run(SETTINGS, point).to_netcdf(files[-1])
    band_files = []
    for k, run in enumerate(_band_runs()):
        band_files.append(folder / f"band{k}.nc")
        run.to_netcdf(band_files[-1])
    out = folder / "flow_curves.nc"
    write_flow_curves(files, out, SETTINGS, band_files=band_files)
    return out


def test_flow_curves_file_keeps_units_and_values(flow_curves_file, gathered):
    with xr.open_dataset(flow_curves_file) as data:
        assert data["shear_rate"].attrs["units"] == "1"
        assert data["shear_rate"].attrs["simulation_units"] == "sigma_star eta_s-1"
        assert data["wall_time"].attrs["units"] == "s"
        xr.testing.assert_allclose(data["relative_deviation"], gathered["relative_deviation"])
        assert list(data["nonlocality"].values) == ["strong", "zero", "weak"]


def test_figure_point_and_views(gathered):
    # the figure point: the imposed stress of 0.54 nearest to 1.25 in log
    phi, index = figure_point(gathered, 0.54, 1.25)
    stresses = phi_stresses(SETTINGS, 0.54)
    assert phi == 0.54 and index == int(np.argmin(np.abs(np.log(stresses / 1.25))))
    with pytest.raises(InputError):
        figure_point(gathered, 0.50, 1.25)
    view = flow_curve_view(gathered, 0.54, "strong")
    assert view.attrs["alpha"] == STRONG_NONLOCALITY and view.sizes["stress"] == 4
    np.testing.assert_allclose(view["stress"].values, stresses)
    assert splitting_view(gathered, 0.54).sizes["stress"] == 1
    with pytest.raises(InputError, match="unstable branch"):
        splitting_view(gathered, 0.48)


@pytest.mark.parametrize("name", ["flow_curves", "particles", "splitting", "bands"])
def test_each_figure_is_drawn(tmp_path, flow_curves_file, name):
    path = tmp_path / f"{name}.png"
    write_dst_figures(flow_curves_file, {name: str(path)}, phi=0.54, stress=1.25)
    with open(path, "rb") as fh:
        assert fh.read(8) == b"\x89PNG\r\n\x1a\n"
    with pytest.raises(ValueError, match="unknown dst figure"):
        write_dst_figures(flow_curves_file, {"other": str(path)}, phi=0.54, stress=1.25)


def test_a_density_error_restarts_the_point_with_a_faster_sound_speed(tmp_path, monkeypatch):
    import suspsim.stages.dst as stage
    from suspsim.errors import NumericalError

    point = find_point(SETTINGS, 0.54, "zero", 2)
    scene = point_scene(SETTINGS, point)
    speeds = []

    def failing(built, out, threads=None):
        speeds.append(built.numerics.sound_speed)
        if len(speeds) < 3:
            raise NumericalError("DST run stopped: density error max|rho/rho0 - 1| exceeds")

    monkeypatch.setattr(stage, "run_dst_scene", failing)
    stage.simulate_point(scene, tmp_path / "run.nc")
    c = scene["numerics"]["sound_speed"]
    assert speeds == pytest.approx([c, 2 * c, 4 * c])  # the caller's scene is left alone
    speeds.clear()

    def always(built, out, threads=None):
        speeds.append(built.numerics.sound_speed)
        raise NumericalError("density error")

    monkeypatch.setattr(stage, "run_dst_scene", always)
    with pytest.raises(NumericalError):
        stage.simulate_point(scene, tmp_path / "run.nc")
    assert len(speeds) == 3
    speeds.clear()

    def jammed(built, out, threads=None):
        speeds.append(built.numerics.sound_speed)
        raise NumericalError("a particle jammed")

    monkeypatch.setattr(stage, "run_dst_scene", jammed)
    with pytest.raises(NumericalError, match="jammed"):
        stage.simulate_point(scene, tmp_path / "run.nc")
    assert len(speeds) == 1
