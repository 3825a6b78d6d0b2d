"""Random sand grains (frame, volume, elongation, reproducibility) and the size distribution."""
import math

import numpy as np
import pytest

from suspsim.bodies import harmonics as sh
from suspsim.bodies import shapes, sizes
from suspsim.bodies.grains import elongation_and_flatness, random_grain


@pytest.fixture(scope="session")
def grains():
    rng = np.random.default_rng(21)
    return [random_grain(rng) for _ in range(6)]


def test_grain_frame_volume_and_shape(grains):
    for a in grains:
        props = shapes.mass_properties(a)
        assert props.volume == pytest.approx(4 * math.pi / 3, rel=1e-13)
        np.testing.assert_allclose(props.centroid, 0.0, atol=1e-12)
        inertia = np.diag(props.inertia)
        np.testing.assert_allclose(props.inertia, np.diag(inertia), atol=1e-12)
        assert inertia[0] <= inertia[1] <= inertia[2]
        elongation, flatness = elongation_and_flatness(a)
        assert 1.2 - 2e-3 <= elongation <= 1.6 + 2e-3
        assert 1.0 <= flatness <= 2.0
        assert shapes.radius_bounds(a)[0] > 0.3


def test_grain_reproducible_from_seed():
    first = random_grain(np.random.default_rng(5), degree=10)
    again = random_grain(np.random.default_rng(5), degree=10)
    other = random_grain(np.random.default_rng(6), degree=10)
    assert np.array_equal(first, again)
    assert not np.allclose(first, other)
    assert len(first) == sh.coefficient_count(10)


def test_roughness_and_elongation_parameters():
    rng = np.random.default_rng(3)
    smooth = random_grain(rng, roughness=0.0, elongation_range=(1.5, 1.5))
    assert elongation_and_flatness(smooth)[0] == pytest.approx(1.5, abs=2e-3)
    # Without roughness the grain is an ellipsoid: no odd degrees.
    n, _ = sh.coefficient_degree(sh.degree_of(smooth))
    assert np.abs(smooth[n % 2 == 1]).max() < 1e-12
    with pytest.raises(ValueError, match="elongation_range"):
        random_grain(rng, elongation_range=(1.6, 1.2))


def test_size_distribution():
    rng = np.random.default_rng(0)
    radii = sizes.draw_radii(200_000, 2.0, 0.4, 5.0, rng)
    assert radii.max() / radii.min() <= 5.0
    assert radii.mean() == pytest.approx(2.0, rel=0.03)
    assert (radii ** 3).mean() == pytest.approx(sizes.mean_cubed_radius(2.0, 0.4, 5.0), rel=0.01)
    assert np.all(sizes.draw_radii(5, 1.5, 0.0, 5.0, rng) == 1.5)
    assert sizes.body_count(1000.0, 0.5, 1.0, 0.0, 5.0) == round(500 / (4 * math.pi / 3))
    factor = sizes.scale_to_volume_fraction(np.array([1.0, 2.0]), 30.0, 0.4)
    assert factor ** 3 * 3.0 / 30.0 == pytest.approx(0.4, rel=1e-15)
