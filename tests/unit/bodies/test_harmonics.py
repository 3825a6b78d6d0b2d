"""Real spherical harmonics: against scipy, orthonormality, synthesis/projection, exact rotation."""
import math

import numpy as np
import pytest
from scipy.special import sph_harm_y

from suspsim.bodies import harmonics as sh


def random_directions(count, seed=0):
    u = np.random.default_rng(seed).normal(size=(count, 3))
    u = u / np.linalg.norm(u, axis=1)[:, None]
    # The poles and a point on the equator, where recurrences and angles are most fragile.
    return np.vstack([u, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]]])


def random_rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def test_basis_is_scipy_real_form_without_condon_shortley_phase():
    degree = 8
    u = random_directions(40)
    theta, phi = np.arccos(np.clip(u[:, 2], -1, 1)), np.arctan2(u[:, 1], u[:, 0])
    for n in range(degree + 1):
        for m in range(-n, n + 1):
            a = np.zeros(sh.coefficient_count(degree))
            a[sh.coefficient_index(n, m)] = 1.0
            y = sph_harm_y(n, abs(m), theta, phi)
            part = y.real if m >= 0 else y.imag
            expected = part if m == 0 else (-1) ** m * math.sqrt(2.0) * part
            np.testing.assert_allclose(sh.evaluate(a, u), expected, atol=1e-13,
                                       err_msg=f"n={n} m={m}")


def test_orthonormal_and_exact_projection():
    degree = 12
    grid = sh.gauss_grid(degree, 2 * degree)
    identity = np.eye(sh.coefficient_count(degree))
    projected = np.stack([sh.project(sh.synthesize(row, grid), grid) for row in identity])
    np.testing.assert_allclose(projected, identity, atol=1e-13)


def test_synthesis_matches_pointwise_evaluation():
    degree = 20
    a = np.random.default_rng(1).normal(size=sh.coefficient_count(degree))
    grid = sh.gauss_grid(degree, 5 * degree + 2)
    np.testing.assert_allclose(sh.synthesize(a, grid), sh.evaluate(a, grid.directions),
                               atol=1e-12)
    assert grid.weights.sum() == pytest.approx(4 * math.pi, rel=1e-14)


def test_coefficient_layout():
    n, m = sh.coefficient_degree(3)
    assert list(zip(n, m))[:5] == [(0, 0), (1, -1), (1, 0), (1, 1), (2, -2)]
    assert all(sh.coefficient_index(a, b) == k for k, (a, b) in enumerate(zip(n, m)))
    assert sh.degree_of(np.zeros(16)) == 3
    with pytest.raises(ValueError):
        sh.degree_of(np.zeros(15))


def test_rotation_is_exact_and_invertible():
    degree = 15
    a = np.random.default_rng(2).normal(size=sh.coefficient_count(degree))
    rotation = random_rotation(3)
    rotated = sh.rotate_coefficients(a, rotation)
    u = random_directions(200, seed=4)
    # A direction u of the old frame is R u in the new one.
    np.testing.assert_allclose(sh.evaluate(rotated, u @ rotation.T), sh.evaluate(a, u),
                               atol=1e-12)
    np.testing.assert_allclose(sh.rotate_coefficients(rotated, rotation.T), a, atol=1e-12)
    # Rotation keeps the power of every degree.
    n, _ = sh.coefficient_degree(degree)
    np.testing.assert_allclose(np.bincount(n, rotated ** 2), np.bincount(n, a ** 2), rtol=1e-12)
