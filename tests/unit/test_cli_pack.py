"""`suspsim pack`: a packing file on success; exit 1, one line, nothing written on bad input."""
import subprocess
import sys

import pytest

from suspsim.cli import main
from suspsim.io.packing_file import read_packing


def suspsim(*args, cwd):
    return subprocess.run([sys.executable, "-m", "suspsim", "-q", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True)


def test_pack_writes_a_packing(tmp_path):
    out = tmp_path / "packs" / "spheres.nc"
    proc = suspsim("pack", "--shape", "sphere", "--phi", "0.5", "--radius", "1.5", "--box", 12,
                   12, 12, "--polydispersity", "0.2", "--seed", "4", "--out", out, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    packing = read_packing(out)
    assert packing.volume_fraction == pytest.approx(0.5, rel=1e-12) and packing.seed == 4
    assert f"{packing.count} sphere bodies" in proc.stdout and str(out) in proc.stdout
    assert [p.name for p in out.parent.iterdir()] == ["spheres.nc"]


def test_bad_value_one_line_exit_1_nothing_written(tmp_path):
    proc = suspsim("pack", "--shape", "sphere", "--phi", "0.7", "--radius", "1", "--box", 10, 10,
                   10, "--out", tmp_path / "p.nc", cwd=tmp_path)
    assert proc.returncode == 1
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "--phi" in lines[0] and "0.64" in lines[0] and "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []


def run(argv):
    """main's exit code, whether it returns or argparse exits."""
    try:
        return main(argv)
    except SystemExit as exit:
        return exit.code


@pytest.mark.parametrize("change, expected", [
    ({"--phi": ["abc"]}, "argument --phi: invalid float value"),
    ({"--box": ["3", "3", "3"]}, "--box: box side 3 is too small"),
    ({"--roughness": ["0.1"]}, "--roughness: applies to --shape sand only"),
    ({"--size-ratio": ["9"]}, "--size-ratio: size ratio"),
    ({"--seed": ["-1"]}, "--seed: seed must be"),
    ({"--out": []}, "argument --out: expected one argument"),
])
def test_more_bad_input_in_process(tmp_path, capsys, change, expected):
    options = {"--shape": ["sphere"], "--phi": ["0.3"], "--radius": ["1"], "--box": ["10"] * 3,
               "--out": [str(tmp_path / "p.nc")]} | change
    argv = [token for flag, values in options.items() for token in (flag, *values)]
    assert run(["-q", "pack", *argv]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and expected in err[0], err
    assert list(tmp_path.iterdir()) == []


def test_unreachable_packing_is_a_numerical_failure(tmp_path, capsys):
    code = run(["-q", "pack", "--shape", "sphere", "--phi", "0.63", "--radius", "1", "--box",
                "12", "12", "12", "--max-steps", "20", "--out", str(tmp_path / "p.nc")])
    assert code == 2
    assert "lower the volume fraction" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []
