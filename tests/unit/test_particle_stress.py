"""The bodies' share of the stress and Batchelor's split of η_r in a run's output
(``Simulation.sample``'s ``particle_stress``, ``run._batchelor_split``)."""
import numpy as np
import pytest
import xarray as xr

from suspsim.run import run_scene
from suspsim.scene import scene_from_dict
from suspsim.sph.simulation import Simulation
from suspsim.sph.terms.force_pass import VXY

NEWTONIAN = {"law": "newtonian", "params": {"mu": 1.0}}
POWER_LAW = {"law": "power_law", "params": {"K": 1.0, "n": 0.5}}


def tiny(fluid, phi=0.1):
    """Three spheres of 1 h in a 5 h box, strain 1 after 0.5 of transient."""
    return scene_from_dict({
        "dimension": 3, "box": [5.0] * 3, "number_density": 4.096, "fluid": fluid,
        "flow": {"type": "couette", "shear_rate": 0.01},
        "run": {"strain": 1.5, "transient": 0.5, "output_interval": 0.05},
        "lattice": {"relax": True},
        "inclusions": {"phi": phi, "radius": 1.0, "seed": 2}})


def test_particle_stress_is_the_stresslets_plus_lubrication():
    """The sample's particle_stress is −(Σ of the body-centre and lubrication virials)_xy/V,
    the part of σ_xy the whole-box shear_stress adds to the pair virial (SPEC §3.5)."""
    sim = Simulation(tiny(NEWTONIAN), threads=1)
    sim.advance(20)
    sample = sim.sample()
    expected = -(sim._body_virial[VXY] + sim._lubrication_virial[VXY]) / sim.scene.volume
    assert sample["particle_stress"] == pytest.approx(expected, rel=1e-12)
    assert sample["particle_stress"] != 0.0
    fluid_alone = Simulation(tiny(NEWTONIAN, phi=0.0), threads=1)
    assert "particle_stress" not in fluid_alone.sample()


def test_newtonian_run_splits_its_relative_viscosity(tmp_path, caplog):
    """η_r = η_r^p + fluid_stress_error (batch means are linear); the series and both parts
    are written with their units, and the log names both; a power-law matrix gets the series
    but no split."""
    caplog.set_level("INFO", logger="suspsim.run")
    out = run_scene(tiny(NEWTONIAN), tmp_path / "newtonian.nc")
    assert any("relative viscosity" in r.message and "the fluid's error" in r.message
               for r in caplog.records)
    with xr.open_dataset(out) as run:
        assert run["particle_stress"].dims == ("time",)
        assert run["particle_stress"].attrs["units"] == run["shear_stress"].attrs["units"]
        assert np.all(np.isfinite(run["particle_stress"]))
        assert float(run["relative_viscosity"]) == pytest.approx(
            float(run["particle_relative_viscosity"]) + float(run["fluid_stress_error"]),
            rel=1e-12)
        assert float(run["particle_relative_viscosity_stderr"]) >= 0.0
        assert float(run["fluid_stress_error_stderr"]) >= 0.0
    out = run_scene(tiny(POWER_LAW), tmp_path / "power_law.nc")
    with xr.open_dataset(out) as run:
        assert "particle_stress" in run and "relative_viscosity" in run
        assert "particle_relative_viscosity" not in run and "fluid_stress_error" not in run
