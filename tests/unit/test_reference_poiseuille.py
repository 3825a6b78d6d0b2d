"""Plane Poiseuille references (SPEC §6.2, §2.7) against closed forms, ODE solutions and limits."""
import time

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from suspsim.reference.poiseuille import (bingham_number, force_density_for_bingham,
                                          poiseuille_flow_rate, poiseuille_profile,
                                          split_force_poiseuille_profile)
from suspsim.reference.shear import inverse_stress
from suspsim.rheology.laws import (carreau_yasuda, cross, herschel_bulkley, newtonian,
                                   papanastasiou, power_law, three_component)

RTOL = 1e-12  # the quadrature's default error target, relative to the centre-line velocity


def ideal_herschel_bulkley(tau_y, K, n, F, W, y):
    """Exact plane Poiseuille flow of the ideal HB fluid (τ_y = 0: power law; n = 1: Bingham).

    With h = W/2, y_c = |y − h| and plug half-width y_p = τ_y/F, integrating
    du/dy_c = −((F y_c − τ_y)/K)^(1/n) from u(h) = 0 gives, for y_c ≥ y_p,
    u = (n/(n+1)) (F/K)^(1/n) [(h − y_p)^((n+1)/n) − (y_c − y_p)^((n+1)/n)], constant in the plug.
    """
    h, y_p = W / 2, tau_y / F
    y_c = np.abs(np.asarray(y) - h)
    p = (n + 1) / n
    return n / (n + 1) * (F / K) ** (1 / n) * ((h - y_p) ** p - (np.maximum(y_c, y_p) - y_p) ** p)


@pytest.mark.parametrize("F, W, mu", [(2.0, 1.0, 0.5), (-3e4, 1e-3, 1e-3), (7.0, 40.0, 3.0)])
def test_newtonian_profile_and_flux_are_the_parabola(F, W, mu):
    y = np.linspace(0.0, W, 201)
    u = poiseuille_profile(newtonian(mu), F, W, y)
    assert np.allclose(u, F * y * (W - y) / (2 * mu), rtol=1e-10, atol=0)
    assert u[0] == 0.0 and u[-1] == 0.0
    assert poiseuille_flow_rate(newtonian(mu), F, W) == pytest.approx(F * W ** 3 / (12 * mu), rel=1e-10)


@pytest.mark.parametrize("n", [0.2, 0.5, 1.0, 1.5, 2.0])
def test_power_law_profile_and_flux_match_closed_form(n):
    K, F, W = 0.8, 3.0, 2.0
    law = power_law(K, n, gdot_min=0.0)
    y = np.linspace(0.0, W, 201)
    u_max = n / (n + 1) * (F / K) ** (1 / n) * (W / 2) ** ((n + 1) / n)
    exact = u_max * (1 - np.abs(1 - 2 * y / W) ** ((n + 1) / n))
    assert np.allclose(exact, ideal_herschel_bulkley(0.0, K, n, F, W, y), rtol=1e-14, atol=0)
    assert np.allclose(poiseuille_profile(law, F, W, y), exact, rtol=1e-8, atol=0)
    # Q = 2 ∫_0^h u dy = 2 h u_max (n+1)/(2n+1).
    flux = W * u_max * (n + 1) / (2 * n + 1)
    assert poiseuille_flow_rate(law, F, W) == pytest.approx(flux, rel=1e-8)


@pytest.mark.parametrize("bingham", [0.0, 1.0, 10.0])
def test_regularised_bingham_approaches_the_plug_solution_as_one_over_M(bingham):
    """u_M − u_ideal is largest in the plug and equals (1/F) ∫_0^{σ_w} (γ̇_M − γ̇_ideal) dσ, the
    area between the two flow curves: ∫ τ_y e^(−Mγ̇) dγ̇ = τ_y/M up to e^(−Mγ̇_w), i.e. y_p/M."""
    mu_pl, tau_y, W = 0.7, 0.3, 1.0
    y = np.linspace(0.0, W, 401)
    if bingham == 0.0:
        F = 2.0
        law = papanastasiou(mu_pl, 0.0, 1e3)
        assert bingham_number(law, F, W) == 0.0
        assert np.allclose(poiseuille_profile(law, F, W, y), F * y * (W - y) / (2 * mu_pl),
                           rtol=1e-10, atol=0)
        return
    F = force_density_for_bingham(papanastasiou(mu_pl, tau_y, 1.0), W, bingham)
    exact = ideal_herschel_bulkley(tau_y, mu_pl, 1.0, F, W, y)
    y_p, U = tau_y / F, exact.max()
    assert bingham_number(papanastasiou(mu_pl, tau_y, 1.0), F, W) == pytest.approx(bingham, rel=1e-13)
    assert bingham == pytest.approx(tau_y * (W / 2) / (mu_pl * U), rel=1e-13)
    errors = []
    for m_rate in (1e2, 1e3):  # M times the characteristic rate U/(W/2)
        M = m_rate * W / (2 * U)
        error = np.abs(poiseuille_profile(papanastasiou(mu_pl, tau_y * M, M), F, W, y) - exact)
        assert np.argmax(error) == 200  # the centre line, inside the plug
        assert error.max() * M / y_p == pytest.approx(1.0, rel=10 * RTOL * U * M / y_p)
        errors.append(error.max())
    assert errors[0] / errors[1] == pytest.approx(10.0, rel=1e-8)


@pytest.mark.parametrize("n", [0.5, 1.5])
@pytest.mark.parametrize("bingham", [1.0, 10.0])
def test_regularised_herschel_bulkley_approaches_the_exact_solution(n, bingham):
    tau_y, K, W = 0.3, 0.7, 1.0
    y = np.linspace(0.0, W, 401)
    F = force_density_for_bingham(herschel_bulkley(tau_y, K, n, 1.0), W, bingham)
    exact = ideal_herschel_bulkley(tau_y, K, n, F, W, y)
    y_p, U = tau_y / F, exact.max()
    assert bingham == pytest.approx(tau_y / (K * (U / (W / 2)) ** n), rel=1e-12)
    errors = []
    for m_rate in (1e2, 1e3):
        M = m_rate * W / (2 * U)
        law = herschel_bulkley(tau_y, K, n, M, gdot_min=0.0)
        error = np.abs(poiseuille_profile(law, F, W, y) - exact)
        # Same area argument as for Bingham: the laws differ by τ_y e^(−Mγ̇) at equal γ̇.
        assert error.max() * M / y_p == pytest.approx(1.0, rel=10 * RTOL * U * M / y_p)
        errors.append(error.max())
    assert errors[0] / errors[1] == pytest.approx(10.0, rel=1e-8)


def test_wall_stress_barely_above_yield_warns_and_stays_within_the_round_off_floor():
    """σ_w = τ_y (1 + 1e-6): the rate is known only to ε σ dγ̇/dσ ≈ 1e-10 of itself, so rtol = 1e-12
    is out of reach. Exact: U = (σ_w − τ_y)²/(2 μ_pl F) + τ_y/(F M) (the 1/M area term above)."""
    M, W = 1e12, 2.0
    law = papanastasiou(1.0, 1.0 * M, M)  # μ_pl = 1 Pa s, τ_y = 1 Pa
    F = 1.0 + 1e-6  # σ_w = F W/2 = F; σ_w − τ_y is exact in floating point
    with pytest.warns(RuntimeWarning, match="round-off"):
        u = poiseuille_profile(law, F, W, W / 2)
    assert u == pytest.approx((F - 1.0) ** 2 / (2 * F) + 1.0 / (F * M), rel=1e-9)


def test_bingham_number_definition_and_inverse():
    W = 2.0
    for bingham in (1e-3, 0.3, 1.0, 10.0, 1e4):
        # n = 1: Bn (1 − ξ)² = 2ξ, so ξ = (Bn + 1 − sqrt(2 Bn + 1))/Bn.
        xi = (bingham + 1 - np.sqrt(2 * bingham + 1)) / bingham
        law = papanastasiou(1.3, 0.4 * 50.0, 50.0)
        F = force_density_for_bingham(law, W, bingham)
        assert 0.4 / (F * W / 2) == pytest.approx(xi, rel=1e-12)
        for n in (0.3, 1.0, 2.0):
            hb = herschel_bulkley(0.4, 1.3, n, 50.0)
            assert bingham_number(hb, force_density_for_bingham(hb, W, bingham), W) == \
                pytest.approx(bingham, rel=1e-12)
    law = papanastasiou(1.0, 5.0, 10.0)  # τ_y = 0.5 Pa
    assert bingham_number(law, 0.5, W) == np.inf  # σ_w = τ_y: the ideal plug fills the channel
    assert bingham_number(newtonian(1.0), 3.0, W) == 0.0
    assert bingham_number(power_law(1.0, 0.5), 3.0, W) == 0.0
    with pytest.raises(ValueError, match="papanastasiou and herschel_bulkley"):
        bingham_number(three_component(1.0, 1.0, 1.0, 10.0), 3.0, W)
    for bad in (0.0, -1.0, np.inf):
        with pytest.raises(ValueError, match="Bingham number"):
            force_density_for_bingham(law, W, bad)
    with pytest.raises(ValueError, match="yield stress"):
        force_density_for_bingham(papanastasiou(1.0, 0.0, 10.0), W, 1.0)


def ode_centre_velocity_and_flux(law, F, W):
    """Brute force: du/dy = γ̇(F (W/2 − y)), dq/dy = u from the wall; Q = 2 q(W/2)."""
    def rhs(y, state):
        return [inverse_stress(law, F * (W / 2 - y)), state[0]]
    sol = solve_ivp(rhs, (0.0, W / 2), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-16)
    return sol.y[0, -1], 2 * sol.y[1, -1]


@pytest.mark.parametrize("law", [carreau_yasuda(10.0, 0.01, 2.0, 2.0, 0.3),
                                 carreau_yasuda(1.0, 0.0, 50.0, 0.7, 0.5),
                                 cross(10.0, 0.01, 2.0, 0.8),
                                 three_component(0.3, 0.5, 0.1, 30.0)], ids=lambda law: law.name)
def test_profile_and_flux_match_brute_force_ode_integration(law):
    F, W = 2.0, 1.0
    u_centre, flux = ode_centre_velocity_and_flux(law, F, W)
    assert poiseuille_profile(law, F, W, W / 2) == pytest.approx(u_centre, rel=1e-9)
    assert poiseuille_flow_rate(law, F, W) == pytest.approx(flux, rel=1e-9)


def test_carreau_yasuda_flux_self_converges_at_simpsons_order():
    """Composite Simpson on Q = (2/F²) ∫ σ γ̇ dσ (smooth for a = 2) converges to the adaptive value
    at fourth order: the two agree in the limit."""
    law, F, W = carreau_yasuda(10.0, 0.01, 2.0, 2.0, 0.3), 2.0, 1.0
    reference = poiseuille_flow_rate(law, F, W)
    errors = []
    for intervals in (16, 32, 64, 128):
        sigma = np.linspace(0.0, F * W / 2, intervals + 1)
        f = sigma * inverse_stress(law, sigma)
        simpson = (sigma[1] - sigma[0]) / 3 * (f[0] + f[-1] + 4 * f[1:-1:2].sum() + 2 * f[2:-1:2].sum())
        errors.append(abs(2 * simpson / F ** 2 - reference))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 3.8) & (orders < 4.2)), orders


def test_adaptive_refinement_meets_rtol_near_a_rate_singularity():
    """Cross with m = 1, μ_inf = 0: τ = μ_0 γ̇/(1 + λγ̇), so γ̇ = σ/(μ_0 − λσ), which nearly blows
    up at the wall when σ_w = 0.998 μ_0/λ. Closed forms: ∫ γ̇ dσ = −σ/λ − (μ_0/λ²) ln(μ_0 − λσ),
    Q = (2/F²) [−σ_w²/(2λ) − μ_0 σ_w/λ² − (μ_0²/λ³) ln(1 − λσ_w/μ_0)]."""
    mu_0, lam, W = 10.0, 2.0, 1.0
    law, F = cross(mu_0, 0.0, lam, 1.0), 9.98
    y = np.linspace(0.0, W, 101)
    s_w, s = F * W / 2, F * np.abs(W / 2 - y)
    u_exact = (-(s_w - s) / lam
               - mu_0 / lam ** 2 * (np.log1p(-lam * s_w / mu_0) - np.log1p(-lam * s / mu_0))) / F
    q_exact = 2 / F ** 2 * (-s_w ** 2 / (2 * lam) - mu_0 * s_w / lam ** 2
                            - mu_0 ** 2 / lam ** 3 * np.log1p(-lam * s_w / mu_0))
    errors = []
    for rtol in (1e-4, 1e-6, 1e-8, 1e-12):
        u = poiseuille_profile(law, F, W, y, rtol=rtol)
        q = poiseuille_flow_rate(law, F, W, rtol=rtol)
        errors.append(max(np.abs(u - u_exact).max() / u_exact.max(), abs(q / q_exact - 1)))
        assert errors[-1] < rtol
    assert errors == sorted(errors, reverse=True)


SPLIT_LAWS = [newtonian(0.5), power_law(1.0, 0.5), cross(10.0, 0.01, 2.0, 0.8),
              papanastasiou(1.0, 0.2 * 1e3, 1e3), herschel_bulkley(0.2, 1.0, 0.6, 1e3),
              three_component(0.2, 0.5, 0.1, 1e3)]


@pytest.mark.parametrize("law", SPLIT_LAWS, ids=lambda law: law.name)
def test_split_force_profile_is_antisymmetric_with_poiseuille_halves(law):
    g, L = 1.5, 2.0
    y = np.linspace(0.0, L, 201)[:-1]
    u = split_force_poiseuille_profile(law, g, L, y)
    assert u[0] == 0.0 and u[100] == 0.0  # y = 0 ≡ L_y and y = L_y/2
    assert np.allclose(split_force_poiseuille_profile(law, g, L, L - y[1:]), -u[1:], rtol=1e-12, atol=0)
    assert np.allclose(u[:101], poiseuille_profile(law, g, L / 2, y[:101]), rtol=1e-14, atol=0)
    assert np.all(u[1:100] > 0) and np.all(u[101:] < 0)
    assert np.allclose(split_force_poiseuille_profile(law, g, L, y + 3 * L), u, rtol=1e-12, atol=1e-15)


def test_sign_zero_force_and_bad_arguments():
    law, W = cross(10.0, 0.01, 2.0, 0.8), 1.0
    y = np.linspace(0.0, W, 11)
    assert np.array_equal(poiseuille_profile(law, -2.0, W, y), -poiseuille_profile(law, 2.0, W, y))
    assert poiseuille_flow_rate(law, -2.0, W) == -poiseuille_flow_rate(law, 2.0, W)
    assert np.array_equal(poiseuille_profile(law, 0.0, W, y), np.zeros(11))
    assert poiseuille_flow_rate(law, 0.0, W) == 0.0
    assert isinstance(poiseuille_profile(law, 2.0, W, 0.5), float)
    with pytest.raises(ValueError, match="heights"):
        poiseuille_profile(law, 2.0, W, [0.5, 1.5])
    with pytest.raises(ValueError, match="width"):
        poiseuille_profile(law, 2.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="force density"):
        poiseuille_flow_rate(law, np.nan, W)
    with pytest.raises(ValueError, match="supremum"):  # the flow curve is bounded by μ_0/λ = 5 Pa
        poiseuille_flow_rate(cross(10.0, 0.0, 2.0, 1.0), 12.0, W)


@pytest.mark.parametrize("law", SPLIT_LAWS + [carreau_yasuda(10.0, 0.01, 2.0, 2.0, 0.3)],
                         ids=lambda law: law.name)
def test_a_200_point_profile_is_fast(law):
    y = np.linspace(0.0, 1.0, 200)
    poiseuille_profile(law, 2.0, 1.0, y)  # compile the law's kernels first
    start = time.perf_counter()
    poiseuille_profile(law, 2.0, 1.0, y)
    assert time.perf_counter() - start < 0.5
