"""The lubrication pass of a step: implicit pair impulses for every close pair of bodies.

After the fluid forces have kicked the bodies, every pair of bodies whose surface gap s is
below the cutoff s_c gets the implicit lubrication and repulsion impulses of
:func:`~suspsim.bodies.lubrication_implicit.lubrication_pair_impulse` (SPEC §3.3: the
correction F_lub(s) − F_lub(s_c), the inner cap s_min, the repulsion C/s⁸, the contact friction
μ_c and rolling friction μ_r), applied to the velocities pair after pair — the order the
implicit step requires when a body has several close neighbours. Pairs are found among all
B(B − 1)/2 with the Lees–Edwards minimum image of the centres (SPEC §2.7): the image of body 2
one box height up moves γ̇ L_y faster in x.

The viscosity of each gap is the matrix law at the gap shear rate (seed 000's heuristic,
:func:`~suspsim.bodies.lubrication.gap_viscosity`). The bodies are spheres, with the scalar
moment of inertia tr(I)/3; sand grains have their own pass at their true closest points
(:mod:`~suspsim.bodies.grain_lubrication_pass`), which shares this pass's statistics and virial
layout.

Stress (SPEC §3.5): the impulse J₁ on body 1 over δt is the step-mean force F₁₂ = J₁/δt, and
the pass adds Σ_pairs F₁₂ ⊗ r₁₂ (r₁₂ = R₁ − R₂, minimum image) to the virial in the layout
(xx, yy, zz, xy, yx) of the fluid's (σ = −Π).

Symbols: R, V, Ω centre [h], velocity [h τ⁻¹], angular velocity [τ⁻¹]; a radius [h]; M mass [m];
I scalar moment [m h²]; s gap [h]; J impulse [m h τ⁻¹]; L angular impulse [m h² τ⁻¹].
"""
from __future__ import annotations

import numpy as np
from numba import njit

from suspsim.bodies.lubrication import gap_viscosity
from suspsim.bodies.lubrication_implicit import lubrication_pair_impulse
from suspsim.sph import JIT_OPTIONS
from suspsim.sph.boundaries import minimum_image_3d

#: Columns of the returned statistics: smallest gap seen [h], pairs treated, predicted overlaps.
SMALLEST_GAP, PAIRS, OVERLAPS = range(3)


@njit(**JIT_OPTIONS)
def lubrication_pass(centres, radii, velocities, omegas, mass, inertia, box, le_offset,
                     shear_rate, dt, law_code, law_params, cutoff_gap, min_gap,
                     repulsion_strength, friction, rolling_friction, virial, stats):
    """Apply the impulses of every pair with s < ``cutoff_gap`` to ``velocities`` and
    ``omegas`` (B, 3) in place; ``virial`` (5,) gets Σ F₁₂ ⊗ r₁₂ (module docstring);
    ``stats`` (3,) the smallest gap, the number of pairs and of predicted overlaps."""
    lx, ly, lz = box[0], box[1], box[2]
    jump = shear_rate * ly
    out = np.zeros((4, 3))
    r12 = np.zeros(3)
    u2 = np.zeros(3)
    zero = np.zeros(3)
    clear_pass_records(virial, stats)
    n = centres.shape[0]
    for p in range(n):
        for q in range(p + 1, n):
            dx, dy, dz, image = minimum_image_3d(centres[p, 0] - centres[q, 0],
                                                 centres[p, 1] - centres[q, 1],
                                                 centres[p, 2] - centres[q, 2],
                                                 lx, ly, lz, le_offset)
            reach = radii[p] + radii[q] + cutoff_gap
            if dx * dx + dy * dy + dz * dz >= reach * reach:
                continue
            r12[0], r12[1], r12[2] = dx, dy, dz
            gap = np.sqrt(dx * dx + dy * dy + dz * dz) - radii[p] - radii[q]
            stats[SMALLEST_GAP] = min(stats[SMALLEST_GAP], gap)
            u2[0] = velocities[q, 0] + image * jump
            u2[1] = velocities[q, 1]
            u2[2] = velocities[q, 2]
            mu = gap_viscosity(law_code, law_params, radii[p], radii[q], r12, velocities[p], u2,
                               omegas[p], omegas[q], min_gap)
            s_new = lubrication_pair_impulse(radii[p], radii[q], r12, velocities[p], u2,
                                             omegas[p], omegas[q], zero, zero, zero, zero,
                                             mass[p], mass[q], inertia[p], inertia[q], dt, mu,
                                             cutoff_gap, min_gap, repulsion_strength, friction,
                                             rolling_friction, out)
            for k in range(3):
                velocities[p, k] += out[0, k] / mass[p]
                velocities[q, k] += out[1, k] / mass[q]
                omegas[p, k] += out[2, k] / inertia[p]
                omegas[q, k] += out[3, k] / inertia[q]
            record_pair(s_new, out, dt, dx, dy, dz, virial, stats)


@njit(**JIT_OPTIONS)
def clear_pass_records(virial, stats):
    """Zero ``virial`` and the pair counts of ``stats``, smallest gap +∞, before a pass."""
    virial[:] = 0.0
    stats[SMALLEST_GAP] = np.inf
    stats[PAIRS] = 0.0
    stats[OVERLAPS] = 0.0


@njit(**JIT_OPTIONS)
def record_pair(s_new, out, dt, dx, dy, dz, virial, stats):
    """Count a treated pair (and a predicted overlap when ``s_new`` ≤ 0) in ``stats`` and add
    its step-mean force ``out[0]``/δt ⊗ r₁₂ = (dx, dy, dz) to ``virial`` (module docstring)."""
    stats[PAIRS] += 1.0
    if s_new <= 0.0:
        stats[OVERLAPS] += 1.0
    fx, fy, fz = out[0, 0] / dt, out[0, 1] / dt, out[0, 2] / dt
    virial[0] += fx * dx
    virial[1] += fy * dy
    virial[2] += fz * dz
    virial[3] += fx * dy
    virial[4] += fy * dx
