"""Sphere lubrication (SPEC §3.3) and curved squeeze (§3.4): tables and structure (the implicit
pair step and contact friction: ``test_lubrication_implicit``)."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from suspsim.bodies import lubrication as lub
from suspsim.rheology import laws

LAMBDAS = [0.2, 0.37, 1.0, 2.5, 5.0]


def pair_r12(a1, a2, s, direction=(0.3, -0.5, 0.8)):
    """r12 = x1 − x2 for a pair at gap s, 2 in the direction ``direction`` from 1."""
    d = np.asarray(direction, float)
    d /= np.linalg.norm(d)
    return -(a1 + a2 + s) * d


def rigid_motions(a1, a2, r12, rng):
    """Random rigid motions of the pair (U1, U2, Ω1, Ω2) stacked as 12-vectors."""
    out = []
    for _ in range(4):
        u = rng.normal(size=3)
        om = rng.normal(size=3)
        x1 = rng.normal(size=3)
        x2 = x1 - r12
        out.append(np.concatenate([u + np.cross(om, x1), u + np.cross(om, x2), om, om]))
    return out


# ------------------------------------------------------------------------------------------
# Scalar functions against the SPEC table

def test_lambda_one_coefficients_match_spec_table():
    assert lub.squeeze_coefficients(1.0) == pytest.approx((1 / 4, 9 / 40, 3 / 112), rel=1e-14)
    assert lub.shear_coefficients(1.0) == pytest.approx((1 / 6, 0.0), rel=1e-14, abs=1e-16)
    assert lub.pump_coefficients(1.0) == pytest.approx((-1 / 4, -1 / 8), rel=1e-14)
    assert lub.roll_coefficients(1.0) == pytest.approx((1 / 5, 47 / 250), rel=1e-14)
    assert lub.roll_cross_coefficients(1.0) == pytest.approx((1 / 20, 31 / 500), rel=1e-14)
    assert lub.twist_coefficient(1.0) == pytest.approx(-1 / 8, rel=1e-14)


@pytest.mark.parametrize("lam", LAMBDAS)
@pytest.mark.parametrize("xi", [1e-4, 3e-3, 0.05])
def test_singular_functions_match_spec_formulas(lam, xi):
    """Each function against the SPEC table retyped here, with the 12 relations."""
    L = math.log(1 / xi)
    q = 1 + lam
    xa = (2 * lam**2 / q**3 / xi + lam * (1 + 7 * lam + lam**2) / (5 * q**3) * L
          + (1 + 18 * lam - 29 * lam**2 + 18 * lam**3 + lam**4) / (42 * q**3) * xi * L)
    ya = (4 * lam * (2 + lam + 2 * lam**2) / (15 * q**3) * L
          + 2 * (16 - 45 * lam + 58 * lam**2 - 45 * lam**3 + 16 * lam**4) / (375 * q**3) * xi * L)
    yb = (-lam * (4 + lam) / (5 * q**2) * L
          - (32 - 33 * lam + 83 * lam**2 + 43 * lam**3) / (250 * q**2) * xi * L)
    yc = 2 * lam / (5 * q) * L + (8 + 6 * lam + 33 * lam**2) / (125 * q) * xi * L
    yc12_8pi = lam**2 / (10 * q) * L + lam * (43 - 24 * lam + 43 * lam**2) / (500 * q) * xi * L
    xc = -lam**2 / (4 * q) * xi * L
    rel = 1e-13
    assert lub.x11a_singular(xi, lam) == pytest.approx(xa, rel=rel)
    assert lub.x12a_singular(xi, lam) == pytest.approx(-2 / q * xa, rel=rel)
    assert lub.y11a_singular(xi, lam) == pytest.approx(ya, rel=rel)
    assert lub.y12a_singular(xi, lam) == pytest.approx(-2 / q * ya, rel=rel)
    assert lub.y11b_singular(xi, lam) == pytest.approx(yb, rel=rel)
    assert lub.y12b_singular(xi, lam) == pytest.approx(-4 / q**2 * yb, rel=rel)
    assert lub.y11c_singular(xi, lam) == pytest.approx(yc, rel=rel)
    # C12 = π(a1+a2)³ Y12C = 8πa1³ (table row)  ⇒  Y12C = 8/(1+λ)³ × table row
    assert lub.y12c_singular(xi, lam) == pytest.approx(8 / q**3 * yc12_8pi, rel=rel)
    assert lub.x11c_singular(xi, lam) == pytest.approx(xc, rel=rel)
    assert lub.x12c_singular(xi, lam) == pytest.approx(-8 / q**3 * xc, rel=rel)


@pytest.mark.parametrize("lam", LAMBDAS)
def test_cross_functions_are_symmetric_under_relabelling(lam):
    """A12 = A21, C12 = C21 (R symmetric) needs X12A, Y12A, Y12C, X12C even in λ → 1/λ."""
    for f in (lub.x12a_singular, lub.y12a_singular, lub.y12c_singular, lub.x12c_singular):
        assert f(0.01, lam) == pytest.approx(f(0.01, 1 / lam), rel=1e-13)


@pytest.mark.parametrize("xi", [1e-5, 1e-3, 1e-2])
def test_equal_sphere_squeeze_leading_order(xi):
    """F = (3/2)πμa²U/s at leading order (seed 000), exactly × 4ξ X11A with the log terms."""
    a, mu, u = 1.3, 0.7, 0.4
    s = xi * a
    out = np.zeros((4, 3))
    r12 = pair_r12(a, a, s)
    d = -r12 / np.linalg.norm(r12)
    lub.lubrication_pair_force(a, a, r12, u * d, np.zeros(3), np.zeros(3), np.zeros(3), mu,
                               math.inf, 0.0, out)
    s = np.linalg.norm(r12) - 2 * a            # the gap the function sees (round-off of r12)
    xi = s / a
    lead = 1.5 * math.pi * mu * a * a * u / s
    f = -out[0] @ d
    assert f / lead == pytest.approx(1 + 0.9 * xi * math.log(1 / xi)
                                     + 3 / 28 * xi * xi * math.log(1 / xi), rel=1e-12)
    assert abs(f / lead - 1) < 1.2 * xi * math.log(1 / xi)
    assert np.allclose(out[0], (out[0] @ d) * d, rtol=0, atol=1e-12 * abs(f))  # along d only


@pytest.mark.parametrize("lam", LAMBDAS)
def test_mode_resistance_log_coefficients(lam):
    """ln(1/ξ) coefficients of the mode form (module docstring): M_σσ = 8πλ(2+λ+2λ²)/(5(1+λ)³) a1,
    M_σρ = 12πλ²(1−λ)/(5(1+λ)³) a1², M_ρρ = 24πλ³/(5(1+λ)³) a1³, the 1/ξ of M_n 12πλ²/(1+λ)³ a1."""
    a1 = 1.7
    a2 = lam * a1
    ell = (a1 + a2) / 2
    xi1, xi2 = 1e-11, 1e-13            # ξL terms < 1e-9 of the log terms
    m1 = np.array(lub.pair_mode_resistances(a1, a2, xi1 * ell, math.inf, 0.0))
    m2 = np.array(lub.pair_mode_resistances(a1, a2, xi2 * ell, math.inf, 0.0))
    q3 = (1 + lam) ** 3
    logs = (m2 - m1)[1:4] / math.log(xi1 / xi2)
    assert logs == pytest.approx([8 * math.pi * lam * (2 + lam + 2 * lam**2) / (5 * q3) * a1,
                                  12 * math.pi * lam**2 * (1 - lam) / (5 * q3) * a1**2,
                                  24 * math.pi * lam**3 / (5 * q3) * a1**3], rel=1e-8, abs=1e-12)
    assert m2[0] * xi2 == pytest.approx(12 * math.pi * lam**2 / q3 * a1, rel=1e-10)


# ------------------------------------------------------------------------------------------
# Structure of the assembled R

@pytest.mark.parametrize("lam", [0.37, 1.0, 2.5])
def test_mode_form_matches_spec_block_form(lam):
    """The hot path's R equals SPEC's block assembly to O(ξ² ln(1/ξ)); the A blocks to
    round-off. Both paths take the gap s = |r12| − a1 − a2, whose rounding error ε|r12| is a
    relative error ε|r12|/s in the 1/ξ terms (2.5e−12 of the largest entry measured at
    λ = 2.5, ξ = 1e−4 on an AVX-only AMD EPYC), so the bound is a few ε|r12|/s."""
    a1, a2 = 1.0, lam
    errors = []
    for xi in (1e-2, 1e-3, 1e-4):
        gap = xi * (a1 + a2) / 2
        r12 = pair_r12(a1, a2, gap)
        r = lub.resistance_matrix(a1, a2, r12)
        j = lub.jeffrey_onishi_matrix(a1, a2, r12)
        err = np.abs(r - j).max()
        assert err <= 10 * xi * xi * math.log(1 / xi) * max(a1, a2) ** 3
        round_off = 8 * np.finfo(float).eps * (a1 + a2 + gap) / gap
        assert np.abs(r - j)[:6, :6].max() <= round_off * np.abs(j).max()
        errors.append(err)
    # O(ξ² ln(1/ξ)): a decade in ξ gains ≈ 100/1.3; the mode form is not merely close at one ξ
    assert errors[1] < errors[0] / 30 and errors[2] < errors[1] / 30


@pytest.mark.parametrize("lam", LAMBDAS)
@pytest.mark.parametrize("cutoff", [math.inf, 0.3])
def test_resistance_matrix_symmetric_and_rigid_null_space(lam, cutoff):
    rng = np.random.default_rng(7)
    a1, a2 = 1.0, lam
    for s in (1e-4, 3e-3, 0.05):
        r12 = pair_r12(a1, a2, s)
        r = lub.resistance_matrix(a1, a2, r12, cutoff, 1e-5)
        scale = np.abs(r).max()
        assert scale > 0
        assert np.abs(r - r.T).max() <= 1e-13 * scale
        for v in rigid_motions(a1, a2, r12, rng):
            assert np.abs(r @ v).max() <= 1e-12 * scale * np.abs(v).max()


@pytest.mark.parametrize("lam", LAMBDAS)
def test_block_form_symmetric_co_translation_exact_rotation_to_order(lam):
    """SPEC's assembly: symmetric, co-translation exactly null, rigid rotation null to O(ξ²L)."""
    rng = np.random.default_rng(3)
    a1, a2 = 1.0, lam
    for xi in (1e-3, 1e-4):
        r12 = pair_r12(a1, a2, xi * (a1 + a2) / 2)
        j = lub.jeffrey_onishi_matrix(a1, a2, r12)
        scale = np.abs(j).max()
        assert np.abs(j - j.T).max() <= 1e-13 * scale
        u = rng.normal(size=3)
        assert np.abs(j @ np.concatenate([u, u, np.zeros(6)])).max() <= 1e-12 * scale
        for v in rigid_motions(a1, a2, r12, rng):
            # residual: the κ = 1 + ξ/2 expansion beyond ξL (measured ≤ 0.6 ξ²L max(a)² |v|)
            bound = 2 * xi * xi * math.log(1 / xi) * max(a1, a2) ** 2 * np.abs(v).max()
            assert np.abs(j @ v).max() <= bound
            assert np.abs(j @ v).max() <= 1e-5 * scale * np.abs(v).max()


@pytest.mark.parametrize("lam", LAMBDAS)
@pytest.mark.parametrize("xi_c", [0.1, 0.5, 1.0])
def test_correction_form_is_positive_semidefinite(lam, xi_c):
    a1, a2 = 1.0, lam
    ell = (a1 + a2) / 2
    cutoff = xi_c * ell
    min_gap = 1e-5 * ell
    for frac in (1e-6, 1e-3, 0.05, 0.3, 0.7, 0.99):
        r12 = pair_r12(a1, a2, frac * cutoff)
        r = lub.resistance_matrix(a1, a2, r12, cutoff, min_gap)
        ev = np.linalg.eigvalsh(0.5 * (r + r.T))
        assert ev.max() > 0
        assert ev.min() >= -1e-12 * ev.max()
        # 6 modes (normal, 2 sliding, 2 rolling, twist) and 6 rigid motions; the twist is
        # clamped to 0 where its correction would be negative (only for ξ_c > 1/e)
        m_t = lub.pair_mode_resistances(a1, a2, np.linalg.norm(r12) - a1 - a2, cutoff, min_gap)[4]
        assert m_t > 0 or xi_c > 1 / math.e
        assert np.sum(ev > 1e-9 * ev.max()) == (6 if m_t > 0 else 5)


def test_bare_singular_part_positive_except_twist():
    """Without the cutoff, R is PSD up to the (negative, non-singular) twist term only."""
    a1, a2 = 1.0, 1.6
    r12 = pair_r12(a1, a2, 1e-3)
    r = lub.resistance_matrix(a1, a2, r12)
    ev = np.linalg.eigvalsh(r)
    _, _, _, _, m_t = lub.pair_mode_resistances(a1, a2, 1e-3, math.inf, 0.0)
    assert m_t < 0
    assert np.sum(ev < -1e-10 * ev.max()) == 1
    # the negative eigenvalue is the twist: M_t |(1, −1)|² along d
    assert ev.min() == pytest.approx(2 * m_t, rel=1e-9)


@pytest.mark.parametrize("cutoff", [math.inf, 0.4])
def test_force_antisymmetry_and_torque_balance(cutoff):
    rng = np.random.default_rng(11)
    out = np.zeros((4, 3))
    for _ in range(5):
        a1, a2 = rng.uniform(0.5, 2.0, 2)
        r12 = pair_r12(a1, a2, rng.uniform(1e-3, 0.3), rng.normal(size=3))
        u1, u2, w1, w2 = rng.normal(size=(4, 3))
        lub.lubrication_pair_force(a1, a2, r12, u1, u2, w1, w2, 1.3, cutoff, 1e-4, out)
        scale = np.abs(out).max()
        assert scale > 0
        assert np.allclose(out[0], -out[1], rtol=0, atol=1e-14 * scale)
        # angular momentum: T1 + T2 + x1 × F1 + x2 × F2 = T1 + T2 + r12 × F1 (any origin)
        assert np.abs(out[2] + out[3] + np.cross(r12, out[0])).max() <= 1e-13 * scale * 3
        # dissipation is non-negative in the correction form
        if math.isfinite(cutoff):
            power = out[0] @ u1 + out[1] @ u2 + out[2] @ w1 + out[3] @ w2
            assert power <= 1e-13 * scale


def test_relabelling_the_pair_swaps_the_forces():
    rng = np.random.default_rng(5)
    a1, a2 = 0.8, 1.9
    r12 = pair_r12(a1, a2, 0.02, rng.normal(size=3))
    u1, u2, w1, w2 = rng.normal(size=(4, 3))
    f, g = np.zeros((4, 3)), np.zeros((4, 3))
    lub.lubrication_pair_force(a1, a2, r12, u1, u2, w1, w2, 1.0, 0.5, 1e-4, f)
    lub.lubrication_pair_force(a2, a1, -r12, u2, u1, w2, w1, 1.0, 0.5, 1e-4, g)
    assert np.allclose(g[[1, 0, 3, 2]], f, rtol=1e-12, atol=1e-13 * np.abs(f).max())


# ------------------------------------------------------------------------------------------
# Correction form, inner cutoff, repulsion, normal potential

def test_correction_zero_beyond_cutoff_and_continuous_at_it():
    a1, a2, cutoff, min_gap = 1.0, 1.4, 0.3, 1e-3
    rng = np.random.default_rng(2)
    u1, u2, w1, w2 = rng.normal(size=(4, 3))
    out = np.zeros((4, 3))
    for s in (cutoff * (1 + 1e-9), cutoff * 1.01, 2.0):    # (1e-9: r12 round-off)
        lub.lubrication_pair_force(a1, a2, pair_r12(a1, a2, s), u1, u2, w1, w2, 1.0, cutoff,
                                   min_gap, out)
        assert np.all(out == 0.0)
    mags = []
    for eps in (1e-3, 1e-4, 1e-5):
        lub.lubrication_pair_force(a1, a2, pair_r12(a1, a2, cutoff * (1 - eps)), u1, u2, w1, w2,
                                   1.0, cutoff, min_gap, out)
        mags.append(np.abs(out).max())
    assert mags[0] > 0
    assert mags[1] < 0.2 * mags[0] and mags[2] < 0.2 * mags[1]   # → 0 linearly in the distance


def test_resistances_held_below_min_gap():
    a1, a2, cutoff, min_gap = 1.0, 0.6, 0.3, 1e-3
    at = lub.pair_mode_resistances(a1, a2, min_gap, cutoff, min_gap)
    for s in (0.5 * min_gap, 1e-9, -0.01):
        assert lub.pair_mode_resistances(a1, a2, s, cutoff, min_gap) == at
    assert lub.pair_mode_resistances(a1, a2, 2 * min_gap, cutoff, min_gap)[0] < at[0]


def test_repulsion_shifted_capped_and_continuous():
    c, cutoff, min_gap = 2e-20, 0.3, 1e-3
    f = lambda s: lub.repulsion_force(s, c, cutoff, min_gap)  # noqa: E731
    assert lub.REPULSION_EXPONENT == 8
    assert f(0.01) == pytest.approx(c / 0.01**8 - c / cutoff**8, rel=1e-14)
    assert f(cutoff) == 0.0 and f(1.0) == 0.0
    assert abs(f(cutoff * (1 - 1e-9))) < 1e-8 * f(0.1)
    assert f(min_gap) == f(0.3 * min_gap) == f(-1.0) == pytest.approx(c / min_gap**8, rel=1e-9)
    assert math.isfinite(f(0.0))
    h = 1e-7
    assert lub.repulsion_slope(0.01, c, cutoff, min_gap) == pytest.approx(
        (f(0.01 + h) - f(0.01 - h)) / (2 * h), rel=1e-6)


@pytest.mark.parametrize("cutoff", [math.inf, 0.3])
def test_normal_potential_is_the_antiderivative_of_the_resistance(cutoff):
    c1, c2, c3, ell = lub.sphere_squeeze_law(1.0, 1.7)
    min_gap = 1e-3
    phi = lambda s: lub.normal_potential(c1, c2, c3, ell, s, cutoff, min_gap)  # noqa: E731
    res = lambda s: lub.normal_resistance(c1, c2, c3, ell, s, cutoff, min_gap)  # noqa: E731
    for s in (-0.002, 3e-4, 2e-3, 0.01, 0.1, 0.25):
        h = 1e-6 * max(abs(s), min_gap)
        assert (phi(s + h) - phi(s - h)) / (2 * h) == pytest.approx(res(s), rel=1e-6)
    for s0 in (min_gap, cutoff):
        if math.isfinite(s0):
            assert phi(s0 * (1 - 1e-12)) == pytest.approx(phi(s0 * (1 + 1e-12)), abs=1e-9)
    if math.isfinite(cutoff):
        assert phi(cutoff) == 0.0 and phi(1.0) == 0.0 and res(1.0) == 0.0
    # the sphere law is the X11A of the table: M_n = 6πa1 X11A
    xi = 0.01 / ell
    assert lub.normal_resistance(c1, c2, c3, ell, 0.01, math.inf, 0.0) == pytest.approx(
        6 * math.pi * lub.x11a_singular(xi, 1.7), rel=1e-13)


# ------------------------------------------------------------------------------------------
# Gap viscosity

def test_gap_viscosity_at_contact_point_shear_rate():
    a1, a2, s = 1.0, 2.0, 0.05
    r12 = np.array([0.0, 0.0, -(a1 + a2 + s)])            # d = +z
    u1 = np.array([1.0, 0.0, 0.0])
    u2 = np.array([0.0, 0.0, -0.5])
    w1 = np.array([0.0, 2.0, 0.0])                         # Ω1 × a1 d = 2 x̂
    w2 = np.array([0.0, 0.0, 5.0])                         # twist: no contact-point velocity
    rate = math.sqrt(3.0**2 + 0.5**2) / s
    assert lub.gap_shear_rate(a1, a2, r12, u1, u2, w1, w2, 1e-3) == pytest.approx(rate, rel=1e-14)
    assert lub.gap_shear_rate(a1, a2, r12, u1, u2, w1, w2, 0.1) == pytest.approx(rate * s / 0.1,
                                                                               rel=1e-14)
    pl = laws.power_law(2.0, 0.5)
    mu = lub.gap_viscosity(pl.code, pl.packed, a1, a2, r12, u1, u2, w1, w2, 1e-3)
    assert mu == pytest.approx(2.0 * rate ** -0.5, rel=1e-13)
    assert mu == pytest.approx(pl.viscosity(rate), rel=1e-14)
    nw = laws.newtonian(0.3)
    assert lub.gap_viscosity(nw.code, nw.packed, a1, a2, r12, u1, u2, w1, w2, 1e-3) == 0.3


# ------------------------------------------------------------------------------------------
# Curved non-spherical squeeze (SPEC §3.4)

@pytest.mark.parametrize("a1,a2", [(1.0, 1.0), (0.5, 2.0), (3.0, 1.2)])
def test_curved_squeeze_recovers_spheres(a1, a2):
    c = lub.curved_squeeze_coefficient(1 / a1, 1 / a1, 1 / a2, 1 / a2, 0.7)
    assert c == pytest.approx(6 * math.pi * (a1 * a2 / (a1 + a2)) ** 2, rel=1e-14)
    assert c == pytest.approx(lub.sphere_squeeze_law(a1, a2)[0], rel=1e-13)  # the 1/ξ term


def test_curvature_determinant_matches_matrix():
    rng = np.random.default_rng(23)
    for _ in range(20):
        k1a, k2a, k1b, k2b = rng.uniform(0.05, 3.0, 4)
        om = rng.uniform(-math.pi, math.pi)
        rot = np.array([[math.cos(om), -math.sin(om)], [math.sin(om), math.cos(om)]])
        k = np.diag([k1a, k2a]) + rot @ np.diag([k1b, k2b]) @ rot.T
        assert lub.curvature_determinant(k1a, k2a, k1b, k2b, om) == pytest.approx(
            np.linalg.det(k), rel=1e-12)
        assert lub.curved_squeeze_coefficient(k1a, k2a, k1b, k2b, om) == pytest.approx(
            12 * math.pi / (np.trace(k) * math.sqrt(np.linalg.det(k))), rel=1e-12)


def test_curved_squeeze_solves_the_reynolds_equation():
    """h = s + xᵀKx/2: p = 3μU/((α+β) h²) satisfies ∇·(h³∇p) = −12μU and ∫p dA = μ c U/s."""
    k1a, k2a, k1b, k2b, om = 1.3, 0.4, 0.9, 0.2, 0.6
    rot = np.array([[math.cos(om), -math.sin(om)], [math.sin(om), math.cos(om)]])
    k = np.diag([k1a, k2a]) + rot @ np.diag([k1b, k2b]) @ rot.T
    s, mu, u = 0.01, 1.7, 0.3
    alpha_beta = 0.5 * np.trace(k)
    def h(x, y):
        return s + 0.5 * (k[0, 0] * x * x + 2 * k[0, 1] * x * y + k[1, 1] * y * y)

    p = lambda x, y: 3 * mu * u / alpha_beta / h(x, y) ** 2  # noqa: E731
    e = 1e-4
    for x, y in [(0.03, -0.05), (0.1, 0.02), (-0.2, 0.15)]:
        flux_x = lambda x, y: h(x, y) ** 3 * (p(x + e, y) - p(x - e, y)) / (2 * e)  # noqa: E731
        flux_y = lambda x, y: h(x, y) ** 3 * (p(x, y + e) - p(x, y - e)) / (2 * e)  # noqa: E731
        div = (flux_x(x + e, y) - flux_x(x - e, y) + flux_y(x, y + e) - flux_y(x, y - e)) / (2 * e)
        assert div == pytest.approx(-12 * mu * u, rel=1e-4)
    force, _ = integrate.dblquad(lambda y, x: p(x, y), -np.inf, np.inf, -np.inf, np.inf,
                                 epsabs=0, epsrel=1e-9)
    c = lub.curved_squeeze_coefficient(k1a, k2a, k1b, k2b, om)
    assert force == pytest.approx(mu * c * u / s, rel=1e-6)


def test_curved_squeeze_from_frames_projects_on_tangent_plane():
    normal = np.array([0.0, 0.0, 2.0])
    om = 0.9
    e1a = np.array([1.0, 0.0, 0.3])
    e1b = np.array([-math.cos(om), -math.sin(om), 0.7])    # sign and normal part are irrelevant
    got = lub.curved_squeeze_coefficient_frames(1.1, 0.3, e1a, 0.8, 0.5, e1b, normal)
    assert got == pytest.approx(lub.curved_squeeze_coefficient(1.1, 0.3, 0.8, 0.5, om), rel=1e-12)
    assert math.isnan(lub.curved_squeeze_coefficient(1.0, -2.0, 0.1, 0.1, 0.0))


def test_check_gap_parameters():
    lub.check_gap_parameters(2.0, 0.5, 1e-3, 1e-20)
    for args in [(2.0, 0.5, 0.0), (2.0, 1e-3, 1e-3), (2.0, 0.5, 1e-3, -1.0), (0.4, 0.5, 1e-3)]:
        with pytest.raises(ValueError):
            lub.check_gap_parameters(*args)
