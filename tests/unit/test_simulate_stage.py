"""The simulate stage: scene from a fit and a physical rate, φ > 0 refused, one tiny real run."""
import json
import logging

import pytest
import xarray as xr

from suspsim.errors import InputError
from suspsim.io.checkpoint import save_checkpoint
from suspsim.rheology.laws import make_law
from suspsim.run import checkpoint_path
from suspsim.stages.simulate import (SIMULATION_SUFFIX, InclusionsNotAvailable, Resolution,
                                     read_fit, simulate_run, simulation_scene)
from suspsim.units import SIMULATION_SHEAR_RATE

FIT = {"law": "carreau_yasuda", "shear_rate_range": [0.01, 1000.0],
       "params": {"mu_0": 2.1, "mu_inf": 1e-7, "lam": 0.1, "a": 0.86, "n": 0.3}}
LAW = make_law(FIT["law"], FIT["params"])
TINY = Resolution(box=5, number_density=4.096, strain=3, transient=1)


def test_scene_is_a_linear_start_couette_of_the_mapped_law():
    scene, mapping = simulation_scene(LAW, 20.0, volume_fraction=0.0, seed=4, resolution=TINY)
    assert scene.flow.type == "couette" and scene.run.start == "linear"
    assert scene.flow.shear_rate == SIMULATION_SHEAR_RATE == mapping.simulation_shear_rate
    assert scene.box == (5.0, 5.0, 5.0) and scene.seed == 4 and scene.run.threads == 1
    mu_sim = float(scene.fluid.law.viscosity(scene.flow.shear_rate))
    assert mu_sim * mapping.viscosity_scale == pytest.approx(float(LAW.viscosity(20.0)))
    assert scene.density / mu_sim * scene.flow.shear_rate == pytest.approx(TINY.reynolds)


def test_volume_fraction_above_zero_names_the_missing_capability():
    with pytest.raises(InclusionsNotAvailable, match="rigid inclusions"):
        simulation_scene(LAW, 1.0, volume_fraction=0.2, seed=1, resolution=TINY)
    with pytest.raises(InputError, match="volume fraction"):
        simulation_scene(LAW, 1.0, volume_fraction=1.0, seed=1, resolution=TINY)


def test_bad_resolution_and_fit_are_input_errors(tmp_path):
    with pytest.raises(InputError, match="spacing"):
        simulation_scene(LAW, 1.0, volume_fraction=0.0, seed=1,
                         resolution=Resolution(box=5.3, number_density=4.096, strain=3,
                                               transient=1))
    with pytest.raises(InputError, match="unknown resolution key"):
        Resolution.from_mapping({"box": 5, "number_density": 4, "strain": 3, "transient": 1,
                                 "cfl": 0.1})
    with pytest.raises(InputError, match="no such fit report"):
        read_fit(tmp_path / "missing.json")
    (tmp_path / "bad.json").write_text(json.dumps({"law": "bingham", "params": {}}))
    with pytest.raises(InputError, match="not a usable fit report"):
        read_fit(tmp_path / "bad.json")


def test_tiny_run_matches_the_fitted_law_and_discards_a_foreign_checkpoint(tmp_path, caplog):
    fit_json = tmp_path / "fit.json"
    fit_json.write_text(json.dumps(FIT))
    out = tmp_path / "runs" / "phi-0_rate-3_seed-1.nc"
    out.parent.mkdir()
    other, _ = simulation_scene(LAW, 3.0, volume_fraction=0.0, seed=9, resolution=TINY)
    stale = checkpoint_path(out.with_suffix(SIMULATION_SUFFIX))
    save_checkpoint(stale, {"x": 1.0}, {"wall_time_s": 0.0, "step": 0}, scene=other)
    with caplog.at_level(logging.WARNING, logger="suspsim.stages.simulate"):
        simulate_run(fit_json, out, shear_rate=3.0, volume_fraction=0.0, seed=1,
                     resolution=TINY.__dict__, threads=1)
    assert "discarding" in caplog.text
    assert sorted(p.name for p in out.parent.iterdir()) == [out.name]
    with xr.open_dataset(out) as run:
        # The matrix alone in uniform shear: the solver against the fitted law (SPEC §2.3
        # measured 0.9985 ± 0.002 for a Newtonian fluid at this density).
        assert float(run["relative_viscosity"]) == pytest.approx(1.0, abs=0.02)
        assert float(run["matrix_viscosity"]) == pytest.approx(float(LAW.viscosity(3.0)))
        assert run["suspension_viscosity"].attrs["units"] == "Pa s"
        assert run["strain"].dims == ("time",)
        assert float(run["shear_rate"]) == 3.0 and float(run["phi"]) == 0.0
        assert run.attrs["unit_time_scale_s_per_tau"] == pytest.approx(SIMULATION_SHEAR_RATE / 3)
        assert 0 <= run.attrs["unit_mach_number"] < 0.1
        assert float(run["particle_reynolds_number"]) == pytest.approx(0.1)
