"""The bingham_suspension study's stages (seed 000 Fig. 3): jobs from the config, the law
scaling of each rate, the validation errors, and the gather's numbers (η/μ_pl, g, the
Chateau–Ovarlez–Trung estimate) against hand calculations, on synthetic run files."""
import json
import math

import numpy as np
import pytest
import xarray as xr

from suspsim.errors import InputError
from suspsim.rheology.laws import make_law
from suspsim.scene import scene_from_dict
from suspsim.scene_rules import AUTO_SHIFTING_NON_NEWTONIAN
from suspsim.stages.bingham_suspension import (case_name, find_job, matrix_law,
                                               matrix_plastic_ratio, pack_seed, study_settings,
                                               suspension_jobs, suspension_scene)
from suspsim.stages.bingham_suspension_figures import write_suspension_figure
from suspsim.stages.bingham_suspension_gather import (cot_relative_viscosity,
                                                      gather_suspension, read_suspension,
                                                      write_suspension)
from test_flows_stage import validated_config

#: The schema defaults of the block (seed 000's φ = 0.4, the owner's scene) with two rates.
BLOCK = {"viscosity_ratio": 99.0, "rates": [1.0, 100.0], "volume_fraction": 0.4, "radius": 2.5,
         "box": 15.0, "number_density": 4.096, "shear_rate": 0.004, "strain": 10.0,
         "transient": 2.0, "seeds": [1], "threads": 1}


def _block(study):
    """The bingham_suspension block of the validated config of ``study``."""
    return validated_config(study)["bingham_suspension"]


def test_default_config_runs_nothing_and_the_studies_list_their_runs():
    assert suspension_jobs(_block(None)) == []
    assert study_settings(_block(None)) == {**BLOCK, "rates": []}
    full = _block("bingham_suspension")
    assert study_settings(full)["rates"] == [0.01, 0.0316, 0.1, 0.316, 1, 3.16, 10, 31.6, 100,
                                             316, 1000]
    assert len(suspension_jobs(full)) == 36
    smoke = study_settings(_block("bingham_suspension_smoke"))
    assert smoke["rates"] == [1] and smoke["volume_fraction"] == 0.2
    assert smoke["box"] == 10 and smoke["strain"] <= 1.5


def test_jobs_are_a_newtonian_run_per_seed_then_every_rate_per_seed():
    jobs = suspension_jobs({**BLOCK, "seeds": [3, 4]})
    assert [(job["rate"], job["seed"]) for job in jobs] == [
        (None, 3), (None, 4), (1.0, 3), (1.0, 4), (100.0, 3), (100.0, 4)]
    assert all(job["volume_fraction"] == 0.4 and job["box"] == 15.0 for job in jobs)
    assert find_job(BLOCK, "newtonian", 1)["rate"] is None
    assert find_job(BLOCK, case_name(100.0, lambda x: f"{x:g}"), 1)["rate"] == 100.0
    with pytest.raises(InputError, match="no run x-3 at seed 1"):
        find_job(BLOCK, "x-3", 1)
    with pytest.raises(InputError, match="no run newtonian at seed 2"):
        find_job(BLOCK, "newtonian", 2)
    with pytest.raises(InputError, match="neither"):
        find_job(BLOCK, "bingham", 1)


@pytest.mark.parametrize("rate", [0.01, 0.0316, 1.0, 3.16, 100.0])
def test_law_has_unit_viscosity_at_the_imposed_rate_and_x_equal_to_m_gdot(rate):
    gdot = BLOCK["shear_rate"]
    name, params = matrix_law(rate, 99.0, gdot)
    law = make_law(name, params)
    assert name == "papanastasiou"
    assert float(law.viscosity(gdot)) == pytest.approx(1.0, rel=1e-14)
    assert params["M"] * gdot == pytest.approx(rate, rel=1e-15)
    assert params["mu_0"] / params["mu_pl"] == pytest.approx(99.0, rel=1e-15)
    # μ_m/μ_pl = 1 + r (1 − e^(−x))/x written out
    assert matrix_plastic_ratio(rate, 99.0) == pytest.approx(
        1 + 99 * (1 - math.exp(-rate)) / rate, rel=1e-13)
    assert 1.0 / params["mu_pl"] == pytest.approx(matrix_plastic_ratio(rate, 99.0), rel=1e-14)


def test_law_limits_and_the_newtonian_reference():
    # x → 0: the zero-rate viscosity μ_pl + μ_0 = 100 μ_pl; x → ∞: the plastic viscosity.
    assert matrix_plastic_ratio(1e-9, 99.0) == pytest.approx(100.0, rel=1e-8)
    assert matrix_plastic_ratio(1e6, 99.0) == pytest.approx(1.0, rel=1e-4)
    np.testing.assert_allclose(matrix_plastic_ratio(np.array([1e-9, 1e6]), 99.0),
                               [100.0, 1.0 + 99e-6])
    assert matrix_law(None, 99.0, 0.004) == ("newtonian", {"mu": 1.0})


def test_scene_is_the_owners_set_up_with_the_seeds_packing_file():
    job = find_job(BLOCK, "x-1", 1)
    data = suspension_scene(job, "results/packings/seed-1.nc", threads=2)
    scene = scene_from_dict(data)
    assert scene.box == (15.0, 15.0, 15.0) and scene.flow.shear_rate == 0.004
    assert data["lattice"] == {"relax": True} and data["run"]["start"] == "linear"
    assert data["inclusions"]["packing"] == "results/packings/seed-1.nc"
    assert data["inclusions"]["phi"] == 0.4 and data["inclusions"]["radius"] == 2.5
    assert data["numerics"] == {}  # the inclusions' defaults
    # the particle Reynolds number ρ γ̇ a²/μ_m(γ̇) of every run, Newtonian or not, and the
    # numerics: the Newtonian reference takes those of the non-Newtonian runs
    numerics = set()
    for case in ("newtonian", "x-1", "x-100"):
        other = scene_from_dict(suspension_scene(find_job(BLOCK, case, 1), None))
        mu = float(other.fluid.law.viscosity(other.flow.shear_rate))
        assert other.density * other.flow.shear_rate * 2.5 ** 2 / mu == pytest.approx(0.1024)
        numerics.add((other.numerics.shifting, other.numerics.spin_correction,
                       other.inclusions.lubrication.cutoff_gap))
    assert len(numerics) == 1 and numerics.pop()[0] == AUTO_SHIFTING_NON_NEWTONIAN


@pytest.mark.parametrize("change, key, message", [
    ({"rates": [1.0, 1]}, "bingham_suspension.rates", "listed twice"),
    ({"rates": [1.0, 0.0]}, "bingham_suspension.rates", "must be positive"),
    ({"rates": [-2.0]}, "bingham_suspension.rates", "must be positive"),
    ({"volume_fraction": 0.0}, "bingham_suspension.volume_fraction", "must be positive"),
    ({"volume_fraction": -0.1}, "bingham_suspension.volume_fraction", "must be positive"),
    ({"seeds": [1, 1]}, "bingham_suspension.seeds", "listed twice"),
    ({"transient": 10.0}, "bingham_suspension.transient", "must lie in"),
    ({"box": 15.3}, "bingham_suspension.box", "lattice"),
])
def test_settings_reject_bad_values_naming_the_key(change, key, message):
    with pytest.raises(InputError, match=message) as err:
        study_settings({**BLOCK, **change})
    assert err.value.key == key and err.value.source == "bingham_suspension"


def test_packing_errors_name_this_blocks_key(tmp_path):
    with pytest.raises(InputError, match="too small") as err:
        pack_seed({**BLOCK, "box": 8.75}, 1, tmp_path / "seed-1.nc")
    assert err.value.key == "bingham_suspension.box"
    assert not (tmp_path / "seed-1.nc").exists()


def test_cot_estimate_is_the_formula_by_hand():
    # g = 5, φ = 0.4, r = 99: s = sqrt(g/(1 − φ)); η_COT/μ_m = g f(x s)/f(x),
    # f(x) = 1 + r (1 − e^(−x))/x (the μ_pl and M of the law cancel).
    g, phi, s = 5.0, 0.4, math.sqrt(5.0 / 0.6)
    def f(x):
        return 1 + 99 * (1 - math.exp(-x)) / x

    rates = [0.01, 1.0, 100.0]
    expected = [g * f(x * s) / f(x) for x in rates]
    np.testing.assert_allclose(cot_relative_viscosity(rates, 99.0, phi, g), expected, rtol=1e-12)
    # limits: g at both ends (a Newtonian matrix there), sqrt(g (1 − φ)) in the plastic regime
    # (cot_herschel_bulkley's n = 0 ratio) when the yield stress dominates
    low, high = cot_relative_viscosity([1e-8, 1e8], 99.0, phi, g)
    assert low == pytest.approx(g, rel=1e-6) and high == pytest.approx(g, rel=1e-6)
    plastic = cot_relative_viscosity([50.0], 1e9, phi, g)[0]
    assert plastic == pytest.approx(math.sqrt(g * (1 - phi)), rel=1e-6)


def synthetic_run(block, rate, seed, eta, error, wall=2.0, packing=None):
    """A run Dataset of ``rate`` (None: Newtonian) and ``seed`` with relative viscosity
    ``eta`` ± ``error``, as suspsim's run file holds it, on the packing file ``packing``
    (default packings/seed-<seed>.nc)."""
    job = find_job(block, case_name(rate), seed)
    scene = scene_from_dict(suspension_scene(job, packing or f"packings/seed-{seed}.nc"))
    return xr.Dataset({"phi": ((), float(block["volume_fraction"])),
                       "relative_viscosity": ((), eta),
                       "relative_viscosity_stderr": ((), error)},
                      attrs={"scene": json.dumps(scene.to_dict()), "wall_time_s": wall,
                             "n_particles": 12000, "n_bodies": 26})


def _gather(block, g, runs):
    """gather_suspension of Newtonian (value, error) per seed and rate-major (value, error)."""
    settings = study_settings(block)
    cases = [(rate, seed) for rate in settings["rates"] for seed in settings["seeds"]]
    return gather_suspension(
        block, [synthetic_run(block, None, s, *v) for s, v in zip(settings["seeds"], g)],
        [synthetic_run(block, r, s, *v) for (r, s), v in zip(cases, runs)],
        newtonian_sources=[f"newtonian_seed-{s}.nc" for s in settings["seeds"]],
        sources=[f"x-{r:g}_seed-{s}.nc" for r, s in cases])


def test_gather_numbers_against_the_formulae():
    data = _gather(BLOCK, [(5.0, 0.2)], [(2.5, 0.1), (4.0, 0.3)])
    assert data["relative_viscosity"].dims == ("rate", "seed")
    f = [1 + 99 * (1 - math.exp(-x)) / x for x in (1.0, 100.0)]
    np.testing.assert_allclose(data["matrix_plastic_ratio"], f, rtol=1e-13)
    np.testing.assert_allclose(data["plastic_relative_viscosity"][:, 0], [2.5 * f[0], 4 * f[1]])
    np.testing.assert_allclose(data["plastic_relative_viscosity_stderr"][:, 0],
                               [0.1 * f[0], 0.3 * f[1]])
    np.testing.assert_allclose(data["regularisation_time"], [250.0, 25000.0])
    assert float(data["newtonian_relative_viscosity_mean"]) == 5.0
    assert float(data["newtonian_relative_viscosity_mean_stderr"]) == pytest.approx(0.2)
    s = math.sqrt(5.0 / 0.6)
    cot = [5.0 * (1 + 99 * (1 - math.exp(-x * s)) / (x * s)) / fx
           for x, fx in zip((1.0, 100.0), f)]
    np.testing.assert_allclose(data["cot_relative_viscosity"], cot, rtol=1e-12)
    np.testing.assert_allclose(data["measured_over_cot"][:, 0], [2.5 / cot[0], 4.0 / cot[1]],
                               rtol=1e-12)
    # the band: the estimate at g ± its error brackets the estimate
    band = [cot_relative_viscosity([1.0, 100.0], 99.0, 0.4, v) for v in (4.8, 5.2)]
    np.testing.assert_allclose(data["cot_relative_viscosity_low"], np.minimum(*band), rtol=1e-12)
    np.testing.assert_allclose(data["cot_relative_viscosity_high"], np.maximum(*band),
                               rtol=1e-12)
    assert np.all(data["cot_relative_viscosity_fine_low"] <= data["cot_relative_viscosity_fine"])
    assert data["rate_fine"].values[0] < 1.0 and data["rate_fine"].values[-1] > 100.0
    assert data["plastic_viscosity"].attrs["simulation_units"] == "m h-1 tau-1"
    assert data["regularisation_time"].attrs["simulation_units"] == "tau"
    for name in data.variables:
        assert "long_name" in data[name].attrs and "units" in data[name].attrs, name
    assert data.attrs["particle_reynolds_number"] == pytest.approx(0.1024)
    assert "git_sha" in data.attrs and data.attrs["completed"] == 1


def test_gather_seed_mean_of_g_has_block_errors_and_seed_scatter():
    block = {**BLOCK, "rates": [1.0], "seeds": [1, 2]}
    data = _gather(block, [(5.0, 0.1), (5.4, 0.2)], [(2.5, 0.1), (2.7, 0.1)])
    assert float(data["newtonian_relative_viscosity_mean"]) == pytest.approx(5.2)
    # sqrt(Σσ²/n² + var/n), var the seeds' sample variance
    expected = math.sqrt((0.1 ** 2 + 0.2 ** 2) / 4 + 0.08 / 2)
    assert float(data["newtonian_relative_viscosity_mean_stderr"]) == pytest.approx(expected)
    np.testing.assert_allclose(data["cot_relative_viscosity"],
                               cot_relative_viscosity([1.0], 99.0, 0.4, 5.2), rtol=1e-12)


def test_gather_refuses_a_run_of_other_settings_or_packing_and_a_missing_run():
    newtonian = [synthetic_run(BLOCK, None, 1, 5.0, 0.2)]
    runs = [synthetic_run(BLOCK, 1.0, 1, 2.5, 0.1), synthetic_run(BLOCK, 1.0, 1, 2.5, 0.1)]
    with pytest.raises(InputError, match=r"x-100_seed-1.nc: not the config's run.*M 250"):
        gather_suspension(BLOCK, newtonian, runs, newtonian_sources=["newtonian_seed-1.nc"],
                          sources=["x-1_seed-1.nc", "x-100_seed-1.nc"])
    other = [runs[0], synthetic_run(BLOCK, 100.0, 1, 2.5, 0.1, packing="elsewhere/seed-1.nc")]
    with pytest.raises(InputError, match=r"x-100_seed-1.nc: .*packing 'elsewhere/seed-1.nc' "
                                         r"\(expected 'packings/seed-1.nc'\)"):
        gather_suspension(BLOCK, newtonian, other, newtonian_sources=["newtonian_seed-1.nc"],
                          sources=["x-1_seed-1.nc", "x-100_seed-1.nc"])
    with pytest.raises(InputError, match="1 Papanastasiou run.*2 rate"):
        gather_suspension(BLOCK, newtonian, runs[:1], newtonian_sources=["n.nc"],
                          sources=["x-1_seed-1.nc"])


def test_written_file_reads_back_and_draws_the_figure(tmp_path):
    paths = []
    for name, run in (("newtonian", synthetic_run(BLOCK, None, 1, 5.0, 0.2)),
                      ("x-1", synthetic_run(BLOCK, 1.0, 1, 2.5, 0.1)),
                      ("x-100", synthetic_run(BLOCK, 100.0, 1, 4.0, 0.3))):
        paths.append(tmp_path / f"{name}_seed-1.nc")
        run.to_netcdf(paths[-1], engine="netcdf4")
    out = tmp_path / "suspension.nc"
    write_suspension(out, BLOCK, paths[:1], paths[1:], command="test")
    data = read_suspension(out)
    assert "test" in data.attrs["history"] and data.attrs["run_files"].endswith("x-100_seed-1.nc")
    assert json.loads(data.attrs["configuration"])["rates"] == [1.0, 100.0]
    write_suspension_figure(out, tmp_path / "fig3.png")
    assert (tmp_path / "fig3.png").stat().st_size > 10_000
    with pytest.raises(InputError, match="cannot read"):
        write_suspension_figure(tmp_path / "missing.nc", tmp_path / "no.png")
