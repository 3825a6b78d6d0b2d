"""Steady local-model DST channel (SPEC §5.7) against its check values and limits."""
import numpy as np
import pytest

from suspsim.reference.dst_channel import (dst_channel_fraction, dst_channel_mean_velocity,
                                           dst_channel_profile)
from suspsim.rheology.wyart_cates import WyartCates

SEED = WyartCates(eta_s=1e-3, phi=0.54, phi_m=0.562, phi_0=0.693, sigma_star=0.005, beta=2.0)
GAP = 0.01


@pytest.mark.parametrize("ratio, mean", [(1, 3.08e-4), (6, 1.58e-4), (10, 1.75e-4),
                                         (100, 1.28e-3)])
def test_spec_check_values(ratio, mean):
    force = ratio * SEED.sigma_star / (GAP / 2)       # F H / σ* = ratio
    assert dst_channel_mean_velocity(SEED, force, GAP) == pytest.approx(mean, rel=2e-3)


def test_profile_matches_mean_symmetry_and_wall_rate():
    force = 10 * SEED.sigma_star / (GAP / 2)
    y = np.linspace(0.0, GAP, 801)
    u = dst_channel_profile(SEED, force, GAP, y)
    assert u[0] == 0.0 and u[-1] == 0.0
    np.testing.assert_allclose(u, u[::-1], rtol=1e-12, atol=1e-18)
    mean = np.trapezoid(u, y) / GAP
    assert mean == pytest.approx(dst_channel_mean_velocity(SEED, force, GAP), rel=1e-4)
    dy = 1e-7
    slope = dst_channel_profile(SEED, force, GAP, dy) / dy
    assert slope == pytest.approx(float(SEED.shear_rate(force * GAP / 2)), rel=1e-4)
    f = dst_channel_fraction(SEED, force, GAP, np.array([0.0, GAP / 2]))
    assert f[0] == pytest.approx(np.exp(-(1 / 10) ** 2)) and f[1] == 0.0


def test_nearly_newtonian_limit_is_poiseuille():
    law = WyartCates(eta_s=1.0, phi=1e-9, phi_m=0.562, phi_0=0.693, sigma_star=1.0)
    force, gap = 3.0, 2.0
    y = np.array([0.25, 0.5, 1.0])
    np.testing.assert_allclose(dst_channel_profile(law, force, gap, y),
                               force / 2 * y * (gap - y), rtol=1e-8)
    assert dst_channel_mean_velocity(law, force, gap) == pytest.approx(
        force * (gap / 2) ** 2 / 3, rel=1e-8)


def test_rejects_bad_input():
    with pytest.raises(ValueError):
        dst_channel_mean_velocity(SEED, -1.0, GAP)
    with pytest.raises(ValueError):
        dst_channel_profile(SEED, 1.0, GAP, [GAP * 1.5])
