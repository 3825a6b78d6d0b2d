"""SPH fluid against exact flows (SPEC §6.1, §6.2): Couette viscosity, start-up, Poiseuille.

Slow; ``SUSPSIM_REDUCED=1`` (CI) runs smaller boxes. Rates and viscosities keep the particle
Reynolds number ρ γ̇ h²/μ(γ̇) = 0.1 (SPEC §7: the dimensionless law is what matters), the
Papanastasiou law keeps seed 000's μ_0/μ_pl = 99 and M = 100. Stresses are averaged over whole
strain units after one unit of transient (a sheared lattice oscillates with period one).
"""
import math
import os
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "unit" / "sph"))
from sph_helpers import couette_scene  # noqa: E402

from suspsim.reference.poiseuille import (force_density_for_bingham,  # noqa: E402
                                          split_force_poiseuille_profile)
from suspsim.rheology.laws import make_law  # noqa: E402
from suspsim.scene import scene_from_dict  # noqa: E402
from suspsim.sph.simulation import Simulation  # noqa: E402

pytestmark = pytest.mark.slow
REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
RE_PARTICLE = 0.1
DENSITY_3D, DENSITY_2D = 4.096, 6.25


def papanastasiou_params(rate, M=100.0):
    """μ_pl for particle Reynolds number 0.1 at ``rate``; μ_0 = 99 μ_pl (seed 000)."""
    x = M * rate
    mu_pl = DENSITY_3D * rate / (RE_PARTICLE * (1.0 + 99.0 * -math.expm1(-x) / x))
    return {"mu_pl": mu_pl, "mu_0": 99.0 * mu_pl, "M": M}


def measured_viscosity_ratio(scene, transient=1, units=3):
    """σ_xy/(μ(γ̇) γ̇) averaged over ``units`` whole strain units after ``transient``."""
    sim = Simulation(scene, threads=2)
    rate = scene.flow.shear_rate
    per_unit = int(round(1.0 / (rate * sim.dt)))
    sim.advance(transient * per_unit)
    stride = max(1, per_unit // 50)
    stresses = []
    for _ in range(units * per_unit // stride):
        sim.advance(stride)
        stresses.append(sim.sample()["shear_stress"])
    ok, message = sim.health()
    assert ok, message
    return np.mean(stresses) / (float(scene.fluid.law.viscosity(rate)) * rate), sim


@pytest.mark.parametrize("dim", [3, 2])
def test_newtonian_couette_viscosity(dim):
    density = DENSITY_3D if dim == 3 else DENSITY_2D
    side = (5.0 if REDUCED else 7.5) if dim == 3 else (6.0 if REDUCED else 10.0)
    rate = RE_PARTICLE / density
    ratio, sim = measured_viscosity_ratio(couette_scene(dim, side, density, rate=rate,
                                                        jitter=0.1))
    assert ratio == pytest.approx(1.0, abs=0.015)
    profile = sim.profiles(5)
    expected = rate * (profile["y"] - 0.5 * side)
    assert np.max(np.abs(profile["velocity_profile"] - expected)) < 0.03 * rate * side


@pytest.mark.parametrize("rate", [0.001, 0.01, 0.1])
def test_papanastasiou_couette_viscosity_over_three_decades(rate):
    scene = couette_scene(3, 5.0 if REDUCED else 7.5, DENSITY_3D, law="papanastasiou",
                          params=papanastasiou_params(rate), rate=rate, jitter=0.1)
    ratio, _ = measured_viscosity_ratio(scene)
    assert ratio == pytest.approx(1.0, abs=0.03)


def papanastasiou_startup(bingham=0.1, side=7.5, strain=3.0, samples=30, bins=12):
    """Seed 000 Fig. 1: Papanastasiou Couette from rest at Bingham number Bn = μ_0/(M μ_pl γ̇).

    Returns {"strain": (S,), "y": (B,), "velocity": (S, B) v_x/(γ̇ L_y)} with y measured from
    the zero-velocity plane; early profiles are flat in the middle (high viscosity at low
    local rate) and steep near the sheared faces, late ones linear.
    """
    M, ratio = 100.0, 99.0
    rate = ratio / (M * bingham)
    mu_pl = DENSITY_3D * rate / (RE_PARTICLE * (1.0 + ratio / (M * rate)))
    scene = couette_scene(3, side, DENSITY_3D, law="papanastasiou",
                          params={"mu_pl": mu_pl, "mu_0": ratio * mu_pl, "M": M}, rate=rate,
                          start="rest")
    sim = Simulation(scene, threads=2)
    steps = max(1, int(round(strain / (rate * sim.dt) / samples)))
    out_strain, out_velocity = [], []
    for _ in range(samples):
        sim.advance(steps)
        out_strain.append(sim.strain)
        out_velocity.append(sim.profiles(bins)["velocity_profile"] / (rate * side))
    y = sim.profiles(bins)["y"] - 0.5 * side
    return {"strain": np.array(out_strain), "y": y, "velocity": np.array(out_velocity)}


def test_papanastasiou_startup_develops_the_linear_profile():
    data = papanastasiou_startup(side=5.0 if REDUCED else 7.5, strain=2.0, samples=10, bins=8)
    late = data["velocity"][-1]
    np.testing.assert_allclose(late, data["y"] / (5.0 if REDUCED else 7.5), atol=0.03)
    early = data["velocity"][0]
    middle = np.abs(data["y"]) < 0.2 * data["y"].max() * 2
    assert np.ptp(early[middle]) < np.ptp(late[middle])


def poiseuille_error(law, params, g, dim, density, height, t_run, t_avg):
    """L2 error relative to the peak of the time-averaged profile against SPEC §6.2, one bin
    per lattice row (bins misaligned with the rows alias the layering into the profile)."""
    bins = round(height * density ** (1 / dim))
    box = [5.0, height, 5.0] if dim == 3 else [8.0, height]
    scene = scene_from_dict({"dimension": dim, "box": box, "number_density": density,
                             "fluid": {"law": law, "params": params},
                             "flow": {"type": "poiseuille", "body_force": g},
                             "run": {"time": t_run}, "lattice": {"jitter": 0.1}})
    sim = Simulation(scene, threads=2)
    sim.advance(int((t_run - t_avg) / sim.dt))
    stride = max(1, int(t_avg / sim.dt) // 40)
    mean = 0.0
    for _ in range(40):
        sim.advance(stride)
        profile = sim.profiles(bins)
        mean = mean + profile["velocity_profile"] / 40
    ok, message = sim.health()
    assert ok, message
    ref = split_force_poiseuille_profile(scene.fluid.law, scene.density * g, height, profile["y"])
    return np.sqrt(np.mean((mean - ref) ** 2)) / np.max(np.abs(ref))


@pytest.mark.parametrize("dim, density", [(3, DENSITY_3D), (2, 16.0)])
def test_newtonian_poiseuille_profile(dim, density):
    """Re = ρ u_max W/μ ≈ 0.1 (μ = 1.25 ρ at g = 0.01, W = 5). At Re ≈ 40 the disordered
    lattice loses 10 % of the flow; in 2D at n = 6.25 the error is 5.6 % (open)."""
    height, g = 10.0, 0.01
    mu = 1.25 * density
    t_visc = density * (height / 2) ** 2 / mu
    error = poiseuille_error("newtonian", {"mu": mu}, g, dim, density, height, 3 * t_visc,
                             t_visc)
    assert error < 0.03


BINGHAM_LAW = {"mu_pl": 20.0, "mu_0": 99.0 * 20.0, "M": 100.0}  # Re ≈ 0.1 at Bn = 1


@pytest.mark.parametrize("bingham", [
    1.0,
    pytest.param(10.0, marks=pytest.mark.xfail(
        reason="open: 29 % L2 at W = 5 h, the yielded layer (0.9 h) is under-resolved", strict=True))])
def test_bingham_poiseuille_profile(bingham):
    """Papanastasiou (seed 000: μ_0/μ_pl = 99, M = 100) in split-force Poiseuille, W = 5 h."""
    height = 10.0
    law = make_law("papanastasiou", BINGHAM_LAW)
    force = force_density_for_bingham(law, height / 2, bingham)
    t_visc = DENSITY_3D * (height / 2) ** 2 / BINGHAM_LAW["mu_pl"]
    error = poiseuille_error("papanastasiou", BINGHAM_LAW, force / DENSITY_3D, 3, DENSITY_3D,
                             height, 0.8 * t_visc, 0.2 * t_visc)
    assert error < 0.03
