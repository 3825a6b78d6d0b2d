"""Periodic and Lees–Edwards boundaries as pure (displacement, wrap) functions (SPEC §2.7).

The box is [0, L_x) × [0, L_y) × [0, L_z); x is the flow direction, y the gradient direction.
Lees–Edwards (LE) imposes the simple shear v_x = γ̇ y: the periodic image above the box is
displaced by the offset Δ(t) = (γ̇ L_y t) mod L_x in x and moves γ̇ L_y faster. A plain periodic
box is the special case Δ = 0, γ̇ = 0 (same functions, same results).

Symbols:

====== ============================================================ ==========
symbol meaning                                                      unit
====== ============================================================ ==========
L_x..  box lengths (lx, ly, lz)                                     [length]
γ̇      imposed shear rate (shear_rate)                              1/[time]
Δ      LE image offset in x of the image above the box (offset)     [length]
n      y-image index of a pair, n = round(dy/L_y)                   1
k      number of upward crossings of the y faces in a wrap          1
====== ============================================================ ==========

Rules (SPEC §2.7, Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed., §5.7.1):

- wrap: crossing y ≥ L_y gives y −= L_y, x −= Δ, v_x −= γ̇ L_y (reverse at y < 0); then x and z
  are wrapped periodically. Scalars are not shifted.
- pair minimum image of r_pq = r_p − r_q: n = round(dy/L_y); dy −= n L_y; dx −= n Δ;
  dx −= L_x round(dx/L_x); dz −= L_z round(dz/L_z); every velocity-dependent pair term uses
  v_pq,x − n γ̇ L_y (:func:`image_velocity`).

The minimum image is exact (the nearest image) whenever the nearest image is closer than half
the smallest box length; neighbour lists guarantee that for every listed pair. The minimum
image is compiled with ``JIT_OPTIONS`` (hot path); the wrap keeps exact IEEE division so that
floor(y/L_y) is consistent with the face it tests.

2D scenes use the same particle arrays with z ≡ 0 (see ``neighbours``); the ``*_2d`` scalar
functions are for code that carries only (x, y).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from suspsim.sph import JIT_OPTIONS


@njit(cache=True)
def lees_edwards_offset(shear_rate, lx, ly, time):
    """Δ(t) = (γ̇ L_y t) mod L_x ∈ [0, L_x) [SPEC §2.7]."""
    d = (shear_rate * ly * time) % lx
    return d if d < lx else 0.0


@njit(**JIT_OPTIONS)
def minimum_image_3d(dx, dy, dz, lx, ly, lz, offset):
    """LE minimum image of the pair vector (dx, dy, dz) = r_p − r_q [SPEC §2.7].

    Returns (dx, dy, dz, n) with n the y-image index for the velocity correction
    v_pq,x −= n γ̇ L_y. ``np.rint`` rounds halves to even; ties occur only at exactly half a box,
    outside every neighbour list.
    """
    n = np.rint(dy / ly)
    dy -= n * ly
    dx -= n * offset
    dx -= lx * np.rint(dx / lx)
    dz -= lz * np.rint(dz / lz)
    return dx, dy, dz, n


@njit(**JIT_OPTIONS)
def minimum_image_2d(dx, dy, lx, ly, offset):
    """LE minimum image of (dx, dy) = r_p − r_q; returns (dx, dy, n) [SPEC §2.7]."""
    n = np.rint(dy / ly)
    dy -= n * ly
    dx -= n * offset
    dx -= lx * np.rint(dx / lx)
    return dx, dy, n


@njit(**JIT_OPTIONS)
def image_velocity(n, shear_rate, ly):
    """n γ̇ L_y: subtract from v_pq,x of a pair with y-image index n [SPEC §2.7]."""
    return n * shear_rate * ly


@njit(cache=True)
def _wrap_periodic(x, lx):
    """x − L floor(x/L), kept strictly below L despite round-off."""
    x -= lx * math.floor(x / lx)
    if x >= lx:
        x = lx * (1.0 - 2.220446049250313e-16)
    return x


@njit(cache=True)
def wrap_3d(x, y, z, vx, lx, ly, lz, offset, shear_rate):
    """Map a particle into the box; returns (x, y, z, vx, k) [SPEC §2.7].

    k = floor(y/L_y) is the number of upward crossings: y −= k L_y, x −= k Δ, v_x −= k γ̇ L_y,
    then x, z are wrapped periodically. Round-off that would put y at L_y moves it just below.
    """
    k = math.floor(y / ly)
    y -= k * ly
    if y >= ly:
        y = ly * (1.0 - 2.220446049250313e-16)
    x -= k * offset
    vx -= k * shear_rate * ly
    return _wrap_periodic(x, lx), y, _wrap_periodic(z, lz), vx, k


@njit(cache=True)
def wrap_2d(x, y, vx, lx, ly, offset, shear_rate):
    """Map a particle into the 2D box; returns (x, y, vx, k), rules as :func:`wrap_3d`."""
    x, y, _, vx, k = wrap_3d(x, y, 0.0, vx, lx, ly, 1.0, offset, shear_rate)
    return x, y, vx, k


@njit(cache=True)
def wrap_particles(positions, velocities, box, offset, shear_rate):
    """Wrap every particle into the box in place (:func:`wrap_3d`); positions, velocities (N, 3).

    ``box`` = (L_x, L_y, L_z); in 2D (z ≡ 0) any L_z > 0 leaves z = 0. Call only when the
    neighbour list is rebuilt (see ``neighbours``): between builds positions stay unwrapped so
    that displacements since the build are exact.
    """
    lx, ly, lz = box[0], box[1], box[2]
    for i in range(positions.shape[0]):
        x, y, z, vx, _ = wrap_3d(positions[i, 0], positions[i, 1], positions[i, 2],
                                 velocities[i, 0], lx, ly, lz, offset, shear_rate)
        positions[i, 0] = x
        positions[i, 1] = y
        positions[i, 2] = z
        velocities[i, 0] = vx
