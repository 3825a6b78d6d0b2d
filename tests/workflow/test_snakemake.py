"""The Snakemake workflow: config validation, drop-in materials, the fit stage end to end."""
import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

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


def _run(cwd, *args):
    return subprocess.run([*SNAKEMAKE, "--cores", "1", *args], cwd=cwd, capture_output=True, text=True)


def test_dry_run_lists_one_fit_per_material(tmp_path):
    study = _study(tmp_path, {"a": REPO / "data/carbopol_pg/matrix.csv",
                              "b": REPO / "data/linear_polymer/matrix.csv"})
    proc = _run(study, "-n")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.count("rule fit_matrix") + proc.stderr.count("rule fit_matrix") == 2


def test_fit_stage_end_to_end_and_cached(tmp_path):
    study = _study(tmp_path, {"poly": REPO / "data/linear_polymer/matrix.csv"})
    proc = _run(study)
    assert proc.returncode == 0, proc.stderr
    report = json.loads((study / "results/poly/fit.json").read_text())
    assert report["law"] in ("cross", "carreau_yasuda") and report["rms_log_residual"] < 0.05
    assert (study / "results/poly/fit.png").stat().st_size > 10_000
    assert (study / "logs/fit_matrix/poly.log").exists()
    # A second run has nothing to do; a new material dropped in adds exactly one job.
    assert "Nothing to be done" in _run(study, "-n").stdout + _run(study, "-n").stderr
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
