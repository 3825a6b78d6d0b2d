"""The ``dst`` study's points: one stress-controlled DST run per (φ, non-locality, stress index).

The workflow's ``dst`` config block (``workflow/schemas/config.schema.yaml``) lists volume
fractions φ, non-localities and the number of imposed stresses per flow curve;
:func:`study_points` expands it into points, :func:`point_scene` turns a point into a DST scene
(:mod:`suspsim.dst.scene`) and :func:`simulate_point` runs it with :func:`suspsim.dst.run.
run_dst_scene`, whose run file keeps the time series, the steady-window means and the final
per-particle snapshot (``particle_*``). :func:`band_points` adds the band runs: the figure
point (one φ, one stress) at chosen non-localities on a finer lattice, where moderate
non-locality's diffusion length sqrt(α/(K_f γ̇)), 0.026–0.043 L_y on the unstable branch at
φ = 0.54 (γ̇ from γ̇_max = 0.0285 to γ̇_min = 0.0110 σ*/η_s), spans about a lattice spacing.
Gathering and figures live in :mod:`suspsim.stages.dst_gather` and
:mod:`suspsim.stages.dst_figures`, so that editing them does not re-run the simulations (the
rules' code fingerprints).

Scaled units as :mod:`suspsim.dst.study`: L_y = η_s = σ* = 1; stresses in σ*, α in
L_y² σ*/η_s. Per point (SPEC §5.4, §5.6):

* the imposed stresses of a φ are :func:`suspsim.dst.study.spanning_stresses` (``stress_count``
  log-spaced over ``stress_range``, a third of them strictly between the turning points σ_β and
  σ_α), the same for every non-locality;
* the fluid is seed 002's (φ_m, φ_0, β, K_f from the config) with the non-locality's α; a
  non-locality named ``strong``, ``moderate`` or ``zero`` without a numeric ``alpha`` takes
  :data:`~suspsim.dst.study.STRONG_NONLOCALITY` (seed 002's 1e−5 m²/s),
  :data:`~suspsim.dst.study.MODERATE_NONLOCALITY` (1e−8 m²/s) or
  :data:`~suspsim.dst.study.LOCAL` (0);
* the density is ρ = ε σ_in/(K_f γ̇_WC²), ε = K_f γ̇ ρ L_y²/η = ``momentum_time_ratio`` (the
  scene's ``numerics.density: auto``, as :func:`~suspsim.dst.study.flow_curve`), the sound
  speed :func:`suspsim.dst.study.splitting_sound_speed` (Morris, raised to the upper-branch
  stress at γ̇_WC where a split particle can reach it);
* the start is f = f̂(σ_in) plus uncorrelated Gaussian noise of rms ``perturbation`` (seeded by
  ``seed``), V_w = γ̇_WC L_y — the start of :func:`suspsim.dst.study.stress_splitting`, for
  every non-locality, so the three differ in α only;
* the run lasts the non-locality's ``equilibration_strain`` + ``averaging_strain`` (nominal
  strain γ̇_WC t) on the unstable branch, at most the ``stable_branch`` strains off it
  (:func:`study_points`); the first is discarded, the second averaged (batch means over whole
  strain units when ≥ 8 of them, else Flyvbjerg–Petersen blocking).
"""
from __future__ import annotations

import copy
import logging
import math
import os
from dataclasses import dataclass, replace
from typing import Any, Mapping

import numpy as np

from ..dst.parameters import WyartCatesFluid
from ..dst.run import run_dst_scene
from ..dst.scene import dst_scene_from_dict
from ..dst.study import (LOCAL, MODERATE_NONLOCALITY, STRONG_NONLOCALITY, spanning_stresses,
                         splitting_sound_speed)
from ..errors import InputError, NumericalError
from ..run import checkpoint_path

log = logging.getLogger(__name__)

#: Named non-localities α [L_y² σ*/η_s] (seed 002's three cases).
NAMED_NONLOCALITIES = {"strong": STRONG_NONLOCALITY, "moderate": MODERATE_NONLOCALITY,
                       "zero": LOCAL}
#: Density tolerance δ of the automatic sound speed [1] (the scene's default).
DENSITY_TOLERANCE = 0.01
#: A run stopped by the density-error limit restarts with c times this, at most this often.
SOUND_SPEED_FACTOR, SOUND_SPEED_RETRIES = 2.0, 2


@dataclass(frozen=True)
class Nonlocality:
    """A non-locality of the study: its ``name`` (file names, the netCDF coordinate), α
    [L_y² σ*/η_s] and the nominal strains discarded and averaged [1]."""

    name: str
    alpha: float
    equilibration_strain: float
    averaging_strain: float


@dataclass(frozen=True)
class StudyPoint:
    """One run: φ [1], the non-locality, the index of its stress on the φ's grid and the
    imposed stress σ_in [σ*]."""

    phi: float
    nonlocality: Nonlocality
    index: int
    stress: float


def nonlocalities(settings: Mapping[str, Any]) -> list[Nonlocality]:
    """The config's non-localities, α resolved from the name where not given.

    Raises InputError for a repeated name or an unknown name without ``alpha``.
    """
    out, seen = [], set()
    for entry in settings["nonlocalities"]:
        name = entry["name"]
        if name in seen:
            raise InputError("dst.nonlocalities", f"non-locality {name!r} is listed twice",
                             key="name")
        seen.add(name)
        alpha = entry.get("alpha")
        if alpha is None:
            if name not in NAMED_NONLOCALITIES:
                raise InputError("dst.nonlocalities", f"{name!r} is not one of "
                                 f"{', '.join(NAMED_NONLOCALITIES)}: give its alpha",
                                 key="alpha")
            alpha = NAMED_NONLOCALITIES[name]
        out.append(Nonlocality(name, float(alpha), float(entry["equilibration_strain"]),
                               float(entry["averaging_strain"])))
    return out


def study_fluid(settings: Mapping[str, Any], phi: float, alpha: float) -> WyartCatesFluid:
    """The scaled Wyart–Cates fluid (η_s = σ* = 1) of the config at ``phi`` and ``alpha``."""
    fluid = settings["fluid"]
    return WyartCatesFluid(eta_s=1.0, phi=float(phi), phi_m=fluid["phi_m"],
                           phi_0=fluid["phi_0"], sigma_star=1.0, beta=fluid["beta"],
                           K_f=fluid["K_f"], alpha=float(alpha))


def phi_stresses(settings: Mapping[str, Any], phi: float):
    """The imposed stresses [σ*] of ``phi`` (:func:`~suspsim.dst.study.spanning_stresses`)."""
    low, high = settings["stress_range"]
    return spanning_stresses(study_fluid(settings, phi, 0.0), settings["stress_count"],
                             low=low, high=high)


def on_unstable_branch(settings: Mapping[str, Any], phi: float, stress: float) -> bool:
    """True where σ_β < σ_in < σ_α on a flowing S-curve (φ < φ_m): the homogeneous state is
    unstable at zero non-locality there (SPEC §5.6)."""
    turning = study_fluid(settings, phi, 0.0).steady_law().turning_points()
    return (turning is not None and math.isfinite(turning.sigma_alpha)
            and turning.sigma_beta < stress < turning.sigma_alpha)


def study_points(settings: Mapping[str, Any]) -> list[StudyPoint]:
    """Every point of the study, φ-major, then non-locality, then stress index.

    Off the unstable branch (:func:`on_unstable_branch` false) a point runs for the
    ``stable_branch`` strains where they are shorter than its non-locality's: there the
    perturbed homogeneous state is linearly stable, and the perturbation relaxes at the rate
    K_f γ̇ (1 − g), g = (d ln f̂/d ln σ)(d ln η/d ln f) < 1 the gain of the per-particle loop,
    so the long runs a split needs are spent for nothing.
    """
    points = []
    kinds = nonlocalities(settings)
    stable = settings["stable_branch"]
    for phi in settings["volume_fractions"]:
        stresses = phi_stresses(settings, phi)
        for kind in kinds:
            short = replace(kind, equilibration_strain=min(kind.equilibration_strain,
                                                           float(stable["equilibration_strain"])),
                            averaging_strain=min(kind.averaging_strain,
                                                 float(stable["averaging_strain"])))
            points.extend(StudyPoint(float(phi), kind if on_unstable_branch(settings, phi, s)
                                     else short, index, float(s))
                          for index, s in enumerate(stresses))
    return points


def find_point(settings: Mapping[str, Any], phi: float, name: str, index: int, *,
               band: bool = False) -> StudyPoint:
    """The point (``band``: the band run) of (φ, non-locality name, stress index); InputError
    if the study has none."""
    for point in (band_points(settings) if band else study_points(settings)):
        if (math.isclose(point.phi, float(phi), rel_tol=1e-12)
                and point.nonlocality.name == name and point.index == int(index)):
            return point
    raise InputError("dst", f"no study point phi = {phi}, nonlocality = {name}, stress index "
                     f"{index}", key="volume_fractions")


def figure_index(settings: Mapping[str, Any]) -> int:
    """Index of the imposed stress of ``figure.phi`` nearest (in log) to ``figure.stress``.

    Raises InputError when ``figure.phi`` is not one of the volume fractions.
    """
    phi = float(settings["figure"]["phi"])
    if not any(math.isclose(phi, float(p), rel_tol=1e-9) for p in settings["volume_fractions"]):
        raise InputError("dst.figure", f"phi = {phi} is not one of the study's volume fractions "
                         f"{list(settings['volume_fractions'])}", key="phi")
    stresses = phi_stresses(settings, phi)
    return int(np.argmin(np.abs(np.log(stresses / float(settings["figure"]["stress"])))))


def band_points(settings: Mapping[str, Any]) -> list[StudyPoint]:
    """The band runs: the figure point (``figure.phi``, :func:`figure_index`) at each
    non-locality named in ``bands.nonlocalities``, with the ``bands`` run lengths (their
    lattice is ``bands.lattice``, :func:`point_scene` with ``band=True``). None without
    volume fractions or band non-localities."""
    bands = settings["bands"]
    if not settings["volume_fractions"] or not bands["nonlocalities"]:
        return []
    kinds = {kind.name: kind for kind in nonlocalities(settings)}
    missing = [name for name in bands["nonlocalities"] if name not in kinds]
    if missing:
        raise InputError("dst.bands", f"non-localities {missing} are not in dst.nonlocalities",
                         key="nonlocalities")
    phi, index = float(settings["figure"]["phi"]), figure_index(settings)
    stress = float(phi_stresses(settings, phi)[index])
    return [StudyPoint(phi, replace(kinds[name],
                                    equilibration_strain=float(bands["equilibration_strain"]),
                                    averaging_strain=float(bands["averaging_strain"])),
                       index, stress)
            for name in bands["nonlocalities"]]


def point_scene(settings: Mapping[str, Any], point: StudyPoint, *, band: bool = False) -> dict:
    """The DST scene (a dict for :func:`~suspsim.dst.scene.dst_scene_from_dict`) of a point.

    Lattice (n_x, n_y) = ``settings["lattice"]``, or ``settings["bands"]["lattice"]`` with
    ``band``: box [n_x/n_y, 1], resolution n_y. See the module docstring for the density,
    sound speed, start and run length.
    """
    lattice = settings["bands"]["lattice"] if band else settings["lattice"]
    n_x, n_y = (int(n) for n in lattice)
    kind = point.nonlocality
    fluid = study_fluid(settings, point.phi, kind.alpha)
    law = fluid.steady_law()
    epsilon = float(settings["momentum_time_ratio"])
    rate = fluid.shear_rate(point.stress)
    k_f = fluid.K_f if fluid.K_f > 0 else 1.0
    density = epsilon * point.stress / (k_f * rate ** 2)
    sound = splitting_sound_speed(law, point.stress, density, 1.0, DENSITY_TOLERANCE)
    return {
        "dimension": 2, "box": [n_x / n_y, 1.0], "resolution": n_y,
        "fluid": {"law": "wyart_cates",
                  "params": {"eta_s": 1.0, "phi": point.phi, "phi_m": fluid.phi_m,
                             "phi_0": fluid.phi_0, "sigma_star": 1.0, "beta": fluid.beta,
                             "K_f": fluid.K_f, "alpha": kind.alpha}},
        "flow": {"type": "stress_couette", "stress": point.stress},
        "run": {"strain": kind.equilibration_strain + kind.averaging_strain,
                "transient": kind.equilibration_strain,
                "perturbation": float(settings["perturbation"]), "seed": int(settings["seed"]),
                "threads": int(settings["threads"])},
        "numerics": {"momentum_time_ratio": epsilon, "density_tolerance": DENSITY_TOLERANCE,
                     "sound_speed": sound},
    }


def simulate_point(scene: Mapping[str, Any], out_nc: str | os.PathLike, *,
                   threads: int | None = None, source: str = "dst point") -> None:
    """Run one point's scene and write its run file atomically (``out_nc``).

    ``threads`` overrides the scene's ``run.threads``. A run stopped by the density-error
    limit is started again with the sound speed times :data:`SOUND_SPEED_FACTOR`, at most
    :data:`SOUND_SPEED_RETRIES` times: a split or banded run can carry stresses above the
    upper-branch stress at γ̇_WC that :func:`point_scene` sizes the sound speed for (at
    φ = 0.54, moderate non-locality, σ_in = 2.82σ*, the 14 × 12 run stopped at strain 16 at
    c = 0.526). The run file records the sound speed used (``sound_speed``). Raises
    InputError for an invalid scene and NumericalError for a blow-up that the retries do not
    cure.
    """
    scene = copy.deepcopy(dict(scene))
    for attempt in range(SOUND_SPEED_RETRIES + 1):
        built = dst_scene_from_dict(scene, source)
        log.info("%s: phi %g, alpha %g, sigma_in %.6g, %d x %d, strain %g (transient %g), "
                 "sound speed %.4g", source, built.fluid.phi, built.fluid.alpha,
                 built.flow.stress, built.geometry.n_x, built.geometry.n_y, built.run.strain,
                 built.run.transient, built.numerics.sound_speed)
        try:
            run_dst_scene(built, out_nc, threads=threads)
            return
        except NumericalError as err:
            if "density error" not in str(err) or attempt == SOUND_SPEED_RETRIES:
                raise
            log.warning("%s: %s; again with the sound speed times %g", source, err,
                        SOUND_SPEED_FACTOR)
            checkpoint_path(out_nc).unlink(missing_ok=True)
            scene["numerics"]["sound_speed"] *= SOUND_SPEED_FACTOR
