"""How the bodies of a sheared suspension are oriented and how fast they turn.

Elongated bodies in a dense sheared suspension can stop tumbling and line up with the flow
(``docs/suspensions.md``, sand at φ = 0.4–0.5), which lowers the viscosity; these two numbers
show it per sample.

- Nematic order S of unit axes u_b: the largest eigenvalue of Q = ⟨(3 u u − I)/2⟩ over the
  bodies, with its eigenvector the director (de Gennes & Prost, The Physics of Liquid
  Crystals, §2.1). S = 1 when all axes are parallel, 0 for isotropic axes (≈ 1/√N for N random
  ones), 1/4 for axes spread evenly in a plane.
- Spin ratio: the bodies' mean Ω_z over the vorticity's −γ̇/2 of the flow u = γ̇ y ê_x, the rate
  at which a free sphere turns (1); an aligned elongated body turns slower (Jeffery 1922,
  ``validation.jeffery``).
"""
from __future__ import annotations

import numpy as np

__all__ = ["nematic_order", "spin_ratio"]


def nematic_order(axes: np.ndarray) -> tuple[float, np.ndarray]:
    """(S, director) of unit vectors ``axes`` (N, 3) [1] (module docstring); the director's
    sign is arbitrary."""
    axes = np.asarray(axes, dtype=float)
    q = 1.5 * np.einsum("bi,bj->ij", axes, axes) / len(axes) - 0.5 * np.eye(3)
    values, vectors = np.linalg.eigh(q)
    return float(values[-1]), vectors[:, -1]


def spin_ratio(angular_velocities: np.ndarray, shear_rate: float) -> float:
    """Mean Ω_z of ``angular_velocities`` (N, 3) [τ⁻¹] over −½ ``shear_rate`` [τ⁻¹] (module
    docstring)."""
    return float(np.mean(np.asarray(angular_velocities)[:, 2]) / (-0.5 * shear_rate))
