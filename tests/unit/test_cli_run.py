"""`suspsim run` and `suspsim bench`: exit codes, one-line errors, nothing written on failure."""
import json
import signal
import subprocess
import sys
import types

import numba
import pytest

import suspsim.run as run_module
from suspsim.cli import main
from suspsim.sph.bench import SUSPENDING_FLUID, lattice_side, paired_cost
from suspsim.io.netcdf import read_run
from test_run_loop import FakeSimulation, fake

SCENE = """\
dimension: 2
box: [{side}, {side}]
number_density: 4
fluid: {{law: newtonian, params: {{mu: 2.0}}}}
flow: {{type: couette, shear_rate: {rate}}}
run: {{strain: {strain}, transient: {transient}}}
seed: 3
"""


def write_scene(tmp_path, side=4, rate=0.5, strain=20, transient=4, name="scene.yaml"):
    path = tmp_path / name
    path.write_text(SCENE.format(side=side, rate=rate, strain=strain, transient=transient))
    return path


def suspsim(*args, cwd, timeout=None):
    return subprocess.run([sys.executable, "-m", "suspsim", "-q", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout)


BAD_SCENES = [
    (lambda text: text.replace("shear_rate: 0.5", "shear_rate: 0"), "[key 'flow.shear_rate']"),
    (lambda text: text.replace("seed: 3", "sead: 3"), "sead"),
    (lambda text: text.replace("strain: 20", "strain: -1"), "[key 'run.strain']"),
]


def test_bad_scene_one_line_exit_1_nothing_written(tmp_path):
    path = write_scene(tmp_path)
    edit, expected = BAD_SCENES[0]
    path.write_text(edit(path.read_text()))
    proc = suspsim("run", path, "--out", tmp_path / "out" / "run.nc", cwd=tmp_path)
    assert proc.returncode == 1
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "scene.yaml:5" in lines[0] and expected in lines[0] and "Traceback" not in proc.stderr
    assert [p.name for p in tmp_path.iterdir()] == ["scene.yaml"]


@pytest.mark.parametrize("edit, expected", BAD_SCENES[1:])
def test_more_bad_scenes_in_process(tmp_path, capsys, edit, expected):
    path = write_scene(tmp_path)
    path.write_text(edit(path.read_text()))
    assert main(["-q", "run", str(path), "--out", str(tmp_path / "run.nc")]) == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1 and "scene.yaml" in lines[0] and expected in lines[0]
    assert [p.name for p in tmp_path.iterdir()] == ["scene.yaml"]


def test_run_exit_codes_with_a_fake_solver(tmp_path, monkeypatch, capsys):
    path, out = write_scene(tmp_path), tmp_path / "run.nc"
    monkeypatch.setattr(run_module, "_solver", lambda: fake(signal_at=(700, signal.SIGTERM)))
    assert main(["-q", "run", str(path), "--out", str(out)]) == 143
    err = capsys.readouterr().err
    assert "interrupted at strain" in err and "--resume" in err and not out.exists()
    monkeypatch.setattr(run_module, "_solver", lambda: FakeSimulation)
    assert main(["-q", "run", str(path), "--out", str(out), "--resume", "--threads", "1"]) == 0
    printed = capsys.readouterr().out
    assert f"viscosity {float(read_run(out)['viscosity']):.6g} ± " in printed
    assert str(out) in printed
    monkeypatch.setattr(run_module, "_solver", lambda: fake(blowup_step=50))
    assert main(["-q", "run", str(path), "--out", str(tmp_path / "bad.nc")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "numerical failure" in err[0] and "run.max_density_error" in err[0]
    assert not (tmp_path / "bad.nc").exists()


def test_bench_table_and_json_with_a_fake_benchmark(monkeypatch, capsys):
    calls = []

    def benchmark(scene_name, n_steps, threads, particles):
        calls.append((scene_name, n_steps, threads, particles))
        return {"scene": scene_name, "n_particles": particles, "threads": threads,
                "steps": n_steps, "wall_time_s": 0.5,
                "particle_steps_per_s": particles * n_steps / 0.5, "rebuilds": 3}

    monkeypatch.setitem(sys.modules, "suspsim.sph.bench", types.SimpleNamespace(
        benchmark=benchmark, lattice_side=lattice_side, paired_cost=None,
        SUSPENDING_FLUID=SUSPENDING_FLUID))
    assert main(["-q", "bench", "--steps", "10"]) == 0
    table = capsys.readouterr().out.splitlines()
    assert len(table) == 7 and "particle-steps/s" in table[0] and "6.55e+05" in table[1]
    assert [c[0] for c in calls] == ["fluid-newtonian", "fluid-newtonian-unnormalised",
                                     "fluid-papanastasiou",
                                     "suspension-newtonian", "suspension-papanastasiou", "dst-2d"]
    assert calls[0][2] == numba.config.NUMBA_NUM_THREADS
    assert main(["-q", "bench", "--scene", "fluid-papanastasiou", "--threads", "1", "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert rows == [benchmark("fluid-papanastasiou", 200, 1, 32768)]
    assert main(["-q", "bench", "--scene", "fluid-newtonian", "--particles", "1000000"]) == 0
    assert calls[-1] == ("fluid-newtonian", 200, numba.config.NUMBA_NUM_THREADS, 1000000)
    capsys.readouterr()
    before = len(calls)
    with pytest.raises(SystemExit) as stop:
        main(["-q", "bench", "--particles", "30000"])
    assert stop.value.code == 1 and "cube k^3" in capsys.readouterr().err
    assert len(calls) == before


def test_bench_against_fluid_with_a_fake_pairing(monkeypatch, capsys):
    calls = []

    def paired_cost(scene_name, n_steps, threads, rounds, particles):
        calls.append((scene_name, n_steps, threads, rounds, particles))
        return {"scene": scene_name, "fluid": SUSPENDING_FLUID[scene_name], "threads": threads,
                "steps": n_steps, "rounds": rounds, "cost_ratio": 1.4,
                "slice_ratios": [1.3, 1.5], "particle_steps_per_s": 2.0e6,
                "fluid_particle_steps_per_s": 2.8e6}

    monkeypatch.setitem(sys.modules, "suspsim.sph.bench", types.SimpleNamespace(
        paired_cost=paired_cost, benchmark=None, lattice_side=lattice_side,
        SUSPENDING_FLUID=SUSPENDING_FLUID))
    assert main(["-q", "bench", "--against-fluid", "--threads", "1", "--steps", "20",
                 "--rounds", "2"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [c[0] for c in calls] == ["suspension-newtonian", "suspension-papanastasiou"]
    assert calls[0][1:4] == (20, 1, 2)
    assert lines[0].startswith("suspension-newtonian: a step per particle costs 1.40 x "
                               "fluid-newtonian's") and "slices 1.30-1.50" in lines[0]
    assert main(["-q", "bench", "--against-fluid", "--scene", "suspension-papanastasiou",
                 "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["fluid"] == "fluid-papanastasiou"
    for argv, problem in ((["--scene", "fluid-newtonian"], "takes a suspension scene"),
                          (["--steps", "5", "--rounds", "6"], "exceeds --steps 5")):
        assert main(["-q", "bench", "--against-fluid", *argv]) == 1
        assert problem in capsys.readouterr().err
    assert len(calls) == 3


def test_paired_cost_alternates_both_scenes_in_one_process():
    """A small box: the suspension and its fluid each advance their share of the steps in
    every round; the ratio is the suspension's time per particle-step over the fluid's."""
    result = paired_cost("suspension-newtonian", 6, 1, 3, particles=8000)
    assert result["fluid"] == "fluid-newtonian" and result["rounds"] == 3
    assert len(result["slice_ratios"]) == 3 and all(r > 0 for r in result["slice_ratios"])
    assert result["n_particles"] != result["fluid_n_particles"] == 8000
    assert result["cost_ratio"] == pytest.approx(
        result["fluid_particle_steps_per_s"] / result["particle_steps_per_s"], rel=1e-12)
    assert min(result["slice_ratios"]) <= result["cost_ratio"] * (1 + 1e-12)
    assert result["cost_ratio"] <= max(result["slice_ratios"]) * (1 + 1e-12)
    with pytest.raises(ValueError, match="not a suspension scene"):
        paired_cost("fluid-newtonian", 6, 1, 3)


def test_bench_dst_scene_json(tmp_path):
    """The 2D DST solver's bench scene: about --particles fluid particles plus walls, its
    speed and memory."""
    proc = suspsim("bench", "--scene", "dst-2d", "--steps", 3, "--threads", 1, "--particles",
                   8000, "--json", cwd=tmp_path, timeout=900)
    assert proc.returncode == 0, proc.stderr
    row = json.loads(proc.stdout.strip().splitlines()[-1])
    assert row["scene"] == "dst-2d" and row["steps"] == 3
    assert row["n_particles"] == 160 * 50 + 2 * 4 * 160  # fluid and two 4-layer walls
    assert row["particle_steps_per_s"] > 0 and 100 < row["bytes_per_particle"] < 5000
    assert set(row["pass_ms"]) == {"list build", "viscosity and pressure", "pair passes",
                                   "finish", "update and checks"}
    assert row["rebuilds"] >= 0 and 0.0 <= row["rebuild_share"] < 1.0


def test_tiny_real_couette_runs_end_to_end(tmp_path):
    path, out = write_scene(tmp_path, side=4, rate=0.5, strain=10, transient=2), tmp_path / "run.nc"
    proc = suspsim("run", path, "--out", out, "--threads", 1, cwd=tmp_path, timeout=900)
    assert proc.returncode == 0, proc.stderr
    assert "viscosity" in proc.stdout and "Reynolds number" in proc.stdout
    result = read_run(out)
    assert result.attrs["completed"] == 1 and result.attrs["n_particles"] == 64
    assert 0.5 * 2.0 < float(result["viscosity"]) < 1.5 * 2.0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.nc", "scene.yaml"]


def test_bench_json_lines(tmp_path):
    proc = suspsim("bench", "--scene", "fluid-newtonian", "--steps", 3, "--threads", 1, "--json",
                   cwd=tmp_path, timeout=900)
    assert proc.returncode == 0, proc.stderr
    rows = [json.loads(line) for line in proc.stdout.strip().splitlines()]
    assert len(rows) == 1 and rows[0]["scene"] == "fluid-newtonian" and rows[0]["threads"] == 1
    assert rows[0]["n_particles"] > 0 and rows[0]["particle_steps_per_s"] > 0
    # The error reached, and where the time and memory go.
    assert abs(rows[0]["viscosity_error"]) < 0.2 and rows[0]["density_error"] < 0.05
    assert 0.0 <= rows[0]["rebuild_share"] < 1.0 and rows[0]["bytes_per_particle"] > 100
    assert set(rows[0]["pass_ms"]) == {"density", "gradient sums", "gradient finish",
                                       "dissipation sums", "normalisation finish", "force sums",
                                       "force finish"}


def test_bench_unnormalised_scene_runs_only_density_and_force():
    """Without the dissipation normalisation a Newtonian step needs no velocity gradient: the
    like-for-like scene against a plain SPH loop times only the density and force passes."""
    from suspsim.sph.bench import benchmark

    row = benchmark("fluid-newtonian-unnormalised", 3, 1, 8000)
    assert set(row["pass_ms"]) == {"density", "force sums", "force finish"}
    assert row["density_error"] < 0.05


def test_bench_suspension_in_a_yield_stress_matrix_times_its_extra_passes():
    """Spheres in a Papanastasiou matrix add the body density and the smoothed rate to the
    fluid's passes."""
    from suspsim.sph.bench import benchmark

    row = benchmark("suspension-papanastasiou", 3, 1, 8000)
    assert set(row["pass_ms"]) == {"density", "body density", "gradient sums", "gradient finish",
                                   "rate smoothing", "dissipation sums", "normalisation finish",
                                   "force sums", "force finish"}
    assert all(t > 0.0 for t in row["pass_ms"].values())
