"""Initial particle positions and velocities (SPEC §2.7; scene keys ``lattice``, ``run.start``).

Positions: a simple cubic (3D) or square (2D) lattice of ``scene.lattice_counts`` sites, site
(i + ½) ℓ_a per axis a with ℓ_a = L_a / n_a (the scene checks that this matches the number
density within 1 %), each coordinate displaced by a seeded uniform jitter in ±jitter ℓ_a.
Velocities: zero ("rest", and every Poiseuille start) or the imposed Couette profile
u_x = γ̇ (y − L_y/2) ("linear"). The imposed profile has zero mean, so a start from rest and the
steady state carry the same (zero) momentum, which Lees–Edwards conserves.

Arrays are (N, 3) float64; a 2D scene has z ≡ 0.

Symbols: ℓ_a lattice spacing along axis a [h]; n_a sites along a; γ̇ imposed rate [τ^−1];
L_y box height [h].
"""
from __future__ import annotations

import numpy as np

from suspsim.scene import Scene


def lattice_positions(scene: Scene) -> np.ndarray:
    """(N, 3) jittered lattice positions inside the box (module docstring)."""
    counts = scene.lattice_counts
    axes = [(np.arange(n) + 0.5) * (side / n) for n, side in zip(counts, scene.box)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, scene.dimension)
    if scene.lattice.jitter > 0:
        spacing = np.array([side / n for n, side in zip(counts, scene.box)])
        rng = np.random.default_rng(scene.seed)
        grid = grid + rng.uniform(-1.0, 1.0, grid.shape) * scene.lattice.jitter * spacing
        grid = np.mod(grid, np.asarray(scene.box))
    positions = np.zeros((grid.shape[0], 3))
    positions[:, :scene.dimension] = grid
    return positions


def imposed_velocity(scene: Scene, y) -> np.ndarray:
    """u_x(y) of the imposed flow: γ̇ (y − L_y/2) for Couette, 0 otherwise (y unwrapped)."""
    y = np.asarray(y, dtype=float)
    if scene.flow.type != "couette":
        return np.zeros_like(y)
    return scene.flow.shear_rate * (y - 0.5 * scene.box[1])


def initial_velocities(scene: Scene, positions: np.ndarray) -> np.ndarray:
    """(N, 3) velocities: the imposed profile for ``run.start == 'linear'``, else rest."""
    velocities = np.zeros_like(positions)
    if scene.flow.type == "couette" and scene.run.start == "linear":
        velocities[:, 0] = imposed_velocity(scene, positions[:, 1])
    return velocities
