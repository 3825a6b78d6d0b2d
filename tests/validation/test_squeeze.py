"""Resolved SPH squeeze force between two spheres against Jeffrey & Onishi (SPEC §3.3).

Fast tests check the theory (JO X^A and Y^A functions against their published limits, the Ewald
image sum against Hasimoto's constant); the slow test runs the prescribed approach at reduced size
(``SUSPSIM_REDUCED=1``: box 20 × 15 × 15 h, Re = 0.1, about three minutes on one core) or at the
size of ``docs/figures/make_squeeze.py`` and compares the binned force with theory.
"""
import math

import numpy as np
import pytest

from suspsim.validation.jeffrey_onishi import (squeeze_resistance, xa_coefficients, xa_functions,
                                               ya_coefficients, ya_functions)
from suspsim.validation.periodic_pair import (hasimoto_factor, image_mobility, periodic_oseen,
                                              periodic_oseen_xx, periodic_self_coefficient,
                                              sliding_theory, squeeze_theory)
from suspsim.validation.squeeze import (bin_series, cutoff_gap, gap_edges, lattice_shifts,
                                        lubrication_correction, phase_means, pooled_runs,
                                        reduced, squeeze_study)


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


def test_jeffrey_onishi_sliding_coefficients_match_the_tabulated_ones():
    # f_k(λ) of Y^A (JO §4): 1, 3λ/2, 9λ/4, 2λ + 27λ²/8 + 2λ³, 6λ + 81λ²/16 + 18λ³
    np.testing.assert_allclose(ya_coefficients(1.0, 4), [1, 1.5, 2.25, 7.375, 29.0625],
                               rtol=1e-12)
    lam = 0.5
    f = ya_coefficients(lam, 4)
    assert f[3] == pytest.approx(2 * lam + 27 / 8 * lam ** 2 + 2 * lam ** 3, rel=1e-12)
    assert f[4] == pytest.approx(6 * lam + 81 / 16 * lam ** 2 + 18 * lam ** 3, rel=1e-12)


def test_ya_near_contact_and_far_field_match_the_published_limits():
    # Equal spheres near contact: Y11A = (1/6) ln(1/ξ) + 0.9983, Y12A = −(1/6) ln(1/ξ) − 0.2737
    # (JO 1984 Eqs. 4.15–4.16 with A^Y_11(1), A^Y_12(1); g₃ = 0 at λ = 1).
    for xi in (1e-3, 3e-3):
        y11, y12 = ya_functions(np.array([2.0 + xi]))
        assert y11[0] == pytest.approx(math.log(1 / xi) / 6 + 0.9983, abs=2e-3)
        assert y12[0] == pytest.approx(-math.log(1 / xi) / 6 - 0.2737, abs=2e-3)
    # Far field, t = r/a: Y11A = Σ f_2k/(2t)^2k, Y12A = −Σ f_2k+1/(2t)^2k+1 (as JO 3.13–3.14).
    t = 20.0
    f = ya_coefficients(1.0, 5)
    y11, y12 = ya_functions(np.array([t]))
    assert y11[0] == pytest.approx(1 + f[2] / (2 * t) ** 2 + f[4] / (2 * t) ** 4, rel=1e-6)
    assert y12[0] == pytest.approx(-(f[1] / (2 * t) + f[3] / (2 * t) ** 3 + f[5] / (2 * t) ** 5),
                                  rel=1e-6)


def test_ewald_tensor_is_symmetric_and_independent_of_splitting():
    box = [20.0, 15.0, 15.0]
    a = periodic_oseen([3.0, 1.0, 0.5], box, splitting=0.15)
    b = periodic_oseen([3.0, 1.0, 0.5], box, splitting=0.3)
    np.testing.assert_allclose(a, b, rtol=1e-7, atol=1e-12)
    np.testing.assert_allclose(a, a.T, atol=1e-15)
    # A cube is isotropic at the origin: the self term is c₁/(6π) times I.
    cube = periodic_oseen(np.zeros(3), [20.0] * 3)
    np.testing.assert_allclose(cube, cube[0, 0] * np.eye(3), atol=1e-12)


def test_image_term_turns_with_the_pair():
    box = [20.0, 20.0, 20.0]
    gap = np.array([0.3, 1.5])
    # In a cube a pair along x and one along y see the same images.
    np.testing.assert_allclose(image_mobility(gap, 2.5, box, angle=math.pi / 2),
                               image_mobility(gap, 2.5, box), rtol=1e-9)
    np.testing.assert_allclose(image_mobility(gap, 2.5, box, angle=math.pi / 2, mode="sliding"),
                               image_mobility(gap, 2.5, box, mode="sliding"), rtol=1e-9)
    # Along x, the squeeze term is the xx projection of the image tensor, suppressed by 1 − A.
    r = 2 * 2.5 + gap[1]
    unsuppressed = 6 * math.pi * 2.5 * (periodic_oseen_xx(np.zeros(3), box)
                                        - periodic_oseen_xx([r, 0.0, 0.0], box))
    suppressed = image_mobility(gap[1:], 2.5, box)[0]
    assert 0.0 < suppressed / unsuppressed < 1.0
    sliding_images = sliding_theory(gap, 2.5, 1.0, 1e-3, box=[400.0] * 3)
    np.testing.assert_allclose(sliding_images / sliding_theory(gap, 2.5, 1.0, 1e-3), 1.0,
                               atol=2e-3)


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


def test_lattice_phases_span_one_spacing_and_weigh_alike_in_a_bin():
    np.testing.assert_allclose(lattice_shifts(4), [0.0, 0.15625, 0.3125, 0.46875], rtol=1e-12)
    gap = np.geomspace(2.0, 0.1, 40)
    run = {"gap": np.concatenate([gap, gap]), "force": np.repeat([1.0, 3.0], 40),
           "phase": np.repeat([0, 1], 40)}
    edges = gap_edges(2.5, 0.1, 8)
    rows = phase_means(run, "force", edges)
    filled = np.isfinite(rows[0])
    assert rows.shape == (2, edges.size - 1) and filled.sum() >= 10
    np.testing.assert_array_equal(rows[:, filled], [[1.0] * filled.sum(), [3.0] * filled.sum()])
    pooled = bin_series(run["gap"], run["force"], edges)[1]
    np.testing.assert_array_equal(pooled[filled], 2.0)


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
    F_theory(a) from 0.25 h (0.185 h at Re = 0.025, 0.18 h at a = 4 h); with the lubrication
    correction of the cutoff 0.185 h the total read 0.76–1.28 × F_theory(a) from 0.06 h to
    2.5 h. The scene's auto cutoff is 0.185 h, where the mean over four lattice phases of this
    approach falls short (the phases differ little here; the sliding test says why the mean),
    so here one phase must fall short inside three quarters of it, and at full size its own
    cutoff (0.25 h) lie within 1.5 × of it. Reduced size (box 20 × 15 × 15 h, Re = 0.1):
    a_h/a = 1.067; at 1–2.5 h 0.81–0.90 with a_h and 1.02–1.12 with a; below 0.9 from 0.47 h;
    the total 0.66–1.12. So the resolved force lies between the theories of the two radii, and
    the check takes that band with a 15 % margin; the total's band [0.6, 1.4] is a guard (the
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
    near = data["ratio_nominal"].where(gap < 0.75 * scene_cutoff, drop=True).values
    assert near.size >= 1 and near.max() < 0.9
    if not reduced():
        assert scene_cutoff / 1.5 < data.attrs["cutoff_gap"] < 1.5 * scene_cutoff
    total = data["ratio_combined"].where(gap <= 2.5, drop=True).values
    np.testing.assert_array_less(0.6, total)
    np.testing.assert_array_less(total, 1.4)


@pytest.mark.slow
def test_resolved_sliding_force_meets_theory_beyond_half_a_lattice_spacing():
    """Approach while sliding at equal speeds (``slide_ratio`` 1: a pair at 45° in a shear's
    compressional quadrant), the defaults of a scene with bodies, as the mean over lattice
    phases (``pooled_runs``: the pair shifted along z by fractions of a spacing; a
    suspension's fluid is disordered). One phase alone is not enough: at gaps below half a
    spacing (0.31 h) the force of one run depends on where the spheres meet the start lattice.
    Measured (2026-12-07): full size (box 25 × 20 × 20 h, Re = 0.05, ``make_squeeze.py
    --no-large --slide 1 --phases 4``), the sliding force's phase mean reads 0.68–1.00 ×
    Jeffrey–Onishi's Y^A at 0.06–0.25 h (single phases 0.11–1.44) and 1.09–1.25 × at
    0.33–2.5 h; the squeeze's phase mean falls below 0.9 × F_theory(a) at 0.10 h and below
    (single phases 0.73–1.59 at 0.14–0.25 h). Reduced size (box 20 × 15 × 15 h, Re = 0.1,
    ``--reduced --slide 1 --phases 3``): sliding 0.66–0.92 at 0.12–0.27 h (single phases
    0.46–1.06), 0.99–1.20 at 0.36–2.5 h; squeeze below 0.9 from 0.20 h. The bounds: the
    phase mean of the sliding force
    at least 0.9 × theory from half a spacing out (the brief's 10 %) and at most 1.5 × at
    1–2.5 h; within half a spacing at least half of theory (a guard: below it the SPH fluid
    under-resolves the tangential mode, which the lubrication correction does not make up);
    and the scene's cutoff covers every gap at which the phase mean of the squeeze force falls
    below 0.9 × theory (at full size, where it is calibrated; within 1.5 × at reduced size)."""
    if reduced():
        box, reynolds, end_gap, phases = (20.0, 15.0, 15.0), 0.1, 0.1, 3
    else:
        box, reynolds, end_gap, phases = (25.0, 20.0, 20.0), 0.05, 0.05, 4
    run = pooled_runs(lattice_shifts(phases), radius=2.5, box=box, reynolds=reynolds,
                      end_gap=end_gap, slide_ratio=1.0)
    assert run["healthy"], run["health"]
    edges = gap_edges(2.5, end_gap, 8)
    gap, sliding, _ = bin_series(run["gap"], run["sliding_force"], edges)
    squeeze = bin_series(run["gap"], run["force"], edges)[1]
    angle = bin_series(run["gap"], run["angle"], edges)[1]
    keep = np.isfinite(sliding)
    gap, sliding, squeeze, angle = gap[keep], sliding[keep], squeeze[keep], angle[keep]
    # The line of centres turns by about 0.9 rad as the spheres pass.
    assert 0.5 < angle[0] < 1.2
    ratio = sliding / sliding_theory(gap, 2.5, 1.0, run["speed"], box, angle=angle)
    half_spacing = lattice_shifts(2)[1]
    np.testing.assert_array_less(0.9, ratio[gap >= half_spacing])
    np.testing.assert_array_less(0.5, ratio[gap >= 0.05])
    middle = (gap >= 1.0) & (gap <= 2.5)
    assert middle.sum() >= 3
    np.testing.assert_array_less(ratio[middle], 1.5)
    squeeze_ratio = squeeze / squeeze_theory(gap, 2.5, 1.0, run["speed"], box, angle=angle)
    # The cutoff is calibrated at full size; the reduced box at twice the Reynolds number falls
    # short to about one bin (a factor 1.33) further out, the band the approach test allows.
    cover = 1.5 if reduced() else 1.0
    assert cutoff_gap(gap, squeeze_ratio) <= cover * run["lubrication_cutoff_gap"]
