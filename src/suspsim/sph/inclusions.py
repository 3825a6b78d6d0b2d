"""Initial particles of a scene with rigid inclusions (SPEC §3.1, scene key ``inclusions``).

The packing comes from ``inclusions.packing`` (a file of ``suspsim pack``, whose box must be
the scene's) or is made from the other keys (:func:`suspsim.bodies.packing.pack`). Each body
becomes the surface shell of a rigid assembly of SPH particles at the fluid's number density
(:func:`suspsim.bodies.construction.build_body_particles`: the core, which no fluid particle
can reach, is dropped, its mass and inertia kept); fluid lattice sites inside a
body or closer than ``inclusions.fluid_margin`` lattice spacings to its surface are removed.
Fluid particles come first in the arrays, then each body's particles.

The reference density of the EOS is that of the fluid lattice before the bodies were cut out,
ρ_eq = m N_lattice/V, the value a scene without inclusions uses (SPEC §2.2: N m/V): counting
the bodies' particles instead would set it by how the two lattices meet at the surfaces.
The cut leaves density errors of ±20 % next to the surfaces, which the relaxation of the start
(:meth:`suspsim.sph.simulation.Simulation.relax`) removes. Body particles take their density
from the fluid around them at every step (``sph.density.body_particle_density``).

Bodies start with the imposed flow at their centre, V = γ̇ (y − L_y/2) x̂, and its rotation
Ω = −½ γ̇ ẑ (``run.start: linear``), or at rest.

Units: lengths [h], mass [m] (particle mass 1), time [τ].
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from suspsim.bodies.construction import build_body_particles, fluid_outside_bodies
from suspsim.bodies.packing import Packing, pack
from suspsim.bodies.rigid import principal_orientations
from suspsim.bodies.system import RigidBodies
from suspsim.errors import InputError
from suspsim.io.packing_file import read_packing
from suspsim.scene import Scene
from suspsim.sph.lattice import imposed_velocity, initial_velocities, lattice_positions


@dataclass
class InclusionSetup:
    """Particles and bodies of a scene with inclusions (module docstring).

    ``body_of`` (N,) body of each particle (−1 fluid); ``offsets`` (N, 3) principal-frame
    offsets of body particles [h] (0 for fluid); ``reference_count`` N_lattice (module
    docstring); ``centre_shift`` (B, 3) and ``body_to_principal`` (B, 3, 3) the lattice
    centres of mass [h] and frame rotations of :class:`~suspsim.bodies.construction.BodyParticles`.
    """

    positions: np.ndarray
    velocities: np.ndarray
    body_of: np.ndarray
    offsets: np.ndarray
    bodies: RigidBodies
    packing: Packing
    reference_count: int
    centre_shift: np.ndarray
    body_to_principal: np.ndarray


def initial_body_motion(scene: Scene, centres: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(V, Ω) (B, 3) at the start: the imposed flow at each centre and its rotation −½ γ̇ ẑ for
    ``run.start: linear`` Couette, else rest (module docstring)."""
    velocities = np.zeros((len(centres), 3))
    omegas = np.zeros((len(centres), 3))
    if scene.flow.type == "couette" and scene.run.start == "linear":
        velocities[:, 0] = imposed_velocity(scene, centres[:, 1])
        omegas[:, 2] = -0.5 * scene.flow.shear_rate
    return velocities, omegas


def scene_packing(scene: Scene) -> Packing:
    """The packing of ``scene``: read from ``inclusions.packing`` or packed from its keys."""
    spec = scene.inclusions
    if spec.packing is not None:
        packing = read_packing(spec.packing)
        if not np.allclose(packing.box, scene.box, rtol=1e-9, atol=0.0):
            raise InputError(spec.packing, f"packing box {list(packing.box)} differs from the "
                             f"scene box {list(scene.box)}", key="inclusions.packing")
        return packing
    seed = scene.seed if spec.seed is None else spec.seed
    return pack(spec.shape, scene.box, spec.phi, spec.radius, polydispersity=spec.polydispersity,
                size_ratio=spec.size_ratio, seed=seed, min_gap=spec.min_gap)


def build_inclusions(scene: Scene, packing: Packing | None = None) -> InclusionSetup:
    """Fluid and body particles, body states and the reference count (module docstring)."""
    packing = scene_packing(scene) if packing is None else packing
    built = build_body_particles(packing, scene.number_density, support=1.0,
                                 dimension=scene.dimension)
    lattice = lattice_positions(scene)
    margin = scene.inclusions.fluid_margin * scene.lattice_spacing
    fluid = lattice[fluid_outside_bodies(lattice, packing, np.asarray(scene.box), margin)]
    n_fluid, n_body = len(fluid), len(built.body_index)
    centres = built.centres_of_mass(packing.centres, packing.orientations)
    quaternions = principal_orientations(packing.orientations, built.body_to_principal)
    velocities_b, omegas = initial_body_motion(scene, centres)
    bodies = RigidBodies.at_rest_in_flow(centres, quaternions, built.mass,
                                         built.principal_moments, velocities_b, omegas)
    positions = np.zeros((n_fluid + n_body, 3))
    positions[:n_fluid] = fluid
    velocities = np.zeros_like(positions)
    velocities[:n_fluid] = initial_velocities(scene, fluid)
    body_of = np.full(n_fluid + n_body, -1, dtype=np.int64)
    body_of[n_fluid:] = built.body_index
    offsets = np.zeros_like(positions)
    offsets[n_fluid:] = built.principal_offsets
    rotations = bodies.rotations()
    shells = np.einsum("nij,nj->ni", rotations[built.body_index], built.principal_offsets)
    positions[n_fluid:] = centres[built.body_index] + shells
    angular = bodies.angular_velocities()
    velocities[n_fluid:] = (bodies.velocities[built.body_index]
                            + np.cross(angular[built.body_index], shells))
    return InclusionSetup(positions, velocities, body_of, offsets, bodies, packing, len(lattice),
                          built.centre_shift, built.body_to_principal)
