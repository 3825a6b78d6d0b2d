"""The DST output registry: every variable and attribute of a ``suspsim run`` DST file.

A DST scene (:mod:`suspsim.dst.scene`) is in any consistent units. With ``units: SI`` its
numbers are SI and each variable carries its UDUNITS ``units`` (``Pa``, ``s-1``, ...). With
``units: scene`` (the default) they are pure numbers in the scene's own units — length L (that
of ``box``), mass M and time T (those of the fluid parameters) — so each variable carries
``units = "1"`` and, when it has a dimension, ``simulation_units`` in L, M and T with UDUNITS
exponent syntax (e.g. ``"M L-1 T-2"`` for a stress; these letters are not UDUNITS symbols).
The 2-D fields are per unit depth: a stress is a force per area, a density a mass per volume.
No CF standard name fits, so no variable has ``standard_name``.
"""
from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Mapping

from .netcdf import Registry
from .variables import Attribute

SI_UNIT_SYSTEM = ("SI units (the scene's parameters are SI); 2-D fields per unit depth, so a "
                  "stress is in Pa and a density in kg m-3")
SCENE_UNIT_SYSTEM = ("scene units: the consistent units of the scene's parameters, length L "
                     "(that of box), mass M and time T; variables have units '1' and state "
                     "their dimension in simulation_units in L, M and T (with eta_s = "
                     "sigma_star = box[1] = 1, L is the gap, T = eta_s/sigma_star and "
                     "M L-1 T-2 = sigma_star); 2-D fields per unit depth")
REFERENCES = (
    "Wyart & Cates, Phys. Rev. Lett. 112, 098302 (2014) (steady law); "
    "seed 002 (2D SPH of DST with microstructure Df/Dt = K_f gdot (f_hat - f) + alpha lap f); "
    "Morris, Fox & Zhu, J. Comput. Phys. 136, 214 (1997) (SPH viscous operator, time step); "
    "Adami, Hu & Adams, J. Comput. Phys. 231, 7057 (2012) (walls); "
    "Lind et al., J. Comput. Phys. 231, 1499 (2012) (particle shifting)")

# Powers of (length, mass, time).
_NONE = (0, 0, 0)
_TIME = (0, 0, 1)
_LENGTH = (1, 0, 0)
_VELOCITY = (1, 0, -1)
_RATE = (0, 0, -1)
_STRESS = (-1, 1, -2)
_VISCOSITY = (-1, 1, -1)
_SI_NAMES = {_STRESS: "Pa", _VISCOSITY: "Pa s"}


def unit_string(powers: tuple[int, int, int], symbols: tuple[str, str, str]) -> str:
    """``"kg m-1 s-2"``-style text for ``powers`` of (length, mass, time); "1" if none.

    ``symbols`` name (length, mass, time); the mass comes first in the text.
    """
    length, mass, time = powers
    terms = zip((symbols[1], symbols[0], symbols[2]), (mass, length, time))
    return " ".join(name if p == 1 else f"{name}{p}" for name, p in terms if p != 0) or "1"


@dataclass(frozen=True)
class DSTVariable:
    """One output variable: name, dimensions, long_name, powers of (length, mass, time)."""

    name: str
    dims: tuple[str, ...]
    long_name: str
    powers: tuple[int, int, int] = _NONE
    comment: str | None = None

    @property
    def is_coordinate(self) -> bool:
        return self.dims == (self.name,)

    def attrs(self, si: bool) -> dict[str, str]:
        """netCDF attributes: SI ``units``, or ``units = "1"`` plus ``simulation_units``."""
        if si:
            out = {"units": _SI_NAMES.get(self.powers) or unit_string(self.powers,
                                                                      ("m", "kg", "s"))}
        else:
            out = {"units": "1"}
        out["long_name"] = self.long_name
        if not si and self.powers != _NONE:
            out["simulation_units"] = unit_string(self.powers, ("L", "M", "T"))
        if self.comment:
            out["comment"] = self.comment
        return out


_T, _Y, _P, _0 = ("time",), ("y",), ("particle",), ()
_NAN = "NaN where the steady law has no turning points (CST, Newtonian)"


def _mean(name: str, what: str, powers=_NONE) -> tuple[DSTVariable, DSTVariable]:
    return (DSTVariable(f"mean_{name}", _0, f"mean of {what} over the steady window", powers),
            DSTVariable(f"mean_{name}_stderr", _0, f"standard error of mean_{name} (block "
                        "averaging)", powers))


VARIABLES: Mapping[str, DSTVariable] = MappingProxyType({v.name: v for v in (
    DSTVariable("time", _T, "simulated time", _TIME),
    DSTVariable("y", _Y, "bin centre across the gap (walls at y = 0 and y = box[1])", _LENGTH),
    DSTVariable("strain", _T, "nominal strain gdot_WC(sigma_in) t of a stress-controlled run",
                comment="gdot_WC is the steady Wyart-Cates shear rate at the imposed stress"),
    DSTVariable("wall_velocity", _T, "top-wall velocity V_w", _VELOCITY),
    DSTVariable("wall_shear_rate", _T, "top-wall velocity over the gap V_w/L_y", _RATE),
    DSTVariable("stress", _T, "domain-averaged shear stress <eta gdot> of the fluid particles",
                _STRESS),
    DSTVariable("shear_rate", _T, "domain-averaged shear-rate magnitude <sqrt(2 D:D)>", _RATE),
    DSTVariable("frictional_fraction", _T, "domain-averaged fraction of frictional contacts "
                "<f>"),
    DSTVariable("bulk_velocity", _T, "domain-averaged flow velocity <v_x>", _VELOCITY),
    DSTVariable("density_error", _T, "largest relative density deviation max |rho/rho0 - 1|"),
    DSTVariable("mach", _T, "Mach number max |v|/c"),
    DSTVariable("lower_branch_fraction", _T, "share psi1 of particles with sigma_i < sigma_beta",
                comment=_NAN),
    DSTVariable("upper_branch_fraction", _T, "share psi2 of particles with sigma_i > "
                "sigma_alpha", comment=_NAN),
    *_mean("stress", "the domain-averaged shear stress", _STRESS),
    *_mean("shear_rate", "the domain-averaged shear rate", _RATE),
    *_mean("wall_shear_rate", "the top-wall shear rate V_w/L_y", _RATE),
    *_mean("frictional_fraction", "the domain-averaged frictional fraction"),
    *_mean("bulk_velocity", "the domain-averaged flow velocity", _VELOCITY),
    *_mean("lower_branch_fraction", "psi1"),
    *_mean("upper_branch_fraction", "psi2"),
    DSTVariable("imposed_stress", _0, "shear stress sigma_in imposed on the top wall", _STRESS),
    DSTVariable("wyart_cates_shear_rate", _0, "steady Wyart-Cates shear rate "
                "sigma_in/eta(f_hat(sigma_in)) at the imposed stress", _RATE,
                comment="the flow-curve point measured is (mean_shear_rate, mean_stress)"),
    DSTVariable("wyart_cates_frictional_fraction", _0, "steady fraction f_hat(sigma_in) = "
                "exp(-(sigma_star/sigma_in)^beta)"),
    DSTVariable("turning_point_position", _0, "q = (sigma_in - sigma_beta)/(sigma_alpha - "
                "sigma_beta): 0 at the lower, 1 at the upper turning point", comment=_NAN),
    DSTVariable("force_density", _0, "driving force per volume F = rho0 body_force",
                (-2, 1, -2)),
    DSTVariable("reference_bulk_velocity", _0, "mean velocity of the local-model channel "
                "(SPEC 5.7; the Newtonian parabola at phi = 0)", _VELOCITY,
                comment="exact for alpha = 0 only"),
    DSTVariable("velocity_profile", _Y, "time-averaged flow velocity v_x per bin of y",
                _VELOCITY),
    DSTVariable("frictional_fraction_profile", _Y, "time-averaged frictional fraction f per "
                "bin of y"),
    DSTVariable("stress_profile", _Y, "time-averaged particle stress eta gdot per bin of y",
                _STRESS),
    DSTVariable("shear_rate_profile", _Y, "time-averaged local shear rate per bin of y", _RATE),
    DSTVariable("viscosity_profile", _Y, "time-averaged particle viscosity eta(f) per bin of y",
                _VISCOSITY),
    DSTVariable("reference_velocity_profile", _Y, "local-model channel velocity v_x per bin "
                "of y (SPEC 5.7; the Newtonian parabola at phi = 0)", _VELOCITY,
                comment="exact for alpha = 0 only"),
    DSTVariable("particle", _P, "index of a fluid particle in the final snapshot"),
    DSTVariable("particle_x", _P, "x of each fluid particle at the end", _LENGTH),
    DSTVariable("particle_y", _P, "y of each fluid particle at the end", _LENGTH),
    DSTVariable("particle_velocity_x", _P, "v_x of each fluid particle at the end", _VELOCITY),
    DSTVariable("particle_frictional_fraction", _P, "f of each fluid particle at the end"),
    DSTVariable("particle_shear_rate", _P, "local shear rate of each fluid particle at the end",
                _RATE),
    DSTVariable("particle_stress", _P, "stress eta gdot of each fluid particle at the end",
                _STRESS, comment="with particle_shear_rate: the scatter over the flow curve"),
)})

RUN_ATTRIBUTES: Mapping[str, Attribute] = MappingProxyType({a.name: a for a in (
    Attribute("n_particles", int, "fluid and wall particles"),
    Attribute("n_fluid_particles", int, "fluid particles"),
    Attribute("n_wall_particles", int, "dummy particles of both walls"),
    Attribute("n_steps", int, "time steps taken, over all resumed segments"),
    Attribute("wall_time_s", float, "wall-clock duration over all resumed segments [s]"),
    Attribute("particle_steps_per_s", float, "particles times steps per wall-clock second [1/s]"),
    Attribute("reynolds_number", float, "rho0 U L_y/eta_min with U the largest |v_x| of the "
              "steady velocity profile and eta_min the smallest particle viscosity at the end [1]"),
    Attribute("mach_number", float, "largest Mach number max |v|/c during the run [1]"),
    Attribute("completed", int, "1 if the run reached its end"),
    Attribute("dt", float, "last time step [T]"),
    Attribute("sound_speed", float, "artificial sound speed c [L T-1]"),
    Attribute("density", float, "reference density rho0 [M L-3]"),
    Attribute("spacing", float, "lattice spacing dx = box[1]/resolution [L]"),
    Attribute("smoothing_length", float, "quintic smoothing length h_sl [L]"),
    Attribute("wall_mass", float, "top-wall mass M_w: per unit depth in 2-D [M L-1], in 3-D "
              "[M]"),
    Attribute("sigma_beta", float, "lower turning point of the steady law [M L-1 T-2]; NaN "
              "without"),
    Attribute("sigma_alpha", float, "upper turning point of the steady law [M L-1 T-2]; NaN "
              "without"),
    Attribute("regime", str, "steady-law regime: CST, DST, jammed_at_high_stress or newtonian"),
    Attribute("averaging_method", str, "how the steady-window errors were estimated"),
    Attribute("averaging_blocks", int, "blocks behind the steady-window errors"),
)})


def dst_registry(si: bool) -> Registry:
    """The registry of a DST run file, with SI ``units`` or scene units."""
    return Registry(VARIABLES, lambda spec: spec.attrs(si), RUN_ATTRIBUTES, REFERENCES,
                    SI_UNIT_SYSTEM if si else SCENE_UNIT_SYSTEM)
