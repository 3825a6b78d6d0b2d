"""Rheometer file readers: every hand-written fixture loads with the right SI numbers, and every
bad input raises InputError naming the file and the line (or sheet)."""
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from suspsim.errors import InputError
from suspsim.rheology.readers import FLOW_CURVE_COLUMNS, list_samples, read_flow_curve
from suspsim.rheology.readers.columns import split_header
from suspsim.rheology.readers.text import decode, parse_number
from suspsim.rheology.readers.units import si_factor

FIXTURES = Path(__file__).resolve().parents[1] / "fixtures" / "rheometry"


def load(name, **kwargs):
    return read_flow_curve(FIXTURES / name, **kwargs)


def assert_valid(df):
    """The contract every successful read must satisfy."""
    assert tuple(df.columns) == FLOW_CURVE_COLUMNS
    assert len(df) > 0
    for column in ("shear_rate", "shear_stress", "viscosity"):
        assert df[column].dtype == np.float64
        assert np.all(np.isfinite(df[column])) and np.all(df[column] > 0)
    assert all(isinstance(s, str) for s in df["sample"])
    assert list(df.index) == list(range(len(df)))
    keys = list(zip(df["sample"], df["shear_rate"], strict=True))
    assert keys == sorted(keys)
    np.testing.assert_allclose(df["shear_stress"], df["viscosity"] * df["shear_rate"],
                               rtol=0.02)
    assert set(df.attrs) == {"source", "format"}


def write(tmp_path, name, content, encoding="utf-8"):
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode(encoding))
    return path


# --- each fixture -------------------------------------------------------------------------

def test_comma_utf8():
    df = load("comma_utf8.csv")
    assert_valid(df)
    assert df.attrs == {"source": str(FIXTURES / "comma_utf8.csv"), "format": "delimited"}
    assert set(df["sample"]) == {"comma_utf8"}
    assert len(df) == 7
    assert df["shear_rate"].tolist() == [0.1, 0.316, 1.0, 3.16, 10.0, 31.6, 100.0]
    assert df.loc[0, "shear_stress"] == 1.199 and df.loc[0, "viscosity"] == 11.99
    # the empty stress cell is derived from η γ̇
    assert df.loc[3, "shear_stress"] == pytest.approx(8.505 * 3.16)


def test_semicolon_decimal_comma_latin1_units_row():
    df = load("semicolon_decimal_comma_latin1.csv")
    assert_valid(df)
    assert len(df) == 11
    assert df.iloc[0][["shear_rate", "shear_stress", "viscosity"]].tolist() == [0.1, 0.43, 4.3]
    assert df.iloc[-1][["shear_rate", "shear_stress", "viscosity"]].tolist() == [
        1000.0, 598.0, 0.598]


def test_tab_utf16le_bom_decimal_comma_exponent():
    df = load("tab_utf16le_bom.txt")
    assert_valid(df)
    assert df["shear_rate"].tolist() == [1e-3, 1e-2, 1e-1, 1.0, 10.0]
    assert df.loc[0, "shear_stress"] == pytest.approx(2.538)
    assert df.loc[0, "viscosity"] == pytest.approx(2538.0)


def test_units_in_header_cgs_conversion():
    df = load("units_in_header_cgs.csv")
    assert_valid(df)
    # 4.925 dyn/cm² = 0.4925 Pa; 9.849 P = 0.9849 Pa s
    assert df.loc[0, "shear_stress"] == pytest.approx(0.4925)
    assert df.loc[0, "viscosity"] == pytest.approx(0.9849)


def test_viscosity_only_mpas_derives_stress():
    df = load("viscosity_only_mpas.csv")
    assert_valid(df)
    np.testing.assert_allclose(df["viscosity"], [0.950, 0.599, 0.378, 0.239])
    np.testing.assert_allclose(df["shear_stress"], [0.950, 5.99, 37.8, 239.0])


def test_viscosity_only_centipoise():
    df = load("viscosity_only_cp.tsv")
    assert_valid(df)
    np.testing.assert_allclose(df["viscosity"], [1.020, 1.000, 0.985, 0.960])
    np.testing.assert_allclose(df["shear_stress"], [5.1, 10.0, 19.7, 48.0])


def test_descending_sweep_is_sorted_ascending():
    df = load("descending_sweep_de.csv")
    assert_valid(df)
    assert df["shear_rate"].tolist() == [0.1, 0.316, 1.0, 3.16, 10.0, 31.6, 100.0]
    assert df.loc[0, "shear_stress"] == 15.95 and df.loc[6, "viscosity"] == 0.45


def test_comments_blank_lines_and_missing_values():
    df = load("comments_blank_lines.csv")
    assert_valid(df)
    assert set(df["sample"]) == {"silicone oil AK 1000"}
    # rows with ' ' rate, '-'/'--' stress+viscosity and zero rate are dropped; 'NaN' stress
    # at 5 1/s is derived from the viscosity
    assert df["shear_rate"].tolist() == [0.5, 1.0, 2.0, 5.0, 20.0]
    assert df.loc[3, "shear_stress"] == pytest.approx(5 * 0.981)


def test_tidy_long_two_samples():
    df = load("tidy_two_samples.csv")
    assert_valid(df)
    assert df.attrs["format"] == "tidy_long"
    assert df["sample"].tolist() == ["gel_A"] * 5 + ["gel_B"] * 5
    assert df.loc[0, "shear_stress"] == 12.3
    assert df.loc[5, "viscosity"] == pytest.approx(4.15 / 0.01)
    assert list_samples(FIXTURES / "tidy_two_samples.csv") == ["gel_A", "gel_B"]
    only_b = load("tidy_two_samples.csv", sample="gel_B")
    assert_valid(only_b)
    assert set(only_b["sample"]) == {"gel_B"} and len(only_b) == 5


@pytest.mark.parametrize("name", ["trios_export.xlsx", "trios_export.xls"])
def test_trios_excel(name):
    df = load(name)
    assert_valid(df)
    assert df.attrs["format"] == "trios_excel"
    assert list_samples(FIXTURES / name) == ["trios_export/Flow sweep - 2",
                                             "trios_export/Flow sweep - 3"]
    up = df[df["sample"] == "trios_export/Flow sweep - 2"]
    down = df[df["sample"] == "trios_export/Flow sweep - 3"]
    assert len(up) == 7 and len(down) == 7  # row without shear rate dropped
    assert up.iloc[0][["shear_rate", "shear_stress", "viscosity"]].tolist() == [
        0.1, 0.284848, 2.84848]
    # the second sheet has another column order and viscosity in mPa.s
    assert down.iloc[0]["shear_rate"] == 0.1
    assert down.iloc[0]["shear_stress"] == 0.290545
    assert down.iloc[0]["viscosity"] == pytest.approx(2.90545)


def test_trios_xls_and_xlsx_agree():
    xls, xlsx = load("trios_export.xls"), load("trios_export.xlsx")
    assert xls.attrs["format"] == xlsx.attrs["format"]
    xls.attrs, xlsx.attrs = {}, {}
    pd.testing.assert_frame_equal(xls, xlsx)


def test_anton_paar_full_export_two_intervals_two_results():
    df = load("anton_paar_rheocompass_utf16.txt")
    assert_valid(df)
    assert df.attrs["format"] == "anton_paar"
    assert list_samples(FIXTURES / "anton_paar_rheocompass_utf16.txt") == [
        "Matrix fluid A", "Matrix fluid B"]
    a = df[df["sample"] == "Matrix fluid A"]
    assert len(a) == 8  # both intervals (up and down ramp) concatenated
    assert a["shear_rate"].tolist() == [0.1, 0.1, 1.0, 1.0, 10.0, 10.0, 100.0, 100.0]
    # viscosity in mPa·s: 1800,0 mPa·s -> 1.8 Pa s
    assert sorted(a[a["shear_rate"] == 0.1]["viscosity"]) == pytest.approx([1.8, 1.9])
    b = df[df["sample"] == "Matrix fluid B"]
    assert b["shear_rate"].tolist() == [0.5, 50.0]  # the point without stress is dropped


def test_haake_rheowin_drops_segments_without_shear_rate():
    df = load("haake_rheowin.txt")
    assert_valid(df)
    assert df.attrs["format"] == "haake_rheowin"
    assert set(df["sample"]) == {"xanthan 0.5% / 7"}
    assert df["shear_rate"].tolist() == [1e-3, 1e-2, 1e-1, 1.0, 10.0]
    assert df.loc[0, "shear_stress"] == 0.004172 and df.loc[0, "viscosity"] == 4.172


def test_path_may_be_str_and_sample_filter_on_single_sample_file():
    df = read_flow_curve(str(FIXTURES / "comma_utf8.csv"), sample="comma_utf8")
    assert_valid(df)
    assert df.attrs["source"] == str(FIXTURES / "comma_utf8.csv")


# --- building blocks ---------------------------------------------------------------------

@pytest.mark.parametrize("header, name, unit", [
    ("Shear rate [1/s]", "shear rate", "1/s"),
    ("Shear Rate (1/s)", "shear rate", "1/s"),
    ("shear_rate_1/s", "shear rate", "1/s"),
    ("stress_Pa", "stress", "Pa"),
    ("viscosity_Pa.s", "viscosity", "Pa.s"),
    ("GP in 1/s", "gp", "1/s"),
    ("Eta in Pas", "eta", "Pas"),
    ("Tau in Pa", "tau", "Pa"),
    ("sample_id", "sample id", None),
    ("Stress (step)", "stress (step)", None),
    ("Viscosity, mPa·s", "viscosity", "mPa·s"),
])
def test_split_header(header, name, unit):
    assert split_header(header) == (name, unit)


@pytest.mark.parametrize("quantity, unit, factor", [
    ("shear_rate", "s^-1", 1.0), ("shear_rate", "s⁻¹", 1.0), ("shear_rate", None, 1.0),
    ("shear_stress", "mPa", 1e-3), ("shear_stress", "kPa", 1e3), ("shear_stress", "dyn/cm2", 0.1),
    ("viscosity", "Pa·s", 1.0), ("viscosity", "Pa s", 1.0), ("viscosity", "mPas", 1e-3),
    ("viscosity", "cP", 1e-3), ("viscosity", "P", 0.1), ("viscosity", "kPa·s", 1e3),
    ("viscosity", "[mPa·s]", 1e-3), ("shear_stress", "MPa", 1e6),
])
def test_si_factor(quantity, unit, factor):
    assert si_factor(quantity, unit) == factor


@pytest.mark.parametrize("cell, value", [
    ("1,5E-3", 1.5e-3), (" 2.5 ", 2.5), ("", None), (" ", None), ("NaN", None), ("-", None),
    ("--", None), (3, 3.0), (None, None), ("inf", math.inf),
])
def test_parse_number(cell, value):
    result = parse_number(cell)
    if value is None:
        assert math.isnan(result)
    else:
        assert result == value


def test_decode_latin1_and_utf16_be(tmp_path):
    assert decode("Pa·s".encode("cp1252"), "x")[0] == "Pa·s"
    assert decode(b"\xfe\xff" + "µ;1".encode("utf-16-be"), "x")[0] == "µ;1"


def test_utf16_be_file(tmp_path):
    text = "Shear rate [1/s]\tViscosity [Pa·s]\r\n1\t2\r\n3\t4\r\n"
    path = write(tmp_path, "be.txt", b"\xfe\xff" + text.encode("utf-16-be"))
    df = read_flow_curve(path)
    assert_valid(df)
    assert df["shear_stress"].tolist() == [2.0, 12.0]


def test_complex_viscosity_is_not_steady_viscosity(tmp_path):
    path = write(tmp_path, "osc.csv", "Shear rate,Complex viscosity\n1,2\n")
    with pytest.raises(InputError, match="no shear-stress or viscosity column"):
        read_flow_curve(path)


def test_speed_in_rpm_is_ignored_and_rate_in_1_per_min_refused(tmp_path):
    path = write(tmp_path, "rpm.csv", "Rate [1/min],Stress [Pa]\n1,2\n")
    with pytest.raises(InputError, match="rotational speed") as info:
        read_flow_curve(path)
    assert "rpm.csv:1" in str(info.value)


# --- bad input --------------------------------------------------------------------------

def assert_input_error(path, *fragments):
    with pytest.raises(InputError) as info:
        read_flow_curve(path)
    message = str(info.value)
    assert Path(path).name in message
    for fragment in fragments:
        assert fragment in message, message
    return info.value


def test_unknown_unit(tmp_path):
    path = write(tmp_path, "unit.csv", "Shear rate [1/s];Shear stress [psi]\n1;2\n")
    error = assert_input_error(path, "unit.csv:1:", "Shear stress [psi]", "psi")
    assert error.line == 1


def test_unknown_unit_in_units_row(tmp_path):
    path = write(tmp_path, "unit_row.csv", "Shear rate;Viscosity\n[1/s];[furlong]\n1;2\n")
    assert_input_error(path, "unit_row.csv:2:", "furlong")


def test_no_shear_rate_column(tmp_path):
    path = write(tmp_path, "norate.csv", "# comment\nTime [s],Stress [Pa]\n1,2\n")
    assert_input_error(path, "norate.csv:2:", "no shear-rate column", "'Time [s]'")


def test_text_in_a_number_cell_names_the_line(tmp_path):
    path = write(tmp_path, "text.csv", "Shear rate;Stress\n1;2\n\n# note\n2;abc\n")
    error = assert_input_error(path, "text.csv:5:", "'abc'", "not a number", "'Stress'")
    assert error.line == 5


def test_decimal_comma_in_comma_file_is_caught(tmp_path):
    path = write(tmp_path, "commas.csv", "rate,stress\n1,5,2,5\n")
    assert_input_error(path, "commas.csv:2:", "decimal comma")


@pytest.mark.parametrize("content", [b"", b"   \n\n", b"# only a comment\n"])
def test_empty_file(tmp_path, content):
    assert_input_error(write(tmp_path, "empty.csv", content), "empty")


def test_header_only_has_no_usable_row(tmp_path):
    path = write(tmp_path, "header.csv", "Shear rate,Stress\n0,0\n-1,2\n")
    assert_input_error(path, "no usable row")


def test_headerless_numbers(tmp_path):
    assert_input_error(write(tmp_path, "nohead.csv", "1,2\n3,4\n"), "nohead.csv:1:",
                       "no header row")


def test_binary_garbage(tmp_path):
    rng = np.random.default_rng(1)
    path = write(tmp_path, "garbage.dat", bytes(rng.integers(0, 256, 4000, dtype=np.uint8)))
    assert_input_error(path)


@pytest.mark.parametrize("suffix", [".xlsx", ".xls"])
def test_corrupt_workbook(tmp_path, suffix):
    data = (FIXTURES / f"trios_export{suffix}").read_bytes()
    assert_input_error(write(tmp_path, f"broken{suffix}", data[: len(data) // 2]), "Excel")


def test_xlsx_without_flow_sheet():
    error = assert_input_error(FIXTURES / "trios_no_flow_step.xlsx", "no steady flow step",
                               "'Details'", "'Amplitude sweep - 1'")
    assert error.sheet is None


def test_text_in_trios_sheet_names_sheet_and_row(tmp_path):
    openpyxl = pytest.importorskip("openpyxl")
    book = openpyxl.Workbook()
    sheet = book.active
    sheet.title = "Flow sweep - 1"
    for row in (["Flow sweep - 1"], ["Shear rate", "Stress"], ["1/s", "Pa"], [1.0, 2.0],
                [2.0, "oops"]):
        sheet.append(row)
    path = tmp_path / "bad_cell.xlsx"
    book.save(path)
    error = assert_input_error(path, "[sheet 'Flow sweep - 1']", "row 5", "'oops'")
    assert error.sheet == "Flow sweep - 1"


def test_unknown_sample_lists_available(tmp_path):
    with pytest.raises(InputError, match="'gel_A', 'gel_B'") as info:
        load("tidy_two_samples.csv", sample="gel_C")
    assert "tidy_two_samples.csv" in str(info.value)


def test_missing_file_and_directory(tmp_path):
    assert_input_error(tmp_path / "absent.csv", "cannot read")
    with pytest.raises(InputError):
        read_flow_curve(tmp_path)


def test_invalid_utf16(tmp_path):
    path = write(tmp_path, "odd.txt", b"\xff\xfe" + "rate\t1".encode("utf-16-le") + b"\x00\xd8")
    assert_input_error(path, "UTF-16")


def test_haake_unexpected_line(tmp_path):
    text = "Substance / Sample no: x / \n\n;GP in 1/s;Tau in Pa;\n1|1;1,0;2,0;\nfooter\n"
    assert_input_error(write(tmp_path, "rw.txt", text, "cp1252"), "rw.txt:5:", "segment|point")


def test_anton_paar_bad_cell(tmp_path):
    text = ("Result:\tR\nInterval data:\tPoint No.\tShear Rate\tShear Stress\n"
            "\t\t[1/s]\t[Pa]\n\t1\t1,0\t2,0\n\t2\tx\t3,0\n")
    assert_input_error(write(tmp_path, "ap.txt", text), "ap.txt:5:", "shear rate 'x'")


def test_phi_column_names_samples_when_no_sample_column(tmp_path):
    path = write(tmp_path, "phi.csv", "phi,shear rate,stress\n0.60,1,2\n0.55,1,1\n0.60,2,3\n")
    df = read_flow_curve(path)
    assert_valid(df)
    assert df.attrs["format"] == "tidy_long"
    assert df["sample"].tolist() == ["0.55", "0.60", "0.60"]


def test_xml_spreadsheet_is_refused(tmp_path):
    path = write(tmp_path, "xml.xls", '<?xml version="1.0"?>\n<Workbook></Workbook>\n')
    assert_input_error(path, "XML or HTML spreadsheet")


def test_anton_paar_interval_without_flow_columns_is_skipped(tmp_path):
    text = ("Result:\tR\nInterval data:\tPoint No.\tTime\tTorque\n\t\t[s]\t[µN·m]\n\t1\t1\t2\n"
            "Interval data:\tPoint No.\tShear Rate\tViscosity\n\t\t[1/s]\t[Pa·s]\n\t1\t2,0\t3,0\n")
    df = read_flow_curve(write(tmp_path, "ap2.txt", text))
    assert_valid(df)
    assert df["sample"].tolist() == ["R"] and df["shear_stress"].tolist() == [6.0]
