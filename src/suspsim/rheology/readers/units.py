"""Unit strings of rheometer exports and their factors to SI.

Quantities and their SI units: shear rate in 1/s, shear stress in Pa, viscosity in Pa s.
A unit string is normalised (brackets, spaces and the product signs ``· . * ⋅`` removed,
superscripts made plain) and then looked up case-sensitively, because ``mPa`` and ``MPa``
differ by 10⁹; a case-insensitive match is accepted only when it is unambiguous (``PA``,
``cp``, ``KPA·S``).
"""
from __future__ import annotations

import re
import unicodedata

__all__ = ["QUANTITIES", "si_factor", "normalise_unit", "is_known_unit", "UnitError"]

#: The quantities a flow curve needs, with their SI unit as shown in messages.
QUANTITIES = {"shear_rate": "1/s", "shear_stress": "Pa", "viscosity": "Pa s"}

_RATE = {"1/s": 1.0, "s-1": 1.0, "/s": 1.0, "1/sec": 1.0, "sec-1": 1.0, "s(-1)": 1.0}
_STRESS = {
    "Pa": 1.0, "mPa": 1e-3, "kPa": 1e3, "MPa": 1e6, "N/m2": 1.0, "Nm-2": 1.0,
    "dyn/cm2": 0.1, "dyncm-2": 0.1, "dyne/cm2": 0.1, "µPa": 1e-6,
}
_VISCOSITY = {
    "Pas": 1.0, "mPas": 1e-3, "kPas": 1e3, "MPas": 1e6, "µPas": 1e-6,
    "Ns/m2": 1.0, "Nsm-2": 1.0, "cP": 1e-3, "cPs": 1e-3, "mP": 1e-4, "P": 0.1, "Poise": 0.1,
    "poise": 0.1, "centipoise": 1e-3, "cps": 1e-3, "dyns/cm2": 0.1,
}
_TABLES: dict[str, dict[str, float]] = {
    "shear_rate": _RATE, "shear_stress": _STRESS, "viscosity": _VISCOSITY,
}

# Why a unit that exists is still refused for a quantity.
_REFUSED = {
    ("shear_rate", "1/min"): "1/min is a rotational speed, not a shear rate",
    ("shear_rate", "rpm"): "rpm is a rotational speed, not a shear rate",
    ("shear_rate", "rad/s"): "rad/s is an angular frequency or speed, not a shear rate",
    ("shear_rate", "Hz"): "Hz is a frequency, not a shear rate",
}

_SUPERSCRIPTS = str.maketrans({"⁻": "-", "\u2212": "-", "¹": "1", "²": "2", "³": "3", "μ": "µ"})
_DROP = re.compile(r"[\s·⋅•∙*×^.]")


class UnitError(ValueError):
    """A unit string that cannot be converted for the quantity; str(exc) says why."""


def normalise_unit(unit: str) -> str:
    """Strip brackets, spaces, product signs and superscripts: ``[mPa·s]`` → ``mPas``."""
    text = unicodedata.normalize("NFKC", unit).translate(_SUPERSCRIPTS)
    text = text.strip().strip("[](){}").strip()
    return _DROP.sub("", text)


def _lookup(table: dict[str, float], unit: str) -> float | None:
    if unit in table:
        return table[unit]
    matches = {key for key in table if key.lower() == unit.lower()}
    factors = {table[key] for key in matches}
    if len(factors) == 1:
        return factors.pop()
    return None


def si_factor(quantity: str, unit: str | None) -> float:
    """Factor that converts values of ``quantity`` given in ``unit`` to SI.

    No unit (None or empty) means SI already. Raises UnitError for an unknown unit, or a
    unit that belongs to another quantity (e.g. 1/min for a shear rate).
    """
    if unit is None:
        return 1.0
    norm = normalise_unit(unit)
    if norm == "":
        return 1.0
    refusal = _REFUSED.get((quantity, norm)) or _REFUSED.get((quantity, norm.lower()))
    if refusal:
        raise UnitError(refusal)
    factor = _lookup(_TABLES[quantity], norm)
    if factor is None:
        raise UnitError(f"unknown unit {unit.strip()!r} for {quantity.replace('_', ' ')} "
                        f"(expected a unit of {QUANTITIES[quantity]})")
    return factor


def is_known_unit(text: str) -> bool:
    """True if ``text`` is a unit of any quantity here, or a common one of extra columns."""
    norm = normalise_unit(text)
    if not norm:
        return False
    if any(_lookup(table, norm) is not None for table in _TABLES.values()):
        return True
    return norm.lower() in _OTHER_UNITS


# Units of columns that are read past (temperature, torque, speed, time…), used only to
# recognise a units row.
_OTHER_UNITS = frozenset({
    "°c", "c", "k", "°f", "s", "min", "h", "1/min", "rpm", "rad/s", "hz", "nm", "mnm",
    "µnm", "mn", "n", "g", "mm", "µm", "%", "rad", "°", "1/pa", "1/k", "pas2", "-", "1",
})
