"""`suspsim fit`: table on stdout, JSON report, figure; bad input → one line, exit 1, nothing written."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from suspsim.cli import main
from suspsim.rheology.laws import make_law

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "rheometry"
REPO = Path(__file__).resolve().parents[2]


def _write_hb_csv(path, noise=0.01, seed=3):
    rate = np.logspace(-2, 3, 30)
    law = make_law("herschel_bulkley", dict(tau_y=12.0, K=3.0, n=0.55, M=1e5))
    rng = np.random.default_rng(seed)
    stress = law.stress(rate) * (1 + noise * rng.standard_normal(rate.size))
    lines = ["Shear rate [1/s],Shear stress [Pa]"] + [f"{g:.6g},{t:.6g}" for g, t in zip(rate, stress)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_fit_writes_report_and_figure(tmp_path, capsys):
    data = _write_hb_csv(tmp_path / "hb.csv")
    out, fig = tmp_path / "res" / "fit.json", tmp_path / "res" / "fit.png"
    assert main(["-q", "fit", str(data), "--law", "herschel_bulkley", "--out", str(out),
                 "--plot", str(fig)]) == 0
    report = json.loads(out.read_text())
    for key in ("law", "params", "stderr", "rms_log_residual", "n_points", "shear_rate_range", "source"):
        assert key in report
    assert report["law"] == "herschel_bulkley" and report["n_points"] == 30
    assert report["params"]["tau_y"] == pytest.approx(12.0, rel=0.1)
    assert report["params"]["n"] == pytest.approx(0.55, abs=0.05)
    assert fig.stat().st_size > 10_000 and fig.read_bytes()[:4] == b"\x89PNG"
    table = capsys.readouterr().out
    assert "tau_y" in table and "Pa" in table and "rms log10 residual" in table
    assert sorted(p.name for p in out.parent.iterdir()) == ["fit.json", "fit.png"]


@pytest.mark.parametrize("content, expected", [
    ("Shear rate [1/s],Shear stress [Pa]\n1,2\n2,abc\n", ":3"),
    ("", "empty"),
    ("Shear rate [1/s],Shear stress [furlong]\n1,2\n2,3\n", "furlong"),
])
def test_bad_input_one_line_exit_1_nothing_written(tmp_path, content, expected):
    bad = tmp_path / "bad.csv"
    bad.write_text(content, encoding="utf-8")
    out, fig = tmp_path / "fit.json", tmp_path / "fit.png"
    proc = subprocess.run([sys.executable, "-m", "suspsim", "-q", "fit", str(bad), "--out", str(out),
                           "--plot", str(fig)], capture_output=True, text=True,
                          cwd=tmp_path)
    assert proc.returncode == 1
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "bad.csv" in lines[0] and expected.lower() in lines[0].lower()
    assert "Traceback" not in proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.csv"]


def test_unknown_law_and_missing_file(tmp_path, capsys):
    data = _write_hb_csv(tmp_path / "hb.csv")
    assert main(["-q", "fit", str(data), "--law", "bingham"]) == 1
    assert "unknown law 'bingham'" in capsys.readouterr().err
    assert main(["-q", "fit", str(tmp_path / "nope.csv")]) == 1
    assert "nope.csv" in capsys.readouterr().err


def test_multi_sample_file_needs_a_sample(tmp_path, capsys):
    rows = ["sample_id,shear_rate_1/s,stress_Pa"]
    for sample, mu in (("a", 1.0), ("b", 2.0)):
        rows += [f"{sample},{g},{mu * g}" for g in (0.1, 1, 10, 100)]
    path = tmp_path / "two.csv"
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    assert main(["-q", "fit", str(path)]) == 1
    assert "--sample" in capsys.readouterr().err
    assert main(["-q", "fit", str(path), "--sample", "b", "--law", "newtonian"]) == 0
    assert "2" in capsys.readouterr().out
