"""The Snakemake workflow: config validation, drop-in materials, the fit stage and the smoke
study (fit, homogenisation, simulate, gather, plot) end to end, and what a change re-runs."""
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr
import yaml

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


def _run(cwd, *args, cores="1", env=None):
    return subprocess.run([*SNAKEMAKE, "--cores", cores, *args], cwd=cwd, capture_output=True,
                          text=True, env=env)


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


def test_a_box_without_a_whole_lattice_stops_before_any_job(tmp_path):
    study = _study(tmp_path, {"a": REPO / "data/carbopol_pg/matrix.csv"})
    (study / "config/box.yaml").write_text("simulation: {box: 17}\n")
    proc = _run(study, "-n", "--configfile", "config/box.yaml")
    assert proc.returncode != 0
    text = proc.stdout + proc.stderr
    assert "simulation.box = 17" in text and "multiples of the spacing 0.625 h" in text
    assert "rule fit_matrix" not in text


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


def _dry_jobs(proc, rule):
    """The wildcards of each job of ``rule`` in a dry run's listing, as dicts."""
    found, current = [], None
    for line in (proc.stdout + proc.stderr).splitlines():
        header = re.match(r"^(?:local)?rule (\w+):$", line)
        if header:
            current = header[1]
        elif current == rule and line.strip().startswith("wildcards: "):
            found.append(dict(item.split("=") for item in
                              line.strip().removeprefix("wildcards: ").split(", ")))
    return found


def _placeholders(study, *args):
    """Empty files for every output a dry run lists, then all marked up to date with their
    metadata recorded (snakemake --touch --forceall): what a finished study looks like to the
    next dry run, without running it. (Without the metadata a dry run does not see that gather
    needs a new run file: it finds the new column through the changed set of gather's inputs.)"""
    dry = _run(study, "-n", *args)
    for line in re.findall(r"^\s+output: (.*)$", dry.stdout + dry.stderr, re.MULTILINE):
        for name in line.split(", "):
            (study / name).parent.mkdir(parents=True, exist_ok=True)
            (study / name).touch()
    assert _run(study, "--touch", "--forceall", *args).returncode == 0


def test_spheres_study_packs_each_phi_and_seed_once_through_the_cache(tmp_path):
    study = _study(tmp_path / "a", {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"})
    cache = tmp_path / "cache"
    cache.mkdir()
    env = {**os.environ, "SNAKEMAKE_OUTPUT_CACHE": str(cache)}
    spheres = ["--configfile", "config/studies/spheres.yaml"]
    dry = _run(study, "-n", "--cache", *spheres, env=env)
    assert dry.returncode == 0, dry.stderr
    config = yaml.safe_load((study / "config/studies/spheres.yaml").read_text())["simulation"]
    packs = _dry_jobs(dry, "pack")
    wanted = {(f"{phi:g}", str(seed)) for phi in config["volume_fractions"] if phi > 0
              for seed in config["seeds"]}
    assert sorted((job["phi"], job["seed"]) for job in packs) == sorted(wanted)
    text = dry.stdout + dry.stderr
    assert text.count("will be written to global between-workflow cache") == len(wanted)
    runs = {(job["phi"], job["rate"], job["seed"]) for job in _dry_jobs(dry, "simulate")}
    assert len(runs) == len(_dry_jobs(dry, "simulate")) == (
        len(config["volume_fractions"]) * len(config["shear_rates"]) * len(config["seeds"]))
    # Packed once for real; a second workflow with the same settings (another material name:
    # wildcards are not part of the cache hash) takes the files from the cache.
    assert _run(study, "--cache", "--until", "pack", *spheres, env=env).returncode == 0
    packing = study / "results/spheres/linear_polymer/packings/phi-0.2_seed-1.nc"
    assert packing.is_symlink() and Path(os.readlink(packing)).parent == cache
    other = _study(tmp_path / "b", {"other": REPO / "data/linear_polymer/matrix.csv"})
    for path in (other / "config/studies/spheres.yaml",):
        path.write_text(path.read_text().replace("[linear_polymer]", "[other]"))
    dry = _run(other, "-n", "--cache", *spheres, env=env)
    assert (dry.stdout + dry.stderr).count("will be obtained from global between-workflow "
                                           "cache") == len(wanted)
    # A material sheet's particle settings are pack params: a new cache entry.
    (other / "data/other/material.yaml").write_text("particles: {polydispersity: 0.2}\n")
    dry = _run(other, "-n", "--cache", *spheres, env=env)
    assert (dry.stdout + dry.stderr).count("will be written to global between-workflow "
                                           "cache") == len(wanted)


def test_changing_one_volume_fraction_reruns_only_its_column(tmp_path):
    study = _study(tmp_path, {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"})
    spheres = ["--configfile", "config/studies/spheres.yaml"]
    _placeholders(study, *spheres)
    assert "Nothing to be done" in _run(study, "-n", *spheres).stdout
    config = study / "config/studies/spheres.yaml"
    text = config.read_text()
    config.write_text(text.replace("[0.0, 0.1, 0.2, 0.3]", "[0.0, 0.1, 0.2, 0.25]"))
    dry = _run(study, "-n", *spheres)
    rates = yaml.safe_load(text)["simulation"]["shear_rates"]
    assert _jobs(dry) == {"pack": 1, "simulate": len(rates), "gather": 1, "plot_summary": 1,
                          "all": 1}
    assert {job["phi"] for job in _dry_jobs(dry, "simulate")} == {"0.25"}


def test_friction_reruns_the_suspension_runs_but_not_their_packings(tmp_path):
    study = _study(tmp_path, {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"})
    spheres = ["--configfile", "config/studies/spheres.yaml"]
    _placeholders(study, *spheres)
    (study / "data/linear_polymer/material.yaml").write_text(
        "particles: {friction: 0.5, rolling_friction: 0.1}\n")
    dry = _run(study, "-n", *spheres)
    config = yaml.safe_load((study / "config/studies/spheres.yaml").read_text())["simulation"]
    suspensions = (sum(phi > 0 for phi in config["volume_fractions"])
                   * len(config["shear_rates"]) * len(config["seeds"]))
    assert _jobs(dry) == {"simulate": suspensions, "gather": 1, "plot_summary": 1, "all": 1}
    assert {job["phi"] for job in _dry_jobs(dry, "simulate")} == {
        f"{phi:g}" for phi in config["volume_fractions"] if phi > 0}


def test_a_suspension_run_goes_through_pack_and_simulate(tmp_path):
    study = _study(tmp_path, {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"})
    config = study / "config/studies/smoke.yaml"
    config.write_text(config.read_text().replace("volume_fractions: [0.0]",
                                                 "volume_fractions: [0.1]")
                      + "  inclusions: {radius: 1.0}\n")
    (study / "data/linear_polymer/material.yaml").write_text("particles: {radius_m: 5.0e-5}\n")
    target = "results/linear_polymer/runs/phi-0.1_rate-0.1_seed-1.nc"
    proc = _run(study, target, "--configfile", "config/studies/smoke.yaml")
    assert proc.returncode == 0, proc.stderr
    assert (study / "logs/pack/linear_polymer/phi-0.1_seed-1.log").exists()
    with xr.open_dataset(study / target) as run:
        assert float(run["phi"]) == 0.1 and float(run["body_count"]) >= 1
        assert float(run["inclusion_radius"]) == 1.0 and float(run["packing_seed"]) == 1
        assert float(run["particle_radius"]) == pytest.approx(5e-5)
        assert run.attrs["inclusion_shape"] == "sphere"
        assert json.loads(run.attrs["scene"])["inclusions"]["packing"] == (
            "results/linear_polymer/packings/phi-0.1_seed-1.nc")


def test_sand_study_packs_sand_grains_for_each_phi(tmp_path):
    study = _study(tmp_path, {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"})
    sand = ["--configfile", "config/studies/sand.yaml"]
    dry = _run(study, "-n", *sand)
    assert dry.returncode == 0, dry.stderr
    config = yaml.safe_load((study / "config/studies/sand.yaml").read_text())["simulation"]
    phis = [phi for phi in config["volume_fractions"] if phi > 0]
    assert sorted(job["phi"] for job in _dry_jobs(dry, "pack")) == [f"{p:g}" for p in phis]
    assert len(_dry_jobs(dry, "simulate")) == (len(config["volume_fractions"])
                                               * len(config["shear_rates"]))
    packing = "results/sand/linear_polymer/packings/phi-0.1_seed-1.nc"
    assert _run(study, packing, *sand).returncode == 0
    with xr.open_dataset(study / packing) as pack:
        assert pack.attrs["shape"] == "sand" and list(pack.attrs["box"]) == [16.875] * 3
        # the box holds 4 support radii + 0.1 h (the packer's rule) of these elongated grains,
        # which reach beyond the volume-equivalent radius of 2.5 h
        support = float(pack["support_radius"].max())
        assert 2.5 < support and 4 * support + 0.1 <= 16.875
        assert pack.sizes["body"] >= 1


def test_a_study_with_its_own_results_folder_logs_apart(tmp_path):
    study = _study(tmp_path, {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"})
    dry = _run(study, "-n", "--configfile", "config/studies/sand.yaml")
    logs = re.findall(r"^\s+log: (.*)$", dry.stdout + dry.stderr, re.MULTILINE)
    assert logs and all(path.startswith("logs/sand/") for path in logs)
