"""Resolved SPH squeeze force between two spheres against Jeffrey & Onishi (SPEC §3.3).

Fast tests check the theory (JO X^A functions against their published limits, the Ewald image
sum against Hasimoto's constant); the slow test runs the prescribed approach at reduced size
(``SUSPSIM_REDUCED=1``: box 20 × 15 × 15 h, Re = 0.1, about a minute on one core) or at the
size of ``docs/figures/make_squeeze.py`` and compares the binned force with theory.
"""
import math

import numpy as np
import pytest

from suspsim.validation.squeeze import (cutoff_gap, hasimoto_factor, periodic_oseen_xx,
                                        periodic_self_coefficient, reduced, squeeze_resistance,
                                        squeeze_study, squeeze_theory, xa_coefficients,
                                        xa_functions)


def test_jeffrey_onishi_coefficients_match_the_tabulated_ones():
    # f_k(λ) of JO Eq. 3.15 at λ = 1: 1, 3λ, 9λ, −4λ + 27λ² − 4λ³, −24λ + 81λ² + 36λ³, ...
    f = xa_coefficients(1.0, 6)
    np.testing.assert_allclose(f, [1, 3, 9, 19, 93, 387, 1197], rtol=1e-12)
    f_half = xa_coefficients(0.5, 4)
    np.testing.assert_allclose(f_half[3], -4 * 0.5 + 27 * 0.25 - 4 * 0.125, rtol=1e-12)


def test_xa_near_contact_matches_the_lubrication_asymptote():
    # Equal spheres: X11A = 1/(4ξ) + (9/40) ln(1/ξ) + 0.9954 + (3/112) ξ ln(1/ξ),
    # X12A = −[1/(4ξ) + (9/40) ln(1/ξ) + (3/112) ξ ln(1/ξ)] − 0.3502 (Kim & Karrila Table 11.?).
    for xi in (1e-3, 3e-3):
        x11, x12 = xa_functions(np.array([2.0 + xi]))
        singular = 0.25 / xi + 0.225 * math.log(1 / xi) + 3 / 112 * xi * math.log(1 / xi)
        assert x11[0] == pytest.approx(singular + 0.9954, abs=2e-3)
        assert x12[0] == pytest.approx(-singular - 0.3502, abs=2e-3)


def test_xa_far_field_matches_the_reflection_series():
    # t = r/a ≫ 2: X11A = Σ f_2k/(2t)^2k, X12A = −Σ f_2k+1/(2t)^2k+1 (JO 3.13-3.14, λ = 1).
    t = 20.0
    x11, x12 = xa_functions(np.array([t]))
    assert x11[0] == pytest.approx(1 + 9 / (4 * t * t) + 93 / (2 * t) ** 4, rel=1e-6)
    assert x12[0] == pytest.approx(-(3 / (2 * t) + 19 / (2 * t) ** 3 + 387 / (2 * t) ** 5),
                                  rel=1e-6)
    # Squeeze: leading lubrication (3/2)πμa²(2U)/s = 6πμaU · a/(2s).
    s = 1e-3
    assert squeeze_resistance(s, 1.0) == pytest.approx(1 / (2 * s), rel=0.01)


def test_ewald_self_term_gives_hasimoto_constant_independent_of_splitting():
    side = 20.0
    assert periodic_self_coefficient([side] * 3) * side == pytest.approx(-2.837297, abs=1e-5)
    a = periodic_oseen_xx([3.0, 1.0, 0.0], [20.0, 15.0, 15.0], splitting=0.15)
    b = periodic_oseen_xx([3.0, 1.0, 0.0], [20.0, 15.0, 15.0], splitting=0.3)
    assert a == pytest.approx(b, rel=1e-7)
    # Cubic box: SPEC §3.1 Hasimoto factor.
    x = 2.5 / side
    assert hasimoto_factor(2.5, [side] * 3) == pytest.approx(
        1 / (1 - 2.837 * x + 4.19 * x ** 3 - 27.4 * x ** 6), rel=1e-3)


def test_image_correction_vanishes_in_a_large_box():
    gap = np.array([0.2, 1.0, 4.0])
    free = squeeze_theory(gap, 2.5, 1.0, 1e-3)
    big = squeeze_theory(gap, 2.5, 1.0, 1e-3, box=[400.0, 400.0, 400.0])
    np.testing.assert_allclose(big / free, 1.0, atol=2e-3)


def test_cutoff_gap_is_the_first_failing_gap_from_above():
    gap = np.array([4.0, 2.0, 1.0, 0.5, 0.2, 0.1])
    ratio = np.array([1.02, 0.98, 0.95, 0.85, 0.92, 0.5])
    assert cutoff_gap(gap, ratio) == 0.5
    assert math.isnan(cutoff_gap(gap, np.ones(6)))


@pytest.mark.slow
def test_resolved_squeeze_force_follows_theory_down_to_the_cutoff():
    """With shifting at the rate U/a (measured, make_squeeze.py, a = 2.5 h, Re = 0.05):
    F_SPH/F_theory(a) 1.00–1.09 for 1 h ≤ s ≤ 2.5 h, 0.94 at 0.78 h, 0.87 at 0.58 h, 0.34 at
    0.1 h; cutoff 0.58 h (0.33 h at Re = 0.025, 0.74 h at a = 4 h); a_h/a = 1.03 from the drag.
    Without shifting the fluid the spheres push through turns disordered and the single-sphere
    drag read 2.3 × Stokes."""
    if reduced():
        box, reynolds, end_gap = (20.0, 15.0, 15.0), 0.1, 0.2
    else:
        box, reynolds, end_gap = (25.0, 20.0, 20.0), 0.05, 0.05
    data = squeeze_study(2.5, box, reynolds=reynolds, end_gap=end_gap, threads=1)
    # The last steps squeeze single fluid particles (density error 0.05 at s = 0.1 h).
    assert np.isfinite(data["force"]).all()
    assert 0.9 < data.attrs["hydrodynamic_radius_ratio"] < 1.25
    gap = data["gap"]
    resolved = data["ratio_nominal"].where((gap >= 1.0) & (gap <= 2.5), drop=True).values
    assert resolved.size >= 3
    np.testing.assert_array_less(np.abs(resolved - 1.0), 0.15)
    # The resolved force must fall short of the lubrication singularity at small gaps.
    near = data["ratio_nominal"].where(gap < 0.3, drop=True).values
    assert near.size >= 1 and near.max() < 0.9
    assert 0.25 < data.attrs["cutoff_gap"] < 1.5
