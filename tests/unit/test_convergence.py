"""The speed-against-error study: cases, configurations, Pareto front, cost table, stages."""
import math

import numpy as np
import pytest
import xarray as xr

from suspsim.convergence.cases import (CASES, Case, DSTChannelCase, DiluteSuspensionCase,
                                      DSTPointCase, get_case, snapped_resolution)
from suspsim.convergence.measure import run_configuration, run_or_failure
from suspsim.convergence.study import (case_dataset, cheapest_meeting, configuration_id,
                                       configurations, cost_table, pareto_front)
from suspsim.errors import InputError
from suspsim.plotting.pareto import plot_pareto
from suspsim.stages.speed_error import gather_case, measure_configuration


def test_snapped_resolution_holds_whole_rows():
    for q, length in [(1.6, 7.5), (1.4, 7.5), (2.3, 10.0), (0.1, 5.0)]:
        rows = snapped_resolution(q, length) * length
        assert rows == pytest.approx(round(rows)) and round(rows) >= 3


@pytest.mark.parametrize("name", sorted(n for n, c in CASES.items() if isinstance(c, Case)))
def test_every_case_builds_the_same_physics_at_every_resolution(name):
    """Kinematic viscosity, rate or force, and the box do not change with q (fixed physics)."""
    case = CASES[name]
    scenes = [case.build(case.settings({"resolution": q})) for q in (1.2, 1.6, 2.4)]
    for scene in scenes:
        assert scene.number_density ** (1 / scene.dimension) * scene.box[1] == pytest.approx(
            round(scene.number_density ** (1 / scene.dimension) * scene.box[1]))
    nu = [float(s.fluid.law.viscosity(0.37)) / s.density for s in scenes]
    assert nu == pytest.approx([nu[0]] * 3, rel=1e-12)
    assert [s.box[1] for s in scenes] == pytest.approx([scenes[0].box[1]] * 3)
    assert len({s.flow.type for s in scenes}) == 1
    assert [s.flow.shear_rate for s in scenes] == pytest.approx([scenes[0].flow.shear_rate] * 3)
    assert [s.flow.body_force for s in scenes] == pytest.approx([scenes[0].flow.body_force] * 3,
                                                                rel=1e-9)


def test_channel_case_at_another_reynolds_number():
    """Re = u_max W/ν at W = 5 h: 0.1 for the training channel, 1 for the held-out one; the
    centre-line velocity of the split-force channel is g W²/(8ν) (SPEC 6.2)."""
    from suspsim.sph.timestep import velocity_scale

    for name, reynolds in [("poiseuille_newtonian_3d", 0.1), ("poiseuille_newtonian_re1_3d", 1.0)]:
        case = get_case(name)
        scene = case.build(case.settings({"width": 5.0}))
        nu = float(scene.fluid.law.viscosity(0.0)) / scene.density
        assert velocity_scale(scene) * 5.0 / nu == pytest.approx(reynolds, rel=1e-6)


def test_failed_run_is_kept_as_a_failure():
    """A blow-up (NumericalError) or NaN positions failing the profile binning (ValueError)
    become a configuration with a failure message, so a sweep keeps going."""
    from suspsim.errors import NumericalError

    base = get_case("poiseuille_newtonian_2d")

    class Failing:
        name, axes, settings = base.name, base.axes, base.settings

        def __init__(self, error):
            self.error = error

        def warm_up(self, settings, threads):
            pass

        def execute(self, settings, threads):
            raise self.error

    record = run_or_failure(Failing(NumericalError("density out of bounds")), {"width": 2.5})
    assert record["width"] == 2.5 and "NumericalError" in record["failure"]
    for error in (TypeError("a bug is not a blow-up"), ValueError("nor is a bad value")):
        with pytest.raises(type(error)):
            run_or_failure(Failing(error), {})


def test_case_rejects_unknown_setting_and_name():
    with pytest.raises(InputError, match="unknown setting 'spacing'"):
        CASES["couette_newtonian_3d"].settings({"spacing": 1})
    with pytest.raises(InputError, match="unknown case 'nope'"):
        get_case("nope")


def test_configurations_one_at_a_time_and_grid():
    case = CASES["couette_newtonian_3d"]
    values = {"resolution": [1.2, 1.6, 2.0], "kernel": ["lucy", "quintic"]}
    one = configurations(case, values)
    # the defaults (1.6, lucy) are not repeated
    assert [configuration_id(o) for o in one] == [
        "base", "resolution-1.2", "resolution-2", "kernel-quintic"]
    grid = configurations(case, values, "grid")
    assert len(grid) == 6 and {} in grid
    assert configuration_id({"kernel": "quintic", "resolution": 2.0}) == (
        "kernel-quintic+resolution-2")
    with pytest.raises(InputError, match="sweep must be"):
        configurations(case, values, "random")
    with pytest.raises(InputError, match="unknown setting"):
        configurations(case, {"spacing": [1]})


def test_pareto_front_is_the_non_dominated_set():
    rng = np.random.default_rng(3)
    cost, error = rng.uniform(1, 100, 200), rng.uniform(1e-3, 1, 200)
    cost[5], error[5] = np.nan, np.nan
    front = pareto_front(cost, error)
    assert not front[5]
    for i in range(200):
        if not np.isfinite(cost[i]):
            continue
        dominated = np.any((cost <= cost[i]) & (error <= error[i])
                           & ((cost < cost[i]) | (error < error[i])))
        assert front[i] == (not dominated)


def _records(case):
    base = case.settings()
    rows = []
    for q, err, cpu in [(1.2, 0.05, 1.0), (1.6, 0.02, 3.0), (2.0, 0.012, 9.0), (2.4, 0.03, 20.0)]:
        rows.append({**base, "resolution": q, "error": err, "signed_error": -err,
                     "error_stderr": err / 10, "cpu_time": cpu, "wall_time": cpu,
                     "n_particles": 1000 * q ** 3, "n_steps": 100,
                     "particle_steps_per_s": 1e6})
    rows.append({**base, "dt_coefficient": 0.5, "failure": "density error 0.3 exceeds ..."})
    return rows


def test_case_dataset_cost_table_and_figure():
    case = CASES["couette_newtonian_3d"]
    ds = case_dataset(case, _records(case))
    assert list(ds["configuration"].values) == [
        "resolution-1.2", "base", "resolution-2", "resolution-2.4", "dt_coefficient-0.5"]
    assert list(ds["pareto"].values) == [1, 1, 1, 0, 0]
    assert ds["failure"].values[-1].startswith("density error")
    assert np.isnan(ds["error"].values[-1])
    assert all("units" in ds[v].attrs for v in ds.data_vars if v != "failure")
    assert ds["error_bound"].values[1] == pytest.approx(0.024)
    assert cheapest_meeting(ds, 0.024) == 1 and cheapest_meeting(ds, 0.02) == 2
    assert cheapest_meeting(ds, 0.014) is None
    table = cost_table([ds], targets=(0.05, 0.024, 0.001))
    lines = table.strip().splitlines()
    assert len(lines) == 5
    assert "| couette_newtonian_3d | 2.4% | base | 2.00% ± 0.20% | 3 |" in lines[3]
    assert "none measured" in lines[4]
    fig = plot_pareto([ds, ds])
    assert len([ax for ax in fig.axes if ax.get_visible()]) == 2
    assert "(1 blew up)" in fig.axes[0].get_title()


def test_measure_gather_round_trip(tmp_path):
    """A real (small, short) configuration and a blow-up (sound 0.1 h/tau at Wi = 0.3: the
    density error passes 5 % within 500 steps), gathered: the blow-up is a record with its
    message, not an error."""
    overrides = {"side": 3.75, "units": 2, "transient": 0.5}
    a = measure_configuration("couette_newtonian_3d", overrides, tmp_path / "a.nc")
    assert a["n_particles"] == 6 ** 3 and a["n_steps"] > 0 and a["cpu_time"] > 0
    assert math.isfinite(a["error"]) and a["error"] < 0.05
    b = measure_configuration("couette_newtonian_3d", {**overrides, "wi_target": 0.3},
                              tmp_path / "b.nc")
    assert "failure" in b
    ds = gather_case("couette_newtonian_3d", [tmp_path / "a.nc", tmp_path / "b.nc"],
                     tmp_path / "case.nc")
    again = xr.load_dataset(tmp_path / "case.nc")
    assert again["error"].values[0] == pytest.approx(a["error"])
    assert again["failure"].values[1] == b["failure"]
    assert int(ds["units"].values[0]) == 2


def test_dst_point_case_reads_the_wyart_cates_curve():
    """The unstable-branch point φ = 0.54, σ_in = 2.5 σ* on a coarse, short run: ⟨γ̇⟩ within
    5 % of the steady curve (the validation's bound on 14 × 20 over 3 strain units)."""
    case = get_case("dst_point_phi0.54_sigma2.5_alpha0.02")
    assert isinstance(case, DSTPointCase)
    overrides = {"n_y": 8, "equilibration_strain": 0.5, "averaging_strain": 0.5}
    record = run_configuration(case, overrides)
    assert abs(record["signed_error"]) < 0.05
    assert record["n_steps"] > 0 and record["n_particles"] > 14 * 8
    assert record["n_y"] == 8 and math.isnan(record["number_density"])


def test_dst_channel_case_reads_the_local_channel_profile():
    """φ = 0.54, F H/σ* = 10 on a coarse lattice (n_y = 10): L2/peak within 3 % of the local
    model's ODE (measured 2.3 %; the validation holds 2 % from n_y = 16)."""
    case = get_case("dst_channel_phi0.54_force10")
    assert isinstance(case, DSTChannelCase)
    record = run_configuration(case, {"n_y": 10})
    assert 0 < record["error"] < 0.03
    assert record["n_steps"] > 0 and record["n_particles"] > 14 * 10
    with pytest.raises(InputError, match="unknown setting"):
        case.settings({"width": 2.0})


def test_dilute_suspension_case_holds_one_sphere_at_its_fraction():
    """The box of one sphere at φ = 0.03, rounded to whole spacings (12.97 h → 13.125 h at
    n = 4.096), a = 3.33 h at the finer setting; the reference is Batchelor–Green's."""
    case = get_case("suspension_dilute_phi0.03")
    assert isinstance(case, DiluteSuspensionCase)
    for radius, side in ((2.5, 13.125), (3.333, 17.5)):
        scene = case._scene(case.settings({"radius": radius}))
        assert scene.box == pytest.approx((side,) * 3)
        assert scene.inclusions.phi == 0.03 and scene.inclusions.radius == radius
        assert 4.0 * math.pi / 3.0 * radius ** 3 / side ** 3 == pytest.approx(0.03, rel=0.05)
    scene = case._scene(case.settings({"units": 8, "wi_target": 0.01}))
    assert scene.run.strain == 9.0 and scene.numerics.wi_target == 0.01
