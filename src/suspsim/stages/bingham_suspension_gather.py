"""Gathering of the ``bingham_suspension`` study (:mod:`suspsim.stages.bingham_suspension`).

:func:`write_suspension` reads the Newtonian run of each seed and the Papanastasiou run of
each (x, seed) and writes one netCDF file on dimensions (``rate``, ``seed``)
(:func:`gather_suspension`):

    η/μ_m(γ̇)   the runs' ``relative_viscosity`` ± stderr (block averages of the run)
    η/μ_pl     = η/μ_m(γ̇) · μ_m/μ_pl, μ_m/μ_pl = 1 + r (1 − e^(−x))/x
    g          the Newtonian runs' relative viscosity ± stderr, per seed; ḡ its seed mean with
               the error of :func:`suspsim.analysis.seeds.seed_mean` (block errors and
               seed scatter)

and the Chateau–Ovarlez–Trung estimate at each x (:func:`cot_relative_viscosity`, from ḡ),

    η_COT/μ_m(γ̇) = g μ_m(γ̇ sqrt(g/(1 − φ)))/μ_m(γ̇)    (Chateau, Ovarlez & Trung 2008)

with the band of g = ḡ ± its error, and measured/COT. The same curves on a fine grid of x
(``rate_fine``) are there for the figure. Simulation units (:mod:`suspsim.io.variables`).
"""
from __future__ import annotations

import json
import logging
import math
import os
from datetime import datetime, timezone
from typing import Any, Mapping, Sequence

import numpy as np
import xarray as xr

from ..errors import InputError
from ..analysis.seeds import seed_mean
from ..io.atomic import atomic_path
from ..io.netcdf import read_run
from ..io.provenance import provenance
from ..io.variables import UNIT_SYSTEM, simulation_units
from ..rheology.laws import make_law
from ..rheology.suspension import chateau_ovarlez_trung_viscosity
from .bingham_suspension import BLOCK, matrix_law, matrix_plastic_ratio, study_settings

log = logging.getLogger(__name__)

REFERENCES = ("Martys, Rheol. Acta 49, 1059 (2010) [seed 000], Fig. 3; Chateau, Ovarlez & "
              "Trung, J. Rheol. 52, 489 (2008); Papanastasiou, J. Rheol. 31, 385 (1987)")
#: Points of the fine x grid of the curves [choice: smooth lines], and how far it extends
#: beyond the simulated rates on either side [factor of x].
FINE_POINTS = 241
FINE_MARGIN = 3.0
#: Largest relative difference between a run's scene and its job accepted as the same run [1].
SCENE_MATCH = 1e-9


def cot_relative_viscosity(rate, viscosity_ratio: float, volume_fraction: float,
                           newtonian: float):
    """η_COT/μ_m(γ̇) [1] at the dimensionless rates x = Mγ̇ [1] (array) of seed 000's law of
    ratio r, at φ [1] and Newtonian relative viscosity g [1]:
    g μ_m(x sqrt(g/(1 − φ)))/μ_m(x) (:func:`~suspsim.rheology.suspension.
    chateau_ovarlez_trung_viscosity` on the law in units μ_pl = 1, M = 1, where the rate is x;
    the ratio does not depend on the units)."""
    law = make_law("papanastasiou", {"mu_pl": 1.0, "mu_0": float(viscosity_ratio), "M": 1.0})
    x = np.asarray(rate, dtype=float)
    eta = chateau_ovarlez_trung_viscosity(law.viscosity, x, volume_fraction, newtonian)
    return np.asarray(eta, dtype=float) / law.viscosity(x)


def _cot_band(rate, settings, g: float, error: float) -> tuple[np.ndarray, ...]:
    """(estimate, low, high) at ``rate`` from g and the band of g ± error."""
    args = (settings["viscosity_ratio"], settings["volume_fraction"])
    curves = [cot_relative_viscosity(rate, *args, value) for value in (g, g - error, g + error)]
    return curves[0], np.minimum.reduce(curves), np.maximum.reduce(curves)


def _attrs(long_name: str, powers=None, **more) -> dict:
    """units "1" and long_name, with simulation_units for a 3D quantity of ``powers`` of
    (h, m, τ, h³)."""
    out = {"units": "1", "long_name": long_name, **more}
    if powers is not None:
        out["simulation_units"] = simulation_units(powers, 3)
    return out


def _check_run(run: xr.Dataset, source: str, job: Mapping[str, Any],
               packing: str | None = None) -> None:
    """InputError naming ``source`` unless the run is the job's scene (law, rate, φ, box,
    number density, strain, seed), read the packing file ``packing`` (when given: its seed's
    Newtonian run's, so that both have the same spheres) and has a relative viscosity."""
    if "relative_viscosity" not in run:
        raise InputError(source, "not a run with inclusions: no relative_viscosity")
    scene = json.loads(run.attrs["scene"])
    name, params = matrix_law(job["rate"], job["viscosity_ratio"], job["shear_rate"])
    wanted = {"law": name, **params, "shear_rate": job["shear_rate"],
              "phi": job["volume_fraction"], "box": job["box"], "number_density": job["number_density"],
              "strain": job["strain"], "seed": job["seed"],
              **({} if packing is None else {"packing": packing})}
    found = {"law": scene["fluid"]["law"], **scene["fluid"]["params"],
             "shear_rate": scene["flow"]["shear_rate"], "phi": float(run["phi"]),
             "box": scene["box"][0], "number_density": scene["number_density"],
             "strain": scene["run"]["strain"], "seed": scene["inclusions"]["seed"],
             "packing": scene["inclusions"]["packing"]}
    wrong = [key for key, value in wanted.items()
             if (found.get(key) != value if isinstance(value, str) or value is None else
                 not math.isclose(float(found.get(key, math.nan)), float(value),
                                  rel_tol=SCENE_MATCH))]
    if wrong:
        details = ", ".join(f"{key} {found.get(key)!r} (expected {wanted[key]!r})"
                            for key in wrong)
        raise InputError(source, f"not the config's run on its seed's packing: {details}; "
                         "re-run its simulate job")


def gather_suspension(block: Mapping[str, Any], newtonian: Sequence[xr.Dataset],
                      runs: Sequence[xr.Dataset], *, newtonian_sources: Sequence[str],
                      sources: Sequence[str]) -> xr.Dataset:
    """The study's Dataset (module docstring) from the config ``block``, the Newtonian run
    of each of its seeds (``newtonian``, seed order) and the Papanastasiou runs (``runs``,
    rate-major: every seed of the first rate, then of the next), each with its file name.

    Raises InputError naming the file when a run is not its job's scene or lacks the
    relative viscosity, and naming the block when the numbers of runs do not match it.
    """
    settings = study_settings(block)
    rates, seeds = settings["rates"], settings["seeds"]
    if not rates or len(newtonian) != len(seeds) or len(runs) != len(rates) * len(seeds):
        raise InputError(BLOCK, f"{len(newtonian)} Newtonian and {len(runs)} Papanastasiou "
                         f"run(s) for {len(seeds)} seed(s) and {len(rates)} rate(s)")
    shared = {key: settings[key] for key in settings if key not in ("rates", "seeds", "threads")}
    for run, source, seed in zip(newtonian, newtonian_sources, seeds):
        _check_run(run, source, {**shared, "rate": None, "seed": seed})
    packings = [json.loads(run.attrs["scene"])["inclusions"]["packing"] for run in newtonian]
    for k, (run, source) in enumerate(zip(runs, sources)):
        _check_run(run, source, {**shared, "rate": rates[k // len(seeds)],
                                 "seed": seeds[k % len(seeds)]}, packings[k % len(seeds)])

    def table(name: str) -> np.ndarray:
        return np.array([float(run[name]) for run in runs]).reshape(len(rates), len(seeds))

    ratio = settings["viscosity_ratio"]
    x = np.array(rates)
    plastic = matrix_plastic_ratio(x, ratio)
    eta, eta_err = table("relative_viscosity"), table("relative_viscosity_stderr")
    g = np.array([float(run["relative_viscosity"]) for run in newtonian])
    g_err = np.array([float(run["relative_viscosity_stderr"]) for run in newtonian])
    per_seed = xr.Dataset({"g": ("seed", g), "g_stderr": ("seed", g_err)})
    g_mean, g_mean_err = (float(v) for v in seed_mean(per_seed, "g"))
    cot, cot_low, cot_high = _cot_band(x, settings, g_mean, g_mean_err)
    fine = np.geomspace(x.min() / FINE_MARGIN, x.max() * FINE_MARGIN, FINE_POINTS)
    fine_cot, fine_low, fine_high = _cot_band(fine, settings, g_mean, g_mean_err)
    both, viscosity, time = ("rate", "seed"), (2, 1, -1, -1), (0, 0, 1, 0)
    cot_name = "Chateau-Ovarlez-Trung estimate eta_COT/mu_m(gdot) from the seed-mean g"
    data = {
        "matrix_plastic_ratio": ("rate", plastic, _attrs(
            "matrix viscosity over its plastic viscosity mu_m(gdot)/mu_pl = 1 + r (1 - "
            "exp(-x))/x")),
        "plastic_viscosity": ("rate", 1.0 / plastic, _attrs(
            "plastic viscosity mu_pl of the run's law (mu_m(gdot) = 1)", viscosity)),
        "regularisation_time": ("rate", x / settings["shear_rate"], _attrs(
            "Papanastasiou regularisation time M = x/gdot of the run's law", time)),
        "relative_viscosity": (both, eta, _attrs(
            "suspension viscosity over the matrix viscosity at the same rate eta/mu_m(gdot)")),
        "relative_viscosity_stderr": (both, eta_err, _attrs(
            "standard error of relative_viscosity (block averaging of the run)")),
        "plastic_relative_viscosity": (both, eta * plastic[:, None], _attrs(
            "suspension viscosity over the matrix's plastic viscosity eta/mu_pl")),
        "plastic_relative_viscosity_stderr": (both, eta_err * plastic[:, None], _attrs(
            "standard error of plastic_relative_viscosity (block averaging of the run)")),
        "newtonian_relative_viscosity": ("seed", g, _attrs(
            "relative viscosity g of the suspension in the Newtonian matrix mu = 1")),
        "newtonian_relative_viscosity_stderr": ("seed", g_err, _attrs(
            "standard error of newtonian_relative_viscosity (block averaging of the run)")),
        "newtonian_relative_viscosity_mean": ((), g_mean, _attrs(
            "seed mean of the Newtonian relative viscosity g")),
        "newtonian_relative_viscosity_mean_stderr": ((), g_mean_err, _attrs(
            "standard error of the seed mean of g (block errors and seed scatter, "
            "suspsim.analysis.seeds.seed_mean)")),
        "cot_relative_viscosity": ("rate", cot, _attrs(cot_name)),
        "cot_relative_viscosity_low": ("rate", cot_low, _attrs(
            "lower edge of the COT estimate for g = mean -/+ its standard error")),
        "cot_relative_viscosity_high": ("rate", cot_high, _attrs(
            "upper edge of the COT estimate for g = mean -/+ its standard error")),
        "measured_over_cot": (both, eta / cot[:, None], _attrs(
            "measured relative viscosity over the COT estimate at the same rate")),
        "matrix_plastic_ratio_fine": ("rate_fine", matrix_plastic_ratio(fine, ratio), _attrs(
            "mu_m(gdot)/mu_pl of the law on the fine grid of x")),
        "cot_relative_viscosity_fine": ("rate_fine", fine_cot, _attrs(
            f"{cot_name}, on the fine grid of x")),
        "cot_relative_viscosity_fine_low": ("rate_fine", fine_low, _attrs(
            "lower edge of the COT band on the fine grid of x")),
        "cot_relative_viscosity_fine_high": ("rate_fine", fine_high, _attrs(
            "upper edge of the COT band on the fine grid of x")),
        "wall_time": (both, np.array([float(run.attrs["wall_time_s"]) for run in runs])
                      .reshape(len(rates), len(seeds)),
                      {"units": "s", "long_name": "wall time of the run"}),
        "newtonian_wall_time": ("seed", np.array([float(run.attrs["wall_time_s"])
                                                  for run in newtonian]),
                                {"units": "s", "long_name": "wall time of the Newtonian run"}),
    }
    coords = {"rate": ("rate", x, _attrs("dimensionless shear rate x = M gdot of the "
                                         "Papanastasiou law")),
              "seed": ("seed", np.array(seeds, dtype=np.int64), _attrs("packing seed")),
              "rate_fine": ("rate_fine", fine, _attrs("fine grid of x = M gdot for the "
                                                      "curves"))}
    prov = provenance()
    first = newtonian[0]
    attrs = {"Conventions": "CF-1.10",
             "title": "Seed 000 Fig. 3: viscosity of a suspension of spheres in a Papanastasiou "
                      "matrix against the Chateau-Ovarlez-Trung estimate",
             "source": f"suspsim {prov['suspsim_version']} (git {prov['git_sha']}), "
                       "suspsim.stages.bingham_suspension_gather",
             "history": f"{datetime.now(timezone.utc).isoformat(timespec='seconds')}: "
                        f"gathered {len(newtonian) + len(runs)} run files",
             "references": REFERENCES, "unit_system": UNIT_SYSTEM,
             "configuration": json.dumps({k: v for k, v in settings.items() if k != "threads"}),
             **shared,
             "matrix_viscosity_at_rate": 1.0,
             "particle_reynolds_number": (settings["number_density"] * settings["shear_rate"]
                                          * settings["radius"] ** 2),
             "particle_reynolds_number_comment": "rho gdot a^2/mu_m(gdot), the same at every x",
             "packing_volume_fraction": float(first["phi"]),
             "n_particles": int(first.attrs["n_particles"]),
             "n_bodies": int(first.attrs.get("n_bodies", 0)),
             "newtonian_run_files": " ".join(newtonian_sources),
             "run_files": " ".join(sources), "completed": 1, **prov}
    return xr.Dataset(data, coords=coords, attrs=attrs)


def write_suspension(out_nc: str | os.PathLike, block: Mapping[str, Any],
                     newtonian: Sequence[str | os.PathLike], runs: Sequence[str | os.PathLike],
                     *, command: str | None = None) -> xr.Dataset:
    """Read the run files (as :func:`gather_suspension` orders them), gather them and write
    ``out_nc`` atomically; returns the Dataset. InputError naming an unreadable file."""
    newtonian_sources, sources = [str(p) for p in newtonian], [str(p) for p in runs]
    data = gather_suspension(block, [read_run(p) for p in newtonian_sources],
                             [read_run(p) for p in sources],
                             newtonian_sources=newtonian_sources, sources=sources)
    if command:
        data.attrs["history"] += f" ({command})"
    with atomic_path(out_nc) as tmp:
        data.to_netcdf(tmp, engine="netcdf4",
                       encoding={name: {"_FillValue": None} for name in data.coords})
    log.info("wrote %s: g = %.4g ± %.2g; eta/mu_m by x: %s", out_nc,
             float(data["newtonian_relative_viscosity_mean"]),
             float(data["newtonian_relative_viscosity_mean_stderr"]),
             ", ".join(f"{x:g}: {m:.3g} (COT {c:.3g})" for x, m, c in zip(
                 data["rate"].values, data["relative_viscosity"].mean("seed").values,
                 data["cot_relative_viscosity"].values)))
    return data


def read_suspension(path: str | os.PathLike) -> xr.Dataset:
    """The file of :func:`write_suspension` (InputError naming it when unreadable)."""
    try:
        return xr.load_dataset(path)
    except (OSError, ValueError) as err:
        raise InputError(str(path), f"cannot read the bingham_suspension study: {err}") from err
