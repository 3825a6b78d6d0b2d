"""DST scenes: the validated description of one ``suspsim run`` of the Wyart–Cates solver.

A scene file is a DST scene when ``fluid.law`` is ``wyart_cates`` or ``flow.type`` is
``stress_couette`` or ``channel`` (:func:`is_dst_scene`); ``suspsim run`` then validates it
against ``suspsim/schemas/dst_scene.schema.json`` (structure, descriptions, defaults) and the
cross-key rules here, and maps it onto :class:`~suspsim.dst.parameters.WyartCatesFluid`,
:class:`~suspsim.dst.parameters.StressCouette` / :class:`~suspsim.dst.parameters.Channel`,
:class:`~suspsim.dst.parameters.Geometry` and :class:`~suspsim.dst.parameters.Numerics`.
Every problem is one :class:`~suspsim.errors.InputError` line naming file, line and key.

Units: any consistent set (issue 5) — seed 002 is SI; scaled scenes take η_s = σ* = L_y = 1.
Geometry: ``dimension`` 2 or 3; walls at y = 0 and y = box[1] (dummy layers outside), x
periodic over box[0] and, in 3D, z periodic over box[2] (box = [L_x, L_y, L_z]); ``resolution``
fluid particles across the gap, spacing Δx = box[1]/resolution, box[0]/Δx along x (box[2]/Δx
along z). Time: ``run.strain`` counts the nominal strain γ̇_WC t, γ̇_WC = σ_in/η(f̂(σ_in)) the
steady rate of the imposed stress (stress_couette only).

Resolved defaults [choices, documented in the schema]: ``numerics.density: auto`` for
stress_couette is ρ0 = ε σ_in/(K γ̇_WC² L_y²), ε = ``numerics.momentum_time_ratio`` (0.1) and
K = K_f (1 when K_f = 0), as :func:`suspsim.dst.study.flow_curve`; a channel needs a density
(its force density is ρ0 g). ``run.output_interval: auto`` is 0.05 strain (at most 1/20 of
the run) for stress_couette and time/200 for channel; ``run.transient: auto`` half the run;
``run.profile_bins: auto`` = resolution.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import partial
from typing import Any, Mapping

import numpy as np

from ..errors import InputError
from ..io.schema import fail_at, fill_defaults, load_schema, validate
from ..io.yamlfile import load_yaml
from ..scene import RunTimes
from .parameters import Channel, Geometry, Numerics, StressCouette, WyartCatesFluid

#: The DST scene schema (a dict), with a description and default for every optional key.
DST_SCENE_SCHEMA = load_schema("dst_scene")
#: Flow types of the DST solver.
DST_FLOWS = ("stress_couette", "channel")
DST_LAW = "wyart_cates"
#: Automatic sampling, as for SPH couette/poiseuille runs [choice].
AUTO_OUTPUT_STRAIN = 0.05
AUTO_OUTPUT_MIN_SAMPLES = 20
AUTO_OUTPUT_SAMPLES_CHANNEL = 200
#: box[0] (and box[2]) must be this close (relative) to a whole number of lattice spacings.
LATTICE_TOLERANCE = 1e-6


def is_dst_scene(data) -> bool:
    """True when ``data`` (a parsed scene file) asks for the DST solver."""
    if not isinstance(data, dict):
        return False
    fluid, flow = data.get("fluid"), data.get("flow")
    law = fluid.get("law") if isinstance(fluid, dict) else None
    kind = flow.get("type") if isinstance(flow, dict) else None
    return law == DST_LAW or kind in DST_FLOWS


@dataclass(frozen=True)
class DSTRunSpec:
    """Run settings, resolved: ``strain`` [1] or ``time`` [T] (the other None),
    ``output_interval`` and ``transient`` in the run-length unit, ``checkpoint_interval_s``
    [s wall clock], ``profile_bins``, ``threads`` (None: all cores), ``initial_fraction``
    (None: the flow's steady start), ``perturbation`` (rms of the Gaussian noise on the initial
    f [1]) and its generator's ``seed``."""

    strain: float | None
    time: float | None
    output_interval: float
    transient: float
    checkpoint_interval_s: float
    profile_bins: int
    threads: int | None
    initial_fraction: float | None
    perturbation: float = 0.0
    seed: int = 1

    @property
    def length(self) -> float:
        """The run length in its own unit (strain or T)."""
        return self.strain if self.strain is not None else self.time

    @property
    def unit(self) -> str:
        return "strain" if self.strain is not None else "time"


@dataclass(frozen=True)
class DSTScene(RunTimes):
    """A complete, validated DST scene (see the module docstring); ``box`` = (L_x, L_y) or
    (L_x, L_y, L_z)."""

    box: tuple[float, ...]
    resolution: int
    units: str
    fluid: WyartCatesFluid
    flow: StressCouette | Channel
    geometry: Geometry
    numerics: Numerics
    run: DSTRunSpec
    complete: dict = field(repr=False, compare=False)
    source: str = field(default="<dict>", compare=False, repr=False)

    @property
    def dimension(self) -> int:
        return self.geometry.dimension

    @property
    def flow_type(self) -> str:
        return "stress_couette" if isinstance(self.flow, StressCouette) else "channel"

    @property
    def nominal_shear_rate(self) -> float | None:
        """γ̇_WC(σ_in) [T⁻¹] of stress_couette (None for channel)."""
        return self.fluid.shear_rate(self.flow.stress) if self.flow_type == "stress_couette" \
            else None

    @property
    def strain_rate(self) -> float | None:
        """The rate that turns strain into time [T⁻¹]: :attr:`nominal_shear_rate`."""
        return self.nominal_shear_rate

    def build(self, *, threads: int | None = None):
        """A fresh :class:`~suspsim.dst.simulation.DSTSimulation` of this scene.

        With ``run.perturbation`` p > 0 each fluid particle's initial f becomes
        clip(f + p N(0, 1), 0, 1), N from ``numpy.random.default_rng(run.seed)``, after the
        flow's start is set (so V_w keeps the unperturbed rate), as
        :func:`suspsim.dst.study.stress_splitting` starts its runs.
        """
        from .simulation import DSTSimulation

        f0 = self.run.initial_fraction
        sim = DSTSimulation(self.fluid, self.flow, self.geometry, self.numerics,
                            threads=threads,
                            initial_fraction=None if f0 is None else (lambda y: f0))
        if self.run.perturbation > 0:
            rng = np.random.default_rng(self.run.seed)
            fraction = sim.f_all[:sim.n_fluid]
            sim.set_state(fraction=np.clip(
                fraction + self.run.perturbation * rng.standard_normal(sim.n_fluid), 0.0, 1.0))
        return sim

    def to_dict(self) -> dict:
        """The complete scene, defaults included, as plain JSON-able data."""
        return _copy(self.complete)


def load_dst_scene(path) -> DSTScene:
    """Read and validate a DST scene file; raises :class:`InputError` with file, line and key."""
    data, lines = load_yaml(path)
    return build_dst_scene(data, str(path), lines)


def dst_scene_from_dict(data: Mapping[str, Any], source: str = "<dict>") -> DSTScene:
    """Validate a DST scene given as a mapping."""
    return build_dst_scene(_copy(data), source, {})


def build_dst_scene(data, source: str, lines: Mapping[tuple, int]) -> DSTScene:
    """Validate parsed scene data (``lines``: key path -> line) into a :class:`DSTScene`."""
    fail = partial(fail_at, source, lines)
    if not isinstance(data, dict):
        raise InputError(source, "a scene must be a mapping of keys to values")
    _check_solver(data, fail)
    validate(data, DST_SCENE_SCHEMA, source=source, lines=lines)
    full = fill_defaults(data, DST_SCENE_SCHEMA)
    dimension = full["dimension"]
    if len(full["box"]) != dimension:
        axes = "x, y" if dimension == 2 else "x, y, z"
        fail(("box",), f"a {dimension}-D scene needs {dimension} box lengths ({axes}), got "
                       f"{len(full['box'])}")
    kind = full["flow"]["type"]
    fluid = _made(WyartCatesFluid, full["fluid"]["params"], ("fluid", "params"), fail)
    flow = _flow(full["flow"], fail)
    geometry = _geometry(full, fail)
    run = _run(full["run"], kind, full["resolution"], fail)
    rate = _check_start(fluid, flow, full, run, fail)
    numerics = _numerics(full["numerics"], flow, fluid, rate, full["box"][1], fail)
    complete = {**full, "run": _run_dict(run)}
    return DSTScene(box=tuple(float(side) for side in full["box"]),
                    resolution=int(full["resolution"]), units=full["units"], fluid=fluid,
                    flow=flow, geometry=geometry, numerics=numerics, run=run,
                    complete=complete, source=source)


def _check_solver(data: dict, fail) -> None:
    """The law and the flow must both be the DST solver's; a pointer for SPH-only keys."""
    fluid = data.get("fluid") if isinstance(data.get("fluid"), dict) else {}
    flow = data.get("flow") if isinstance(data.get("flow"), dict) else {}
    law, kind = fluid.get("law"), flow.get("type")
    if law is None or kind is None:
        return  # the schema names the missing key
    if law != DST_LAW:
        fail(("fluid", "law"), f"{kind} flow runs the Wyart-Cates solver and needs law "
                               f"wyart_cates (phi: 0, K_f: 0 is its Newtonian fluid); law "
                               f"{law!r} runs in couette or poiseuille flow")
    if kind not in DST_FLOWS:
        fail(("flow", "type"), f"the wyart_cates law runs between walls: flow.type "
                               f"stress_couette or channel, not {kind!r} (couette and poiseuille "
                               f"are the periodic SPH solver's)")
    if "number_density" in data:
        fail(("number_density",), "a DST scene sets its lattice by resolution (fluid particles "
                                  "across the gap), not number_density")


def _made(cls, values: Mapping[str, Any], path: tuple, fail, rename=None):
    """``cls(**values)``, its InputError re-raised at the scene key (``rename``: field ->
    scene key path)."""
    try:
        return cls(**values)
    except InputError as err:
        where = (rename or {}).get(err.key, path + ((err.key,) if err.key else ()))
        fail(where, err.problem)


def _flow(flow: dict, fail):
    stress, force = float(flow["stress"]), float(flow["body_force"])
    if flow["type"] == "stress_couette":
        if stress <= 0:
            fail(("flow", "stress"), "stress_couette flow needs stress > 0 (the shear stress "
                                     "imposed on the top wall)")
        if force != 0:
            fail(("flow", "body_force"), "stress_couette flow takes no body force; remove it or "
                                         "set 0")
        mass = None if flow["wall_mass"] == "auto" else flow["wall_mass"]
        return _made(StressCouette, {"stress": stress, "wall_mass": mass}, ("flow",), fail)
    if force <= 0:
        fail(("flow", "body_force"), "channel flow needs body_force > 0 (an acceleration along x)")
    if stress != 0:
        fail(("flow", "stress"), "channel flow has no imposed stress; remove it or set 0")
    if flow["wall_mass"] != "auto":
        fail(("flow", "wall_mass"), "channel walls are fixed and have no mass; remove wall_mass")
    return _made(Channel, {"body_force": force}, ("flow",), fail)


def _geometry(full: dict, fail) -> Geometry:
    gap = float(full["box"][1])
    n_y = int(full["resolution"])
    spacing = gap / n_y
    ratio, skin = float(full["numerics"]["smoothing_ratio"]), float(full["numerics"]["skin"])
    # Geometry's periodic-direction rule and DSTSimulation's three list cells of (3 + skin) h_sl.
    needed = math.ceil(max(10.8 * ratio + 1, 3 * (3 + skin) * ratio) - 1e-9)
    # The periodic directions: x, and z in 3D.
    counts = {index: _periodic_count(full["box"], index, spacing, needed, fail)
              for index in (0, 2)[:len(full["box"]) - 1]}
    layers = full["numerics"]["wall_layers"]
    values = {"n_x": counts[0], "n_y": n_y, "gap": gap, "smoothing_ratio": ratio,
              "wall_layers": None if layers == "auto" else layers, "n_z": counts.get(2)}
    rename = {"n_x": ("box", 0), "n_y": ("resolution",), "gap": ("box", 1),
              "n_z": ("box", 2), "smoothing_ratio": ("numerics", "smoothing_ratio"),
              "wall_layers": ("numerics", "wall_layers")}
    return _made(Geometry, values, (), fail, rename)


def _periodic_count(box, index: int, spacing: float, needed: int, fail) -> int:
    """Lattice spacings along the periodic box[index]: a whole number, at least ``needed``."""
    length = float(box[index])
    count = round(length / spacing)
    if abs(count * spacing / length - 1) > LATTICE_TOLERANCE:
        fail(("box", index), f"box[{index}] = {length:g} is not a whole number of lattice "
                             f"spacings box[1]/resolution = {spacing:.6g}; use e.g. "
                             f"{max(count, 1) * spacing:.6g}")
    if count < needed:
        fail(("box", index), f"box[{index}] holds {count} lattice spacings; the periodic "
                             f"direction needs at least {needed}: make box[{index}] >= "
                             f"{needed * spacing:.6g}")
    return count


def _run(run: dict, kind: str, resolution: int, fail) -> DSTRunSpec:
    if "strain" in run and "time" in run:
        fail(("run", "time"), "give either run.strain or run.time, not both")
    if "strain" not in run and "time" not in run:
        fail(("run", "strain"), "missing the run length: give run.strain (stress_couette) or "
                                "run.time")
    couette = kind == "stress_couette"
    if not couette and "strain" in run:
        fail(("run", "strain"), "channel flow has no imposed strain; give run.time instead")
    key = "strain" if "strain" in run else "time"
    length = float(run[key])
    interval = run["output_interval"]
    if interval == "auto":
        interval = (min(AUTO_OUTPUT_STRAIN, length / AUTO_OUTPUT_MIN_SAMPLES) if key == "strain"
                    else length / (AUTO_OUTPUT_MIN_SAMPLES if couette
                                   else AUTO_OUTPUT_SAMPLES_CHANNEL))
    elif interval > length:
        fail(("run", "output_interval"), f"output_interval {interval:g} exceeds the run {key} "
                                         f"{length:g}")
    transient = length / 2 if run["transient"] == "auto" else float(run["transient"])
    if transient >= length:
        fail(("run", "transient"), f"transient {transient:g} leaves nothing of the run {key} "
                                   f"{length:g} to average")
    bins = resolution if run["profile_bins"] == "auto" else int(run["profile_bins"])
    f0 = run["initial_fraction"]
    return DSTRunSpec(strain=length if key == "strain" else None,
                      time=length if key == "time" else None, output_interval=float(interval),
                      transient=float(transient),
                      checkpoint_interval_s=float(run["checkpoint_interval_s"]),
                      profile_bins=bins, threads=None if run["threads"] == "all"
                      else int(run["threads"]),
                      initial_fraction=None if f0 == "steady" else float(f0),
                      perturbation=float(run["perturbation"]), seed=int(run["seed"]))


def _run_dict(run: DSTRunSpec) -> dict:
    out = {f.name: getattr(run, f.name) for f in fields(run)}
    for name in ("strain", "time"):
        if out[name] is None:
            del out[name]
    out["threads"] = "all" if run.threads is None else run.threads
    out["initial_fraction"] = "steady" if run.initial_fraction is None else run.initial_fraction
    return out


def _check_start(fluid: WyartCatesFluid, flow, full: dict, run: DSTRunSpec, fail):
    """The start must not be jammed; returns γ̇_WC(σ_in) of stress_couette (None otherwise)."""
    phi = ("fluid", "params", "phi")
    try:
        if run.initial_fraction is not None:
            fluid.viscosity(run.initial_fraction)
        if isinstance(flow, StressCouette):
            return fluid.shear_rate(flow.stress)
        density = full["numerics"]["density"]
        if density != "auto":
            fluid.viscosity(fluid.frictional_fraction(density * flow.body_force
                                                      * full["box"][1] / 2))
        return None
    except InputError as err:
        fail(phi, f"{err.problem} at the start")


def _numerics(data: dict, flow, fluid: WyartCatesFluid, rate, gap: float, fail) -> Numerics:
    values = {f.name: data[f.name] for f in fields(Numerics) if f.name in data}
    density = data["density"]
    if density == "auto":
        if isinstance(flow, Channel):
            fail(("numerics", "density"), "channel flow needs numerics.density: its driving "
                                          "force density is density * body_force (the "
                                          "validation uses 1 in scaled units)")
        k = fluid.K_f if fluid.K_f > 0 else 1.0
        density = data["momentum_time_ratio"] * flow.stress / (k * rate ** 2 * gap ** 2)
    values["density"] = float(density)
    values["sound_speed"] = None if data["sound_speed"] == "auto" else data["sound_speed"]
    values["shifting"] = data["shifting"] > 0
    values["shifting_coefficient"] = data["shifting"] if data["shifting"] > 0 else 2.0
    rename = {"shifting_coefficient": ("numerics", "shifting")}
    return _made(Numerics, values, ("numerics",), fail, rename)


def _copy(data):
    if isinstance(data, Mapping):
        return {k: _copy(v) for k, v in data.items()}
    if isinstance(data, (list, tuple)):
        return [_copy(v) for v in data]
    return data.item() if isinstance(data, np.generic) else data
