"""The spin correction of the viscous pair form (``numerics.spin_correction``,
``terms.viscous.local_spin``): a symmetric stress with the same shear viscosity and μ∇²v."""
import numpy as np
import pytest

from sph_helpers import (constant, couette_scene, evaluate, interior, relaxed_simulation,
                         shear_squared)
from suspsim.errors import InputError
from suspsim.sph.simulation import Simulation
from suspsim.sph.terms.force_pass import VXY, VYX
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


def test_time_step_and_scene_rules():
    """β doubled: the viscous step shrinks by κ = (5/6 + 5/3)/(5/3) = 3/2 in 3D; a
    non-Newtonian matrix with the bulk correction is refused, naming the key."""
    assert viscous_stiffness(couette_scene(spin=True)) == pytest.approx(1.5)
    assert viscous_stiffness(couette_scene(dim=2, number_density=4.0, spin=True)) == 2.0
    with pytest.raises(InputError, match="spin_correction"):
        couette_scene(law="power_law", params={"K": 1.0, "n": 0.5}, spin=True)
