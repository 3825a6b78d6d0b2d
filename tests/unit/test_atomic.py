"""Atomic outputs: a failed write leaves neither the target nor a temporary behind."""
import json

import pytest

from suspsim.io.atomic import atomic_path, write_json


def test_success_renames_into_place(tmp_path):
    target = tmp_path / "sub" / "out.json"
    write_json(target, {"a": 1.0, "b": float("nan"), "c": [float("inf"), 2]})
    assert json.loads(target.read_text()) == {"a": 1.0, "b": None, "c": [None, 2]}
    assert sorted(p.name for p in target.parent.iterdir()) == ["out.json"]


def test_failure_leaves_nothing(tmp_path):
    target = tmp_path / "fig.png"
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            assert tmp.suffix == ".png" and tmp.parent == tmp_path
            tmp.write_bytes(b"half")
            raise RuntimeError("interrupted")
    assert list(tmp_path.iterdir()) == []


def test_failure_keeps_previous_output(tmp_path):
    target = tmp_path / "fit.json"
    target.write_text("old")
    with pytest.raises(ValueError):
        with atomic_path(target) as tmp:
            tmp.write_text("new, half")
            raise ValueError
    assert target.read_text() == "old" and len(list(tmp_path.iterdir())) == 1


def test_output_gets_the_permissions_of_a_plain_file(tmp_path):
    plain = tmp_path / "plain.txt"
    plain.write_text("x")
    target = tmp_path / "out.txt"
    with atomic_path(target) as tmp:
        tmp.write_text("x")
    assert (target.stat().st_mode & 0o777) == (plain.stat().st_mode & 0o777)
