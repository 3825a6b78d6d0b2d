"""The implicit pair step of lubrication and repulsion (SPEC §3.3,
``bodies.lubrication_implicit``): no overlap at the fluid's step, the squeeze ODE, backward Euler
of the tangential modes, conservation; and the contact and rolling friction on top of it."""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from suspsim.bodies import lubrication as lub
from suspsim.bodies.lubrication_implicit import implicit_normal_gap, lubrication_pair_impulse
from test_lubrication import pair_r12


# ------------------------------------------------------------------------------------------
# Implicit pair step

A, MU, FORCE, S0, CUTOFF, MIN_GAP = 1.0, 1.0, 1.0, 0.2, 0.5, 1e-3
C_LEAD = 6 * math.pi * (A * A / (2 * A)) ** 2          # 6π a_eff², a_eff = a1a2/(a1+a2)
DT = 0.05                                               # τ_s = μ C_LEAD/F ≈ 4.7 ≈ 94 steps
MASS = 2 * (DT / 100) * MU * C_LEAD / S0                # δt = 100 m_eff s0/(6πμ a_eff²)


def drive_pair(steps, repulsion, implicit=True, s0=S0, cutoff=CUTOFF):
    """Two equal spheres pushed together by ±FORCE along d; returns gaps s_n at t_n = n δt."""
    x1, x2 = np.zeros(3), np.array([0.0, 0.0, 2 * A + s0])
    u1, u2, w1, w2 = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    inertia = 0.4 * MASS * A * A
    out = np.zeros((4, 3))
    gaps = [s0]
    for _ in range(steps):
        d = (x2 - x1) / np.linalg.norm(x2 - x1)
        du1, du2 = DT * FORCE * d / MASS, -DT * FORCE * d / MASS
        if implicit:
            lubrication_pair_impulse(A, A, x1 - x2, u1, u2, w1, w2, du1, du2, np.zeros(3),
                                     np.zeros(3), MASS, MASS, inertia, inertia, DT, MU, cutoff,
                                     MIN_GAP, repulsion, 0.0, 0.0, out)
            u1, u2 = u1 + du1 + out[0] / MASS, u2 + du2 + out[1] / MASS
        else:
            s = lub.lubrication_pair_force(A, A, x1 - x2, u1, u2, w1, w2, MU, cutoff, MIN_GAP, out)
            fr = lub.repulsion_force(s, repulsion, cutoff, MIN_GAP)
            u1 = u1 + du1 + DT * (out[0] - fr * d) / MASS
            u2 = u2 + du2 + DT * (out[1] + fr * d) / MASS
        x1, x2 = x1 + DT * u1, x2 + DT * u2
        gaps.append(np.linalg.norm(x2 - x1) - 2 * A)
    return np.array(gaps)


def test_explicit_step_at_this_time_step_overlaps():
    """Sanity of the set-up: at δt = 100 × the explicit limit an explicit step fails at once."""
    gaps = drive_pair(3, 0.0, implicit=False)
    assert gaps[1] < 0


def test_implicit_approach_never_overlaps_and_settles_smoothly():
    s_eq = 1.2 * MIN_GAP
    c = FORCE / (1 / s_eq**8 - 1 / CUTOFF**8)             # repulsion balances F at s_eq
    gaps = drive_pair(1500, c)
    assert np.all(gaps > 0)
    assert gaps.min() >= s_eq * (1 - 1e-9)                # no overshoot below equilibrium
    assert np.diff(gaps).max() <= 1e-12                   # monotone (round-off at rest)
    assert gaps[-1] == pytest.approx(s_eq, rel=1e-9)


def test_implicit_approach_follows_the_squeeze_ode():
    """At low inertia μ M_n(s) ds/dt = −F, i.e. t(s) = μ (Φ(s0) − Φ(s))/F for the implemented
    (correction-form) law; agreement to 5e-4 of s at δt = 100 × the explicit limit."""
    c1, c2, c3, ell = lub.sphere_squeeze_law(A, A)
    phi = lambda s: lub.normal_potential(c1, c2, c3, ell, s, CUTOFF, MIN_GAP)  # noqa: E731
    gaps = drive_pair(300, 0.0)
    t = DT * np.arange(gaps.size)
    keep = gaps > 2 * MIN_GAP
    assert keep.sum() > 250
    exact = [brentq(lambda s: phi(s) - (phi(S0) - FORCE * tt / MU), MIN_GAP, S0 * 1.000001)
             for tt in t[keep]]
    assert np.abs(gaps[keep] / exact - 1).max() < 5e-4


def test_implicit_leading_order_squeeze_is_exponential():
    """Leading-order law M_n = 6π a_eff²/s: s(t) = s0 exp(−F t/(6πμ a_eff²)) to 5e-4."""
    w = 2 / MASS
    s, x, gaps = S0, 0.0, []
    for _ in range(300):
        s_new, j_lub, j_rep = implicit_normal_gap(s, x - DT * w * FORCE, w, DT, MU, C_LEAD, 0.0,
                                                  0.0, 1.0, math.inf, 1e-12, 0.0)
        assert j_rep == 0.0 and j_lub > 0
        x, s = (s_new - s) / DT, s_new
        gaps.append(s)
    t = DT * np.arange(1, 301)
    assert np.abs(np.array(gaps) / (S0 * np.exp(-FORCE * t / (MU * C_LEAD))) - 1).max() < 5e-4


def test_full_law_decay_rate_tends_to_leading_order():
    """Bare sphere law: per-step decay rate of s over F/(6πμ a_eff²) lies between
    1/(4ξ X11A(ξ)) at the two ends of the step (1 + 0.9 ξ ln(1/ξ) + …), so it → 1 as ξ → 0."""
    gaps = drive_pair(200, 0.0, s0=0.01, cutoff=math.inf)
    rate = np.log(gaps[:-1] / gaps[1:]) / DT * MU * C_LEAD / FORCE
    bound = lambda s: 1 / (4 * (s / A) * lub.x11a_singular(s / A, 1.0))  # noqa: E731
    lower = np.array([bound(s) for s in gaps[:-1]])
    upper = np.array([bound(s) for s in gaps[1:]])
    assert np.all(rate[1:] >= lower[1:] - 1e-3) and np.all(rate[1:] <= upper[1:] + 1e-3)
    assert rate[-1] == pytest.approx(1.0, abs=0.02)
    assert gaps[-1] < 0.2 * gaps[0]


def test_implicit_tangential_modes_equal_dense_backward_euler():
    """With no normal relative motion (and no repulsion) the step is (M + δt μ R) v' = M v*."""
    rng = np.random.default_rng(13)
    a1, a2, s, mu, dt = 1.0, 1.5, 0.01, 0.8, 3.0
    m1, m2 = 0.02, 0.05
    i1, i2 = 0.4 * m1 * a1**2, 0.4 * m2 * a2**2
    r12 = pair_r12(a1, a2, s, rng.normal(size=3))
    d = -r12 / np.linalg.norm(r12)
    u1, u2, w1, w2, du1, du2, dw1, dw2 = rng.normal(size=(8, 3))
    du2 += ((u1 + du1 - u2 - du2) @ d) * d                # zero relative normal velocity
    out = np.zeros((4, 3))
    s_new = lubrication_pair_impulse(a1, a2, r12, u1, u2, w1, w2, du1, du2, dw1, dw2, m1, m2,
                                     i1, i2, dt, mu, 0.3, 1e-4, 0.0, 0.0, 0.0, out)
    assert s_new == pytest.approx(s, rel=1e-12)
    mass = np.diag(np.repeat([m1, m2, i1, i2], 3))
    v_star = np.concatenate([u1 + du1, u2 + du2, w1 + dw1, w2 + dw2])
    r = lub.resistance_matrix(a1, a2, r12, 0.3, 1e-4)
    v_new = np.linalg.solve(mass + dt * mu * r, mass @ v_star)
    assert np.allclose(out.ravel(), mass @ (v_new - v_star), rtol=1e-10,
                       atol=1e-12 * np.abs(out).max())
    assert np.abs(out).max() > 0


def test_implicit_impulses_conserve_momentum_and_dissipate():
    rng = np.random.default_rng(17)
    out = np.zeros((4, 3))
    for dt in (1e-3, 1.0, 1e3):
        a1, a2 = 1.0, 0.7
        m1, m2 = 0.3, 0.1
        i1, i2 = 0.4 * m1 * a1**2, 0.4 * m2 * a2**2
        r12 = pair_r12(a1, a2, 0.02, rng.normal(size=3))
        v = rng.normal(size=(4, 3))
        lubrication_pair_impulse(a1, a2, r12, v[0], v[1], v[2], v[3], *np.zeros((4, 3)), m1, m2,
                                 i1, i2, dt, 1.0, 0.3, 1e-4, 1e-22, 0.0, 0.0, out)
        scale = np.abs(out).max()
        assert scale > 0
        assert np.allclose(out[0], -out[1], rtol=0, atol=1e-14 * scale)
        assert np.abs(out[2] + out[3] + np.cross(r12, out[0])).max() <= 1e-13 * scale * 3
        inv = np.array([1 / m1, 1 / m2, 1 / i1, 1 / i2])[:, None]
        mass = 1 / inv
        ke0 = 0.5 * np.sum(mass * v * v)
        vn = v + out * inv
        assert 0.5 * np.sum(mass * vn * vn) <= ke0 * (1 + 1e-12)


# ------------------------------------------------------------------------------------------
# Contact friction (a [choice] beyond SPEC: Coulomb, at the repulsion's contacts)

def _pressed_pair(rng, s=0.06):
    """Unequal spheres at gap s (inside the repulsion's reach), pushed together, with random
    sliding and spins: (a1, a2, r12, velocities (4, 3), masses, moments, dt, cutoff, min_gap, C)."""
    a1, a2 = 1.0, 0.7
    r12 = pair_r12(a1, a2, s, rng.normal(size=3))
    v = rng.normal(size=(4, 3))
    d = -r12 / np.linalg.norm(r12)
    v[0] += 2.0 * d                                 # 1 moves towards 2
    return a1, a2, r12, v, (0.3, 0.1), (0.4 * 0.3, 0.4 * 0.1 * 0.49), 0.01, 0.3, 0.05, 1e-9


def _impulse(pair, friction, repulsion=None, rolling=0.0):
    a1, a2, r12, v, (m1, m2), (i1, i2), dt, cutoff, min_gap, c = pair
    out = np.zeros((4, 3))
    lubrication_pair_impulse(a1, a2, r12, v[0], v[1], v[2], v[3], *np.zeros((4, 3)), m1, m2, i1,
                             i2, dt, 1.0, cutoff, min_gap, c if repulsion is None else repulsion,
                             friction, rolling, out)
    return out


def _sliding(pair, out):
    """Relative velocity of the contact points after the impulses ``out`` (σ of the mode form)."""
    a1, a2, r12, v, (m1, m2), (i1, i2), *_ = pair
    u1, u2 = v[0] + out[0] / m1, v[1] + out[1] / m2
    w1, w2 = v[2] + out[2] / i1, v[3] + out[3] / i2
    r = np.linalg.norm(r12)
    d = -r12 / r
    u = u1 - u2
    return u - (u @ d) * d + r / (a1 + a2) * np.cross(a1 * w1 + a2 * w2, d)


def _repulsion_impulse(pair):
    a1, a2, r12, v, (m1, m2), _, dt, cutoff, min_gap, c = pair
    d = -r12 / np.linalg.norm(r12)
    s = np.linalg.norm(r12) - a1 - a2
    c1, c2, c3, ell = lub.sphere_squeeze_law(a1, a2)
    return implicit_normal_gap(s, -(v[0] - v[1]) @ d, 1 / m1 + 1 / m2, dt, 1.0, c1, c2, c3, ell,
                               cutoff, min_gap, c)[2]


def test_friction_sticks_within_its_cone_and_slips_at_its_limit():
    """Stick: a large μ_c leaves no sliding at the contact points. Slip: a small μ_c adds a
    tangential impulse of exactly μ_c j_rep against the sliding left by lubrication."""
    rng = np.random.default_rng(41)
    for _ in range(5):
        pair = _pressed_pair(rng)
        j_rep = _repulsion_impulse(pair)
        assert j_rep > 0
        plain = _impulse(pair, 0.0)
        slide = _sliding(pair, plain)
        assert np.linalg.norm(slide) > 1e-3
        stuck = _impulse(pair, 1e6)
        assert np.linalg.norm(_sliding(pair, stuck)) <= 1e-10 * np.linalg.norm(slide)
        # |J_f| = 1e-3 |σ'| is far below the stick impulse |σ'|/W_σσ (W_σσ ≈ 47 here)
        mu_c = 1e-3 * np.linalg.norm(slide) / j_rep
        slip = _impulse(pair, mu_c)
        extra = slip[0] - plain[0]
        d = -pair[2] / np.linalg.norm(pair[2])
        assert abs(extra @ d) <= 1e-12 * np.linalg.norm(extra)
        assert np.linalg.norm(extra) == pytest.approx(mu_c * j_rep, rel=1e-10)
        assert extra @ slide < 0


def _rolling(pair, out):
    """Relative rolling (Ω₁ − Ω₂) × d after the impulses ``out``."""
    a1, a2, r12, v, _, (i1, i2), *_ = pair
    d = -r12 / np.linalg.norm(r12)
    return np.cross(v[2] + out[2] / i1 - v[3] - out[3] / i2, d)


def test_rolling_friction_sticks_and_slips_at_its_torque_limit():
    """Stick: a large μ_r leaves no relative rolling. Slip: a small μ_r adds only an angular
    impulse pair ±d × J_r with |J_r| = μ_r R_eff j_rep, against the rolling left; the linear
    impulses are those of sliding friction alone."""
    rng = np.random.default_rng(47)
    for friction in (0.0, 0.3):
        pair = _pressed_pair(rng)
        a1, a2, r12 = pair[:3]
        d = -r12 / np.linalg.norm(r12)
        r_eff = a1 * a2 / (a1 + a2)
        j_rep = _repulsion_impulse(pair)
        plain = _impulse(pair, friction)
        roll = _rolling(pair, plain)
        assert np.linalg.norm(roll) > 1e-3
        stuck = _impulse(pair, friction, rolling=1e6)
        assert np.linalg.norm(_rolling(pair, stuck)) <= 1e-10 * np.linalg.norm(roll)
        mu_r = 1e-3 * np.linalg.norm(roll) * pair[5][0] / (r_eff * j_rep)
        slip = _impulse(pair, friction, rolling=mu_r)
        assert np.array_equal(slip[:2], plain[:2])
        extra1, extra2 = slip[2] - plain[2], slip[3] - plain[3]
        noise = 1e-13 * np.abs(slip[2:]).max()          # round-off of the differences
        assert np.allclose(extra1, -extra2, rtol=0, atol=noise)
        assert abs(extra1 @ d) <= noise
        j_r = np.cross(extra1, d)                       # d × J_r, J_r ⟂ d
        assert np.linalg.norm(j_r) == pytest.approx(mu_r * r_eff * j_rep, abs=noise)
        assert np.linalg.norm(j_r) > 1e3 * noise
        assert j_r @ roll < 0


@pytest.mark.parametrize("base,added", [
    ((0.0, 0.0), [(0.1, 0.0), (1.0, 0.0), (1e6, 0.0)]),        # sliding friction
    ((0.4, 0.0), [(0.4, 0.05), (0.4, 0.5), (0.4, 1e6)]),       # rolling on top of it
])
def test_friction_conserves_momentum_removes_energy_and_needs_a_contact(base, added):
    """Each friction (μ_c, μ_r) added to ``base`` keeps J₂ = −J₁ and the angular momentum,
    lowers the kinetic energy, and changes nothing where the repulsion does not act."""
    rng = np.random.default_rng(43)
    for friction, rolling in added:
        pair = _pressed_pair(rng)
        a1, a2, r12, v, (m1, m2), (i1, i2), *_ = pair
        before = _impulse(pair, base[0], rolling=base[1])
        out = _impulse(pair, friction, rolling=rolling)
        scale = np.abs(out).max()
        assert np.allclose(out[0], -out[1], rtol=0, atol=1e-14 * scale)
        assert np.abs(out[2] + out[3] + np.cross(r12, out[0])).max() <= 1e-12 * scale
        mass = np.array([m1, m2, i1, i2])[:, None]
        energy = [0.5 * np.sum(mass * (v + o / mass) ** 2) for o in (before, out)]
        assert energy[1] < energy[0]
        assert np.array_equal(_impulse(pair, friction, repulsion=0.0, rolling=rolling),
                              _impulse(pair, 0.0, repulsion=0.0))
