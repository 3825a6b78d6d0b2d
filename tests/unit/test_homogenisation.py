"""Homogenisation estimate from a matrix fit (SPEC §1.2): Newtonian and plastic limits, output file."""
import json

import numpy as np
import pytest
import xarray as xr

from suspsim.errors import InputError
from suspsim.rheology.suspension import cot_herschel_bulkley, krieger_dougherty
from suspsim.stages.homogenisation import homogenisation_estimate, write_homogenisation

PHI = [0.1, 0.25, 0.4]
RATES = np.geomspace(1e-3, 1e3, 25)


def test_newtonian_matrix_gives_the_newtonian_relative_viscosity():
    ds = homogenisation_estimate({"law": "newtonian", "params": {"mu": 0.3}}, PHI, RATES, phi_max=0.6)
    g = krieger_dougherty(np.array(PHI), 0.6)
    assert np.allclose(ds["relative_viscosity"].values, g[:, None], rtol=1e-13)
    assert np.allclose(ds["suspension_viscosity"].values, 0.3 * g[:, None], rtol=1e-13)


def test_herschel_bulkley_matrix_matches_the_closed_form():
    """For an HB matrix the estimate is again HB with τ_y(φ), K(φ) and the same n (COT 2008)."""
    tau_y, K, n = 20.0, 5.0, 0.5
    fit = {"law": "herschel_bulkley", "params": {"tau_y": tau_y, "K": K, "n": n, "M": 1e9,
                                                 "gdot_min": 1e-12}}
    ds = homogenisation_estimate(fit, PHI, RATES, phi_max=0.57)
    g = krieger_dougherty(np.array(PHI), 0.57)
    for i, phi in enumerate(PHI):
        tau_phi, K_phi, n_phi = cot_herschel_bulkley(tau_y, K, n, phi, g[i])
        expected = tau_phi / RATES + K_phi * RATES ** (n_phi - 1)
        assert np.allclose(ds["suspension_viscosity"].values[i], expected, rtol=1e-6)
    # Plastic regime: η/μ_matrix → sqrt((1 − φ) g), SPEC §1.2 (≈ 2.45 for φ = 0.4, g = 10).
    plastic = ds["relative_viscosity"].values[:, 0]
    assert np.allclose(plastic, np.sqrt((1 - np.array(PHI)) * g), rtol=0.02)


def test_written_file_has_units_everywhere_and_no_partial_output(tmp_path):
    fit_path = tmp_path / "fit.json"
    fit_path.write_text(json.dumps({"law": "power_law", "params": {"K": 2.0, "n": 0.4},
                                    "shear_rate_range": [0.01, 100.0]}))
    out = tmp_path / "h.nc"
    write_homogenisation(fit_path, out, volume_fractions=PHI, out_plot=tmp_path / "h.png")
    with xr.open_dataset(out) as ds:
        assert ds.sizes == {"volume_fraction": 3, "shear_rate": 61}
        assert float(ds["shear_rate"].min()) == pytest.approx(0.01)
        for name in [*ds.data_vars, *ds.coords]:
            assert "units" in ds[name].attrs and "long_name" in ds[name].attrs
        assert json.loads(ds.attrs["matrix_fit"])["law"] == "power_law"
    assert (tmp_path / "h.png").stat().st_size > 10_000

    with pytest.raises(InputError, match="phi_max"):
        write_homogenisation(fit_path, tmp_path / "bad.nc", volume_fractions=[0.6])
    assert not (tmp_path / "bad.nc").exists()
