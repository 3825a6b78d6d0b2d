"""From recognised columns and raw rows to the flow-curve DataFrame, shared by all formats.

Every format reader ends up with rows of cells (text or spreadsheet values), a header mapped
by :mod:`columns` and units; this module parses the needed cells (reporting the exact line or
sheet row of a bad one), converts to SI (shear rate 1/s, stress Pa, viscosity Pa s), derives
the missing one of stress and viscosity (τ = η γ̇), drops unusable rows and sorts.
"""
from __future__ import annotations

import logging
from collections.abc import Iterable
from dataclasses import dataclass
from os import PathLike

import numpy as np
import pandas as pd

from suspsim.errors import InputError
from suspsim.rheology.readers.columns import Column
from suspsim.rheology.readers.text import NotANumber, parse_number
from suspsim.rheology.readers.units import UnitError, normalise_unit, si_factor

__all__ = ["FLOW_CURVE_COLUMNS", "Block", "Locator", "require_columns", "resolve_factors",
           "read_rows", "assemble"]

logger = logging.getLogger(__name__)

#: Columns of the table :func:`suspsim.rheology.readers.read_flow_curve` returns.
FLOW_CURVE_COLUMNS = ("shear_rate", "shear_stress", "viscosity", "sample")

_NEEDED = ("shear_rate", "shear_stress", "viscosity")
_LABEL = {"shear_rate": "shear rate", "shear_stress": "shear stress", "viscosity": "viscosity"}


@dataclass
class Block:
    """One sample's rows in SI units; a quantity the file lacks is None."""

    sample: str
    shear_rate: np.ndarray
    shear_stress: np.ndarray | None
    viscosity: np.ndarray | None


@dataclass(frozen=True)
class Locator:
    """Builds InputErrors that point at a text line, or at a row of a worksheet."""

    source: str
    sheet: str | None = None

    def error(self, position: int | None, problem: str) -> InputError:
        """InputError at 1-based ``position`` (line in text, row in a sheet)."""
        if self.sheet is None:
            return InputError(self.source, problem, line=position)
        if position is not None:
            problem = f"row {position}: {problem}"
        return InputError(self.source, problem, sheet=self.sheet)


def require_columns(columns: dict[str, Column], header: list[object], locator: Locator,
                    position: int | None) -> None:
    """Raise unless there is a shear-rate column and a stress or viscosity column."""
    names = [str(c).strip() for c in header if c is not None and str(c).strip()]
    shown = ", ".join(repr(n) for n in names[:20]) or "none"
    if "shear_rate" not in columns:
        raise locator.error(position, "no shear-rate column (looked for a name such as "
                                      f"'Shear rate', 'GP', 'γ̇' or 'shear_rate_1/s'); columns: "
                                      f"{shown}")
    if "shear_stress" not in columns and "viscosity" not in columns:
        raise locator.error(position, "no shear-stress or viscosity column (looked for names "
                                      "such as 'Shear stress', 'Tau', 'Viscosity', 'Eta'); "
                                      f"columns: {shown}")


def resolve_factors(columns: dict[str, Column], units_row: list[object] | None,
                    locator: Locator, position: int | None) -> dict[str, float]:
    """SI factor of each needed column, from the unit in its header or in a units row.

    A unit given both ways must agree. No unit at all means SI.
    """
    factors = {}
    for quantity in _NEEDED:
        column = columns.get(quantity)
        if column is None:
            continue
        unit = column.unit
        if units_row is not None and column.index < len(units_row):
            cell = units_row[column.index]
            row_unit = str(cell).strip() if cell is not None else ""
            if row_unit and unit and normalise_unit(row_unit) != normalise_unit(unit):
                raise locator.error(position, f"column {column.header!r} has unit {unit!r} in "
                                              f"its name but {row_unit!r} in the units row")
            unit = row_unit or unit
        try:
            factors[quantity] = si_factor(quantity, unit)
        except UnitError as exc:
            raise locator.error(position, f"column {column.header!r}: {exc}") from None
    return factors


def read_rows(rows: Iterable[tuple[int, list[object]]], columns: dict[str, Column],
              factors: dict[str, float], *, default_sample: str, decimal_comma: bool,
              locator: Locator) -> list[Block]:
    """Parse the needed cells of ``(position, cells)`` rows into Blocks, one per sample.

    Missing cells become NaN (dropped later); a cell that is not a number raises an
    InputError at its position. Rows with an empty sample cell are skipped.
    """
    wanted = [q for q in _NEEDED if q in columns]
    sample_column = columns.get("sample")
    values: dict[str, dict[str, list[float]]] = {}
    for position, cells in rows:
        sample = default_sample
        if sample_column is not None:
            cell = cells[sample_column.index] if sample_column.index < len(cells) else None
            sample = "" if cell is None else _sample_text(cell)
            if not sample:
                logger.debug("%s: row %s has no sample name, skipped", locator.source, position)
                continue
        target = values.setdefault(sample, {q: [] for q in wanted})
        for quantity in wanted:
            column = columns[quantity]
            cell = cells[column.index] if column.index < len(cells) else None
            try:
                value = parse_number(cell, decimal_comma)
            except NotANumber as exc:
                raise locator.error(position, f"{_LABEL[quantity]} {str(exc)!r} in column "
                                              f"{column.header!r} is not a number") from None
            target[quantity].append(value * factors[quantity])
    blocks = []
    for sample, data in values.items():
        arrays = {q: np.asarray(data[q], dtype=np.float64) if q in data else None
                  for q in _NEEDED}
        blocks.append(Block(sample, arrays["shear_rate"], arrays["shear_stress"],
                            arrays["viscosity"]))
    return blocks


def _sample_text(cell: object) -> str:
    if isinstance(cell, float) and cell.is_integer():
        return str(int(cell))
    return str(cell).strip()


def _complete(block: Block) -> pd.DataFrame:
    rate = block.shear_rate
    stress = block.shear_stress if block.shear_stress is not None else np.full_like(rate, np.nan)
    eta = block.viscosity if block.viscosity is not None else np.full_like(rate, np.nan)
    with np.errstate(all="ignore"):
        stress = np.where(np.isnan(stress), eta * rate, stress)
        eta = np.where(np.isnan(eta), stress / rate, eta)
        usable = (np.isfinite(rate) & (rate > 0) & np.isfinite(stress) & (stress > 0)
                  & np.isfinite(eta) & (eta > 0))
    return pd.DataFrame({"shear_rate": rate[usable], "shear_stress": stress[usable],
                         "viscosity": eta[usable],
                         "sample": pd.Series([block.sample] * int(usable.sum()), dtype=object)})


def assemble(blocks: list[Block], source: str | PathLike, fmt: str,
             sample: str | None = None) -> pd.DataFrame:
    """Build the final flow-curve table (see ``read_flow_curve``) from format-neutral blocks."""
    frames = [frame for frame in map(_complete, blocks) if len(frame)]
    total = sum(len(block.shear_rate) for block in blocks)
    table = (pd.concat(frames, ignore_index=True) if frames
             else pd.DataFrame({c: [] for c in FLOW_CURVE_COLUMNS}))
    if len(table) < total:
        logger.info("%s: dropped %d of %d rows with missing, non-positive or non-finite "
                    "shear rate or stress/viscosity", source, total - len(table), total)
    if table.empty:
        raise InputError(source, "no usable row: every data row lacks a positive, finite "
                                 "shear rate together with a shear stress or viscosity")
    table = table.astype({"shear_rate": np.float64, "shear_stress": np.float64,
                          "viscosity": np.float64})
    available = sorted(set(table["sample"]))
    if sample is not None:
        if sample not in available:
            raise InputError(source, f"no sample {sample!r} in this file; samples: "
                                     + ", ".join(repr(s) for s in available))
        table = table[table["sample"] == sample]
    table = table.sort_values(["sample", "shear_rate"], kind="mergesort").reset_index(drop=True)
    table = table.loc[:, list(FLOW_CURVE_COLUMNS)]
    table.attrs = {"source": str(source), "format": fmt}
    return table
