"""Sand grains at φ = 0.3 in the linear-polymer matrix at 10 1/s stay apart and calm (issue 4).

The sand study's scene (config/studies/sand.yaml: a = 2.5 h, box 16.875 h, packing seed 1,
gap ≥ 0.05 h): with lubrication between volume-equivalent spheres it reported "bodies overlap
(smallest gap −0.929 h)" at step 2, the capped repulsion drove the grains to |V| ≈ 2.5 h/τ
(30 times the wall speed) and the run blew up at step ~70. With the closest points of the
grains (bodies.grain_lubrication_pass) the gaps stay positive, no body outruns the walls and
the fluid's density error stays under the run's limit.

Slow (packing and set-up ≈ 35 s, then ≈ 0.03 s a step: 43 s reduced, 37 s full on a quiet core);
``SUSPSIM_REDUCED=1`` runs 60 steps instead of 300.
"""
import os

import numpy as np
import pytest

from suspsim.rheology.laws import make_law
from suspsim.sph.lattice import imposed_velocity
from suspsim.sph.simulation import Simulation
from suspsim.stages.pack import Particles
from suspsim.stages.simulate import Resolution, simulation_scene

pytestmark = pytest.mark.slow
REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
#: The linear polymer's Carreau–Yasuda fit (results/sand/linear_polymer/fit.json; SI units).
MATRIX = {"mu_0": 2.1054134658718944, "mu_inf": 8.042307660751053e-08,
          "lam": 0.10198992369946352, "a": 0.8640718531766323, "n": 0.2994569788067771}


def test_sand_at_phi_0_3_keeps_its_gaps():
    law = make_law("carreau_yasuda", MATRIX)
    resolution = Resolution(box=16.875, number_density=4.096, strain=8, transient=2)
    scene, _ = simulation_scene(law, 10.0, volume_fraction=0.3, seed=1, resolution=resolution,
                                particles=Particles(shape="sand", radius=2.5,
                                                    polydispersity=0.0, size_ratio=5.0))
    sim = Simulation(scene, threads=1)
    wall_speed = 0.5 * scene.flow.shear_rate * scene.box[1]
    smallest = np.inf
    for _ in range((60 if REDUCED else 300) // 2):
        sim.advance(2)
        ok, message = sim.health()
        assert ok, message
        smallest = min(smallest, sim._lubrication_stats[0])
        bodies = sim.bodies
        peculiar = bodies.velocities.copy()
        peculiar[:, 0] -= imposed_velocity(scene, bodies.centres[:, 1])
        assert np.abs(peculiar).max() < wall_speed, f"step {sim.step_count}"
    # the packing's radial gap is ≥ 0.05 h; the Euclidean gap is at most that and stays > 0
    assert 0.0 < smallest < 0.1
