"""The kernel-smoothed strain rate a non-Newtonian law sees (``terms.rate_smoothing``): exact on
linear fields, an average of fluid neighbours only, and a filter of particle-scale noise."""
import math

import numpy as np
import pytest

from sph_helpers import constant, evaluate, interior, relaxed_simulation
from suspsim.rheology.laws import make_law
from suspsim.scene import scene_from_dict
from suspsim.sph.density import GEOMETRY_DTYPE
from suspsim.sph.kernels import kernel_code, lucy_w_3d
from suspsim.sph.terms.rate_smoothing import RATE_WIDTH, smoothed_rate_viscosity

POWER_LAW = make_law("power_law", {"K": 1.0, "n": 0.5})


def smoothed(sim):
    """(γ̇, μ) of the smoothed rate over the simulation's last pair table."""
    n = sim.n_particles
    gdot, mu = sim._gdot.copy(), np.zeros(n)
    tb = sim._table
    smoothed_rate_viscosity(tb.pair_start, tb.pair_end, tb.pair_j, tb.pair_geometry,
                            kernel_code("lucy", 3), 1.0, sim._volume, sim._gradient,
                            sim._body_of, POWER_LAW.code, POWER_LAW.packed,
                            np.zeros(RATE_WIDTH * n), np.zeros((0, 15 * n)),
                            np.array([0, n]), gdot, mu)
    return gdot, mu


@pytest.fixture(scope="session")
def disordered():
    return relaxed_simulation(3, 8.125, 4.096, jitter=0.3, relax_steps=60, sound_speed=2.0,
                              law="power_law", params={"K": 1.0, "n": 0.5})


def test_smoothed_rate_is_exact_for_linear_fields_on_disorder(disordered):
    grad = np.random.default_rng(3).normal(size=(3, 3))  # grad[k, l] = ∂_k v_l
    xi, *_ = evaluate(disordered, lambda x: x @ grad, constant, normalise=False)
    gdot, mu = smoothed(disordered)
    # The average reaches one support further than the gradient: two supports from the faces.
    inside = interior(disordered, xi, margin=2.25)
    sym = grad + grad.T
    exact = math.sqrt(0.5 * np.sum(sym * sym))
    assert inside.sum() > 100
    # exact up to the pair table's rounding of r_ij (density.GEOMETRY_DTYPE)
    tol = 16 * np.finfo(GEOMETRY_DTYPE).eps
    np.testing.assert_allclose(gdot[inside], exact, rtol=tol)
    np.testing.assert_allclose(mu[inside], POWER_LAW.viscosity(exact), rtol=tol)


def test_smoothing_filters_particle_scale_noise(disordered):
    """Simple shear plus independent velocity noise of 0.3 γ̇ h per particle: the rate the law
    sees is closer to γ̇ after smoothing (measured: median error 0.45 → 0.21 γ̇)."""
    rng = np.random.default_rng(4)
    n = disordered.n_particles
    noise = 0.3 * rng.normal(size=(n, 3))

    def noisy_shear(x):
        v = np.zeros_like(x)
        v[:, 0] = x[:, 1]
        return v + noise

    xi, _, _, raw = evaluate(disordered, noisy_shear, constant, normalise=False)
    gdot, _ = smoothed(disordered)
    inside = interior(disordered, xi, margin=2.25)
    raw_error = np.median(np.abs(raw[inside] - 1.0))
    smooth_error = np.median(np.abs(gdot[inside] - 1.0))
    assert raw_error > 0.2
    assert smooth_error < 0.6 * raw_error


def test_body_particles_are_not_sources():
    """Three particles, 2 a body particle with a wild gradient: the fluid pair averages only
    the two fluid gradients; the body particle takes their average without a self term."""
    r01, r02, r12 = 0.5, 0.6, 0.7
    geometry = np.array([[r01, 0, 0, 0.0], [r02, 0, 0, 0.0], [r12, 0, 0, 0.0]])
    start = np.array([0, 2, 3])
    pair_end, pair_j = np.array([2, 3, 3]), np.array([1, 2, 2])
    volume = np.array([0.25, 0.3, 0.2])
    gradient = np.zeros((3, 9))
    gradient[0, 3], gradient[1, 3], gradient[2, 3] = 1.0, 3.0, 1000.0  # ∂_y v_x
    gdot, mu = np.zeros(3), np.zeros(3)
    smoothed_rate_viscosity(start, pair_end, pair_j, geometry, kernel_code("lucy", 3), 1.0,
                            volume, gradient, np.array([-1, -1, 0]), POWER_LAW.code,
                            POWER_LAW.packed, np.zeros(RATE_WIDTH * 3), np.zeros((0, 45)),
                            np.array([0, 3]), gdot, mu)
    w0, w01, w02, w12 = (lucy_w_3d(r, 1.0) for r in (0.0, r01, r02, r12))
    expected_0 = (w0 * 0.25 * 1.0 + w01 * 0.3 * 3.0) / (w0 * 0.25 + w01 * 0.3)
    expected_1 = (w0 * 0.3 * 3.0 + w01 * 0.25 * 1.0) / (w0 * 0.3 + w01 * 0.25)
    expected_2 = (w02 * 0.25 * 1.0 + w12 * 0.3 * 3.0) / (w02 * 0.25 + w12 * 0.3)
    np.testing.assert_allclose(gdot, [expected_0, expected_1, expected_2], rtol=1e-12)
    np.testing.assert_allclose(mu, POWER_LAW.viscosity(gdot), rtol=1e-12)


@pytest.mark.parametrize("law, inclusions, expected", [
    ({"law": "power_law", "params": {"K": 1.0, "n": 0.5}}, True, True),
    ({"law": "newtonian", "params": {"mu": 1.0}}, True, False),
    ({"law": "power_law", "params": {"K": 1.0, "n": 0.5}}, False, False),
])
def test_rate_smoothing_auto_acts_where_shifting_stirs_a_non_newtonian_fluid(law, inclusions,
                                                                            expected):
    scene = scene_from_dict({
        "dimension": 3, "box": [15.0] * 3, "number_density": 4.096, "fluid": law,
        "flow": {"type": "couette", "shear_rate": 0.01}, "run": {"strain": 1.0},
        "inclusions": {"phi": 0.1 if inclusions else 0.0, "radius": 2.5}})
    assert scene.numerics.rate_smoothing is expected
