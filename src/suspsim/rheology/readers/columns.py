"""Recognising the columns of a flow curve by their header text.

A header cell holds a name and often a unit: ``Shear rate [1/s]``, ``Shear Rate (1/s)``,
``GP in 1/s`` (HAAKE), ``shear_rate_1/s`` (rheopy-rheodata), ``Viscosity, mPa·s``. The name
is matched whole (not as a substring) against aliases in English, German and a few other
languages, so ``Complex viscosity``, ``Dynamic viscosity`` (oscillatory η′), ``Oscillation
stress`` or ``Stress (step)`` are never taken for the steady-shear columns.
"""
from __future__ import annotations

import re
import unicodedata
from dataclasses import dataclass

from suspsim.rheology.readers.units import UnitError, is_known_unit, si_factor

__all__ = ["Column", "split_header", "classify", "find_columns"]

_ALIASES = {
    "shear_rate": {
        "shear rate", "rate", "gamma dot", "gammadot", "gamma point", "gp", "γ\u0307",
        "dγ/dt", "shearrate", "shear strain rate", "scherrate", "schergeschwindigkeit",
        "schergefälle", "taux de cisaillement", "vitesse de cisaillement",
        "velocidad de corte", "velocidad de cizalla", "taxa de cisalhamento",
        "velocità di taglio",
    },
    "shear_stress": {
        "shear stress", "stress", "tau", "τ", "sigma", "σ", "schubspannung", "scherspannung",
        "contrainte", "contrainte de cisaillement", "esfuerzo cortante",
        "tensión de corte", "tensão de cisalhamento", "sforzo di taglio",
    },
    "viscosity": {
        "viscosity", "eta", "η", "shear viscosity", "apparent viscosity", "steady viscosity",
        "viskosität", "scherviskosität", "viscosité", "viscosidad", "viscosidade",
        "viscosità",
    },
    "sample": {
        "sample", "sample id", "sampleid", "sample name", "samplename", "specimen", "step",
    },
    # Tidy files without a sample column tell their curves apart by volume fraction.
    "sample_by_phi": {"phi", "φ", "volume fraction"},
}
# Short names that mean a shear rate only with a rate unit: HAAKE's "GP in 1/s", whereas
# "Gp_Pa" is a storage modulus G′ in oscillation tables.
_NEEDS_RATE_UNIT = frozenset({"gp"})
_BY_NAME = {alias: quantity for quantity, names in _ALIASES.items() for alias in names}

_SQUARE = re.compile(r"(.*?)\s*\[([^\[\]]*)\]\s*")
_ROUND = re.compile(r"(.*?)\s*\(([^()]*)\)\s*")
_IN = re.compile(r"(.+?)\s+in\s+(\S+)", re.IGNORECASE)
_SLASH = re.compile(r"(.+?)\s+/\s+(.+)")
_COMMA = re.compile(r"(.+?)\s*,\s*(.+)")
_LAST_WORD = re.compile(r"(.+?)\s+(\S+)")
_WORD = re.compile(r"[^\W\d_]+(?:\s+[^\W\d_]+)*")


@dataclass(frozen=True)
class Column:
    """A recognised column: its index in the row, header text, quantity and unit (or None)."""

    index: int
    header: str
    quantity: str
    unit: str | None


def _norm_name(text: str) -> str:
    text = unicodedata.normalize("NFKC", text).replace("\u02d9", "\u0307").lower()
    text = re.sub(r"[_\s]+", " ", text).strip().strip(":.").strip()
    return re.sub(r"\s+\u0307", "\u0307", text)


def split_header(cell: str) -> tuple[str, str | None]:
    """Split a header cell into (normalised name, unit text or None)."""
    text = unicodedata.normalize("NFKC", str(cell)).strip()
    whole = _norm_name(text)
    if whole in _BY_NAME:
        return whole, None
    match = _SQUARE.fullmatch(text)
    if match and match.group(1):
        return _norm_name(match.group(1)), match.group(2).strip()
    match = _ROUND.fullmatch(text)
    if match and match.group(1):
        inner = match.group(2).strip()
        # "(step)", "(complex)", "(cmd)" qualify the name; "(1/s)", "(mPa·s)" are units.
        if not _WORD.fullmatch(inner) or is_known_unit(inner):
            return _norm_name(match.group(1)), inner
        return whole, None
    for pattern in (_IN, _SLASH, _COMMA):
        match = pattern.fullmatch(text)
        if match and _norm_name(match.group(1)) in _BY_NAME:
            return _norm_name(match.group(1)), match.group(2).strip()
    for cut in (i for i, ch in enumerate(text) if ch == "_"):
        if _norm_name(text[:cut]) in _BY_NAME and text[cut + 1:].strip():
            return _norm_name(text[:cut]), text[cut + 1:].strip()
    match = _LAST_WORD.fullmatch(text)
    if match and _norm_name(match.group(1)) in _BY_NAME and is_known_unit(match.group(2)):
        return _norm_name(match.group(1)), match.group(2)
    return whole, None


def _is_rate_unit(unit: str) -> bool:
    try:
        si_factor("shear_rate", unit)
    except UnitError:
        return False
    return True


def classify(name: str) -> str | None:
    """Quantity of a normalised column name (``shear_rate``, ``shear_stress``, ``viscosity``,
    ``sample``, ``sample_by_phi``), or None for columns that are read past (temperature,
    torque, time…)."""
    return _BY_NAME.get(name)


def find_columns(cells: list[object]) -> dict[str, Column]:
    """Map each quantity to the first header cell that names it.

    A later column naming the same quantity again is ignored: real exports repeat a
    quantity only in derived or step-wise forms, and the first is the measured one. A
    ``phi`` column serves as the sample column when there is no ``sample`` column.
    """
    found: dict[str, Column] = {}
    for index, cell in enumerate(cells):
        if cell is None or not isinstance(cell, str) or not cell.strip():
            continue
        name, unit = split_header(cell)
        quantity = classify(name)
        if name in _NEEDS_RATE_UNIT and unit is not None and not _is_rate_unit(unit):
            continue
        if quantity is not None and quantity not in found:
            found[quantity] = Column(index, cell.strip(), quantity, unit)
    by_phi = found.pop("sample_by_phi", None)
    if by_phi is not None and "sample" not in found:
        found["sample"] = Column(by_phi.index, by_phi.header, "sample", None)
    return found
