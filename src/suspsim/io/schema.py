"""JSON-schema (Draft 2020-12) validation with one-line errors that name the key, and defaults.

:func:`validate` turns the first problem (in file order when key lines are known) into an
:class:`~suspsim.errors.InputError` such as ``scene.yaml:9 [key 'flow.shear_rate']: 'fast' is
not a number``. :func:`fill_defaults` adds every ``default`` the schema declares.
"""
from __future__ import annotations

import copy
import difflib
import json
import math
import re
from importlib import resources
from typing import Any, Mapping, NoReturn

from jsonschema import Draft202012Validator

from ..errors import InputError

_TYPE_PHRASES = {"number": "a number", "integer": "an integer", "boolean": "true or false",
                 "string": "a string", "object": "a mapping of keys to values", "array": "a list"}
_BOUNDS = {"minimum": "≥", "exclusiveMinimum": ">", "maximum": "≤", "exclusiveMaximum": "<"}


def load_schema(name: str) -> dict:
    """The schema ``suspsim/schemas/<name>.schema.json`` shipped with the package."""
    text = resources.files("suspsim").joinpath("schemas", f"{name}.schema.json").read_text("utf-8")
    schema = json.loads(text)
    Draft202012Validator.check_schema(schema)
    return schema


def dotted_key(path) -> str:
    """``("run", "strain")`` → ``"run.strain"``; ``("box", 1)`` → ``"box[1]"``."""
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def fail_at(source: str, lines: Mapping[tuple, int], path: tuple, problem: str) -> NoReturn:
    """Raise :class:`InputError` for the key ``path``, at the line of the nearest enclosing key
    that has one (``lines`` as from :func:`suspsim.io.yamlfile.load_yaml`)."""
    line = next((lines[path[:i]] for i in range(len(path), 0, -1) if path[:i] in lines), None)
    raise InputError(source, problem, line=line, key=dotted_key(path) or None)


def validate(data: Any, schema: Mapping, *, source: str, lines: Mapping[tuple, int] | None = None) -> None:
    """Raise :class:`InputError` for the first problem of ``data`` against ``schema``.

    Non-finite numbers (``.nan``, ``.inf``) are rejected everywhere. ``lines`` maps key paths
    to line numbers (see :func:`suspsim.io.yamlfile.load_yaml`); problems are reported in file
    order when it is given, else in schema order.
    """
    lines = lines or {}
    problems = [_non_finite(data, (), source, lines)]
    problems += [_to_input_error(err, source, lines)
                 for err in Draft202012Validator(schema).iter_errors(data)]
    problems = [p for p in problems if p is not None]
    if problems:
        raise min(problems, key=lambda p: math.inf if p.line is None else p.line)


def fill_defaults(data: Any, schema: Mapping) -> Any:
    """A copy of ``data`` with each missing key that has a schema ``default`` filled in, recursively."""
    if not isinstance(data, dict):
        return data
    out = dict(data)
    for name, sub in schema.get("properties", {}).items():
        if name not in out and "default" in sub:
            out[name] = copy.deepcopy(sub["default"])
        if name in out:
            out[name] = fill_defaults(out[name], sub)
    return out


def describe(schema: Mapping) -> str:
    """A short phrase for what ``schema`` accepts, e.g. ``a number > 0 or 'auto'``."""
    if "anyOf" in schema or "oneOf" in schema:
        return " or ".join(describe(s) for s in schema.get("anyOf", schema.get("oneOf")))
    if "const" in schema:
        return repr(schema["const"])
    if "enum" in schema:
        return "one of " + ", ".join(str(v) for v in schema["enum"])
    phrase = _TYPE_PHRASES.get(schema.get("type"), "a value")
    bounds = [f"{sign} {schema[k]:g}" for k, sign in _BOUNDS.items() if k in schema]
    return " ".join([phrase, " and ".join(bounds)]).strip()


def first_sentence(text: str) -> str:
    """The text up to its first full stop or semicolon (schema descriptions in one-line messages)."""
    return re.split(r"[.;] ", text)[0].rstrip(".")


def _show(value) -> str:
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, list):
        return "a list"
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _non_finite(data, path, source, lines) -> InputError | None:
    if isinstance(data, float) and not math.isfinite(data):
        return InputError(source, f"{data} is not a finite number", line=lines.get(path),
                          key=dotted_key(path) or None)
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, list) else ()
    for k, v in items:
        found = _non_finite(v, path + (k,), source, lines)
        if found is not None:
            return found
    return None


def _to_input_error(err, source: str, lines: Mapping[tuple, int]) -> InputError:
    path = tuple(err.absolute_path)
    kind, value, instance = err.validator, err.validator_value, err.instance
    if kind == "required":
        missing = next(k for k in value if k not in instance)
        desc = first_sentence(err.schema.get("properties", {}).get(missing, {}).get("description", ""))
        return InputError(source, f"missing key {missing!r}" + (f" ({desc})" if desc else ""),
                          line=lines.get(path), key=dotted_key(path + (missing,)))
    if kind == "additionalProperties":
        allowed = list(err.schema.get("properties", {}))
        extras = sorted((k for k in instance if k not in allowed),
                        key=lambda k: lines.get(path + (k,), math.inf))
        extra = extras[0]
        near = difflib.get_close_matches(str(extra), allowed, n=1)
        hint = f"; did you mean {near[0]!r}?" if near else f"; allowed keys: {', '.join(allowed)}"
        return InputError(source, f"unknown key {extra!r}{hint}", line=lines.get(path + (extra,)),
                          key=dotted_key(path + (extra,)))
    if kind == "type":
        problem = f"{_show(instance)} is not {_TYPE_PHRASES.get(value, value)}"
    elif kind in _BOUNDS:
        problem = f"must be {_BOUNDS[kind]} {value:g} (got {_show(instance)})"
    elif kind in ("minItems", "maxItems"):
        bound = "at least" if kind == "minItems" else "at most"
        problem = f"has {len(instance)} entries; {bound} {value} allowed"
    else:
        problem = f"must be {describe(err.schema)} (got {_show(instance)})"
    return InputError(source, problem, line=lines.get(path), key=dotted_key(path) or None)
