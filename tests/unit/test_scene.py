"""Scene files: defaults, one-line errors naming key and line, round trips."""
import json

import numpy as np
import pytest
import yaml
from jsonschema import Draft202012Validator

from suspsim.errors import InputError
from suspsim.io.yamlfile import load_yaml
from suspsim.rheology.laws import ConstitutiveLaw
from suspsim.scene import SCENE_SCHEMA, load_scene, scene_from_dict

MINIMAL = """\
dimension: 3                 # 2 or 3
box: [12, 12, 12]            # lengths in units of the kernel support h
number_density: 4.0          # particles per h^dimension (mass m = 1)
kernel: lucy                 # lucy | quintic
fluid:
  law: papanastasiou
  params: {mu_pl: 1.0, mu_0: 99.0, M: 100.0}
flow:
  type: couette
  shear_rate: 0.01
  body_force: 0.0
run:
  strain: 10
  dt: auto
  sound_speed: auto
seed: 1
"""

POISEUILLE_2D = """\
dimension: 2
box: [4, 16]
number_density: 4
fluid: {law: newtonian, params: {mu: 2.5}}
flow: {type: poiseuille, body_force: 1e-3}
run: {time: 400, threads: 2}
numerics: {wi_target: 1e-4, bulk_correction: no}
"""


def _write(tmp_path, text, name="scene.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _edit(old, new):
    assert old in MINIMAL, old
    return MINIMAL.replace(old, new)


def test_minimal_scene_gets_every_default(tmp_path):
    scene = load_scene(_write(tmp_path, MINIMAL.replace("kernel: lucy", "").replace("seed: 1", "")))
    assert scene.dimension == 3 and scene.box == (12.0, 12.0, 12.0) and scene.kernel == "lucy"
    assert isinstance(scene.fluid.law, ConstitutiveLaw) and scene.fluid.law.name == "papanastasiou"
    assert scene.fluid.law.params["mu_0"] == 99.0 and scene.density == 4.0 and scene.seed == 1
    assert (scene.flow.type, scene.flow.shear_rate, scene.flow.body_force) == ("couette", 0.01, 0.0)
    run = scene.run
    assert (run.strain, run.time, run.dt, run.sound_speed, run.threads) == (10.0, None, None, None, None)
    assert (run.start, run.output_interval, run.transient, run.profile_bins) == ("linear", 0.05, 5.0, 12)
    assert (run.checkpoint_interval_s, run.max_density_error, run.max_mach) == (300.0, 0.05, 0.3)
    assert scene.lattice.jitter == 0.0 and scene.inclusions.phi == 0.0 and not scene.inclusions.present
    assert scene.numerics.bulk_correction is True and scene.numerics.viscous_normalisation is True
    assert (scene.numerics.wi_target, scene.numerics.dt_viscous_coefficient) == (1e-3, 0.05)
    assert scene.total_time == pytest.approx(1000.0) and scene.transient_time == pytest.approx(500.0)
    assert scene.output_interval_time == pytest.approx(5.0) and scene.lattice_counts == (19, 19, 19)


def test_poiseuille_2d_resolves_time_defaults(tmp_path):
    scene = load_scene(_write(tmp_path, POISEUILLE_2D))
    assert scene.run.start == "rest" and scene.run.threads == 2 and scene.run.strain is None
    assert scene.run.output_interval == pytest.approx(2.0) and scene.run.transient == 200.0
    assert scene.flow.body_force == 1e-3 and scene.numerics.wi_target == 1e-4
    assert scene.numerics.bulk_correction is False and scene.lattice_counts == (8, 32)
    assert scene.run.profile_bins == 16 and scene.total_time == 400.0


def test_couette_by_time_samples_every_005_strain(tmp_path):
    scene = load_scene(_write(tmp_path, _edit("strain: 10", "time: 2000")))
    assert scene.run.output_interval == pytest.approx(5.0) and scene.transient_time == 1000.0


@pytest.mark.parametrize("text", [MINIMAL, POISEUILLE_2D])
def test_to_dict_round_trips(tmp_path, text):
    scene = load_scene(_write(tmp_path, text))
    complete = scene.to_dict()
    assert json.loads(json.dumps(complete)) == complete
    assert scene_from_dict(complete) == scene
    assert load_scene(_write(tmp_path, yaml.safe_dump(complete), "again.yaml")) == scene
    assert scene_from_dict(complete).to_dict() == complete


BAD = [
    # (id, scene text, key, line or None, words the message must hold)
    ("missing top-level key", _edit("number_density: 4.0          # particles per h^dimension (mass m = 1)\n",
                                    ""),
     "number_density", None, "missing key"),
    ("missing nested key", _edit("  type: couette\n", ""), "flow.type", 8, "missing key"),
    ("negative box", _edit("[12, 12, 12]", "[12, -12, 12]"), "box[1]", 2, "> 0"),
    ("unknown law", _edit("law: papanastasiou", "law: bingham"), "fluid.law", 6, "unknown law"),
    ("volume fraction above 1", MINIMAL + "inclusions: {phi: 1.2}\n",
     "inclusions.phi", 17, "< 0.64"),
    ("unknown inclusion shape", MINIMAL + "inclusions: {shape: cube, phi: 0.1}\n",
     "inclusions.shape", 17, "sphere"),
    ("non-numeric shear rate", _edit("shear_rate: 0.01", "shear_rate: fast"), "flow.shear_rate", 10,
     "not a number"),
    ("non-numeric box entry", _edit("[12, 12, 12]", "[12, abc, 12]"), "box[1]", 2, "not a number"),
    ("non-numeric law parameter", _edit("mu_0: 99.0", "mu_0: lots"), "fluid.params.mu_0", 7, "not a number"),
    ("unknown top-level key", MINIMAL + "colour: red\n", "colour", 17, "unknown key"),
    ("unknown nested key", _edit("  dt: auto", "  dtt: auto"), "run.dtt", 14, "did you mean 'dt'"),
    ("unknown numerics key", MINIMAL + "numerics:\n  smoothing: true\n", "numerics.smoothing", 18,
     "unknown key"),
    ("strain and time", _edit("  strain: 10", "  strain: 10\n  time: 100"), "run.time", 14, "not both"),
    ("no run length", _edit("  strain: 10\n", ""), "run.strain", 12, "run length"),
    ("couette without shear rate", _edit("  shear_rate: 0.01\n", ""), "flow.shear_rate", 8, "> 0"),
    ("couette with body force", _edit("body_force: 0.0", "body_force: 0.1"), "flow.body_force", 11,
     "no body force"),
    ("poiseuille with strain", _edit("type: couette\n  shear_rate: 0.01\n  body_force: 0.0",
                                     "type: poiseuille\n  body_force: 0.1"), "run.strain", 12, "run.time"),
    ("poiseuille without force", _edit("type: couette\n  shear_rate: 0.01\n", "type: poiseuille\n")
     .replace("strain: 10", "time: 10"), "flow.body_force", 10, "> 0"),
    ("box too small", _edit("[12, 12, 12]", "[12, 3.5, 12]"), "box[1]", 2, "three cells"),
    ("2-D with 3 box entries", _edit("dimension: 3", "dimension: 2"), "box", 2, "2 box lengths"),
    ("law parameter out of range", _edit("M: 100.0", "M: -1"), "fluid.params.M", 7, "outside"),
    ("law parameter missing", _edit("mu_pl: 1.0, ", ""), "fluid.params", 7, "missing parameter mu_pl"),
    ("unknown law parameter", _edit("M: 100.0", "M: 100.0, K: 1"), "fluid.params", 7, "unknown parameter"),
    ("unknown kernel", _edit("kernel: lucy", "kernel: gaussian"), "kernel", 4, "lucy, quintic"),
    ("dimension 4", _edit("dimension: 3", "dimension: 4"), "dimension", 1, "one of 2, 3"),
    ("numerics switch not a bool", MINIMAL + "numerics: {bulk_correction: 3}\n",
     "numerics.bulk_correction", 17, "true or false"),
    ("lattice off the density", _edit("[12, 12, 12]", "[10, 10, 10]").replace("4.0 ", "3.0 "),
     "number_density", 3, "multiples of the spacing"),
    ("transient longer than run", _edit("  dt: auto", "  transient: 12"), "run.transient", 14, "nothing"),
    ("dt neither number nor auto", _edit("dt: auto", "dt: fast"), "run.dt", 14, "> 0 or 'auto'"),
    ("duplicate key", MINIMAL + "seed: 2\n", "seed", 17, "duplicate key (first given on line 16)"),
    ("jitter too large", MINIMAL + "lattice: {jitter: 0.7}\n", "lattice.jitter", 17, "≤ 0.5"),
    ("negative seed", _edit("seed: 1", "seed: -1"), "seed", 16, "≥ 0"),
    ("non-finite number", _edit("4.0 ", ".nan "), "number_density", 3, "finite"),
    ("zero threads", _edit("  dt: auto", "  threads: 0"), "run.threads", 14, "an integer ≥ 1 or 'all'"),
    ("poiseuille started linear", POISEUILLE_2D.replace("threads: 2", "start: linear"), "run.start", 6,
     "starts from rest"),
    ("outlier ceiling below the limit", _edit("  dt: auto", "  max_density_error: 0.3\n"
                                              "  max_outlier_density_error: 0.2"),
     "run.max_outlier_density_error", 15, "at least the limit"),
]


@pytest.mark.parametrize("text, key, line, words", [case[1:] for case in BAD], ids=[c[0] for c in BAD])
def test_bad_scene_names_key_and_line(tmp_path, text, key, line, words):
    path = _write(tmp_path, text)
    with pytest.raises(InputError) as caught:
        load_scene(path)
    err, message = caught.value, str(caught.value)
    assert (err.key, err.line) == (key, line), message
    assert words in message and "\n" not in message
    assert message.startswith(f"{path}:{line} " if line else f"{path} ")
    assert f"[key {key!r}]" in message


@pytest.mark.parametrize("text, key, line, words", [case[1:] for case in BAD if case[0] != "duplicate key"],
                         ids=[c[0] for c in BAD if c[0] != "duplicate key"])
def test_bad_dict_names_key_without_line(tmp_path, text, key, line, words):
    data, _ = load_yaml(_write(tmp_path, text))
    with pytest.raises(InputError) as caught:
        scene_from_dict(data)
    assert (caught.value.key, caught.value.line, caught.value.source) == (key, None, "<dict>")
    assert words in str(caught.value)


def test_invalid_yaml_gives_its_line(tmp_path):
    with pytest.raises(InputError, match=r"scene.yaml:3: not valid YAML"):
        load_scene(_write(tmp_path, _edit("[12, 12, 12]            #", "[12, 12, 12\nnumber_density: 4 #")))


@pytest.mark.parametrize("text, problem", [("", "mapping"), ("- 1\n- 2\n", "mapping")])
def test_empty_or_list_scene(tmp_path, text, problem):
    with pytest.raises(InputError, match=problem):
        load_scene(_write(tmp_path, text))


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        load_scene(tmp_path / "nope.yaml")


def test_yaml_exponent_without_dot_is_a_float(tmp_path):
    text = MINIMAL + "numerics: {wi_target: 1e-3, dt_viscous_coefficient: 5E-2}\n"
    scene = load_scene(_write(tmp_path, text))
    assert scene.numerics.wi_target == 1e-3 and scene.numerics.dt_viscous_coefficient == 0.05


def test_dict_accepts_tuples_and_numpy_scalars():
    data = yaml.safe_load(MINIMAL)
    data.update(box=(np.int64(12), 12.0, np.float32(12)), seed=np.int64(3))
    scene = scene_from_dict(data)
    assert scene.box == (12.0, 12.0, 12.0) and scene.seed == 3


def _properties(schema, path=()):
    for name, sub in schema.get("properties", {}).items():
        yield path + (name,), sub, name in schema.get("required", ())
        yield from _properties(sub, path + (name,))


def test_schema_is_valid_and_documents_every_key():
    Draft202012Validator.check_schema(SCENE_SCHEMA)
    for path, sub, required in _properties(SCENE_SCHEMA):
        assert sub.get("description"), path
        if not required and path not in {("run", "strain"), ("run", "time")}:
            assert "default" in sub, path


@pytest.mark.parametrize("numerics, expected", [
    ("{}", "nominal"), ("{shifting: 30}", "fluid_mean"),
    ("{shifting: 30, pressure_reference: nominal}", "nominal")])
def test_pressure_reference_auto_follows_shifting(tmp_path, numerics, expected):
    scene = load_scene(_write(tmp_path, MINIMAL + f"numerics: {numerics}\n"))
    assert scene.numerics.pressure_reference == expected


def test_fluid_mean_pressure_reference_needs_shifting(tmp_path):
    with pytest.raises(InputError, match="numerics.pressure_reference.*shifting"):
        load_scene(_write(tmp_path, MINIMAL + "numerics: {pressure_reference: fluid_mean}\n"))


@pytest.mark.parametrize("newtonian, expected", [(True, 30.0), (False, 3.0)])
def test_shifting_auto_is_on_only_with_inclusions(tmp_path, newtonian, expected):
    text = MINIMAL
    if newtonian:
        text = text.replace("law: papanastasiou", "law: newtonian").replace(
            "{mu_pl: 1.0, mu_0: 99.0, M: 100.0}", "{mu: 1.0}")
    fluid = load_scene(_write(tmp_path, text))
    suspension = load_scene(_write(tmp_path, text + "inclusions: {phi: 0.1, radius: 2.0}\n"))
    assert (fluid.numerics.shifting, fluid.numerics.pressure_reference) == (0.0, "nominal")
    assert suspension.numerics.shifting == expected
    assert suspension.numerics.pressure_reference == "fluid_mean"
    assert (fluid.numerics.shifting_at_bodies, suspension.numerics.shifting_at_bodies) == (
        "full", "full")


@pytest.mark.parametrize("extra, spin, cutoff", [
    ("", True, 0.44), ("numerics: {shifting: 30}\n", True, 0.185),
    ("numerics: {shifting: 100}\n", True, 0.185), ("numerics: {shifting: 300}\n", True, 0.185),
    ("numerics: {shifting: 10}\n", True, 0.2797),
    ("numerics: {shifting: 100, shifting_at_bodies: tangential}\n", True, 0.185),
    ("numerics: {shifting_at_bodies: tangential}\n", True, 0.583),
    ("numerics: {shifting: 10, shifting_at_bodies: tangential}\n", True, 0.3713),
    ("numerics: {shifting: 30, shifting_at_bodies: tangential}\n", True, 0.246),
    ("numerics: {spin_correction: false, shifting: 30}\n", False, 0.778)])
def test_spin_correction_and_cutoff_auto_follow_the_squeeze_calibration(tmp_path, extra, spin,
                                                                       cutoff):
    """The correction is on with bodies only; the auto cutoff is the calibrated gap at the
    scene's shifting coefficient (A = 3 auto in this non-Newtonian matrix) and its shifting at
    the bodies (full or tangential), interpolated in log A between the measured 3, 30 and 100;
    an explicit cutoff stays."""
    fluid = load_scene(_write(tmp_path, MINIMAL + extra))
    suspension = load_scene(_write(tmp_path, MINIMAL + extra
                                   + "inclusions: {phi: 0.1, radius: 2.0}\n"))
    assert not fluid.numerics.spin_correction
    assert suspension.numerics.spin_correction is spin
    assert suspension.inclusions.lubrication.cutoff_gap == pytest.approx(cutoff, abs=1e-3)
    given = load_scene(_write(tmp_path, MINIMAL + extra + "inclusions: {phi: 0.1, radius: 2.0, "
                              "lubrication: {cutoff_gap: 0.4}}\n"))
    assert given.inclusions.lubrication.cutoff_gap == 0.4


def test_an_auto_cutoff_below_min_gap_is_refused(tmp_path):
    with pytest.raises(InputError, match="min_gap 0.2 must be below cutoff_gap 0.185"):
        load_scene(_write(tmp_path, MINIMAL + "numerics: {shifting: 30}\ninclusions: {phi: 0.1, "
                          "radius: 2.0, lubrication: {min_gap: 0.2}}\n"))


def test_density_limits_let_outliers_pass_only_with_inclusions(tmp_path):
    fluid = load_scene(_write(tmp_path, MINIMAL)).run
    suspension = load_scene(_write(tmp_path, MINIMAL + "inclusions: {phi: 0.1, radius: 2.0}\n")).run
    assert (fluid.max_density_error, fluid.density_outlier_fraction,
            fluid.max_outlier_density_error) == (0.05, 0.0, 0.05)
    assert (suspension.max_density_error, suspension.density_outlier_fraction,
            suspension.max_outlier_density_error) == (0.3, 1e-3, 0.6)
    given = load_scene(_write(tmp_path, _edit("  dt: auto", "  max_density_error: 0.1")
                              + "inclusions: {phi: 0.1, radius: 2.0}\n")).run
    assert given.max_outlier_density_error == pytest.approx(0.2)


def test_smallest_box_side_is_three_cells_of_the_neighbour_list():
    """A scene that passes validation can always build its cell list (3 cells of h + skin)."""
    from suspsim.scene_rules import MIN_BOX_SIDE
    from suspsim.sph.simulation import SKIN, SUPPORT

    assert MIN_BOX_SIDE == pytest.approx(3 * (SUPPORT + SKIN))
