"""Checkpoints: round trip, atomicity, scene check; clean stops on SIGTERM/SIGINT."""
import os
import signal
import threading
import time

import numpy as np
import pytest

from suspsim.errors import InputError
from suspsim.io.checkpoint import graceful_interrupt, load_checkpoint, save_checkpoint, scene_hash
from suspsim.scene import scene_from_dict

SCENE = scene_from_dict({
    "dimension": 2, "box": [4, 8], "number_density": 4,
    "fluid": {"law": "newtonian", "params": {"mu": 1.0}},
    "flow": {"type": "couette", "shear_rate": 0.1}, "run": {"strain": 2},
}).to_dict()


def _state():
    rng = np.random.default_rng(1)
    return {"positions": rng.random((128, 2)), "velocities": rng.random((128, 2)),
            "cell": np.arange(128, dtype=np.int32), "offset": np.array(0.25), "time": 12.5,
            "step": 1000, "lees_edwards": True, "accumulated": np.float64(3.0)}


def _with(scene, section, key, value):
    return {**scene, section: {**scene[section], key: value}}


def test_round_trip(tmp_path):
    path = tmp_path / "run.ckpt"
    state, meta = _state(), {"samples": 40, "wall_time_s": 12.0, "note": "φ = 0", "lists": [1, 2]}
    save_checkpoint(path, state, meta, scene=SCENE)
    loaded, loaded_meta = load_checkpoint(path, SCENE)
    assert loaded_meta == meta and set(loaded) == set(state)
    for name in ("positions", "velocities", "cell", "offset"):
        np.testing.assert_array_equal(loaded[name], state[name])
        assert loaded[name].dtype == np.asarray(state[name]).dtype
    assert loaded["offset"].shape == ()
    scalars = ("time", "step", "lees_edwards", "accumulated")
    assert [loaded[k] for k in scalars] == [12.5, 1000, True, 3.0]
    assert [type(loaded[k]) for k in scalars] == [float, int, bool, float]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.ckpt"]


def test_other_scene_is_refused_naming_the_key(tmp_path):
    path = tmp_path / "run.ckpt"
    save_checkpoint(path, _state(), {}, scene=SCENE)
    with pytest.raises(InputError, match=r"flow\.shear_rate is 0\.1 in the checkpoint, 0\.2 now"):
        load_checkpoint(path, _with(SCENE, "flow", "shear_rate", 0.2))


def test_a_scene_object_will_do(tmp_path):
    path = tmp_path / "run.ckpt"
    scene = scene_from_dict(SCENE)
    save_checkpoint(path, _state(), {}, scene=scene)
    assert load_checkpoint(path, SCENE)[0]["step"] == 1000 and scene_hash(scene) == scene_hash(SCENE)


def test_resumable_keys_may_change_and_numbers_compare_by_value(tmp_path):
    path = tmp_path / "run.ckpt"
    save_checkpoint(path, _state(), {}, scene=SCENE)
    resumed = _with(_with(SCENE, "run", "threads", 4), "run", "max_mach", 0.5)
    resumed["box"] = [4, 8]
    assert scene_hash(resumed) == scene_hash(SCENE)
    load_checkpoint(path, resumed)


def test_failed_save_keeps_previous_checkpoint(tmp_path, monkeypatch):
    path = tmp_path / "run.ckpt"
    save_checkpoint(path, _state(), {"segment": 1}, scene=SCENE)

    def half_write(stream, **arrays):
        stream.write(b"PK\x03\x04 half")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez", half_write)
    with pytest.raises(KeyboardInterrupt):
        save_checkpoint(path, _state(), {"segment": 2}, scene=SCENE)
    monkeypatch.undo()
    assert load_checkpoint(path, SCENE)[1] == {"segment": 1}
    assert [p.name for p in tmp_path.iterdir()] == ["run.ckpt"]


@pytest.mark.parametrize("content, match", [(None, "no checkpoint"), (b"", "not a readable"),
                                            (b"garbage" * 10, "not a readable")])
def test_missing_or_corrupt_file(tmp_path, content, match):
    path = tmp_path / "run.ckpt"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(InputError, match=match):
        load_checkpoint(path, SCENE)


def test_plain_npz_is_not_a_checkpoint(tmp_path):
    path = tmp_path / "x.npz"
    np.savez(path, a=np.zeros(3))
    with pytest.raises(InputError, match="no header"):
        load_checkpoint(path, SCENE)


@pytest.mark.parametrize("state", [{"file": np.zeros(2)}, {"x": np.array([object()])}])
def test_bad_state_is_a_programming_error(tmp_path, state):
    with pytest.raises(ValueError):
        save_checkpoint(tmp_path / "run.ckpt", state, {}, scene=SCENE)
    assert list(tmp_path.iterdir()) == []


def _wait(request, timeout=5.0):
    deadline = time.monotonic() + timeout
    while not request.requested and time.monotonic() < deadline:
        time.sleep(0.001)
    return request.requested


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT])
def test_graceful_interrupt_catches_a_real_signal(signum):
    def sentinel(s, f):
        raise AssertionError("previous handler must not run inside the context")

    before = signal.signal(signum, sentinel)
    try:
        with graceful_interrupt() as stop:
            assert not stop.requested
            os.kill(os.getpid(), signum)
            assert _wait(stop) and stop.signum == signum
        assert signal.getsignal(signum) is sentinel
    finally:
        signal.signal(signum, before)


def test_second_sigint_interrupts_at_once():
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        with pytest.raises(KeyboardInterrupt):
            with graceful_interrupt() as stop:
                os.kill(os.getpid(), signal.SIGINT)
                assert _wait(stop)
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(5)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, before)


def test_outside_main_thread_the_flag_stays_down():
    seen = []

    def worker():
        with graceful_interrupt() as stop:
            seen.append(stop.requested)

    thread = threading.Thread(target=worker)
    thread.start()
    thread.join()
    assert seen == [False]
