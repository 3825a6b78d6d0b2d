"""Tolerance-driven set-up of a scene (``suspsim run SCENE --tolerance ε``): the scene gives the
physics, the error model's picker (:func:`~.picker.pick`) the numerics.

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

import json
import math
from typing import Any, Mapping

from suspsim.convergence.cases import Axis, Case, _channel_box, snapped_resolution
from suspsim.convergence.error_model import FIXED, ErrorModel, load_model
from suspsim.convergence.picker import Choice, pick
from suspsim.errors import InputError
from suspsim.rheology.laws import LAW_SPECS
from suspsim.scene import Scene, scene_from_dict

SUPPORTED = ("--tolerance supports SPH fluid scenes without inclusions of couette or poiseuille "
             "flow (2D or 3D); DST scenes, suspensions and other flows have no error model")
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


def choose(scene: Scene, tolerance: float, model: ErrorModel | None = None
           ) -> tuple[Scene, Choice, dict[str, Any]]:
    """The scene set up for ``tolerance`` [1], the picker's choice, and the run attributes that
    record it (:data:`suspsim.io.variables.RUN_ATTRIBUTES`)."""
    model = model or load_model()
    case = scene_case(scene)
    choice = pick(case, tolerance, model)
    chosen = scene_from_dict(case.scene(choice.settings), source=f"{scene.source} (tolerance)")
    if scene.flow.type == "couette":
        scale = chosen.number_density / scene.number_density
    else:
        s = 0.5 * scene.box[1] / (0.5 * chosen.box[1])
        scale = chosen.number_density / scene.number_density / s ** 2
    keys = [a.name for a in case.axes]
    attrs = {"tolerance": float(tolerance), "expected_error": choice.expected_error,
             "expected_cost_s": choice.expected_cost, "tolerance_stress_scale": scale,
             "tolerance_settings": json.dumps({k: choice.settings[k] for k in keys}),
             "tolerance_error_terms": json.dumps(choice.terms),
             "error_model": json.dumps({**model.provenance,
                                       "inflation": model.inflation_of(choice.drivers)})}
    if not math.isfinite(scale):
        raise InputError(scene.source, "cannot rescale the scene")
    return chosen, choice, attrs
