"""Physical ↔ simulation units (SPEC §7): one mapping per simulated physical shear rate.

A non-Brownian suspension at Re ≪ 1 has a relative viscosity that depends only on φ, the shapes
and the dimensionless shape of μ(γ̇) (seed 000). A physical shear rate γ̇ [1/s] is therefore
simulated at a fixed simulation rate γ̇_sim [τ⁻¹] with a time scale T and a viscosity scale S_μ
chosen so that the law keeps its dimensionless shape and the flow stays creeping:

    T   = γ̇_sim / γ̇                          [s per τ]       (so γ̇_sim = T γ̇)
    S_μ = μ(γ̇) Re / (ρ_sim ℓ² γ̇_sim)          [Pa s per simulation viscosity unit]
    S_σ = S_μ / T                             [Pa per simulation stress unit]

where μ(γ̇) is the fitted matrix law at the physical rate, ρ_sim = number density × m the
simulation density [m h⁻ᵈ], ℓ the particle length of the Reynolds number [h] (the kernel support
h = 1 for the matrix alone, the inclusion radius once there are inclusions) and Re the target
particle Reynolds number ρ_sim ℓ² γ̇_sim / μ_sim(γ̇_sim), at most :data:`MAX_REYNOLDS`.

Every law parameter converts by its declared unit (``Parameter.unit`` of
:mod:`suspsim.rheology.laws`). A quantity of dimension Pa^a s^b is divided by S_σ^a T^b [derived]:

======== ======== =========================== ================================================
unit     (a, b)   simulation value            check
======== ======== =========================== ================================================
Pa s     (1, 1)   x / S_μ                     S_σ T = S_μ
s        (0, 1)   x / T                       λγ̇ and Mγ̇ are unchanged
1/s      (0, −1)  x T                         γ̇/γ̇_c is unchanged
Pa       (1, 0)   x T / S_μ                   τ_y/(μγ̇) is unchanged
Pa s^n   (1, n)   x / (S_μ T^(n−1))           K γ̇^(n−1) = S_μ K_sim γ̇_sim^(n−1)
1        (0, 0)   x                           —
======== ======== =========================== ================================================

so that μ_sim(T γ̇') S_μ = μ(γ̇') at every rate γ̇', and stresses convert back as σ = S_σ σ_sim.
With a physical particle size a [m] and its simulated radius a_sim [h] the length scale is
L = a / a_sim [m per h]; the matrix alone has none.

Symbols: γ̇ physical rate [1/s]; γ̇_sim simulation rate [τ⁻¹]; T time scale [s/τ]; S_μ, S_σ
viscosity and stress scales; ρ_sim simulation density [m h⁻ᵈ]; ℓ Reynolds length [h]; Re
particle Reynolds number [1]; Ma = v/c Mach number [1] (known after a run).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from .errors import InputError
from .rheology.laws import ConstitutiveLaw, make_law

#: The simulation shear rate every physical rate is mapped to [τ⁻¹] [choice]: any value gives
#: the same dimensionless run (all scales follow it); 0.01 keeps simulated times readable.
SIMULATION_SHEAR_RATE = 0.01
#: Default target particle Reynolds number [1] [choice]: the SPEC §7 limit. Lower values cost
#: steps: the viscous step limit scales with Re and the acoustic one with sqrt(Re).
DEFAULT_REYNOLDS = 0.1
#: Largest particle Reynolds number accepted [1] (SPEC §7: Re ≤ 0.1).
MAX_REYNOLDS = 0.1

#: Dimension of each parameter unit as powers (a, b) of Pa^a s^b; "n" is the law's flow index.
UNIT_POWERS: Mapping[str, tuple[float, float | str]] = {
    "Pa s": (1, 1), "s": (0, 1), "1/s": (0, -1), "Pa": (1, 0), "Pa s^n": (1, "n"), "1": (0, 0)}


@dataclass(frozen=True)
class UnitMapping:
    """The scales of one simulated physical shear rate (module docstring).

    Attributes
    ----------
    shear_rate : physical shear rate γ̇ [1/s].
    simulation_shear_rate : γ̇_sim [τ⁻¹].
    time_scale : T [s per τ].
    viscosity_scale : S_μ [Pa s per simulation viscosity unit m h^(2−d) τ⁻¹].
    density : ρ_sim [m h⁻ᵈ].
    reynolds_length : ℓ [h].
    reynolds_number : particle Re = ρ_sim ℓ² γ̇_sim / μ_sim(γ̇_sim) [1].
    matrix_viscosity : μ(γ̇) of the fitted law [Pa s].
    length_scale : L [m per h] when a physical particle size is known, else None.
    mach_number : Mach number of the run [1] once known, else None.
    """

    shear_rate: float
    simulation_shear_rate: float
    time_scale: float
    viscosity_scale: float
    density: float
    reynolds_length: float
    reynolds_number: float
    matrix_viscosity: float
    length_scale: float | None = None
    mach_number: float | None = None

    @property
    def stress_scale(self) -> float:
        """S_σ = S_μ / T [Pa per simulation stress unit m h^(1−d) τ⁻²]."""
        return self.viscosity_scale / self.time_scale

    def rate_to_simulation(self, shear_rate):
        """γ̇_sim = T γ̇ [τ⁻¹] from a physical rate [1/s]."""
        return np.asarray(shear_rate, dtype=float) * self.time_scale

    def time_to_physical(self, time):
        """t = T t_sim [s] from a simulation time [τ]."""
        return np.asarray(time, dtype=float) * self.time_scale

    def viscosity_to_physical(self, viscosity):
        """μ = S_μ μ_sim [Pa s] from a simulation viscosity."""
        return np.asarray(viscosity, dtype=float) * self.viscosity_scale

    def stress_to_physical(self, stress):
        """σ = S_σ σ_sim [Pa] from a simulation stress."""
        return np.asarray(stress, dtype=float) * self.stress_scale

    def length_to_physical(self, length):
        """x = L x_sim [m] from a length in h; InputError when no particle size was given."""
        if self.length_scale is None:
            raise InputError("unit mapping", "no physical length scale: give the particle size "
                             "[m] and its simulated radius [h] to convert lengths")
        return np.asarray(length, dtype=float) * self.length_scale

    def law_to_simulation(self, law: ConstitutiveLaw) -> ConstitutiveLaw:
        """The same law with every parameter converted by its unit (module docstring table)."""
        return make_law(law.name, {p.name: convert_parameter(law.params[p.name], p.unit,
                                                             self.time_scale, self.viscosity_scale,
                                                             flow_index=law.params.get("n"))
                                   for p in law.spec.parameters})

    def with_mach(self, mach_number: float) -> "UnitMapping":
        """A copy carrying the run's Mach number [1]."""
        return dataclasses.replace(self, mach_number=float(mach_number))

    def to_attributes(self) -> dict[str, float]:
        """Every scale, Re and (when known) Mach as flat netCDF attributes, units in the names."""
        out = {"unit_shear_rate_per_s": self.shear_rate,
               "unit_simulation_shear_rate_per_tau": self.simulation_shear_rate,
               "unit_time_scale_s_per_tau": self.time_scale,
               "unit_viscosity_scale_pa_s": self.viscosity_scale,
               "unit_stress_scale_pa": self.stress_scale,
               "unit_simulation_density": self.density,
               "unit_reynolds_length_h": self.reynolds_length,
               "unit_particle_reynolds_number": self.reynolds_number,
               "unit_matrix_viscosity_pa_s": self.matrix_viscosity}
        if self.length_scale is not None:
            out["unit_length_scale_m_per_h"] = self.length_scale
        if self.mach_number is not None:
            out["unit_mach_number"] = self.mach_number
        return {k: float(v) for k, v in out.items()}


def convert_parameter(value: float, unit: str, time_scale: float, viscosity_scale: float, *,
                      flow_index: float | None = None) -> float:
    """A law parameter of ``unit`` in simulation units: value / (S_σ^a T^b) (module docstring).

    ``flow_index`` is the law's n, needed for ``"Pa s^n"``. Raises ValueError for a unit this
    table does not know (a new law must declare one of :data:`UNIT_POWERS`).
    """
    try:
        a, b = UNIT_POWERS[unit]
    except KeyError:
        raise ValueError(f"no simulation-unit conversion for parameter unit {unit!r}; "
                         f"known: {', '.join(UNIT_POWERS)}") from None
    if b == "n":
        if flow_index is None:
            raise ValueError("a parameter in 'Pa s^n' needs the law's flow index n")
        b = flow_index
    stress_scale = viscosity_scale / time_scale
    return float(value) / (stress_scale ** a * time_scale ** b)


def unit_mapping(law: ConstitutiveLaw, shear_rate: float, *, density: float,
                 reynolds_number: float = DEFAULT_REYNOLDS,
                 simulation_shear_rate: float = SIMULATION_SHEAR_RATE,
                 reynolds_length: float = 1.0, particle_size: float | None = None,
                 particle_radius: float | None = None) -> UnitMapping:
    """The mapping of physical ``shear_rate`` [1/s] for the fitted ``law`` (SI parameters).

    Parameters
    ----------
    law : the matrix law in SI units.
    shear_rate : physical rate γ̇ > 0 [1/s].
    density : simulation density ρ_sim = number density × m [m h⁻ᵈ].
    reynolds_number : target particle Re, 0 < Re ≤ :data:`MAX_REYNOLDS`.
    simulation_shear_rate : γ̇_sim > 0 [τ⁻¹].
    reynolds_length : ℓ [h] of the Reynolds number (1 = h for the matrix alone).
    particle_size, particle_radius : a physical radius [m] and its simulated radius [h]; both
        or neither; they set the length scale L = particle_size / particle_radius [m per h].

    Raises
    ------
    InputError : a non-positive or non-finite rate, density, length or Re, Re above the limit,
        or a law viscosity that is not positive and finite at the rate.
    """
    _positive("shear_rate", shear_rate, "1/s")
    _positive("density", density, "m h^-d")
    _positive("simulation_shear_rate", simulation_shear_rate, "1/tau")
    _positive("reynolds_length", reynolds_length, "h")
    _positive("reynolds_number", reynolds_number, "1")
    if reynolds_number > MAX_REYNOLDS:
        raise InputError("unit mapping", f"reynolds_number {reynolds_number:g} exceeds "
                         f"{MAX_REYNOLDS:g}: the mapping assumes creeping flow (SPEC §7)")
    if (particle_size is None) != (particle_radius is None):
        raise InputError("unit mapping", "give both particle_size [m] and particle_radius [h] "
                         "for a length scale, or neither")
    length_scale = None
    if particle_size is not None:
        _positive("particle_size", particle_size, "m")
        _positive("particle_radius", particle_radius, "h")
        length_scale = float(particle_size) / float(particle_radius)
    mu = float(law.viscosity(float(shear_rate)))
    if not (math.isfinite(mu) and mu > 0):
        raise InputError("unit mapping", f"the {law.name} law gives viscosity {mu:g} Pa s at "
                         f"{shear_rate:g} 1/s; a mapping needs a positive, finite value")
    time_scale = simulation_shear_rate / float(shear_rate)
    viscosity_scale = (mu * reynolds_number
                       / (density * reynolds_length ** 2 * simulation_shear_rate))
    return UnitMapping(shear_rate=float(shear_rate),
                       simulation_shear_rate=float(simulation_shear_rate),
                       time_scale=time_scale, viscosity_scale=viscosity_scale,
                       density=float(density), reynolds_length=float(reynolds_length),
                       reynolds_number=float(reynolds_number), matrix_viscosity=mu,
                       length_scale=length_scale)


def _positive(name: str, value, unit: str) -> None:
    try:
        ok = math.isfinite(float(value)) and float(value) > 0
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise InputError("unit mapping", f"{name} must be a positive number [{unit}], "
                         f"got {value!r}")
