"""The rigid bodies of a run: their state and its time integration beside the fluid's.

Translation follows the fluid's Groot–Warren velocity Verlet (SPEC §2.6, ``sph.integrator``):

    R(t + δt) = R + V δt + ½ δt² A,   Ṽ = V + λ δt A,   V(t + δt) = V + ½ δt (A + A(t + δt)),

A = F/M. Rotation is NO_SQUISH (Miller et al. 2002; SPEC §3.2, :mod:`~suspsim.bodies.rigid`):
a half kick of the conjugate momentum π with the torque T(t), the free-rotor sequence over δt,
and after the force evaluation a half kick with T(t + δt). The angular velocity used for the
body particles' predicted velocities is that of the half-kicked π at the new orientation — the
rotational counterpart of Ṽ (λ = ½).

Quaternions q (w, x, y, z) map each body's **principal** frame to the box frame; the particle
offsets s⁰ and the moments I₁, I₂, I₃ are in that frame (``bodies.construction``). Lees–Edwards
wrapping of the centres (SPEC §2.7) happens at neighbour-list builds, like the particles'.

Symbols: R, V, A centre [h], velocity [h τ⁻¹], acceleration [h τ⁻²]; M mass [m]; I principal
moments [m h²]; F force [m h τ⁻²]; T torque [m h² τ⁻²] (box frame); π NO_SQUISH momentum
(4,) [m h² τ⁻¹]; Ω angular velocity [τ⁻¹] (box frame).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from suspsim.bodies import rigid
from suspsim.bodies.rotations import rotation_matrices
from suspsim.sph.boundaries import wrap_3d

#: Groot–Warren λ (as ``sph.integrator.LAMBDA``).
LAMBDA = 0.5


@dataclass
class RigidBodies:
    """State of B rigid bodies (module docstring); every array's first axis is B."""

    centres: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray
    quaternions: np.ndarray
    momenta: np.ndarray
    forces: np.ndarray
    torques: np.ndarray
    mass: np.ndarray
    moments: np.ndarray

    @classmethod
    def at_rest_in_flow(cls, centres, quaternions, mass, moments, velocities, omegas):
        """Bodies at ``centres`` with ``velocities`` and box-frame angular velocities ``omegas``."""
        count = len(mass)
        q = np.ascontiguousarray(quaternions, dtype=float)
        moments = np.ascontiguousarray(moments, dtype=float)
        momenta = np.zeros((count, 4))
        rigid.conjugate_momentum_from_angular_velocity(
            q, np.ascontiguousarray(omegas, dtype=float), moments, momenta)
        return cls(centres=np.ascontiguousarray(centres, dtype=float).copy(),
                   velocities=np.ascontiguousarray(velocities, dtype=float).copy(),
                   accelerations=np.zeros((count, 3)), quaternions=q.copy(), momenta=momenta,
                   forces=np.zeros((count, 3)), torques=np.zeros((count, 3)),
                   mass=np.ascontiguousarray(mass, dtype=float), moments=moments)

    @property
    def count(self) -> int:
        return len(self.mass)

    def rotations(self) -> np.ndarray:
        """Rotation matrices (B, 3, 3), principal frame → box frame."""
        return rotation_matrices(self.quaternions)

    def angular_velocities(self) -> np.ndarray:
        """Ω (B, 3) in the box frame from (q, π)."""
        out = np.empty((self.count, 3))
        rigid.angular_velocity(self.quaternions, self.momenta, self.moments, out)
        return out

    def drift(self, dt: float) -> None:
        """R += V δt + ½ δt² A; π half kick with T(t); free rotor over δt."""
        self.centres += self.velocities * dt + 0.5 * dt * dt * self.accelerations
        rigid.half_kick_rotation(self.quaternions, self.momenta, self.torques, dt)
        rigid.free_rotor(self.quaternions, self.momenta, self.moments, dt)

    def predicted(self, dt: float) -> tuple[np.ndarray, np.ndarray]:
        """(Ṽ, Ω̃) for the force evaluation (module docstring)."""
        return self.velocities + LAMBDA * dt * self.accelerations, self.angular_velocities()

    def kick(self, forces: np.ndarray, torques: np.ndarray, dt: float) -> None:
        """V += ½ δt (A + F/M), A ← F/M; π half kick with the new torque; store F, T."""
        new = forces / self.mass[:, None]
        self.velocities += 0.5 * dt * (self.accelerations + new)
        self.accelerations[...] = new
        self.forces[...] = forces
        self.torques[...] = torques
        rigid.half_kick_rotation(self.quaternions, self.momenta, self.torques, dt)

    def set_motion(self, velocities: np.ndarray, omegas: np.ndarray) -> None:
        """Set V and (through π) the box-frame angular velocities Ω; A, F, T to zero."""
        self.velocities[...] = velocities
        self.set_angular_velocities(omegas)
        for array in (self.accelerations, self.forces, self.torques):
            array[...] = 0.0

    def set_angular_velocities(self, omegas: np.ndarray) -> None:
        """Set π from the box-frame angular velocities Ω (B, 3) at the current orientations."""
        rigid.conjugate_momentum_from_angular_velocity(
            self.quaternions, np.ascontiguousarray(omegas, dtype=float), self.moments,
            self.momenta)

    def set_forces(self, forces: np.ndarray, torques: np.ndarray) -> None:
        """Initial F, T and A = F/M (before the first step)."""
        self.forces[...] = forces
        self.torques[...] = torques
        self.accelerations[...] = forces / self.mass[:, None]

    def wrap(self, box, le_offset: float, shear_rate: float) -> None:
        """Map the centres into the box (Lees–Edwards rules, SPEC §2.7)."""
        lx, ly, lz = float(box[0]), float(box[1]), float(box[2])
        for b in range(self.count):
            x, y, z, vx, _ = wrap_3d(self.centres[b, 0], self.centres[b, 1], self.centres[b, 2],
                                     self.velocities[b, 0], lx, ly, lz, le_offset, shear_rate)
            self.centres[b] = (x, y, z)
            self.velocities[b, 0] = vx

    def state(self) -> dict[str, np.ndarray]:
        """Copies of every array, for checkpoints."""
        return {name: getattr(self, name).copy() for name in self.__dataclass_fields__}

    @classmethod
    def from_state(cls, state) -> "RigidBodies":
        return cls(**{name: np.array(state[name], dtype=float)
                      for name in cls.__dataclass_fields__})
