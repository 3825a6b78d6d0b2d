"""Overlap removal by soft repulsion and FIRE minimisation (compiled kernels of the packers).

Bodies at their final size, possibly overlapping, are pushed apart pairwise with unit stiffness
and mass (only reaching zero overlap matters, so the scale is free):

    spheres:  F_i = δ e_ij,  δ = max(0, a_i + a_j + g − |r_ij|)  (harmonic soft spheres,
              U = Σ ½δ²; O'Hern et al., Phys. Rev. E 68, 011306 (2003));
    grains:   δ = the deepest radial penetration r_B(û) + g − |p − R_B| of a surface sample
              point p of one grain into the other (û the direction of p in B's body frame, r_B
              from a cube-map table), F = δ along the inward normal −n(p) of the penetrating
              point (moving p back out), or along e_ij when that would bring the centres closer
              (deep overlaps of non-convex grains, where the local normal misleads).

The grain law is the sphere law with the deepest penetration as the overlap. It is not the
gradient of an energy; the gradient of Σ ½δ_p² over all penetrating points would be, but its
radial pushes point inwards for a small grain deep inside a large one (the radial depth grows
towards B's centre), and it stalled in tests. FIRE needs only F·v, so it accepts this law.

The bodies move by FIRE (Bitzek et al., Phys. Rev. Lett. 97, 170201 (2006), with the
velocity reset of Guénolé et al., Comput. Mater. Sci. 175, 109584 (2020)) until no overlap
exceeds a tolerance, reached in finitely many steps below jamming (φ_J ≈ 0.64 for spheres).
Translations only: orientations stay as drawn [choice: enough for sand up to φ = 0.55; φ = 0.58
does not converge, rotations would be needed].

Kernel state, kept by the caller so that a call interrupted by a full pair list resumes:
``state`` = [dt, α, steps since P ≤ 0, steps done]. Return codes: :data:`CONVERGED`
(every overlap ≤ ``tolerance``), :data:`BUDGET` (``max_steps`` reached), :data:`PAIR_OVERFLOW`
(reallocate the pair list with at least the returned count and call again).

Symbols: a radius, g working gap, δ overlap [length]; dt FIRE time step, α mixing factor.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from .pairs import build_pairs, minimum_image
from .radius_table import table_radius

__all__ = ["BUDGET", "CONVERGED", "PAIR_OVERFLOW", "fire_spheres", "fire_grains", "new_state"]

CONVERGED, BUDGET, PAIR_OVERFLOW = 0, 1, 2

# FIRE parameters (Bitzek et al. 2006 defaults) for unit stiffness and mass.
_DT_START, _DT_MAX, _DT_MIN = 0.05, 0.5, 1e-4
_N_DELAY, _F_INC, _F_DEC, _ALPHA_START, _F_ALPHA = 5, 1.1, 0.5, 0.1, 0.99


def new_state() -> np.ndarray:
    """A fresh FIRE state [dt, α, steps since P ≤ 0, steps done]."""
    return np.array([_DT_START, _ALPHA_START, 0.0, 0.0])


@njit(cache=True)
def _fire_step(positions, velocities, forces, state):
    """One FIRE step (semi-implicit Euler with mixing); updates everything in place."""
    n = positions.shape[0]
    dt, alpha = state[0], state[1]
    power = 0.0
    for i in range(n):
        for d in range(3):
            power += forces[i, d] * velocities[i, d]
    if power > 0.0:
        state[2] += 1.0
        if state[2] > _N_DELAY:
            dt = min(dt * _F_INC, _DT_MAX)
            alpha *= _F_ALPHA
    else:
        state[2] = 0.0
        dt = max(dt * _F_DEC, _DT_MIN)
        alpha = _ALPHA_START
        for i in range(n):
            for d in range(3):
                positions[i, d] -= 0.5 * dt * velocities[i, d]
                velocities[i, d] = 0.0
    v_norm = 0.0
    f_norm = 0.0
    for i in range(n):
        for d in range(3):
            velocities[i, d] += dt * forces[i, d]
            v_norm += velocities[i, d] ** 2
            f_norm += forces[i, d] ** 2
    mix = alpha * math.sqrt(v_norm / f_norm) if f_norm > 0.0 else 0.0
    for i in range(n):
        for d in range(3):
            velocities[i, d] = (1.0 - alpha) * velocities[i, d] + mix * forces[i, d]
            positions[i, d] += dt * velocities[i, d]
    state[0], state[1] = dt, alpha
    state[3] += 1.0


@njit(cache=True)
def _moved_beyond(positions, reference, limit):
    """True if some body moved farther than ``limit`` since ``reference``."""
    limit2 = limit * limit
    for i in range(positions.shape[0]):
        d2 = 0.0
        for d in range(3):
            d2 += (positions[i, d] - reference[i, d]) ** 2
        if d2 > limit2:
            return True
    return False


@njit(cache=True)
def fire_spheres(positions, velocities, radii, box, gap, skin, tolerance, pairs, reference,
                 state, max_steps):
    """Relax spheres until every pair has |r_ij| ≥ a_i + a_j + ``gap`` − ``tolerance``.

    Returns (code, pairs needed on overflow else the largest overlap left).
    """
    n = positions.shape[0]
    forces = np.zeros((n, 3))
    reach = radii + 0.5 * gap
    count = 0
    rebuild = True
    largest = 0.0
    while state[3] < max_steps:
        if rebuild:
            count = build_pairs(positions, reach, box, skin, pairs)
            if count > pairs.shape[0]:
                return PAIR_OVERFLOW, float(count)
            reference[:] = positions
            rebuild = False
        forces[:] = 0.0
        largest = 0.0
        for k in range(count):
            i, j = pairs[k, 0], pairs[k, 1]
            dx, dy, dz = minimum_image(positions[i, 0] - positions[j, 0],
                                       positions[i, 1] - positions[j, 1],
                                       positions[i, 2] - positions[j, 2], box[0], box[1], box[2])
            r2 = dx * dx + dy * dy + dz * dz
            contact = radii[i] + radii[j] + gap
            if r2 >= contact * contact:
                continue
            r = math.sqrt(r2)
            overlap = contact - r
            largest = max(largest, overlap)
            if r > 0.0:
                fx, fy, fz = dx * overlap / r, dy * overlap / r, dz * overlap / r
            else:
                # Coincident centres (a chance of ~1e-300 per pair): any direction will do.
                fx, fy, fz = overlap, 0.0, 0.0
            forces[i, 0] += fx
            forces[i, 1] += fy
            forces[i, 2] += fz
            forces[j, 0] -= fx
            forces[j, 1] -= fy
            forces[j, 2] -= fz
        if largest <= tolerance:
            return CONVERGED, largest
        _fire_step(positions, velocities, forces, state)
        rebuild = _moved_beyond(positions, reference, 0.5 * skin)
    return BUDGET, largest


@njit(cache=True)
def _deepest_point(offsets_a, base_x, base_y, base_z, table_b, rotation_b, size_b, reach_b, gap):
    """Deepest radial penetration of A's sample points into B enlarged by ``gap``.

    ``offsets_a`` (M, 3) are A's surface points relative to its centre (box frame), ``base`` =
    R_A − R_B (minimum image), ``rotation_b`` maps box to B's body frame, ``reach_b`` bounds
    B's radius + gap. Returns (depth, index of the deepest point; −1 if none penetrates).
    """
    deepest = 0.0
    index = -1
    reach2 = reach_b * reach_b
    for k in range(offsets_a.shape[0]):
        dx = base_x + offsets_a[k, 0]
        dy = base_y + offsets_a[k, 1]
        dz = base_z + offsets_a[k, 2]
        rho2 = dx * dx + dy * dy + dz * dz
        if rho2 >= reach2:
            continue
        rho = math.sqrt(rho2)
        if rho == 0.0:
            return reach_b, k
        ux = (rotation_b[0, 0] * dx + rotation_b[0, 1] * dy + rotation_b[0, 2] * dz) / rho
        uy = (rotation_b[1, 0] * dx + rotation_b[1, 1] * dy + rotation_b[1, 2] * dz) / rho
        uz = (rotation_b[2, 0] * dx + rotation_b[2, 1] * dy + rotation_b[2, 2] * dz) / rho
        depth = size_b * table_radius(table_b, ux, uy, uz) + gap - rho
        if depth > deepest:
            deepest = depth
            index = k
    return deepest, index


@njit(cache=True)
def fire_grains(positions, velocities, sizes, support, tables, offsets, normals, to_body, box,
                gap, skin, tolerance, pairs, reference, state, max_steps):
    """Relax grains until no sample point of one lies within ``gap`` (radially) of another.

    Grain i: centre ``positions[i]``, radius function sizes[i]·r̂_i from ``tables[i]`` (unit-size
    cube map), support radius sizes[i]·support[i], surface sample points ``offsets[i]`` (M, 3)
    relative to the centre and their outward unit normals ``normals[i]`` (M, 3), both in the box
    frame, ``to_body[i]`` the box-to-body rotation. A pair's force has the magnitude of its
    deepest penetration δ and pushes the penetrating point back along its own inward normal;
    if that would move the grain towards the other's centre (deep, awkward overlaps) it
    pushes along the line of centres instead. Converged when every δ ≤ ``tolerance``.
    Returns (code, pairs needed on overflow else the largest overlap left).
    """
    n = positions.shape[0]
    forces = np.zeros((n, 3))
    reach = sizes * support + 0.5 * gap
    count = 0
    rebuild = True
    largest = 0.0
    while state[3] < max_steps:
        if rebuild:
            count = build_pairs(positions, reach, box, skin, pairs)
            if count > pairs.shape[0]:
                return PAIR_OVERFLOW, float(count)
            reference[:] = positions
            rebuild = False
        forces[:] = 0.0
        largest = 0.0
        for k in range(count):
            i, j = pairs[k, 0], pairs[k, 1]
            bx, by, bz = minimum_image(positions[i, 0] - positions[j, 0],
                                       positions[i, 1] - positions[j, 1],
                                       positions[i, 2] - positions[j, 2], box[0], box[1], box[2])
            distance = math.sqrt(bx * bx + by * by + bz * bz)
            if distance >= reach[i] + reach[j]:
                continue
            depth_ij, k_ij = _deepest_point(offsets[i], bx, by, bz, tables[j], to_body[j],
                                            sizes[j], sizes[j] * support[j] + gap, gap)
            depth_ji, k_ji = _deepest_point(offsets[j], -bx, -by, -bz, tables[i], to_body[i],
                                            sizes[i], sizes[i] * support[i] + gap, gap)
            if depth_ij <= 0.0 and depth_ji <= 0.0:
                continue
            # Direction in which i is pushed: i's point retreats along −n_i, or j's along −n_j.
            if depth_ij >= depth_ji:
                depth = depth_ij
                nx, ny, nz = -normals[i, k_ij, 0], -normals[i, k_ij, 1], -normals[i, k_ij, 2]
            else:
                depth = depth_ji
                nx, ny, nz = normals[j, k_ji, 0], normals[j, k_ji, 1], normals[j, k_ji, 2]
            largest = max(largest, depth)
            if nx * bx + ny * by + nz * bz <= 0.0:
                if distance > 0.0:
                    nx, ny, nz = bx / distance, by / distance, bz / distance
                else:
                    nx, ny, nz = 1.0, 0.0, 0.0
            forces[i, 0] += depth * nx
            forces[i, 1] += depth * ny
            forces[i, 2] += depth * nz
            forces[j, 0] -= depth * nx
            forces[j, 1] -= depth * ny
            forces[j, 2] -= depth * nz
        if largest <= tolerance:
            return CONVERGED, largest
        _fire_step(positions, velocities, forces, state)
        rebuild = _moved_beyond(positions, reference, 0.5 * skin)
    return BUDGET, largest
