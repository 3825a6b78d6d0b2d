"""Packing files: round trips, units on every variable, attributes, atomic writes, bad files."""
import numpy as np
import pytest
import xarray as xr

from suspsim.bodies.packing import pack_sand, pack_spheres
from suspsim.errors import InputError
from suspsim.io.packing_file import read_packing, write_packing
from suspsim.io.variables import PACKING_ATTRIBUTES, PACKING_VARIABLES


@pytest.fixture(scope="session")
def spheres():
    return pack_spheres([10, 12, 14], 0.4, 1.0, polydispersity=0.2, seed=3)


@pytest.fixture(scope="session")
def sand():
    return pack_sand([7, 7, 7], 0.3, 1.0, seed=2, degree=6)


@pytest.mark.parametrize("name", ["spheres", "sand"])
def test_round_trip(tmp_path, request, name):
    packing = request.getfixturevalue(name)
    path = tmp_path / "pack.nc"
    write_packing(path, packing, command="suspsim pack ...")
    back = read_packing(path)
    for field in ("shape", "seed", "polydispersity", "size_ratio", "min_gap"):
        assert getattr(back, field) == getattr(packing, field), field
    for field in ("box", "centres", "orientations", "radii", "volumes", "support_radii"):
        np.testing.assert_array_equal(getattr(back, field), getattr(packing, field))
    if packing.coefficients is None:
        assert back.coefficients is None
    else:
        np.testing.assert_array_equal(back.coefficients, packing.coefficients)
    assert back.volume_fraction == packing.volume_fraction
    assert back.details == packing.details


def test_metadata(tmp_path, sand):
    path = tmp_path / "pack.nc"
    write_packing(path, sand)
    with xr.open_dataset(path) as ds:
        for name, variable in ds.data_vars.items():
            assert variable.attrs == PACKING_VARIABLES[name].attrs(3), name
            assert variable.attrs["units"] == "1"
        assert ds["centre"].attrs["simulation_units"] == "h"
        assert ds["volume"].attrs["simulation_units"] == "h3"
        assert "simulation_units" not in ds["orientation"].attrs
        assert ds["coefficient_degree"].values[-1] == 6
        assert list(ds["quaternion"].values) == ["w", "x", "y", "z"]
        assert ds.attrs["Conventions"] == "CF-1.10" and "Garboczi" in ds.attrs["references"]
        assert ds.attrs["volume_fraction"] == pytest.approx(0.3, rel=1e-12)
        assert ds.attrs["shape"] == "sand" and ds.attrs["seed"] == 2
        np.testing.assert_array_equal(ds.attrs["box"], [7, 7, 7])
        assert set(PACKING_ATTRIBUTES) <= set(ds.attrs)


def test_interrupted_write_leaves_no_file(tmp_path, monkeypatch, spheres):
    def half_write(self, path, **kwargs):
        with open(path, "wb") as stream:
            stream.write(b"\x89HDF\r\n half")
        raise KeyboardInterrupt

    monkeypatch.setattr(xr.Dataset, "to_netcdf", half_write)
    with pytest.raises(KeyboardInterrupt):
        write_packing(tmp_path / "pack.nc", spheres)
    assert list(tmp_path.iterdir()) == []


def test_bad_files(tmp_path):
    with pytest.raises(InputError, match="no such packing file"):
        read_packing(tmp_path / "missing.nc")
    (tmp_path / "text.nc").write_text("not netCDF")
    with pytest.raises(InputError, match="not a readable netCDF"):
        read_packing(tmp_path / "text.nc")
    xr.Dataset({"x": ("t", np.arange(3.0))}).to_netcdf(tmp_path / "other.nc")
    with pytest.raises(InputError, match="not a suspsim packing file: centre"):
        read_packing(tmp_path / "other.nc")
