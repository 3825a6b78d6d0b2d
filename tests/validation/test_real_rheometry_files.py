"""The rheometer readers on real public exports in ../shared/data/rheometry (see its
PROVENANCE.md). Those files are not in the repository (licences: GPL-3.0 or none for some);
a clone without them skips this module, and tests/fixtures/rheometry covers the formats."""
import csv
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from suspsim.errors import InputError
from suspsim.rheology.readers import FLOW_CURVE_COLUMNS, list_samples, read_flow_curve

DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "rheometry"
if not DATA.is_dir():
    pytest.skip("../shared/data/rheometry not present (only in the developers' and CI "
                "checkout); fixtures in tests/fixtures cover the formats",
                allow_module_level=True)

RHEODATA = DATA / "rheopy-rheodata_0.1.1"
TRIOS = DATA / "rheofit_6f736d7" / "trios_excel"
TRIOS_TIDY = DATA / "rheofit_6f736d7" / "trios_excel_flow_sweeps_tidy"
PYRHEO = DATA / "pyRheo_9435084"
EC_TABLES = sorted((PYRHEO / "ec_solution").glob("ec_shear_viscosity_*.csv"))
HAAKE = DATA / "haake_rheowin_KarlClinckspoor-Rheology_c49709a" / "rheo5.txt"


def ids(paths):
    return [p.parent.name + "/" + p.name for p in paths]


def assert_valid(df):
    assert tuple(df.columns) == FLOW_CURVE_COLUMNS
    values = df[["shear_rate", "shear_stress", "viscosity"]].to_numpy()
    assert np.all(np.isfinite(values)) and np.all(values > 0)
    keys = list(zip(df["sample"], df["shear_rate"], strict=True))
    assert keys == sorted(keys)
    np.testing.assert_allclose(df["shear_stress"], df["viscosity"] * df["shear_rate"],
                               rtol=0.05)


def read_decimal_comma_table(path):
    """Independent parse of the pyRheo ';' decimal-comma Latin-1 tables: (rate, stress, eta)."""
    lines = path.read_bytes().decode("latin-1").splitlines()
    rows = [[float(c.replace(",", ".")) for c in line.split(";")[:3]] for line in lines[2:]
            if line.strip()]
    return np.array(rows)


# --- pyRheo instrument table exports (';', decimal comma, Latin-1, CRLF, units row) -------

def test_ec_shear_viscosity_07_first_point():
    df = read_flow_curve(PYRHEO / "ec_solution" / "ec_shear_viscosity_07-00.csv")
    assert_valid(df)
    assert len(df) == 43
    assert df.loc[0, "shear_rate"] == 0.1
    assert df.loc[0, "viscosity"] == pytest.approx(4.19, rel=1e-12)   # "4,19" [Pa·s]
    assert df.loc[0, "shear_stress"] == pytest.approx(0.419, rel=1e-12)
    assert set(df["sample"]) == {"ec_shear_viscosity_07-00"}


@pytest.mark.parametrize("path", EC_TABLES, ids=ids(EC_TABLES))
def test_ec_tables_match_independent_parse(path):
    df = read_flow_curve(path)
    assert_valid(df)
    expected = read_decimal_comma_table(path)
    expected = expected[np.argsort(expected[:, 0], kind="stable")]
    assert len(df) == len(expected) == 43
    np.testing.assert_allclose(df[["shear_rate", "shear_stress", "viscosity"]].to_numpy(),
                               expected, rtol=1e-12)


def test_rotation_ec07_viscosity_only_derives_stress():
    df = read_flow_curve(PYRHEO / "ec_solution" / "rotation_ec07_data.csv")
    assert_valid(df)
    assert len(df) == 42
    np.testing.assert_allclose(df["shear_stress"], df["viscosity"] * df["shear_rate"],
                               rtol=1e-15)
    # the same measurement as ec_shear_viscosity_07-00, re-saved as tab-separated text
    table = read_flow_curve(PYRHEO / "ec_solution" / "ec_shear_viscosity_07-00.csv")
    merged = df.merge(table, on="shear_rate", suffixes=("", "_table"))
    assert len(merged) >= 40
    np.testing.assert_allclose(merged["viscosity"], merged["viscosity_table"], rtol=1e-12)


def test_cnf_hydrogel():
    df = read_flow_curve(PYRHEO / "cnf_hydrogel" / "rotation_cnf1_data.csv")
    assert_valid(df)
    assert len(df) == 12
    assert df["viscosity"].iloc[0] == pytest.approx(7348.0, rel=1e-6)
    assert df["viscosity"].iloc[-1] < 30.0
    assert 0.09 < df["shear_rate"].iloc[0] < 0.11 and 50 < df["shear_rate"].iloc[-1] < 60


EMULSIONS = sorted((PYRHEO / "emulsion").glob("0.*.csv"))


@pytest.mark.parametrize("path", EMULSIONS, ids=ids(EMULSIONS))
def test_pyrheo_emulsion_rate_stress_tables(path):
    df = read_flow_curve(path)
    assert_valid(df)
    expected = pd.read_csv(path)
    assert len(df) == len(expected) and len(df) >= 29
    np.testing.assert_allclose(df["shear_rate"], np.sort(expected["Shear Rate"]), rtol=1e-15)
    assert set(df["sample"]) == {path.stem}


def test_headerless_wide_file_is_refused_clearly():
    with pytest.raises(InputError, match="no header row") as info:
        read_flow_curve(PYRHEO / "emulsion" / "emulsions_v2.csv")
    assert "emulsions_v2.csv:1" in str(info.value)


# --- rheopy-rheodata tidy long files --------------------------------------------------------

def _rheodata(kind):
    out = []
    for path in sorted(RHEODATA.glob("*/data.csv")):
        header = path.read_text(encoding="utf-8").splitlines()[0]
        if ("shear_rate" in header) == (kind == "flow"):
            out.append(path)
    return out


FLOW_SETS = _rheodata("flow")
OSCILLATION_SETS = _rheodata("oscillation")


@pytest.mark.parametrize("path", FLOW_SETS, ids=ids(FLOW_SETS))
def test_rheodata_flow_sets_match_pandas(path):
    df = read_flow_curve(path)
    assert_valid(df)
    assert df.attrs["format"] == "tidy_long"
    expected = pd.read_csv(path, dtype={"sample_id": str})
    expected = expected[(expected["shear_rate_1/s"] > 0) & (expected["stress_Pa"] > 0)]
    expected = expected.sort_values(["sample_id", "shear_rate_1/s"], kind="mergesort")
    assert list_samples(path) == sorted(expected["sample_id"].unique())
    assert len(df) == len(expected)
    np.testing.assert_allclose(df["shear_rate"], expected["shear_rate_1/s"], rtol=1e-15)
    np.testing.assert_allclose(df["shear_stress"], expected["stress_Pa"], rtol=1e-15)


def test_caggioni_pg_carbopol_2pct_has_61_points():
    df = read_flow_curve(RHEODATA / "caggioni_pg_carbopol_2pct" / "data.csv")
    assert len(df) == 61
    assert set(df["sample"]) == {"carbopol_2pct"}
    assert df["shear_rate"].iloc[0] == pytest.approx(1e-3, rel=0.01)
    assert df["shear_rate"].iloc[-1] == pytest.approx(1e3, rel=0.01)


@pytest.mark.parametrize("path", OSCILLATION_SETS, ids=ids(OSCILLATION_SETS))
def test_rheodata_oscillation_sets_are_refused(path):
    with pytest.raises(InputError, match="no shear-rate column"):
        read_flow_curve(path)


# --- TA TRIOS .xls exports vs. their flow-sweep extracts ------------------------------------

TRIOS_FILES = sorted(TRIOS.glob("*.xls"))


def _tidy_extract(path):
    """The DERIVED extract of the flow sheets, read with the csv module (not our reader)."""
    with open(TRIOS_TIDY / f"{path.stem}_flow.csv", newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    table = pd.DataFrame({
        "sample": [f"{path.stem}/{r['step']}" for r in rows],
        "shear_rate": [float(r["shear_rate_1/s"]) for r in rows],
        "shear_stress": [float(r["stress_Pa"]) for r in rows],
        "viscosity": [float(r["viscosity_Pa.s"]) for r in rows],
    })
    usable = (table[["shear_rate", "shear_stress", "viscosity"]] > 0).all(axis=1)
    return table[usable].sort_values(["sample", "shear_rate"], kind="mergesort")


@pytest.mark.parametrize("path", TRIOS_FILES, ids=ids(TRIOS_FILES))
def test_trios_xls_matches_tidy_extract(path):
    df = read_flow_curve(path)
    assert_valid(df)
    assert df.attrs["format"] == "trios_excel"
    samples = list_samples(path)
    assert len(samples) >= 1
    assert all(s.startswith(f"{path.stem}/Flow") for s in samples)
    assert all((df["sample"] == s).sum() > 10 for s in samples)
    expected = _tidy_extract(path)
    assert samples == sorted(expected["sample"].unique())
    assert len(df) == len(expected)
    for column in ("shear_rate", "shear_stress", "viscosity"):
        np.testing.assert_allclose(df[column], expected[column], rtol=1e-9)


def test_trios_two_sweeps_with_different_column_orders():
    df = read_flow_curve(TRIOS / "Flow_curve_example.xls")
    assert list_samples(TRIOS / "Flow_curve_example.xls") == [
        "Flow_curve_example/Flow sweep - 1", "Flow_curve_example/Flow sweep - 2"]
    up = df[df["sample"].str.endswith("1")]
    # first point of "Flow sweep - 1" (columns Stress, Shear rate, Viscosity…)
    assert up["shear_rate"].iloc[0] == pytest.approx(0.00998318, rel=1e-6)
    assert up["viscosity"].iloc[0] == pytest.approx(0.588953, rel=1e-6)


def test_trios_sample_filter():
    path = TRIOS / "Flow_curve_example.xls"
    df = read_flow_curve(path, sample="Flow_curve_example/Flow sweep - 2")
    assert set(df["sample"]) == {"Flow_curve_example/Flow sweep - 2"} and len(df) == 41


# --- everything else: loads or fails with InputError -----------------------------------------

OTHER = sorted(p for p in (DATA / "rheofit_6f736d7" / "digitized").glob("*.csv"))


@pytest.mark.parametrize("path", OTHER, ids=ids(OTHER))
def test_digitized_files_load_or_raise_input_error(path):
    # WebPlotDigitizer exports (wide, φ labels, no column names) are not a supported format;
    # they must be refused with a clear InputError, never crash.
    try:
        df = read_flow_curve(path)
    except InputError as exc:
        assert path.name in str(exc)
    else:
        assert_valid(df)


@pytest.mark.skipif(not HAAKE.exists(), reason="the real RheoWin export is not in shared/")
def test_real_haake_rheowin_export():
    df = read_flow_curve(HAAKE)
    assert_valid(df)
    assert set(df["sample"]) == {"teste5"}
    assert len(df) == 10  # segments 1-2 have no shear rate
    assert df["shear_rate"].iloc[0] == pytest.approx(0.0009999)
