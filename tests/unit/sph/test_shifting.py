"""Particle shifting (``terms.shifting``) and the concentration gradient the force pass sums for it
(``terms.force_pass``): ∇C_i = −Σ_j V_j F(r_ij) r_ij against a brute-force sum over all pairs,
the forces unchanged by the extra columns, and the shift δr = −A h² γ_s δt ∇C, clipped at
``MAX_SHIFT`` h, of fluid particles only."""
import numpy as np
import pytest

from suspsim.sph.kernels import LUCY_3D, kernel_f
from suspsim.sph.terms.force_pass import concentration_column, force_sums, force_width
from suspsim.sph.terms.shifting import MAX_SHIFT, shift_particles
from suspsim.sph.terms.viscous import viscous_weights

N = 40


def _cloud(seed=3):
    """Positions in a 2 h cube (no periodic images), velocities, densities, volumes, and the
    half pair table within h: start, end, j, rows (dx, dy, dz, F)."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(0.0, 2.0, (N, 3))
    v = rng.normal(0.0, 0.1, (N, 3))
    rho = rng.uniform(3.8, 4.2, N)
    start, js, rows = [0], [], []
    for i in range(N):
        for j in range(i + 1, N):
            d = x[i] - x[j]
            r = float(np.linalg.norm(d))
            if r < 1.0:
                js.append(j)
                rows.append([*d, kernel_f(LUCY_3D, r, 1.0)])
        start.append(len(js))
    start = np.array(start)
    return x, v, rho, 1.0 / rho, start, np.array(js), np.array(rows)


def _force_pass(cloud, width, bulk_gradient, body_of, chunks=1):
    """acc (width N,) of ``force_sums`` on ``cloud`` in ``chunks`` chunks."""
    x, v, rho, volume, start, js, rows = cloud
    alpha, beta = viscous_weights(3, True)
    acc = np.zeros(width * N)
    bounds = np.linspace(0, N, chunks + 1).astype(np.int64)
    force_sums(start, start[1:], js, rows, start[1:].copy(), np.zeros(len(js), dtype=np.int64),
               v, rho, volume, np.linspace(0.5, 1.5, N), 1.0, 4.0, 4.0, alpha, beta,
               -5.0 / 3.0, bulk_gradient, 0.0, body_of, np.zeros((1, 3)), False, 0.0,
               np.zeros((N, 9)), np.zeros(N), np.zeros((N, 3)), acc,
               np.zeros((chunks - 1, width * N)), bounds, np.zeros((chunks, 5)))
    return acc.reshape(N, width)


def _brute_gradient(cloud, sources=None):
    """∇C_i = −Σ_{j ≠ i, r < h} V_j F(r_ij) r_ij over all ordered pairs (over j in the
    boolean mask ``sources`` only, if given)."""
    x, volume = cloud[0], cloud[3]
    grad = np.zeros((N, 3))
    for i in range(N):
        for j in range(N):
            d = x[i] - x[j]
            r = float(np.linalg.norm(d))
            if i != j and r < 1.0 and (sources is None or sources[j]):
                grad[i] -= volume[j] * kernel_f(LUCY_3D, r, 1.0) * d
    return grad


@pytest.mark.parametrize("bulk_gradient", [False, True])
@pytest.mark.parametrize("chunks", [1, 3])
def test_the_force_pass_sums_the_concentration_gradient_without_changing_the_forces(
        bulk_gradient, chunks):
    cloud = _cloud()
    fluid = np.full(N, -1, dtype=np.int64)
    plain = _force_pass(cloud, force_width(bulk_gradient, False), bulk_gradient, fluid, chunks)
    shifted = _force_pass(cloud, force_width(bulk_gradient, True), bulk_gradient, fluid, chunks)
    np.testing.assert_allclose(shifted[:, -3:], _brute_gradient(cloud), rtol=1e-12, atol=1e-12)
    np.testing.assert_array_equal(shifted[:, :plain.shape[1]], plain)
    assert np.abs(shifted[:, -3:]).max() > 0.1


def test_the_shift_moves_fluid_particles_down_the_gradient_and_clips_it():
    cloud = _cloud()
    x, v = cloud[0].copy(), cloud[1].copy()
    body_of = np.full(N, -1, dtype=np.int64)
    body_of[:5] = 0
    acc = _force_pass(cloud, force_width(False, True), False, body_of)
    grad_c = acc[:, -3:].copy()
    gradient = np.random.default_rng(1).normal(0.0, 0.3, (N, 9))
    coefficient, rate, dt = 30.0, 0.05, 0.1
    shift_particles(acc.reshape(-1), concentration_column(False), False, body_of, coefficient,
                    rate, dt, 1.0, gradient, x, v)
    step = -coefficient * rate * dt * grad_c
    size = np.linalg.norm(step, axis=1)
    step *= np.minimum(1.0, MAX_SHIFT / size)[:, None]
    step[:5] = 0.0
    assert np.any(size[5:] > MAX_SHIFT) and np.any(size[5:] < MAX_SHIFT)
    np.testing.assert_allclose(x - cloud[0], step, rtol=1e-12, atol=1e-15)
    expected_v = cloud[1] + np.einsum("ik,ikl->il", step, gradient.reshape(N, 3, 3))
    np.testing.assert_allclose(v, expected_v, rtol=1e-12, atol=1e-15)


def _two_bodies():
    """Particles 0–4 of body 0, 5–9 of body 1, the rest fluid."""
    body_of = np.full(N, -1, dtype=np.int64)
    body_of[:5] = 0
    body_of[5:10] = 1
    return body_of


@pytest.mark.parametrize("bulk_gradient", [False, True])
@pytest.mark.parametrize("chunks", [1, 3])
def test_the_force_pass_sums_the_bodies_part_of_the_gradient_for_fluid_particles(
        bulk_gradient, chunks):
    cloud = _cloud()
    body_of = _two_bodies()
    shifted = _force_pass(cloud, force_width(bulk_gradient, True), bulk_gradient, body_of,
                          chunks)
    both = _force_pass(cloud, force_width(bulk_gradient, True, True), bulk_gradient, body_of,
                       chunks)
    c0 = concentration_column(bulk_gradient)
    np.testing.assert_array_equal(both[:, :shifted.shape[1]], shifted)
    expected = _brute_gradient(cloud, body_of >= 0)
    fluid = body_of < 0
    np.testing.assert_allclose(both[fluid, c0 + 3:c0 + 6], expected[fluid], rtol=1e-12,
                               atol=1e-12)
    assert np.abs(expected[fluid]).max() > 0.1
    np.testing.assert_array_equal(both[~fluid, c0 + 3:c0 + 6], 0.0)


def test_tangential_shifting_moves_nothing_along_the_bodies_gradient():
    cloud = _cloud()
    body_of = _two_bodies()
    acc = _force_pass(cloud, force_width(False, True, True), False, body_of)
    c0 = concentration_column(False)
    normal = acc[:, c0 + 3:c0 + 6].copy()
    x, v = cloud[0].copy(), cloud[1].copy()
    gradient = np.random.default_rng(2).normal(0.0, 0.3, (N, 9))
    shift_particles(acc.reshape(-1), c0, True, body_of, 30.0, 0.05, 0.1, 1.0, gradient, x, v)
    step = x - cloud[0]
    touching = np.linalg.norm(normal, axis=1) > 0.0
    assert touching[10:].sum() > 5 and (~touching[10:]).sum() > 0
    np.testing.assert_allclose(np.einsum("ik,ik->i", step, normal)[touching], 0.0, atol=1e-14)
    assert np.abs(step[10:][touching[10:]]).max() > 1e-4
    full = cloud[0].copy()
    shift_particles(acc.reshape(-1), c0, False, body_of, 30.0, 0.05, 0.1, 1.0, gradient, full,
                    cloud[1].copy())
    alone = ~touching & (body_of < 0)
    np.testing.assert_array_equal(step[alone], (full - cloud[0])[alone])
    np.testing.assert_array_equal(step[:10], 0.0)
