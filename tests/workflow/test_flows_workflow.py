"""The flows study (seed 000 Figs. 1-2) in the Snakemake workflow: the jobs its config lists,
and (slow) the smoke study end to end against the 1D references.

Slow; ``SUSPSIM_REDUCED=1`` (CI) runs ``config/studies/flows_smoke.yaml`` as it is (start-up in
a 5 h box, channels at Bn = 0 and 1, W = 5 h), otherwise with the start-up at the full 7.5 h.
"""
import os

import numpy as np
import pytest
import xarray as xr

from suspsim.stages.flows_gather import read_flows
from suspsim.validation.startup import profile_error
from test_snakemake import _dry_jobs, _jobs, _run, _study

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"


def test_flows_study_lists_the_startup_one_channel_per_bingham_and_nothing_else(tmp_path):
    study = _study(tmp_path, {})
    dry = _run(study, "-n", "--configfile", "config/studies/flows.yaml")
    assert dry.returncode == 0, dry.stderr
    assert _jobs(dry) == {"simulate_startup": 1, "simulate_poiseuille": 4, "gather_flows": 1,
                          "plot_flows": 1, "all": 1}
    assert sorted(job["bingham"] for job in _dry_jobs(dry, "simulate_poiseuille")) == [
        "0", "1", "10", "5"]
    text = dry.stdout + dry.stderr
    assert "results/flows/startup.png" in text and "results/flows/poiseuille.png" in text


@pytest.mark.slow
def test_flows_smoke_study_end_to_end_against_the_references(tmp_path):
    study = _study(tmp_path, {})
    config = study / "config/studies/flows_smoke.yaml"
    if not REDUCED:
        config.write_text(config.read_text().replace("side: 5.0", "side: 7.5"))
    args = ("--configfile", "config/studies/flows_smoke.yaml")
    proc = _run(study, *args)
    assert proc.returncode == 0, proc.stderr
    results = study / "results/flows"
    parts = read_flows(results / "flows.nc")
    startup = parts["startup"]
    assert startup.attrs["healthy"] == 1
    # Seed 000 Fig. 1 against the 1D start-up: max |v_SPH − v_1D|/(γ̇L) over bins, largest at
    # the first strain (tests/validation/test_sph_flows.py: 0.016–0.021, bound 0.025).
    error = profile_error(startup)
    assert float(error.max()) < 0.025, error.values
    assert startup["velocity"].attrs["simulation_units"] == "h tau-1"
    # Seed 000 Fig. 2: 2D channels at n = 16, W = 5 h within the validation's 3 % L2/peak
    # (measured there: Bn = 1 1.3 %).
    channel = parts["poiseuille"]
    assert channel["bingham"].values.tolist() == [0.0, 1.0]
    assert np.all(channel["profile_error"].values < 0.03), channel["profile_error"].values
    # the plug: Bn = 1 peaks below the Newtonian maximum under its force
    peaks = channel["velocity"].max("y") / channel["newtonian_velocity"]
    assert peaks.values[1] < 0.6 < 0.95 < peaks.values[0]
    assert channel["newtonian_velocity"].attrs["simulation_units"] == "h tau-1"
    for name in ("startup", "poiseuille"):
        assert (results / f"{name}.png").stat().st_size > 10_000
    for rule in ("simulate_startup/startup", "simulate_poiseuille/bn-1",
                 "gather_flows/gather_flows", "plot_flows/plot_flows"):
        assert (study / f"logs/{rule}.log").exists()
        assert (study / f"logs/benchmarks/{rule}.tsv").exists()
    # The job's threads (flows.threads = 1) reach numba.
    assert "on 1 thread(s)" in (study / "logs/simulate_poiseuille/bn-1.log").read_text()
    with xr.open_dataset(results / "flows.nc") as root:
        assert root.attrs["groups"] == "startup poiseuille" and root.attrs["completed"] == 1
    assert "Nothing to be done" in _run(study, "-n", *args).stdout
