"""Bodies made of SPH particles (SPEC §3.1): lattice counts, shell and core, mass and
inertia against the analytic sphere and disc, a sand grain, packing and principal frames, and
clearing the fluid lattice across periodic faces against brute force."""
import math

import numpy as np
import pytest

from suspsim.bodies import shapes
from suspsim.bodies.construction import (BALL_DIRECTIONS, build_body_particles,
                                         fluid_outside_bodies)
from suspsim.bodies.grains import random_grain
from suspsim.bodies.overlap import fibonacci_directions
from suspsim.bodies.packing import Packing
from suspsim.bodies.rigid import principal_orientations
from suspsim.bodies.rotations import random_quaternions, rotation_matrices

N3 = 4.096            # ℓ = 0.625 h: a sphere of radius 2.5 h is 4 spacings across its radius
SPACING = N3 ** (-1.0 / 3.0)


def packing(centres, radii, coefficients=None, box=(20.0, 20.0, 20.0), orientations=None):
    """A Packing of given bodies (no relaxation: these tests place bodies by hand)."""
    centres = np.atleast_2d(np.asarray(centres, dtype=float))
    count = len(centres)
    radii = np.broadcast_to(np.asarray(radii, dtype=float), (count,)).copy()
    if orientations is None:
        orientations = np.tile([1.0, 0.0, 0.0, 0.0], (count, 1))
    if coefficients is None:
        support, volumes = radii, 4.0 / 3.0 * math.pi * radii ** 3
    else:
        support = np.array([shapes.radius_bounds(a)[1] for a in coefficients])
        volumes = np.array([shapes.volume(a) for a in coefficients])
    return Packing("sphere" if coefficients is None else "sand", np.asarray(box, dtype=float),
                   centres, np.asarray(orientations, dtype=float), radii, volumes, coefficients,
                   support, 0, 0.0, 1.0, 0.0)


def lattice(reach, spacing, dimension=3):
    """All lattice points ℓ k within the cube |x_a| ≤ reach (+1 spacing)."""
    k = int(math.ceil(reach / spacing)) + 1
    axis = np.arange(-k, k + 1) * spacing
    axes = [axis] * dimension + [np.zeros(1)] * (3 - dimension)
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)


@pytest.fixture(scope="session")
def sphere():
    return build_body_particles(packing([5.0, 5.0, 5.0], 2.5), N3)


@pytest.fixture(scope="session")
def grain_packing():
    coefficients = random_grain(np.random.default_rng(7)) * 3.0
    q = random_quaternions(1, np.random.default_rng(1))
    return packing([5.0, 5.0, 5.0], 3.0, coefficients[None], orientations=q)


@pytest.fixture(scope="session")
def grain(grain_packing):
    return build_body_particles(grain_packing, N3)


# --- sphere ------------------------------------------------------------------------------------

def test_sphere_particle_count(sphere):
    """N_full ≈ n (4/3)π a³. The difference is the lattice-counting error, a surface effect:
    rigorously the union of the N voxels (cubes of side ℓ) lies between the balls of radius
    a ∓ √3ℓ/2; in practice it is −6.4 % at a/ℓ = 4 (tolerance 8 %) and shrinks with a/ℓ
    (−0.5 % at a/ℓ = 16, tolerance 1.5 %)."""
    a = 2.5
    count = int(sphere.particle_count_full[0])
    points = lattice(a, SPACING)
    assert count == int((np.linalg.norm(points, axis=1) < a).sum()) == 251
    s = math.sqrt(3.0) / 2.0 * SPACING
    assert 4 / 3 * math.pi * (a - s) ** 3 * N3 <= count <= 4 / 3 * math.pi * (a + s) ** 3 * N3
    assert count / (N3 * 4 / 3 * math.pi * a ** 3) == pytest.approx(1.0, abs=0.08)
    big = build_body_particles(packing([0.0, 0.0, 0.0], 10.0, box=(40.0,) * 3), N3)
    assert big.particle_count_full[0] / (N3 * 4 / 3 * math.pi * 1e3) == pytest.approx(1.0,
                                                                                     abs=0.015)


def test_sphere_shell_is_within_support_of_the_surface(sphere):
    a, h = 2.5, 1.0
    rho = np.linalg.norm(sphere.offsets, axis=1)
    assert np.all(rho < a) and np.all(rho > a - h)
    points = np.linalg.norm(lattice(a, SPACING), axis=1)
    assert sphere.particle_count_shell[0] == ((points < a) & (points > a - h)).sum() == 194
    assert sphere.first.tolist() == [0, 194]
    assert np.all(sphere.body_index == 0)


def test_sphere_mass_and_inertia(sphere):
    """M = N_full m; the voxel-body inertia is isotropic (cube symmetry, exactly) and within
    the counting error of 2/5 M a² (−2.3 % at a/ℓ = 4, tolerance 3 %; −0.2 % at a/ℓ = 16)."""
    m, a = sphere.mass[0], 2.5
    assert m == sphere.particle_count_full[0] * 1.0
    np.testing.assert_allclose(sphere.inertia[0], sphere.inertia[0, 0, 0] * np.eye(3),
                               atol=1e-12 * m)
    np.testing.assert_array_equal(sphere.body_to_principal[0], np.eye(3))
    np.testing.assert_allclose(sphere.principal_moments[0], 0.4 * m * a * a, rtol=0.03)
    np.testing.assert_array_equal(sphere.centre_shift, 0.0)
    heavy = build_body_particles(packing([5.0, 5.0, 5.0], a), N3, particle_mass=2.0)
    np.testing.assert_allclose(heavy.principal_moments, 2.0 * sphere.principal_moments,
                               rtol=1e-14)
    big = build_body_particles(packing([0.0, 0.0, 0.0], 10.0, box=(40.0,) * 3), N3)
    np.testing.assert_allclose(big.principal_moments[0], 0.4 * big.mass[0] * 100.0, rtol=0.005)


# --- discs (2D) --------------------------------------------------------------------------------

def test_disc():
    """Square lattice at n₂ = 4.096^(2/3) (same ℓ); N ≈ nπa² (−10 % at a/ℓ = 4: the counting
    error is larger in 2D, tolerance 12 %) and I_zz ≈ ½ M a² (−9 %, tolerance 12 %)."""
    a, n2 = 2.5, N3 ** (2.0 / 3.0)
    bp = build_body_particles(packing([5.0, 5.0, 0.0], a), n2, dimension=2)
    assert bp.spacing == pytest.approx(SPACING, rel=1e-14)
    np.testing.assert_array_equal(bp.offsets[:, 2], 0.0)
    points = lattice(a, SPACING, dimension=2)
    full = points[np.linalg.norm(points, axis=1) < a]
    assert bp.particle_count_full[0] == len(full)
    assert len(full) / (n2 * math.pi * a * a) == pytest.approx(1.0, abs=0.12)
    assert bp.principal_moments[0, 2] == pytest.approx(0.5 * bp.mass[0] * a * a, rel=0.12)
    with pytest.raises(ValueError, match="discs"):
        build_body_particles(packing([5.0, 5.0, 5.0], 1.0, random_grain(
            np.random.default_rng(0))[None]), n2, dimension=2)


# --- sand grain --------------------------------------------------------------------------------

def full_grain_lattice(grain_packing):
    a = grain_packing.coefficients[0]
    points = lattice(grain_packing.support_radii[0], SPACING)
    return points[shapes.contains(a, points)]


def test_grain_builds_with_com_centred_offsets(grain, grain_packing):
    full = full_grain_lattice(grain_packing)
    assert grain.particle_count_full[0] == len(full)
    volume = grain_packing.volumes[0]
    assert len(full) / (N3 * volume) == pytest.approx(1.0, abs=0.08)
    np.testing.assert_allclose(grain.centre_shift[0], full.mean(axis=0), atol=1e-14)
    np.testing.assert_allclose((full - grain.centre_shift[0]).mean(axis=0), 0.0, atol=1e-12)
    assert np.linalg.norm(grain.centre_shift[0]) < 0.1 * SPACING
    assert 0 < grain.particle_count_shell[0] < grain.particle_count_full[0]


def test_grain_shell_and_core(grain, grain_packing):
    """Shell particles are inside and within h of the surface; every dropped core particle has
    its whole ball B(x, h) inside the grain (dense exact check, 2000 directions)."""
    a = grain_packing.coefficients[0]
    h = 1.0
    full = full_grain_lattice(grain_packing)
    shell = grain.offsets + grain.centre_shift[0]
    assert np.all(shapes.contains(a, shell))
    is_shell = (np.abs(full[:, None] - shell[None]).sum(-1) < 1e-9).any(1)
    core = full[~is_shell]
    u = fibonacci_directions(2000)
    assert np.all(shapes.contains(a, (core[:, None] + h * u[None]).reshape(-1, 3)))
    # A shell particle is within h of the outside: some point of its sphere of radius h (slightly
    # enlarged, the ball test's direction spacing) is outside.
    u = fibonacci_directions(BALL_DIRECTIONS * 4)
    out = ~shapes.contains(a, (shell[:, None] + 1.05 * h * u[None]).reshape(-1, 3))
    assert np.all(out.reshape(len(shell), -1).any(1))
    # The radial test alone (r − |x| < h) would drop some of these (the reason for the ball test).
    rho = np.linalg.norm(shell, axis=1)
    radial_depth = np.linalg.norm(shapes.surface_points(a, shell / rho[:, None]), axis=1) - rho
    assert np.any(radial_depth >= h)


def test_grain_mass_properties(grain, grain_packing):
    """Voxel-lattice inertia within 5 % of the exact n m J (surface effect) and diagonalised
    by body_to_principal (rows the principal axes, det +1, I_1 ≤ I_2 ≤ I_3)."""
    exact = shapes.mass_properties(grain_packing.coefficients[0]).inertia * N3
    np.testing.assert_allclose(grain.inertia[0], exact, atol=0.05 * np.trace(exact) / 3)
    p = grain.body_to_principal[0]
    np.testing.assert_allclose(p @ p.T, np.eye(3), atol=1e-13)
    assert np.linalg.det(p) == pytest.approx(1.0, abs=1e-13)
    np.testing.assert_allclose(p @ grain.inertia[0] @ p.T, np.diag(grain.principal_moments[0]),
                               atol=1e-10 * np.trace(exact))
    assert np.all(np.diff(grain.principal_moments[0]) >= 0.0)
    np.testing.assert_allclose(grain.principal_offsets, grain.offsets @ p.T, atol=1e-14)


# --- moving with the body ----------------------------------------------------------------------

def test_principal_frame_places_the_same_particles():
    """Packing quaternions with packing-frame offsets and principal quaternions with principal
    offsets put every particle at the same place, inside its grain."""
    rng = np.random.default_rng(3)
    coefficients = np.stack([random_grain(rng) * s for s in (2.0, 2.5, 3.0)])
    q = random_quaternions(3, rng)
    pk = packing(rng.uniform(0.0, 20.0, (3, 3)), [2.0, 2.5, 3.0], coefficients, orientations=q)
    bp = build_body_particles(pk, N3)
    centres = bp.centres_of_mass(pk.centres, q)
    rot = rotation_matrices(q)
    x = centres[bp.body_index] + np.einsum("mij,mj->mi", rot[bp.body_index], bp.offsets)
    for b in range(3):
        part = slice(bp.first[b], bp.first[b + 1])
        assert np.all(bp.body_index[part] == b)
        body_frame = (x[part] - pk.centres[b]) @ rot[b]
        assert np.all(shapes.contains(coefficients[b], body_frame, margin=1e-9))
    rot_p = rotation_matrices(principal_orientations(q, bp.body_to_principal))
    xp = centres[bp.body_index] + np.einsum("mij,mj->mi", rot_p[bp.body_index],
                                            bp.principal_offsets)
    np.testing.assert_allclose(xp, x, atol=1e-12)


# --- clearing the fluid ------------------------------------------------------------------------

def brute_force_outside(points, pk, margin, dimension=3):
    """Every body against every point through all 27 periodic images (no minimum image)."""
    keep = np.ones(len(points), dtype=bool)
    rot = rotation_matrices(pk.orientations)
    images = np.stack(np.meshgrid(*[[-1, 0, 1]] * 3, indexing="ij"), -1).reshape(-1, 3)
    if dimension == 2:
        images = images[images[:, 2] == 0]
    for b in range(pk.count):
        for image in images:
            d = points - pk.centres[b] + image * pk.box
            if dimension == 2:
                d[:, 2] = 0.0
            if pk.coefficients is None:
                inside = np.linalg.norm(d, axis=1) < pk.radii[b] + margin
            else:
                inside = shapes.contains(pk.coefficients[b], d @ rot[b], margin)
            keep &= ~inside
    return keep


@pytest.mark.parametrize("margin", [0.0, 0.3])
def test_fluid_outside_spheres_across_faces(margin):
    box = (12.0, 11.0, 10.0)
    centres = [[0.3, 5.0, 5.0], [11.8, 10.7, 0.2], [6.0, 0.0, 9.9], [6.0, 5.5, 5.0]]
    pk = packing(centres, [2.0, 2.5, 1.5, 1.0], box=box)
    points = np.random.default_rng(0).uniform(0.0, 1.0, (20000, 3)) * box
    keep = fluid_outside_bodies(points, pk, margin=margin)
    expected = brute_force_outside(points, pk, margin)
    np.testing.assert_array_equal(keep, expected)
    assert 0.5 < keep.mean() < 0.95


def test_fluid_outside_grains_across_faces():
    rng = np.random.default_rng(5)
    box = (12.0, 12.0, 12.0)
    coefficients = np.stack([random_grain(rng) * s for s in (2.0, 2.5, 1.5)])
    centres = [[0.2, 6.0, 11.9], [11.5, 0.4, 0.3], [6.0, 6.0, 6.0]]
    pk = packing(centres, [2.0, 2.5, 1.5], coefficients, box=box,
                 orientations=random_quaternions(3, rng))
    points = rng.uniform(0.0, 1.0, (20000, 3)) * box
    keep = fluid_outside_bodies(points, pk, margin=0.2)
    np.testing.assert_array_equal(keep, brute_force_outside(points, pk, 0.2))
    assert 0.7 < keep.mean() < 0.97


def test_fluid_outside_discs():
    box = (10.0, 10.0, 1.0)
    pk = packing([[0.5, 9.0, 0.0], [5.0, 5.0, 0.0]], [2.0, 1.5], box=box)
    points = np.zeros((5000, 3))
    points[:, :2] = np.random.default_rng(1).uniform(0.0, 10.0, (5000, 2))
    keep = fluid_outside_bodies(points, pk, margin=0.1, dimension=2)
    np.testing.assert_array_equal(keep, brute_force_outside(points, pk, 0.1, dimension=2))


def test_fluid_outside_rejects_bodies_larger_than_half_the_box():
    pk = packing([[1.0, 1.0, 1.0]], [3.0], box=(5.0, 5.0, 5.0))
    with pytest.raises(ValueError, match="half the box"):
        fluid_outside_bodies(np.zeros((1, 3)), pk)
