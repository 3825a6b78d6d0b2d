"""Shared set-up of the SPH solver tests: small scenes and operator evaluation on fields."""
import numpy as np

from suspsim.scene import scene_from_dict
from suspsim.sph.simulation import Simulation
from suspsim.validation.flows import couette_viscosity_ratio


def couette_scene(dim=3, side=5.0, number_density=4.096, law="newtonian", params=None,
                  rate=0.05, jitter=0.0, normalise=True, bulk=True, seed=1, interval=None,
                  spin=False, **run):
    run_keys = {"strain": 1.0, **run}
    numerics = {"viscous_normalisation": normalise, "bulk_correction": bulk,
                "spin_correction": spin}
    if interval is not None:
        numerics["normalisation_interval"] = interval
    return scene_from_dict({
        "dimension": dim, "box": [side] * dim, "number_density": number_density,
        "fluid": {"law": law, "params": params or {"mu": 1.0}},
        "flow": {"type": "couette", "shear_rate": rate}, "run": run_keys,
        "lattice": {"jitter": jitter}, "seed": seed,
        "numerics": numerics})


def relaxed_simulation(dim=3, side=5.0, number_density=4.096, jitter=0.0, relax_steps=0,
                       **kw):
    """A simulation whose particles relaxed ``relax_steps`` steps from a jittered lattice."""
    sim = Simulation(couette_scene(dim, side, number_density, rate=1e-6, jitter=jitter, **kw),
                     threads=1)
    if relax_steps:
        sim.advance(relax_steps)
    return sim


def evaluate(sim, velocity, viscosity, normalise, bulk_gradient=False):
    """Accelerations ρa (the viscous force density: c = 0), corrected gradient, γ̇ and s of
    the fields ``velocity(ξ)`` (N, 3) and ``viscosity(ξ)`` (N,) at ξ = r − box centre."""
    centre = 0.5 * np.array(sim.scene.box + ((0.0,) if sim.scene.dimension == 2 else ()))
    xi = sim._x - centre
    sim._v[:] = velocity(xi)
    sim._mu[:] = viscosity(xi)
    sim._mu_hat[:] = sim._mu
    sim._normalise = normalise
    sim._velocity_gradient = True
    sim._bulk_gradient = bulk_gradient
    sim._force_views()
    sim.sound_speed = 0.0
    sim._normalisation_age[0] = 0  # s of these fields, not one held from an earlier step
    out = np.zeros_like(sim._x)
    sim._compute_accelerations(sim._v, out)
    return xi, out * sim._rho[:, None], sim._gradient.reshape(-1, 3, 3).copy(), sim._gdot.copy()


def shear_squared(xi):
    """v_x = y²: μ∇²v = 2μ e_x."""
    v = np.zeros_like(xi)
    v[:, 0] = xi[:, 1] ** 2
    return v


def constant(xi):
    """μ = 1 everywhere."""
    return np.ones(len(xi))


def interior(sim, xi, margin=1.25):
    """Particles whose whole neighbourhood lies inside the box (no image pairs)."""
    half = 0.5 * np.array(sim.scene.box)
    d = sim.scene.dimension
    return np.all(np.abs(xi[:, :d]) < half - margin, axis=1)


def measured_viscosity_ratio(scene, transient=1, units=3, threads=2):
    """(σ_xy/(μ(γ̇) γ̇) averaged over ``units`` whole strain units after ``transient``, the
    simulation); raises NumericalError if the run left its limits. Two threads: CI's cores."""
    sim = Simulation(scene, threads=threads)
    return 1.0 + couette_viscosity_ratio(sim, transient=transient, units=units).value, sim
