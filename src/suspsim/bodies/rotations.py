"""Unit quaternions q = (w, x, y, z) for body orientations (body frame → box frame).

A body-frame vector v is v' = R(q) v in the box frame, with

    R = [[1 − 2(y²+z²), 2(xy − wz),   2(xz + wy)],
         [2(xy + wz),   1 − 2(x²+z²), 2(yz − wx)],
         [2(xz − wy),   2(yz + wx),   1 − 2(x²+y²)]],

the convention of SPEC §3.2 (scalar first). Uniform random orientations use Shoemake's method
(Graphics Gems III, 1992): three uniform numbers per body.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from suspsim.sph import JIT_OPTIONS

__all__ = ["random_quaternions", "rotation_matrices"]


def random_quaternions(count: int, rng: np.random.Generator) -> np.ndarray:
    """``count`` uniformly distributed unit quaternions (count, 4), w ≥ 0."""
    u1, u2, u3 = rng.uniform(0.0, 1.0, (3, count))
    a, b = np.sqrt(1.0 - u1), np.sqrt(u1)
    q = np.stack([a * np.sin(2 * math.pi * u2), a * np.cos(2 * math.pi * u2),
                  b * np.sin(2 * math.pi * u3), b * np.cos(2 * math.pi * u3)], axis=1)
    # q and −q are the same rotation; w ≥ 0 makes the stored value unique.
    return np.where(q[:, :1] < 0.0, -q, q)


@njit(**JIT_OPTIONS)
def _rotation_matrices(q, out):
    """R(q) of each row of ``q`` (count, 4) into ``out`` (count, 3, 3) (module docstring)."""
    for b in range(q.shape[0]):
        w, x, y, z = q[b, 0], q[b, 1], q[b, 2], q[b, 3]
        out[b, 0, 0] = 1 - 2 * (y * y + z * z)
        out[b, 0, 1] = 2 * (x * y - w * z)
        out[b, 0, 2] = 2 * (x * z + w * y)
        out[b, 1, 0] = 2 * (x * y + w * z)
        out[b, 1, 1] = 1 - 2 * (x * x + z * z)
        out[b, 1, 2] = 2 * (y * z - w * x)
        out[b, 2, 0] = 2 * (x * z - w * y)
        out[b, 2, 1] = 2 * (y * z + w * x)
        out[b, 2, 2] = 1 - 2 * (x * x + y * y)


def rotation_matrices(quaternions: np.ndarray) -> np.ndarray:
    """Rotation matrices (count, 3, 3) of unit quaternions (count, 4). Compiled: a run builds
    them every step, and the stacked NumPy form took 75 µs for 49 bodies."""
    q = np.ascontiguousarray(quaternions, dtype=np.float64).reshape(-1, 4)
    out = np.empty((q.shape[0], 3, 3))
    _rotation_matrices(q, out)
    return out
