"""Turning the bytes of a rheometer text export into lines and cells, and cells into numbers.

Rheometer software writes text in whatever the operating system of the lab PC liked:
UTF-8 with or without BOM, UTF-16 with BOM (Anton Paar RheoCompass), or Windows code page
1252 (HAAKE RheoWin, ``Pa·s`` as byte 0xB7). Numbers may use a decimal comma. Decoding and
number parsing are done here by hand rather than by pandas so that every failure can be
reported with its 1-based line number as :class:`suspsim.errors.InputError`.
"""
from __future__ import annotations

import csv
import math
import re
from os import PathLike

from suspsim.errors import InputError

__all__ = [
    "decode", "split_lines", "is_blank", "is_comment", "sniff_delimiter", "split_cells",
    "parse_number", "is_missing", "looks_numeric", "NotANumber",
]

_BOMS = (
    (b"\xef\xbb\xbf", "utf-8-sig"),
    (b"\xff\xfe", "utf-16-le"),
    (b"\xfe\xff", "utf-16-be"),
)

# Cell texts that mean "no value" in real exports (RheoWin writes a single space).
_MISSING = frozenset({"", "nan", "-", "--", "---", "na", "n/a", "#n/a", "null", "none"})

_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
_INFINITY = re.compile(r"[+-]?inf(?:inity)?", re.IGNORECASE)
_LINE_BREAK = re.compile(r"\r\n|\r|\n")
_QUOTES = "\"'"
# Characters allowed in text files; other control characters mean binary content.
_ALLOWED_CONTROLS = frozenset("\t\n\r\f\v")


class NotANumber(ValueError):
    """Raised by :func:`parse_number` for a cell that is neither a number nor missing."""


def _utf16_without_bom(data: bytes) -> str | None:
    """Guess UTF-16 without BOM from the NUL bytes of ASCII text (every other byte is 0)."""
    if len(data) < 4 or len(data) % 2:
        return None
    even_nuls = data[0::2].count(0)
    odd_nuls = data[1::2].count(0)
    half = len(data) // 2
    if odd_nuls > 0.4 * half and even_nuls < 0.05 * half:
        return "utf-16-le"
    if even_nuls > 0.4 * half and odd_nuls < 0.05 * half:
        return "utf-16-be"
    return None


def decode(data: bytes, source: str | PathLike) -> tuple[str, str]:
    """Decode the bytes of a text export; return ``(text, encoding name)``.

    Order: byte-order mark (UTF-8, UTF-16 LE/BE); UTF-16 recognised by its NUL bytes;
    strict UTF-8; cp1252; Latin-1 (which never fails). Raises InputError for binary
    content (NUL or many control characters) and for invalid UTF-16.
    """
    encoding = None
    for bom, name in _BOMS:
        if data.startswith(bom):
            encoding = name
            break
    if encoding is None and b"\x00" in data:
        encoding = _utf16_without_bom(data)
        if encoding is None:
            raise InputError(source, "the file contains NUL bytes: it is binary, not a text "
                                     "export or a spreadsheet")
    if encoding is not None and encoding.startswith("utf-16"):
        try:
            text = data.decode(encoding)
        except UnicodeDecodeError as exc:
            raise InputError(source, f"the file looks like {encoding.upper()} text but is not "
                                     f"valid {encoding.upper()} ({exc.reason} at byte "
                                     f"{exc.start})") from None
        text = text.removeprefix("\ufeff")
    else:
        body = data[3:] if encoding == "utf-8-sig" else data
        text = None
        for name in ("utf-8", "cp1252", "latin-1"):
            try:
                text = body.decode(name)
            except UnicodeDecodeError:
                continue
            encoding = name
            break
    assert text is not None  # latin-1 decodes any byte string
    _reject_binary(text, source)
    return text, encoding


def _reject_binary(text: str, source: str | PathLike) -> None:
    if "\x00" in text:
        raise InputError(source, "the file contains NUL characters: it is binary, not a text "
                                 "export")
    controls = sum(1 for ch in text if ch < " " and ch not in _ALLOWED_CONTROLS)
    if controls > max(3, 0.02 * len(text)):
        raise InputError(source, f"the file holds {controls} control characters: it is binary, "
                                 "not a text export")


def split_lines(text: str) -> list[str]:
    """Split on CRLF, CR or LF only (not on the other separators str.splitlines knows), so
    list index + 1 is the line number an editor shows."""
    lines = _LINE_BREAK.split(text)
    if lines and lines[-1] == "":
        lines.pop()
    return lines


def is_comment(line: str) -> bool:
    """A ``#`` comment line."""
    return line.lstrip().startswith("#")


def is_blank(line: str, delimiter: str | None = None) -> bool:
    """Empty, whitespace only, or only delimiters (``;;;;`` rows of spreadsheet exports)."""
    stripped = line.strip()
    if delimiter is not None and delimiter.strip():
        stripped = stripped.replace(delimiter, "").strip()
    return stripped == ""


def sniff_delimiter(lines: list[str]) -> str | None:
    """Pick the field delimiter among tab, ``;`` and ``,`` from significant lines.

    The delimiter present in the most lines wins; ties go to tab, then ``;``, then ``,``,
    because a ``;`` or tab file with decimal commas has commas in its data lines too.
    Returns None when no candidate occurs (a one-column or whitespace-separated file).
    """
    best, best_count = None, 0
    for candidate in ("\t", ";", ","):
        count = sum(1 for line in lines if candidate in line)
        if count > best_count:
            best, best_count = candidate, count
    return best


def split_cells(line: str, delimiter: str | None) -> list[str]:
    """Split one line into stripped cells, honouring double quotes; None splits on whitespace."""
    if delimiter is None:
        return line.split()
    if '"' not in line:
        return [cell.strip() for cell in line.split(delimiter)]
    try:
        row = next(csv.reader([line], delimiter=delimiter, strict=False), [])
    except csv.Error:
        # An unbalanced quote is not worth failing for: the numbers are checked afterwards.
        row = line.split(delimiter)
    return [cell.strip() for cell in row]


def _clean(cell: str) -> str:
    text = cell.strip().replace("\xa0", "").replace("\u202f", "")
    if len(text) >= 2 and text[0] == text[-1] and text[0] in _QUOTES:
        text = text[1:-1].strip()
    return text


def is_missing(cell: object) -> bool:
    """True for an empty cell or a missing-value marker (``NaN``, ``-``, ``--``, space…)."""
    if cell is None:
        return True
    if isinstance(cell, float):
        return math.isnan(cell)
    if isinstance(cell, str):
        text = _clean(cell).lower()
        return text in _MISSING or (text.startswith("#") and text.endswith("!"))
    return False


def parse_number(cell: object, decimal_comma: bool = True) -> float:
    """Parse a cell to float; NaN for a missing cell; raise NotANumber otherwise.

    With ``decimal_comma`` a comma is read as the decimal mark (``1,5E-3``); it must be
    False for comma-delimited files, where a comma can never be inside a number. Only ASCII
    digits are accepted (``float`` would also take ``1_000`` or Arabic-Indic digits).
    Numbers outside the float range give ±inf, which callers drop as non-finite.
    """
    if isinstance(cell, bool):
        raise NotANumber(repr(cell))
    if isinstance(cell, (int, float)):
        try:
            return float(cell)
        except OverflowError:  # a huge integer cell in a spreadsheet
            return math.inf if cell > 0 else -math.inf
    if not isinstance(cell, str) or is_missing(cell):
        if isinstance(cell, str) or cell is None:
            return math.nan
        raise NotANumber(repr(cell))
    text = _clean(cell)
    if decimal_comma:
        text = text.replace(",", ".")
    if _NUMBER.fullmatch(text):
        return float(text)
    if _INFINITY.fullmatch(text):
        return -math.inf if text.startswith("-") else math.inf
    raise NotANumber(text)


def looks_numeric(cell: object, decimal_comma: bool = True) -> bool:
    """True if :func:`parse_number` accepts the cell (missing cells included)."""
    try:
        parse_number(cell, decimal_comma)
    except NotANumber:
        return False
    return True
