"""TA Instruments TRIOS "Export to Excel" workbooks (``.xls`` BIFF via xlrd, ``.xlsx`` via
openpyxl).

Layout: sheet ``Details`` holds key/value metadata; one sheet per procedure step named
``"<Step type> - <n>"`` (``Flow sweep - 1``, ``Amplitude sweep - 2``, ``Stress growth - 4``).
In a step sheet row 1 is the step name, row 2 the variable names, row 3 the units (``Pa``,
``1/s``, ``Pa.s``), data from row 4 (1-based Excel rows, as in the messages). Column order
differs between sheets of one file, so columns are mapped by name.

Only steady flow steps are read: sheets whose name starts with ``Flow`` (flow sweep, flow
ramp, flow peak hold) and that have a shear rate plus a stress or viscosity. Each becomes
one sample named ``"<file stem>/<sheet name>"``. The ``Sample name`` of ``Details`` is not
used for naming: TRIOS copies it unchanged into every file of a series (e.g. one name for
workbooks at five temperatures), so the file stem is what tells the curves apart.

The workbooks are read cell by cell with xlrd/openpyxl rather than ``pandas.read_excel``
so that row numbers in messages are exact Excel rows and cell types (error cells, dates)
are known.
"""
from __future__ import annotations

import io
import logging
import warnings

from suspsim.errors import InputError
from suspsim.rheology.readers.columns import find_columns
from suspsim.rheology.readers.table import (Block, Locator, read_rows, require_columns,
                                            resolve_factors)
from suspsim.rheology.readers.text import looks_numeric

__all__ = ["XLS_MAGIC", "XLSX_MAGIC", "read_workbook_cells", "read_trios"]

logger = logging.getLogger(__name__)

XLS_MAGIC = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
XLSX_MAGIC = b"PK\x03\x04"
_HEADER_SEARCH_ROWS = 6


def _xls_sheets(data: bytes) -> dict[str, list[list[object]]]:
    import xlrd  # imported here: only workbooks need it, and text reads stay fast to start

    # xlrd writes its warnings to stdout unless given a log file.
    log = io.StringIO()
    book = xlrd.open_workbook(file_contents=data, logfile=log)
    if log.getvalue():
        logger.debug("xlrd: %s", log.getvalue().strip())
    sheets = {}
    for sheet in book.sheets():
        rows = []
        for r in range(sheet.nrows):
            row = []
            for cell in sheet.row(r):
                if cell.ctype in (xlrd.XL_CELL_EMPTY, xlrd.XL_CELL_BLANK, xlrd.XL_CELL_ERROR):
                    row.append(None)
                elif cell.ctype == xlrd.XL_CELL_BOOLEAN:
                    row.append(bool(cell.value))
                else:
                    row.append(cell.value)
            rows.append(row)
        sheets[sheet.name] = rows
    return sheets


def _xlsx_sheets(data: bytes) -> dict[str, list[list[object]]]:
    import openpyxl  # imported here: only workbooks need it, and text reads stay fast to start

    with warnings.catch_warnings(record=True) as caught:
        # e.g. "Workbook contains no default style": noise for a user of the reader
        warnings.simplefilter("always")
        book = openpyxl.load_workbook(io.BytesIO(data), read_only=True, data_only=True)
        try:
            sheets = {ws.title: [list(row) for row in ws.iter_rows(min_row=1, min_col=1,
                                                                    values_only=True)]
                      for ws in book.worksheets}
        finally:
            book.close()
    for warning in caught:
        logger.debug("openpyxl: %s", warning.message)
    return sheets


def read_workbook_cells(data: bytes, source: str) -> dict[str, list[list[object]]]:
    """All sheets of an ``.xls`` or ``.xlsx`` workbook as rows of cell values (None = empty).

    Raises InputError for a workbook the Excel libraries cannot open.
    """
    reader = _xls_sheets if data.startswith(XLS_MAGIC) else _xlsx_sheets
    try:
        return reader(data)
    except Exception as exc:  # noqa: BLE001 - xlrd/openpyxl/zipfile raise many types on bad files
        kind = "xls" if reader is _xls_sheets else "xlsx"
        raise InputError(source, f"cannot read this as an Excel .{kind} workbook "
                                 f"({type(exc).__name__}: {exc})"[:400]) from None


def _is_flow_sheet(name: str) -> bool:
    return name.strip().lower().startswith("flow")


def _units_row(row: list[object], indexes: list[int]) -> bool:
    cells = [row[i] for i in indexes if i < len(row) and row[i] is not None]
    return bool(cells) and all(isinstance(c, str) and not looks_numeric(c) for c in cells)


def _read_step(name: str, rows: list[list[object]], source: str,
               stem: str) -> list[Block] | None:
    """Blocks of one flow sheet, or None if the sheet has no flow-curve columns."""
    locator = Locator(source, sheet=name)
    header_at = None
    for r, row in enumerate(rows[:_HEADER_SEARCH_ROWS]):
        columns = find_columns(row)
        if "shear_rate" in columns and ("shear_stress" in columns or "viscosity" in columns):
            header_at = r
            break
    if header_at is None:
        return None
    header = rows[header_at]
    require_columns(columns, header, locator, header_at + 1)
    needed = [c.index for q, c in columns.items() if q != "sample"]
    units_row, units_at = None, header_at + 1
    start = header_at + 1
    if start < len(rows) and _units_row(rows[start], needed):
        units_row, units_at = rows[start], start + 1
        start += 1
    factors = resolve_factors(columns, units_row, locator, units_at)
    columns.pop("sample", None)  # a TRIOS step is one sample whatever its columns say
    data = [(r + 1, row) for r, row in enumerate(rows) if r >= start]
    return read_rows(data, columns, factors, default_sample=f"{stem}/{name.strip()}",
                     decimal_comma=True, locator=locator)


def read_trios(data: bytes, source: str, stem: str) -> tuple[list[Block], str]:
    """Read the flow steps of a TRIOS workbook; return blocks and the format
    ``"trios_excel"``."""
    sheets = read_workbook_cells(data, source)
    blocks: list[Block] = []
    used = []
    for name, rows in sheets.items():
        if not _is_flow_sheet(name) or not any(any(c is not None for c in r) for r in rows):
            continue
        step = _read_step(name, rows, source, stem)
        if step is None:
            logger.info("%s: sheet %r has no shear rate with stress or viscosity, skipped",
                        source, name)
            continue
        blocks.extend(step)
        used.append(name)
    if not used:
        listed = ", ".join(repr(n) for n in sheets) or "none"
        raise InputError(source, "no steady flow step in this workbook: expected a sheet "
                                 "named 'Flow …' (e.g. 'Flow sweep - 1') with shear rate and "
                                 f"stress or viscosity columns; sheets: {listed}")
    logger.debug("%s: TRIOS flow sheets %s", source, used)
    return blocks, "trios_excel"
