"""η_r of a sheared suspension in a Newtonian matrix, for studies of shape, packing and
resolution (docs/figures/make_shape_seeds.py, make_sphere_resolution.py).

Newtonian μ = 1 at γ̇ = 0.004 τ⁻¹ (particle Reynolds number ρa²γ̇/μ = 0.1 at a = 2.5 h, as
the suspension validation, tests/validation/test_suspension.py), number density 4.096 h⁻³,
a relaxed start and the inclusions' defaults.
"""
from __future__ import annotations

import argparse
import json
import math
import time
from typing import Any, Iterator, Mapping, NamedTuple, Sequence

import numpy as np

from suspsim.bodies.lubrication_pass import SMALLEST_GAP
from suspsim.errors import NumericalError
from suspsim.scene import Scene, scene_from_dict
from suspsim.sph.lattice import imposed_velocity
from suspsim.sph.simulation import Simulation
from suspsim.validation.flows import SAMPLES_PER_UNIT, couette_stress_ratios

RATE = 0.004
"""Imposed shear rate [τ⁻¹]."""
NUMBER_DENSITY = 4.096
"""Particles per h³ (lattice spacing 0.625 h)."""


class SuspensionReading(NamedTuple):
    """``relative_viscosity`` σ_xy/(μγ̇) [1], its strain-unit standard error ``stderr`` [1], the
    ``cpu_time`` of set-up and run [s], ``n_particles``, the packing's ``phi`` [1], and the
    run's health over its samples (every 1/50 strain unit): the largest fluid
    ``density_error`` max|ρ/ρ_eq − 1| [1], the ``smallest_gap`` between body surfaces [h] and
    the largest body speed relative to the imposed flow, ``body_speed``, in units of the wall
    speed γ̇L_y/2 [1]; ``particle_relative_viscosity`` 1 + σ^p_xy/(μγ̇) from the bodies' share
    of the stress alone (Batchelor 1970; ``run._batchelor_split``) and its ``particle_stderr``
    [1]; over the samples after the transient, the bodies' mean ``spin`` Ω_z/(−γ̇/2) and, for
    grains, the nematic ``order`` S of their long axes (nan for spheres) [1]
    (``analysis.orientation``)."""

    relative_viscosity: float
    stderr: float
    cpu_time: float
    n_particles: int
    phi: float
    density_error: float
    smallest_gap: float
    body_speed: float
    particle_relative_viscosity: float
    particle_stderr: float
    spin: float
    order: float


class HealthWatch:
    """The health extremes of a run, updated at each sample; stops the run (NumericalError
    with the simulation's reason) at the first sample outside its health limits. Also keeps
    each sample's strain, the bodies' spin ratio and, for grains, the nematic order of their
    long axes (``Simulation.body_orientation``; :meth:`steady_means`)."""

    def __init__(self) -> None:
        self.density_error, self.smallest_gap, self.body_speed = 0.0, math.inf, 0.0
        self.samples: list[tuple[float, float, float]] = []

    def steady_means(self, transient: float) -> tuple[float, float]:
        """(spin ratio, nematic order) averaged over the samples after the strain
        ``transient`` (nan without such samples; the order is nan without grains)."""
        rows = np.array([row for row in self.samples if row[0] > transient + 1e-9])
        if len(rows) == 0:
            return math.nan, math.nan
        return float(rows[:, 1].mean()), float(rows[:, 2].mean())

    def __call__(self, sim: Simulation) -> None:
        ok, message = sim.health()
        if not ok:
            raise NumericalError(message)
        scene, bodies = sim.scene, sim.bodies
        self.density_error = max(self.density_error, sim._density_error())
        if bodies is None:
            return
        # the gap of the step just taken (the lubrication pass resets it every step)
        self.smallest_gap = min(self.smallest_gap, float(sim._lubrication_stats[SMALLEST_GAP]))
        peculiar = bodies.velocities.copy()
        peculiar[:, 0] -= imposed_velocity(scene, bodies.centres[:, 1])
        wall_speed = 0.5 * scene.flow.shear_rate * scene.box[1]
        self.body_speed = max(self.body_speed,
                              float(np.sqrt((peculiar ** 2).sum(axis=1)).max()) / wall_speed)
        orientation = sim.body_orientation()
        self.samples.append((sim.strain, orientation["body_spin"],
                             orientation.get("body_order", math.nan)))


def add_run_options(parser: argparse.ArgumentParser, *, units: float = 4.0,
                    example: str = "") -> None:
    """A figure script's ``--strain TRANSIENT UNITS`` (default 1 and ``units``) and repeatable
    ``--set KEY=VALUE`` (:func:`parse_overrides`; ``example`` goes into its help)."""
    parser.add_argument("--strain", type=float, nargs=2, default=[1.0, units],
                        metavar=("TRANSIENT", "UNITS"))
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help=f"a scene key for every run{example} (repeatable)")


def overrides_text(overrides: Mapping[str, Any]) -> str:
    """", KEY = VALUE" for each override, for a script's header line."""
    return "".join(f", {key} = {value}" for key, value in overrides.items())


def parse_overrides(items: Sequence[str]) -> dict[str, Any]:
    """``KEY=VALUE`` strings (a figure script's ``--set``) as :func:`suspension_scene`
    overrides, each VALUE read as JSON (``run.dt=0.1``, ``inclusions.shape="sand"``)."""
    return {key: json.loads(value) for key, value in (item.split("=", 1) for item in items)}


def suspension_scene(*, shape: str = "sphere", phi: float, radius: float, box: float,
                     seed: int = 1, strain: float = 5.0,
                     overrides: Mapping[str, Any] | None = None) -> Scene:
    """The scene of bodies of ``shape`` and volume-equivalent ``radius`` [h] packed at ``phi``
    [1] (packing ``seed``) in a cubic periodic box of side ``box`` [h], sheared for ``strain``
    [1] in the module's Newtonian matrix. ``overrides`` maps dotted scene keys to values
    (e.g. ``{"run.dt": 0.1}``, ``{"inclusions.lubrication.repulsion": 1e5}``)."""
    data: dict[str, Any] = {
        "dimension": 3, "box": [box] * 3, "number_density": NUMBER_DENSITY, "seed": seed,
        "fluid": {"law": "newtonian", "params": {"mu": 1.0}},
        "flow": {"type": "couette", "shear_rate": RATE},
        "run": {"strain": strain, "start": "linear"},
        "lattice": {"relax": True},
        "inclusions": {"phi": phi, "radius": radius, "shape": shape}}
    for key, value in (overrides or {}).items():
        *parents, leaf = key.split(".")
        block = data
        for name in parents:
            block = block.setdefault(name, {})
        block[leaf] = value
    return scene_from_dict(data)


def relative_viscosity(*, shape: str = "sphere", phi: float, radius: float, box: float,
                       seed: int = 1, transient: float = 1.0, units: int = 4,
                       threads: int = 1,
                       overrides: Mapping[str, Any] | None = None) -> SuspensionReading:
    """η_r of the :func:`suspension_scene` (with its ``overrides``) averaged over ``units``
    whole strain units after ``transient`` strain units, on ``threads`` threads. Raises
    NumericalError at the first sample (every 1/50 strain unit) outside the run's health
    limits."""
    scene = suspension_scene(shape=shape, phi=phi, radius=radius, box=box, seed=seed,
                             strain=transient + units, overrides=overrides)
    started = time.process_time()
    sim = Simulation(scene, threads=threads)
    watch = HealthWatch()
    ratios = couette_stress_ratios(sim, ("shear_stress", "particle_stress"),
                                   transient=transient, units=units, on_sample=watch)
    total, particle = ratios["shear_stress"], ratios["particle_stress"]
    return SuspensionReading(total.value, total.stderr, time.process_time() - started,
                             sim.n_particles, sim.packing_phi, watch.density_error,
                             watch.smallest_gap, watch.body_speed, 1.0 + particle.value,
                             particle.stderr, *watch.steady_means(transient))


def sampled_run(scene: Scene, *, transient: float, units: float) -> Iterator[Simulation]:
    """A one-thread :class:`Simulation` of the Couette ``scene`` run ``transient`` strain units,
    then yielded after each of ``SAMPLES_PER_UNIT`` equal strides per strain unit for ``units``
    units, for the figure scripts that read more than σ_xy (``make_sphere_spin.py``,
    ``make_stress_split.py``)."""
    sim = Simulation(scene, threads=1)
    per_unit = int(round(1.0 / (scene.flow.shear_rate * sim.dt)))
    sim.advance(int(round(transient * per_unit)))
    for _ in range(int(round(units * SAMPLES_PER_UNIT))):
        sim.advance(max(1, per_unit // SAMPLES_PER_UNIT))
        yield sim
