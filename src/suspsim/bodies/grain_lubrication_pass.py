"""The lubrication pass between sand grains: implicit pair impulses at the true closest points.

Grains take the place of the spheres of :mod:`~suspsim.bodies.lubrication_pass` (same
statistics, same virial layout, same order: pair after pair on the updated velocities), with
the gap, normal and curvatures of the grains' closest points
(:mod:`~suspsim.bodies.grain_contacts`) instead of those of volume-equivalent spheres.

For each pair within reach (support radii + s_c about the centroids, Lees–Edwards minimum
image, SPEC §2.7) the two osculating spheres (radii R_A, R_B, centres c_A, c_B) carry the
implicit impulses of :func:`~suspsim.bodies.lubrication_implicit.lubrication_pair_impulse_law`
(SPEC §3.3) [choice, derived]:

* **Virtual motion**: a virtual sphere moves rigidly with its grain, U' = U + Ω × ℓ,
  ℓ = c − R (centre of mass R), Ω' = Ω.
* **Normal law**: the squeeze c1 of SPEC §3.4, c1 = 12π/(tr K √det K) with K = K_A + K_B from
  the principal curvatures and directions at the two contact points (clamped to the osculating
  radii's range, so K is positive definite), and the sub-leading c2, c3, ℓ of the two osculating
  spheres (:func:`~suspsim.bodies.lubrication.sphere_squeeze_law`). For two spheres
  c1 = 6π (a1 a2/(a1 + a2))², the sphere law; for grains the leading 1/s term sees the
  anisotropic curvatures, which the mean-curvature spheres alone would not. Tangential and
  twist modes are those of the osculating spheres.
* **Mobility**: the normal mode is solved with the exact inverse mass of each grain's contact
  point along d, 1/m' = 1/M + (ℓ × d)·I⁻¹(ℓ × d) (I the full inertia tensor in the box frame),
  so the normal impulse is implicit for the grain as it is; the tangential and twist modes use
  the same m' and the mean principal moment as the sphere's scalar inertia (an approximation:
  the implicit step stays stable as long as the true mobility in a mode is less than twice the
  one assumed).
* **Back to the grain**: the impulse J and the angular impulse L about c act on the grain as J
  and L + ℓ × J about its centre of mass: ΔV = J/M, ΔΩ = I⁻¹ (L + ℓ × J).

Stress (SPEC §3.5): the pair virial uses the step-mean force F = J_A/δt with the centre
difference of the real bodies, r = R_A − R_B (minimum image). The smallest gap and the overlap
count are those of the closest points, so the run's health check sees the true gap.

Symbols: R, V, Ω centre [h], velocity [h τ⁻¹], angular velocity [τ⁻¹]; M mass [m]; I inertia
[m h²]; s gap [h]; J impulse [m h τ⁻¹]; L angular impulse [m h² τ⁻¹].
"""
from __future__ import annotations

import numpy as np
from numba import njit

from suspsim.sph import JIT_OPTIONS
from suspsim.sph.boundaries import minimum_image_3d

from .grain_contacts import (C_A, C_B, CONTACT_WIDTH, GAP, INDEX_A, INDEX_B, RADIUS_A, RADIUS_B,
                             grain_pair_contact)
from .lubrication import curved_squeeze_coefficient_frames, gap_viscosity, sphere_squeeze_law
from .lubrication_implicit import lubrication_pair_impulse_law
from .lubrication_pass import SMALLEST_GAP, clear_pass_records, record_pair

__all__ = ["grain_lubrication_pass", "grain_pair_impulse"]


@njit(**JIT_OPTIONS)
def _inverse_inertia(rot, moments, out):
    """I⁻¹ = Q diag(1/I₁, 1/I₂, 1/I₃) Qᵀ (box frame) into ``out`` (3, 3) [m⁻¹ h⁻²]."""
    for i in range(3):
        for j in range(3):
            out[i, j] = (rot[i, 0] * rot[j, 0] / moments[0] + rot[i, 1] * rot[j, 1] / moments[1]
                         + rot[i, 2] * rot[j, 2] / moments[2])


@njit(**JIT_OPTIONS)
def _lever_mobility(lx, ly, lz, dx, dy, dz, inv_inertia):
    """(ℓ × d)·I⁻¹(ℓ × d) [m⁻¹]."""
    cx, cy, cz = ly * dz - lz * dy, lz * dx - lx * dz, lx * dy - ly * dx
    return (cx * (inv_inertia[0, 0] * cx + inv_inertia[0, 1] * cy + inv_inertia[0, 2] * cz)
            + cy * (inv_inertia[1, 0] * cx + inv_inertia[1, 1] * cy + inv_inertia[1, 2] * cz)
            + cz * (inv_inertia[2, 0] * cx + inv_inertia[2, 1] * cy + inv_inertia[2, 2] * cz))


@njit(**JIT_OPTIONS)
def grain_pair_impulse(contact, r12, v1, v2, w1, w2, mass1, mass2, inv_inertia1, inv_inertia2,
                       scalar1, scalar2, e1a, k1a, k2a, e1b, k1b, k2b, dt, law_code, law_params,
                       cutoff_gap, min_gap, repulsion_strength, friction, rolling_friction,
                       out):
    """Impulses on two grains from their contact record (``contact``,
    :func:`~suspsim.bodies.grain_contacts.grain_pair_contact`; module docstring).

    ``r12`` = R1 − R2 [h] (minimum image); v, w velocities [h τ⁻¹] and angular velocities [τ⁻¹]
    (v2 with its Lees–Edwards image correction); M [m]; I⁻¹ (3, 3) box frame [m⁻¹ h⁻²];
    ``scalar*`` the virtual spheres' scalar moments [m h²]; e1, k1, k2 the first principal
    direction (box frame) and clamped principal curvatures [h⁻¹] at each contact point. Writes
    ``out`` (4, 3): J1, J2 on the grains and their angular impulses about the centres of mass.
    Returns the predicted end-of-step gap [h].
    """
    ra, rb = contact[RADIUS_A], contact[RADIUS_B]
    lax, lay, laz = contact[C_A], contact[C_A + 1], contact[C_A + 2]
    lbx, lby, lbz = contact[C_B], contact[C_B + 1], contact[C_B + 2]
    rv = np.empty(3)
    rv[0] = r12[0] + lax - lbx
    rv[1] = r12[1] + lay - lby
    rv[2] = r12[2] + laz - lbz
    dist = np.sqrt(rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2])
    dx, dy, dz = -rv[0] / dist, -rv[1] / dist, -rv[2] / dist
    u1 = np.empty(3)
    u2 = np.empty(3)
    u1[0] = v1[0] + w1[1] * laz - w1[2] * lay
    u1[1] = v1[1] + w1[2] * lax - w1[0] * laz
    u1[2] = v1[2] + w1[0] * lay - w1[1] * lax
    u2[0] = v2[0] + w2[1] * lbz - w2[2] * lby
    u2[1] = v2[1] + w2[2] * lbx - w2[0] * lbz
    u2[2] = v2[2] + w2[0] * lby - w2[1] * lbx
    m1 = 1.0 / (1.0 / mass1 + _lever_mobility(lax, lay, laz, dx, dy, dz, inv_inertia1))
    m2 = 1.0 / (1.0 / mass2 + _lever_mobility(lbx, lby, lbz, dx, dy, dz, inv_inertia2))
    normal = np.empty(3)
    normal[0], normal[1], normal[2] = dx, dy, dz
    c1 = curved_squeeze_coefficient_frames(k1a, k2a, e1a, k1b, k2b, e1b, normal)
    _, c2, c3, ell = sphere_squeeze_law(ra, rb)
    mu = gap_viscosity(law_code, law_params, ra, rb, rv, u1, u2, w1, w2, min_gap)
    zero = np.zeros(3)
    s_new = lubrication_pair_impulse_law(ra, rb, rv, u1, u2, w1, w2, zero, zero, zero, zero, m1,
                                         m2, scalar1, scalar2, dt, mu, c1, c2, c3, ell,
                                         cutoff_gap, min_gap, repulsion_strength, friction,
                                         rolling_friction, out)
    # angular impulses about the centres of mass: L + ℓ × J
    jx, jy, jz = out[0, 0], out[0, 1], out[0, 2]
    out[2, 0] += lay * jz - laz * jy
    out[2, 1] += laz * jx - lax * jz
    out[2, 2] += lax * jy - lay * jx
    out[3, 0] -= lby * jz - lbz * jy
    out[3, 1] -= lbz * jx - lbx * jz
    out[3, 2] -= lbx * jy - lby * jx
    return s_new


@njit(**JIT_OPTIONS)
def grain_lubrication_pass(centres, rotations, velocities, omegas, mass, moments, box, le_offset,
                           shear_rate, dt, law_code, law_params, cutoff_gap, min_gap,
                           repulsion_strength, friction, rolling_friction, points, normals,
                           first_directions, osculating, principal_curvatures, tables,
                           to_packing, centroids, reach, virial, stats):
    """Apply the impulses of every grain pair whose closest-point gap is below ``cutoff_gap``
    to ``velocities`` and ``omegas`` (B, 3) in place (module docstring).

    ``rotations`` (B, 3, 3) principal → box; ``moments`` (B, 3) principal moments [m h²]; the
    surface arrays those of :class:`~suspsim.bodies.grain_contacts.GrainSurfaces`. ``virial``
    (5,) gets Σ F₁₂ ⊗ (R₁ − R₂) in the layout (xx, yy, zz, xy, yx); ``stats`` (3,) the smallest
    gap, the pairs treated and the predicted overlaps (as
    :func:`~suspsim.bodies.lubrication_pass.lubrication_pass`).
    """
    lx, ly, lz = box[0], box[1], box[2]
    jump = shear_rate * ly
    n = centres.shape[0]
    out = np.zeros((4, 3))
    contact = np.zeros(CONTACT_WIDTH)
    r12 = np.zeros(3)
    u2 = np.zeros(3)
    inv_inertia = np.zeros((n, 3, 3))
    scalar = np.zeros(n)
    # the centroids lie within |centroid| of the centres of mass
    extra = np.zeros(n)
    e1a = np.zeros(3)
    e1b = np.zeros(3)
    for b in range(n):
        _inverse_inertia(rotations[b], moments[b], inv_inertia[b])
        scalar[b] = (moments[b, 0] + moments[b, 1] + moments[b, 2]) / 3.0
        extra[b] = np.sqrt(centroids[b, 0] ** 2 + centroids[b, 1] ** 2 + centroids[b, 2] ** 2)
    clear_pass_records(virial, stats)
    for p in range(n):
        for q in range(p + 1, n):
            dx, dy, dz, image = minimum_image_3d(centres[p, 0] - centres[q, 0],
                                                 centres[p, 1] - centres[q, 1],
                                                 centres[p, 2] - centres[q, 2],
                                                 lx, ly, lz, le_offset)
            far = reach[p] + reach[q] + extra[p] + extra[q] + cutoff_gap
            if dx * dx + dy * dy + dz * dz >= far * far:
                continue
            r12[0], r12[1], r12[2] = dx, dy, dz
            if not grain_pair_contact(p, q, r12, rotations[p], rotations[q], points, normals,
                                      osculating, tables, to_packing, centroids, reach,
                                      cutoff_gap, contact):
                continue
            gap = contact[GAP]
            if gap >= cutoff_gap:
                continue
            stats[SMALLEST_GAP] = min(stats[SMALLEST_GAP], gap)
            u2[0] = velocities[q, 0] + image * jump
            u2[1] = velocities[q, 1]
            u2[2] = velocities[q, 2]
            ka, kb = int(contact[INDEX_A]), int(contact[INDEX_B])
            for i in range(3):
                e1a[i] = (rotations[p, i, 0] * first_directions[p, ka, 0]
                          + rotations[p, i, 1] * first_directions[p, ka, 1]
                          + rotations[p, i, 2] * first_directions[p, ka, 2])
                e1b[i] = (rotations[q, i, 0] * first_directions[q, kb, 0]
                          + rotations[q, i, 1] * first_directions[q, kb, 1]
                          + rotations[q, i, 2] * first_directions[q, kb, 2])
            s_new = grain_pair_impulse(contact, r12, velocities[p], u2, omegas[p], omegas[q],
                                       mass[p], mass[q], inv_inertia[p], inv_inertia[q],
                                       scalar[p], scalar[q], e1a, principal_curvatures[p, ka, 0],
                                       principal_curvatures[p, ka, 1], e1b,
                                       principal_curvatures[q, kb, 0],
                                       principal_curvatures[q, kb, 1], dt, law_code, law_params,
                                       cutoff_gap, min_gap, repulsion_strength, friction,
                                       rolling_friction, out)
            for k in range(3):
                velocities[p, k] += out[0, k] / mass[p]
                velocities[q, k] += out[1, k] / mass[q]
            for k in range(3):
                omegas[p, k] += (inv_inertia[p, k, 0] * out[2, 0] + inv_inertia[p, k, 1] * out[2, 1]
                                 + inv_inertia[p, k, 2] * out[2, 2])
                omegas[q, k] += (inv_inertia[q, k, 0] * out[3, 0] + inv_inertia[q, k, 1] * out[3, 1]
                                 + inv_inertia[q, k, 2] * out[3, 2])
            record_pair(s_new, out, dt, dx, dy, dz, virial, stats)
