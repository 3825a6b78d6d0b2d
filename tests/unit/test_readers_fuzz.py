"""Property test of the rheometer readers on mangled fixtures: whatever the bytes, read_flow_curve
returns a valid flow-curve table or raises InputError; no other exception may escape.

Mangling: truncation, byte deletion/insertion/replacement, line deletion/duplication/swaps,
a duplicated header, swapped delimiters and decimal marks, re-encoding (UTF-8 ± BOM, cp1252,
UTF-16 LE/BE with and without BOM), random Unicode text and random cells. About 4000
examples in all, ~15 s on two cores; ``database=None`` keeps no .hypothesis folder behind.
"""
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from suspsim.errors import InputError
from suspsim.rheology.readers import FLOW_CURVE_COLUMNS, read_flow_curve
from suspsim.rheology.readers.text import decode

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "rheometry"
TEXT_FIXTURES = sorted(p for p in FIXTURES.iterdir()
                       if p.is_file() and p.suffix in (".csv", ".tsv", ".txt"))
EXCEL_FIXTURES = sorted(FIXTURES.glob("*.xls*"))
FUZZ = settings(max_examples=1000, deadline=None, database=None,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])

_ENCODINGS = ["utf-8", "utf-8-sig", "cp1252", "latin-1", "utf-16", "utf-16-le", "utf-16-be"]
_BOMS = {"utf-16-le": b"\xff\xfe", "utf-16-be": b"\xfe\xff"}


def check(path):
    """The property: a valid table or an InputError."""
    try:
        df = read_flow_curve(path)
    except InputError as exc:
        assert str(path) in str(exc)
        return
    assert tuple(df.columns) == FLOW_CURVE_COLUMNS
    assert len(df) > 0
    values = df[["shear_rate", "shear_stress", "viscosity"]].to_numpy()
    assert values.dtype == np.float64
    assert np.all(np.isfinite(values)) and np.all(values > 0)
    assert all(isinstance(s, str) for s in df["sample"])
    keys = list(zip(df["sample"], df["shear_rate"], strict=True))
    assert keys == sorted(keys)
    assert list(df.index) == list(range(len(df)))


@st.composite
def byte_mutation(draw, data):
    kind = draw(st.sampled_from(["truncate", "delete", "insert", "replace"]))
    if not data:
        return draw(st.binary(max_size=50))
    at = draw(st.integers(0, len(data)))
    if kind == "truncate":
        return data[:at]
    if kind == "delete":
        return data[:at] + data[at + draw(st.integers(1, 40)):]
    chunk = draw(st.binary(min_size=1, max_size=20))
    if kind == "insert":
        return data[:at] + chunk + data[at:]
    return data[:at] + chunk + data[at + len(chunk):]


@st.composite
def text_mutation(draw, text):
    lines = text.split("\n")
    kind = draw(st.sampled_from(["delete_line", "duplicate_line", "duplicate_header",
                                 "swap_lines", "insert_unicode", "replace_cell",
                                 "swap_delimiters", "swap_decimal", "delete_chars"]))
    i = draw(st.integers(0, max(len(lines) - 1, 0)))
    j = draw(st.integers(0, max(len(lines) - 1, 0)))
    if kind == "delete_line" and lines:
        del lines[i]
    elif kind == "duplicate_line" and lines:
        lines.insert(j, lines[i])
    elif kind == "duplicate_header":
        first = next((n for n, line in enumerate(lines) if line.strip()
                      and not line.startswith("#")), 0)
        lines.insert(first + draw(st.integers(1, 3)), lines[first] if lines else "")
    elif kind == "swap_lines" and lines:
        lines[i], lines[j] = lines[j], lines[i]
    elif kind == "insert_unicode":
        at = draw(st.integers(0, len(lines[i]) if lines else 0))
        junk = draw(st.text(max_size=15))
        lines[i] = lines[i][:at] + junk + lines[i][at:] if lines else junk
    elif kind == "replace_cell" and lines:
        cells = lines[i].split(draw(st.sampled_from([";", "\t", ","])))
        k = draw(st.integers(0, len(cells) - 1))
        cells[k] = draw(st.one_of(st.text(max_size=8), st.sampled_from(
            ["", " ", "NaN", "-", "--", "inf", "-1", "0", "1e999", "1,2,3", "1.2.3", "[Pa]",
             "Shear rate", "Viscosity [psi]"])))
        lines[i] = ";".join(cells) if ";" in lines[i] else "\t".join(cells)
    elif kind == "swap_delimiters":
        a, b = draw(st.permutations([";", "\t", ","]))[:2]
        text = "\n".join(lines).replace(a, b)
        return text
    elif kind == "swap_decimal":
        text = "\n".join(lines)
        return text.replace(",", ".") if draw(st.booleans()) else text.replace(".", ",")
    elif kind == "delete_chars" and lines:
        at = draw(st.integers(0, len(lines[i])))
        lines[i] = lines[i][:at] + lines[i][at + draw(st.integers(1, 5)):]
    return "\n".join(lines)


def encode(draw, text):
    encoding = draw(st.sampled_from(_ENCODINGS))
    data = text.encode(encoding, errors="replace")
    if encoding in _BOMS and draw(st.booleans()):
        data = _BOMS[encoding] + data
    return data


@st.composite
def mangled_text(draw):
    path = draw(st.sampled_from(TEXT_FIXTURES))
    text, _ = decode(path.read_bytes(), path)
    for _ in range(draw(st.integers(1, 3))):
        text = draw(text_mutation(text))
    data = encode(draw, text)
    if draw(st.booleans()):
        data = draw(byte_mutation(data))
    return path.suffix, data


@st.composite
def mangled_bytes(draw, fixtures):
    path = draw(st.sampled_from(fixtures))
    data = path.read_bytes()
    for _ in range(draw(st.integers(1, 4))):
        data = draw(byte_mutation(data))
    return path.suffix, data


@pytest.fixture(scope="session")
def fuzz_dir(tmp_path_factory):
    return tmp_path_factory.mktemp("fuzz")


def _write(directory, suffix, data):
    path = directory / f"mangled{suffix}"
    path.write_bytes(data)
    return path


@FUZZ
@given(case=mangled_text())
def test_mangled_text_lines_encodings(fuzz_dir, case):
    check(_write(fuzz_dir, *case))


@FUZZ
@given(case=mangled_bytes(TEXT_FIXTURES))
def test_mangled_text_bytes(fuzz_dir, case):
    check(_write(fuzz_dir, *case))


@FUZZ
@given(case=mangled_bytes(EXCEL_FIXTURES))
def test_mangled_workbooks(fuzz_dir, case):
    check(_write(fuzz_dir, *case))


@settings(FUZZ, max_examples=500)
@given(data=st.binary(max_size=2000), suffix=st.sampled_from([".csv", ".txt", ".xls", ".xlsx"]))
def test_random_bytes(fuzz_dir, data, suffix):
    check(_write(fuzz_dir, suffix, data))


@settings(FUZZ, max_examples=500)
@given(text=st.text(max_size=400), encoding=st.sampled_from(_ENCODINGS))
def test_random_unicode_text(fuzz_dir, text, encoding):
    check(_write(fuzz_dir, ".csv", text.encode(encoding, errors="replace")))
