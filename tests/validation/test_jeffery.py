"""One spheroid in simple shear against Jeffery's orbit (``validation.jeffery``).

Fast tests check the theory (the closed-form orbit against its ODE and period), the fit
(it recovers known coefficients) and the spheroid's packing. The slow test shears a spheroid of
aspect ratio 2 at two resolutions: the mean turning must follow the vorticity at both, and the
hydrodynamic shape factor λ_h, which the discrete body overestimates (its tips, of curvature
radius c/r, are about h across), must move towards Jeffery's as the body is resolved finer.
Full size: a = 2.5 h and 3.75 h, strain 10 (about five minutes on two threads);
``SUSPSIM_REDUCED=1``: a = 2.5 h alone for the strain 6, through the first alignment (under a
minute), which checks the coupling and the plane; the convergence needs the finer body, whose
run alone takes four minutes.
"""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from suspsim.bodies.grains import elongation_and_flatness
from suspsim.bodies.rotations import rotation_matrices
from suspsim.validation.jeffery import (fit_orbit, jeffery_angle, jeffery_lambda, spheroid_box,
                                        spheroid_packing, spheroid_run)
from suspsim.validation.squeeze import reduced


@pytest.mark.parametrize("aspect", [1.0, 1.5, 2.0, 4.0])
def test_closed_form_orbit_solves_jefferys_equation(aspect):
    lam = jeffery_lambda(aspect)
    strain = np.linspace(0.0, 3.0 * math.pi * (aspect + 1.0 / aspect), 4001)
    alpha = jeffery_angle(strain, aspect, 0.3)
    assert alpha[0] == pytest.approx(0.3, abs=1e-12)
    rate = np.gradient(alpha, strain, edge_order=2)
    np.testing.assert_allclose(rate, -0.5 * (1.0 - lam * np.cos(2.0 * alpha)), atol=1e-4)
    # three half turns, each taking the strain π (r + 1/r)
    assert alpha[-1] == pytest.approx(0.3 - 3.0 * math.pi, abs=1e-9)


def test_fit_recovers_the_coefficients_of_a_known_orbit():
    k, lam = 0.97, 0.75
    strain = np.linspace(0.0, 10.0, 201)
    solution = solve_ivp(lambda s, y: [-0.5 * (k - lam * math.cos(2.0 * y[0]))], (0.0, 10.0),
                         [0.5 * math.pi], t_eval=strain, rtol=1e-11, atol=1e-12)
    fit = fit_orbit(strain, solution.y[0])
    assert fit.coupling == pytest.approx(k, abs=2e-3)
    assert fit.shape_factor == pytest.approx(lam, abs=2e-3)
    assert jeffery_lambda(fit.aspect) == pytest.approx(lam / k, abs=3e-3)


def test_spheroid_packing_has_the_asked_shape_volume_and_angle():
    packing = spheroid_packing(2.0, 2.5, spheroid_box(2.5), 0.4)
    assert packing.box[0] == pytest.approx(15.0)
    assert packing.radii[0] == pytest.approx(2.5, rel=1e-9)
    elongation, flatness = elongation_and_flatness(packing.coefficients[0])
    assert elongation == pytest.approx(2.0, rel=2e-3)
    assert flatness == pytest.approx(1.0, rel=2e-3)
    axis = rotation_matrices(packing.orientations)[0][:, 0]
    np.testing.assert_allclose(axis, [math.cos(0.4), math.sin(0.4), 0.0], atol=1e-12)


@pytest.mark.slow
def test_spheroid_turns_with_the_vorticity_and_its_shape_converges_to_jefferys():
    radii, strain = ((2.5,), 6.0) if reduced() else ((2.5, 3.75), 10.0)
    lam = jeffery_lambda(2.0)
    fits = []
    for radius in radii:
        run = spheroid_run(2.0, radius, strain, threads=2)
        fit = fit_orbit(run.strain, run.angle)
        print(f"a = {radius} h: k = {fit.coupling:.3f}, lambda_h = {fit.shape_factor:.3f} "
              f"(Jeffery {lam:.3f}), r_h = {fit.aspect:.3f}, |p_z| <= "
              f"{np.abs(run.out_of_plane).max():.3f}, {run.n_particles} particles")
        assert fit.coupling == pytest.approx(1.0, abs=0.05)
        assert np.abs(run.out_of_plane).max() < 0.2
        fits.append(fit)
    if not reduced():
        coarse, fine = (abs(f.shape_factor - lam) for f in fits)
        assert fine <= 0.8 * coarse
