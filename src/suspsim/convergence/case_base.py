"""What every kind of validation case of the speed-against-error study shares (:mod:`.cases`,
:mod:`.dst_cases`, :mod:`.suspension_cases`): the numerical axes it sweeps, their validated
settings, and what one run measured."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

from suspsim.errors import InputError
from suspsim.validation.flows import Reading

#: Steps of the untimed warm-up that loads the compiled code [choice].
WARM_UP_STEPS = 2


@dataclass(frozen=True)
class Axis:
    """A numerical setting a study may sweep: ``name``, its ``default``, ``unit`` (UDUNITS or
    "1") and what it is."""

    name: str
    default: Any
    unit: str
    description: str


class CaseSettings:
    """The axes' defaults and their validated overrides (shared by every kind of case)."""

    name: str
    axes: tuple[Axis, ...]

    def settings(self, overrides: Mapping[str, Any] | None = None) -> dict[str, Any]:
        """The axes' defaults updated by ``overrides``; an unknown axis is an InputError."""
        names = {axis.name: axis for axis in self.axes}
        out = {name: axis.default for name, axis in names.items()}
        for key, value in (overrides or {}).items():
            if key not in names:
                raise InputError(f"case {self.name}", f"unknown setting '{key}'; the case sweeps "
                                 f"{', '.join(names)}", key=key)
            out[key] = value
        return out


@dataclass(frozen=True)
class Run:
    """What a case's ``execute`` measured: the error ``reading`` and the run's size
    (particles, steps, time step [τ], sound speed [h τ⁻¹], number density [h⁻ᵈ] and q after
    snapping; NaN where the solver has none) and its set-up and run wall times [s]."""

    reading: Reading
    n_particles: int
    n_steps: int
    dt: float
    sound_speed: float
    number_density: float
    resolution_used: float
    setup_time: float
    run_time: float
