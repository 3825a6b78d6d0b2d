"""Tabulated radius functions: a cube map with bilinear interpolation, for the packer's inner loop.

Evaluating r(u) = Σ a_nm Y_nm(u) exactly costs (N+1)² terms (441 at N = 20); the relaxation of
a packing asks for it millions of times. The table samples r on the six faces of the cube
[−1, 1]³ projected onto the sphere (gnomonic cube map: face +x holds u ∝ (1, a, b) with
a, b ∈ [−1, 1] on an (n+1) × (n+1) grid), which has no poles and nearly uniform cells; a lookup
picks the face of the largest |u_k| and interpolates bilinearly in (a, b). Face edges carry the
exact values of the shared directions, so the table is continuous. Its interpolation error is
measured at every cell centre (:func:`table_error`, where bilinear interpolation errs most);
the packer adds twice that to its working gap and verifies the result with exact radii.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .harmonics import evaluate

__all__ = ["DEFAULT_TABLE_CELLS", "build_table", "table_error", "table_radius"]

#: Cells per face edge [choice]: 32 resolves degree 20 to ~1e-4 of the radius (6 × 33² nodes,
#: 52 kB per grain).
DEFAULT_TABLE_CELLS = 32


def _face_directions(nodes: np.ndarray) -> np.ndarray:
    """Unit vectors (6, k, k, 3) of face coordinates ``nodes`` (k,) on each face."""
    a, b = np.meshgrid(nodes, nodes, indexing="ij")
    one = np.ones_like(a)
    faces = []
    for axis in range(3):
        for sign in (1.0, -1.0):
            u = np.empty(a.shape + (3,))
            u[..., axis] = sign * one
            u[..., (axis + 1) % 3] = a
            u[..., (axis + 2) % 3] = b
            faces.append(u / np.linalg.norm(u, axis=-1)[..., None])
    return np.stack(faces)


def build_table(coefficients: np.ndarray, cells: int = DEFAULT_TABLE_CELLS) -> np.ndarray:
    """Cube-map table (6, cells + 1, cells + 1) of r [length] from exact evaluation."""
    return evaluate(coefficients, _face_directions(np.linspace(-1.0, 1.0, cells + 1)))


def table_error(coefficients: np.ndarray, table: np.ndarray) -> float:
    """Largest |r_table − r| [length] over the centres of all table cells."""
    cells = table.shape[1] - 1
    centres = -1.0 + (np.arange(cells) + 0.5) * 2.0 / cells
    u = _face_directions(centres).reshape(-1, 3)
    exact = evaluate(coefficients, u)
    looked_up = np.empty(len(u))
    _lookup_many(table, u, looked_up)
    return float(np.abs(looked_up - exact).max())


@njit(cache=True)
def table_radius(table, ux, uy, uz):
    """r(u) for a unit vector u from a cube-map ``table`` (bilinear)."""
    ax, ay, az = abs(ux), abs(uy), abs(uz)
    if ax >= ay and ax >= az:
        face = 0 if ux > 0.0 else 1
        a, b = uy / ax, uz / ax
    elif ay >= az:
        face = 2 if uy > 0.0 else 3
        a, b = uz / ay, ux / ay
    else:
        face = 4 if uz > 0.0 else 5
        a, b = ux / az, uy / az
    cells = table.shape[1] - 1
    fa = (a + 1.0) * 0.5 * cells
    fb = (b + 1.0) * 0.5 * cells
    ia = min(max(int(fa), 0), cells - 1)
    ib = min(max(int(fb), 0), cells - 1)
    ta = fa - ia
    tb = fb - ib
    return ((1.0 - ta) * ((1.0 - tb) * table[face, ia, ib] + tb * table[face, ia, ib + 1])
            + ta * ((1.0 - tb) * table[face, ia + 1, ib] + tb * table[face, ia + 1, ib + 1]))


@njit(cache=True)
def _lookup_many(table, u, out):
    for i in range(u.shape[0]):
        out[i] = table_radius(table, u[i, 0], u[i, 1], u[i, 2])
