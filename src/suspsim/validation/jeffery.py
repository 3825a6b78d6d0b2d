"""One rigid spheroid tumbling in simple shear against Jeffery's orbit (Jeffery 1922).

Theory. A prolate spheroid of aspect ratio r (semi-axes r c, c, c) whose symmetry axis p lies
in the flow–gradient plane of u = γ̇ y ê_x stays in that plane (Jeffery's orbit constant
C = ∞) and turns as

    dα/dγ = −½ (1 − λ cos 2α),   λ = (r² − 1)/(r² + 1)

(G. B. Jeffery, Proc. R. Soc. Lond. A 102, 161 (1922)), α the angle of p from ê_x [rad],
γ = γ̇t the strain [1]. Integrated [derived]: tan α = tan θ / r with θ = θ₀ − rγ/(r² + 1), so
a half turn takes the strain π (r + 1/r), and the turning is slowest, ½ (1 − λ) of the
vorticity's rate, while p lies along the flow.

Measurement. :func:`spheroid_run` builds the spheroid from the degree-N spherical-harmonic
projection of its radius (:func:`suspsim.bodies.grains.ellipsoid_coefficients`), as sand grains
are built, puts it at the centre of a periodic Lees–Edwards box in the Newtonian matrix of
:mod:`suspsim.validation.suspension` (particle Reynolds number ρa²γ̇/μ = 0.1 at a = 2.5 h) and
records α every 1/20 strain unit. :func:`fit_orbit` fits the measured
dα/dγ to −½ (k − λ_h cos 2α): the rotation coupling k is 1 for Jeffery (the mean turning
follows the vorticity, what the one-sphere spin test checks), and λ_h gives the hydrodynamic
aspect ratio r_h = √((k + λ_h)/(k − λ_h)) of the discrete body — what a suspension of such
bodies feels (``docs/suspensions.md``).

Units: lengths [h], time [τ]; angles [rad].
"""
from __future__ import annotations

import math
import tempfile
from pathlib import Path
from typing import Any, Mapping, NamedTuple

import numpy as np

from suspsim.bodies.grains import DEFAULT_DEGREE, ellipsoid_coefficients
from suspsim.bodies.packing import Packing
from suspsim.bodies.shapes import mass_properties, radius_bounds
from suspsim.io.packing_file import write_packing
from suspsim.sph.simulation import Simulation
from suspsim.validation.suspension import NUMBER_DENSITY, RATE, suspension_scene

__all__ = ["OrbitFit", "SpheroidRun", "fit_orbit", "jeffery_angle", "jeffery_lambda",
           "spheroid_box", "spheroid_packing", "spheroid_run"]

#: Samples per strain unit of :func:`spheroid_run`.
SAMPLES_PER_UNIT = 20
#: Box side per volume-equivalent radius [choice]: at r = 2 the body's length is 2.5 a, so
#: its periodic images are 2.4 lengths apart.
BOX_PER_RADIUS = 6.0
#: Lattice spacing of the matrix [h]; box sides are multiples of it (``scene_rules``).
SPACING = NUMBER_DENSITY ** (-1.0 / 3.0)


def jeffery_lambda(aspect: float) -> float:
    """Jeffery's shape factor λ = (r² − 1)/(r² + 1) of a spheroid of aspect ratio r [1]."""
    return (aspect * aspect - 1.0) / (aspect * aspect + 1.0)


def jeffery_angle(strain: np.ndarray, aspect: float, angle0: float) -> np.ndarray:
    """α(γ) [rad] of the in-plane Jeffery orbit from α(0) = ``angle0``, continuous in γ (module
    docstring: tan α = tan θ / r, θ = θ₀ − rγ/(r² + 1))."""
    r = float(aspect)
    theta0 = math.atan2(r * math.sin(angle0), math.cos(angle0))
    theta = theta0 - r * np.asarray(strain, dtype=float) / (r * r + 1.0)
    alpha = np.arctan2(np.sin(theta), r * np.cos(theta))
    # α and θ cross every multiple of π/2 together: carry θ's turns over to α.
    return alpha + math.pi * np.round((theta - alpha) / math.pi)


def spheroid_box(radius: float) -> float:
    """Cube side [h] for a spheroid of volume-equivalent ``radius`` [h]: :data:`BOX_PER_RADIUS`
    radii, rounded up to a whole number of lattice spacings."""
    return SPACING * math.ceil(BOX_PER_RADIUS * radius / SPACING - 1e-9)


def spheroid_packing(aspect: float, radius: float, box: float, angle: float,
                     degree: int = DEFAULT_DEGREE) -> Packing:
    """One prolate spheroid (semi-axes r c, c, c with volume-equivalent ``radius`` [h]) at the
    centre of a cube of side ``box`` [h], its symmetry axis in the x–y plane at ``angle`` [rad]
    from x (a "sand" packing: the body frame is the principal frame, long axis x)."""
    coefficients = ellipsoid_coefficients((aspect, 1.0, 1.0), radius, degree)
    volume = mass_properties(coefficients).volume
    sides = np.full(3, float(box))
    turn = np.array([[math.cos(0.5 * angle), 0.0, 0.0, math.sin(0.5 * angle)]])
    return Packing("sand", sides, 0.5 * sides[None, :], turn,
                   np.array([np.cbrt(0.75 * volume / math.pi)]), np.array([volume]),
                   coefficients[None, :], np.array([radius_bounds(coefficients)[1]]), 0, 0.0,
                   1.0, 1e-3 * radius, {"aspect_ratio": float(aspect)})


class SpheroidRun(NamedTuple):
    """Samples of :func:`spheroid_run`: ``strain`` [1], ``angle`` α of the long axis from the
    flow direction, continuous [rad], ``out_of_plane`` its z component [1]; ``n_particles``."""

    strain: np.ndarray
    angle: np.ndarray
    out_of_plane: np.ndarray
    n_particles: int


def spheroid_run(aspect: float, radius: float, strain: float, *, angle0: float = 0.5 * math.pi,
                 box: float | None = None, threads: int = 1,
                 overrides: Mapping[str, Any] | None = None) -> SpheroidRun:
    """Shear one spheroid (:func:`spheroid_packing`, box :func:`spheroid_box` unless given)
    for ``strain`` from the angle ``angle0`` [rad] with the defaults of a suspension scene
    (``overrides`` as in :func:`~suspsim.validation.suspension.suspension_scene`)."""
    box = spheroid_box(radius) if box is None else float(box)
    packing = spheroid_packing(aspect, radius, box, angle0)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "spheroid.nc"
        write_packing(path, packing)
        scene = suspension_scene(shape="sand", phi=packing.volume_fraction, radius=radius,
                                 box=box, strain=strain,
                                 overrides={"inclusions.packing": str(path),
                                            **(overrides or {})})
        sim = Simulation(scene, threads=threads)
    stride = max(1, int(round(1.0 / (SAMPLES_PER_UNIT * RATE * sim.dt))))
    rows = []
    while True:
        axis = sim.bodies.rotations()[0][:, 0]
        rows.append((sim.strain, math.atan2(axis[1], axis[0]), axis[2]))
        if sim.strain >= strain:
            break
        sim.advance(stride)
    data = np.array(rows)
    return SpheroidRun(data[:, 0], np.unwrap(data[:, 1]), data[:, 2], sim.n_particles)


class OrbitFit(NamedTuple):
    """:func:`fit_orbit`'s rotation coupling ``coupling`` k [1], shape factor ``shape_factor``
    λ_h [1] and the hydrodynamic aspect ratio ``aspect`` r_h [1] they imply."""

    coupling: float
    shape_factor: float
    aspect: float


def fit_orbit(strain: np.ndarray, angle: np.ndarray, skip: float = 0.5) -> OrbitFit:
    """Least-squares fit of dα/dγ = −½ (k − λ_h cos 2α) to samples (``strain``, ``angle``),
    the derivative by central differences, leaving out the first ``skip`` strain units (the
    start from rest in a linear flow); r_h = √((k + λ_h)/(k − λ_h)) (module docstring)."""
    rate = np.gradient(angle, strain)
    keep = strain > skip
    design = np.column_stack([np.ones(keep.sum()), -np.cos(2.0 * angle[keep])])
    (coupling, shape), *_ = np.linalg.lstsq(design, -2.0 * rate[keep], rcond=None)
    ratio = shape / coupling
    aspect = math.sqrt((1.0 + ratio) / (1.0 - ratio)) if abs(ratio) < 1.0 else math.inf
    return OrbitFit(float(coupling), float(shape), aspect)
