"""Where numba keeps suspsim's compiled functions: one cache folder per version of the sources.

numba's on-disk cache (``cache=True``) checks a function against its own source file only: an
edit to a compiled function that it calls from another file goes unseen, and the caller keeps
running the old code (numba's "Notes on Caching", cache invalidation). After a ``git pull`` that
changes ``sph/terms/force_pass.py`` but not ``sph/integrator.py``, the step would run the old
force pass, silently. So, unless ``NUMBA_CACHE_DIR`` is set, :func:`use_source_cache` points
numba at ``<user cache>/suspsim/numba/<hash>``, the hash of every source file of the package:
any edit starts a fresh cache (one compilation, about a minute), and the folders of older
sources beyond the :data:`KEEP` most recently used are removed. The variable is exported, so
the processes a run or a workflow starts use the same folder.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import sys
from pathlib import Path

#: Cache folders of earlier source versions kept besides the current one.
KEEP = 2
#: Package root whose ``*.py`` files make the hash.
PACKAGE = Path(__file__).resolve().parent


def source_hash(root: Path = PACKAGE) -> str:
    """First 16 hex digits of the SHA-256 of every ``*.py`` under ``root`` (relative path and
    bytes, in sorted order)."""
    digest = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        digest.update(str(path.relative_to(root)).encode())
        digest.update(b"\0")
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def cache_root() -> Path:
    """``$XDG_CACHE_HOME/suspsim/numba`` (default ``~/.cache/suspsim/numba``)."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "suspsim" / "numba"


def prune(root: Path, current: Path, keep: int = KEEP) -> None:
    """Remove the folders under ``root`` other than ``current`` and the ``keep`` most recently
    used (modification time)."""
    others = sorted((p for p in root.iterdir() if p.is_dir() and p != current),
                    key=lambda p: p.stat().st_mtime, reverse=True)
    for old in others[keep:]:
        shutil.rmtree(old, ignore_errors=True)


def use_source_cache() -> Path | None:
    """Point numba's cache at the folder of these sources (module docstring); returns it, or
    None when ``NUMBA_CACHE_DIR`` was already set (the user's choice stands) or the folder
    cannot be made (numba then caches beside the sources, as before)."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return None
    root = cache_root()
    folder = root / source_hash()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        os.utime(folder)
        prune(root, folder)
    except OSError:
        return None
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    if "numba" in sys.modules:  # else numba reads the variable when it is first imported
        from numba.core import config

        config.CACHE_DIR = str(folder)
    return folder
