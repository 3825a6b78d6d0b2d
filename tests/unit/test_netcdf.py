"""Run files: registry metadata, CF global attributes, round trips, atomic writes, provenance."""
import json
import os
import subprocess

import numpy as np
import pytest
import xarray as xr

from suspsim.errors import InputError
from suspsim.io import netcdf, provenance as provenance_module
from suspsim.io.netcdf import build_dataset, provenance, read_run, write_run
from suspsim.io.variables import RUN_ATTRIBUTES, VARIABLES, simulation_units
from suspsim.scene import scene_from_dict

SCENE = scene_from_dict({
    "dimension": 3, "box": [12, 12, 12], "number_density": 4.0,
    "fluid": {"law": "papanastasiou", "params": {"mu_pl": 1.0, "mu_0": 99.0, "M": 100.0}},
    "flow": {"type": "couette", "shear_rate": 0.01}, "run": {"strain": 10}, "seed": 7,
}).to_dict()


def _data(n_time=6, n_y=12):
    rng = np.random.default_rng(0)
    time = np.linspace(0.0, 1000.0, n_time)
    y = (np.arange(n_y) + 0.5) * 12.0 / n_y
    data = {"time": time, "y": y, "strain": 0.01 * time, "viscosity": 1.98, "viscosity_stderr": 0.01}
    data.update({name: rng.normal(size=n_time) for name in
                 ("shear_stress", "pressure", "kinetic_energy", "density_error", "mach")})
    data.update({name: rng.normal(size=n_y) for name in
                 ("velocity_profile", "viscosity_profile", "shear_rate_profile", "density_profile",
                  "reference_velocity_profile")})
    data["shear_stress"][2] = np.nan
    return data


ATTRS = {"n_particles": 6859, "n_steps": 120000, "wall_time_s": 321.5, "particle_steps_per_s": 2.5e6,
         "reynolds_number": 1e-3, "mach_number": 0.02, "completed": True, "dt": 0.0125,
         "sound_speed": 3.2}


def test_round_trip_preserves_values_and_attributes(tmp_path):
    path = tmp_path / "run.nc"
    data = _data()
    write_run(path, data, ATTRS, SCENE, command="suspsim run scene.yaml --out run.nc")
    ds = read_run(path)
    assert set(ds.variables) == set(data)
    assert "_FillValue" not in ds["time"].encoding and "_FillValue" not in ds["y"].encoding
    for name, value in data.items():
        np.testing.assert_array_equal(ds[name].values, value)
        assert ds[name].attrs == VARIABLES[name].attrs(3), name
    assert ds.attrs["Conventions"] == "CF-1.10" and ds.attrs["seed"] == 7
    assert json.loads(ds.attrs["scene"]) == SCENE
    assert ds.attrs["completed"] == 1 and ds.attrs["n_particles"] == 6859
    for name, value in ATTRS.items():
        assert ds.attrs[name] == value, name
    assert ds.attrs["history"].endswith("Z: suspsim run scene.yaml --out run.nc") or \
        ds.attrs["history"].endswith("+00:00: suspsim run scene.yaml --out run.nc")
    assert ds.attrs["source"].startswith("suspsim ") and "(git " in ds.attrs["source"]
    assert "Martys" in ds.attrs["references"] and "simulation units" in ds.attrs["unit_system"]
    expected = build_dataset(data, ATTRS, SCENE, command="x").attrs
    assert set(ds.attrs) == set(expected)
    assert all(ds.attrs[k] == expected[k] for k in expected if k != "history")


def test_a_scene_object_will_do():
    ds = build_dataset(_data(), ATTRS, scene_from_dict(SCENE))
    assert json.loads(ds.attrs["scene"]) == SCENE


def test_read_run_closes_the_file(tmp_path):
    path = tmp_path / "run.nc"
    write_run(path, _data(), ATTRS, SCENE)
    ds = read_run(path)
    os.replace(path, tmp_path / "moved.nc")
    assert float(ds["viscosity"]) == 1.98


def test_every_variable_has_units_and_long_name(tmp_path):
    path = tmp_path / "run.nc"
    write_run(path, _data(), ATTRS, SCENE)
    ds = read_run(path)
    for name in ds.variables:
        assert ds[name].attrs["units"] and ds[name].attrs["long_name"], name
    for spec in VARIABLES.values():
        for dimension in (2, 3):
            attrs = spec.attrs(dimension)
            assert attrs["units"] == "1" and attrs["long_name"]


@pytest.mark.parametrize("name, dimension, units", [
    ("shear_stress", 3, "m h-1 tau-2"), ("shear_stress", 2, "m tau-2"),
    ("viscosity", 3, "m h-1 tau-1"), ("viscosity", 2, "m tau-1"),
    ("density_profile", 3, "m h-3"), ("density_profile", 2, "m h-2"),
    ("velocity_profile", 2, "h tau-1"), ("time", 3, "tau"), ("kinetic_energy", 3, "m h2 tau-2"),
])
def test_simulation_units_follow_dimension(name, dimension, units):
    assert VARIABLES[name].attrs(dimension)["simulation_units"] == units


def test_dimensionless_variables_have_no_simulation_units():
    assert simulation_units((0, 0, 0, 0), 3) == "1"
    assert "simulation_units" not in VARIABLES["mach"].attrs(3)


@pytest.mark.parametrize("data, attrs, match", [
    ({**_data(), "viscosity_error": 0.1}, ATTRS, "not in the output registry"),
    (_data(), {**ATTRS, "colour": "red"}, "not in the registry"),
    (_data(), {k: v for k, v in ATTRS.items() if k != "wall_time_s"}, "wall_time_s"),
    ({k: v for k, v in _data().items() if k != "y"}, ATTRS, "without their coordinate"),
    ({**_data(), "viscosity": [1.0, 2.0]}, ATTRS, "registry says"),
    (_data(), {**ATTRS, "n_steps": 1.5}, "integer"),
])
def test_programming_errors_raise_value_error(tmp_path, data, attrs, match):
    with pytest.raises(ValueError, match=match):
        write_run(tmp_path / "run.nc", data, attrs, SCENE)
    assert list(tmp_path.iterdir()) == []


def test_interrupted_write_leaves_no_file(tmp_path, monkeypatch):
    def half_write(self, path, **kwargs):
        with open(path, "wb") as stream:
            stream.write(b"\x89HDF\r\n half")
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", half_write)
    with pytest.raises(KeyboardInterrupt):
        write_run(tmp_path / "run.nc", _data(), ATTRS, SCENE)
    assert list(tmp_path.iterdir()) == []


def test_failed_rename_leaves_no_file(tmp_path, monkeypatch):
    def denied(src, dst):
        raise PermissionError(13, "Permission denied", str(dst))

    monkeypatch.setattr(os, "replace", denied)
    with pytest.raises(PermissionError):
        write_run(tmp_path / "run.nc", _data(), ATTRS, SCENE)
    assert list(tmp_path.iterdir()) == []


def test_read_only_directory_leaves_no_file(tmp_path):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        if os.access(folder, os.W_OK):
            pytest.skip("running with privileges that ignore directory permissions")
        with pytest.raises(PermissionError):
            write_run(folder / "run.nc", _data(), ATTRS, SCENE)
        assert list(folder.iterdir()) == []
    finally:
        folder.chmod(0o755)


@pytest.mark.parametrize("content", [None, b"", b"not netcdf at all"])
def test_read_run_rejects_missing_or_bad_files(tmp_path, content):
    path = tmp_path / "run.nc"
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(InputError):
        read_run(path)


def test_provenance_reports_versions_and_never_raises(monkeypatch, tmp_path):
    info = provenance()
    assert set(info) >= {"suspsim_version", "git_sha", "python_version", "numpy_version",
                         "numba_version", "host"}
    assert all(isinstance(v, str) and v for v in info.values())

    def broken(*args, **kwargs):
        raise FileNotFoundError("git")

    monkeypatch.setattr(subprocess, "run", broken)
    assert provenance()["git_sha"] == "unknown"
    monkeypatch.undo()
    assert provenance_module.git_sha(tmp_path) == "unknown"


def test_git_sha_of_this_checkout_is_a_commit():
    sha = provenance_module.git_sha()
    assert sha == "unknown" or len(sha.removesuffix("-dirty")) in (40, 64)


def test_run_attribute_registry_types():
    # str attributes hold JSON (the tolerance set-up of suspsim run --tolerance)
    assert all(a.type in (int, float, str) and a.description for a in RUN_ATTRIBUTES.values())
    assert netcdf.REFERENCES.count("doi:") >= 1
