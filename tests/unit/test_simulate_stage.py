"""The simulate stage: scene from a fit and a physical rate, inclusions at φ > 0 from a packing
file, and tiny real runs of the matrix alone and of a suspension."""
import json
import logging
import math

import pytest
import xarray as xr

from suspsim.errors import InputError, NumericalError
from suspsim.io.checkpoint import save_checkpoint
from suspsim.rheology.laws import make_law
from suspsim.run import checkpoint_path
from suspsim.stages.pack import Particles, write_study_packing
from suspsim.stages.simulate import (SIMULATION_SUFFIX, Resolution, read_fit, simulate_run,
                                     simulation_scene)
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


def test_scene_above_zero_has_the_inclusions_and_their_reynolds_length():
    particles = Particles(shape="sand", radius=1.2, polydispersity=0.1, physical_radius=3e-5,
                          friction=0.5, rolling_friction=0.1)
    scene, mapping = simulation_scene(LAW, 20.0, volume_fraction=0.2, seed=4, resolution=TINY,
                                      particles=particles, packing="p.nc")
    spec = scene.inclusions
    assert spec.present and spec.packing == "p.nc" and spec.phi == 0.2 and spec.seed == 4
    assert spec.lubrication.friction == 0.5 and spec.lubrication.enabled
    assert spec.lubrication.rolling_friction == 0.1
    assert (spec.shape, spec.radius, spec.polydispersity) == ("sand", 1.2, 0.1)
    mu_sim = float(scene.fluid.law.viscosity(scene.flow.shear_rate))
    # SPEC §7: at φ > 0 the particle Reynolds number takes the inclusion radius as its length.
    assert mapping.reynolds_length == 1.2
    assert scene.density * 1.2 ** 2 * scene.flow.shear_rate / mu_sim == pytest.approx(0.1)
    assert mapping.length_scale == pytest.approx(3e-5 / 1.2)
    assert scene.numerics.shifting > 0 and scene.lattice.relax
    alone, matrix = simulation_scene(LAW, 20.0, volume_fraction=0.0, seed=4, resolution=TINY,
                                     particles=particles)
    assert not alone.inclusions.present
    assert matrix.reynolds_length == 1.0 and matrix.length_scale is None
    with pytest.raises(InputError, match="volume fraction"):
        simulation_scene(LAW, 1.0, volume_fraction=1.0, seed=1, resolution=TINY)
    with pytest.raises(InputError, match="packing file for a run at volume fraction 0"):
        simulation_scene(LAW, 1.0, volume_fraction=0.0, seed=1, resolution=TINY,
                         packing="p.nc")


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


def test_tiny_suspension_run_reads_its_packing_and_records_the_inclusions(tmp_path):
    fit_json = tmp_path / "fit.json"
    fit_json.write_text(json.dumps(FIT))
    particles = Particles(radius=1.0, physical_radius=1e-4)
    packing = tmp_path / "phi-0.1_seed-2.nc"
    write_study_packing(packing, volume_fraction=0.1, seed=2, box=TINY.box, particles=particles)
    out = tmp_path / "phi-0.1_rate-3_seed-2.nc"
    with pytest.raises(InputError, match="seed 2 \\(the run's 1\\)"):
        simulate_run(fit_json, out, shear_rate=3.0, volume_fraction=0.1, seed=1,
                     resolution=TINY, particles=particles, packing=packing)
    simulate_run(fit_json, out, shear_rate=3.0, volume_fraction=0.1, seed=2, resolution=TINY,
                 particles=particles.to_dict(), packing=packing)
    with xr.open_dataset(out) as run:
        assert float(run["phi"]) == 0.1 and run["phi"].attrs["units"] == "1"
        assert float(run["body_count"]) == run.attrs["n_bodies"] == 3
        assert float(run["inclusion_radius"]) == 1.0
        assert run["inclusion_radius"].attrs["simulation_units"] == "h"
        assert float(run["packing_seed"]) == 2 and float(run["reynolds_length"]) == 1.0
        assert float(run["particle_radius"]) == pytest.approx(1e-4)
        assert run["particle_radius"].attrs["units"] == "m"
        assert run["suspension_viscosity"].attrs["units"] == "Pa s"
        assert math.isfinite(float(run["relative_viscosity"]))
        assert float(run["matrix_viscosity_at_rate"]) > 0  # the run's own, simulation units
        assert json.loads(run.attrs["inclusions"])["shape"] == run.attrs["inclusion_shape"]
        assert run.attrs["unit_length_scale_m_per_h"] == pytest.approx(1e-4)
        assert json.loads(run.attrs["scene"])["inclusions"]["packing"] == str(packing)


def test_study_numerics_reach_the_scene_and_a_blow_up_names_them(tmp_path):
    scene, _ = simulation_scene(LAW, 3.0, volume_fraction=0.0, seed=1, resolution=TINY,
                                numerics={"wi_target": 3e-4, "dt_viscous_coefficient": 0.02})
    assert scene.numerics.wi_target == 3e-4 and scene.numerics.dt_viscous_coefficient == 0.02
    fit_json = tmp_path / "fit.json"
    fit_json.write_text(json.dumps(FIT))
    out = tmp_path / "run.nc"
    # Ten times the stable viscous step and a slow sound: the health check stops the run.
    with pytest.raises(NumericalError, match="simulation.numerics in the study config"):
        simulate_run(fit_json, out, shear_rate=3.0, volume_fraction=0.0, seed=1,
                     resolution=TINY, numerics={"wi_target": 0.5, "dt_viscous_coefficient": 0.5},
                     threads=1)
    assert not out.exists()
