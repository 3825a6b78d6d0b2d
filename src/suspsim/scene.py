"""Scenes: the validated, complete description of one SPH run (SPEC §2), without I/O beyond loading.

A scene file is YAML. Its structure, types, descriptions and defaults live in the JSON schema
``suspsim/schemas/scene.schema.json`` (Draft 2020-12); the cross-key rules and the resolution
of ``auto`` values live in :mod:`suspsim.scene_rules`. Every
problem becomes one :class:`~suspsim.errors.InputError` line naming the file, the line and the
key, e.g. ``scene.yaml:9 [key 'flow.shear_rate']: couette flow needs shear_rate > 0``.

Simulation units: length h (the kernel's support radius, for lucy and quintic alike), mass m
(the particle mass, m = 1) and time τ (the unit of the law parameters and rates in the scene).
A density is then number_density × m [m h^-d], a viscosity m h^(2−d) τ^-1, a shear rate τ^-1.
``run.output_interval`` and ``run.transient`` count in the unit of the run length: strain when
``run.strain`` is given, τ when ``run.time`` is.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields
from functools import partial
from os import PathLike
from typing import Any, Mapping, NoReturn

import numpy as np

from .errors import InputError
from .io.schema import fail_at, fill_defaults, load_schema, validate
from .io.yamlfile import load_yaml
from .rheology.laws import ConstitutiveLaw
from .scene_rules import lattice_counts, resolve

#: The scene schema (a dict), with a description and default for every optional key.
SCENE_SCHEMA = load_schema("scene")
#: Particle mass m [m]: the mass unit.
PARTICLE_MASS = 1.0


@dataclass(frozen=True)
class FluidSpec:
    """The matrix fluid: ``law`` with parameters in simulation units."""

    law: ConstitutiveLaw


@dataclass(frozen=True)
class FlowSpec:
    """Imposed flow: ``type`` couette or poiseuille; ``shear_rate`` [τ^-1]; ``body_force`` g [h τ^-2]."""

    type: str
    shear_rate: float
    body_force: float


@dataclass(frozen=True)
class RunSpec:
    """Run settings with every default resolved except the solver's ``dt`` and ``sound_speed``.

    ``strain`` [1] or ``time`` [τ] (the other is None); ``dt`` [τ] and ``sound_speed`` [h/τ]
    are None for auto; ``output_interval`` and ``transient`` in the unit of the run length;
    ``checkpoint_interval_s`` [s wall clock]; ``threads`` None for all cores.
    """

    strain: float | None
    time: float | None
    dt: float | None
    sound_speed: float | None
    start: str
    output_interval: float
    checkpoint_interval_s: float
    transient: float
    profile_bins: int
    threads: int | None
    max_density_error: float
    density_outlier_fraction: float
    max_outlier_density_error: float
    max_mach: float

    @property
    def length(self) -> float:
        """The run length in its own unit (strain or τ)."""
        return self.strain if self.strain is not None else self.time

    def to_dict(self) -> dict:
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        for name in ("strain", "time"):
            if out[name] is None:
                del out[name]
        out["dt"] = "auto" if self.dt is None else self.dt
        out["sound_speed"] = "auto" if self.sound_speed is None else self.sound_speed
        out["threads"] = "all" if self.threads is None else self.threads
        return out


@dataclass(frozen=True)
class LatticeSpec:
    """Initial lattice: ``jitter`` [lattice spacings], uniform in ±jitter per coordinate;
    ``relax`` the start (resolved: True/False), until the density error is below
    ``relax_tolerance`` [1] or for at most ``relax_max_steps``."""

    jitter: float
    relax: bool
    relax_tolerance: float
    relax_max_steps: int


@dataclass(frozen=True)
class NumericsSpec:
    """Scheme choices (SPEC §2.3–2.6); add a field here and a key in the schema together."""

    bulk_correction: bool
    viscous_normalisation: bool
    normalisation_interval: int
    wi_target: float
    shifting: float
    shifting_rate: float
    shifting_at_bodies: str
    rate_smoothing: bool
    pressure_reference: str
    dt_viscous_coefficient: float
    spin_correction: bool


@dataclass(frozen=True)
class LubricationSpec:
    """Lubrication between bodies (SPEC §3.3): ``enabled``, ``cutoff_gap`` s_c [h], ``min_gap``
    s_min [h], ``repulsion`` k [1], ``friction`` μ_c [1], ``rolling_friction`` μ_r [1] (schema
    ``inclusions.lubrication``)."""

    enabled: bool
    cutoff_gap: float
    min_gap: float
    repulsion: float
    friction: float
    rolling_friction: float


@dataclass(frozen=True)
class InclusionsSpec:
    """Rigid inclusions (SPEC §3–4): ``shape`` sphere|sand, ``phi`` φ [1] (0: none), mean
    ``radius`` a [h], ``polydispersity`` [1], ``size_ratio`` [1], packing ``min_gap`` [h],
    ``packing`` file (None: pack from these keys), packing ``seed`` (None: the scene's),
    ``fluid_margin`` [lattice spacings] (fluid sites nearer a surface are removed)."""

    shape: str
    phi: float
    radius: float
    polydispersity: float
    size_ratio: float
    min_gap: float
    packing: str | None
    seed: int | None
    fluid_margin: float
    lubrication: LubricationSpec

    @property
    def present(self) -> bool:
        """True when the scene has bodies (φ > 0 or a packing file)."""
        return self.phi > 0.0 or self.packing is not None


class RunTimes:
    """Run length, sampling interval and transient as simulated time, for a scene whose
    ``run`` gives ``time`` or ``strain`` (its ``length``, ``output_interval``, ``transient``
    in that unit) and whose ``strain_rate`` turns strain into time."""

    @property
    def total_time(self) -> float:
        """Simulated time of the whole run [time unit of the scene]."""
        return self.to_time(self.run.length)

    @property
    def output_interval_time(self) -> float:
        """Time between samples."""
        return self.to_time(self.run.output_interval)

    @property
    def transient_time(self) -> float:
        """Time discarded before averaging."""
        return self.to_time(self.run.transient)

    def to_time(self, value: float) -> float:
        """Convert a value in the run-length unit (strain or time) to time."""
        return value if self.run.time is not None else value / self.strain_rate


@dataclass(frozen=True)
class Scene(RunTimes):
    """A complete, validated scene; ``box`` [h] is (x flow, y gradient[, z]), ``number_density`` [h^-d]."""

    dimension: int
    box: tuple[float, ...]
    number_density: float
    kernel: str
    fluid: FluidSpec
    flow: FlowSpec
    run: RunSpec
    lattice: LatticeSpec
    numerics: NumericsSpec
    inclusions: InclusionsSpec
    seed: int
    source: str = field(default="<dict>", compare=False, repr=False)

    @property
    def mass(self) -> float:
        """Particle mass m [m]."""
        return PARTICLE_MASS

    @property
    def density(self) -> float:
        """Nominal mass density ρ = number_density × m [m h^-d]."""
        return self.number_density * PARTICLE_MASS

    @property
    def volume(self) -> float:
        """Box volume (area in 2-D) [h^d]."""
        return math.prod(self.box)

    @property
    def lattice_spacing(self) -> float:
        """Nominal lattice spacing number_density^(−1/d) [h]."""
        return self.number_density ** (-1.0 / self.dimension)

    @property
    def lattice_counts(self) -> tuple[int, ...]:
        """Lattice sites per box side: round(side / spacing); their product is the particle count."""
        return lattice_counts(self.box, self.number_density)

    @property
    def strain_rate(self) -> float:
        """The rate that turns strain into time [τ⁻¹] (couette's shear rate)."""
        return self.flow.shear_rate

    def to_dict(self) -> dict:
        """The complete scene, defaults included, as plain JSON-able data."""
        return {"dimension": self.dimension, "box": list(self.box),
                "number_density": self.number_density, "kernel": self.kernel,
                "fluid": {"law": self.fluid.law.name, "params": dict(self.fluid.law.params)},
                "flow": asdict(self.flow), "run": self.run.to_dict(),
                "lattice": asdict(self.lattice), "numerics": asdict(self.numerics),
                "inclusions": asdict(self.inclusions), "seed": self.seed}


def _lattice(data: Mapping[str, Any], inclusions: InclusionsSpec) -> LatticeSpec:
    relax = data["relax"]
    if relax == "auto":
        relax = inclusions.present
    return LatticeSpec(float(data["jitter"]), bool(relax), float(data["relax_tolerance"]),
                       int(data["relax_max_steps"]))


def _inclusions(data: Mapping[str, Any]) -> InclusionsSpec:
    floats = ("phi", "radius", "polydispersity", "size_ratio", "min_gap", "fluid_margin")
    lub = data["lubrication"]
    values = {f.name: float(data[f.name]) if f.name in floats else data[f.name]
              for f in fields(InclusionsSpec) if f.name != "lubrication"}
    return InclusionsSpec(**values, lubrication=LubricationSpec(
        bool(lub["enabled"]), float(lub["cutoff_gap"]), float(lub["min_gap"]),
        float(lub["repulsion"]), float(lub["friction"]), float(lub["rolling_friction"])))


def load_scene(path: str | PathLike) -> Scene:
    """Read and validate a scene file; raises :class:`InputError` with file, line and key."""
    data, lines = load_yaml(path)
    return _build(data, str(path), lines)


def load_any_scene(path: str | PathLike):
    """Read and validate a scene file of either solver: a :class:`Scene`, or a
    :class:`suspsim.dst.scene.DSTScene` when ``fluid.law`` is wyart_cates or ``flow.type`` is
    stress_couette or channel (:func:`suspsim.dst.scene.is_dst_scene`)."""
    from .dst.scene import build_dst_scene, is_dst_scene

    data, lines = load_yaml(path)
    if is_dst_scene(data):
        return build_dst_scene(data, str(path), lines)
    return _build(data, str(path), lines)


def scene_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> Scene:
    """Validate a scene given as a mapping (tuples and NumPy scalars are accepted)."""
    return _build(_plain(data), source, {})


def _plain(data):
    if isinstance(data, Mapping):
        return {k: _plain(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [_plain(v) for v in data]
    return data.item() if isinstance(data, np.generic) else data


def _fail(source: str, lines: Mapping[tuple, int], path: tuple, problem: str) -> NoReturn:
    fail_at(source, lines, path, problem)


def _build(data, source: str, lines: Mapping[tuple, int]) -> Scene:
    if data is None:
        raise InputError(source, "the scene is empty; it must be a mapping of keys to values")
    if not isinstance(data, dict):
        raise InputError(source, "a scene must be a mapping of keys to values, "
                         f"not a {type(data).__name__}")
    validate(data, SCENE_SCHEMA, source=source, lines=lines)
    full, law = resolve(fill_defaults(data, SCENE_SCHEMA), data["run"], partial(_fail, source, lines))
    inclusions = _inclusions(full["inclusions"])
    run = {f.name: full["run"].get(f.name) for f in fields(RunSpec)}
    run.update({key: None for key in ("dt", "sound_speed", "threads") if run[key] in ("auto", "all")})
    numerics = {f.name: float(full["numerics"][f.name]) if f.type == "float" else full["numerics"][f.name]
                for f in fields(NumericsSpec)}
    return Scene(dimension=full["dimension"], box=tuple(float(s) for s in full["box"]),
                 number_density=float(full["number_density"]), kernel=full["kernel"],
                 fluid=FluidSpec(law), flow=FlowSpec(**full["flow"]), run=RunSpec(**run),
                 lattice=_lattice(full["lattice"], inclusions),
                 numerics=NumericsSpec(**numerics), inclusions=inclusions,
                 seed=int(full["seed"]), source=source)
