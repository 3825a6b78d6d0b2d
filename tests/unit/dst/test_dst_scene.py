"""DST scene files: dispatch, defaults and their resolution, round trip, shipped examples."""
from pathlib import Path

import pytest
import yaml
from jsonschema import Draft202012Validator

from suspsim.dst.scene import DST_SCENE_SCHEMA, DSTScene, dst_scene_from_dict, is_dst_scene
from suspsim.errors import InputError
from suspsim.scene import Scene, load_any_scene

ROOT = Path(__file__).resolve().parents[3]
MINIMAL = dict(dimension=2, box=[1.0, 1.0],
               fluid={"law": "wyart_cates", "params": dict(
                   eta_s=1.0, phi=0.54, phi_m=0.562, phi_0=0.693, sigma_star=1.0)},
               flow={"type": "stress_couette", "stress": 2.5}, run={"strain": 3})


def _properties(schema, path=()):
    for name, sub in schema.get("properties", {}).items():
        yield path + (name,), sub, name in schema.get("required", ())
        yield from _properties(sub, path + (name,))


def test_schema_is_valid_and_documents_every_key():
    Draft202012Validator.check_schema(DST_SCENE_SCHEMA)
    for path, sub, required in _properties(DST_SCENE_SCHEMA):
        assert sub.get("description"), path
        if not required and path not in {("run", "strain"), ("run", "time")}:
            assert "default" in sub, path


def test_minimal_scene_resolves_the_documented_defaults():
    scene = dst_scene_from_dict(MINIMAL)
    fluid, geo, num, run = scene.fluid, scene.geometry, scene.numerics, scene.run
    assert (fluid.beta, fluid.K_f, fluid.alpha) == (2.0, 1.0, 0.0)
    assert (geo.n_x, geo.n_y, geo.gap, geo.smoothing_ratio, geo.wall_layers) == (20, 20, 1.0,
                                                                                 1.1, 4)
    rate = fluid.shear_rate(2.5)
    assert scene.nominal_shear_rate == rate
    # ε = 0.1 = K_f γ̇ ρ L_y²/η, as suspsim.dst.study.flow_curve
    assert num.density == pytest.approx(0.1 * 2.5 / rate ** 2)
    assert (num.sound_speed, num.viscous_number, num.courant, num.shifting) == (None, 0.3, 0.25,
                                                                                False)
    assert (run.output_interval, run.transient, run.profile_bins, run.threads) == (0.05, 1.5,
                                                                                   20, 1)
    assert scene.total_time == pytest.approx(3 / rate)
    assert scene.units == "scene" and scene.flow.wall_mass is None


def test_round_trip_and_threads_do_not_change_the_hash():
    from suspsim.io.checkpoint import scene_hash

    scene = dst_scene_from_dict(MINIMAL)
    again = dst_scene_from_dict(yaml.safe_load(yaml.safe_dump(scene.to_dict())))
    assert again == scene
    other = dict(MINIMAL, run={"strain": 3, "threads": 2, "checkpoint_interval_s": 5},
                 numerics={"max_mach": 0.2})
    assert scene_hash(dst_scene_from_dict(other)) == scene_hash(scene)
    assert scene_hash(dst_scene_from_dict(dict(MINIMAL, resolution=25))) != scene_hash(scene)


def test_shifting_coefficient_and_channel_keys():
    scene = dst_scene_from_dict(dict(MINIMAL, numerics={"shifting": 1.5}))
    assert scene.numerics.shifting and scene.numerics.shifting_coefficient == 1.5
    channel = dst_scene_from_dict(dict(MINIMAL, flow={"type": "channel", "body_force": 3.0},
                                       run={"time": 2.0}, numerics={"density": 2.0}))
    assert channel.flow_type == "channel" and channel.flow.body_force == 3.0
    assert channel.run.output_interval == pytest.approx(0.01) and channel.total_time == 2.0


def test_dispatch_between_the_solvers(tmp_path):
    assert is_dst_scene(MINIMAL) and not is_dst_scene({"fluid": {"law": "newtonian"}})
    sph = tmp_path / "sph.yaml"
    sph.write_text("dimension: 2\nbox: [4, 4]\nnumber_density: 4\n"
                   "fluid: {law: newtonian, params: {mu: 1}}\n"
                   "flow: {type: couette, shear_rate: 0.1}\nrun: {strain: 2}\n")
    assert isinstance(load_any_scene(sph), Scene)
    with pytest.raises(InputError, match=r"\[key 'fluid.params.phi_m'\]: need 0 < phi_m"):
        dst_scene_from_dict(dict(MINIMAL, fluid={"law": "wyart_cates", "params": dict(
            MINIMAL["fluid"]["params"], phi_m=0.8)}))


@pytest.mark.parametrize("name", ["dst_stress_couette.yaml", "dst_channel.yaml"])
def test_shipped_examples_are_valid(name):
    scene = load_any_scene(ROOT / "config" / "scenes" / name)
    assert isinstance(scene, DSTScene) and scene.geometry.n_y == 20


def test_shipped_3d_example_is_valid():
    scene = load_any_scene(ROOT / "config" / "scenes" / "dst_stress_couette_3d.yaml")
    geo = scene.geometry
    assert scene.dimension == 3 and (geo.n_x, geo.n_y, geo.n_z) == (13, 8, 13)


def test_three_dimensional_scene_sets_the_z_lattice():
    scene = dst_scene_from_dict(dict(MINIMAL, dimension=3, box=[1.0, 1.0, 0.75]))
    geo = scene.geometry
    assert scene.dimension == geo.dimension == 3 and scene.box == (1.0, 1.0, 0.75)
    assert (geo.n_x, geo.n_y, geo.n_z, geo.depth) == (20, 20, 15, pytest.approx(0.75))
    assert dst_scene_from_dict(MINIMAL).geometry.n_z is None


@pytest.mark.parametrize("dimension, box, key, words", [
    (3, [1.0, 1.0], r"\[key 'box'\]", "a 3-D scene needs 3 box lengths (x, y, z), got 2"),
    (2, [1.0, 1.0, 1.0], r"\[key 'box'\]", "a 2-D scene needs 2 box lengths (x, y), got 3"),
    (3, [1.0, 1.0, 0.73], r"\[key 'box\[2\]'\]", "not a whole number of lattice spacings"),
    (3, [1.0, 1.0, 0.5], r"\[key 'box\[2\]'\]", "periodic direction needs at least 13"),
])
def test_bad_box_names_the_key(dimension, box, key, words):
    with pytest.raises(InputError, match=key) as error:
        dst_scene_from_dict(dict(MINIMAL, dimension=dimension, box=box))
    assert words in str(error.value)
