"""Sand grains at φ = 0.3 in the linear-polymer matrix at 10 1/s stay apart and calm (issue 4).

The sand study's scene (config/studies/sand.yaml: a = 2.5 h, box 16.875 h, packing seed 1,
gap ≥ 0.05 h): with lubrication between volume-equivalent spheres it reported "bodies overlap
(smallest gap −0.929 h)" at step 2, the capped repulsion drove the grains to |V| ≈ 2.5 h/τ
(30 times the wall speed) and the run blew up at step ~70. With the closest points of the
grains (bodies.grain_lubrication_pass) the gaps stay positive, no body outruns the walls and
the fluid's density error stays under the run's limit.

Dense sand (φ = 0.5, the sand/spheres comparison's Newtonian scene) runs with :data:`DENSE`:
its gaps stay positive, its density error under the limit and its grains at the flow's speed.

Slow (φ = 0.3: packing and set-up ≈ 35 s, then ≈ 0.03 s a step: 43 s reduced, 37 s full on a
quiet core; φ = 0.5: set-up ≈ 23 s, then ≈ 0.025 s a step: 30 s reduced, 48 s full);
``SUSPSIM_REDUCED=1`` runs 60 steps instead of 300 at φ = 0.3, 300 instead of 1000 at 0.5.
"""
import os

import numpy as np
import pytest

from suspsim.rheology.laws import make_law
from suspsim.sph.lattice import imposed_velocity
from suspsim.sph.simulation import Simulation
from suspsim.stages.pack import Particles
from suspsim.stages.simulate import Resolution, simulation_scene
from suspsim.validation.suspension import suspension_scene

pytestmark = pytest.mark.slow
REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
#: The linear polymer's Carreau–Yasuda fit (results/sand/linear_polymer/fit.json; SI units).
MATRIX = {"mu_0": 2.1054134658718944, "mu_inf": 8.042307660751053e-08,
          "lam": 0.10198992369946352, "a": 0.8640718531766323, "n": 0.2994569788067771}
def _shear(sim: Simulation, steps: int) -> tuple[float, float, float]:
    """Advance ``sim`` by ``steps``, asserting its health every 2 steps; (smallest surface gap
    [h], largest fluid density error [1], largest body velocity component relative to the
    imposed flow over the wall speed γ̇L_y/2 [1]) over those checks."""
    scene = sim.scene
    wall_speed = 0.5 * scene.flow.shear_rate * scene.box[1]
    smallest, density_error, speed = np.inf, 0.0, 0.0
    for _ in range(steps // 2):
        sim.advance(2)
        ok, message = sim.health()
        assert ok, message
        smallest = min(smallest, sim._lubrication_stats[0])
        density_error = max(density_error, sim.sample()["density_error"])
        bodies = sim.bodies
        peculiar = bodies.velocities.copy()
        peculiar[:, 0] -= imposed_velocity(scene, bodies.centres[:, 1])
        speed = max(speed, np.abs(peculiar).max() / wall_speed)
    return smallest, density_error, speed


def test_sand_at_phi_0_3_keeps_its_gaps():
    law = make_law("carreau_yasuda", MATRIX)
    resolution = Resolution(box=16.875, number_density=4.096, strain=8, transient=2)
    scene, _ = simulation_scene(law, 10.0, volume_fraction=0.3, seed=1, resolution=resolution,
                                particles=Particles(shape="sand", radius=2.5,
                                                    polydispersity=0.0, size_ratio=5.0))
    smallest, _, speed = _shear(Simulation(scene, threads=1), 60 if REDUCED else 300)
    # no body outruns the walls relative to the flow (the blow-up: 30 times the wall speed)
    assert speed < 1.0
    # the packing's radial gap is ≥ 0.05 h; the Euclidean gap is at most that and stays > 0
    assert 0.0 < smallest < 0.1


def test_dense_sand_at_phi_0_5_runs_with_the_defaults():
    """37 grains at φ = 0.5 in the Newtonian scene of the sand/spheres comparison
    (validation.suspension, packing seed 1), with the defaults: the sound speed raised by the
    crowding factor (``sph.timestep``: 1.83 × 0.988 h/τ) and lubrication held from s_min =
    0.05 h. Before them (c = 0.988 h/τ, s_min = 0.02 h) this packing stopped at step 792 (density
    error 0.301 > 0.3) and, with that limit raised to 0.5, at step 816 (bodies overlap, gap
    −0.031 h); with the crowding factor alone it overlapped at step 4981 (gap −0.007 h)."""
    scene = suspension_scene(shape="sand", phi=0.5, radius=2.5, box=16.875, seed=1)
    smallest, density_error, speed = _shear(Simulation(scene, threads=1),
                                            300 if REDUCED else 1000)
    # measured: smallest gap 0.074 h, density error 0.198, speed 0.35 of the wall's (1000
    # steps); 0.074 h, 0.198, 0.28 (300 steps)
    assert 0.0 < smallest < 0.1
    assert density_error < scene.run.max_density_error
    assert speed < 1.0
