"""The output registry: every variable and attribute a run file may hold (CF-1.10 metadata).

Unit convention. A run is computed in simulation units — length h (the kernel's support
radius), mass m (the particle mass, m = 1) and time τ (the scene's time unit) — so its numbers
are pure numbers: multiples of h, m and τ. In UDUNITS, "h" is the hour and "m" the metre, so
these names must not appear in ``units``. Every variable therefore carries ``units = "1"``
(CF: dimensionless), and, when it has a dimension, the attribute ``simulation_units`` states
it in h, m and tau with UDUNITS exponent syntax, e.g. ``"m h-1 tau-2"`` for a 3-D stress. The
global attribute ``unit_system`` (:data:`UNIT_SYSTEM`) says the same once per file. Stresses,
viscosities and densities depend on the space dimension d (a 2-D stress is a force per
length); :meth:`Variable.attrs` resolves that. A later conversion to SI replaces ``units`` and
drops ``simulation_units``. No CF standard name fits dimensionless simulation quantities, so no
variable has ``standard_name``.
"""
from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Mapping

UNIT_SYSTEM = ("simulation units: length h = kernel support radius, mass m = particle mass, "
               "time tau = scene time unit; variables have units '1' and state their dimension "
               "in the attribute simulation_units")

# Powers of (h, m, tau, V) with V = h^d the d-dimensional volume.
_TIME = (0, 0, 1, 0)
_LENGTH = (1, 0, 0, 0)
_VELOCITY = (1, 0, -1, 0)
_RATE = (0, 0, -1, 0)
_STRESS = (2, 1, -2, -1)
_VISCOSITY = (2, 1, -1, -1)
_DENSITY = (0, 1, 0, -1)
_ENERGY = (2, 1, -2, 0)
_NONE = (0, 0, 0, 0)


def simulation_units(powers: tuple[int, int, int, int], dimension: int) -> str:
    """UDUNITS-style unit string in h, m, tau for ``powers`` of (h, m, tau, h^d); "1" if none."""
    length, mass, time, volume = powers
    terms = zip(("m", "h", "tau"), (mass, length + dimension * volume, time))
    text = " ".join(name if p == 1 else f"{name}{p}" for name, p in terms if p != 0)
    return text or "1"


@dataclass(frozen=True)
class Variable:
    """One output variable: name, dimensions, long_name and powers of (h, m, tau, h^d).

    A variable whose only dimension is its own name is a coordinate (``time``, ``y``).
    """

    name: str
    dims: tuple[str, ...]
    long_name: str
    powers: tuple[int, int, int, int] = _NONE
    standard_name: str | None = None
    comment: str | None = None

    @property
    def is_coordinate(self) -> bool:
        return self.dims == (self.name,)

    def attrs(self, dimension: int) -> dict[str, str]:
        """netCDF attributes of this variable in a ``dimension``-D run."""
        out = {"units": "1", "long_name": self.long_name}
        if self.powers != _NONE:
            out["simulation_units"] = simulation_units(self.powers, dimension)
        if self.standard_name:
            out["standard_name"] = self.standard_name
        if self.comment:
            out["comment"] = self.comment
        return out


_T, _Y = ("time",), ("y",)

VARIABLES: Mapping[str, Variable] = MappingProxyType({v.name: v for v in (
    Variable("time", _T, "simulated time", _TIME),
    Variable("y", _Y, "bin centre along the gradient direction y", _LENGTH),
    Variable("strain", _T, "accumulated shear strain (shear rate times time)"),
    Variable("shear_stress", _T, "shear stress sigma_xy of the whole box", _STRESS,
             comment="virial stress relative to the imposed flow (SPEC 2.8)"),
    Variable("pressure", _T, "mean pressure -trace(sigma)/d of the whole box", _STRESS),
    Variable("kinetic_energy", _T, "kinetic energy per particle, m <|v|^2>/2", _ENERGY),
    Variable("density_error", _T, "largest relative density deviation max |rho - rho_eq|/rho_eq"),
    Variable("mach", _T, "Mach number max |v|/c"),
    Variable("viscosity", (), "shear viscosity sigma_xy/shear_rate averaged after the transient",
             _VISCOSITY),
    Variable("viscosity_stderr", (), "standard error of viscosity (block averaging)", _VISCOSITY),
    Variable("velocity_profile", _Y, "time-averaged flow velocity v_x per bin of y", _VELOCITY),
    Variable("viscosity_profile", _Y, "time-averaged particle viscosity per bin of y", _VISCOSITY),
    Variable("shear_rate_profile", _Y, "time-averaged local shear rate per bin of y", _RATE),
    Variable("density_profile", _Y, "time-averaged mass density per bin of y", _DENSITY),
    Variable("reference_velocity_profile", _Y, "analytic flow velocity v_x per bin of y", _VELOCITY,
             comment="continuum solution for the scene's law and flow (SPEC 6)"),
    Variable("phi", (), "solid volume fraction of the rigid inclusions"),
    Variable("suspension_viscosity", (), "suspension shear viscosity sigma_xy/shear_rate averaged "
             "after the transient", _VISCOSITY,
             comment="stress with body particles at their body centre (SPEC 3.5)"),
    Variable("matrix_viscosity_at_rate", (), "matrix law viscosity at the imposed shear rate",
             _VISCOSITY),
    Variable("relative_viscosity", (), "suspension viscosity over the matrix viscosity at the "
             "same shear rate"),
    Variable("relative_viscosity_stderr", (), "standard error of relative_viscosity (block "
             "averaging)"),
    Variable("particle_stress", _T, "the bodies' share of sigma_xy: their stresslets plus "
             "lubrication and repulsion, (1/V) sum_B S_B,xy", _STRESS,
             comment="Batchelor, J. Fluid Mech. 41, 545 (1970); SPEC 3.5"),
    Variable("body_spin", _T, "mean angular velocity Omega_z of the bodies over -shear_rate/2, "
             "the rate of a free sphere turning with the vorticity",
             comment="analysis.orientation; an elongated body aligned with the flow turns "
             "slower (Jeffery 1922)"),
    Variable("body_order", _T, "nematic order S of the bodies' long axes: the largest "
             "eigenvalue of <(3 u u - I)/2>, 0 for isotropic axes, 1 for parallel ones (grains "
             "only)", comment="analysis.orientation"),
    Variable("particle_relative_viscosity", (), "1 + particle_stress/(matrix viscosity x shear "
             "rate) averaged after the transient: relative viscosity from the bodies' share "
             "alone, the fluid's taken at its law (Newtonian matrix only)",
             comment="Batchelor (1970): in a Newtonian matrix the fluid's share is exactly "
             "2 mu E around rigid bodies"),
    Variable("particle_relative_viscosity_stderr", (), "standard error of "
             "particle_relative_viscosity (block averaging)"),
    Variable("fluid_stress_error", (), "the rest of sigma_xy (fluid pairs and kinetic stress) "
             "over matrix viscosity x shear rate, minus 1: the discrete fluid's departure from "
             "its law, 0 in the continuum (Newtonian matrix only)"),
    Variable("fluid_stress_error_stderr", (), "standard error of fluid_stress_error (block "
             "averaging)"),
)})


@dataclass(frozen=True)
class Attribute:
    """A global attribute a run sets: type (int or float) and description with units."""

    name: str
    type: type
    description: str


RUN_ATTRIBUTES: Mapping[str, Attribute] = MappingProxyType({a.name: a for a in (
    Attribute("n_particles", int, "number of SPH particles"),
    Attribute("n_steps", int, "time steps taken, over all resumed segments"),
    Attribute("wall_time_s", float, "wall-clock duration over all resumed segments [s]"),
    Attribute("particle_steps_per_s", float, "particles times steps per wall-clock second [1/s]"),
    Attribute("reynolds_number", float, "Reynolds number rho v L / mu of the flow [1]"),
    Attribute("mach_number", float, "largest Mach number max |v|/c during the run [1]"),
    Attribute("completed", int, "1 if the run reached its end, 0 if it stopped early"),
    Attribute("dt", float, "time step used [tau]"),
    Attribute("sound_speed", float, "sound speed c used [h/tau]"),
    Attribute("tolerance", float, "requested relative error of suspsim run --tolerance [1]"),
    Attribute("tolerance_mode", str, "how the set-up was chosen: verified (runs measured "
              "against the exact solution until one met the tolerance) or bound (the inflated "
              "error model alone)"),
    Attribute("expected_error", float, "error model's expected error bound (error + 2 "
              "standard errors) of the chosen set-up: inflated (bound) or calibrated on the "
              "earlier attempts (verified) [1]"),
    Attribute("measured_error", float, "error bound (error + 2 standard errors) measured "
              "against the flow's exact solution [1]"),
    Attribute("tolerance_attempts", str, "runs of a verified --tolerance, in order (JSON: "
              "settings, model_error [1], calibration [1], measured_error [1] or null for a "
              "blow-up, cpu_time_s [s])"),
    Attribute("expected_cost_s", float, "cost model's expected CPU time of one thread [s]"),
    Attribute("tolerance_settings", str, "numerical settings chosen for the tolerance (JSON: "
              "resolution h/dx [1], dt_coefficient [1], wi_target [1], side or width [h], "
              "units [strain], kernel, jitter [spacings])"),
    Attribute("tolerance_error_terms", str, "error model contributions of the chosen set-up "
              "(JSON, each [1], before the inflation factor)"),
    Attribute("tolerance_stress_scale", float, "factor applied to the scene's stress-like law "
              "parameters (and so to output stresses and viscosities) by the rescaling [1]"),
    Attribute("error_model", str, "provenance of the error model (JSON: datasets, date, "
              "command, inflation)"),
    Attribute("n_bodies", int, "number of rigid inclusions"),
    Attribute("n_body_particles", int, "SPH particles in the bodies' surface shells"),
)})

#: Run attributes every output must set.
REQUIRED_RUN_ATTRIBUTES = ("wall_time_s", "completed")


# Packing files (suspsim.io.packing_file): one row per body.
_VOLUME = (0, 0, 0, 1)
_B = ("body",)

PACKING_VARIABLES: Mapping[str, Variable] = MappingProxyType({v.name: v for v in (
    Variable("centre", _B + ("axis",), "position of the body-frame origin in the box (sphere "
             "centre, grain centroid)", _LENGTH,
             comment="the box is [0, Lx) x [0, Ly) x [0, Lz), periodic; bodies may cross faces"),
    Variable("orientation", _B + ("quaternion",), "unit quaternion (w, x, y, z) rotating the "
             "body frame into the box frame"),
    Variable("radius", _B, "volume-equivalent radius (sphere radius)", _LENGTH),
    Variable("volume", _B, "body volume", _VOLUME),
    Variable("support_radius", _B, "upper bound of the distance from the body-frame origin to "
             "the surface", _LENGTH),
    Variable("shape_coefficient", _B + ("coefficient",), "real spherical-harmonic coefficient "
             "a_nm of the surface radius r(theta, phi) in the body frame", _LENGTH,
             comment="r = sum a_nm Y_nm, orthonormal real harmonics without Condon-Shortley "
                     "phase, flat index n*n + n + m (suspsim.bodies.harmonics)"),
    Variable("coefficient_degree", ("coefficient",), "degree n of each shape coefficient"),
    Variable("coefficient_order", ("coefficient",), "order m of each shape coefficient"),
)})

PACKING_ATTRIBUTES: Mapping[str, Attribute] = MappingProxyType({a.name: a for a in (
    Attribute("shape", str, "body shape: sphere or sand"),
    Attribute("volume_fraction", float, "sum of body volumes over box volume [1]"),
    Attribute("seed", int, "seed of numpy.random.default_rng that produced the packing"),
    Attribute("box", tuple, "box lengths Lx, Ly, Lz [h]"),
    Attribute("body_count", int, "number of bodies"),
    Attribute("polydispersity", float, "coefficient of variation of the radius distribution "
              "asked for [1]"),
    Attribute("size_ratio", float, "bound on largest/smallest radius [1]"),
    Attribute("min_gap", float, "smallest gap guaranteed between bodies [h] (sand: radial)"),
    Attribute("smallest_gap", float, "smallest gap found by the exact check [h]"),
    Attribute("relaxation_steps", int, "FIRE steps of the overlap removal"),
    Attribute("wall_time_s", float, "wall-clock time of the packing [s]"),
    Attribute("degree", int, "spherical-harmonic degree N of the grain shapes"),
    Attribute("roughness", float, "rms radius deviation of degrees >= 3 [equivalent radius]"),
    Attribute("spectral_exponent", float, "p in |a_nm| ~ n^-p for degrees >= 3"),
    Attribute("elongation_range", tuple, "range of the elongation L/W drawn [1]"),
    Attribute("relax_points", int, "surface sample points per grain in the relaxation"),
    Attribute("check_points", int, "surface sample points per grain in the exact check"),
    Attribute("working_gap", float, "gap the relaxation worked with [h]"),
)})
