"""The pack stage: particle settings from study and material sheet, one study packing, the same
packing a scene makes for itself, sand through the same path, errors naming the config key."""
import math

import numpy as np
import pytest

from suspsim.errors import InputError
from suspsim.io.packing_file import read_packing
from suspsim.rheology.laws import make_law
from suspsim.sph.inclusions import scene_packing
from suspsim.stages.pack import (STUDY_MIN_GAP, Particles, particle_settings,
                                 write_study_packing)
from suspsim.stages.simulate import Resolution, simulation_scene

STUDY = {"shape": "sphere", "radius": 2.5, "polydispersity": 0.0, "size_ratio": 5.0}
SMALL = Particles(radius=1.0)


def test_sheet_overrides_the_study_and_gives_the_physical_radius():
    assert particle_settings(STUDY) == Particles()
    assert particle_settings(STUDY, {"shape": None, "polydispersity": None}) == Particles()
    merged = particle_settings({**STUDY, "friction": 0.5, "rolling_friction": 0.2},
                               {"shape": "sand", "polydispersity": 0.3, "size_ratio": 3,
                                "radius_m": 2e-4, "friction": 0.7, "rolling_friction": None})
    assert merged == Particles(shape="sand", radius=2.5, polydispersity=0.3, size_ratio=3,
                               physical_radius=2e-4, friction=0.7, rolling_friction=0.2)
    assert particle_settings({**STUDY, "friction": 0.5}).friction == 0.5
    assert particle_settings(STUDY, {"rolling_friction": 0.1}).rolling_friction == 0.1
    assert Particles.from_mapping(merged.to_dict()) == merged


def test_bad_particle_settings_are_input_errors():
    with pytest.raises(InputError, match="unknown shape 'cube'"):
        Particles(shape="cube")
    with pytest.raises(InputError, match="physical_radius must be positive"):
        Particles(physical_radius=0.0)
    with pytest.raises(InputError, match="friction must be >= 0"):
        Particles(friction=-0.1)
    with pytest.raises(InputError, match="rolling_friction must be >= 0"):
        Particles(rolling_friction=math.nan)
    with pytest.raises(InputError, match="unknown key"):
        Particles.from_mapping({"radius": 1.0, "colour": "red"})


def test_study_packing_is_the_one_the_scene_would_make(tmp_path):
    out = tmp_path / "phi-0.1_seed-3.nc"
    made = write_study_packing(out, volume_fraction=0.1, seed=3, box=5.0, particles=SMALL)
    packing = read_packing(out)
    assert packing.shape == "sphere" and packing.seed == 3 and packing.count == made.count
    assert packing.box.tolist() == [5.0, 5.0, 5.0]
    assert packing.volume_fraction == pytest.approx(0.1, rel=1e-12)
    assert packing.min_gap == STUDY_MIN_GAP == 0.05
    law = make_law("newtonian", {"mu": 1.0})
    scene, _ = simulation_scene(law, 1.0, volume_fraction=0.1, seed=3, particles=SMALL,
                                resolution=Resolution(box=5, number_density=4.096, strain=3,
                                                      transient=1))
    itself = scene_packing(scene)
    np.testing.assert_array_equal(itself.centres, packing.centres)
    np.testing.assert_array_equal(itself.radii, packing.radii)


def test_sand_flows_through_the_same_stage(tmp_path):
    out = tmp_path / "sand.nc"
    write_study_packing(out, volume_fraction=0.1, seed=2, box=8.0,
                        particles={"shape": "sand", "radius": 1.0, "polydispersity": 0.2,
                                   "size_ratio": 3.0, "physical_radius": None})
    packing = read_packing(out)
    assert packing.shape == "sand" and packing.coefficients is not None
    assert packing.polydispersity == 0.2 and packing.size_ratio == 3.0
    assert packing.volume_fraction == pytest.approx(0.1, rel=1e-12)


@pytest.mark.parametrize("change, key", [
    ({"box": 5.0, "particles": Particles()}, "simulation.box"),
    ({"volume_fraction": 0.7}, "simulation.volume_fractions"),
    ({"particles": Particles(radius=1.0, size_ratio=9.0)}, "particles.size_ratio"),
])
def test_errors_name_the_config_key_and_write_nothing(tmp_path, change, key):
    arguments = {"volume_fraction": 0.1, "seed": 1, "box": 5.0, "particles": SMALL} | change
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        write_study_packing(tmp_path / "p.nc", **arguments)
    assert list(tmp_path.iterdir()) == []
