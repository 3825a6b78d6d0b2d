"""The spin correction of the viscous pair form (``numerics.spin_correction``,
``terms.viscous.local_spin``): a symmetric stress with the same shear viscosity and μ∇²v."""
import numpy as np
import pytest

from sph_helpers import (constant, couette_scene, evaluate, interior, relaxed_simulation,
                         shear_squared)
from suspsim.sph.simulation import Simulation
from suspsim.sph.terms.force_pass import VXY, VYX
from suspsim.sph.terms.viscous import spin_bulk_ratio
from suspsim.sph.timestep import viscous_stiffness

RATE = 0.05


def _shear_virial(spin, jitter):
    """(σ_xy, σ_yx)/(μγ̇) of the viscous pair virial for the linear profile v_x = γ̇ y (the
    Lees–Edwards images carry it across the box), normalised, on a lattice (``jitter`` 0) or
    a relaxed jittered lattice."""
    scene = couette_scene(rate=RATE, jitter=jitter, spin=spin, sound_speed=2.0)
    sim = Simulation(scene, threads=1)
    if jitter:
        sim.relax(1e-3, 200)

    def profile(xi):
        v = np.zeros_like(xi)
        v[:, 0] = RATE * xi[:, 1]
        return v

    evaluate(sim, profile, constant, normalise=True)
    virial = sim._virial.sum(axis=0)
    return -virial[VXY] / (scene.volume * RATE), -virial[VYX] / (scene.volume * RATE)


@pytest.mark.parametrize("jitter, tolerance", [(0.0, 1e-9), (0.3, 0.01)])
def test_the_corrected_stress_is_symmetric_with_the_same_shear_stress(jitter, tolerance):
    """Español–Revenga (3D, α = β = 5/6) in a linear shear: σ_yx/σ_xy = (α/15)/(β/3 + α/15)
    = 1/6 in the continuum (``terms.viscous.local_spin``; the discrete fourth moment makes it
    0.06 on the lattice, 0.10 on disorder). Corrected: σ_yx = σ_xy, and σ_xy is that of the
    uncorrected form (on the lattice 0.991 μγ̇ with the normalisation, the pairs' harmonic
    mean of μ̂ being the rest)."""
    xy, yx = _shear_virial(False, jitter)
    assert xy == pytest.approx(1.0, abs=0.02)
    assert 0.0 < yx / xy < 1.0 / 6.0
    corrected_xy, corrected_yx = _shear_virial(True, jitter)
    assert corrected_xy == pytest.approx(xy, rel=tolerance)
    assert corrected_yx == pytest.approx(corrected_xy, rel=tolerance)


def test_the_corrected_operator_keeps_mu_laplacian():
    """v_x = y²: μ∇²v = 2 in the interior of the lattice with the normalisation, as without the
    correction (``test_operators``)."""
    sim = relaxed_simulation(3, 5.0, 4.096, spin=True)
    xi, force, _, _ = evaluate(sim, shear_squared, constant, normalise=True)
    inside = interior(sim, xi)
    np.testing.assert_allclose(force[inside, 0], 2.0, rtol=2e-3)
    np.testing.assert_allclose(force[inside, 1:], 0.0, atol=2e-3)


def _variable_viscosity_error(dim, number_density, spin):
    """Relative error of the normalised viscous force density on a lattice for the linear
    fields v = ξ G and μ = 1 + c·ξ (random G with divergence and rotation, |∇μ| ≈ 0.1 h⁻¹)
    against the continuum ∇·σ = (G + Gᵀ)ᵀ c + λ tr G c, σ = μ(∇v + ∇vᵀ) + λ(∇·v) I with
    λ = −2μ/d, zero bulk viscosity: uncorrected with the explicit ∇a term (SPEC §2.3–2.4),
    corrected without it (``terms.viscous.local_spin``) and with its bulk viscosity
    (d + 2)μ/(2d) taken out through the pressure (``terms.viscous.spin_bulk_pressure``; the
    sound speed is 0, so that is all the pressure holds)."""
    rng = np.random.default_rng(3)
    grad = np.zeros((3, 3))
    grad[:dim, :dim] = rng.normal(size=(dim, dim))
    slope = np.zeros(3)
    slope[:dim] = 0.1 * rng.normal(size=dim)
    sim = relaxed_simulation(dim, 5.0, number_density, spin=spin)
    xi, force, _, _ = evaluate(sim, lambda x: x @ grad, lambda x: 1.0 + x @ slope,
                               normalise=True, bulk_gradient=not spin)
    lam = -2.0 / dim
    exact = slope @ (grad + grad.T) + lam * np.trace(grad) * slope
    error = force[interior(sim, xi)] - exact
    return np.linalg.norm(error.mean(axis=0)) / np.linalg.norm(exact)


@pytest.mark.parametrize("spin", [False, True])
def test_variable_viscosity_converges_to_the_divergence_of_the_stress(spin):
    """Both pair forms converge, at the same rate, to their own σ with variable μ (3D: 13 %,
    4 %, 1.2 % at 4.096, 8 and 27 particles per h³; 2D: 0.2 %): the corrected one without
    the explicit ∇a term, which would leave 35 % at 27 per h³."""
    errors = [_variable_viscosity_error(3, n, spin) for n in (4.096, 8.0, 27.0)]
    assert errors[0] > errors[1] > errors[2]
    assert errors[2] < 0.02
    assert _variable_viscosity_error(2, 4.0, spin) < 0.005


def test_the_removed_bulk_viscosity_is_that_of_the_corrected_stress():
    """ζ = 2μ/d + (d − 2)μ/(2d) of σ = μ(∇v + ∇vᵀ) + (d − 2)/(2d) μ(∇·v) I."""
    for dim in (2, 3):
        assert spin_bulk_ratio(dim) == pytest.approx(2.0 / dim + (dim - 2) / (2.0 * dim))
    assert spin_bulk_ratio(3) == pytest.approx(5.0 / 6.0)


def test_time_step_and_scene_rules():
    """β doubled: the viscous step shrinks by κ = (5/6 + 5/3)/(5/3) = 3/2 in 3D; a
    non-Newtonian matrix takes the correction without the explicit ∇a term."""
    assert viscous_stiffness(couette_scene(spin=True)) == pytest.approx(1.5)
    assert viscous_stiffness(couette_scene(dim=2, number_density=4.0, spin=True)) == 2.0
    scene = couette_scene(law="power_law", params={"K": 1.0, "n": 0.5}, spin=True)
    assert not Simulation(scene, threads=1)._bulk_gradient
