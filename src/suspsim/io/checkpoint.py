"""Checkpoints of a run and clean stops on SIGTERM/SIGINT.

A checkpoint is one ``.npz`` file written atomically (a stop mid-write keeps the previous
checkpoint): the state arrays, plus a JSON header with the run's metadata, the scene and the
SHA-256 of the scene's physics. :func:`load_checkpoint` refuses a checkpoint of another scene.
Wherever a scene is asked for, a :class:`~suspsim.scene.Scene` or its ``to_dict()`` will do.
Keys in :data:`RESUMABLE_KEYS` (threads, checkpoint cadence, safety limits) may change between
segments; every other scene key must be identical.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import signal
import zipfile
from dataclasses import dataclass
from datetime import datetime, timezone
from typing import Any, Iterator, Mapping

import numpy as np

from .. import __version__
from ..errors import InputError
from .atomic import atomic_path

log = logging.getLogger(__name__)

FORMAT = "suspsim-checkpoint"
#: 2: body particles take μ̂ (``viscosity_hat``) from the fluid beside them (2026-12-05).
#: 3: a run with inclusions records the series ``particle_stress`` (2026-12-06).
#: 4: and ``body_spin``, with grains ``body_order`` (2026-12-07).
FORMAT_VERSION = 4
#: Scene keys that do not change the physics and may differ when a run resumes.
RESUMABLE_KEYS = (("run", "threads"), ("run", "checkpoint_interval_s"),
                  ("run", "max_density_error"), ("run", "density_outlier_fraction"),
                  ("run", "max_outlier_density_error"), ("run", "max_mach"),
                  ("numerics", "max_density_error"), ("numerics", "max_mach"),
                  ("numerics", "max_viscosity_ratio"))
_HEADER = "__suspsim_header__"
_RESERVED = {_HEADER, "file", "allow_pickle"}
_SCALARS = {"int": int, "float": float, "bool": bool}


def scene_hash(scene: Mapping[str, Any]) -> str:
    """SHA-256 of the scene's physics: canonical JSON without :data:`RESUMABLE_KEYS`.

    Numbers are compared by value (``12`` and ``12.0`` hash alike).
    """
    text = json.dumps(_physics(_as_dict(scene)), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def save_checkpoint(path: str | os.PathLike, state: Mapping[str, np.ndarray | float | int],
                    meta: Mapping[str, Any], *, scene: Mapping[str, Any]) -> None:
    """Write ``state`` (arrays and Python/NumPy scalars), JSON-able ``meta`` and ``scene``'s hash.

    Raises ValueError for a reserved or non-numeric state entry (a programming error).
    """
    arrays, scalars = {}, {}
    for name, value in state.items():
        if name in _RESERVED:
            raise ValueError(f"state key {name!r} is reserved")
        if isinstance(value, (bool, int, float, np.bool_, np.integer, np.floating)):
            scalars[name] = type(np.asarray(value).item()).__name__
        arrays[name] = np.asarray(value)
        if arrays[name].dtype.hasobject:
            raise ValueError(f"state entry {name!r} is not a numeric array")
    header = {"format": FORMAT, "version": FORMAT_VERSION, "scene_sha256": scene_hash(scene),
              "scene": _canonical(_as_dict(scene)), "scalars": scalars,
              "meta": _canonical(meta, floats=False),
              "written": datetime.now(timezone.utc).isoformat(timespec="seconds"),
              "suspsim_version": __version__}
    arrays[_HEADER] = np.array(json.dumps(header))
    with atomic_path(path) as tmp, open(tmp, "wb") as stream:
        np.savez(stream, **arrays)
        stream.flush()
        os.fsync(stream.fileno())


def load_checkpoint(path: str | os.PathLike, scene: Mapping[str, Any]) -> tuple[dict, dict]:
    """Return ``(state, meta)`` of the checkpoint at ``path``, written for ``scene``.

    Scalars come back as Python int/float/bool, arrays as arrays. Raises :class:`InputError`
    for a missing or unreadable file and for a checkpoint of a different scene (naming the
    first key that differs).
    """
    try:
        with np.load(path, allow_pickle=False) as archive:
            if _HEADER not in archive.files:
                raise InputError(path, "not a suspsim checkpoint (no header)")
            header = json.loads(str(archive[_HEADER]))
            state = {name: archive[name] for name in archive.files if name != _HEADER}
    except FileNotFoundError:
        raise InputError(path, "no checkpoint here; run without --resume to start afresh") from None
    except (OSError, EOFError, ValueError, zipfile.BadZipFile) as err:
        raise InputError(path, f"not a readable suspsim checkpoint ({err})") from None
    if header.get("format") != FORMAT or header.get("version") != FORMAT_VERSION:
        raise InputError(path, f"not a {FORMAT} version {FORMAT_VERSION} file")
    if header["scene_sha256"] != scene_hash(scene):
        difference = (_first_difference(_physics(header["scene"]), _physics(_as_dict(scene)))
                      or "its scene hash differs")
        raise InputError(path, f"the checkpoint belongs to a different scene ({difference}); "
                         "restore that scene or run without --resume to start afresh")
    for name, kind in header["scalars"].items():
        state[name] = _SCALARS[kind](state[name].item())
    return state, header["meta"]


@dataclass
class InterruptRequest:
    """Set by :func:`graceful_interrupt` when a stop was requested: ``requested``, ``signum``."""

    requested: bool = False
    signum: int | None = None


@contextlib.contextmanager
def graceful_interrupt(signals=(signal.SIGTERM, signal.SIGINT)) -> Iterator[InterruptRequest]:
    """Turn the first SIGTERM/SIGINT into a flag the run loop polls; restore handlers on exit.

    ``with graceful_interrupt() as stop: ... if stop.requested: save; break``. A second signal
    acts as it would without this context (SIGTERM ends the process, SIGINT raises
    KeyboardInterrupt). Outside the main thread no handler can be installed: the flag then
    never rises and a warning is logged.
    """
    request = InterruptRequest()
    previous: dict[int, Any] = {}

    def handler(signum, frame):
        if request.requested:
            signal.signal(signum, _restorable(previous[signum]))
            signal.raise_signal(signum)
            return
        request.requested, request.signum = True, signum
        log.warning("%s received: stopping after this step (send it again to stop at once)",
                    signal.Signals(signum).name)

    try:
        for signum in signals:
            previous[signum] = signal.signal(signum, handler)
    except ValueError:
        log.warning("not in the main thread: SIGTERM/SIGINT will not stop the run cleanly")
    try:
        yield request
    finally:
        for signum, old in previous.items():
            signal.signal(signum, _restorable(old))


def _as_dict(scene) -> Mapping[str, Any]:
    return scene.to_dict() if hasattr(scene, "to_dict") else scene


def _restorable(handler):
    return signal.SIG_DFL if handler is None else handler


def _physics(scene: Mapping[str, Any]) -> dict:
    out = _canonical(scene)
    for section, key in RESUMABLE_KEYS:
        if isinstance(out.get(section), dict):
            out[section].pop(key, None)
    return out


def _canonical(obj, floats: bool = True):
    """Plain JSON data: mappings, lists, and (with ``floats``) every non-bool number as float."""
    if isinstance(obj, Mapping):
        return {str(k): _canonical(v, floats) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_canonical(v, floats) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if floats and isinstance(obj, int) and not isinstance(obj, bool):
        return float(obj)
    return obj


def _first_difference(saved, current, path: str = "") -> str:
    if isinstance(saved, dict) and isinstance(current, dict):
        for key in sorted(set(saved) | set(current)):
            here = f"{path}.{key}" if path else key
            if key not in current or key not in saved:
                where = "this scene" if key not in current else "the checkpoint's scene"
                return f"{here} is missing from {where}"
            found = _first_difference(saved[key], current[key], here)
            if found:
                return found
        return ""
    if saved != current:
        return f"{path} is {saved!r} in the checkpoint, {current!r} now"
    return ""
