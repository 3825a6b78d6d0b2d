"""The Snakemake workflow: config validation, drop-in materials, the fit stage and the smoke
study (fit, homogenisation, simulate, gather, plot) end to end, and what a change re-runs."""
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr

REPO = Path(__file__).resolve().parents[2]
SNAKEMAKE = [sys.executable, "-m", "snakemake"]


def _study(tmp_path, materials):
    """A copy of the workflow with a data folder holding the given {name: matrix file}."""
    tmp_path.mkdir(parents=True, exist_ok=True)
    for item in ("Snakefile", "workflow", "config"):
        src = REPO / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp_path / item)
    for name, matrix in materials.items():
        folder = tmp_path / "data" / name
        folder.mkdir(parents=True)
        shutil.copy(matrix, folder / f"matrix{matrix.suffix}")
    return tmp_path


def _run(cwd, *args, cores="1"):
    return subprocess.run([*SNAKEMAKE, "--cores", cores, *args], cwd=cwd, capture_output=True,
                          text=True)


def _fit_targets(name):
    return [f"results/{name}/fit.json", f"results/{name}/fit.png"]


def _jobs(proc):
    """{rule: count} from the job-stats table of a (dry) run; empty when nothing is to be done."""
    text = proc.stdout + proc.stderr
    table = text.partition("Job stats:")[2].partition("\n\n")[0]
    return {m[1]: int(m[2]) for m in re.finditer(r"^(\w+)\s+(\d+)$", table, re.MULTILINE)
            if m[1] != "total"}


def test_dry_run_lists_one_fit_per_material(tmp_path):
    study = _study(tmp_path, {"a": REPO / "data/carbopol_pg/matrix.csv",
                              "b": REPO / "data/linear_polymer/matrix.csv"})
    proc = _run(study, "-n")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.count("rule fit_matrix") + proc.stderr.count("rule fit_matrix") == 2


def test_fit_stage_end_to_end_and_cached(tmp_path):
    study = _study(tmp_path, {"poly": REPO / "data/linear_polymer/matrix.csv"})
    proc = _run(study, *_fit_targets("poly"))
    assert proc.returncode == 0, proc.stderr
    report = json.loads((study / "results/poly/fit.json").read_text())
    assert report["law"] in ("cross", "carreau_yasuda") and report["rms_log_residual"] < 0.05
    assert (study / "results/poly/fit.png").stat().st_size > 10_000
    assert (study / "logs/fit_matrix/poly.log").exists()
    # A second run has nothing to do; a new material dropped in adds exactly one job.
    again = _run(study, "-n", *_fit_targets("poly"))
    assert "Nothing to be done" in again.stdout + again.stderr
    (study / "data/new").mkdir()
    shutil.copy(REPO / "data/carbopol_pg/matrix.csv", study / "data/new/matrix.csv")
    dry = _run(study, "-n")
    assert (dry.stdout + dry.stderr).count("rule fit_matrix") == 1


def test_invalid_config_is_rejected(tmp_path):
    study = _study(tmp_path, {"a": REPO / "data/carbopol_pg/matrix.csv"})
    (study / "config/config.yaml").write_text("fit: {law: bingham}\n")
    proc = _run(study, "-n")
    assert proc.returncode != 0
    assert "bingham" in proc.stdout + proc.stderr


def test_bad_matrix_file_fails_the_job_with_a_clear_log(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("Shear rate [1/s],Shear stress [Pa]\n1,2\n2,oops\n", encoding="utf-8")
    study = _study(tmp_path / "study", {"bad": bad})
    proc = _run(study)
    assert proc.returncode != 0
    assert not (study / "results/bad/fit.json").exists()
    log = (study / "logs/fit_matrix/bad.log").read_text()
    assert "matrix.csv:3" in log


def test_smoke_study_end_to_end_then_nothing_then_only_the_changed_rate(tmp_path):
    study = _study(tmp_path, {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"})
    smoke = ["--configfile", "config/studies/smoke.yaml"]
    proc = _run(study, *smoke, cores="2")
    assert proc.returncode == 0, proc.stderr
    results = study / "results/linear_polymer"
    with xr.open_dataset(results / "summary.nc") as summary:
        assert summary["suspension_viscosity"].dims == ("phi", "shear_rate", "seed")
        assert summary["shear_rate"].values.tolist() == [0.1, 10.0]
        assert summary["suspension_viscosity"].attrs["units"] == "Pa s"
        # The matrix alone must reproduce the fitted law (SPEC §2.3: within a few per cent).
        assert abs(summary["relative_viscosity"].values - 1).max() < 0.03
    assert (results / "summary.png").stat().st_size > 10_000
    for rule in ("simulate/linear_polymer/phi-0_rate-0.1_seed-1", "gather/linear_polymer",
                 "plot_summary/linear_polymer"):
        assert (study / f"logs/{rule}.log").exists()
        assert (study / f"logs/benchmarks/{rule}.tsv").exists()
    # The job's threads (config simulation.threads = 1) reach numba.
    assert "on 1 thread(s)" in (study / "logs/simulate/linear_polymer/"
                                        "phi-0_rate-0.1_seed-1.log").read_text()
    dry = _run(study, "-n", *smoke)
    assert "Nothing to be done" in dry.stdout + dry.stderr
    config = study / "config/studies/smoke.yaml"
    config.write_text(config.read_text().replace("[0.1, 10.0]", "[0.1, 20.0]"))
    assert _jobs(_run(study, "-n", *smoke)) == {"simulate": 1, "gather": 1, "plot_summary": 1,
                                                "all": 1}


def test_volume_fraction_above_zero_fails_its_job_naming_the_missing_capability(tmp_path):
    study = _study(tmp_path, {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"})
    config = study / "config/studies/smoke.yaml"
    config.write_text(config.read_text().replace("volume_fractions: [0.0]",
                                                 "volume_fractions: [0.3]"))
    target = "results/linear_polymer/runs/phi-0.3_rate-0.1_seed-1.nc"
    proc = _run(study, target, "--configfile", "config/studies/smoke.yaml")
    assert proc.returncode != 0
    log = (study / "logs/simulate/linear_polymer/phi-0.3_rate-0.1_seed-1.log").read_text()
    assert "rigid inclusions" in log
