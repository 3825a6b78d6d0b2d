"""Provenance of an output: software versions, the package's git commit and the host.

Nothing here raises: anything that cannot be found is reported as ``"unknown"``.
"""
from __future__ import annotations

import platform
import re
import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from .. import __version__

_PACKAGE_DIR = Path(__file__).resolve().parents[1]
_GIT_TIMEOUT_S = 10


def provenance() -> dict[str, str]:
    """Versions of suspsim, Python, NumPy and numba, the git commit of the package and the host."""
    return {"suspsim_version": __version__, "git_sha": git_sha(),
            "python_version": platform.python_version(),
            "numpy_version": _dist_version("numpy"), "numba_version": _dist_version("numba"),
            "host": platform.node() or "unknown", "platform": platform.platform()}


def git_sha(directory: str | Path = _PACKAGE_DIR) -> str:
    """HEAD commit of the checkout holding ``directory`` (default: the suspsim package).

    ``-dirty`` is appended when files under ``directory`` differ from the commit (changed,
    staged or new and not ignored): the code that ran is then not exactly the commit.
    ``"unknown"`` when git is missing, the package is not tracked in a checkout (e.g. installed
    into site-packages inside some other repository) or anything else fails.
    """
    try:
        _git(directory, "ls-files", "--error-unmatch", "__init__.py")
        sha = _git(directory, "rev-parse", "HEAD")
        changed = _git(directory, "status", "--porcelain", "--", ".")
    except (OSError, ValueError, subprocess.SubprocessError):
        return "unknown"
    if not re.fullmatch(r"[0-9a-f]{40}|[0-9a-f]{64}", sha):
        return "unknown"
    return sha + ("-dirty" if changed else "")


def _git(directory, *args: str) -> str:
    result = subprocess.run(["git", *args], cwd=directory, capture_output=True, text=True,
                            timeout=_GIT_TIMEOUT_S, check=True, stdin=subprocess.DEVNULL)
    return result.stdout.strip()


def _dist_version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "unknown"
