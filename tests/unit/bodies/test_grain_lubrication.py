"""Lubrication between sand grains at their closest points (bodies.grain_contacts,
bodies.grain_lubrication_pass): spheres reproduce the sphere path, the gap and normal agree with
a brute-force search, the squeeze follows SPEC §3.4."""
import math

import numpy as np
import pytest

from suspsim.bodies import harmonics as sh
from suspsim.bodies.grain_contacts import (CONTACT_WIDTH, C_A, C_B, GAP, grain_pair_contact,
                                           grain_surfaces)
from suspsim.bodies.grain_lubrication_pass import grain_lubrication_pass
from suspsim.bodies.grains import random_grain
from suspsim.bodies.lubrication import curved_squeeze_coefficient_frames, sphere_squeeze_law
from suspsim.bodies.lubrication_pass import OVERLAPS, PAIRS, SMALLEST_GAP, lubrication_pass
from suspsim.bodies.overlap import fibonacci_directions
from suspsim.bodies.rotations import random_quaternions, rotation_matrices
from suspsim.bodies.shapes import radius_bounds, sphere_coefficients, surface_geometry
from suspsim.rheology.laws import make_law

BOX = np.array([40.0, 40.0, 40.0])
CUTOFF, MIN_GAP = 0.6, 0.02


def _grain(seed, radius=2.5, **kwargs):
    coefficients = random_grain(np.random.default_rng(seed), **kwargs) * radius
    return coefficients, radius_bounds(coefficients)[1]


def _surfaces(coefficients, radii, support, points=2000):
    count = len(coefficients)
    return grain_surfaces(np.array(coefficients), np.array(radii), np.array(support),
                          np.zeros((count, 3)), np.tile(np.eye(3), (count, 1, 1)), points=points)


def _run_pass(surfaces, centres, rotations, velocities, omegas, mass, moments, strength, law,
              dt=0.05, cutoff=CUTOFF, min_gap=MIN_GAP):
    velocities, omegas = velocities.copy(), omegas.copy()
    virial, stats = np.zeros(5), np.zeros(3)
    sf = surfaces
    grain_lubrication_pass(centres, rotations, velocities, omegas, mass, moments, BOX, 0.0, 0.0,
                           dt, law.code, law.packed, cutoff, min_gap, strength, 0.0, 0.0, sf.points,
                           sf.normals, sf.first_directions, sf.osculating,
                           sf.principal_curvatures, sf.tables, sf.to_packing, sf.centroids,
                           sf.reach, virial, stats)
    return velocities, omegas, virial, stats


def _brute_force(coefficients, support, centres, rotations, points=60000):
    """Signed gap [h] of two bodies (box frame) from dense samples, with the closest points
    (p on body 1, q on body 2) and the outward normal of body 1 there.

    Every sample point x of one body within the other's support sphere is projected radially
    onto the other's exact surface (q = R + r(û) û) and the signed distance (x − q)·n(q) is
    taken, n(q) the exact outward normal there (:func:`surface_geometry`): negative inside, and
    exact to O(s² κ) for a gap s. The smallest over both bodies' samples is the gap. Point
    clouds alone cannot do this: their nearest pair is off by up to the sample spacing."""
    u = fibonacci_directions(points)
    best = (np.inf, None, None, None)
    for i, j in ((0, 1), (1, 0)):
        x = centres[i] + (sh.evaluate(coefficients[i], u)[:, None] * u) @ rotations[i].T
        y = x - centres[j]
        rho = np.linalg.norm(y, axis=1)
        near = rho < support[j]
        if not near.any():
            continue
        x, y, rho = x[near], y[near], rho[near]
        body = (y @ rotations[j]) / rho[:, None]
        radial = rho - sh.evaluate(coefficients[j], body)
        keep = radial < radial.min() + 0.2
        geometry = surface_geometry(coefficients[j], body[keep])
        q = centres[j] + geometry.points @ rotations[j].T
        n = geometry.normals @ rotations[j].T
        signed = np.einsum("ij,ij->i", x[keep] - q, n)
        k = int(np.argmin(signed))
        if signed[k] < best[0]:
            foot = x[keep][k] - signed[k] * n[k]
            best = ((signed[k], x[keep][k], foot, -n[k]) if i == 0
                    else (signed[k], foot, x[keep][k], n[k]))
    return best


def _place(coefficients, support, rotations, direction, gap, points=60000):
    """Centres (2, 3) [h] with body 2 along ``direction`` from body 1 at surface gap ``gap``
    (fixed-point iteration on the signed gap of :func:`_brute_force`)."""
    centres = np.array([[20.0, 20.0, 20.0], [20.0, 20.0, 20.0]])
    distance = support[0] + support[1]
    for _ in range(20):
        centres[1] = centres[0] + distance * direction
        found = _brute_force(coefficients, support, centres, rotations, points)[0]
        if abs(found - gap) < 1e-5:
            break
        # no point of either body within the other's support sphere yet: come closer
        distance -= found - gap if np.isfinite(found) else 0.5
    return centres


def test_two_spheres_through_the_grain_path_reproduce_the_sphere_path():
    radii = np.array([2.5, 1.8])
    coefficients = [sphere_coefficients(r, 0) for r in radii]
    surfaces = _surfaces(coefficients, radii, radii)
    rng = np.random.default_rng(4)
    rotations = rotation_matrices(random_quaternions(2, rng))
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    centres = np.array([[20.0, 20.0, 20.0], [20.0, 20.0, 20.0]])
    centres[1] += (radii.sum() + 0.1) * direction
    velocities = rng.normal(scale=0.1, size=(2, 3))
    omegas = rng.normal(scale=0.05, size=(2, 3))
    mass = np.array([270.0, 100.0])
    moments = np.column_stack([mass * 0.4 * radii ** 2] * 3)
    law = make_law("power_law", {"K": 2.0, "n": 0.6, "gdot_min": 1e-3})
    strength = 1e4 * 2.0 * MIN_GAP ** 8
    got = _run_pass(surfaces, centres, rotations, velocities, omegas, mass, moments, strength, law)
    want_v, want_w = velocities.copy(), omegas.copy()
    virial, stats = np.zeros(5), np.zeros(3)
    lubrication_pass(centres, radii, want_v, want_w, mass, moments[:, 0], BOX, 0.0, 0.0, 0.05,
                     law.code, law.packed, CUTOFF, MIN_GAP, strength, 0.0, 0.0, virial, stats)
    assert stats[PAIRS] == 1 and got[3][PAIRS] == 1
    assert got[3][SMALLEST_GAP] == pytest.approx(stats[SMALLEST_GAP], abs=1e-9)
    # the change of each velocity is the impulse; compare those, to round-off
    np.testing.assert_allclose(got[0] - velocities, want_v - velocities, rtol=1e-8, atol=1e-14)
    np.testing.assert_allclose(got[1] - omegas, want_w - omegas, rtol=1e-8, atol=1e-14)
    np.testing.assert_allclose(got[2], virial, rtol=1e-8, atol=1e-12)


def _elongated_pair(gap):
    """Two copies of a smooth grain with L/W = W/T = 1.6, short axes (z) on the line of centres,
    surfaces ``gap`` apart: the exact gap is D − r(ẑ) − r(−ẑ) (both are the same body)."""
    coefficients, support = _grain(7, roughness=0.0, elongation_range=(1.6, 1.6))
    up, down = sh.evaluate(coefficients, np.array([[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]))
    distance = up + down + gap
    centres = np.array([[20.0, 20.0, 20.0], [20.0, 20.0, 20.0 + distance]])
    return coefficients, support, centres, distance


def test_elongated_grains_side_by_side_have_their_true_gap():
    coefficients, support, centres, distance = _elongated_pair(0.5)
    assert distance < 2 * 2.5  # the volume-equivalent spheres would overlap
    surfaces = _surfaces([coefficients] * 2, [2.5, 2.5], [support] * 2)
    rotations = np.tile(np.eye(3), (2, 1, 1))
    mass = np.full(2, 270.0)
    moments = np.tile([300.0, 500.0, 600.0], (2, 1))
    still = np.zeros((2, 3))
    law = make_law("newtonian", {"mu": 1.0})
    strength = 1e4 * MIN_GAP ** 8
    velocities, omegas, _, stats = _run_pass(surfaces, centres, rotations, still, still, mass,
                                             moments, strength, law)
    # sample spacing √(4π/2000) · 2.5 h = 0.2 h; the gap is right to ~|κ₁ − κ₂| (0.1 h)²/4
    assert stats[SMALLEST_GAP] == pytest.approx(0.5, abs=5e-3)
    assert stats[OVERLAPS] == 0
    # bodies at rest: no lubrication impulse, only the repulsion C (1/s⁸ − 1/s_c⁸) at s = 0.5 h
    # (1e-12 of its cap C/s_min⁸), along the line of centres, no torque
    push = 0.05 * strength * (0.5 ** -8 - CUTOFF ** -8) / mass[0]
    np.testing.assert_allclose(velocities, [[0.0, 0.0, -push], [0.0, 0.0, push]], rtol=0.05,
                               atol=0.01 * push)
    # a torque only from the lever of the sample point's offset from the line (≤ 0.1 h)
    assert np.abs(omegas).max() * moments.min() < 0.1 * push * mass[0]
    sphere_stats = np.zeros(3)
    lubrication_pass(centres, np.full(2, 2.5), still.copy(), still.copy(), mass, moments[:, 0],
                     BOX, 0.0, 0.0, 0.05, law.code, law.packed, CUTOFF, MIN_GAP, strength,
                     0.0, 0.0, np.zeros(5), sphere_stats)
    assert sphere_stats[SMALLEST_GAP] < 0.0  # the defect this replaces


@pytest.mark.parametrize("seed", range(4))
def test_closest_points_agree_with_brute_force(seed):
    rng = np.random.default_rng(100 + seed)
    grains = [_grain(2 * seed + k + 11) for k in range(2)]
    coefficients = [g[0] for g in grains]
    rotations = rotation_matrices(random_quaternions(2, rng))
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    support = [g[1] for g in grains]
    centres = _place(coefficients, support, rotations, direction, rng.uniform(0.05, 0.5))
    gap, p_a, p_b, reference = _brute_force(coefficients, support, centres, rotations)
    surfaces = _surfaces(coefficients, [2.5, 2.5], [g[1] for g in grains])
    contact = np.zeros(CONTACT_WIDTH)
    found = grain_pair_contact(0, 1, centres[0] - centres[1], rotations[0], rotations[1],
                               surfaces.points, surfaces.normals, surfaces.osculating,
                               surfaces.tables, surfaces.to_packing, surfaces.centroids,
                               surfaces.reach, CUTOFF, contact)
    assert found
    # brute force: 60000 points, spacing 0.025 h, so its gap is high by ≲ 1e-4 h
    assert contact[GAP] == pytest.approx(gap, abs=0.01)
    c_a, c_b = centres[0] + contact[C_A:C_A + 3], centres[1] + contact[C_B:C_B + 3]
    normal = (c_b - c_a) / np.linalg.norm(c_b - c_a)
    assert math.degrees(math.acos(min(1.0, normal @ reference))) < 6.0


@pytest.mark.parametrize("seed, target", [(3, 0.02), (5, 0.05)])
def test_squeeze_between_grains_follows_the_curvatures_at_the_closest_points(seed, target):
    """Heavy grains approaching along their contact normal for one short step feel
    F = μ U M_n(s) (SPEC §3.4): M_n = c1/s + c2 ln(ℓ/s) + c3 (s/ℓ) ln(ℓ/s), c1 = 12π/(tr K √det K)
    from the principal curvatures and directions at the brute-force closest points, c2, c3, ℓ
    of the spheres of their mean curvature (Jeffrey–Onishi), s the brute-force gap."""
    rng = np.random.default_rng(seed)
    grains = [_grain(seed + 21 + k) for k in range(2)]
    coefficients = [g[0] for g in grains]
    rotations = rotation_matrices(random_quaternions(2, rng))
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    support = [g[1] for g in grains]
    centres = _place(coefficients, support, rotations, direction, target)
    gap, p_a, p_b, normal = _brute_force(coefficients, support, centres, rotations)
    geometry = [surface_geometry(coefficients[i], rotations[i].T @ (p - centres[i]))
                for i, p in enumerate((p_a, p_b))]
    k = [g.curvatures[0] for g in geometry]
    e1 = [rotations[i] @ g.directions[0, 0] for i, g in enumerate(geometry)]
    c1 = curved_squeeze_coefficient_frames(k[0][0], k[0][1], e1[0], k[1][0], k[1][1], e1[1],
                                           normal)
    _, c2, c3, ell = sphere_squeeze_law(2.0 / k[0].sum(), 2.0 / k[1].sum())
    surfaces = _surfaces(coefficients, [2.5, 2.5], support, points=8000)
    heavy = np.full(2, 1e12)
    moments = np.full((2, 3), 1e12)
    speed, dt, mu = 1e-3, 1e-3, 1.0
    velocities = np.zeros((2, 3))
    velocities[1] = -speed * normal
    law = make_law("newtonian", {"mu": mu})
    new, _, _, stats = _run_pass(surfaces, centres, rotations, velocities, np.zeros((2, 3)),
                                 heavy, moments, 0.0, law, dt=dt, cutoff=math.inf,
                                 min_gap=1e-6)
    force = (new[1] - velocities[1]) @ normal * heavy[1] / dt
    expected = mu * speed * (c1 / gap + (c2 + c3 * gap / ell) * math.log(ell / gap))
    # the sample (8000 points, spacing 0.1 h) finds the gap to ~3e-4 h and curvatures at a
    # point ≤ 0.05 h from the closest point
    assert stats[SMALLEST_GAP] == pytest.approx(gap, abs=1e-3)
    assert force == pytest.approx(expected, rel=0.05)


def _kinetic_energy(velocities, omegas, mass, moments, rotations):
    """Σ ½ M V² + ½ Ωᵀ I Ω, I = Q diag(I₁, I₂, I₃) Qᵀ (box frame)."""
    body = np.einsum("bji,bj->bi", rotations, omegas)
    return 0.5 * float((mass * (velocities ** 2).sum(1)).sum() + (moments * body ** 2).sum())


@pytest.mark.parametrize("seed", range(3))
def test_grain_impulses_conserve_momentum_and_dissipate(seed):
    """Lubrication alone (no repulsion): total momentum and angular momentum about the origin are
    unchanged (J₂ = −J₁, torques L + ℓ × J about each centre of mass), and the kinetic energy
    with the full inertia tensors does not grow; dt large enough to be stiff."""
    rng = np.random.default_rng(200 + seed)
    grains = [_grain(31 + 2 * seed + k) for k in range(2)]
    coefficients = [g[0] for g in grains]
    support = [g[1] for g in grains]
    rotations = rotation_matrices(random_quaternions(2, rng))
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    centres = _place(coefficients, support, rotations, direction, 0.1, points=6000)
    surfaces = _surfaces(coefficients, [2.5, 2.5], support)
    mass = np.full(2, 270.0)
    moments = np.array([[330.0, 560.0, 640.0], [300.0, 520.0, 700.0]])
    velocities = rng.normal(scale=0.1, size=(2, 3))
    omegas = rng.normal(scale=0.05, size=(2, 3))
    law = make_law("newtonian", {"mu": 1.0})
    new_v, new_w, _, stats = _run_pass(surfaces, centres, rotations, velocities, omegas, mass,
                                       moments, 0.0, law, dt=5.0)
    assert stats[PAIRS] == 1

    def momenta(v, w):
        body = np.einsum("bji,bj->bi", rotations, w)
        spin = np.einsum("bij,bj->bi", rotations, moments * body)
        return (mass[:, None] * v).sum(0), (np.cross(centres, mass[:, None] * v) + spin).sum(0)

    before, after = momenta(velocities, omegas), momenta(new_v, new_w)
    np.testing.assert_allclose(after[0], before[0], atol=1e-12 * 270.0)
    np.testing.assert_allclose(after[1], before[1], atol=1e-10 * 270.0 * 20.0)
    energy = _kinetic_energy(velocities, omegas, mass, moments, rotations)
    assert 0.0 < energy - _kinetic_energy(new_v, new_w, mass, moments, rotations) < energy
