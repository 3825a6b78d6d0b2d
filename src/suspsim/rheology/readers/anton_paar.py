"""Anton Paar RheoCompass full table exports (``Project:``/``Test:``/``Result:`` blocks).

Layout (tab-delimited, often UTF-16 LE with BOM, decimal comma or point)::

    Project:<TAB>myproj
    Test:<TAB>flow curve
    Result:<TAB>Flow Curve 1
    Interval and data points:<TAB>2<TAB>25
    Interval data:<TAB>Point No.<TAB>Shear Rate<TAB>Shear Stress<TAB>Viscosity<TAB>…
    <TAB><TAB>[1/s]<TAB>[Pa]<TAB>[mPa·s]<TAB>…
    <TAB>1<TAB>0,1<TAB>0,5<TAB>5000<TAB>…

Each ``Result:`` is one sample named by its text (else by the ``Test:`` text, else by the file
stem; repeated names get `` #2``, `` #3``). Its intervals are concatenated: RheoCompass splits
one flow curve into intervals (e.g. up and down ramps). Intervals without a shear-rate
column, or with neither stress nor viscosity (rest, pre-shear by time), are skipped.
"""
from __future__ import annotations

import logging
from dataclasses import replace

from suspsim.errors import InputError
from suspsim.rheology.readers.columns import find_columns
from suspsim.rheology.readers.table import Block, Locator, read_rows, resolve_factors
from suspsim.rheology.readers.text import is_blank, split_cells, split_lines

__all__ = ["is_anton_paar", "read_anton_paar"]

logger = logging.getLogger(__name__)

# English and German RheoCompass keys.
_INTERVAL = ("interval data:", "intervalldaten:")
_NAMING_KEYS = {"result:": "result", "ergebnis:": "result", "test:": "test"}


def _first_cell(line: str) -> str:
    for delimiter in ("\t", ";", ","):
        if delimiter in line:
            return line.split(delimiter, 1)[0].strip().lower()
    return line.strip().lower()


def is_anton_paar(lines: list[str]) -> bool:
    """True if some line starts with ``Interval data:``."""
    return any(_first_cell(line) in _INTERVAL for line in lines)


def _delimiter(line: str) -> str:
    for delimiter in ("\t", ";", ","):
        if delimiter in line:
            return delimiter
    return "\t"


def _value(line: str, delimiter: str) -> str:
    cells = [c for c in split_cells(line, delimiter)[1:] if c]
    return " ".join(cells)


def _intervals(lines: list[str], source: str, locator: Locator):
    """Yield ``(result number, result name, blocks of one interval)`` in file order."""
    names = {"result": None, "test": None}
    group = 0
    n = 0
    while n < len(lines):
        line = lines[n]
        key = _first_cell(line)
        if key in _NAMING_KEYS:
            field = _NAMING_KEYS[key]
            if field == "test":
                names["result"] = None
            names[field] = _value(line, _delimiter(line)) or None
            group += 1
            n += 1
            continue
        if key not in _INTERVAL:
            n += 1
            continue
        delimiter = _delimiter(line)
        header_at = n + 1
        header = split_cells(line, delimiter)
        columns = find_columns(header)
        n += 1
        units_row, units_at = None, header_at
        if n < len(lines) and _first_cell(lines[n]) == "" and not is_blank(lines[n], delimiter):
            candidate = split_cells(lines[n], delimiter)
            if any(c.startswith("[") for c in candidate):
                units_row, units_at = candidate, n + 1
                n += 1
        rows = []
        while n < len(lines):
            cells = split_cells(lines[n], delimiter)
            if is_blank(lines[n], delimiter):
                n += 1
                continue
            if cells[0]:  # a new key (Interval data:, Result:, …) ends the interval
                break
            rows.append((n + 1, cells))
            n += 1
        if "shear_rate" not in columns or not ({"shear_stress", "viscosity"} & set(columns)):
            logger.info("%s:%d: interval without shear rate and stress or viscosity skipped",
                        source, header_at)
            continue
        factors = resolve_factors(columns, units_row, locator, units_at)
        name = names["result"] or names["test"]
        blocks = read_rows(rows, columns, factors, default_sample=name or "",
                           decimal_comma=delimiter != ",", locator=locator)
        yield group, name, blocks


def read_anton_paar(text: str, source: str, default_sample: str) -> tuple[list[Block], str]:
    """Read a RheoCompass full export; return its blocks and the format name ``"anton_paar"``."""
    lines = split_lines(text)
    locator = Locator(source)
    merged: dict[int, tuple[str | None, list[Block]]] = {}
    for group, name, blocks in _intervals(lines, source, locator):
        merged.setdefault(group, (name, []))[1].extend(blocks)
    if not merged:
        raise InputError(source, "no interval with a shear rate and a shear stress or viscosity "
                                 "(an 'Interval data:' header naming e.g. 'Shear Rate' and "
                                 "'Shear Stress')")
    result, used = [], {}
    for name, blocks in merged.values():
        label = name or default_sample
        used[label] = used.get(label, 0) + 1
        if used[label] > 1:
            label = f"{label} #{used[label]}"
        result.extend(replace(block, sample=label) for block in blocks)
    return result, "anton_paar"
