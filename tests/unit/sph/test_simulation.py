"""Simulation API, momentum conservation, resume, stable time step and blow-up detection."""
import numpy as np
import pytest

from sph_helpers import couette_scene
from suspsim.errors import NumericalError
from suspsim.scene import scene_from_dict
from suspsim.sph.lattice import imposed_velocity
from suspsim.sph.simulation import Simulation
from suspsim.sph.timestep import ACOUSTIC_COEFFICIENT, auto_sound_speed, stable_time_step

PAPANASTASIOU = {"mu_pl": 0.1, "mu_0": 9.9, "M": 100.0}


def peculiar_momentum(sim):
    v = sim._v.copy()
    v[:, 0] -= imposed_velocity(sim.scene, sim._x[:, 1])
    return v.sum(axis=0) * sim.scene.mass


def test_api_end_to_end_newtonian_couette():
    sim = Simulation(couette_scene(jitter=0.02, start="rest"), threads=1)
    assert sim.n_particles == 512 and sim.dt > 0 and sim.sound_speed > 0
    assert sim.time == 0.0 and sim.step_count == 0 and sim.strain == 0.0
    sim.advance(25)
    assert sim.step_count == 25 and sim.time == pytest.approx(25 * sim.dt)
    assert sim.strain == pytest.approx(0.05 * sim.time)
    ok, message = sim.health()
    assert ok, message
    sample = sim.sample()
    assert set(sample) == {"shear_stress", "pressure", "kinetic_energy", "density_error", "mach"}
    assert all(np.isfinite(list(sample.values())))
    profiles = sim.profiles(8)
    assert set(profiles) == {"y", "velocity_profile", "viscosity_profile", "shear_rate_profile",
                             "density_profile"}
    assert all(p.shape == (8,) for p in profiles.values())
    np.testing.assert_allclose(profiles["viscosity_profile"], 1.0)
    # A position that went NaN between health checks is a blow-up, not a binning error.
    sim._x[3, 1] = np.nan
    with pytest.raises(NumericalError, match="blew up; lower run.dt"):
        sim.profiles(8)


@pytest.mark.parametrize("law, params, bulk", [("newtonian", {"mu": 1.0}, True),
                                               ("papanastasiou", PAPANASTASIOU, False)])
def test_momentum_is_conserved_to_round_off(law, params, bulk):
    """Pair forces are antisymmetric (B off, or μ constant): Σ m ṽ stays at round-off, also
    across Lees–Edwards faces and neighbour-list rebuilds."""
    sim = Simulation(couette_scene(law=law, params=params, rate=0.1, jitter=0.02, bulk=bulk,
                                   start="rest"), threads=2)
    before = peculiar_momentum(sim)
    builds = sim.rebuild_count
    sim.advance(250)
    assert sim.rebuild_count > builds
    scale = sim.n_particles * sim.scene.mass * 0.1 * sim.scene.box[1]
    np.testing.assert_allclose(peculiar_momentum(sim) - before, 0.0, atol=1e-12 * scale)


@pytest.mark.parametrize("law, params, interval", [("papanastasiou", PAPANASTASIOU, 2),
                                                   ("newtonian", {"mu": 1.0}, 3)])
def test_resume_from_state_is_bit_for_bit(law, params, interval):
    """Also in the middle of a Newtonian scene's held normalisation (40 steps, k = 3)."""
    scene = couette_scene(law=law, params=params, rate=0.1, jitter=0.02, interval=interval)
    reference = Simulation(scene, threads=2)
    reference.advance(40)
    state = reference.state()
    reference.advance(40)
    resumed = Simulation.from_state(scene, state, threads=1)
    resumed.advance(40)
    assert resumed.step_count == reference.step_count
    np.testing.assert_array_equal(resumed._x, reference._x)
    np.testing.assert_array_equal(resumed._v, reference._v)
    assert resumed.sample() == reference.sample()


@pytest.mark.parametrize("shifting", [0.0, 30.0])
def test_a_pair_table_that_starts_too_small_grows_and_changes_nothing(monkeypatch, shifting):
    """The compact pair table (``density``) overflows, grows and repeats the density pass, in
    the compiled step loop and in the Python one (shifting on): positions and velocities equal
    those of a run whose table never overflowed, bit for bit."""
    import suspsim.sph.simulation as simulation

    scene = scene_from_dict({
        "dimension": 3, "box": [5.0] * 3, "number_density": 4.096,
        "fluid": {"law": "papanastasiou", "params": PAPANASTASIOU},
        "flow": {"type": "couette", "shear_rate": 0.1}, "run": {"strain": 1.0, "start": "rest"},
        "lattice": {"jitter": 0.02}, "numerics": {"shifting": shifting}})
    reference = Simulation(scene, threads=2)
    monkeypatch.setattr(simulation, "pair_capacity", lambda *args: 100)
    grown = Simulation(scene, threads=2)
    assert grown._table.pair_j.shape[0] > 100
    reference.advance(30)
    grown.advance(30)
    np.testing.assert_array_equal(grown._x, reference._x)
    np.testing.assert_array_equal(grown._v, reference._v)


def viscous_limited(coefficient):
    """μ = 100 at ρ = 4.096: the viscous limit (not the acoustic one) binds."""
    return Simulation(couette_scene(params={"mu": 100.0}, rate=0.005,
                                    dt=coefficient * 4.096 / 100.0), threads=2)


def acoustic_limited(coefficient):
    """μ = 0.1, c = 20: the acoustic limit binds."""
    return Simulation(couette_scene(params={"mu": 0.1}, rate=0.05, jitter=0.02,
                                    sound_speed=20.0, dt=coefficient / 20.0), threads=2)


def test_time_step_coefficients_are_stable_and_4x_trips_the_health_check():
    """Measured for the Lucy kernel with the normalisation: the viscous step is stable to
    ≈ 0.075 ρh²/μ (0.07 clean, 0.08 growing, 0.09 blows up); the default 0.05 runs, 4× fails.
    The acoustic step is stable to 0.75 h/c and not at 1.0; the chosen 0.25 runs, 4× fails."""
    default = couette_scene().numerics.dt_viscous_coefficient
    for make, coefficient in ((viscous_limited, default),
                              (acoustic_limited, ACOUSTIC_COEFFICIENT)):
        stable = make(coefficient)
        stable.advance(300)
        ok, message = stable.health()
        assert ok, message
        unstable = make(4 * coefficient)
        unstable.advance(300)
        ok, message = unstable.health()
        assert not ok and "run.dt" in message


def test_blow_up_is_detected_and_names_the_setting():
    scene = scene_from_dict({
        "dimension": 3, "box": [5.0, 5.0, 5.0], "number_density": 4.096,
        "fluid": {"law": "newtonian", "params": {"mu": 1.0}},
        "flow": {"type": "poiseuille", "body_force": 0.05},
        "run": {"time": 10.0, "sound_speed": 0.05}})
    sim = Simulation(scene, threads=1)
    sim.advance(200)
    ok, message = sim.health()
    assert not ok
    assert "run.sound_speed" in message


@pytest.mark.parametrize("dim, density, stiffness", [(3, 4.096, 3.0), (2, 4.0, 4.0)])
def test_viscous_step_follows_the_pair_forms_stiffness(dim, density, stiffness):
    """Without the bulk correction the viscous pair force along r has weight α = d + 2, against
    α + β = 5/3 (3D) and 1 (2D) for the corrected form the coefficient was measured on: the
    automatic step shrinks by that ratio and runs; the corrected form's step blows up."""
    def scene(bulk, **run):
        return couette_scene(dim=dim, number_density=density, params={"mu": 100.0}, rate=0.005,
                             jitter=0.02, bulk=bulk, **run)
    corrected = stable_time_step(scene(True), auto_sound_speed(scene(True)))
    plain = Simulation(scene(False), threads=2)
    assert plain.dt == pytest.approx(corrected / stiffness)
    plain.advance(300)
    ok, message = plain.health()
    assert ok, message
    unstable = Simulation(scene(False, dt=corrected), threads=2)
    unstable.advance(300)
    ok, message = unstable.health()
    assert not ok and "run.dt" in message
