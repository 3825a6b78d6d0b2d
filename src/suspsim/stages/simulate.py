"""Stage 3: one SPH simulation per (material, φ, γ̇, seed), results back in physical units.

From the matrix fit (``fit.json``, SI) and a physical shear rate γ̇ [1/s], :func:`simulation_scene`
maps the law to simulation units (:mod:`suspsim.units`, SPEC §7) and builds a Lees–Edwards
Couette scene (SPEC §2.7) of a cubic box; :func:`simulate_run` runs it through
:func:`suspsim.run.run_scene` (checkpoints, health checks, atomic write) and writes one run file
holding the run in simulation units plus its results converted back:

    η = S_μ ⟨σ_xy⟩_sim / γ̇_sim                  [Pa s]   suspension viscosity (SPEC §2.8)
    μ_m = μ(γ̇)                                   [Pa s]   the fitted matrix law
    η_r = η / μ_m = ⟨σ_xy⟩_sim / (γ̇_sim μ_sim(γ̇_sim))  [1]

with standard errors from the run's batch means. At φ = 0 the box holds the matrix alone, so
η_r = 1 within its error checks the solver against the fitted law at each rate.

At φ > 0 the scene holds rigid inclusions (:class:`~suspsim.stages.pack.Particles`, scene key
``inclusions``), read from the run's packing file (:mod:`suspsim.stages.pack`) when one is
given, else packed by the scene itself from the same keys, which gives the same packing. The
particle Reynolds number then takes the inclusion radius a [h] as its length (SPEC §7), and a
physical particle radius [m], when known, sets the length scale. What the suspension
viscosity is validated against, and where it falls short, is in the README (Suspensions).

The run starts from the linear profile (``run.start = linear``): the step is then limited by
μ(γ̇/2) rather than the zero-rate viscosity (:mod:`suspsim.sph.timestep`), which for a
yield-stress matrix is many orders of magnitude cheaper.
"""
from __future__ import annotations

import json
import logging
import os
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Mapping

import xarray as xr

from ..errors import InputError, NumericalError
from ..io.atomic import atomic_path
from ..io.checkpoint import load_checkpoint
from ..io.netcdf import read_run
from ..io.packing_file import read_packing
from ..io.study_variables import STUDY_VARIABLES
from ..rheology.laws import ConstitutiveLaw, make_law
from ..run import checkpoint_path, run_scene
from ..scene import Scene, scene_from_dict
from ..units import DEFAULT_REYNOLDS, UnitMapping, unit_mapping
from .pack import CONTACT_KEYS, STUDY_MIN_GAP, Particles

log = logging.getLogger(__name__)

#: Suffix of the simulation-unit run file written by run_scene before the physical results are
#: added; its checkpoint (``+ .ckpt.npz``) lets an interrupted job resume.
SIMULATION_SUFFIX = ".sim.nc"
#: Results of a run with inclusions that :func:`with_physical_results` replaces by their
#: physical-unit study variables of the same names (the run's are in simulation units).
REPLACED_RUN_RESULTS = ("phi", "suspension_viscosity", "relative_viscosity",
                        "relative_viscosity_stderr")
#: Largest |φ_packing − φ| accepted between a run's packing and its nominal φ [1]: packings
#: reach φ to round-off (:mod:`suspsim.bodies.packing`).
PHI_TOLERANCE = 1e-9


#: What a study can change when a run stops numerically (the solver's message names scene keys).
STUDY_NUMERICS_HINT = ("In a study the time step and sound speed follow simulation.numerics in the "
                       "study config: lower wi_target for a faster sound speed (smaller density "
                       "error, smaller step) or dt_viscous_coefficient for a smaller viscous step")


@dataclass(frozen=True)
class Resolution:
    """Numerical resolution of a study's runs.

    ``box`` cubic box side [h]; ``number_density`` [h⁻³] (box/spacing must be whole);
    ``strain`` total strain [1]; ``transient`` strain discarded before averaging [1];
    ``reynolds`` target particle Re [1] (SPEC §7); ``jitter`` initial lattice disorder
    [spacings], seeded by the run's seed.
    """

    box: float
    number_density: float
    strain: float
    transient: float
    reynolds: float = DEFAULT_REYNOLDS
    jitter: float = 0.0

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], source: str = "resolution") -> "Resolution":
        """From a config block; unknown keys or missing required ones raise InputError."""
        names = set(cls.__dataclass_fields__)
        unknown = sorted(set(data) - names)
        if unknown:
            raise InputError(source, f"unknown resolution key(s) {', '.join(unknown)}; "
                             f"known: {', '.join(sorted(names))}")
        try:
            return cls(**{k: float(v) for k, v in data.items()})
        except TypeError as err:
            raise InputError(source, f"incomplete resolution: {err}") from None
        except ValueError as err:
            raise InputError(source, f"resolution values must be numbers: {err}") from None


def read_fit(path: str | os.PathLike) -> dict:
    """The fit report ``fit.json`` as a dict; InputError if unreadable or without a law."""
    try:
        with open(path, encoding="utf-8") as fh:
            fit = json.load(fh)
        make_law(fit["law"], fit["params"])
    except FileNotFoundError:
        raise InputError(path, "no such fit report; run the fit stage first") from None
    except (OSError, json.JSONDecodeError, KeyError, TypeError, ValueError) as err:
        raise InputError(path, f"not a usable fit report ({err})") from None
    return fit


def simulation_scene(law: ConstitutiveLaw, shear_rate: float, *, volume_fraction: float,
                     seed: int, resolution: Resolution, threads: int | None = 1,
                     particles: Particles | None = None,
                     packing: str | os.PathLike | None = None,
                     numerics: Mapping[str, Any] | None = None) -> tuple[Scene, UnitMapping]:
    """The Couette scene of physical ``shear_rate`` [1/s] for ``law`` (SI) and its mapping.

    ``numerics`` the scene's numerics keys that differ from the solver's defaults (a study's
    ``simulation.numerics``).
    φ > 0: inclusions of ``particles`` (default :class:`Particles`()) packed with the run's
    ``seed`` and gap :data:`~suspsim.stages.pack.STUDY_MIN_GAP`, read from the file
    ``packing`` when given (it is not opened here); the Reynolds length is their radius [h].
    Raises InputError for a bad rate, φ, seed or resolution (e.g. a box that is not a whole
    number of lattice spacings) or a packing at φ = 0.
    """
    if not 0.0 <= volume_fraction < 1.0:
        raise InputError("simulation", f"volume fraction {volume_fraction!r} must be in [0, 1)")
    if volume_fraction == 0 and packing is not None:
        raise InputError(packing, "a packing file for a run at volume fraction 0")
    particles = particles or Particles()
    length = {}
    if volume_fraction > 0:
        length["reynolds_length"] = particles.radius
        if particles.physical_radius is not None:
            length.update(particle_size=particles.physical_radius,
                          particle_radius=particles.radius)
    mapping = unit_mapping(law, shear_rate, density=resolution.number_density,
                           reynolds_number=resolution.reynolds, **length)
    sim_law = mapping.law_to_simulation(law)
    inclusions = {"phi": float(volume_fraction)}
    if volume_fraction > 0:
        inclusions.update(shape=particles.shape, radius=particles.radius,
                          polydispersity=particles.polydispersity,
                          size_ratio=particles.size_ratio, min_gap=STUDY_MIN_GAP,
                          seed=int(seed), packing=None if packing is None else str(packing),
                          lubrication={name: getattr(particles, name)
                                       for name in CONTACT_KEYS})
    data = {"dimension": 3, "box": [resolution.box] * 3,
            "number_density": resolution.number_density,
            "fluid": {"law": sim_law.name, "params": dict(sim_law.params)},
            "flow": {"type": "couette", "shear_rate": mapping.simulation_shear_rate},
            "run": {"strain": resolution.strain, "transient": resolution.transient,
                    "start": "linear", "threads": "all" if threads is None else int(threads)},
            "lattice": {"jitter": resolution.jitter},
            "inclusions": inclusions,
            "numerics": dict(numerics or {}),
            "seed": int(seed)}
    return scene_from_dict(data, source="simulation resolution"), mapping


def simulate_run(fit_json: str | os.PathLike, out_nc: str | os.PathLike, *, shear_rate: float,
                 volume_fraction: float, seed: int, resolution: Mapping[str, Any] | Resolution,
                 threads: int | None = 1,
                 particles: Mapping[str, Any] | Particles | None = None,
                 packing: str | os.PathLike | None = None,
                 numerics: Mapping[str, Any] | None = None) -> xr.Dataset:
    """Simulate one (φ, γ̇, seed) of the matrix in ``fit_json`` and write ``out_nc`` atomically.

    ``particles``, ``packing`` and ``numerics`` as :func:`simulation_scene` (φ > 0); a packing file must
    hold the scene's shape, φ, seed and box. The simulation-unit run goes first to ``out_nc``
    with :data:`SIMULATION_SUFFIX` (and its checkpoint); a checkpoint of the same scene left
    by an interrupted job is resumed, one of another scene is discarded. Returns the written
    Dataset.

    Raises InputError (fit report, parameters, a packing of other settings), NumericalError
    (blow-up; the checkpoint is kept) or :class:`suspsim.run.RunInterrupted`.
    """
    fit = read_fit(fit_json)
    law = make_law(fit["law"], fit["params"])
    if not isinstance(resolution, Resolution):
        resolution = Resolution.from_mapping(resolution)
    if particles is not None and not isinstance(particles, Particles):
        particles = Particles.from_mapping(particles)
    scene, mapping = simulation_scene(law, shear_rate, volume_fraction=volume_fraction,
                                      seed=seed, resolution=resolution, threads=threads,
                                      particles=particles, packing=packing, numerics=numerics)
    if packing is not None:
        check_packing(packing, scene)
    low, high = fit.get("shear_rate_range", (shear_rate, shear_rate))
    if not low <= shear_rate <= high:
        log.warning("shear rate %g 1/s lies outside the measured range %g–%g 1/s: the matrix law "
                    "is extrapolated", shear_rate, low, high)
    out = Path(out_nc)
    sim_path = out.with_suffix(SIMULATION_SUFFIX)
    log.info("%s at %g 1/s: time scale %.4g s/tau, viscosity scale %.4g Pa s, particle Re %g "
             "(length %g h); law in simulation units %s", law.name, shear_rate,
             mapping.time_scale, mapping.viscosity_scale, mapping.reynolds_number,
             mapping.reynolds_length, dict(scene.fluid.law.params))
    try:
        run_scene(scene, sim_path, resume=resumable(sim_path, scene), threads=threads)
    except NumericalError as err:
        raise NumericalError(f"{err}. {STUDY_NUMERICS_HINT}") from None
    run = read_run(sim_path)
    dataset = with_physical_results(run, mapping, scene=scene, volume_fraction=volume_fraction,
                                    seed=seed, resolution=resolution, fit=fit)
    with atomic_path(out) as tmp:
        dataset.to_netcdf(tmp, engine="netcdf4",
                          encoding={name: {"_FillValue": None} for name in dataset.coords})
    sim_path.unlink(missing_ok=True)
    log.info("wrote %s: viscosity %.5g ± %.2g Pa s, matrix %.5g Pa s, relative %.4f ± %.4f",
             out, float(dataset["suspension_viscosity"]),
             float(dataset["suspension_viscosity_stderr"]), float(dataset["matrix_viscosity"]),
             float(dataset["relative_viscosity"]), float(dataset["relative_viscosity_stderr"]))
    return dataset


def check_packing(path: str | os.PathLike, scene: Scene) -> None:
    """InputError unless the packing file holds the shape, φ, seed and box of ``scene``'s
    inclusions (a stale or foreign file would silently change the run)."""
    packing, spec = read_packing(path), scene.inclusions
    found = {"shape": packing.shape, "seed": packing.seed,
             "polydispersity": packing.polydispersity, "size_ratio": packing.size_ratio}
    wanted = {"shape": spec.shape, "seed": spec.seed, "polydispersity": spec.polydispersity,
              "size_ratio": spec.size_ratio}
    wrong = [f"{name} {found[name]!r} (the run's {wanted[name]!r})" for name in found
             if found[name] != wanted[name]]
    if abs(packing.volume_fraction - spec.phi) > PHI_TOLERANCE:
        wrong.append(f"volume fraction {packing.volume_fraction:.12g} (the run's {spec.phi:g})")
    if [float(length) for length in packing.box] != list(scene.box):
        wrong.append(f"box {list(packing.box)} (the run's {list(scene.box)})")
    if wrong:
        raise InputError(path, f"packing of other settings: {'; '.join(wrong)}; re-run its "
                         "pack job")


def with_physical_results(run: xr.Dataset, mapping: UnitMapping, *, scene: Scene,
                          volume_fraction: float, seed: int, resolution: Resolution,
                          fit: Mapping) -> xr.Dataset:
    """``run`` (simulation units) plus its results in physical units and the unit mapping.

    Adds the 0-d variables of :data:`~suspsim.io.study_variables.STUDY_VARIABLES` (φ, γ̇ and
    seed as scalar coordinates, so gathered runs combine by coordinate; the inclusions' radius
    [h], packing seed, body count and physical radius [m], NaN where they do not apply), the
    mapping as ``unit_*`` global attributes, with the run's Mach number, and the inclusion
    settings as the JSON attribute ``inclusions`` ("" at φ = 0) and ``inclusion_shape``. A
    run with inclusions has its own φ and viscosities in simulation units
    (:data:`REPLACED_RUN_RESULTS`): they are replaced once its φ is checked.
    """
    mapping = mapping.with_mach(float(run.attrs["mach_number"]))
    spec = scene.inclusions
    if spec.present:
        packed = float(run["phi"])
        if abs(packed - volume_fraction) > PHI_TOLERANCE:
            raise ValueError(f"the run's packing has phi = {packed:.12g}, not the study's "
                             f"{volume_fraction:g}")
        run = run.drop_vars([name for name in REPLACED_RUN_RESULTS if name in run.variables])
    nan = float("nan")
    mu_sim = float(scene.fluid.law.viscosity(mapping.simulation_shear_rate))
    eta_sim, err_sim = float(run["viscosity"]), float(run["viscosity_stderr"])
    values = {"suspension_viscosity": float(mapping.viscosity_to_physical(eta_sim)),
              "suspension_viscosity_stderr": float(mapping.viscosity_to_physical(err_sim)),
              "matrix_viscosity": mapping.matrix_viscosity,
              "relative_viscosity": eta_sim / mu_sim,
              "relative_viscosity_stderr": err_sim / mu_sim,
              "wall_time": float(run.attrs["wall_time_s"]),
              "n_particles": float(run.attrs["n_particles"]),
              "box_side": resolution.box, "number_density": resolution.number_density,
              "total_strain": resolution.strain, "transient_strain": resolution.transient,
              "particle_reynolds_number": mapping.reynolds_number,
              "reynolds_number": float(run.attrs["reynolds_number"]),
              "mach_number": mapping.mach_number,
              "time_scale": mapping.time_scale, "viscosity_scale": mapping.viscosity_scale,
              "reynolds_length": mapping.reynolds_length,
              "inclusion_radius": spec.radius if spec.present else nan,
              "packing_seed": float(spec.seed) if spec.present else nan,
              "body_count": float(run.attrs.get("n_bodies", 0)),
              "particle_radius": (spec.radius * mapping.length_scale
                                  if spec.present and mapping.length_scale is not None else nan)}
    coords = {"phi": float(volume_fraction), "shear_rate": mapping.shear_rate, "seed": int(seed)}
    clashes = sorted((set(values) | set(coords)) & set(run.variables))
    if clashes:
        raise ValueError(f"study variables {clashes} would overwrite the run's own")
    out = run.copy()
    for name, value in values.items():
        out[name] = xr.Variable((), value, attrs=STUDY_VARIABLES[name].attrs())
    out = out.assign_coords({name: xr.Variable((), value, attrs=STUDY_VARIABLES[name].attrs())
                             for name, value in coords.items()})
    out.attrs.update(mapping.to_attributes())
    out.attrs["resolution"] = json.dumps(asdict(resolution))
    settings = {name: value for name, value in asdict(spec).items()
                if name in ("shape", "radius", "polydispersity", "size_ratio", "min_gap")}
    settings.update({name: getattr(spec.lubrication, name) for name in CONTACT_KEYS})
    if spec.present and mapping.length_scale is not None:
        settings["physical_radius"] = spec.radius * mapping.length_scale
    out.attrs["inclusions"] = json.dumps(settings) if spec.present else ""
    out.attrs["inclusion_shape"] = spec.shape if spec.present else "none"
    out.attrs["matrix_fit"] = json.dumps({"law": fit["law"], "params": fit["params"],
                                          "source": fit.get("source")}, ensure_ascii=False)
    bodies = f" ({spec.shape}s of radius {spec.radius:g} h)" if spec.present else ""
    out.attrs["title"] = (f"suspsim study run: {fit['law']} matrix, phi = {volume_fraction:g}"
                          f"{bodies}, shear rate {mapping.shear_rate:g} 1/s, seed {seed}")
    return out


def resumable(sim_path: Path, scene: Scene) -> bool:
    """True when a checkpoint of this very scene is waiting; one of another scene is removed."""
    ckpt = checkpoint_path(sim_path)
    if not ckpt.exists():
        return False
    try:
        load_checkpoint(ckpt, scene)
    except InputError as err:
        log.warning("discarding %s: %s", ckpt, err)
        ckpt.unlink()
        return False
    log.info("resuming the interrupted run from %s", ckpt)
    return True
