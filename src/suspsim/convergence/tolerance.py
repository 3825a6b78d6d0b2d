"""Tolerance-driven set-up of a scene (``suspsim run SCENE --tolerance ε``): the scene gives the
physics, the error model's picker the numerics.

Two modes. Verified (the default, :func:`run_verified`): the picker's attempts
(:func:`~.picker.verified_pick`) are run and each measured against the flow's exact solution
(:func:`measured_error`) until one meets ε; the output is that run and records every attempt.
Bound (``--no-verify``, :func:`choose`): one run of the cheapest configuration whose inflated
model bound (:func:`~.picker.pick`) meets ε, not checked.

Supported scenes: SPH fluid scenes (no inclusions) of periodic Couette or split-force
Poiseuille flow, 2D or 3D, any generalized-Newtonian law. A scene is turned into a case-like
description (:class:`~.cases.Case`) whose settings are the numerical axes and whose physics is
the scene's in dimensionless form, as :mod:`.cases` keeps it:

- Couette: the law and the shear rate are kept; the box side (cubic, periodic) and the number
  density n = q^d (snapped to whole rows) are chosen, and every stress-like law parameter
  (units Pa, Pa s, Pa s^n) is scaled by n/n_scene so ν = μ/ρ, the particle Reynolds number and
  the Bingham number stay (stresses in the output are in the new density's units: multiply by
  ``tolerance_stress_scale``⁻¹ for the scene's). The run becomes 1 strain unit of transient plus
  the chosen averaged units;
- Poiseuille: the channel is kept and its width W = L_y/2 in units of h is chosen. With
  s = W_scene/W (old h per new h) and the time unit kept, kinematic quantities scale as lengths:
  g → g/s, and stress-like parameters → (n/n_scene) × parameter/s², so Re, Bn and every time
  scale (τ) stay; the run time, transient and output interval [τ] are unchanged; the lateral
  sides follow the cases (3.75 h in 3D, 8 h in 2D, whole rows).

In both the time step and sound speed are automatic from the chosen ``dt_viscous_coefficient``
and ``wi_target`` (the scene's ``run.dt``/``run.sound_speed`` are dropped), the kernel is lucy
and the start jitter 0.1 (the model's training settings).
"""
from __future__ import annotations

import itertools
import json
import logging
import math
import time
from os import PathLike
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np
import xarray as xr

from suspsim.convergence.case_base import Axis
from suspsim.convergence.cases import Case, _channel_box, snapped_resolution
from suspsim.convergence.error_model import FIXED, ErrorModel, load_model
from suspsim.convergence.picker import Attempt, Choice, pick, verified_pick
from suspsim.convergence.study import error_bound
from suspsim.errors import InputError, NumericalError
from suspsim.io.atomic import atomic_path
from suspsim.io.netcdf import read_run
from suspsim.reference.poiseuille import split_force_poiseuille_profile
from suspsim.rheology.laws import LAW_SPECS
from suspsim.run import checkpoint_path, run_scene
from suspsim.scene import Scene, scene_from_dict
from suspsim.validation.flows import l2_peak_error

SUPPORTED = ("--tolerance supports SPH fluid scenes without inclusions of couette or poiseuille "
             "flow (2D or 3D); DST scenes, suspensions and other flows have no error model")
log = logging.getLogger(__name__)
#: Strain units of transient discarded before averaging in a Couette run [1] (as the cases).
TRANSIENT_STRAIN = 1.0


def _stress_like(law: str) -> set[str]:
    """Parameters of ``law`` with stress units (Pa, Pa s, Pa s^n), scaled with ρ."""
    return {p.name for p in LAW_SPECS[law].parameters if p.unit.startswith("Pa")}


def _check_supported(scene: Scene) -> None:
    if scene.inclusions.present or scene.flow.type not in ("couette", "poiseuille"):
        raise InputError(scene.source, SUPPORTED, key="flow.type")


def _scaled_params(scene: Scene, factor: float) -> dict[str, float]:
    stress = _stress_like(scene.fluid.law.name)
    return {k: (v * factor if k in stress else v) for k, v in scene.fluid.law.params.items()}


def _numerics(base: dict, settings: Mapping[str, Any]) -> dict:
    run = {k: v for k, v in base["run"].items() if k not in ("dt", "sound_speed")}
    return {"kernel": settings["kernel"],
            "lattice": {**base["lattice"], "jitter": float(settings["jitter"])},
            "numerics": {**base["numerics"],
                         "dt_viscous_coefficient": float(settings["dt_coefficient"]),
                         "wi_target": float(settings["wi_target"])}, "run": run}


def scene_case(scene: Scene) -> Case:
    """The scene as a case: its physics fixed, the numerical axes of :mod:`.cases` free
    (defaults: the scene's own values where it has them). InputError for unsupported scenes."""
    _check_supported(scene)
    base = scene.to_dict()
    dim = scene.dimension
    q0 = scene.number_density ** (1.0 / dim)
    common = (Axis("resolution", q0, "1", "lattice sites per support radius h/dx"),
              Axis("dt_coefficient", scene.numerics.dt_viscous_coefficient, "1", "C"),
              Axis("wi_target", scene.numerics.wi_target, "1", "Wi of the sound speed"),
              Axis("kernel", FIXED["kernel"], "1", "SPH kernel"),
              Axis("jitter", FIXED["jitter"], "1", "start jitter [spacings]"))
    name = f"scene {scene.source}"

    def unused(*_):
        raise InputError(name, "a scene's case has no reference to measure against")

    if scene.flow.type == "couette":
        axes = common + (Axis("side", float(scene.box[1]), "h", "box side"),
                         Axis("transient", TRANSIENT_STRAIN, "1", "strain units discarded"),
                         Axis("units", 3, "1", "strain units averaged"))

        def build(settings):
            side = float(settings["side"])
            q = snapped_resolution(float(settings["resolution"]), side)
            factor = q ** dim / scene.number_density
            out = {**base, **_numerics(base, settings), "box": [side] * dim,
                   "number_density": q ** dim,
                   "fluid": {"law": scene.fluid.law.name, "params": _scaled_params(scene, factor)}}
            strain = float(settings["transient"]) + int(settings["units"])
            out["run"].pop("time", None)
            out["run"].update(strain=strain, transient=float(settings["transient"]),
                              output_interval=min(out["run"]["output_interval"], 0.1))
            return out
    else:
        width0 = 0.5 * scene.box[1]
        axes = common + (Axis("width", width0, "h", "channel width W = L_y/2"),)

        def build(settings):
            box, density = _channel_box(settings, dim)
            s = width0 / float(settings["width"])
            factor = density / scene.number_density / s ** 2
            out = {**base, **_numerics(base, settings), "box": box, "number_density": density,
                   "fluid": {"law": scene.fluid.law.name, "params": _scaled_params(scene, factor)},
                   "flow": {**base["flow"], "body_force": scene.flow.body_force / s}}
            return out
    return Case(name, f"{scene.flow.type} scene {scene.source}", "none", axes, build, unused)


def _set_up(scene: Scene, case: Case, settings: Mapping[str, Any]) -> tuple[Scene, dict]:
    """The scene rescaled to ``settings`` and the run attributes of the set-up."""
    chosen = scene_from_dict(case.scene(settings), source=f"{scene.source} (tolerance)")
    if scene.flow.type == "couette":
        scale = chosen.number_density / scene.number_density
    else:
        s = 0.5 * scene.box[1] / (0.5 * chosen.box[1])
        scale = chosen.number_density / scene.number_density / s ** 2
    if not math.isfinite(scale):
        raise InputError(scene.source, "cannot rescale the scene")
    keys = [a.name for a in case.axes]
    return chosen, {"tolerance_stress_scale": scale,
                    "tolerance_settings": json.dumps({k: settings[k] for k in keys})}


def choose(scene: Scene, tolerance: float, model: ErrorModel | None = None
           ) -> tuple[Scene, Choice, dict[str, Any]]:
    """The scene set up for ``tolerance`` [1] by the inflated bound (:func:`~.picker.pick`,
    no run), the picker's choice, and the run attributes that record it
    (:data:`suspsim.io.variables.RUN_ATTRIBUTES`)."""
    model = model or load_model()
    case = scene_case(scene)
    choice = pick(case, tolerance, model)
    chosen, attrs = _set_up(scene, case, choice.settings)
    attrs.update(tolerance=float(tolerance), tolerance_mode="bound",
                 expected_error=choice.expected_error, expected_cost_s=choice.expected_cost,
                 tolerance_error_terms=json.dumps(choice.terms),
                 error_model=json.dumps({**model.provenance,
                                         "inflation": model.inflation_of(choice.drivers)}))
    return chosen, choice, attrs


def measured_error(scene: Scene, result: xr.Dataset) -> float:
    """Error bound [1] of a finished run ``result`` of ``scene`` against the flow's exact
    solution, as the cases measure it (:mod:`.cases`, the error model's training data):

    - Couette: the shear stress samples of each whole strain unit after ``run.transient``,
      averaged per unit and divided by μ(γ̇)γ̇; |mean − 1| + 2 standard errors of the unit means
      (:func:`~suspsim.validation.flows.couette_viscosity_ratio`). With fewer than two whole
      units, the run's ``viscosity`` and its block-average ``viscosity_stderr``;
    - Poiseuille: the L2/peak error of the steady-window ``velocity_profile`` against the
      split-force profile of the law (SPEC §6.2)."""
    if scene.flow.type == "couette":
        rate = scene.flow.shear_rate
        expected = float(scene.fluid.law.viscosity(rate)) * rate
        since = result["strain"].values - scene.run.transient
        units = int(math.floor(scene.run.length - scene.run.transient + 1e-9))
        unit = np.ceil(since - 1e-9).astype(int) - 1
        stress = result["shear_stress"].values
        means = [stress[unit == k].mean() / expected for k in range(units)
                 if np.any(unit == k)]
        if len(means) >= 2:
            return float(error_bound(np.mean(means) - 1.0,
                                     np.std(means, ddof=1) / math.sqrt(len(means))))
        return float(error_bound(float(result["viscosity"]) * rate / expected - 1.0,
                                 float(result["viscosity_stderr"]) * rate / expected))
    y = result["y"].values
    reference = split_force_poiseuille_profile(
        scene.fluid.law, scene.density * scene.flow.body_force, scene.box[1], y)
    return l2_peak_error(result["velocity_profile"].values, reference)


def attempt_path(out: Path, index: int) -> Path:
    """Where attempt ``index`` (from 1) of a verified run writes: beside ``out``."""
    return out.with_name(f"{out.stem}.attempt{index}{out.suffix}")


def run_verified(scene: Scene, tolerance: float, out: str | PathLike, *, resume: bool = False,
                 threads: int | None = None, model: ErrorModel | None = None,
                 run: Callable[..., Path] | None = None) -> list[Attempt]:
    """``suspsim run SCENE --tolerance ε``: the attempts of :func:`~.picker.verified_pick`, each
    a run of the rescaled scene (``run``, :func:`suspsim.run.run_scene`) to ``OUT.attemptK.nc``
    measured by :func:`measured_error`. The one that meets the tolerance becomes ``out`` with
    the run attributes ``tolerance``, ``tolerance_mode`` (verified), ``expected_error`` (the
    calibrated model's), ``measured_error``, ``expected_cost_s``, ``tolerance_settings``,
    ``tolerance_stress_scale``, ``tolerance_error_terms``, ``tolerance_attempts`` (every
    attempt's settings, model error, calibration, measured error and CPU time) and
    ``error_model``; the missed attempts' files are removed. With ``resume`` a finished attempt
    file of the same settings is measured again rather than re-run (its recorded CPU time is
    then that of reading it) and an interrupted one resumes from its checkpoint (the attempts
    are deterministic). An InputError when no
    attempt meets the tolerance (the files of the attempts stay)."""
    run = run or run_scene
    model = model or load_model()
    case = scene_case(scene)
    out = Path(out)
    numbers = itertools.count(1)

    def attempt(settings):
        chosen, attrs = _set_up(scene, case, settings)
        number = next(numbers)
        path = attempt_path(out, number)
        c0 = time.process_time()
        if not (resume and path.exists()
                and read_run(path).attrs.get("tolerance_settings") == attrs["tolerance_settings"]):
            log.info("tolerance %g: attempt %d, %s", tolerance, number,
                     attrs["tolerance_settings"])
            try:
                run(chosen, path, resume=resume and checkpoint_path(path).exists(),
                    threads=threads, extra_attrs={"tolerance": float(tolerance), **attrs})
            except NumericalError as err:
                log.warning("tolerance %g: attempt %d blew up: %s", tolerance, number, err)
                return math.inf, time.process_time() - c0, None
        measured = measured_error(chosen, read_run(path))
        log.info("tolerance %g: attempt %d measured %.3g", tolerance, number, measured)
        return measured, time.process_time() - c0, (chosen, path)

    attempts = verified_pick(case, tolerance, attempt, model)
    answer = attempts[-1]
    chosen, path = answer.result
    result = read_run(path)
    result.attrs.update(
        tolerance_mode="verified", measured_error=answer.measured,
        expected_error=answer.calibration * answer.model_error,
        expected_cost_s=model.expected_cost(answer.drivers),
        tolerance_error_terms=json.dumps(model.terms(answer.drivers)),
        tolerance_attempts=json.dumps([a.record() for a in attempts]),
        error_model=json.dumps({**model.provenance, "calibration": answer.calibration}))
    with atomic_path(out) as tmp:
        result.to_netcdf(tmp, engine="netcdf4")
    for other in out.parent.glob(f"{out.stem}.attempt*{out.suffix}"):
        other.unlink()
    return attempts
