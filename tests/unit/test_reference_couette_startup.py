"""Couette start-up reference (seed 000 Fig. 1) against the Newtonian series and its symmetries."""
import numpy as np
import pytest

from suspsim.reference.couette_startup import (bin_means, cell_centres, couette_startup,
                                               newtonian_couette_startup)
from suspsim.rheology.laws import newtonian, papanastasiou

MU, RHO, GAP, V = 2.0, 3.0, 5.0, 1.5
#: Time constant of the slowest Newtonian mode, L²/(4π²ν).
T_SLOW = GAP ** 2 / (4 * np.pi ** 2 * MU / RHO)
TIMES = np.array([0.0, 0.1, 0.3, 1.0, 3.0]) * T_SLOW


def newtonian_error(cells):
    u = couette_startup(newtonian(MU), RHO, GAP, V, TIMES, cells=cells)
    exact = newtonian_couette_startup(MU, RHO, GAP, V, TIMES, cell_centres(GAP, cells))
    return np.abs(u - exact).max(axis=1) / V


def test_series_meets_the_walls_and_the_linear_steady_state():
    y = np.array([0.0, 0.3 * GAP, GAP])
    u = newtonian_couette_startup(MU, RHO, GAP, V, [1e-3 * T_SLOW, 40 * T_SLOW], y)
    np.testing.assert_allclose(u[:, [0, 2]], [[-V / 2, V / 2]] * 2, atol=1e-14)
    np.testing.assert_allclose(u[1], V * (y / GAP - 0.5), atol=1e-14)
    # Early on the middle has not felt the walls yet (diffusion length √(νt) ≪ L).
    assert abs(u[0, 1]) < 1e-12


def test_finite_volumes_match_the_newtonian_series_to_second_order():
    """Measured: 2.8e-5, 9e-6, 3e-6, 8e-7 of V at t/T = 0.1, 0.3, 1, 3 with 480 cells (the
    cell-mean versus centre-value difference is of the same order), ×4 per halving of Δ."""
    assert np.all(newtonian_error(480)[1:] < 5e-5)
    assert newtonian_error(480)[0] == 0.0
    ratio = newtonian_error(120)[1:] / newtonian_error(240)[1:]
    np.testing.assert_allclose(ratio, 4.0, rtol=0.1)


def test_papanastasiou_start_up_is_odd_and_ends_linear():
    """Any generalized-Newtonian steady Couette flow is linear; the flow stays odd about L/2
    (seed 000's law: μ_0/μ_pl = 99, M = 100, here Bn = μ_0/(M μ_pl γ̇) = 3.3)."""
    law = papanastasiou(1.0, 99.0, 100.0)
    u = couette_startup(law, RHO, GAP, V, [0.02, 0.2, 200.0], cells=200)
    np.testing.assert_allclose(u, -u[:, ::-1], atol=1e-12 * V)
    np.testing.assert_allclose(u[-1], V * (cell_centres(GAP, 200) / GAP - 0.5), atol=1e-6 * V)
    # Early (t = 0.02), the thinned layers at the walls follow a Newtonian fluid of the plastic
    # viscosity, while the low-rate middle is as flat as a rigid plug: it spans 7e-4 V where a
    # Newtonian fluid of the zero-rate viscosity 100 would span 0.09 V.
    plastic = couette_startup(newtonian(1.0), RHO, GAP, V, [0.02], cells=200)[0]
    stiff = couette_startup(newtonian(100.0), RHO, GAP, V, [0.02], cells=200)[0]
    assert u[0, 0] == pytest.approx(plastic[0], rel=1e-3)
    middle = slice(60, 100)
    assert np.ptp(u[0, middle]) < 0.02 * np.ptp(stiff[middle])


def test_bin_means_and_argument_checks():
    np.testing.assert_allclose(bin_means(np.arange(12.0).reshape(2, 6), 3),
                               [[0.5, 2.5, 4.5], [6.5, 8.5, 10.5]])
    with pytest.raises(ValueError, match="equal bins"):
        bin_means(np.zeros(10), 3)
    with pytest.raises(ValueError, match="non-decreasing"):
        couette_startup(newtonian(MU), RHO, GAP, V, [1.0, 0.5])
    with pytest.raises(ValueError, match="gap"):
        couette_startup(newtonian(MU), RHO, 0.0, V, [1.0])
