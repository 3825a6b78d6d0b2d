"""The compiled-code cache follows the sources (``suspsim.jit_cache``): any edit to any source
file gives a new folder, the user's NUMBA_CACHE_DIR stands, and old folders are pruned."""
import os
import subprocess
import sys

import numba

from suspsim import jit_cache


def test_importing_suspsim_points_numba_at_the_folder_of_its_sources(tmp_path):
    """In a fresh interpreter without NUMBA_CACHE_DIR: the variable and numba's own setting
    name <XDG_CACHE_HOME>/suspsim/numba/<source hash>, and the folder exists."""
    env = {key: value for key, value in os.environ.items() if key != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    shown = subprocess.run(
        [sys.executable, "-c", "import os, suspsim, numba; "
         "print(os.environ['NUMBA_CACHE_DIR']); print(numba.config.CACHE_DIR)"],
        env=env, capture_output=True, text=True, check=True).stdout.split()
    folder = tmp_path / "suspsim" / "numba" / jit_cache.source_hash()
    assert shown == [str(folder), str(folder)] and folder.is_dir()


def test_the_hash_changes_with_any_file_and_only_with_the_sources(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "sub" / "b.py").write_text("y = 2\n")
    (tmp_path / "notes.txt").write_text("not a source")
    first = jit_cache.source_hash(tmp_path)
    assert jit_cache.source_hash(tmp_path) == first
    (tmp_path / "notes.txt").write_text("changed")
    assert jit_cache.source_hash(tmp_path) == first
    (tmp_path / "sub" / "b.py").write_text("y = 3\n")
    second = jit_cache.source_hash(tmp_path)
    assert second != first
    (tmp_path / "sub" / "b.py").rename(tmp_path / "b.py")
    assert jit_cache.source_hash(tmp_path) not in (first, second)


def test_a_user_cache_dir_stands_and_xdg_is_honoured(monkeypatch, tmp_path):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    assert jit_cache.use_source_cache() is None
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "mine")
    monkeypatch.delenv("NUMBA_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    monkeypatch.setattr(numba.config, "CACHE_DIR", numba.config.CACHE_DIR)
    folder = jit_cache.use_source_cache()
    assert folder == tmp_path / "xdg" / "suspsim" / "numba" / jit_cache.source_hash()
    assert folder.is_dir() and os.environ["NUMBA_CACHE_DIR"] == str(folder)
    assert numba.config.CACHE_DIR == str(folder)


def test_prune_keeps_the_current_folder_and_the_most_recent_others(tmp_path):
    folders = [tmp_path / f"v{k}" for k in range(5)]
    for age, folder in enumerate(folders):
        folder.mkdir()
        os.utime(folder, (1000.0 * age, 1000.0 * age))
    jit_cache.prune(tmp_path, folders[0], keep=2)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["v0", "v3", "v4"]
