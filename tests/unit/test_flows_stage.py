"""The flows study's stages (seed 000 Figs. 1-2): jobs from the config, the channel law of each
Bingham number against the Poiseuille reference, the run Dataset, gathering and figures, on
synthetic runs (the reference itself, or scaled) instead of simulations."""
import functools
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from matplotlib.figure import Figure

from suspsim.errors import InputError
from suspsim.plotting.poiseuille import half_channel, plot_poiseuille
from suspsim.reference.poiseuille import bingham_number, poiseuille_profile
from suspsim.rheology.laws import make_law
from suspsim.scene import scene_from_dict
from suspsim.stages.flows import (channel_dataset, channel_law, find_poiseuille_job,
                                  plastic_time, poiseuille_jobs, poiseuille_scene, startup_job)
from suspsim.stages.flows_figures import write_flows_figure
from suspsim.stages.flows_gather import read_flows, write_flows
from test_plot_startup import fake_startup

REPO = Path(__file__).resolve().parents[2]
#: The schema defaults of the poiseuille block (W = 15 h, 2D, n = 16, Re = 2.28), small lists.
BLOCK = {"binghams": [0.0, 10.0], "dimension": 2, "number_density": 16.0, "width": 15.0,
         "lateral": 3.75, "reynolds": 2.28, "plastic_viscosity": 20 / 4.096, "start": "rest",
         "run_time": 0.6, "averaging": 0.15, "jitter": 0.1, "seed": 1}


def validated_config(study):
    """config.yaml under ``study`` (None: config.yaml alone) with the schema defaults, as the
    workflow sees it."""
    from snakemake.utils import validate

    config = yaml.safe_load((REPO / "config/config.yaml").read_text())
    if study:
        config.update(yaml.safe_load((REPO / f"config/studies/{study}.yaml").read_text()))
    validate(config, str(REPO / "workflow/schemas/config.schema.yaml"))
    return config


def _flows_block(study):
    """The flows block of :func:`validated_config`."""
    return validated_config(study)["flows"]


def test_default_config_runs_nothing_and_the_study_configs_list_their_runs():
    assert startup_job(_flows_block(None)) is None and poiseuille_jobs(_flows_block(None)) == []
    full = _flows_block("flows")
    assert [job["bingham"] for job in poiseuille_jobs(full)] == [0.0, 1.0, 5.0, 10.0]
    assert startup_job(full) == {"bingham": 0.1, "side": 7.5, "number_density": 4.096,
                                 "strains": [0.05, 0.1, 0.2, 0.4, 1.0, 3.0], "jitter": 0.1,
                                 "seed": 1}
    smoke = _flows_block("flows_smoke")
    assert startup_job(smoke)["side"] == 5.0 and poiseuille_jobs(smoke)[1]["width"] == 5.0


def test_jobs_reject_repeats_and_an_averaging_longer_than_the_run():
    with pytest.raises(InputError, match="listed twice"):
        poiseuille_jobs({"poiseuille": {**BLOCK, "binghams": [1, 1.0]}})
    with pytest.raises(InputError, match="averaging"):
        poiseuille_jobs({"poiseuille": {**BLOCK, "averaging": 0.7}})
    with pytest.raises(InputError, match="listed twice"):
        startup_job({"startup": {"strains": [0.1, 0.1]}})
    with pytest.raises(InputError, match="no channel run at Bn = 5"):
        find_poiseuille_job({"poiseuille": BLOCK}, 5.0)
    assert find_poiseuille_job({"poiseuille": BLOCK}, 10.0)["bingham"] == 10.0


@pytest.mark.parametrize("bingham", [1.0, 5.0, 10.0])
def test_channel_law_has_its_bingham_number_reynolds_number_and_seed_ratio(bingham):
    job = {**BLOCK, "bingham": bingham}
    name, params, force, newtonian = channel_law(job)
    law = make_law(name, params)
    width, rho = BLOCK["width"], BLOCK["number_density"]
    assert bingham_number(law, force, width) == pytest.approx(bingham, rel=1e-10)
    assert params["mu_0"] / params["mu_pl"] == pytest.approx(99.0)
    assert params["mu_pl"] == pytest.approx(BLOCK["plastic_viscosity"] * rho)
    # Re = rho U W/mu_pl with U the ideal fluid's centre-line velocity; Bingham ideal fluid:
    # U = (F/mu_pl) (W/2)^2 (1 - xi)^2/2, xi = tau_y/sigma_w.
    xi = params["mu_0"] / params["M"] / (force * width / 2)
    ideal = force / params["mu_pl"] * (width / 2) ** 2 * (1 - xi) ** 2 / 2
    assert rho * ideal * width / params["mu_pl"] == pytest.approx(BLOCK["reynolds"], rel=1e-10)
    assert newtonian == pytest.approx(force * width ** 2 / (8 * params["mu_pl"]))
    # The regularised fluid flows faster than the ideal one: its viscosity
    # μ_pl + τ_y (1 − e^(−Mγ̇))/γ̇ is below the ideal μ_pl + τ_y/γ̇ at every rate.
    assert poiseuille_profile(law, force, width, width / 2) > ideal


def test_bingham_10_channel_is_the_validation_run_and_bn_0_the_newtonian_parabola():
    _, params, _, _ = channel_law({**BLOCK, "bingham": 10.0})
    # suspsim.validation.flows.bingham_law(16), the 2D validation channel: mu_pl = 78.125,
    # mu_0 = 99 mu_pl, M = 100 (W = 15 h; there Re follows from M, here M from Re = 2.28).
    assert params["mu_pl"] == pytest.approx(78.125)
    assert params["M"] == pytest.approx(100.0, rel=1e-3)
    name, params, force, newtonian = channel_law({**BLOCK, "bingham": 0.0})
    assert name == "newtonian"
    law = make_law(name, params)
    assert poiseuille_profile(law, force, BLOCK["width"], BLOCK["width"] / 2) == pytest.approx(
        newtonian, rel=1e-10)
    assert BLOCK["number_density"] * newtonian * BLOCK["width"] / params["mu"] == pytest.approx(
        BLOCK["reynolds"])


def test_scene_is_the_split_force_box_run_for_its_plastic_times():
    job = {**BLOCK, "bingham": 10.0}
    scene = scene_from_dict(poiseuille_scene(job))
    assert scene.box == (3.75, 30.0) and scene.flow.type == "poiseuille"
    _, _, force, _ = channel_law(job)
    assert scene.density * scene.flow.body_force == pytest.approx(force)
    assert plastic_time(job) == pytest.approx(15.0 ** 2 * 4.096 / 20)
    assert scene.total_time == pytest.approx(0.6 * plastic_time(job))
    three_d = scene_from_dict(poiseuille_scene({**job, "dimension": 3, "number_density": 4.096}))
    assert three_d.box == (3.75, 30.0, 3.75)


def synthetic_run(bingham, factor=1.0, width=5.0):
    """A channel run Dataset whose 'SPH' profile is ``factor`` × the reference at the bins."""
    return _synthetic_run(bingham, factor, width).copy(deep=True)


@functools.cache
def _synthetic_run(bingham, factor, width):
    job = {**BLOCK, "bingham": bingham, "width": width}
    scene = scene_from_dict(poiseuille_scene(job))
    y = (np.arange(8) + 0.5) * 2 * width / 8
    _, _, force, _ = channel_law(job)
    from suspsim.reference.poiseuille import split_force_poiseuille_profile

    reference = split_force_poiseuille_profile(scene.fluid.law, force, 2 * width, y)
    data = channel_dataset(job, scene, y, factor * reference, reference)
    data.attrs.update(n_particles=600, dt=1e-4, sound_speed=50.0, steps=10, threads=1,
                      wall_time_s=1.5)
    return data


def test_run_dataset_has_units_the_error_and_the_fine_reference():
    data = synthetic_run(1.0, factor=1.02)
    assert data.attrs["profile_error"] == pytest.approx(
        0.02 * np.sqrt(np.mean(data["reference_velocity"].values ** 2))
        / np.abs(data["reference_velocity"]).max())
    for name in data.variables:
        assert data[name].attrs["units"] == "1", name
    assert data["velocity"].attrs["simulation_units"] == "h tau-1"
    fine = data["reference_velocity_fine"].values
    assert fine[0] == fine[-1] == 0.0 and fine.max() == pytest.approx(-fine.min())
    assert data.attrs["yield_stress"] == pytest.approx(data.attrs["law_mu_0"]
                                                       / data.attrs["law_M"])
    assert np.isnan(synthetic_run(0.0).attrs["regularisation_time"])


def _write_runs(tmp_path, runs):
    paths = []
    for k, run in enumerate(runs):
        paths.append(tmp_path / f"run{k}.nc")
        run.to_netcdf(paths[-1], engine="netcdf4")
    return paths


def test_gather_puts_the_runs_on_bingham_and_the_startup_beside_them(tmp_path):
    runs = _write_runs(tmp_path, [synthetic_run(0.0), synthetic_run(1.0, factor=1.02)])
    startup = tmp_path / "startup.nc"
    fake_startup(0.01).to_netcdf(startup, engine="netcdf4")
    out = tmp_path / "flows.nc"
    write_flows(out, startup=startup, poiseuille=runs, command="test")
    with xr.open_dataset(out) as root:
        assert root.attrs["groups"] == "startup poiseuille"
        assert root.attrs["Conventions"] == "CF-1.10" and "test" in root.attrs["history"]
    parts = read_flows(out)
    channel = parts["poiseuille"]
    assert channel["bingham"].values.tolist() == [0.0, 1.0]
    assert channel["velocity"].dims == ("bingham", "y")
    np.testing.assert_allclose(channel["profile_error"],
                               [0.0, synthetic_run(1.0, factor=1.02).attrs["profile_error"]])
    assert channel["yield_stress"].attrs["simulation_units"] == "m tau-2"
    assert channel["force_density"].attrs["simulation_units"] == "m h-1 tau-2"
    assert channel["wall_time"].attrs["units"] == "s"
    assert "profile_error" not in channel.attrs and channel.attrs["laws"] == (
        "newtonian papanastasiou")
    xr.testing.assert_allclose(parts["startup"]["velocity"], fake_startup(0.01)["velocity"])


def test_gather_refuses_runs_of_different_channels_and_nothing(tmp_path):
    runs = _write_runs(tmp_path, [synthetic_run(0.0), synthetic_run(1.0, width=6.0)])
    with pytest.raises(InputError, match="run1.nc.*channel_width"):
        write_flows(tmp_path / "flows.nc", poiseuille=runs)
    with pytest.raises(InputError, match="nothing to gather"):
        write_flows(tmp_path / "flows.nc")
    assert not (tmp_path / "flows.nc").exists()


def test_figures_from_the_gathered_file(tmp_path):
    runs = _write_runs(tmp_path, [synthetic_run(0.0), synthetic_run(1.0, factor=1.02)])
    out = tmp_path / "flows.nc"
    write_flows(out, poiseuille=runs, command="test")
    write_flows_figure(out, "poiseuille", tmp_path / "poiseuille.png")
    assert (tmp_path / "poiseuille.png").stat().st_size > 10_000
    with pytest.raises(InputError, match="no startup group"):
        write_flows_figure(out, "startup", tmp_path / "startup.png")
    with pytest.raises(ValueError, match="unknown flows figure"):
        write_flows_figure(out, "squeeze", tmp_path / "squeeze.png")


def test_half_channel_folds_the_reversed_upper_half_onto_the_lower():
    y = np.array([0.5, 2.5, 4.5, 5.5, 7.5, 9.5])
    u = np.array([1.0, 2.0, 1.0, -1.0, -2.0, -1.0])
    x, folded = half_channel(y, u, 5.0)
    np.testing.assert_allclose(x, [-0.4, 0.0, 0.4, -0.4, 0.0, 0.4])
    np.testing.assert_allclose(folded, [1.0, 2.0, 1.0, 1.0, 2.0, 1.0])


def test_plot_poiseuille_normalises_by_the_newtonian_maximum(tmp_path):
    runs = _write_runs(tmp_path, [synthetic_run(0.0), synthetic_run(1.0, factor=1.02)])
    write_flows(tmp_path / "flows.nc", poiseuille=runs, command="test")
    data = read_flows(tmp_path / "flows.nc")["poiseuille"]
    fig = plot_poiseuille(data)
    assert isinstance(fig, Figure)
    lines = fig.axes[0].get_lines()
    assert len(lines) == 2 * data.sizes["bingham"]  # a reference line and markers per Bn
    # Bn = 0: the parabola of peak 1; the plug of Bn = 1 is slower.
    assert lines[0].get_ydata().max() == pytest.approx(1.0, rel=1e-4)
    assert lines[2].get_ydata().max() < 0.7
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    error = 100 * float(data["profile_error"][1])
    assert 0.5 < error < 2 and labels == ["Bn = 0: L2/peak = 0.0 %",
                                          f"Bn = 1: L2/peak = {error:.1f} %"]


def test_unhealthy_startup_stops_and_writes_nothing(tmp_path, monkeypatch):
    """A start-up that ended outside its health limits raises NumericalError with the health
    message, and leaves no run file (its profiles would be a blow-up's)."""
    from suspsim.errors import NumericalError
    from suspsim.stages import flows

    blown = fake_startup(0.0)
    blown.attrs.update(healthy=0, health="Mach number 0.4 exceeds run.max_mach 0.3 at step 9")
    monkeypatch.setattr(flows, "papanastasiou_startup", lambda **job: blown)
    out = tmp_path / "startup.nc"
    with pytest.raises(NumericalError, match="Bn 0.1: Mach number 0.4 exceeds run.max_mach"):
        flows.simulate_startup(startup_job(_flows_block("flows_smoke")), out)
    assert list(tmp_path.iterdir()) == []
