"""The density check of a run's health (sph.health.density_verdict, Simulation.health)."""
import numpy as np

from suspsim.scene import scene_from_dict
from suspsim.sph.health import density_verdict
from suspsim.sph.simulation import Simulation


def _errors(n=10_000, bulk=0.1, outliers=()):
    errors = np.random.default_rng(1).uniform(0.0, bulk, n)
    errors[:len(outliers)] = outliers
    return errors


def test_a_few_squeezed_particles_pass_and_a_crowd_beyond_the_limit_stops():
    assert density_verdict(_errors(outliers=[0.35] * 10), 0.3, 1e-3, 0.6) == ""
    message = density_verdict(_errors(outliers=[0.35] * 11), 0.3, 1e-3, 0.6)
    assert "run.max_density_error 0.3 on 11 particles" in message
    assert "the 10 that run.density_outlier_fraction lets pass" in message


def test_one_particle_past_the_ceiling_stops_and_names_it():
    message = density_verdict(_errors(outliers=[0.61]), 0.3, 1e-3, 0.6)
    assert message.startswith("density error 0.61 exceeds run.max_outlier_density_error 0.6")


def test_without_outliers_the_largest_error_is_the_limit():
    assert density_verdict(_errors(bulk=0.05), 0.05, 0.0, 0.05) == ""
    message = density_verdict(_errors(bulk=0.05, outliers=[0.06]), 0.05, 0.0, 0.05)
    assert message.startswith("density error 0.06 exceeds run.max_outlier_density_error 0.05")
    assert density_verdict(np.zeros(0), 0.05, 0.0, 0.05) == ""


def test_the_blow_up_of_a_dense_run_stops_on_the_bulk_limit():
    """Measured on φ = 0.4 at 1.6 × the stable step (README): ten steps before its NaN the
    largest error was 1.32, and 198 of 12,000 fluid particles were past 0.3."""
    errors = _errors(n=12_000, outliers=[0.35] * 198)
    assert "on 198 particles" in density_verdict(errors, 0.3, 1e-3, 1e3)


def test_health_reads_the_outlier_settings():
    scene = scene_from_dict({
        "dimension": 2, "box": [6.0, 6.0], "number_density": 4.0,
        "fluid": {"law": "newtonian", "params": {"mu": 1.0}},
        "flow": {"type": "couette", "shear_rate": 0.01},
        "run": {"strain": 1.0, "start": "linear", "max_density_error": 0.05,
                "density_outlier_fraction": 0.02, "max_outlier_density_error": 0.5}})
    sim = Simulation(scene, threads=1)
    assert sim.health()[0]
    rho0 = sim._rho_eq
    sim._rho[:2] = 1.3 * rho0
    assert sim.health()[0]
    sim._rho[:3] = 1.3 * rho0
    ok, message = sim.health()
    assert not ok and "on 3 particles" in message and "run.sound_speed" in message
    sim._rho[:3] = rho0
    sim._rho[0] = 1.6 * rho0
    ok, message = sim.health()
    assert not ok and "run.max_outlier_density_error 0.5" in message
