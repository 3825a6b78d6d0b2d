"""Provenance of an output: software versions, the package's git commit and the host.

Nothing here raises: anything that cannot be found is reported as ``"unknown"``.
:func:`code_version` fingerprints the source a stage runs, so a workflow can re-run a stage
when that code changes (an editable install changes no version number).
"""
from __future__ import annotations

import ast
import functools
import hashlib
import platform
import re
import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

from .. import __version__

_PACKAGE_DIR = Path(__file__).resolve().parents[1]
_PACKAGE = _PACKAGE_DIR.name
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


def code_version(*modules: str) -> str:
    """SHA-256 (16 hex digits) of the source that ``modules`` run, for re-run triggers.

    Hashes each named suspsim module (e.g. ``"suspsim.stages.simulate"``), every suspsim module
    it imports, directly or not, at module level or inside functions (found by parsing, without
    importing), the ``__init__`` of their packages, and the package's JSON schemas (scene
    defaults live there). Code outside suspsim (NumPy, numba, ...) is not included.
    Raises ValueError for a name that is not a module of the package.
    """
    todo = [_checked_module(name) for name in modules]
    seen: dict[str, Path] = {}
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen[name] = path = _module_file(name)
        todo.extend(_parents(name))
        todo.extend(_imported_modules(name, path))
    digest = hashlib.sha256()
    files = sorted(seen.items()) + [(f"schema:{p.name}", p)
                                    for p in sorted((_PACKAGE_DIR / "schemas").glob("*.json"))]
    for name, path in files:
        digest.update(name.encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def _checked_module(name: str) -> str:
    if not (name == _PACKAGE or name.startswith(_PACKAGE + ".")) or _module_file(name) is None:
        raise ValueError(f"{name!r} is not a module of the {_PACKAGE} package")
    return name


def _module_file(name: str) -> Path | None:
    """The source file of module ``name`` of this package, or None if there is none."""
    base = _PACKAGE_DIR.joinpath(*name.split(".")[1:])
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _parents(name: str) -> list[str]:
    parts = name.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def _imported_modules(name: str, path: Path) -> list[str]:
    """Modules of this package that the source of ``name`` imports anywhere in its body."""
    return list(_imports_of_source(name, path, path.read_bytes()))


@functools.lru_cache(maxsize=None)
def _imports_of_source(name: str, path: Path, source: bytes) -> tuple[str, ...]:
    """:func:`_imported_modules` of one version of the source, parsed once per process (a
    workflow asks for the fingerprint of a dozen stages that share most of their imports)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(source, filename=str(path))):
        if isinstance(node, ast.Import):
            found.extend(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(package.split(".")[: len(package.split(".")) - node.level + 1])
                target = f"{base}.{node.module}" if node.module else base
            else:
                target = node.module or ""
            found.append(target)
            # "from pkg import sub" imports the module pkg.sub when there is one.
            found.extend(f"{target}.{alias.name}" for alias in node.names)
    return tuple(m for m in found if (m == _PACKAGE or m.startswith(_PACKAGE + "."))
                 and _module_file(m) is not None)
