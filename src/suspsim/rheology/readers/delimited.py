"""Delimited text tables: one header row naming the columns, an optional units row, data.

Covers plain CSV/TSV exports, the simple RheoCompass table export (``;``, decimal comma,
Latin-1, ``[1/s];[Pa];[Pa·s]`` units row) and tidy long files with a sample column
(rheopy-rheodata ``sample_id,shear_rate_1/s,stress_Pa``). The header is the first
non-comment line that names a shear rate; lines above it are metadata,
where ``Sample: name`` (also as a ``#`` comment) gives the sample name of a one-sample file.
"""
from __future__ import annotations

import logging
import re

from suspsim.errors import InputError
from suspsim.rheology.readers.columns import find_columns
from suspsim.rheology.readers.table import (Block, Locator, read_rows, require_columns,
                                            resolve_factors)
from suspsim.rheology.readers.text import (is_blank, is_comment, is_missing, looks_numeric,
                                           sniff_delimiter, split_cells, split_lines)
from suspsim.rheology.readers.units import is_known_unit

__all__ = ["read_delimited", "metadata_sample"]

logger = logging.getLogger(__name__)

_MAX_HEADER_SEARCH = 200
_SAMPLE_KEY = re.compile(
    r"\s*#?\s*(?:sample(?:\s*name|\s*id)?|specimen|probe|substance\s*/\s*sample\s*no)\s*"
    r"[:=\t;,]\s*(.*?)[\s;,\t]*", re.IGNORECASE)
_NEEDED = ("shear_rate", "shear_stress", "viscosity")


def metadata_sample(line: str) -> str | None:
    """Sample name of a ``Sample: name`` metadata or comment line, else None."""
    match = _SAMPLE_KEY.fullmatch(line)
    if match is None:
        return None
    # RheoWin writes "Substance / Sample no: gel / " when the number is left empty.
    name = match.group(1).strip().rstrip("/;,\t ").strip()
    return name or None


def _trimmed(cells: list[str]) -> list[str]:
    end = len(cells)
    while end and not cells[end - 1]:
        end -= 1
    return cells[:end]


def _is_units_row(cells: list[str], indexes: list[int], decimal_comma: bool) -> bool:
    """A row under the header whose needed cells are units, not numbers (``[1/s]``, ``Pa``)."""
    needed = [cells[i] for i in indexes if i < len(cells) and not is_missing(cells[i])]
    if not needed or any(looks_numeric(c, decimal_comma) for c in needed):
        return False
    return any(c.strip().startswith(("[", "(")) or is_known_unit(c) for c in needed)


def read_delimited(text: str, source: str, default_sample: str) -> tuple[list[Block], str]:
    """Read a delimited table; return its blocks and the format name
    (``"tidy_long"`` when it has a sample column, else ``"delimited"``)."""
    lines = split_lines(text)
    significant = [(n, line) for n, line in enumerate(lines, start=1)
                   if not is_comment(line) and not is_blank(line)]
    locator = Locator(source)
    if not significant:
        raise InputError(source, "the file is empty: no header or data line")
    delimiter = sniff_delimiter([line for _, line in significant[:40]])
    decimal_comma = delimiter != ","

    header_at, header, columns = None, [], {}
    fallback = None  # a line naming stress or viscosity only: the best place for the error
    for lineno, line in significant[:_MAX_HEADER_SEARCH]:
        cells = split_cells(line, delimiter)
        found = find_columns(cells)
        if "shear_rate" in found:
            header_at, header, columns = lineno, cells, found
            break
        if fallback is None and any(q in found for q in _NEEDED):
            fallback = (lineno, cells, found)
    if header_at is None:
        first_no, first = significant[0]
        cells = split_cells(first, delimiter)
        if fallback is None and cells and all(looks_numeric(c, decimal_comma) for c in cells):
            raise locator.error(first_no, "no header row: the first line holds numbers; add a "
                                          "header naming the columns, e.g. "
                                          "'shear_rate,shear_stress'")
        header_at, header, columns = fallback or (first_no, cells, {})
    require_columns(columns, header, locator, header_at)

    sample = default_sample
    for line in lines[:header_at - 1]:
        sample = metadata_sample(line) or sample

    needed_idx = [columns[q].index for q in _NEEDED if q in columns]
    body = [(n, split_cells(line, delimiter)) for n, line in significant if n > header_at]
    units_row, units_at = None, header_at
    if body and _is_units_row(body[0][1], needed_idx, decimal_comma):
        units_at, units_row = body[0]
        body = body[1:]
    factors = resolve_factors(columns, units_row, locator, units_at)

    rows = []
    header_width = len(_trimmed(header))
    for lineno, cells in body:
        cells = _trimmed(cells)
        if not cells or cells == _trimmed(header) or (units_row and cells == _trimmed(units_row)):
            # Empty rows and repeated header/units rows of concatenated exports.
            continue
        if delimiter == "," and len(cells) > header_width:
            raise locator.error(lineno, f"{len(cells)} fields but the header (line {header_at}) "
                                        f"has {header_width}; a decimal comma in a "
                                        "comma-delimited file? Use ';' or tab as delimiter")
        rows.append((lineno, cells))
    blocks = read_rows(rows, columns, factors, default_sample=sample,
                       decimal_comma=decimal_comma, locator=locator)
    fmt = "tidy_long" if "sample" in columns else "delimited"
    logger.debug("%s: %s table, delimiter %r, header on line %d", source, fmt, delimiter,
                 header_at)
    return blocks, fmt
