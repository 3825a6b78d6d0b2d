"""The bingham_suspension study (seed 000 Fig. 3) in the Snakemake workflow: the jobs its
config lists, and (slow) the smoke study end to end.

Slow; the smoke study (``config/studies/bingham_suspension_smoke.yaml``: φ = 0.2 of a = 2 h
spheres in a 10 h box, x = 1, strain 1) is already the reduced size, so
``SUSPSIM_REDUCED=1`` runs it as it is.
"""
import numpy as np
import pytest
import xarray as xr

from suspsim.stages.bingham_suspension_gather import cot_relative_viscosity, read_suspension
from test_snakemake import _dry_jobs, _jobs, _run, _study


def test_study_lists_a_packing_a_newtonian_run_and_one_run_per_rate_for_each_seed(tmp_path):
    study = _study(tmp_path, {})
    dry = _run(study, "-n", "--configfile", "config/studies/bingham_suspension.yaml")
    assert dry.returncode == 0, dry.stderr
    assert _jobs(dry) == {"pack_bingham_suspension": 3, "simulate_bingham_suspension": 36,
                          "gather_bingham_suspension": 1, "plot_bingham_suspension": 1,
                          "all": 1}
    cases = sorted(job["case"] for job in _dry_jobs(dry, "simulate_bingham_suspension"))
    assert cases == sorted(3 * ["newtonian", "x-0.01", "x-0.0316", "x-0.1", "x-0.316", "x-1",
                                "x-3.16", "x-10", "x-31.6", "x-100", "x-316", "x-1000"])
    text = dry.stdout + dry.stderr
    assert "results/bingham_suspension/fig3.png" in text
    for seed in (1, 2, 3):
        assert f"results/bingham_suspension/packings/seed-{seed}.nc" in text


def test_default_config_lists_no_bingham_suspension_job(tmp_path):
    study = _study(tmp_path, {})
    config = study / "config/config.yaml"
    config.write_text(config.read_text().replace("material_study: true",
                                                 "material_study: false"))
    dry = _run(study, "-n")
    assert dry.returncode == 0, dry.stderr
    assert not any("bingham" in rule for rule in _jobs(dry))


def test_repeated_rate_stops_the_workflow_naming_the_key(tmp_path):
    study = _study(tmp_path, {})
    config = study / "config/studies/bingham_suspension_smoke.yaml"
    config.write_text(config.read_text().replace("rates: [1]", "rates: [1, 1.0]"))
    dry = _run(study, "-n", "--configfile", "config/studies/bingham_suspension_smoke.yaml")
    text = dry.stdout + dry.stderr
    assert dry.returncode != 0
    assert "bingham_suspension.rates" in text and "listed twice" in text


@pytest.mark.slow
def test_smoke_study_end_to_end(tmp_path):
    study = _study(tmp_path, {})
    args = ("--configfile", "config/studies/bingham_suspension_smoke.yaml")
    proc = _run(study, *args)
    assert proc.returncode == 0, proc.stderr
    results = study / "results/bingham_suspension"
    data = read_suspension(results / "suspension.nc")
    assert data["rate"].values.tolist() == [1.0] and data["seed"].values.tolist() == [1]
    g = float(data["newtonian_relative_viscosity_mean"])
    # phi = 0.2 in a Newtonian matrix: above Einstein's 1 + 2.5 phi = 1.5, below
    # Krieger-Dougherty with phi_m = 0.57 plus a margin for the 1-strain average (1.85).
    assert 1.4 < g < 2.3, g
    eta = data["relative_viscosity"].values[:, 0]
    assert np.all(np.isfinite(eta)) and np.all(eta > 1.0), eta
    # The gathered COT numbers are the formula's at the file's own g.
    np.testing.assert_allclose(data["cot_relative_viscosity"].values, cot_relative_viscosity(
        data["rate"].values, 99.0, 0.2, g), rtol=1e-12)
    np.testing.assert_allclose(data["plastic_relative_viscosity"].values,
                               eta[:, None] * data["matrix_plastic_ratio"].values[:, None])
    assert data["plastic_viscosity"].attrs["simulation_units"] == "m h-1 tau-1"
    assert data.attrs["completed"] == 1 and data.attrs["packing_volume_fraction"] == \
        pytest.approx(0.2, abs=1e-9)
    # The Newtonian and the Papanastasiou runs of the seed share the packing file.
    for name in ("newtonian_seed-1", "x-1_seed-1"):
        with xr.open_dataset(results / f"runs/{name}.nc") as run:
            assert "packings/seed-1.nc" in run.attrs["scene"], name
    assert (results / "fig3.png").stat().st_size > 10_000
    for rule in ("pack_bingham_suspension/seed-1", "simulate_bingham_suspension/x-1_seed-1",
                 "gather_bingham_suspension/gather_bingham_suspension",
                 "plot_bingham_suspension/plot_bingham_suspension"):
        assert (study / f"logs/{rule}.log").exists()
        assert (study / f"logs/benchmarks/{rule}.tsv").exists()
    # The job's threads (bingham_suspension.threads = 1) reach numba.
    assert "on 1 thread(s)" in (study / "logs/simulate_bingham_suspension/x-1_seed-1.log"
                                ).read_text()
    assert "Nothing to be done" in _run(study, "-n", *args).stdout
