"""The automatic sound speed of a dense suspension (``sph.timestep``): the viscous criterion
grows as sqrt(ḡ(φ_ref)/ḡ(φ)) with the bodies' mean gap above φ_ref, from the packing's own φ."""
import math

import pytest

from suspsim.scene import scene_from_dict
from suspsim.sph.simulation import Simulation
from suspsim.sph.timestep import (CLOSE_PACKING, CROWDING_REFERENCE_PHI, auto_sound_speed,
                                  crowding_factor, mean_gap)


def _scene(phi, **inclusions):
    return scene_from_dict({
        "dimension": 3, "box": [7.5] * 3, "number_density": 4.096,
        "fluid": {"law": "newtonian", "params": {"mu": 1.0}},
        "flow": {"type": "couette", "shear_rate": 0.004},
        "run": {"strain": 1.0, "start": "linear"},
        "inclusions": {"phi": phi, "radius": 1.5, **inclusions}})


def test_the_mean_gap_closes_at_close_packing_and_the_factor_follows_it():
    assert mean_gap(CLOSE_PACKING) == pytest.approx(0.01)
    assert mean_gap(CLOSE_PACKING / 8.0) == pytest.approx(1.0)
    assert crowding_factor(0.0) == crowding_factor(CROWDING_REFERENCE_PHI) == 1.0
    phis = [0.35, 0.4, 0.45, 0.5, 0.55]
    factors = [crowding_factor(phi) for phi in phis]
    assert all(a < b for a, b in zip(factors, factors[1:]))
    for phi, factor in zip(phis, factors):
        assert factor == pytest.approx(
            math.sqrt(mean_gap(CROWDING_REFERENCE_PHI) / mean_gap(phi)), rel=1e-14)


def test_the_viscous_criterion_takes_the_factor_and_the_mach_criterion_does_not():
    fluid = auto_sound_speed(_scene(0.0))
    assert fluid == pytest.approx(math.sqrt(0.004 / (4.096 * 1e-3)))
    assert auto_sound_speed(_scene(0.2)) == fluid
    assert auto_sound_speed(_scene(0.5)) == pytest.approx(fluid * crowding_factor(0.5))
    assert auto_sound_speed(_scene(0.5), phi=0.0) == fluid


def test_a_run_sets_its_sound_speed_from_the_packed_phi():
    sim = Simulation(_scene(0.4, min_gap=0.1), threads=1)
    assert sim.sound_speed == pytest.approx(
        auto_sound_speed(_scene(0.0)) * crowding_factor(sim.packing_phi), rel=1e-14)
    assert sim.sound_speed > auto_sound_speed(_scene(0.0))
