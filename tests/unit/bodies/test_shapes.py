"""Star-shaped bodies: sphere limit, ellipsoid against analytic and numerical values,
Gauss–Bonnet and the divergence theorem on random grains (curvatures and normals everywhere,
the polar frame included)."""
import math

import numpy as np
import pytest

from suspsim.bodies import harmonics as sh
from suspsim.bodies import shapes
from suspsim.bodies.grains import random_grain

AXES = np.array([1.3, 1.0, 0.8])


def directions_with_poles(count=300, seed=0):
    u = np.random.default_rng(seed).normal(size=(count, 3))
    u = u / np.linalg.norm(u, axis=1)[:, None]
    return np.vstack([u, np.eye(3), -np.eye(3)])


@pytest.fixture(scope="session")
def ellipsoid():
    """Degree-30 projection of the ellipsoid with semi-axes AXES (truncation error ~1e-8)."""
    grid = sh.gauss_grid(30, 100)
    return sh.project(1.0 / np.sqrt(((grid.directions / AXES) ** 2).sum(-1)), grid)


@pytest.fixture(scope="session")
def grain():
    return random_grain(np.random.default_rng(11), roughness=0.05)


def test_pure_y00_is_a_sphere():
    radius = 2.5
    a = shapes.sphere_coefficients(radius, degree=6)
    props = shapes.mass_properties(a)
    volume = 4 * math.pi / 3 * radius ** 3
    assert props.volume == pytest.approx(volume, rel=1e-14)
    np.testing.assert_allclose(props.centroid, 0.0, atol=1e-14)
    np.testing.assert_allclose(props.inertia, 0.4 * volume * radius ** 2 * np.eye(3), rtol=1e-13,
                               atol=1e-12)
    u = directions_with_poles()
    geometry = shapes.surface_geometry(a, u)
    np.testing.assert_allclose(geometry.curvatures, 1.0 / radius, rtol=1e-13)
    np.testing.assert_allclose(geometry.normals, u, atol=1e-13)
    np.testing.assert_allclose(geometry.points, radius * u, atol=1e-13)
    low, high = shapes.radius_bounds(a)
    assert low <= radius <= high and high - low < 1e-12
    points = np.array([[0.0, 0.0, 0.0], [2.49, 0, 0], [0, 0, -2.51], [1.5, 1.5, 1.5]])
    assert shapes.contains(a, points).tolist() == [True, True, False, False]
    assert shapes.contains(a, points, margin=0.02).tolist() == [True, True, True, False]


def test_ellipsoid_volume_against_numerical_integration(ellipsoid):
    props = shapes.mass_properties(ellipsoid)

    # A different rule from the code's (Gauss in cos θ): Gauss–Legendre in θ itself times the
    # trapezoidal rule in φ, both exponentially convergent here.
    nodes, weights = np.polynomial.legendre.leggauss(160)
    theta, w_theta = 0.5 * math.pi * (nodes + 1), 0.5 * math.pi * weights
    phi = 2 * math.pi * np.arange(320) / 320
    t, p = np.meshgrid(theta, phi, indexing="ij")
    u = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    r = sh.evaluate(ellipsoid, u)
    numerical = (r ** 3 / 3 * np.sin(t) * w_theta[:, None]).sum() * 2 * math.pi / 320
    assert props.volume == pytest.approx(numerical, rel=1e-12)
    assert props.volume == pytest.approx(4 * math.pi / 3 * AXES.prod(), rel=1e-7)
    b2 = AXES ** 2
    expected = props.volume / 5 * np.array([b2[1] + b2[2], b2[0] + b2[2], b2[0] + b2[1]])
    np.testing.assert_allclose(props.inertia, np.diag(expected), rtol=1e-7, atol=1e-9)
    # Voxel count with the point-in-body test (independent of the quadrature).
    side = 64
    nodes = (np.arange(side) + 0.5) / side * 2 * AXES.max() - AXES.max()
    grid = np.stack(np.meshgrid(nodes, nodes, nodes, indexing="ij"), -1).reshape(-1, 3)
    inside = shapes.contains(ellipsoid, grid).sum() * (2 * AXES.max() / side) ** 3
    assert inside == pytest.approx(props.volume, rel=1e-2)


def test_ellipsoid_curvatures_against_analytic(ellipsoid):
    a, b, c = AXES
    tips = shapes.surface_geometry(ellipsoid, np.eye(3))
    np.testing.assert_allclose(tips.curvatures, [[a / c ** 2, a / b ** 2], [b / c ** 2, b / a ** 2],
                                                 [c / b ** 2, c / a ** 2]], rtol=1e-6)
    # At the x tip the direction of the largest curvature 1/R = a/c² is z.
    assert abs(tips.directions[0, 0, 2]) == pytest.approx(1.0, abs=1e-9)
    geometry = shapes.surface_geometry(ellipsoid, directions_with_poles(500))
    p = geometry.points
    gauss = 1.0 / (AXES.prod() ** 2 * ((p ** 2 / AXES ** 4).sum(1)) ** 2)
    np.testing.assert_allclose(geometry.curvatures.prod(1), gauss, rtol=1e-6)
    normal = p / AXES ** 2
    np.testing.assert_allclose(geometry.normals, normal / np.linalg.norm(normal, axis=1)[:, None],
                               atol=1e-7)


def test_gauss_bonnet_and_divergence_theorem_on_a_rough_grain(grain):
    grid = sh.gauss_grid(20, 160)
    u = grid.directions.reshape(-1, 3)
    geometry = shapes.surface_geometry(grain, u)
    r = np.linalg.norm(geometry.points, axis=1)
    # Surface element per solid angle of a star-shaped surface: r² / (n·u).
    area = r ** 2 / (geometry.normals * u).sum(1) * grid.weights.ravel()
    assert (geometry.curvatures.prod(1) * area).sum() == pytest.approx(4 * math.pi, rel=1e-9)
    np.testing.assert_allclose((geometry.normals * area[:, None]).sum(0), 0.0, atol=1e-10)
    flux = ((geometry.points * geometry.normals).sum(1) * area).sum() / 3
    assert flux == pytest.approx(shapes.volume(grain), rel=1e-10)
    t1, t2 = geometry.directions[:, 0], geometry.directions[:, 1]
    np.testing.assert_allclose((t1 * geometry.normals).sum(1), 0.0, atol=1e-12)
    np.testing.assert_allclose((t1 * t2).sum(1), 0.0, atol=1e-12)
    assert np.all(geometry.curvatures[:, 0] >= geometry.curvatures[:, 1])


def test_radius_bounds_bracket_the_radius(grain):
    low, high = shapes.radius_bounds(grain)
    u = directions_with_poles(20000, seed=5)
    r = sh.evaluate(grain, u)
    assert low <= r.min() and r.max() <= high
    assert high - r.max() < 0.02 and r.min() - low < 0.02
    points = shapes.surface_points(grain, u)
    assert not shapes.contains(grain, points * 1.001).any()
    assert shapes.contains(grain, points * 0.999).all()
