"""Rigid-body rotation: the symplectic NO_SQUISH integrator of Miller et al. (2002) (SPEC §3.2).

The orientation of body b is a unit quaternion q = (q0, q1, q2, q3) = (w, x, y, z), the rotation
A(q) from the body's **principal** frame to the box frame (the convention of
:mod:`~suspsim.bodies.rotations`). Its conjugate momentum is the 4-vector

    π = 2 S(q) (0, L_body),   S(q) = [[q0, −q1, −q2, −q3],
                                      [q1,  q0, −q3,  q2],
                                      [q2,  q3,  q0, −q1],
                                      [q3, −q2,  q1,  q0]],

S(q) v = q ⊗ v the quaternion product, L_body = Aᵀ L the angular momentum in the principal
frame, so that (0, L_body) = ½ S(q)ᵀ π (S is orthogonal for |q| = 1). One step δt:

1. half kick (q fixed): dπ/dt = 2 S(q)(0, T_body), so over δt/2
   π ← π + δt S(q)(0, T_body), T_body = Aᵀ T (:func:`half_kick_rotation`; δt is the *full*
   step, the kick spans δt/2);
2. free rotor (:func:`free_rotor`), the symmetric splitting
   R3(δt/2) R2(δt/2) R1(δt) R2(δt/2) R3(δt/2) with the exact rotation about principal axis k

       R_k(τ):  ζ = πᵀ P_k q / (4 I_k),   q ← cos(ζτ) q + sin(ζτ) P_k q,
                                          π ← cos(ζτ) π + sin(ζτ) P_k π,
       P1 q = (−q1, q0, q3, −q2),  P2 q = (−q2, −q3, q0, q1),  P3 q = (−q3, q2, −q1, q0)

   (P_k q = q ⊗ (0, e_k), so ζ = L_k/(2 I_k) = ω_k/2 and R_k rotates the body by ω_k τ
   about its axis k);
3. half kick with the new torque.

Each R_k is an orthogonal rotation in the (q, P_k q) and (π, P_k π) planes, so |q| = 1 and the
box-frame angular momentum L = A(q) L_body are preserved to round-off; a constant torque gives
L(t) = L₀ + T t exactly; the energy error is bounded (symplectic, time-reversible, second
order). Translation is the solver's velocity Verlet.

The packing stores orientations of the packing (shape) frame; with P the rotation body →
principal of :class:`~suspsim.bodies.construction.BodyParticles` (y_principal = P y_body), the
principal-frame quaternion is q_p = q_body ⊗ q(Pᵀ) (:func:`principal_orientations`, inverse
:func:`body_orientations`).

Symbols:

======= ================================================= ====================
symbol  meaning                                           unit
======= ================================================= ====================
q       unit quaternion, principal frame → box            1
π       conjugate momentum 2 S(q)(0, L_body)              [mass length²/time]
L       angular momentum (box frame; _body: principal)    [mass length²/time]
T       torque (box frame)                                [mass length²/time²]
I_k     principal moments of inertia                      [mass length²]
ω, Ω    angular velocity, principal and box frame         [1/time]
δt, τ   time step, sub-step                               [time]
======= ================================================= ====================

Reference: T. F. Miller III, M. Eleftheriou, P. Pattnaik, A. Ndirango, D. Newns,
G. J. Martyna, J. Chem. Phys. 116, 8649 (2002), Eqs. 2.11–2.16 and Sec. II C.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from suspsim.sph import JIT_OPTIONS

__all__ = ["angular_momentum", "angular_velocity", "body_orientations", "conjugate_momentum",
           "conjugate_momentum_from_angular_velocity", "free_rotor", "half_kick_rotation",
           "principal_orientations", "quaternion_from_matrix", "quaternion_multiply",
           "rotational_kinetic_energy"]


# ---------------------------------------------------------------------------------------------
# Per-body building blocks (scalars in, tuples out)

@njit(inline="always", **JIT_OPTIONS)
def _matrix(q0, q1, q2, q3):
    """A(q), row-major (principal frame → box)."""
    return (1.0 - 2.0 * (q2 * q2 + q3 * q3), 2.0 * (q1 * q2 - q0 * q3), 2.0 * (q1 * q3 + q0 * q2),
            2.0 * (q1 * q2 + q0 * q3), 1.0 - 2.0 * (q1 * q1 + q3 * q3), 2.0 * (q2 * q3 - q0 * q1),
            2.0 * (q1 * q3 - q0 * q2), 2.0 * (q2 * q3 + q0 * q1), 1.0 - 2.0 * (q1 * q1 + q2 * q2))


@njit(inline="always", **JIT_OPTIONS)
def _to_body(q0, q1, q2, q3, vx, vy, vz):
    """Aᵀ v: a box-frame vector in the principal frame."""
    a = _matrix(q0, q1, q2, q3)
    return (a[0] * vx + a[3] * vy + a[6] * vz, a[1] * vx + a[4] * vy + a[7] * vz,
            a[2] * vx + a[5] * vy + a[8] * vz)


@njit(inline="always", **JIT_OPTIONS)
def _to_box(q0, q1, q2, q3, vx, vy, vz):
    """A v: a principal-frame vector in the box frame."""
    a = _matrix(q0, q1, q2, q3)
    return (a[0] * vx + a[1] * vy + a[2] * vz, a[3] * vx + a[4] * vy + a[5] * vz,
            a[6] * vx + a[7] * vy + a[8] * vz)


@njit(inline="always", **JIT_OPTIONS)
def _s_times(q0, q1, q2, q3, vx, vy, vz):
    """S(q)(0, v) = q ⊗ (0, v)."""
    return (-q1 * vx - q2 * vy - q3 * vz, q0 * vx - q3 * vy + q2 * vz,
            q3 * vx + q0 * vy - q1 * vz, -q2 * vx + q1 * vy + q0 * vz)


@njit(inline="always", **JIT_OPTIONS)
def _body_momentum(q0, q1, q2, q3, p0, p1, p2, p3):
    """L_body = components 1..3 of ½ S(q)ᵀ π."""
    return (0.5 * (-q1 * p0 + q0 * p1 + q3 * p2 - q2 * p3),
            0.5 * (-q2 * p0 - q3 * p1 + q0 * p2 + q1 * p3),
            0.5 * (-q3 * p0 + q2 * p1 - q1 * p2 + q0 * p3))


@njit(inline="always", **JIT_OPTIONS)
def _permute(k, v0, v1, v2, v3):
    """P_k v (k = 1, 2, 3; SPEC §3.2)."""
    if k == 1:
        return -v1, v0, v3, -v2
    if k == 2:
        return -v2, -v3, v0, v1
    return -v3, v2, -v1, v0


@njit(**JIT_OPTIONS)
def _rotor(q, p, b, k, moment, tau):
    """R_k(τ) on body b in place: ζ = πᵀP_k q/(4 I_k), (q, π) ← cos ζτ (q, π) + sin ζτ P_k(q, π)."""
    q0, q1, q2, q3 = q[b, 0], q[b, 1], q[b, 2], q[b, 3]
    p0, p1, p2, p3 = p[b, 0], p[b, 1], p[b, 2], p[b, 3]
    a0, a1, a2, a3 = _permute(k, q0, q1, q2, q3)
    c0, c1, c2, c3 = _permute(k, p0, p1, p2, p3)
    zeta = (p0 * a0 + p1 * a1 + p2 * a2 + p3 * a3) / (4.0 * moment)
    c = math.cos(zeta * tau)
    s = math.sin(zeta * tau)
    q[b, 0], q[b, 1], q[b, 2], q[b, 3] = c * q0 + s * a0, c * q1 + s * a1, c * q2 + s * a2, \
        c * q3 + s * a3
    p[b, 0], p[b, 1], p[b, 2], p[b, 3] = c * p0 + s * c0, c * p1 + s * c1, c * p2 + s * c2, \
        c * p3 + s * c3


# ---------------------------------------------------------------------------------------------
# Array operations (B bodies)

@njit(**JIT_OPTIONS)
def half_kick_rotation(q, pi, torque_box, dt):
    """π ← π + δt S(q)(0, A(q)ᵀ T): the torque's half kick over δt/2 (``dt`` the full step).

    ``q`` (B, 4) unit quaternions principal → box, ``pi`` (B, 4) conjugate momenta (updated in
    place), ``torque_box`` (B, 3) [mass length²/time²].
    """
    for b in range(q.shape[0]):
        q0, q1, q2, q3 = q[b, 0], q[b, 1], q[b, 2], q[b, 3]
        tx, ty, tz = _to_body(q0, q1, q2, q3, torque_box[b, 0], torque_box[b, 1],
                              torque_box[b, 2])
        d0, d1, d2, d3 = _s_times(q0, q1, q2, q3, tx, ty, tz)
        pi[b, 0] += dt * d0
        pi[b, 1] += dt * d1
        pi[b, 2] += dt * d2
        pi[b, 3] += dt * d3


@njit(**JIT_OPTIONS)
def free_rotor(q, pi, principal_moments, dt):
    """Torque-free rotation over δt: R3(δt/2) R2(δt/2) R1(δt) R2(δt/2) R3(δt/2), in place.

    ``principal_moments`` (B, 3) I_1, I_2, I_3 [mass length²], the axes of ``q``'s frame.
    """
    half = 0.5 * dt
    for b in range(q.shape[0]):
        _rotor(q, pi, b, 3, principal_moments[b, 2], half)
        _rotor(q, pi, b, 2, principal_moments[b, 1], half)
        _rotor(q, pi, b, 1, principal_moments[b, 0], dt)
        _rotor(q, pi, b, 2, principal_moments[b, 1], half)
        _rotor(q, pi, b, 3, principal_moments[b, 2], half)


@njit(**JIT_OPTIONS)
def angular_momentum(q, pi, out):
    """out (B, 3) ← L = A(q) L_body, L_body = (½ S(q)ᵀ π)_{1..3} (box frame)."""
    for b in range(q.shape[0]):
        q0, q1, q2, q3 = q[b, 0], q[b, 1], q[b, 2], q[b, 3]
        lx, ly, lz = _body_momentum(q0, q1, q2, q3, pi[b, 0], pi[b, 1], pi[b, 2], pi[b, 3])
        out[b, 0], out[b, 1], out[b, 2] = _to_box(q0, q1, q2, q3, lx, ly, lz)


@njit(**JIT_OPTIONS)
def angular_velocity(q, pi, principal_moments, out):
    """out (B, 3) ← Ω = A(q) ω, ω_k = L_body,k / I_k (box frame) [1/time]."""
    for b in range(q.shape[0]):
        q0, q1, q2, q3 = q[b, 0], q[b, 1], q[b, 2], q[b, 3]
        lx, ly, lz = _body_momentum(q0, q1, q2, q3, pi[b, 0], pi[b, 1], pi[b, 2], pi[b, 3])
        out[b, 0], out[b, 1], out[b, 2] = _to_box(
            q0, q1, q2, q3, lx / principal_moments[b, 0], ly / principal_moments[b, 1],
            lz / principal_moments[b, 2])


@njit(**JIT_OPTIONS)
def conjugate_momentum(q, angular_momentum_box, out):
    """out (B, 4) ← π = 2 S(q)(0, A(q)ᵀ L) from the box-frame angular momentum L."""
    for b in range(q.shape[0]):
        q0, q1, q2, q3 = q[b, 0], q[b, 1], q[b, 2], q[b, 3]
        lx, ly, lz = _to_body(q0, q1, q2, q3, angular_momentum_box[b, 0],
                              angular_momentum_box[b, 1], angular_momentum_box[b, 2])
        d0, d1, d2, d3 = _s_times(q0, q1, q2, q3, lx, ly, lz)
        out[b, 0], out[b, 1], out[b, 2], out[b, 3] = 2.0 * d0, 2.0 * d1, 2.0 * d2, 2.0 * d3


@njit(**JIT_OPTIONS)
def conjugate_momentum_from_angular_velocity(q, angular_velocity_box, principal_moments, out):
    """out (B, 4) ← π = 2 S(q)(0, L_body), L_body,k = I_k (A(q)ᵀ Ω)_k."""
    for b in range(q.shape[0]):
        q0, q1, q2, q3 = q[b, 0], q[b, 1], q[b, 2], q[b, 3]
        wx, wy, wz = _to_body(q0, q1, q2, q3, angular_velocity_box[b, 0],
                              angular_velocity_box[b, 1], angular_velocity_box[b, 2])
        d0, d1, d2, d3 = _s_times(q0, q1, q2, q3, principal_moments[b, 0] * wx,
                                  principal_moments[b, 1] * wy, principal_moments[b, 2] * wz)
        out[b, 0], out[b, 1], out[b, 2], out[b, 3] = 2.0 * d0, 2.0 * d1, 2.0 * d2, 2.0 * d3


@njit(**JIT_OPTIONS)
def rotational_kinetic_energy(q, pi, principal_moments):
    """Σ_b Σ_k L_body,k² / (2 I_k) [mass length²/time²]."""
    total = 0.0
    for b in range(q.shape[0]):
        lx, ly, lz = _body_momentum(q[b, 0], q[b, 1], q[b, 2], q[b, 3],
                                    pi[b, 0], pi[b, 1], pi[b, 2], pi[b, 3])
        total += 0.5 * (lx * lx / principal_moments[b, 0] + ly * ly / principal_moments[b, 1]
                        + lz * lz / principal_moments[b, 2])
    return total


# ---------------------------------------------------------------------------------------------
# Frames (NumPy, set-up only)

def quaternion_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton products a ⊗ b (…, 4), scalar first: A(a ⊗ b) = A(a) A(b)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    a0, a1, a2, a3 = np.moveaxis(a, -1, 0)
    b0, b1, b2, b3 = np.moveaxis(b, -1, 0)
    return np.stack([a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
                     a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
                     a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
                     a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0], axis=-1)


def quaternion_from_matrix(rotation: np.ndarray) -> np.ndarray:
    """Unit quaternions (…, 4), w ≥ 0, of rotation matrices (…, 3, 3) (Shepperd's method:
    the largest of 1 + tr R, 1 + 2R_kk − tr R is the pivot, so no catastrophic division)."""
    r = np.asarray(rotation, dtype=np.float64)
    flat = r.reshape(-1, 3, 3)
    out = np.empty((len(flat), 4))
    for i, m in enumerate(flat):
        t = np.trace(m)
        pivots = np.array([t, m[0, 0], m[1, 1], m[2, 2]])
        k = int(np.argmax(pivots))
        if k == 0:
            s = 2.0 * math.sqrt(1.0 + t)
            q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s,
                 (m[1, 0] - m[0, 1]) / s]
        elif k == 1:
            s = 2.0 * math.sqrt(1.0 + 2.0 * m[0, 0] - t)
            q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s,
                 (m[0, 2] + m[2, 0]) / s]
        elif k == 2:
            s = 2.0 * math.sqrt(1.0 + 2.0 * m[1, 1] - t)
            q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s,
                 (m[1, 2] + m[2, 1]) / s]
        else:
            s = 2.0 * math.sqrt(1.0 + 2.0 * m[2, 2] - t)
            q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s,
                 0.25 * s]
        q = np.array(q)
        out[i] = (-q if q[0] < 0.0 else q) / np.linalg.norm(q)
    return out.reshape(r.shape[:-2] + (4,))


def principal_orientations(orientations: np.ndarray, body_to_principal: np.ndarray) -> np.ndarray:
    """q_p = q_body ⊗ q(Pᵀ) (B, 4): principal frame → box, from packing-frame orientations."""
    back = quaternion_from_matrix(np.transpose(np.asarray(body_to_principal), (0, 2, 1)))
    return quaternion_multiply(orientations, back)


def body_orientations(principal: np.ndarray, body_to_principal: np.ndarray) -> np.ndarray:
    """q_body = q_p ⊗ q(P) (B, 4): the packing-frame orientations of principal quaternions."""
    return quaternion_multiply(principal, quaternion_from_matrix(body_to_principal))
