"""η_r of a sheared suspension in a Newtonian matrix, for studies of shape, packing and
resolution (docs/figures/make_shape_seeds.py, make_sphere_resolution.py).

Newtonian μ = 1 at γ̇ = 0.004 τ⁻¹ (particle Reynolds number ρa²γ̇/μ = 0.1 at a = 2.5 h, as
the suspension validation, tests/validation/test_suspension.py), number density 4.096 h⁻³,
a relaxed start and the inclusions' defaults.
"""
from __future__ import annotations

import time
from typing import NamedTuple

from suspsim.scene import Scene, scene_from_dict
from suspsim.sph.simulation import Simulation
from suspsim.validation.flows import couette_viscosity_ratio

RATE = 0.004
"""Imposed shear rate [τ⁻¹]."""
NUMBER_DENSITY = 4.096
"""Particles per h³ (lattice spacing 0.625 h)."""


class SuspensionReading(NamedTuple):
    """``relative_viscosity`` σ_xy/(μγ̇) [1], its strain-unit standard error ``stderr`` [1], the
    ``cpu_time`` of set-up and run [s], ``n_particles`` and the packing's ``phi`` [1]."""

    relative_viscosity: float
    stderr: float
    cpu_time: float
    n_particles: int
    phi: float


def suspension_scene(*, shape: str = "sphere", phi: float, radius: float, box: float,
                     seed: int = 1, strain: float = 5.0) -> Scene:
    """The scene of bodies of ``shape`` and volume-equivalent ``radius`` [h] packed at ``phi``
    [1] (packing ``seed``) in a cubic periodic box of side ``box`` [h], sheared for ``strain``
    [1] in the module's Newtonian matrix."""
    return scene_from_dict({
        "dimension": 3, "box": [box] * 3, "number_density": NUMBER_DENSITY, "seed": seed,
        "fluid": {"law": "newtonian", "params": {"mu": 1.0}},
        "flow": {"type": "couette", "shear_rate": RATE},
        "run": {"strain": strain, "start": "linear"},
        "lattice": {"relax": True},
        "inclusions": {"phi": phi, "radius": radius, "shape": shape}})


def relative_viscosity(*, shape: str = "sphere", phi: float, radius: float, box: float,
                       seed: int = 1, transient: float = 1.0, units: int = 4,
                       threads: int = 1) -> SuspensionReading:
    """η_r of the :func:`suspension_scene` averaged over ``units`` whole strain units after
    ``transient`` strain units, on ``threads`` threads. Raises NumericalError if the run left
    its health limits."""
    scene = suspension_scene(shape=shape, phi=phi, radius=radius, box=box, seed=seed,
                             strain=transient + units)
    started = time.process_time()
    sim = Simulation(scene, threads=threads)
    reading = couette_viscosity_ratio(sim, transient=transient, units=units)
    return SuspensionReading(1.0 + reading.value, reading.stderr,
                             time.process_time() - started, sim.n_particles, sim.packing_phi)
