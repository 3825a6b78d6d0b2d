"""Irving–Kirkwood pressure tensor and stress (SPEC §2.8; seed 000 Eq. 26, sign derived).

    Π_ab = (1/V) [Σ_q m ṽ_q,a ṽ_q,b + ½ Σ_p Σ_q f_pq,a r_pq,b],    σ = −Π,

with ṽ the velocity relative to the imposed flow (``lattice.imposed_velocity``) and f_pq the
force on p from q. The pair part comes from the force pass (``terms.force_pass``, summed per
chunk over the half table, i.e. once per pair). The measured viscosity is σ_xy/γ̇, the
pressure tr Π/d. Only the components the run reports are kept: xx, yy, zz, xy, yx.

Symbols: V box volume (area in 2D) [h^d]; m particle mass; ṽ peculiar velocity [h τ^−1];
Π, σ [m h^(2−d) τ^−2].
"""
from __future__ import annotations

import numpy as np

from suspsim.sph.terms.force_pass import VXX, VXY, VYY, VZZ


def kinetic_tensor(peculiar: np.ndarray, mass: float) -> np.ndarray:
    """Σ_q m ṽ_a ṽ_b as (xx, yy, zz, xy, yx)."""
    v = peculiar
    xy = mass * float(np.dot(v[:, 0], v[:, 1]))
    return np.array([mass * float(np.dot(v[:, 0], v[:, 0])), mass * float(np.dot(v[:, 1], v[:, 1])),
                     mass * float(np.dot(v[:, 2], v[:, 2])), xy, xy])


def pressure_tensor(virial_rows: np.ndarray, peculiar: np.ndarray, mass: float,
                    volume: float) -> np.ndarray:
    """Π as (xx, yy, zz, xy, yx) from the per-chunk virial rows (summed in row order)."""
    pair = np.zeros(5)
    for row in virial_rows:
        pair += row
    return (kinetic_tensor(peculiar, mass) + pair) / volume


def shear_stress(pi: np.ndarray) -> float:
    """σ_xy = −Π_xy (force component x, separation component y)."""
    return -float(pi[VXY])


def mean_pressure(pi: np.ndarray, dimension: int) -> float:
    """p = tr Π/d = −tr σ/d."""
    return float(pi[VXX] + pi[VYY] + pi[VZZ]) / dimension

