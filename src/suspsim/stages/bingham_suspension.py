"""The ``bingham_suspension`` study (issues 4 and 6): seed 000's Fig. 3 as workflow jobs.

Monosize spheres at volume fraction φ in seed 000's Papanastasiou matrix
μ(γ̇) = μ_pl + μ_0 (1 − e^(−Mγ̇))/(Mγ̇), μ_0 = r μ_pl (r = ``viscosity_ratio``, 99 in seed 000),
over the dimensionless rate x = Mγ̇; a Newtonian matrix on the same packing gives g(φ).

Set-up [design decided by the owner]. Every run uses the same scene in simulation units: a
3D cubic Lees–Edwards Couette box started from the linear profile at γ̇_sim = ``shear_rate``,
the lattice relaxed around the spheres, the inclusions' default numerics of a non-Newtonian
matrix, and the spheres of the seed's packing file (``inclusions.packing``: the Newtonian and
every Papanastasiou run of a seed share exactly the same centres). Only the law changes (:func:`matrix_law`):

    M = x/γ̇_sim,   μ_pl = 1/(1 + r (1 − e^(−x))/x),   μ_0 = r μ_pl

so that μ_m(γ̇_sim) = 1 [m h^-1 τ^-1] at every x and the particle Reynolds number
ρ γ̇_sim a²/μ_m(γ̇_sim) is the same at every rate (0.10 at ρ = 4.096, γ̇ = 0.004, a = 2.5 h).
The Newtonian reference is μ = 1, run with the numerics the Papanastasiou runs take by default
(``numerics.shifting`` = :data:`~suspsim.scene_rules.AUTO_SHIFTING_NON_NEWTONIAN`, and the
lubrication cutoff that follows it): the estimate then compares one numerical model in two
matrices. With the Newtonian defaults of then (A = 30, cutoff 0.185 h) the same packing read
g = 3.86 ± 0.09 against 5.01 ± 0.07 for the Papanastasiou run at x = 0.01, whose matrix is
Newtonian at that rate (2026-12-06). A run's relative viscosity η/μ_m(γ̇_sim) is then its
suspension viscosity in simulation units, and η/μ_pl = η_r μ_m/μ_pl with
μ_m/μ_pl = 1 + r (1 − e^(−x))/x (:func:`matrix_plastic_ratio`).

Gathering (with the Chateau–Ovarlez–Trung estimate) lives in
:mod:`suspsim.stages.bingham_suspension_gather` and the figure in
:mod:`suspsim.stages.bingham_suspension_figures`, so that editing them re-runs no simulation
(the rules' code fingerprints).

Symbols and units (simulation units, :mod:`suspsim.io.variables`): lengths [h]; number
density n [h^-3]; γ̇ [τ^-1]; M [τ]; viscosities [m h^-1 τ^-1]; x, r, φ, strains [1].
"""
from __future__ import annotations

import logging
import math
import os
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from ..errors import InputError
from ..rheology.laws import relaxation_factor
from ..run import run_scene
from ..scene import scene_from_dict
from ..scene_rules import AUTO_SHIFTING_NON_NEWTONIAN, lattice_mismatch
from .pack import STUDY_MIN_GAP, Particles, describe_packing, pack_to_file
from .simulate import check_packing, resumable

log = logging.getLogger(__name__)

#: The config block's name, the source of its InputErrors.
BLOCK = "bingham_suspension"
#: Case name of the Newtonian reference run of a seed (file ``newtonian_seed-N.nc``).
NEWTONIAN = "newtonian"
#: Floats of the block shared by every run of the study (schema: workflow/schemas).
SHARED_FLOATS = ("viscosity_ratio", "volume_fraction", "radius", "box", "number_density",
                 "shear_rate", "strain", "transient")
#: This block's key behind each argument of the packer, for its error messages.
PACK_KEYS = {"box": f"{BLOCK}.box", "volume_fraction": f"{BLOCK}.volume_fraction",
             "radius": f"{BLOCK}.radius", "seed": f"{BLOCK}.seeds"}
#: Numerical tolerance when matching a file name's rate to the config's [1].
RATE_MATCH = 1e-12


def study_settings(block: Mapping[str, Any]) -> dict:
    """The ``bingham_suspension`` config block checked and normalised: the floats of
    :data:`SHARED_FLOATS`, ``rates`` (x = Mγ̇ in config order) and ``seeds`` as lists, and
    ``threads``.

    Raises InputError naming the key for a repeated or non-positive rate, a repeated seed,
    φ ≤ 0, a non-positive ratio, radius, box, density, rate or strain, a transient not below
    the strain, or a box holding no whole lattice of the number density.
    """
    try:
        settings = {key: float(block[key]) for key in SHARED_FLOATS}
        rates = [float(x) for x in block.get("rates") or []]
        seeds = [int(s) for s in block.get("seeds") or []]
    except KeyError as err:
        raise InputError(BLOCK, "missing key", key=f"{BLOCK}.{err.args[0]}") from None
    except (TypeError, ValueError) as err:
        raise InputError(BLOCK, f"values must be numbers: {err}") from None
    if len(set(rates)) != len(rates):
        raise InputError(BLOCK, f"a rate is listed twice in {rates}", key=f"{BLOCK}.rates")
    bad = [x for x in rates if not (math.isfinite(x) and x > 0)]
    if bad:
        raise InputError(BLOCK, f"rates x = M gdot must be positive, got {bad}",
                         key=f"{BLOCK}.rates")
    if len(set(seeds)) != len(seeds):
        raise InputError(BLOCK, f"a seed is listed twice in {seeds}", key=f"{BLOCK}.seeds")
    for key in SHARED_FLOATS:
        if key != "transient" and not (math.isfinite(settings[key]) and settings[key] > 0):
            raise InputError(BLOCK, f"must be positive, got {settings[key]!r}",
                             key=f"{BLOCK}.{key}")
    if not 0 <= settings["transient"] < settings["strain"]:
        raise InputError(BLOCK, f"transient {settings['transient']:g} must lie in [0, strain = "
                         f"{settings['strain']:g})", key=f"{BLOCK}.transient")
    problem = lattice_mismatch(3, [settings["box"]] * 3, settings["number_density"])
    if problem:
        raise InputError(BLOCK, problem, key=f"{BLOCK}.box")
    return {**settings, "rates": rates, "seeds": seeds, "threads": int(block.get("threads", 1))}


def case_name(rate: float | None, tag=None) -> str:
    """The run's case in file names: ``newtonian`` (rate None) or ``x-<tag(rate)>``, ``tag``
    the workflow's number formatter (default ``repr``)."""
    return NEWTONIAN if rate is None else f"x-{(tag or repr)(rate)}"


def suspension_jobs(block: Mapping[str, Any]) -> list[dict]:
    """Every run of the block: per seed the Newtonian reference (``rate`` None), then per
    rate x (config order) and seed a Papanastasiou run. No rates: no runs (not even the
    Newtonian ones). Each job is the shared settings with its ``rate`` and ``seed``."""
    settings = study_settings(block)
    if not settings["rates"]:
        return []
    shared = {key: settings[key] for key in SHARED_FLOATS}
    cases = [None, *settings["rates"]]
    return [{**shared, "rate": rate, "seed": seed} for rate in cases for seed in settings["seeds"]]


def find_job(block: Mapping[str, Any], case: str, seed: int) -> dict:
    """The job of a file's ``case`` (``newtonian`` or ``x-<rate>``) and ``seed``; InputError
    when the config lists no such run."""
    if case == NEWTONIAN:
        rate = None
    elif case.startswith("x-"):
        try:
            rate = float(case[2:])
        except ValueError:
            raise InputError(BLOCK, f"no run {case!r}: not x-<number>") from None
    else:
        raise InputError(BLOCK, f"no run {case!r}: neither {NEWTONIAN} nor x-<number>")
    for job in suspension_jobs(block):
        same_rate = (job["rate"] is None if rate is None else job["rate"] is not None and
                     math.isclose(job["rate"], rate, rel_tol=RATE_MATCH, abs_tol=0.0))
        if same_rate and job["seed"] == int(seed):
            return job
    raise InputError(BLOCK, f"no run {case} at seed {seed} in the config")


def matrix_plastic_ratio(rate, viscosity_ratio: float):
    """μ_m/μ_pl = 1 + r (1 − e^(−x))/x [1] of seed 000's law at the dimensionless rate
    x = Mγ̇ [1] (scalar or array), r = μ_0/μ_pl."""
    x = np.asarray(rate, dtype=float)
    factor = np.vectorize(relaxation_factor, otypes=[float])(x)
    out = 1.0 + float(viscosity_ratio) * factor
    return float(out) if out.ndim == 0 else out


def matrix_law(rate: float | None, viscosity_ratio: float,
               shear_rate: float) -> tuple[str, dict[str, float]]:
    """(law name, params in simulation units) of a run: μ = 1 [m h^-1 τ^-1] for the Newtonian
    reference (``rate`` None), else the Papanastasiou law of the module docstring with
    M = x/γ̇_sim [τ], μ_pl = 1/(1 + r (1 − e^(−x))/x) and μ_0 = r μ_pl, so μ(γ̇_sim) = 1."""
    if rate is None:
        return "newtonian", {"mu": 1.0}
    mu_pl = 1.0 / matrix_plastic_ratio(rate, viscosity_ratio)
    return "papanastasiou", {"mu_pl": mu_pl, "mu_0": float(viscosity_ratio) * mu_pl,
                             "M": float(rate) / float(shear_rate)}


def particles(job: Mapping[str, Any]) -> Particles:
    """The study's monosize spheres of radius ``radius`` [h]."""
    return Particles(shape="sphere", radius=float(job["radius"]))


def pack_seed(settings: Mapping[str, Any], seed: int, out_nc: str | os.PathLike) -> None:
    """Write the packing of ``seed`` that every run of the seed reads: the material study's
    packer and gap (:func:`suspsim.stages.pack.pack_to_file`, the packing a scene of the same
    ``inclusions`` keys makes for itself). InputError naming this block's key for a φ the
    packer cannot reach or a box too small for the spheres."""
    phi, box = float(settings["volume_fraction"]), float(settings["box"])
    spheres = particles(settings)
    try:
        packing = pack_to_file(out_nc, spheres.shape, [box] * 3, phi, spheres.radius,
                               seed=int(seed), min_gap=STUDY_MIN_GAP,
                               command=f"suspsim workflow {BLOCK} pack: phi {phi:g}, seed "
                                       f"{seed}, box {box:g}, radius {spheres.radius:g}")
    except InputError as err:
        raise InputError(BLOCK, err.problem, key=PACK_KEYS.get(err.source, BLOCK)) from None
    log.info("%s", describe_packing(packing, phi, out_nc))


def suspension_scene(job: Mapping[str, Any], packing: str | os.PathLike | None,
                     threads: int = 1) -> dict:
    """The scene dict of one run (module docstring); ``packing`` the seed's packing file
    (None: the scene packs the same spheres itself)."""
    name, params = matrix_law(job["rate"], job["viscosity_ratio"], job["shear_rate"])
    spheres = particles(job)
    numerics = {"shifting": AUTO_SHIFTING_NON_NEWTONIAN} if job["rate"] is None else {}
    return {"dimension": 3, "box": [float(job["box"])] * 3,
            "number_density": float(job["number_density"]),
            "fluid": {"law": name, "params": params},
            "flow": {"type": "couette", "shear_rate": float(job["shear_rate"])},
            "run": {"strain": float(job["strain"]), "transient": float(job["transient"]),
                    "start": "linear", "threads": int(threads)},
            "lattice": {"relax": True},
            "numerics": numerics,
            "inclusions": {"phi": float(job["volume_fraction"]), "shape": spheres.shape,
                           "radius": spheres.radius, "min_gap": STUDY_MIN_GAP,
                           "seed": int(job["seed"]),
                           "packing": None if packing is None else str(packing)},
            "seed": int(job["seed"])}


def simulate_suspension(job: Mapping[str, Any], packing: str | os.PathLike | None,
                        out_nc: str | os.PathLike, *, threads: int = 1) -> None:
    """Run one job (:func:`suspension_jobs`) on the seed's ``packing`` and write suspsim's run
    file ``out_nc`` (atomically, :func:`suspsim.run.run_scene`; it holds
    ``relative_viscosity`` ± ``relative_viscosity_stderr``). A checkpoint of the same scene
    left by an interrupted job is resumed. Raises InputError for a packing of other settings."""
    label = case_name(job["rate"], lambda x: f"{x:g}")
    scene = scene_from_dict(suspension_scene(job, packing, threads),
                            source=f"{BLOCK} run {label}, seed {job['seed']}")
    if packing is not None:
        check_packing(packing, scene)
    law = scene.fluid.law
    log.info("%s, seed %d: %s %s, mu(gdot_sim) = %.12g", label, job["seed"], law.name,
             dict(law.params), float(law.viscosity(scene.flow.shear_rate)))
    out = run_scene(scene, out_nc, resume=resumable(Path(out_nc), scene), threads=threads)
    log.info("wrote %s", out)
