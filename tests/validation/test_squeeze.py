"""Resolved SPH squeeze force between two spheres against Jeffrey & Onishi (SPEC §3.3).

Fast tests check the theory (JO X^A functions against their published limits, the Ewald image
sum against Hasimoto's constant); the slow test runs the prescribed approach at reduced size
(``SUSPSIM_REDUCED=1``: box 20 × 15 × 15 h, Re = 0.1, about three minutes on one core) or at the
size of ``docs/figures/make_squeeze.py`` and compares the binned force with theory.
"""
import math

import numpy as np
import pytest

from suspsim.validation.squeeze import (cutoff_gap, hasimoto_factor, lubrication_correction,
                                        periodic_oseen_xx, periodic_self_coefficient, reduced,
                                        squeeze_resistance, squeeze_study, squeeze_theory,
                                        xa_coefficients, xa_functions)


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


def test_lubrication_correction_is_the_singular_squeeze_between_min_gap_and_cutoff():
    """6πμa (2U) [X(ξ) − X(ξ_c)] with X = 1/(4ξ) + 9/40 ln(1/ξ) + 3/112 ξ ln(1/ξ) (SPEC §3.3,
    λ = 1), held below s_min and 0 from s_c up."""
    a, mu, speed, s_c, s_min = 2.5, 2.0, 1e-3, 0.185, 0.05

    def singular(s):
        xi = s / a
        return 1 / (4 * xi) + 9 / 40 * math.log(1 / xi) + 3 / 112 * xi * math.log(1 / xi)

    gap = np.array([0.01, 0.05, 0.1, 0.185, 0.3, 2.0])
    force = lubrication_correction(gap, a, mu, speed, s_c, s_min)
    expected = [6 * math.pi * mu * a * 2 * speed * (singular(max(s, s_min)) - singular(s_c))
                if s < s_c else 0.0 for s in gap]
    np.testing.assert_allclose(force, expected, rtol=1e-13, atol=0.0)
    assert force[0] == force[1] > force[2] > 0.0 == force[3]


@pytest.mark.slow
def test_resolved_squeeze_force_follows_theory_down_to_the_cutoff():
    """With the defaults of a scene with bodies (spin correction, A = 30 at the rate U/a).
    Measured (make_squeeze.py, 2026-12-06): a = 2.5 h, Re = 0.05: a_h/a = 1.056 from the drag;
    at 1–2.5 h F_SPH/F_theory 0.96–1.07 with a_h and 1.21–1.28 with the nominal a; below 0.9 ×
    F_theory(a) from 0.25 h (0.185 h at Re = 0.025, 0.18 h at a = 4 h; the scene's auto cutoff
    0.185 h); with the scene's lubrication correction the total reads 0.76–1.28 × F_theory(a)
    from 0.06 h to 2.5 h. Reduced size (box 20 × 15 × 15 h, Re = 0.1): a_h/a = 1.067; at
    1–2.5 h 0.81–0.90 with a_h and 1.02–1.12 with a; below 0.9 from 0.47 h; the total
    0.66–1.12. So the resolved force lies between the theories of the two radii, and the
    check takes that band with a 15 % margin; the total's band [0.6, 1.4] is a guard (the
    resolved force alone reads 0.3 at 0.06 h), not a tight criterion. Without shifting the
    fluid the spheres push through turns disordered and the single-sphere drag read
    2.3 × Stokes."""
    if reduced():
        box, reynolds, end_gap = (20.0, 15.0, 15.0), 0.1, 0.1
    else:
        box, reynolds, end_gap = (25.0, 20.0, 20.0), 0.05, 0.05
    data = squeeze_study(2.5, box, reynolds=reynolds, end_gap=end_gap, threads=1)
    # The last steps squeeze single fluid particles (density error 0.05 at s = 0.1 h).
    assert np.isfinite(data["force"]).all()
    assert 0.9 < data.attrs["hydrodynamic_radius_ratio"] < 1.25
    gap = data["gap"]
    middle = (gap >= 1.0) & (gap <= 2.5)
    nominal = data["ratio_nominal"].where(middle, drop=True).values
    hydrodynamic = data["ratio"].where(middle, drop=True).values
    assert nominal.size >= 3
    np.testing.assert_array_less(0.85, nominal)
    np.testing.assert_array_less(hydrodynamic, 1.15)
    # The resolved force must fall short of the lubrication singularity inside the cutoff.
    scene_cutoff = data.attrs["lubrication_cutoff_gap"]
    near = data["ratio_nominal"].where(gap < scene_cutoff, drop=True).values
    assert near.size >= 1 and near.max() < 0.9
    if not reduced():
        assert scene_cutoff / 1.5 < data.attrs["cutoff_gap"] < 1.5 * scene_cutoff
    total = data["ratio_combined"].where(gap <= 2.5, drop=True).values
    np.testing.assert_array_less(0.6, total)
    np.testing.assert_array_less(total, 1.4)
