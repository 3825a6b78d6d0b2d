"""Nematic order and spin ratio of bodies (``analysis.orientation``)."""
import math

import numpy as np
import pytest

from suspsim.analysis.orientation import nematic_order, spin_ratio


def test_parallel_axes_have_order_one_whatever_their_sign():
    axes = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    order, director = nematic_order(axes)
    assert order == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(np.abs(director), [1.0, 0.0, 0.0], atol=1e-12)


def test_isotropic_axes_have_order_near_zero_and_planar_ones_a_quarter():
    rng = np.random.default_rng(3)
    isotropic = rng.normal(size=(20000, 3))
    isotropic /= np.linalg.norm(isotropic, axis=1)[:, None]
    assert abs(nematic_order(isotropic)[0]) < 0.03
    angle = np.linspace(0.0, math.pi, 360, endpoint=False)
    planar = np.column_stack([np.cos(angle), np.sin(angle), np.zeros_like(angle)])
    assert nematic_order(planar)[0] == pytest.approx(0.25, abs=1e-12)


def test_director_follows_a_tilted_alignment():
    tilt = math.radians(20.0)
    axes = np.tile([math.cos(tilt), math.sin(tilt), 0.0], (5, 1))
    order, director = nematic_order(axes)
    assert order == pytest.approx(1.0, abs=1e-12)
    assert abs(director @ axes[0]) == pytest.approx(1.0, abs=1e-12)


def test_spin_ratio_is_one_for_bodies_turning_with_the_vorticity():
    rate = 0.004
    omegas = np.array([[0.0, 0.0, -0.5 * rate], [0.1, 0.0, -0.25 * rate]])
    assert spin_ratio(omegas, rate) == pytest.approx(0.75, rel=1e-12)
