"""Read a YAML file into plain data plus the line of every key, so errors can point at lines.

PyYAML follows YAML 1.1, in which ``1e-3`` and ``1.0e3`` are strings; the loader here reads
them as floats, as YAML 1.2 and JSON do. A key given twice in one mapping is an error instead
of silently keeping the last value.
"""
from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import yaml

from ..errors import InputError
from .schema import dotted_key

_FLOAT_TAG = "tag:yaml.org,2002:float"
_FLOAT = re.compile(r"""^(?:[-+]?[0-9][0-9_]*\.[0-9_]*(?:[eE][-+]?[0-9]+)?
                        |[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+
                        |[-+]?\.[0-9_]+(?:[eE][-+]?[0-9]+)?
                        |[-+]?\.(?:inf|Inf|INF)
                        |\.(?:nan|NaN|NAN))$""", re.X)


class _Loader(yaml.SafeLoader):
    """SafeLoader with YAML 1.2 floats."""

    yaml_implicit_resolvers = {first: [r for r in resolvers if r[0] != _FLOAT_TAG]
                               for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()}


_Loader.add_implicit_resolver(_FLOAT_TAG, _FLOAT, list("-+0123456789."))


def load_yaml(path: str | os.PathLike) -> tuple[Any, dict[tuple, int]]:
    """Return ``(data, lines)``: the file's content and the 1-based line of each key path.

    ``lines`` maps a path such as ``("run", "strain")`` or ``("box", 1)`` to the line of that
    key (or list item). Raises :class:`InputError` for an unreadable file, invalid YAML (with
    its line) or a duplicate key.
    """
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as err:
        raise InputError(path, f"cannot read the file: {err.strerror or err}") from None
    except UnicodeDecodeError:
        raise InputError(path, "not a UTF-8 text file") from None
    loader = _Loader(text)
    lines: dict[tuple, int] = {}
    try:
        node = loader.get_single_node()
        if node is None:
            return None, lines
        _collect_lines(node, (), lines, path, set())
        data = loader.construct_document(node)
    except yaml.MarkedYAMLError as err:
        mark = err.problem_mark or err.context_mark
        problem = " ".join(str(err.problem or err.context).split())
        raise InputError(path, f"not valid YAML: {problem}",
                         line=None if mark is None else mark.line + 1) from None
    except yaml.YAMLError as err:
        raise InputError(path, f"not valid YAML: {' '.join(str(err).split())}") from None
    finally:
        loader.dispose()
    return data, lines


def _collect_lines(node, path: tuple, lines: dict[tuple, int], source, seen: set[int]) -> None:
    """Record key lines; an aliased node is walked once (no blow-up on recursive aliases)."""
    if id(node) in seen:
        return
    seen.add(id(node))
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            if not isinstance(key_node, yaml.ScalarNode):
                continue
            here = path + (key_node.value,)
            line = key_node.start_mark.line + 1
            if here in lines:
                raise InputError(source, f"duplicate key (first given on line {lines[here]})",
                                 line=line, key=dotted_key(here))
            lines[here] = line
            _collect_lines(value_node, here, lines, source, seen)
    elif isinstance(node, yaml.SequenceNode):
        for index, item in enumerate(node.value):
            lines[path + (index,)] = item.start_mark.line + 1
            _collect_lines(item, path + (index,), lines, source, seen)
