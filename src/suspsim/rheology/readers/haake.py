"""Thermo HAAKE RheoWin text exports.

Layout (``;``-delimited, decimal comma, often cp1252, trailing ``;``)::

    C:\\…\\sample 13.56.21.rwd
    Company / Operator: LAB / me
    Date / Time / Version: 11.10.2017 / 13:47:12 / HAAKE RheoWin 4.63.0003
    Substance / Sample no: gel / 2

    ;GP in 1/s;Tau in Pa;Eta in Pas;T in °C;t in s;t_seg in s;
    1|1; ;0,0666; ; ;17,8;7,2;
    3|1;0,0009999;0,01350;13,50; ;244,6;33,0;

The first field of a data row is ``segment|point``. Segments without shear rate (stress
ramps, creep) drop out by the general missing-value rule. All segments with flow data are
kept in ONE sample, named from ``Substance / Sample no`` (else the file stem): a RheoWin job
that measures several flow segments (e.g. up and down ramps) still describes one fluid.
A later line starting with ``;`` is read as a new header for the rows below it.
"""
from __future__ import annotations

import re

from suspsim.errors import InputError
from suspsim.rheology.readers.columns import find_columns
from suspsim.rheology.readers.delimited import metadata_sample
from suspsim.rheology.readers.table import (Block, Locator, read_rows, require_columns,
                                            resolve_factors)
from suspsim.rheology.readers.text import is_blank, split_cells, split_lines

__all__ = ["is_haake", "read_haake"]

_ROW_ID = re.compile(r"\s*\d+\s*\|\s*\d+\s*")
_HEAD_KEYS = ("company / operator:", "date / time / version:", "substance / sample no:")


def is_haake(lines: list[str]) -> bool:
    """True for RheoWin's header keys or ``segment|point`` data rows."""
    head = [line.strip().lower() for line in lines[:15]]
    if any(line.startswith(_HEAD_KEYS) or "rheowin" in line for line in head):
        return True
    return any(_ROW_ID.fullmatch(re.split(r"[;\t]", line, maxsplit=1)[0])
               and (";" in line or "\t" in line) for line in lines[:200])


def read_haake(text: str, source: str, default_sample: str) -> tuple[list[Block], str]:
    """Read a RheoWin export; return its blocks and the format name ``"haake_rheowin"``."""
    lines = split_lines(text)
    locator = Locator(source)
    sample = default_sample
    for line in lines[:15]:
        if line.strip().lower().startswith("substance / sample no:"):
            sample = metadata_sample(line) or sample
    tables: list[tuple[dict, dict, list]] = []  # (columns, factors, rows) per header line
    delimiter = ";"
    for lineno, line in enumerate(lines, start=1):
        if line.lstrip(" ")[:1] in (";", "\t"):
            delimiter = "\t" if "\t" in line and ";" not in line else ";"
            header = split_cells(line, delimiter)
            columns = find_columns(header)
            require_columns(columns, header, locator, lineno)
            tables.append((columns, resolve_factors(columns, None, locator, lineno), []))
            continue
        if not tables or is_blank(line, delimiter):
            continue  # the metadata lines above the header
        cells = split_cells(line, delimiter)
        if not _ROW_ID.fullmatch(cells[0]):
            raise locator.error(lineno, "expected a data row starting with 'segment|point;' "
                                        f"(like '3|1;'), found {line.strip()[:40]!r}")
        tables[-1][2].append((lineno, cells))
    if not tables:
        raise InputError(source, "no RheoWin header row (a line starting with ';' such as "
                                 "';GP in 1/s;Tau in Pa;Eta in Pas;')")
    blocks: list[Block] = []
    for columns, factors, rows in tables:
        blocks.extend(read_rows(rows, columns, factors, default_sample=sample,
                                decimal_comma=True, locator=locator))
    return blocks, "haake_rheowin"
