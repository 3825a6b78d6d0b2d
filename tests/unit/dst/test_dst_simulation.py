"""DSTSimulation: microstructure relaxation, walls, smoke runs of both flows, error paths."""
import math
import os

import numpy as np
import pytest

from suspsim.dst import (Channel, DSTSimulation, Geometry, Numerics, StressCouette,
                         WyartCatesFluid)
from suspsim.errors import InputError, NumericalError

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
DST_FLUID = dict(eta_s=1.0, phi=0.54, phi_m=0.562, phi_0=0.693, sigma_star=1.0, beta=2.0,
                 K_f=1.0, alpha=0.0)


def test_relaxation_ode_under_uniform_shear():
    """α = 0, η independent of f (φ = 0) and uniform γ̇: f(t) = f̂ + (f0 − f̂) e^(−K_f γ̇ t)."""
    K_f, stress = 20.0, 1.0
    fluid = WyartCatesFluid(eta_s=1.0, phi=0.0, phi_m=0.5, phi_0=0.6, sigma_star=1.0,
                            beta=2.0, K_f=K_f, alpha=0.0)
    sim = DSTSimulation(fluid, StressCouette(stress), Geometry(14, 12, 1.0),
                        Numerics(density=0.1), threads=1, initial_fraction=lambda y: 0.9)
    f_hat = math.exp(-1.0)  # σ = η_s γ̇ = σ_in = σ*
    times, means = [], []
    while sim.time < 0.1:
        sim.advance(200)
        times.append(sim.time)
        means.append(sim.sample()["fraction"])
    gdot = stress / 1.0
    expected = f_hat + (0.9 - f_hat) * np.exp(-K_f * gdot * np.array(times))
    np.testing.assert_allclose(means, expected, atol=3e-3)
    assert means[-1] < 0.9 - 0.8 * (0.9 - f_hat)  # most of the way relaxed


@pytest.mark.parametrize("dimension", [2, pytest.param(3, marks=pytest.mark.slow)])
def test_walls_stop_particles_moving_into_them(dimension):
    """No penetration: fluid pushed at the bottom wall at Mach 0.05 stays inside 0 < y < L_y
    (3D: 13 × 12 × 13, slow)."""
    fluid = WyartCatesFluid.newtonian(1.0)
    geometry = Geometry(14, 12, 1.0) if dimension == 2 else Geometry(13, 12, 1.0, n_z=13)
    sim = DSTSimulation(fluid, Channel(1e-12), geometry,
                        Numerics(density=1.0, sound_speed=20.0, max_density_error=0.2),
                        threads=1)
    nf = sim.n_fluid
    velocity = np.zeros((nf, dimension))
    velocity[:, 1] = -1.0
    sim.set_state(velocity=velocity)
    momentum0 = sim.snapshot()["v_y"].sum()
    while sim.time < 0.6:
        sim.advance(100)
        y = sim.snapshot()["y"]
        assert y.min() > 0.25 * sim.geometry.spacing
        assert y.max() < 1.0
    v_y = sim.snapshot()["v_y"]
    assert abs(v_y.sum()) < 0.05 * abs(momentum0)   # the wall took the momentum


def test_stress_couette_smoke_and_diagnostics():
    fluid = WyartCatesFluid(**{**DST_FLUID, "alpha": 1e-3})
    law = fluid.steady_law()
    tp = law.turning_points()
    stress = 0.5 * (tp.sigma_beta + tp.sigma_alpha)   # unstable branch
    sim = DSTSimulation(fluid, StressCouette(stress), Geometry(14, 12, 1.0),
                        Numerics(density=1.0), threads=1)
    assert sim.wall_velocity == pytest.approx(float(law.shear_rate(stress)) * 1.0)
    sim.advance(5)
    s = sim.sample()
    assert set(s) >= {"time", "wall_velocity", "stress", "shear_rate", "fraction"}
    assert all(math.isfinite(v) for v in s.values())
    assert s["fraction"] == pytest.approx(float(law.frictional_fraction(stress)), rel=1e-3)
    assert s["stress"] == pytest.approx(stress, rel=0.1)
    prof = sim.profiles(6)
    assert prof["velocity"].shape == (6,) and prof["count"].sum() == sim.n_fluid
    assert np.all(np.diff(prof["velocity"]) > 0)     # increasing towards the moving wall
    stats = sim.branch_statistics()
    assert stats["q"] == pytest.approx(0.5)
    assert 0.0 <= stats["psi1"] <= 1.0 and 0.0 <= stats["psi2"] <= 1.0
    snap = sim.snapshot()
    assert snap["x"].shape == (sim.n_fluid,) and np.all(snap["eta"] > 0)


def test_channel_smoke_starts_from_local_state():
    fluid = WyartCatesFluid(**DST_FLUID)
    sim = DSTSimulation(fluid, Channel(20.0), Geometry(14, 12, 1.0), Numerics(density=1.0),
                        threads=1)
    snap = sim.snapshot()
    expected = [fluid.frictional_fraction(abs(20.0 * (0.5 - y))) for y in snap["y"]]
    np.testing.assert_allclose(snap["f"], expected)
    sim.advance(5)
    s = sim.sample()
    assert s["wall_velocity"] == 0.0
    assert all(math.isfinite(v) for v in s.values())
    assert sim.snapshot()["v_x"].min() > 0.0          # accelerating along the body force
    d = sim.describe()
    assert d["dt"] == pytest.approx(min(d["dt_sound"], d["dt_viscous"]), rel=0.5)


def test_bad_parameters_raise_input_error():
    with pytest.raises(InputError, match="phi"):
        WyartCatesFluid(**{**DST_FLUID, "phi": 0.7})
    with pytest.raises(InputError, match="K_f"):
        WyartCatesFluid(**{**DST_FLUID, "K_f": -1.0})
    with pytest.raises(InputError, match="wall_layers"):
        Geometry(14, 12, 1.0, wall_layers=2)
    # φ > φ_m: starting frictional (f = 1 at a large stress) is jammed
    fluid = WyartCatesFluid(**{**DST_FLUID, "phi": 0.58})
    with pytest.raises(InputError, match="jammed"):
        DSTSimulation(fluid, StressCouette(100.0), Geometry(14, 12, 1.0))


def test_blow_up_names_the_setting():
    fluid = WyartCatesFluid.newtonian(1.0)
    sim = DSTSimulation(fluid, Channel(100.0), Geometry(14, 12, 1.0),
                        Numerics(density=1.0, sound_speed=0.5), threads=1)
    with pytest.raises(NumericalError, match="sound_speed"):
        sim.advance(5000)


def _colour_gradient_after(shifting, dimension, steps):
    fluid = WyartCatesFluid.newtonian(1.0)
    geometry = Geometry(14, 12, 1.0) if dimension == 2 else Geometry(13, 12, 1.0, n_z=13)
    sim = DSTSimulation(fluid, Channel(50.0), geometry,
                        Numerics(density=1.0, shifting=shifting), threads=1)
    rng = np.random.default_rng(11)
    jitter = 0.15 * sim.geometry.spacing * rng.uniform(-1, 1, (sim.n_fluid, dimension))
    sim.set_state(positions=sim.positions_all[:sim.n_fluid] + jitter)
    before = np.sqrt(np.mean(np.sum(sim.rates()["colour_gradient"] ** 2, axis=1)))
    sim.advance(steps)
    after = np.sqrt(np.mean(np.sum(sim.rates()["colour_gradient"] ** 2, axis=1)))
    return before, after, sim


@pytest.mark.parametrize("dimension, steps", [
    (2, 1500), pytest.param(3, 200 if REDUCED else 1500, marks=pytest.mark.slow)])
def test_particle_shifting_is_switchable_and_regularises(dimension, steps):
    """Lind shifting (δx = −A h |v| δt ∇C) evens out a jittered start faster than advection
    (3D: 13 × 12 × 13, slow; 200 steps reduced)."""
    before, plain, sim_plain = _colour_gradient_after(False, dimension, steps)
    _, shifted, sim_shift = _colour_gradient_after(True, dimension, steps)
    assert shifted < 0.7 * plain
    assert shifted < before
    assert np.all(np.isfinite(sim_shift.snapshot()["v_x"]))
    # start-up of plane Poiseuille from rest (g = 50, ν = L = 1): mean velocity
    # ū(t) = g L²/(12ν) [1 − Σ_odd n 96/(nπ)⁴ exp(−(nπ)² ν t/L²)]
    n = np.arange(1, 200, 2)
    t = sim_shift.time
    exact = 50.0 / 12.0 * (1.0 - np.sum(96.0 / (n * np.pi) ** 4 * np.exp(-(n * np.pi) ** 2 * t)))
    assert sim_shift.snapshot()["v_x"].mean() == pytest.approx(exact, rel=0.05)
    assert sim_plain.snapshot()["v_x"].mean() == pytest.approx(exact, rel=0.05)


def test_creeping_towards_jamming_stops_with_a_clear_error():
    """φ = 0.58 > φ_m under σ_in = 5σ* > σ_J: f grows towards φ_J(f) = φ from f = 0."""
    fluid = WyartCatesFluid(**{**DST_FLUID, "phi": 0.58, "K_f": 50.0})
    sim = DSTSimulation(fluid, StressCouette(5.0), Geometry(14, 12, 1.0),
                        Numerics(density=100.0, max_viscosity_ratio=1e3), threads=1,
                        initial_fraction=lambda y: 0.0)
    with pytest.raises(NumericalError, match="max_viscosity_ratio"):
        sim.advance(20000)
    assert sim.snapshot()["f"].max() > 0.5


def test_neighbour_list_grows_when_full():
    fluid = WyartCatesFluid.newtonian(1.0)
    sim = DSTSimulation(fluid, Channel(1.0), Geometry(14, 12, 1.0), Numerics(density=1.0),
                        threads=1)
    reference = DSTSimulation(fluid, Channel(1.0), Geometry(14, 12, 1.0),
                              Numerics(density=1.0), threads=1)
    sim._lists = sim._lists._replace(neighbours=np.zeros(10, dtype=np.int64))
    sim._lists.force_rebuild[0] = 1
    sim.advance(20)
    reference.advance(20)
    assert sim._lists.neighbours.shape[0] > 10
    np.testing.assert_array_equal(sim.snapshot()["v_x"], reference.snapshot()["v_x"])


def _couette(**numerics):
    fluid = WyartCatesFluid(**{**DST_FLUID, "alpha": 1e-3})
    return DSTSimulation(fluid, StressCouette(2.5), Geometry(14, 6, 1.0),
                         Numerics(density=1.0, **numerics), threads=1)


def test_diagnostics_splits_and_restore_leave_the_trajectory_unchanged():
    """Sampling between steps, any split of advance calls, ``until`` and state()/restore()
    give the same bits as one uninterrupted advance (what a resumed run relies on)."""
    reference = _couette()
    reference.advance(120)
    sampled = _couette()
    for _ in range(4):
        sampled.advance(30)
        sampled.sample(), sampled.profiles(3), sampled.branch_statistics(), sampled.dt
    halfway = _couette()
    halfway.advance(70)
    restored = _couette()
    restored.advance(3)
    restored.restore(halfway.state())
    restored.advance(50)
    until = _couette()
    until.advance(500, until=reference.time)
    for sim in (sampled, restored, until):
        assert sim.step_count == 120
        for name in ("positions_all", "velocity_all", "rho_all", "f_all", "wall", "clock"):
            np.testing.assert_array_equal(getattr(sim, name), getattr(reference, name), name)


def test_until_stops_on_the_first_step_at_or_past_the_time():
    sim = _couette()
    sim.advance(10)
    target = sim.time + 2.5 * sim.last_dt
    sim.advance(100, until=target)
    assert sim.step_count == 13 and sim.time >= target > sim.time - 1.5 * sim.last_dt
    sim.advance(100, until=target)  # already there: no step
    assert sim.step_count == 13
