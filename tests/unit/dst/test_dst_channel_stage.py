"""The dst study's channel stage: jobs from the config block, gathering one-force runs into
groups, and its figures (synthetic runs from the local ODE, see test_channel_study)."""
import json

import numpy as np
import pytest
import xarray as xr

from suspsim.errors import InputError
from suspsim.stages.dst_channel import channel_jobs, encoding, find_channel_job
from suspsim.stages.dst_channel_gather import (gather_channel_set, read_groups,
                                               write_channel_figures, write_channel_sets)
from test_channel_study import RATIOS, synthetic

FLUID = {"phi_m": 0.562, "phi_0": 0.693, "beta": 2.0, "K_f": 1.0}
CHANNEL = {"phi": 0.54, "forces": [1.0, 10.0, 100.0], "profile_forces": [1.0, 10.0],
           "lattice": [14, 20], "sets": [{"name": "local", "alpha": 0.0},
                                         {"name": "fig8", "alpha": 0.02, "phi_m": 0.56,
                                          "phi_0": 0.64}]}


def settings(**channel):
    return {"fluid": FLUID, "channel": {**CHANNEL, **channel}}


def test_one_job_per_set_and_force_with_the_study_fluid_where_a_set_gives_none():
    jobs = channel_jobs(settings())
    assert [(j.name, j.index, j.force_ratio) for j in jobs] == [
        (name, k, f) for name in ("local", "fig8") for k, f in enumerate(CHANNEL["forces"])]
    local, fig8 = jobs[0].sweep, jobs[-1].sweep
    assert (local["phi_m"], local["phi_0"], local["alpha"]) == (0.562, 0.693, 0.0)
    assert (fig8["phi_m"], fig8["phi_0"], fig8["alpha"]) == (0.56, 0.64, 0.02)
    assert local["beta"] == 2.0 and local["K_f"] == 1.0 and local["lattice"] == [14, 20]
    assert find_channel_job(settings(), "fig8", 2) == jobs[-1]
    with pytest.raises(InputError, match="no channel run 'fig8' with force index 3"):
        find_channel_job(settings(), "fig8", 3)


@pytest.mark.parametrize("block", [None, {}, {"sets": []}])
def test_no_sets_no_jobs(block):
    assert channel_jobs({"fluid": FLUID} if block is None else
                        {"fluid": FLUID, "channel": block}) == []


@pytest.mark.parametrize("change, key", [
    ({"forces": [1.0, 1.0]}, "forces"),
    ({"profile_forces": [1.0, 50.0]}, "profile_forces"),
    ({"sets": [{"name": "a", "alpha": 0.0}, {"name": "a", "alpha": 0.02}]}, "name")])
def test_bad_blocks_name_the_key(change, key):
    with pytest.raises(InputError) as err:
        channel_jobs(settings(**change))
    assert err.value.key == key


def _runs(data):
    """One single-force Dataset per force, as simulate_channel_point writes them."""
    runs = []
    for k in range(data.sizes["force_ratio"]):
        run = data.isel(force_ratio=[k])
        run.attrs = {**data.attrs, "wall_time_s": float(data["wall_time"][k]),
                     "configuration": json.dumps({**json.loads(data.attrs["configuration"]),
                                                  "force_ratios": [float(RATIOS[k])]})}
        runs.append(run)
    return runs


def test_gathered_set_equals_the_sweep_of_all_forces():
    whole = synthetic()
    gathered = gather_channel_set(_runs(whole), [f"run{k}.nc" for k in range(len(RATIOS))])
    xr.testing.assert_identical(gathered.drop_attrs(), whole.drop_attrs())
    assert gathered.attrs["wall_time_s"] == pytest.approx(float(whole["wall_time"].sum()))
    assert json.loads(gathered.attrs["configuration"])["force_ratios"] == RATIOS.tolist()
    assert gathered.attrs["alpha"] == whole.attrs["alpha"]


def test_a_run_of_another_fluid_is_refused_naming_its_file():
    runs = _runs(synthetic())
    runs[2].attrs["alpha"] = 0.02
    with pytest.raises(InputError, match="alpha") as err:
        gather_channel_set(runs, ["a.nc", "b.nc", "c.nc", "d.nc"])
    assert err.value.source == "c.nc"


def test_sets_round_trip_through_groups_and_draw(tmp_path):
    files = {}
    for name, alpha in (("local", 0.0), ("strong", 0.02)):
        files[name] = []
        for k, run in enumerate(_runs(synthetic(alpha=alpha))):
            path = tmp_path / f"{name}_force-{k:02d}.nc"
            run.to_netcdf(path, encoding=encoding())
            files[name].append(path)
    out = tmp_path / "channel.nc"
    write_channel_sets(files, out, command="test")
    sets = read_groups(out)
    assert list(sets) == ["local", "strong"]
    np.testing.assert_array_equal(sets["strong"]["force_ratio"], RATIOS)
    assert sets["strong"].attrs["alpha"] == 0.02
    with xr.open_dataset(out) as root:
        assert root.attrs["groups"] == "local strong" and root.attrs["completed"] == 1
    figures = {"profiles": tmp_path / "p.png", "flow": tmp_path / "f.png"}
    write_channel_figures(out, figures, profile_forces=[1.0, 10.0])
    assert all(path.stat().st_size > 10_000 for path in figures.values())
    with pytest.raises(InputError, match="cannot read the channel sets"):
        read_groups(tmp_path / "p.png")
