"""The SLURM profile (workflow/profiles/slurm): every rule has its resources, and the smoke study
run through a real one-node SLURM (tests/workflow/slurm_cluster.py) gives the local summary.nc."""
import importlib.util
import os
import re
import subprocess
import tempfile
import time

import numpy as np
import pytest
import xarray as xr
import yaml

from slurm_cluster import OneNodeCluster, missing_binaries, process_start_time
from test_snakemake import REPO, SNAKEMAKE, _study

PROFILE = REPO / "workflow/profiles/slurm"
# Differ between any two runs by design: the runs' wall-clock times and the gather's time stamp.
WALL_TIME_VARIABLES = {"wall_time"}
TIME_STAMP_ATTRS = {"history"}


def _profile():
    return yaml.safe_load((PROFILE / "config.yaml").read_text())


def _rules():
    """Every rule of workflow/rules/ that runs a job (the Snakefile's `all` only collects),
    including those derived with `use rule ... as NAME`."""
    text = "".join(p.read_text() for p in sorted((REPO / "workflow/rules").glob("*.smk")))
    return set(re.findall(r"^rule (\w+):", text, re.MULTILINE)) | set(
        re.findall(r"^use rule \w+ as (\w+)", text, re.MULTILINE))


def test_profile_submits_to_slurm_polls_squeue_and_gives_every_rule_runtime_and_memory():
    profile = _profile()
    assert profile["executor"] == "slurm"
    assert profile["slurm-status-command"] == "squeue"  # sacct needs slurmdbd
    assert "default-resources" not in profile  # left to the site: account, partition
    assert "cpus_per_task" not in str(profile)  # the plugin takes each rule's threads
    resources = profile["set-resources"]
    assert set(resources) == _rules()
    for rule, values in resources.items():
        assert values["runtime"] > 0 and values["mem_mb"] > 0, rule


def _skip_reason():
    missing = missing_binaries()
    if missing:
        return (f"SLURM not installed ({', '.join(missing)} missing): "
                "apt-get install slurm-wlm munge")
    if os.geteuid() != 0:
        return "the one-node test cluster runs slurmd and slurmctld as root"
    if importlib.util.find_spec("snakemake_executor_plugin_slurm") is None:
        return "snakemake-executor-plugin-slurm not installed: pip install -e '.[slurm]'"
    return None


@pytest.mark.slow
@pytest.mark.skipif(_skip_reason() is not None, reason=str(_skip_reason()))
def test_smoke_study_through_slurm_gives_the_local_summary(tmp_path):
    smoke = ["--configfile", "config/studies/smoke.yaml"]
    data = {"linear_polymer": REPO / "data/linear_polymer/matrix.csv"}

    local = _study(tmp_path / "local", data)
    started = time.monotonic()
    proc = subprocess.run([*SNAKEMAKE, "--cores", "2", *smoke], cwd=local, capture_output=True,
                          text=True)
    local_seconds = time.monotonic() - started
    assert proc.returncode == 0, proc.stderr

    remote = _study(tmp_path / "slurm", data)
    # A short state directory: the daemons' Unix sockets live there (tmp_path can be too long).
    with tempfile.TemporaryDirectory(prefix="suspsim-slurm-") as state, \
            OneNodeCluster(state) as cluster:
        daemons = cluster.daemons
        assert set(daemons) == {"munged", "slurmctld", "slurmd"}
        started = time.monotonic()
        # Poll every 5 s instead of the profile's 40 s (seconds-long jobs here); no accounts
        # exist without accounting, so do not let the plugin try to guess one.
        proc = subprocess.run([*SNAKEMAKE, "--workflow-profile", "workflow/profiles/slurm",
                               *smoke, "--slurm-init-seconds-before-status-checks", "5",
                               "--slurm-no-account"],
                              cwd=remote, capture_output=True, text=True, env=cluster.env())
        slurm_seconds = time.monotonic() - started
        assert proc.returncode == 0, proc.stderr[-4000:] + cluster.logs_tail()
        queue = subprocess.run(["squeue", "--states=all", "-h", "-o", "%k|%T|%C|%m|%l"],
                               capture_output=True, text=True, env=cluster.env(), check=True)
    print(f"cluster start {cluster.start_seconds:.1f} s; smoke study local {local_seconds:.0f} s, "
          f"through SLURM {slurm_seconds:.0f} s")

    # Every job went through SLURM and completed, with the profile's resources and the rule's
    # threads as CPUs (config simulation.threads = 1; the run log shows numba got it).
    jobs = [line.split("|") for line in queue.stdout.splitlines()]
    by_rule = {}
    for comment, status, cpus, memory, limit in jobs:
        rule = re.match(r"rule_([a-z_]+?)(_wildcards_|$)", comment)[1]
        by_rule[rule] = by_rule.get(rule, 0) + 1
        assert status == "COMPLETED", jobs
        if rule == "simulate":
            assert (cpus, memory, limit) == ("1", "4000M", "2:00:00"), jobs
    assert by_rule == {"fit_matrix": 1, "predict_homogenisation": 1, "simulate": 2, "gather": 1,
                       "plot_summary": 1}
    assert "on 1 thread(s)" in (remote / "logs/simulate/linear_polymer/"
                                         "phi-0_rate-0.1_seed-1.log").read_text()
    # The daemons it started are gone (a PID now running again belongs to another process).
    for name, (pid, start) in daemons.items():
        assert process_start_time(pid) != start, name

    with (xr.open_dataset(local / "results/linear_polymer/summary.nc") as expected,
          xr.open_dataset(remote / "results/linear_polymer/summary.nc") as got):
        assert set(got.variables) == set(expected.variables)
        assert got.sizes == expected.sizes
        for name in set(expected.variables) - WALL_TIME_VARIABLES:
            assert got[name].dims == expected[name].dims, name
            assert got[name].attrs == expected[name].attrs, name
            if np.issubdtype(expected[name].dtype, np.number):
                # Deterministic given seed and thread count: equal to round-off (here bitwise).
                np.testing.assert_allclose(got[name].values, expected[name].values, rtol=1e-12,
                                           atol=0, err_msg=name)
            else:
                assert (got[name].values == expected[name].values).all(), name
        assert ({k: v for k, v in got.attrs.items() if k not in TIME_STAMP_ATTRS}
                == {k: v for k, v in expected.attrs.items() if k not in TIME_STAMP_ATTRS})

