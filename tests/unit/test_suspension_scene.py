"""The Newtonian suspension scene of suspsim.validation.suspension (shape, packing and
resolution studies): what it asks for is what the scene holds, with the inclusions' defaults."""
import pytest

from suspsim.scene_rules import AUTO_SHIFTING_WITH_INCLUSIONS
from suspsim.validation.suspension import (NUMBER_DENSITY, RATE, parse_overrides,
                                          suspension_scene)


@pytest.mark.parametrize("shape", ["sphere", "sand"])
def test_scene_holds_the_requested_bodies_in_the_newtonian_matrix(shape):
    scene = suspension_scene(shape=shape, phi=0.3, radius=2.5, box=16.875, seed=4, strain=5.0)
    assert scene.inclusions.present
    assert (scene.inclusions.shape, scene.inclusions.phi, scene.inclusions.radius) == (
        shape, 0.3, 2.5)
    assert scene.seed == 4 and scene.box == pytest.approx([16.875] * 3)
    assert scene.number_density == NUMBER_DENSITY and scene.flow.shear_rate == RATE
    assert float(scene.fluid.law.viscosity(RATE)) == 1.0
    # the suspension validation's numerics: shifting with the Newtonian bodies' A
    assert scene.numerics.shifting == AUTO_SHIFTING_WITH_INCLUSIONS
    assert scene.total_time == pytest.approx(5.0 / RATE)


def test_overrides_set_dotted_scene_keys_and_keep_the_rest():
    scene = suspension_scene(shape="sand", phi=0.5, radius=2.5, box=16.875, overrides={
        "run.sound_speed": 1.18, "inclusions.lubrication.min_gap": 0.05})
    assert scene.run.sound_speed == 1.18
    assert scene.inclusions.lubrication.min_gap == 0.05
    # the siblings of an overridden key keep their values
    assert (scene.inclusions.shape, scene.inclusions.phi) == ("sand", 0.5)
    assert scene.flow.shear_rate == RATE


def test_set_items_become_overrides_read_as_json():
    assert parse_overrides(["run.dt=0.1", 'inclusions.shape="sand"',
                            "inclusions.lubrication.friction=0.5"]) == {
        "run.dt": 0.1, "inclusions.shape": "sand", "inclusions.lubrication.friction": 0.5}
