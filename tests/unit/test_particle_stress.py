"""The bodies' share of the stress and Batchelor's split of η_r in a run's output
(``Simulation.sample``'s ``particle_stress``, ``run._batchelor_split``), and the bodies' spin
and the grains' nematic order beside them (``body_spin``, ``body_order``)."""
import numpy as np
import pytest
import xarray as xr

from suspsim.analysis.orientation import nematic_order, spin_ratio
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
    assert sample["body_spin"] == pytest.approx(
        spin_ratio(sim.bodies.angular_velocities(), 0.01), rel=1e-12)
    assert "body_order" not in sample
    fluid_alone = Simulation(tiny(NEWTONIAN, phi=0.0), threads=1)
    assert not {"particle_stress", "body_spin"} & set(fluid_alone.sample())


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
        assert run["body_spin"].dims == ("time",) and run["body_spin"].attrs["units"] == "1"
        assert np.all(np.isfinite(run["body_spin"]))
        assert "body_order" not in run
    out = run_scene(tiny(POWER_LAW), tmp_path / "power_law.nc")
    with xr.open_dataset(out) as run:
        assert "particle_stress" in run and "relative_viscosity" in run
        assert "particle_relative_viscosity" not in run and "fluid_stress_error" not in run


def test_grain_run_writes_the_nematic_order_of_the_long_axes(tmp_path):
    """Grains add body_order, S of their long axes (the principal axis of least inertia,
    column 0 of each rotation), as a series of the run's output."""
    scene = scene_from_dict({
        "dimension": 3, "box": [10.0] * 3, "number_density": 4.096, "fluid": NEWTONIAN,
        "flow": {"type": "couette", "shear_rate": 0.004},
        "run": {"strain": 0.004, "transient": 0.002, "output_interval": 0.001,
                "max_density_error": 0.2},
        "lattice": {"relax_max_steps": 100},
        "inclusions": {"shape": "sand", "phi": 0.25, "radius": 1.5, "min_gap": 0.05}})
    sim = Simulation(scene, threads=1)
    sample = sim.sample()
    assert sample["body_order"] == pytest.approx(
        nematic_order(sim.bodies.rotations()[:, :, 0])[0], rel=1e-12)
    assert 0.0 <= sample["body_order"] <= 1.0
    out = run_scene(scene, tmp_path / "sand.nc")
    with xr.open_dataset(out) as run:
        assert run["body_order"].dims == ("time",) and run["body_order"].attrs["units"] == "1"
        assert np.all((run["body_order"] >= 0.0) & (run["body_order"] <= 1.0))
        assert np.all(np.isfinite(run["body_spin"]))
