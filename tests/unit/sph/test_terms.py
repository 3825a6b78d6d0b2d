"""Physics terms as scalar functions: pair antisymmetry, cutoff, weights and continuum values."""
import math

import numpy as np
import pytest

from suspsim.sph.kernels import LUCY_2D, LUCY_3D, kernel_f
from suspsim.sph.terms.force_pass import force_sums, force_width
from suspsim.sph.terms.gradient import corrected_gradient, invert_symmetric, shear_rate
from suspsim.sph.terms.normalisation import (continuum_dissipation, moment_dissipation,
                                             normalisation_factor, pair_dissipation,
                                             quadratic_form, strain_form)
from suspsim.sph.terms.pressure import pressure_pair, pressure_term
from suspsim.sph.terms.viscous import (bulk_factor, explicit_bulk_term, pair_viscosity,
                                       viscous_pair, viscous_weights)


def pair_force(ri, rj, vi, vj, rho_i, rho_j, mu_i, mu_j, dim=3, bulk=True, c2=4.0, h=1.0):
    """Force on i from j: pressure + viscous (as the force pass combines them)."""
    d = np.subtract(ri, rj)
    v = np.subtract(vi, vj)
    r2 = float(d @ d)
    f = kernel_f(LUCY_3D if dim == 3 else LUCY_2D, math.sqrt(r2), h)
    kp = pressure_pair(pressure_term(rho_i, 4.0, c2, 1.0), pressure_term(rho_j, 4.0, c2, 1.0), f)
    alpha, beta = viscous_weights(dim, bulk)
    w = viscous_pair(pair_viscosity(mu_i, mu_j), f / (rho_i * rho_j), *d, r2, *v, alpha, beta)
    return kp * d + np.array(w)


@pytest.mark.parametrize("bulk", [True, False])
def test_pair_force_is_antisymmetric_and_vanishes_beyond_the_support(bulk):
    rng = np.random.default_rng(3)
    for _ in range(20):
        ri, rj, vi, vj = rng.normal(size=(4, 3)) * [[0.4], [0.4], [1.0], [1.0]]
        args = (4.1, 3.9, 0.7, 2.3)
        f_ij = pair_force(ri, rj, vi, vj, *args, bulk=bulk)
        f_ji = pair_force(rj, ri, vj, vi, 3.9, 4.1, 2.3, 0.7, bulk=bulk)
        np.testing.assert_allclose(f_ij, -f_ji, rtol=1e-13, atol=1e-15)
    far = pair_force([0, 0, 0], [1.0, 0, 0], [1, 2, 3], [0, 0, 0], 4.1, 3.9, 1.0, 1.0)
    assert np.all(far == 0.0)
    beyond = pair_force([0, 0, 0], [0.8, 0.7, 0], [1, 2, 3], [0, 0, 0], 4.1, 3.9, 1.0, 1.0)
    assert np.all(beyond == 0.0)


PAIR_SEPARATION = np.array([0.3, 0.2, -0.1])


def _two_particle_force(body_of, viscosity, velocity=((0.1, -0.2, 0.05), (0.0, 0.3, 0.0)),
                        spin=((0.0, 0.0, 0.0),), both_ends=False, gradient=None):
    """Force on particle 0 from particle 1 (r_01 = PAIR_SEPARATION) through ``force_sums``
    (c = 0: viscous only), the bodies' angular velocities ``spin`` (B, 3); with ``both_ends``
    the forces on both particles; with ``gradient`` (2, 9) the pair takes the spin correction
    (``numerics.spin_correction``) from those velocity gradients."""
    d = PAIR_SEPARATION
    f = kernel_f(LUCY_3D, float(np.linalg.norm(d)), 1.0)
    velocity = np.asarray(velocity, dtype=float)
    width = force_width(False, False)
    acc = np.zeros(2 * width)
    correction = gradient is not None
    alpha, beta = viscous_weights(3, True, correction)
    gradient = np.zeros((2, 9)) if gradient is None else np.asarray(gradient, dtype=float)
    force_sums(np.array([0, 1, 1]), np.array([1, 1]), np.array([1]), np.array([[*d, f]]),
               np.array([1, 1]), np.zeros(1, dtype=np.int64), velocity, np.full(2, 4.0),
               np.full(2, 0.25), np.asarray(viscosity, dtype=float), 1.0, 4.0, 0.0, alpha,
               beta, -5.0 / 3.0, False, 0.0, np.asarray(body_of), np.asarray(spin, dtype=float),
               correction, 0.0, gradient, np.zeros(2), np.zeros((2, 3)), acc,
               np.zeros((0, 2 * width)), np.array([0, 2]), np.zeros((1, 5)))
    return acc.reshape(2, width)[:, :3] if both_ends else acc[:3]


def test_a_fluid_body_pair_takes_the_fluid_viscosity_at_both_ends():
    """A body particle's own μ̂ does not enter a fluid–body pair (``force_pass``): the force
    equals that of two fluid particles of the fluid's μ̂, whichever end is the body."""
    fluid_pair = _two_particle_force([-1, -1], [1.5, 1.5])
    np.testing.assert_allclose(_two_particle_force([-1, 0], [1.5, 9.0]), fluid_pair, rtol=1e-14)
    np.testing.assert_allclose(_two_particle_force([0, -1], [9.0, 1.5]), fluid_pair, rtol=1e-14)
    assert not np.allclose(_two_particle_force([-1, -1], [1.5, 9.0]), fluid_pair)


def test_a_fluid_particle_rotating_rigidly_with_a_body_feels_no_viscous_force():
    """``viscous.spin_free_velocity``: v_01 = Ω × r_01 is the body's rigid rotation, which the
    β term of the pair form would resist (the spurious torque that spun a sphere at 1.36 × γ̇/2);
    relative to the body's spin it vanishes, for a body at either end and for two bodies of
    the same spin. A different spin leaves the part of v_01 it does not explain, and the pair
    stays antisymmetric (momentum conserved)."""
    omega = np.array([0.3, -0.7, 1.1])
    body_velocity = np.array([0.2, 0.1, -0.4])
    rigid = [body_velocity + np.cross(omega, PAIR_SEPARATION), body_velocity]
    assert np.linalg.norm(_two_particle_force([-1, -1], [1.0, 1.0], rigid)) > 1e-3
    for body_of in ([-1, 0], [0, -1]):
        np.testing.assert_allclose(_two_particle_force(body_of, [1.0, 1.0], rigid, [omega]), 0.0,
                                   atol=1e-15)
    np.testing.assert_allclose(
        _two_particle_force([0, 1], [1.0, 1.0], rigid, [omega, omega]), 0.0, atol=1e-15)
    half_spin = _two_particle_force([-1, 0], [1.0, 1.0], rigid, [0.5 * omega], both_ends=True)
    relative = [body_velocity + np.cross(0.5 * omega, PAIR_SEPARATION), body_velocity]
    np.testing.assert_allclose(half_spin[0], _two_particle_force([-1, -1], [1.0, 1.0], relative),
                               rtol=1e-12)
    np.testing.assert_allclose(half_spin[0], -half_spin[1], rtol=1e-14)


def test_viscous_weights_combine_a_and_b_as_derived():
    # 3D with B: Español–Revenga weights 5/6, 5/6; 2D with B: pure v_ij; without B: (d + 2, 0)
    assert viscous_weights(3, True) == pytest.approx((5 / 6, 5 / 6))
    assert viscous_weights(2, True) == pytest.approx((0.0, 1.0))
    assert viscous_weights(3, False) == (5.0, 0.0)
    assert bulk_factor(3) == pytest.approx(-5 / 3) and bulk_factor(2) == pytest.approx(-2.0)


def test_pair_viscosity_is_the_sum_for_equal_viscosities():
    assert pair_viscosity(1.5, 1.5) == pytest.approx(3.0)
    assert pair_viscosity(1.0, 1.1) == pytest.approx(2.1, rel=3e-3)


@pytest.mark.parametrize("dim", [2, 3])
def test_continuum_dissipation_of_simple_shear_is_rate_squared_with_b(dim):
    g = np.zeros(9)
    g[3] = 0.7  # ∂_y v_x
    alpha, beta = viscous_weights(dim, True)
    assert continuum_dissipation(g, alpha, beta, dim) == pytest.approx(0.49)


def test_split_dissipation_equals_the_pair_form():
    """α Σ w (r·S r)²/r² + β (L Lᵀ):M2 (what the pass computes) = Σ w pair_dissipation."""
    rng = np.random.default_rng(5)
    g = rng.normal(size=9)
    r = rng.normal(size=(40, 3))
    w = rng.uniform(0.5, 2.0, size=40)
    alpha, beta = 0.7, 1.3
    pair = sum(wk * pair_dissipation(g, *rk, rk @ rk, alpha, beta) for wk, rk in zip(w, r))
    s = np.zeros(6)
    strain_form(g, s)
    quartic = sum(wk * quadratic_form(s, x * x, y * y, z * z, x * y, x * z, y * z) ** 2 / (rk @ rk)
                  for wk, rk in zip(w, r) for x, y, z in [rk])
    m2 = np.einsum("k,ki,kj->ij", w, r, r)
    moment = np.array([m2[0, 0], m2[1, 1], m2[2, 2], m2[0, 1], m2[0, 2], m2[1, 2]])
    assert alpha * quartic + beta * moment_dissipation(g, moment) == pytest.approx(pair, rel=1e-12)


def test_normalisation_factor_falls_back_and_clips():
    assert normalisation_factor(0.8, 1.0, 1.0, 3.0, 3) == pytest.approx(0.8)
    assert normalisation_factor(0.0, 0.0, 0.0, 2.7, 3) == pytest.approx(0.9)
    assert normalisation_factor(100.0, 1.0, 1.0, 3.0, 3) == 4.0


def test_shear_rate_is_exact_in_simple_shear_and_zero_in_rotation():
    g = np.zeros(9)
    g[3] = 2.5
    assert shear_rate(g) == pytest.approx(2.5)
    g[1] = -2.5
    assert shear_rate(g) == pytest.approx(0.0, abs=1e-15)


def test_moment_correction_recovers_the_gradient():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(3, 3))
    m2 = a @ a.T + 3 * np.eye(3)
    grad = rng.normal(size=(3, 3))
    packed = np.array([m2[0, 0], m2[1, 1], m2[2, 2], m2[0, 1], m2[0, 2], m2[1, 2]])
    minv = np.zeros(6)
    invert_symmetric(packed, minv)
    out = np.zeros(9)
    corrected_gradient(minv, (m2 @ grad).ravel(), out)
    np.testing.assert_allclose(out.reshape(3, 3), grad, rtol=1e-12, atol=1e-12)


def test_explicit_bulk_term_vanishes_in_simple_shear_with_gradient_across():
    g = np.zeros(9)
    g[3] = 1.0  # ∂_y v_x, ∇a along y
    assert explicit_bulk_term(0.0, 3.0, 0.0, g, 4.0) == pytest.approx((0.0, 0.0, 0.0))


def _rotation_gradient(omega):
    """g[3k + l] = ∂_k v_l of the rigid rotation v = ω × x."""
    w = np.array([[0.0, -omega[2], omega[1]], [omega[2], 0.0, -omega[0]],
                  [-omega[1], omega[0], 0.0]])  # v = w x, w[l, k] = ∂_k v_l
    return w.T.reshape(9)


def test_spin_correction_removes_the_viscous_force_of_rigid_rotation():
    """With ``numerics.spin_correction`` a fluid pair moving in rigid rotation, v_01 = ω × r_01,
    with the gradients of that rotation feels no viscous force (``viscous.local_spin``);
    without it the β term pulls. A pure strain is felt through β doubled, and the pair stays
    antisymmetric."""
    omega = np.array([0.3, -0.2, 0.5])
    rotating = (np.cross(omega, PAIR_SEPARATION), (0.0, 0.0, 0.0))
    g = np.tile(_rotation_gradient(omega), (2, 1))
    np.testing.assert_allclose(_two_particle_force([-1, -1], [1.0, 1.0], rotating, gradient=g),
                               0.0, atol=1e-15)
    assert np.linalg.norm(_two_particle_force([-1, -1], [1.0, 1.0], rotating)) > 1e-3
    strain = np.array([[0.0, 0.4, 0.0], [0.4, 0.0, 0.1], [0.0, 0.1, -0.2]])
    straining = (strain @ PAIR_SEPARATION, (0.0, 0.0, 0.0))
    both = _two_particle_force([-1, -1], [1.0, 1.0], straining, both_ends=True,
                               gradient=np.tile(strain.T.reshape(9), (2, 1)))
    np.testing.assert_allclose(both[0], -both[1], rtol=1e-14)
    alpha, beta = viscous_weights(3, True)
    r = PAIR_SEPARATION
    u = strain @ r
    plain = alpha * (r @ u) * r / (r @ r) + beta * u
    corrected = alpha * (r @ u) * r / (r @ r) + 2.0 * beta * u
    scale = both[0] / corrected
    np.testing.assert_allclose(scale, scale[0], rtol=1e-12)
    np.testing.assert_allclose(_two_particle_force([-1, -1], [1.0, 1.0], straining),
                               scale[0] * plain, rtol=1e-12)


def test_spin_corrected_fluid_body_pair_takes_the_mean_spin():
    """With ``numerics.spin_correction`` a fluid–body pair takes v relative to the mean of the
    fluid particle's ½ ∇×v and the body's Ω (``viscous.particle_spin``): none if the fluid
    turns rigidly with the body; a fluid particle at rest in a turning body's neighbourhood
    gets half the body's rotation taken out, as a fluid pair of spins Ω and 0 would."""
    omega = np.array([0.3, -0.7, 1.1])
    rigid = (np.cross(omega, PAIR_SEPARATION), (0.0, 0.0, 0.0))
    turning = np.tile(_rotation_gradient(omega), (2, 1))
    for body_of in ([-1, 0], [0, -1]):
        np.testing.assert_allclose(
            _two_particle_force(body_of, [1.0, 1.0], rigid, [omega], gradient=turning), 0.0,
            atol=1e-15)
    still = np.zeros((2, 9))
    half = [turning[0], still[0]]
    fluid_pair = _two_particle_force([-1, -1], [1.0, 1.0], rigid, gradient=half)
    np.testing.assert_allclose(
        _two_particle_force([-1, 0], [1.0, 1.0], rigid, [0.0 * omega], gradient=half),
        fluid_pair, rtol=1e-12)
    np.testing.assert_allclose(
        _two_particle_force([-1, 0], [1.0, 1.0], rigid, [omega], gradient=still),
        fluid_pair, rtol=1e-12)
