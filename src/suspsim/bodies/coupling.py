"""Coupling of rigid bodies to the SPH fluid: rigid particle motion, force and torque, virial.

A body b is a rigid assembly of SPH particles i (SPEC §3.1) with body-frame offsets s⁰_i from
its centre of mass R_b and the rotation matrix Q_b (body frame → box frame):

    x_i = R_b + Q_b s⁰_i,     v_i = V_b + Ω_b × (Q_b s⁰_i)                    (SPEC §3.1)
    F_b = Σ_{i∈b} f_i,        T_b = Σ_{i∈b} (Q_b s⁰_i) × f_i                  (SPEC §3.2)

with f_i the pair forces on i from every particle not of body b (the force pass skips pairs
inside one body). The fluid solver keeps positions unwrapped between neighbour-list builds and
wraps them (Lees–Edwards) at a build, so a body particle is placed at the periodic image of
R_b + Q_b s⁰_i nearest its previous position: an image k box heights up is shifted by k Δ(t)
in x and carries k γ̇ L_y more x velocity (SPEC §2.7), then x and z images by whole box lengths.

Stress (SPEC §3.5): the molecular virial with body particles taken at their body's centre adds
−Σ_{i ∈ bodies} f_i ⊗ (Q_b s⁰_i) to the pair virial Σ_pairs f_pq ⊗ r_pq of the force pass
(the inertial constraint term is dropped: Re ≪ 1).

Symbols: R, V, Ω body centre [h], velocity [h τ⁻¹], angular velocity [τ⁻¹]; Q rotation matrix;
s⁰ body-frame offset [h]; f force [m h τ⁻²]; T torque [m h² τ⁻²]; Δ Lees–Edwards offset [h];
γ̇ imposed shear rate [τ⁻¹]; L_x, L_y, L_z box lengths [h].
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from suspsim.sph import JIT_OPTIONS

#: Columns of the virial correction, as the force pass's virial rows: xx, yy, zz, xy, yx.
VXX, VYY, VZZ, VXY, VYX = range(5)


@njit(inline="always", **JIT_OPTIONS)
def _arm(q, o):
    """Q s⁰: the box-frame arm of a particle with body-frame offset ``o`` (3,), rotation ``q``."""
    return (q[0, 0] * o[0] + q[0, 1] * o[1] + q[0, 2] * o[2],
            q[1, 0] * o[0] + q[1, 1] * o[1] + q[1, 2] * o[2],
            q[2, 0] * o[0] + q[2, 1] * o[1] + q[2, 2] * o[2])


@njit(parallel=True, **JIT_OPTIONS)
def place_body_particles(members, body_of, offsets, centres, rotations, velocities, omegas,
                         box, le_offset, shear_rate, positions, particle_velocities):
    """Set x_i and v_i of every body particle i in ``members`` from its body's state, at the
    image nearest its previous x_i (module docstring). ``rotations`` (B, 3, 3) body → box.
    Each k writes only row members[k], so the loop runs in parallel."""
    lx, ly, lz = box[0], box[1], box[2]
    for k in prange(members.shape[0]):
        i = members[k]
        b = body_of[i]
        sx, sy, sz = _arm(rotations[b], offsets[i])
        x = centres[b, 0] + sx
        y = centres[b, 1] + sy
        z = centres[b, 2] + sz
        ny = math.floor((positions[i, 1] - y) / ly + 0.5)
        y += ny * ly
        x += ny * le_offset
        x += lx * math.floor((positions[i, 0] - x) / lx + 0.5)
        z += lz * math.floor((positions[i, 2] - z) / lz + 0.5)
        positions[i, 0] = x
        positions[i, 1] = y
        positions[i, 2] = z
        w = omegas[b]
        particle_velocities[i, 0] = velocities[b, 0] + w[1] * sz - w[2] * sy + ny * shear_rate * ly
        particle_velocities[i, 1] = velocities[b, 1] + w[2] * sx - w[0] * sz
        particle_velocities[i, 2] = velocities[b, 2] + w[0] * sy - w[1] * sx


#: Fixed slices of the members that :func:`body_force_torque` sums in parallel and then adds
#: in order, so that F, T and the virial do not depend on the thread count [choice].
SLICES = 4


@njit(parallel=True, **JIT_OPTIONS)
def body_force_torque(members, body_of, offsets, rotations, force_acc, width, forces, torques,
                      virial):
    """F_b, T_b (B, 3) from the pair forces on each body's particles (``force_acc`` flat, stride
    ``width``, force first) and the stress correction ``virial`` (5,) (module docstring)."""
    n_bodies = forces.shape[0]
    partial = np.zeros((SLICES, n_bodies, 6))
    partial_virial = np.zeros((SLICES, 5))
    n = members.shape[0]
    for c in prange(SLICES):
        acc = partial[c]
        vir = partial_virial[c]
        for k in range(c * n // SLICES, (c + 1) * n // SLICES):
            i = members[k]
            b = body_of[i]
            sx, sy, sz = _arm(rotations[b], offsets[i])
            fx = force_acc[width * i]
            fy = force_acc[width * i + 1]
            fz = force_acc[width * i + 2]
            acc[b, 0] += fx
            acc[b, 1] += fy
            acc[b, 2] += fz
            acc[b, 3] += sy * fz - sz * fy
            acc[b, 4] += sz * fx - sx * fz
            acc[b, 5] += sx * fy - sy * fx
            vir[VXX] -= fx * sx
            vir[VYY] -= fy * sy
            vir[VZZ] -= fz * sz
            vir[VXY] -= fx * sy
            vir[VYX] -= fy * sx
    forces[:] = 0.0
    torques[:] = 0.0
    virial[:] = 0.0
    for c in range(SLICES):
        for b in range(n_bodies):
            for d in range(3):
                forces[b, d] += partial[c, b, d]
                torques[b, d] += partial[c, b, 3 + d]
        for d in range(5):
            virial[d] += partial_virial[c, d]
