"""The study registry: variables of a study in physical (SI) units, per run and gathered.

A simulate run file (:mod:`suspsim.stages.simulate`) holds the run in simulation units, whose
metadata come from :mod:`suspsim.io.variables` (``units = "1"`` plus ``simulation_units``), and
its results converted back to physical units as 0-d variables named here. The gathered
``summary.nc`` (:mod:`suspsim.stages.gather`) holds the same names on the dimensions
:data:`SUMMARY_DIMS`, one cell per run. This registry is kept apart from the simulation-unit one
because its ``units`` are real UDUNITS strings. Numbers counted in the simulation's kernel support
radius h keep ``units = "1"`` and say so in ``simulation_units`` (UDUNITS "h" is the hour).
"""
from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Mapping

#: Dimensions of a gathered summary: volume fraction, physical shear rate, seed.
SUMMARY_DIMS = ("phi", "shear_rate", "seed")


@dataclass(frozen=True)
class StudyVariable:
    """One study variable: name, UDUNITS ``units``, ``long_name`` and optional notes."""

    name: str
    units: str
    long_name: str
    simulation_units: str | None = None
    comment: str | None = None

    @property
    def is_coordinate(self) -> bool:
        return self.name in SUMMARY_DIMS

    def attrs(self) -> dict[str, str]:
        out = {"units": self.units, "long_name": self.long_name}
        if self.simulation_units:
            out["simulation_units"] = self.simulation_units
        if self.comment:
            out["comment"] = self.comment
        return out


STUDY_VARIABLES: Mapping[str, StudyVariable] = MappingProxyType({v.name: v for v in (
    StudyVariable("phi", "1", "solid volume fraction of rigid inclusions"),
    StudyVariable("shear_rate", "s-1", "imposed macroscopic shear rate"),
    StudyVariable("seed", "1", "seed of the random lattice jitter and packing"),
    StudyVariable("suspension_viscosity", "Pa s", "steady shear viscosity sigma_xy/shear_rate of "
                  "the simulated suspension", comment="phi = 0: the matrix fluid alone"),
    StudyVariable("suspension_viscosity_stderr", "Pa s", "standard error of "
                  "suspension_viscosity (batch means over whole strain units)"),
    StudyVariable("matrix_viscosity", "Pa s", "viscosity of the fitted matrix law at the shear "
                  "rate"),
    StudyVariable("relative_viscosity", "1", "suspension_viscosity over matrix_viscosity",
                  comment="phi = 0 checks the solver against the fitted law: expect 1"),
    StudyVariable("relative_viscosity_stderr", "1", "standard error of relative_viscosity"),
    StudyVariable("wall_time", "s", "wall-clock time of the simulation, all segments"),
    StudyVariable("n_particles", "1", "number of SPH particles"),
    StudyVariable("box_side", "1", "side of the cubic periodic box", simulation_units="h"),
    StudyVariable("number_density", "1", "SPH particles per kernel support cubed",
                  simulation_units="h-3"),
    StudyVariable("total_strain", "1", "total shear strain of the run"),
    StudyVariable("transient_strain", "1", "strain discarded before averaging"),
    StudyVariable("particle_reynolds_number", "1", "particle Reynolds number "
                  "rho l^2 shear_rate/mu(shear_rate) of the simulation",
                  comment="l = kernel support h for the matrix, the inclusion radius with "
                          "inclusions (SPEC 7)"),
    StudyVariable("reynolds_number", "1", "box Reynolds number rho (shear_rate L_y/2)(L_y/2)/mu "
                  "of the simulation"),
    StudyVariable("mach_number", "1", "largest Mach number |v - v_imposed|/c during the run"),
    StudyVariable("time_scale", "s", "physical duration of the simulation time unit tau"),
    StudyVariable("viscosity_scale", "Pa s", "physical value of the simulation viscosity unit"),
    StudyVariable("reynolds_length", "1", "length l of particle_reynolds_number",
                  simulation_units="h", comment="1 h for the matrix alone, inclusion_radius with "
                                                "inclusions"),
    StudyVariable("inclusion_radius", "1", "nominal mean volume-equivalent radius of the rigid "
                  "inclusions", simulation_units="h", comment="NaN at phi = 0 (no inclusions); "
                  "the packing rescales it by a factor near 1 to reach phi exactly"),
    StudyVariable("packing_seed", "1", "seed of the random packing of the inclusions",
                  comment="NaN at phi = 0 (no packing)"),
    StudyVariable("body_count", "1", "number of rigid inclusions in the box"),
    StudyVariable("particle_radius", "m", "physical mean radius of the inclusions",
                  comment="from the material sheet (particles.radius_m); NaN when it gives none "
                          "or at phi = 0. It sets the length scale particle_radius/"
                          "inclusion_radius of the run"),
)})
