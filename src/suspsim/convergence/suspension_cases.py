"""A dilute-suspension validation case for the speed-against-error study
(:class:`DiluteSuspensionCase`: one sphere against Batchelor & Green)."""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Mapping

from suspsim.convergence.case_base import WARM_UP_STEPS, Axis, CaseSettings, Run
from suspsim.validation.flows import Reading, couette_viscosity_ratio


@dataclass(frozen=True)
class DiluteSuspensionCase(CaseSettings):
    """One sphere (φ ≪ 1) in a sheared periodic box of the Newtonian matrix of
    :mod:`suspsim.validation.suspension`: error η_r/η_BG − 1 against Batchelor & Green's
    1 + 2.5φ + 5.2φ² at the packing's φ, with the standard error of the strain-unit means.
    The reference is not exact: one sphere meets only its periodic images, so its φ² term
    differs from 5.2φ² by about φ² (0.1 % of η_r at φ = 0.03), the floor of what this case can
    resolve. Axes: ``radius`` a [h] (the sphere's resolution), ``units`` (strain units averaged
    after one of transient), ``wi_target`` and ``dt_coefficient``; the box side follows from a
    and φ (one sphere), rounded to whole lattice spacings (the packing keeps φ exact, so a
    moves by up to a third of a spacing)."""

    name: str
    description: str
    reference: str
    axes: tuple[Axis, ...]
    phi: float

    def _scene(self, settings):
        from suspsim.validation.suspension import NUMBER_DENSITY, suspension_scene

        radius = float(settings["radius"])
        spacing = NUMBER_DENSITY ** (-1.0 / 3.0)
        box = spacing * round((4.0 * math.pi / 3.0 * radius ** 3 / self.phi) ** (1.0 / 3.0)
                              / spacing)
        return suspension_scene(phi=self.phi, radius=radius, box=box,
                                strain=1.0 + int(settings["units"]), overrides={
                                    "numerics.wi_target": float(settings["wi_target"]),
                                    "numerics.dt_viscous_coefficient":
                                        float(settings["dt_coefficient"])})

    def warm_up(self, settings: Mapping[str, Any], threads: int) -> None:
        """Two steps of the same scene, so compiled code is loaded."""
        from suspsim.sph.simulation import Simulation

        Simulation(self._scene(settings), threads=threads).advance(WARM_UP_STEPS)

    def execute(self, settings: Mapping[str, Any], threads: int) -> Run:
        """Build, run and read the suspension of ``settings``."""
        from suspsim.rheology.suspension import batchelor
        from suspsim.sph.simulation import Simulation

        t0 = time.perf_counter()
        scene = self._scene(settings)
        sim = Simulation(scene, threads=threads)
        t1 = time.perf_counter()
        reading = couette_viscosity_ratio(sim, transient=1.0, units=int(settings["units"]))
        reference = float(batchelor(sim.packing_phi))
        return Run(Reading((1.0 + reading.value) / reference - 1.0, reading.stderr / reference),
                   sim.n_particles, sim.step_count, sim.dt, sim.sound_speed,
                   scene.number_density, scene.number_density ** (1.0 / 3.0), t1 - t0,
                   time.perf_counter() - t1)


def dilute_suspension(phi: float = 0.03) -> DiluteSuspensionCase:
    """One sphere at ``phi`` (the Einstein test's 0.03: a = 2.5 h in a 12.5 h box)."""
    axes = (Axis("radius", 2.5, "h", "sphere radius a in support radii (its resolution)"),
            Axis("units", 4, "1", "strain units averaged after one of transient"),
            Axis("wi_target", 1e-3, "1", "mu gdot/(rho c^2) of the sound speed"),
            Axis("dt_coefficient", 0.05, "1", "C in the viscous step limit C rho h^2/mu_max"))
    return DiluteSuspensionCase(f"suspension_dilute_phi{phi:g}",
                                f"one sphere in a periodic box (3D), phi = {phi:g}",
                                "Batchelor-Green 1 + 2.5 phi + 5.2 phi^2 (approximate: one "
                                "sphere meets only its images)", axes, phi)
