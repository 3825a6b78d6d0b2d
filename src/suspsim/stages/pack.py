"""Stage 2b: the random packing of one (material, φ, seed), written before its simulations.

A study's inclusions are set by the config block ``simulation.inclusions`` (shape, radius in
kernel supports h, polydispersity, size ratio), which a material sheet's ``particles`` block may
override (shape, polydispersity, size ratio, and the physical radius in metres, which fixes the
length scale of that material's runs). :func:`particle_settings` merges the two into
:class:`Particles`; :func:`write_study_packing` packs bodies in the study's cubic box with
:func:`suspsim.bodies.packing.pack` and writes them with
:func:`suspsim.io.packing_file.write_packing`, exactly the packing a scene with the same
``inclusions`` keys would make for itself (:mod:`suspsim.sph.inclusions`), so a packing file is a
cached precomputation of the scene, not a different input.

:func:`pack_to_file` is the step ``suspsim pack`` and the workflow share. Lengths in h.
"""
from __future__ import annotations

import logging
import math
import os
from dataclasses import asdict, dataclass
from typing import Any, Mapping, Sequence

from ..bodies.packing import SHAPES, Packing, pack
from ..errors import InputError
from ..io.packing_file import write_packing
from ..io.schema import load_schema

log = logging.getLogger(__name__)

#: Smallest surface gap of a study's packings [h]: the scene's ``inclusions.min_gap`` default,
#: so that a packing file and a scene packing itself from the same keys are the same packing.
STUDY_MIN_GAP = float(load_schema("scene")["properties"]["inclusions"]["properties"]
                      ["min_gap"]["default"])

#: Particle settings of the contacts (the scene's ``inclusions.lubrication`` keys of the same
#: names): they set the runs, not the packings.
CONTACT_KEYS = ("friction", "rolling_friction")

#: The study's config key (or material-sheet key) behind each argument of the packer, for
#: error messages.
CONFIG_KEYS = {"box": "simulation.box", "volume_fraction": "simulation.volume_fractions",
               "radius": "simulation.inclusions.radius", "seed": "simulation.seeds",
               "shape": "simulation.inclusions.shape (or the material's particles.shape)",
               "polydispersity": "simulation.inclusions.polydispersity (or the material's "
                                 "particles.polydispersity)",
               "size_ratio": "simulation.inclusions.size_ratio (or the material's "
                             "particles.size_ratio)"}


@dataclass(frozen=True)
class Particles:
    """The rigid inclusions of a material's runs.

    ``shape`` sphere or sand; ``radius`` mean volume-equivalent radius a [h], the Reynolds
    length of the runs with inclusions; ``polydispersity`` coefficient of variation of the
    radii [1]; ``size_ratio`` largest/smallest radius bound [1]; ``physical_radius`` the
    particles' mean radius [m] when the material sheet gives it (it sets the length scale
    physical_radius/radius [m per h]), else None; ``friction`` the Coulomb coefficient of their
    contacts [1] and ``rolling_friction`` their rolling resistance [1] (the scene's
    ``inclusions.lubrication.friction`` and ``rolling_friction``; they do not shape packings).
    """

    shape: str = "sphere"
    radius: float = 2.5
    polydispersity: float = 0.0
    size_ratio: float = 5.0
    physical_radius: float | None = None
    friction: float = 0.0
    rolling_friction: float = 0.0

    def __post_init__(self):
        if self.shape not in SHAPES:
            raise InputError("particles", f"unknown shape {self.shape!r}; use one of "
                             f"{', '.join(SHAPES)}")
        for name in ("radius", "physical_radius"):
            value = getattr(self, name)
            if value is not None and not (math.isfinite(value) and value > 0):
                raise InputError("particles", f"{name} must be positive, got {value!r}")
        for name in CONTACT_KEYS:
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise InputError("particles", f"{name} must be >= 0, got {value!r}")

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able values (a Snakemake param, a netCDF attribute)."""
        return asdict(self)

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any]) -> "Particles":
        """From :meth:`to_dict` output; unknown keys raise InputError."""
        unknown = sorted(set(data) - set(cls.__dataclass_fields__))
        if unknown:
            raise InputError("particles", f"unknown key(s) {', '.join(unknown)}")
        return cls(**data)


def particle_settings(study: Mapping[str, Any],
                      sheet: Mapping[str, Any] | None = None) -> Particles:
    """The study's ``simulation.inclusions`` block, overridden by a material sheet's
    ``particles`` block (keys ``shape``, ``polydispersity``, ``size_ratio``, ``friction``,
    ``rolling_friction``, ``radius_m``)."""
    sheet = sheet or {}
    values = {name: study[name]
              for name in ("shape", "radius", "polydispersity", "size_ratio") + CONTACT_KEYS
              if name in study}
    values.update({name: sheet[name]
                   for name in ("shape", "polydispersity", "size_ratio") + CONTACT_KEYS
                   if sheet.get(name) is not None})
    if sheet.get("radius_m") is not None:
        values["physical_radius"] = float(sheet["radius_m"])
    return Particles(**values)


def pack_to_file(out_nc: str | os.PathLike, shape: str, box: Sequence[float],
                 volume_fraction: float, radius: float, *, command: str | None = None,
                 **options) -> Packing:
    """Pack (:func:`~suspsim.bodies.packing.pack`, ``options`` passed on) and write ``out_nc``
    atomically; returns the packing (:func:`describe_packing` says what was made).

    Raises InputError (arguments) or :class:`~suspsim.bodies.packing.PackingError`; nothing is
    written then.
    """
    packing = pack(shape, box, volume_fraction, radius, **options)
    write_packing(out_nc, packing, command=command)
    return packing


def describe_packing(packing: Packing, asked: float, out_nc: str | os.PathLike) -> str:
    """One line: bodies, box, volume fraction reached and asked, gaps, steps, time, file."""
    details = packing.details
    return (f"packed {packing.count} {packing.shape} bodies in a "
            f"{' x '.join(f'{length:g}' for length in packing.box)} box: volume fraction "
            f"{packing.volume_fraction:.12g} (asked {asked:g}), smallest gap "
            f"{details['smallest_gap']:.3g} (min {packing.min_gap:.3g}), "
            f"{details['relaxation_steps']} relaxation steps, {details['wall_time_s']:.2f} s; "
            f"wrote {out_nc}")


def write_study_packing(out_nc: str | os.PathLike, *, volume_fraction: float, seed: int,
                        box: float, particles: Particles | Mapping[str, Any]) -> Packing:
    """The packing of one (φ, seed) of a study in its cubic box of side ``box`` [h].

    Gap :data:`STUDY_MIN_GAP`; the physical radius plays no part. Raises InputError naming the
    study's config key (:data:`CONFIG_KEYS`) for a φ outside (0, 0.64), a box too small for
    the bodies, or bad particle settings.
    """
    if not isinstance(particles, Particles):
        particles = Particles.from_mapping(particles)
    try:
        packing = pack_to_file(out_nc, particles.shape, [float(box)] * 3,
                               float(volume_fraction), particles.radius,
                               polydispersity=particles.polydispersity,
                               size_ratio=particles.size_ratio, seed=int(seed),
                               min_gap=STUDY_MIN_GAP,
                               command=f"suspsim workflow pack: phi {volume_fraction:g}, seed "
                                       f"{seed}, box {box:g}, {particles.to_dict()}")
    except InputError as err:
        raise InputError(CONFIG_KEYS.get(err.source, err.source), err.problem) from None
    log.info("%s", describe_packing(packing, volume_fraction, out_nc))
    return packing
