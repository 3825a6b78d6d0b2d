"""Readers of rheometer exports of a steady-shear flow curve (the pipeline's first stage).

>>> from suspsim.rheology.readers import read_flow_curve
>>> df = read_flow_curve("matrix.csv")          # doctest: +SKIP

:func:`read_flow_curve` returns a DataFrame with the columns :data:`FLOW_CURVE_COLUMNS`:
``shear_rate`` in 1/s, ``shear_stress`` in Pa, ``viscosity`` in Pa s (float64, all finite
and > 0) and ``sample`` (str), sorted by (sample, shear_rate), index 0…n-1, and
``df.attrs == {"source": str(path), "format": <format>}``.

The format is detected from the content (the extension is not trusted: "xls" exports that
are really text exist), one of:

``"trios_excel"``
    TA TRIOS Excel workbook (.xls/.xlsx); one sample per ``Flow…`` sheet, named
    ``"<file stem>/<sheet name>"``.
``"anton_paar"``
    Anton Paar RheoCompass full export (``Result:`` / ``Interval data:`` blocks); one
    sample per ``Result:``, named by its text.
``"haake_rheowin"``
    Thermo HAAKE RheoWin text export; one sample for all segments, named from
    ``Substance / Sample no``.
``"tidy_long"``
    Delimited table with a sample column (``sample``, ``sample_id``, ``specimen``,
    ``step``; else ``phi``); one sample per distinct value, named by the cell text.
``"delimited"``
    Any other delimited table (also the simple RheoCompass table export); one sample
    named by a ``Sample: name`` line above the header, else the file stem.

Every problem with the file is raised as :class:`suspsim.errors.InputError` naming the file,
the line (or sheet and row) and what is wrong.
"""
from __future__ import annotations

import logging
from os import PathLike, fsdecode
from pathlib import Path

import pandas as pd

from suspsim.errors import InputError
from suspsim.rheology.readers.anton_paar import is_anton_paar, read_anton_paar
from suspsim.rheology.readers.delimited import read_delimited
from suspsim.rheology.readers.haake import is_haake, read_haake
from suspsim.rheology.readers.table import FLOW_CURVE_COLUMNS, assemble
from suspsim.rheology.readers.text import decode, split_lines
from suspsim.rheology.readers.trios import XLS_MAGIC, XLSX_MAGIC, read_trios

__all__ = ["FLOW_CURVE_COLUMNS", "read_flow_curve", "list_samples"]

logger = logging.getLogger(__name__)

# Larger files are not flow-curve exports; refusing them avoids decoding gigabytes by mistake.
_MAX_BYTES = 200 * 1024 * 1024


def _read_bytes(path: Path, source: str) -> bytes:
    try:
        size = path.stat().st_size
        if size > _MAX_BYTES:
            raise InputError(source, f"the file is {size / 1e6:.0f} MB, too large for a "
                                     "rheometer export")
        return path.read_bytes()
    except OSError as exc:
        raise InputError(source, f"cannot read the file: {exc.strerror or exc}") from None


def _blocks(path: Path, source: str):
    data = _read_bytes(path, source)
    stem = path.stem
    if not data.strip():
        raise InputError(source, "the file is empty")
    if data.startswith((XLS_MAGIC, XLSX_MAGIC)):
        return read_trios(data, source, stem)
    if path.suffix.lower() in (".xls", ".xlsx", ".xlsm"):
        logger.info("%s: not an Excel workbook despite its extension; reading it as text",
                    source)
    text, encoding = decode(data, source)
    logger.debug("%s: decoded as %s", source, encoding)
    if text.lstrip()[:5].lower() in ("<?xml", "<html", "<!doc"):
        raise InputError(source, "this is an XML or HTML spreadsheet, not a supported export; "
                                 "save it as .xlsx or as delimited text (CSV)")
    lines = split_lines(text)
    if is_anton_paar(lines):
        return read_anton_paar(text, source, stem)
    if is_haake(lines):
        return read_haake(text, source, stem)
    return read_delimited(text, source, stem)


def read_flow_curve(path: str | PathLike, sample: str | None = None) -> pd.DataFrame:
    """Read a rheometer export of a steady-shear flow curve.

    Parameters
    ----------
    path : str or os.PathLike
        The export: delimited text (any of ``, ; TAB``; decimal point or comma; UTF-8,
        UTF-16 or cp1252), TRIOS .xls/.xlsx, Anton Paar RheoCompass or HAAKE RheoWin text.
    sample : str, optional
        Keep only this sample (see :func:`list_samples`).

    Returns
    -------
    pandas.DataFrame
        Columns ``shear_rate`` [1/s], ``shear_stress`` [Pa], ``viscosity`` [Pa s],
        ``sample``; whichever of stress and viscosity the file lacks is derived from
        τ = η γ̇. Rows with a missing, non-positive or non-finite value are dropped.

    Raises
    ------
    InputError
        For any unreadable or unusable file, an unknown sample or no usable row.
    """
    source = fsdecode(path)
    blocks, fmt = _blocks(Path(source), source)
    table = assemble(blocks, source, fmt, sample)
    logger.info("%s: %s, %d points in %d sample(s)", source, fmt, len(table),
                table["sample"].nunique())
    return table


def list_samples(path: str | PathLike) -> list[str]:
    """Names of the samples :func:`read_flow_curve` finds in ``path``, sorted."""
    return sorted(set(read_flow_curve(path)["sample"]))
