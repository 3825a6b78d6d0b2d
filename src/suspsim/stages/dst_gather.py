"""Gather the ``dst`` study's run files into ``flow_curves.nc``; the band criterion.

:func:`gather_flow_curves` reads one run file per study point (:mod:`suspsim.stages.dst`) and
returns a Dataset on (``phi``, ``nonlocality``, ``stress_index``) — the imposed stress
``imposed_stress`` (phi, stress_index) differs between volume fractions, since each φ's grid
crosses its own turning points — with, per point, the steady-window means of the run
(⟨γ̇⟩, ⟨σ⟩, V_w/L_y, ⟨f⟩, ψ1, ψ2 and their standard errors), the steady Wyart–Cates values at
σ_in, the lever rule (SPEC §5.6), the band measures of the final snapshot
(:func:`correlation_length`, the spread of f), the final per-particle snapshot on
``particle`` and the f and stress profiles on ``y``; and the steady Wyart–Cates S-curve of
each φ on ``curve_point`` for comparison. Scaled units (L_y = η_s = σ* = 1): every variable
has ``units`` ("1", or "s" for wall time), ``long_name`` and its dimension in
``simulation_units``.

**Band criterion.** Seed 002 (Fig. 4 g–i) describes the f field at zero non-locality as
discontinuous, particle by particle, and at moderate non-locality as bands: spatially
correlated. :func:`correlation_length` measures that as the distance ξ over which the pair
correlation of f fluctuations,

    C(r) = ⟨δf_i δf_j⟩_{|r_ij| ≈ r} / ⟨δf²⟩,   δf = f − ⟨f⟩,

falls to 1/e (pairs binned by distance in lattice spacings, x periodic by minimum image; C(0) =
1; linear interpolation between bins). Uncorrelated particle noise gives ξ below one spacing;
bands of width w give ξ ∝ w.
"""
from __future__ import annotations

import json
import logging
import math
import os
from datetime import datetime, timezone
from typing import Mapping, Sequence

import numpy as np
import xarray as xr

from ..errors import InputError
from ..io.atomic import atomic_path
from ..io.provenance import provenance
from ..dst.study import REFERENCES, UNIT_SYSTEM
from .dst import StudyPoint, band_points, nonlocalities, study_fluid, study_points

log = logging.getLogger(__name__)

#: Points of each φ's steady Wyart–Cates curve [choice].
CURVE_POINTS = 400
#: The curve spans the imposed stresses and this factor beyond each end [choice].
CURVE_MARGIN = 1.5
#: C(r) level that defines the correlation length [1].
CORRELATION_LEVEL = math.exp(-1.0)

_RATE, _STRESS, _LENGTH = "sigma_star eta_s-1", "sigma_star", "L_y"

#: Run-file variable -> (flow-curve name, long_name, simulation_units).
FROM_RUN = {
    "mean_shear_rate": ("shear_rate", "domain- and time-averaged shear-rate magnitude "
                        "<sqrt(2 D:D)>", _RATE),
    "mean_shear_rate_stderr": ("shear_rate_stderr", "standard error of shear_rate", _RATE),
    "mean_stress": ("measured_stress", "domain- and time-averaged shear stress <eta gdot>",
                    _STRESS),
    "mean_stress_stderr": ("measured_stress_stderr", "standard error of measured_stress",
                           _STRESS),
    "mean_wall_shear_rate": ("wall_shear_rate", "time-averaged top-wall velocity over the gap "
                             "V_w/L_y", _RATE),
    "mean_wall_shear_rate_stderr": ("wall_shear_rate_stderr", "standard error of "
                                    "wall_shear_rate", _RATE),
    "mean_frictional_fraction": ("frictional_fraction", "domain- and time-averaged fraction "
                                 "of frictional contacts <f>", None),
    "mean_lower_branch_fraction": ("psi1", "time-averaged share psi1 of particles with "
                                   "sigma_i < sigma_beta", None),
    "mean_lower_branch_fraction_stderr": ("psi1_stderr", "standard error of psi1", None),
    "mean_upper_branch_fraction": ("psi2", "time-averaged share psi2 of particles with "
                                   "sigma_i > sigma_alpha", None),
    "mean_upper_branch_fraction_stderr": ("psi2_stderr", "standard error of psi2", None),
    "wyart_cates_shear_rate": ("wyart_cates_shear_rate", "steady Wyart-Cates shear rate "
                               "sigma_in/eta(f_hat(sigma_in))", _RATE),
    "wyart_cates_frictional_fraction": ("steady_frictional_fraction", "steady fraction "
                                        "f_hat(sigma_in) = exp(-(sigma*/sigma_in)^beta)", None),
    "turning_point_position": ("q", "stress coordinate q = (sigma_in - sigma_beta)/"
                               "(sigma_alpha - sigma_beta)", None),
}
#: Run-file per-particle and profile variables -> (name, long_name, simulation_units).
SNAPSHOT = {
    "particle_x": ("particle_x", "x of each fluid particle at the end", _LENGTH),
    "particle_y": ("particle_y", "y of each fluid particle at the end", _LENGTH),
    "particle_frictional_fraction": ("particle_frictional_fraction", "f of each fluid "
                                     "particle at the end", None),
    "particle_shear_rate": ("particle_shear_rate", "local shear rate sqrt(2 D:D) of each "
                            "fluid particle at the end", _RATE),
    "particle_stress": ("particle_stress", "local stress eta gdot of each fluid particle at "
                        "the end", _STRESS),
}
PROFILES = {
    "frictional_fraction_profile": ("frictional_fraction_profile", "steady-window mean f "
                                    "over y (bins across the gap)", None),
    "stress_profile": ("stress_profile", "steady-window mean stress eta gdot over y", _STRESS),
}
#: Computed per point -> (long_name, simulation_units, comment).
COMPUTED = {
    "relative_deviation": ("shear_rate/wyart_cates_shear_rate - 1", None, None),
    "psi_sum": ("psi1 + psi2, share of particles on a stable branch", None, None),
    "lever_rule": ("lever-rule share (sigma2 - sigma_in)/(sigma2 - sigma1) at wall_shear_rate",
                   None, "prediction for psi1 at the measured common rate; NaN off the "
                   "unstable branch"),
    "wyart_cates_lever_rule": ("lever-rule share at the Wyart-Cates rate gdot_WC(sigma_in)",
                               None, "seed 002 Fig. 5 line"),
    "correlation_length": ("distance at which the pair correlation of f fluctuations of the "
                           "final snapshot falls to 1/e", _LENGTH,
                           "the band criterion (suspsim.stages.dst_gather.correlation_length)"),
    "frictional_fraction_spread": ("standard deviation of f over the particles of the final "
                                   "snapshot", None, None),
    "equilibration_strain": ("nominal strain gdot_WC t discarded", None, None),
    "averaging_strain": ("nominal strain gdot_WC t averaged", None, None),
    "wall_time": ("wall-clock time of the run", None, None),
    "steps": ("predictor-corrector steps of the run", None, None),
}


def correlation_length(x, y, f, period: float, spacing: float) -> float:
    """Correlation length ξ [length of x, y] of the field f on particles (module docstring).

    ``x`` periodic with ``period``; pairs binned in shells of width ``spacing`` (the lattice
    spacing) around r = k·spacing, k ≥ 1. ξ is where C(r) first falls below 1/e, linearly
    interpolated from C(0) = 1; the largest shell centre when it never does; NaN when f is
    uniform. Raises ValueError for mismatched arrays or fewer than 2 particles.
    """
    x, y, f = (np.asarray(a, dtype=float).ravel() for a in (x, y, f))
    if not (x.size == y.size == f.size) or x.size < 2:
        raise ValueError("x, y and f must have the same length >= 2")
    delta = f - f.mean()
    variance = float(np.mean(delta ** 2))
    if not variance > 1e-300:
        return math.nan
    dx = x[:, None] - x[None, :]
    dx -= period * np.round(dx / period)
    r = np.hypot(dx, y[:, None] - y[None, :])
    upper = np.triu_indices(x.size, k=1)
    r, product = r[upper], (delta[:, None] * delta[None, :])[upper]
    shell = np.rint(r / spacing).astype(np.int64)
    count = np.bincount(shell)
    total = np.bincount(shell, weights=product)
    centres = np.arange(1, count.size) * spacing
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = total[1:] / count[1:] / variance
    keep = count[1:] > 0
    radii = np.concatenate([[0.0], centres[keep]])
    values = np.concatenate([[1.0], corr[keep]])
    below = np.nonzero(values < CORRELATION_LEVEL)[0]
    if below.size == 0:
        return float(radii[-1])
    k = below[0]
    r0, r1, c0, c1 = radii[k - 1], radii[k], values[k - 1], values[k]
    return float(r0 + (c0 - CORRELATION_LEVEL) * (r1 - r0) / (c0 - c1))


def gather_flow_curves(runs: Sequence[xr.Dataset], settings: Mapping, *,
                       sources: Sequence[str] | None = None,
                       bands: Sequence[xr.Dataset] = (),
                       band_sources: Sequence[str] | None = None) -> xr.Dataset:
    """The flow-curve Dataset (module docstring) of the study ``settings`` (the config's
    ``dst`` block) from its run files, one per :func:`~suspsim.stages.dst.study_points` point
    in that order, and the band runs (:func:`~suspsim.stages.dst.band_points` order), whose
    values get the prefix ``band_`` on the dimensions ``band_nonlocality`` and
    ``band_particle``.

    Raises InputError when the number of runs differs from the points or a run's φ, α or
    imposed stress is not its point's.
    """
    points = study_points(settings)
    sources = list(sources) if sources is not None else [f"run {i}" for i in range(len(runs))]
    if len(runs) != len(points):
        raise InputError("gather_dst", f"{len(runs)} run files for {len(points)} study points")
    phis = sorted({p.phi for p in points})
    names = list(dict.fromkeys(p.nonlocality.name for p in points))
    count = int(settings["stress_count"])
    n_particles = int(settings["lattice"][0]) * int(settings["lattice"][1])
    shape = (len(phis), len(names), count)
    cells: dict[str, np.ndarray] = {}

    def cell(name, extra=()):
        if name not in cells:
            cells[name] = np.full(shape + tuple(extra), np.nan)
        return cells[name]

    stress = np.full((len(phis), count), np.nan)
    for point, run, source in zip(points, runs, sources):
        at = (phis.index(point.phi), names.index(point.nonlocality.name), point.index)
        stress[at[0], at[2]] = point.stress
        values = _point_values(point, run, source, settings, n_particles)
        for name, value in values.items():
            cell(name, np.shape(value))[at] = value
    dims = ("phi", "nonlocality", "stress_index")
    data = {}
    for table in (FROM_RUN, SNAPSHOT, PROFILES):
        for name, long_name, scaled in table.values():
            extra = (("particle",) if table is SNAPSHOT else ("y",) if table is PROFILES
                     else ())
            data[name] = (dims + extra, cells[name], _attrs(long_name, scaled))
    for name, (long_name, scaled, comment) in COMPUTED.items():
        data[name] = (dims, cells[name], _attrs(long_name, scaled, comment,
                                                units="s" if name == "wall_time" else "1"))
    data.update(_curves(settings, phis, stress))
    if bands:
        data.update(_band_variables(settings, bands, band_sources or
                                    [f"band run {i}" for i in range(len(bands))]))
    kinds = {kind.name: kind for kind in nonlocalities(settings)}
    y_centres = runs[0]["y"].values
    coords = {
        "phi": ("phi", np.array(phis), _attrs("solid volume fraction", None)),
        "nonlocality": ("nonlocality", np.array(names, dtype=object),
                        {"long_name": "name of the non-locality (seed 002: strong, moderate, "
                                      "zero)"}),
        "stress_index": ("stress_index", np.arange(count),
                         {"long_name": "index of the imposed stress on its phi's grid",
                          "units": "1"}),
        "alpha": ("nonlocality", np.array([kinds[n].alpha for n in names]),
                  _attrs("diffusivity alpha of f (non-locality)", "L_y2 sigma_star eta_s-1")),
        "imposed_stress": (("phi", "stress_index"), stress,
                           _attrs("imposed shear stress sigma_in on the top wall", _STRESS)),
        "y": ("y", y_centres, _attrs("bin centre across the gap (walls at y = 0 and 1)",
                                     _LENGTH)),
        "particle": ("particle", np.arange(n_particles),
                     {"long_name": "fluid particle index", "units": "1"}),
    }
    dataset = xr.Dataset(data, coords=coords)
    prov = provenance()
    when = datetime.now(timezone.utc).isoformat(timespec="seconds")
    scene = json.loads(runs[0].attrs["scene"])
    dataset.attrs = {
        "Conventions": "CF-1.10",
        "title": "Stress-controlled 2D SPH flow curves of a Wyart-Cates suspension at several "
                 "volume fractions and non-localities (suspsim dst study)",
        "source": f"suspsim {prov['suspsim_version']} (git {prov['git_sha']}), "
                  "suspsim.stages.dst_gather",
        "history": f"{when}: gathered {len(runs)} run files",
        "references": REFERENCES, "unit_system": UNIT_SYSTEM,
        "eta_s": 1.0, "sigma_star": 1.0, **{k: float(v) for k, v in settings["fluid"].items()},
        "n_x": int(settings["lattice"][0]), "n_y": int(settings["lattice"][1]),
        "smoothing_ratio": float(scene["numerics"]["smoothing_ratio"]),
        "momentum_time_ratio": float(settings["momentum_time_ratio"]),
        "perturbation": float(settings["perturbation"]), "seed": int(settings["seed"]),
        "configuration": json.dumps(dict(settings)),
        "wall_time_s": float(np.nansum(cells["wall_time"])
                             + (np.nansum(dataset["band_wall_time"].values) if bands else 0.0)),
        "completed": 1, **prov}
    if bands:
        dataset.attrs.update(band_n_x=int(settings["bands"]["lattice"][0]),
                             band_n_y=int(settings["bands"]["lattice"][1]))
    return dataset


def _point_values(point: StudyPoint, run: xr.Dataset, source: str, settings: Mapping,
                  n_particles: int) -> dict:
    """Every per-point value of a run file: the run's means, snapshot and profiles, the band
    measures, the lever rule, wall time and steps."""
    _check(point, run, source)
    scene = json.loads(run.attrs["scene"])
    x, y = run["particle_x"].values, run["particle_y"].values
    if x.size != n_particles:
        raise InputError(source, f"{x.size} fluid particles, the study's lattice has "
                                 f"{n_particles}")
    values = {name: float(run[key]) for key, (name, _, _) in FROM_RUN.items()}
    for table in (SNAPSHOT, PROFILES):
        values.update({name: run[key].values for key, (name, _, _) in table.items()})
    f = run["particle_frictional_fraction"].values
    values["correlation_length"] = correlation_length(x, y, f, float(scene["box"][0]),
                                                      1.0 / int(scene["resolution"]))
    values["frictional_fraction_spread"] = float(np.std(f))
    values["equilibration_strain"] = point.nonlocality.equilibration_strain
    values["averaging_strain"] = point.nonlocality.averaging_strain
    values["wall_time"] = float(run.attrs["wall_time_s"])
    values["steps"] = float(run.attrs["n_steps"])
    law = study_fluid(settings, point.phi, 0.0).steady_law()
    values["lever_rule"] = _lever(law, point.stress, values["wall_shear_rate"])
    values["wyart_cates_lever_rule"] = _lever(law, point.stress,
                                              values["wyart_cates_shear_rate"])
    values["relative_deviation"] = values["shear_rate"] / values["wyart_cates_shear_rate"] - 1
    values["psi_sum"] = values["psi1"] + values["psi2"]
    return values


#: Per-point values the band runs keep (with the prefix band_).
BAND_VALUES = ("shear_rate", "measured_stress", "wall_shear_rate", "psi1", "psi2",
               "relative_deviation", "correlation_length", "frictional_fraction_spread",
               "wall_time")


def _band_variables(settings: Mapping, bands: Sequence[xr.Dataset],
                    sources: Sequence[str]) -> dict:
    points = band_points(settings)
    if len(bands) != len(points):
        raise InputError("gather_dst", f"{len(bands)} band run files for {len(points)} band "
                                       "points")
    n_particles = int(settings["bands"]["lattice"][0]) * int(settings["bands"]["lattice"][1])
    values = [_point_values(p, run, source, settings, n_particles)
              for p, run, source in zip(points, bands, sources)]
    tables = {**{v[0]: (v[1], v[2], None) for v in FROM_RUN.values()}, **COMPUTED}
    out = {}
    for name in BAND_VALUES:
        long_name, scaled, _ = tables[name]
        out[f"band_{name}"] = ("band_nonlocality", np.array([v[name] for v in values]),
                               _attrs(f"band run: {long_name}", scaled,
                                      units="s" if name == "wall_time" else "1"))
    for name, long_name, scaled in SNAPSHOT.values():
        out[f"band_{name}"] = (("band_nonlocality", "band_particle"),
                               np.array([v[name] for v in values]),
                               _attrs(f"band run: {long_name}", scaled))
    out["band_nonlocality"] = ("band_nonlocality",
                               np.array([p.nonlocality.name for p in points], dtype=object),
                               {"long_name": "non-locality of the band run"})
    out["band_phi"] = ((), points[0].phi, _attrs("volume fraction of the band runs", None))
    out["band_stress"] = ((), points[0].stress, _attrs("imposed stress of the band runs",
                                                       _STRESS))
    out["band_stress_index"] = ((), points[0].index,
                                _attrs("index of the band runs' stress on the grid of band_phi",
                                       None))
    return out


def write_flow_curves(run_files: Sequence[str | os.PathLike], out_nc: str | os.PathLike,
                      settings: Mapping, *,
                      band_files: Sequence[str | os.PathLike] = ()) -> None:
    """Gather ``run_files`` (study-point order) and ``band_files`` (band-point order) into
    ``out_nc`` atomically."""
    runs, bands = load_runs(run_files), load_runs(band_files)
    dataset = gather_flow_curves(runs, settings, sources=[str(p) for p in run_files],
                                 bands=bands, band_sources=[str(p) for p in band_files])
    encoding = {name: {"_FillValue": None} for name in dataset.coords
                if name not in ("nonlocality", "band_nonlocality")}
    with atomic_path(out_nc) as tmp:
        dataset.to_netcdf(tmp, engine="netcdf4", encoding=encoding)
    log.info("wrote %s: %d points, %.0f s of runs", out_nc, len(runs),
             dataset.attrs["wall_time_s"])


def load_runs(paths) -> list[xr.Dataset]:
    """Each run file loaded into memory; InputError naming the file it cannot read."""
    out = []
    for path in paths:
        try:
            out.append(xr.load_dataset(path))
        except (OSError, ValueError) as err:
            raise InputError(str(path), f"cannot read the run file: {err}") from err
    return out


def _check(point: StudyPoint, run: xr.Dataset, source: str) -> None:
    scene = json.loads(run.attrs.get("scene", "{}"))
    params = scene.get("fluid", {}).get("params", {})
    found = (params.get("phi"), params.get("alpha"), scene.get("flow", {}).get("stress"))
    wanted = (point.phi, point.nonlocality.alpha, point.stress)
    if any(v is None or not math.isclose(float(v), w, rel_tol=1e-9, abs_tol=1e-300)
           for v, w in zip(found, wanted)):
        raise InputError(source, f"run of (phi, alpha, stress) = {found}, the study point is "
                                 f"{wanted}")


def _lever(law, stress: float, rate: float) -> float:
    """Lever rule at ``rate``, NaN off the unstable branch or where a branch lacks the rate."""
    turning = law.turning_points()
    if (turning is None or not math.isfinite(turning.sigma_alpha) or not rate > 0
            or not turning.sigma_beta < stress < turning.sigma_alpha):
        return math.nan
    return float(law.lever_rule(stress, rate))


def _curves(settings: Mapping, phis: list[float], stress: np.ndarray) -> dict:
    """The steady S-curve of each φ over its imposed stresses (× CURVE_MARGIN each way), and
    its turning points (NaN without)."""
    low, high = np.nanmin(stress) / CURVE_MARGIN, np.nanmax(stress) * CURVE_MARGIN
    sigma = np.geomspace(low, high, CURVE_POINTS)
    rates, slopes, turning = [], [], {k: [] for k in ("sigma_beta", "gdot_max", "sigma_alpha",
                                                      "gdot_min")}
    for phi in phis:
        law = study_fluid(settings, phi, 0.0).steady_law()
        rates.append(np.asarray(law.shear_rate(sigma), dtype=float))
        with np.errstate(invalid="ignore"):
            slopes.append(np.asarray(law.log_slope(sigma), dtype=float))
        points = law.turning_points()
        for key in turning:
            turning[key].append(math.nan if points is None else float(getattr(points, key)))
    out = {
        "curve_stress": ("curve_point", sigma, _attrs("stress of the steady Wyart-Cates curve",
                                                      _STRESS)),
        "curve_shear_rate": (("phi", "curve_point"), np.array(rates),
                             _attrs("steady Wyart-Cates shear rate sigma/eta(f_hat(sigma))",
                                    _RATE)),
        "curve_log_slope": (("phi", "curve_point"), np.array(slopes),
                            _attrs("d ln gdot/d ln sigma of the steady curve", None,
                                   "negative on the unstable branch")),
    }
    for key, (long_name, scaled) in {
            "sigma_beta": ("turning-point stress sigma_beta (end of the lower branch)", _STRESS),
            "gdot_max": ("shear rate at sigma_beta", _RATE),
            "sigma_alpha": ("turning-point stress sigma_alpha (start of the upper branch)",
                            _STRESS),
            "gdot_min": ("shear rate at sigma_alpha", _RATE)}.items():
        out[key] = ("phi", np.array(turning[key]), _attrs(long_name, scaled,
                                                          "NaN without turning points"))
    return out


def _attrs(long_name: str, scaled: str | None, comment: str | None = None, *,
           units: str = "1") -> dict:
    out = {"units": units, "long_name": long_name}
    if scaled:
        out["simulation_units"] = scaled
    if comment:
        out["comment"] = comment
    return out
