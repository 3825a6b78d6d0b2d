"""Random dense packings of spheres and sand grains in a periodic box (SPEC §4).

Algorithm (both shapes):

1. sizes: N volume-equivalent radii t_i from :mod:`~suspsim.bodies.sizes`, N the nearest
   integer to φ V_box / E[V]; then one common factor λ with Σ λ³ V(t_i) = φ V_box, so the volume
   fraction is exact to round-off (grain volumes are the exact ⅓∫r³dΩ of their expansions);
2. shapes and orientations (grains: :func:`~suspsim.bodies.grains.random_grain`, uniform
   random orientations), centres uniform in the box — overlapping freely;
3. overlap removal at the final size by soft repulsion and FIRE (:mod:`~suspsim.bodies.relax`),
   O(N) per step with a cell list and Verlet skin. Random sequential addition jams near
   φ ≈ 0.38; a quench from random positions at the final size reaches any φ below jamming
   (≈ 0.64 for monodisperse spheres; O'Hern et al., Phys. Rev. E 68, 011306 (2003)) and gives
   an amorphous, uncrystallised structure;
4. exact check: every sphere pair has |r_ij| − a_i − a_j ≥ ``min_gap``; for grains, no point of a
   dense exact surface sample lies radially within ``min_gap`` of another grain
   (:mod:`~suspsim.bodies.overlap`). The relaxation works with a larger gap (spheres: 1 %;
   grains: plus twice the radius-table error) so that rounding and the table cannot spoil the
   check; a grain packing that fails it anyway is relaxed again with the working gap enlarged.

Every random number comes from ``numpy.random.default_rng(seed)`` in a fixed order (radii,
shapes, orientations, centres), so a seed reproduces a packing bit for bit on one machine.
The box is periodic in x, y, z; bodies may cross its faces (centres are wrapped into the box,
overlaps use the minimum image), as a Lees–Edwards box needs. Lengths are in [length], the
project's unit h (SPH kernel support radius).
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np

from ..errors import InputError, NumericalError
from . import grains as grain_shapes
from .overlap import fibonacci_directions, grain_gaps, sphere_gaps
from .radius_table import build_table, table_error
from .relax import BUDGET, CONVERGED, PAIR_OVERFLOW, fire_grains, fire_spheres, new_state
from .rotations import random_quaternions, rotation_matrices
from .shapes import radius_bounds, surface_geometry, volume
from .sizes import body_count, draw_radii, scale_to_volume_fraction

__all__ = ["MAX_VOLUME_FRACTION", "Packing", "PackingError", "pack", "pack_sand",
           "pack_spheres", "SHAPES"]

log = logging.getLogger(__name__)

SHAPES = ("sphere", "sand")
#: Random close packing of monodisperse spheres: no random packing of these bodies is denser
#: [choice: the same bound for grains; polydisperse spheres pack a little denser, not needed].
MAX_VOLUME_FRACTION = 0.64
#: Default smallest gap between bodies, as a fraction of the mean radius.
DEFAULT_GAP_FRACTION = 1e-3
#: Default relaxation budgets (FIRE steps). Spheres need ~200 steps at φ = 0.55 and ~2e4 at
#: 0.63; grains ~200 at φ = 0.50–0.55, at ~1 ms per step for 40 grains.
DEFAULT_MAX_STEPS = 200_000
DEFAULT_MAX_STEPS_SAND = 20_000
#: Surface sample points per grain: in the relaxation, and in the exact check.
DEFAULT_RELAX_POINTS = 1200
DEFAULT_CHECK_POINTS = 4000


class PackingError(NumericalError):
    """The relaxation did not remove every overlap within its step budget."""


@dataclass(frozen=True)
class Packing:
    """A packing of N bodies in a periodic box; lengths in [length] (h).

    Attributes
    ----------
    shape : "sphere" or "sand".
    box : (3,) box lengths L_x, L_y, L_z; the box is [0, L_x) × [0, L_y) × [0, L_z).
    centres : (N, 3) body-frame origins in the box: sphere centres, grain centroids.
    orientations : (N, 4) unit quaternions (w, x, y, z), body frame → box frame.
    radii : (N,) volume-equivalent radii (sphere radii).
    volumes : (N,) exact body volumes [length³].
    coefficients : (N, (N_deg+1)²) radius expansions a_nm [length] in the body frame
        (:mod:`~suspsim.bodies.harmonics`), or None for spheres.
    support_radii : (N,) upper bounds of each body's radius (= radii for spheres).
    seed : the seed of ``numpy.random.default_rng`` that produced the packing.
    polydispersity : coefficient of variation of the size distribution asked for.
    size_ratio : bound on the ratio of the largest to the smallest radius.
    min_gap : the gap guaranteed between bodies (sand: radially, see
        :mod:`~suspsim.bodies.overlap`).
    details : shape parameters and diagnostics (relaxation steps, wall time, smallest gap
        found), written to the packing file as attributes.
    """

    shape: str
    box: np.ndarray
    centres: np.ndarray
    orientations: np.ndarray
    radii: np.ndarray
    volumes: np.ndarray
    coefficients: np.ndarray | None
    support_radii: np.ndarray
    seed: int
    polydispersity: float
    size_ratio: float
    min_gap: float
    details: dict[str, Any] = field(default_factory=dict)

    @property
    def count(self) -> int:
        """Number of bodies N."""
        return len(self.radii)

    @property
    def volume_fraction(self) -> float:
        """φ = Σ V_i / (L_x L_y L_z)."""
        return float(self.volumes.sum() / np.prod(self.box))


def pack(shape: str, box: Sequence[float], volume_fraction: float, radius: float,
         **options) -> Packing:
    """:func:`pack_spheres` for ``shape`` "sphere", :func:`pack_sand` for "sand"."""
    if shape not in SHAPES:
        raise InputError("shape", f"unknown shape {shape!r}; use one of {', '.join(SHAPES)}")
    return (pack_spheres if shape == "sphere" else pack_sand)(box, volume_fraction, radius,
                                                              **options)


def pack_spheres(box: Sequence[float], volume_fraction: float, radius: float, *,
                 polydispersity: float = 0.0, size_ratio: float = 5.0, seed: int = 0,
                 min_gap: float | None = None, max_steps: int = DEFAULT_MAX_STEPS) -> Packing:
    """Random non-overlapping spheres at exactly ``volume_fraction`` (module docstring).

    Parameters
    ----------
    box : three box lengths [length].
    volume_fraction : φ, 0 < φ < 0.64 (tested up to 0.55).
    radius : mean radius [length] before the final common rescaling (a factor close to 1).
    polydispersity : coefficient of variation of the radii (0: monodisperse).
    size_ratio : largest/smallest radius bound of the truncated lognormal, 1 < ratio ≤ 5.
    seed : seed of the random generator.
    min_gap : smallest surface gap [length]; default 1e-3 × ``radius``.
    max_steps : relaxation budget (FIRE steps).

    Raises
    ------
    InputError : an unusable argument (the message names it and what to change).
    PackingError : overlaps remain after ``max_steps``.
    """
    box, min_gap = _check_common(box, volume_fraction, radius, polydispersity, size_ratio,
                                 min_gap, max_steps, seed)
    started = time.perf_counter()
    rng = np.random.default_rng(seed)
    box_volume = float(np.prod(box))
    count = body_count(box_volume, volume_fraction, radius, polydispersity, size_ratio)
    drawn = draw_radii(count, radius, polydispersity, size_ratio, rng)
    radii = drawn * scale_to_volume_fraction(4.0 * math.pi / 3.0 * drawn ** 3, box_volume,
                                             volume_fraction)
    orientations = random_quaternions(count, rng)
    positions = rng.uniform(0.0, 1.0, (count, 3)) * box
    skin = _skin(box, radii.max(), min_gap, radius)
    # 1 % over the guaranteed gap absorbs the rounding of the final wrap into the box.
    working_gap = 1.01 * min_gap + 1e-12 * float(box.max())
    steps = _relax(fire_spheres, positions, (radii,), box, working_gap, skin,
                   0.25 * (working_gap - min_gap), max_steps, "spheres", volume_fraction)
    positions = _wrap(positions, box)
    gaps = sphere_gaps(positions, radii, box, within=radius)
    smallest = float(gaps.min()) if len(gaps) else math.inf
    if smallest < min_gap:
        raise NumericalError(f"internal check failed: a sphere gap {smallest:.3g} is below "
                             f"min_gap {min_gap:.3g} after relaxation (please report)")
    details = {"relaxation_steps": steps, "wall_time_s": time.perf_counter() - started,
               "smallest_gap": smallest}
    log.info("packed %d spheres at phi = %.6f in %d steps, %.2f s; smallest gap %.3g",
             count, volume_fraction, steps, details["wall_time_s"], smallest)
    return Packing("sphere", box, positions, orientations, radii,
                   4.0 * math.pi / 3.0 * radii ** 3, None, radii.copy(), int(seed),
                   float(polydispersity), float(size_ratio), float(min_gap), details)


def pack_sand(box: Sequence[float], volume_fraction: float, radius: float, *,
              polydispersity: float = 0.0, size_ratio: float = 5.0, seed: int = 0,
              min_gap: float | None = None, max_steps: int = DEFAULT_MAX_STEPS_SAND,
              degree: int = grain_shapes.DEFAULT_DEGREE,
              roughness: float = grain_shapes.DEFAULT_ROUGHNESS,
              spectral_exponent: float = grain_shapes.DEFAULT_SPECTRAL_EXPONENT,
              elongation_range: tuple[float, float] = grain_shapes.DEFAULT_ELONGATION_RANGE,
              relax_points: int = DEFAULT_RELAX_POINTS,
              check_points: int = DEFAULT_CHECK_POINTS) -> Packing:
    """Random non-overlapping sand grains at exactly ``volume_fraction`` (module docstring).

    Parameters as :func:`pack_spheres` (``radius``: mean volume-equivalent radius), plus the
    grain-shape parameters of :func:`~suspsim.bodies.grains.random_grain` (``degree``,
    ``roughness``, ``spectral_exponent``, ``elongation_range``) and the surface sample points
    per grain in the relaxation (``relax_points``) and in the exact check (``check_points``).
    Tested up to φ = 0.50.
    """
    box, min_gap = _check_common(box, volume_fraction, radius, polydispersity, size_ratio,
                                 min_gap, max_steps, seed)
    if not isinstance(degree, (int, np.integer)) or not 2 <= degree <= 60:
        raise InputError("degree", f"harmonic degree must be an integer in [2, 60], got {degree}")
    if not 0.0 <= roughness <= 0.2:
        raise InputError("roughness", f"roughness must be in [0, 0.2] (rms radius deviation "
                         f"relative to the equivalent radius), got {roughness}")
    low, high = elongation_range
    if not 1.0 <= low <= high <= 3.0:
        raise InputError("elongation_range", "elongation range must satisfy 1 <= low <= high "
                         f"<= 3, got {tuple(elongation_range)}")
    if not 0.0 < spectral_exponent <= 10.0:
        raise InputError("spectral_exponent", f"spectral exponent must be in (0, 10], got "
                         f"{spectral_exponent}")
    for name, value in (("relax_points", relax_points), ("check_points", check_points)):
        if not isinstance(value, (int, np.integer)) or value < 100:
            raise InputError(name, f"{name} must be an integer >= 100, got {value}")
    started = time.perf_counter()
    rng = np.random.default_rng(seed)
    box_volume = float(np.prod(box))
    count = body_count(box_volume, volume_fraction, radius, polydispersity, size_ratio)
    drawn = draw_radii(count, radius, polydispersity, size_ratio, rng)
    try:
        unit = np.stack([grain_shapes.random_grain(
            rng, degree=degree, spectral_exponent=spectral_exponent, roughness=roughness,
            elongation_range=(low, high)) for _ in range(count)])
    except ValueError as err:
        raise InputError("roughness", str(err)) from None
    unit_volumes = np.array([volume(a) for a in unit])
    sizes = drawn * scale_to_volume_fraction(drawn ** 3 * unit_volumes, box_volume,
                                             volume_fraction)
    coefficients = unit * sizes[:, None]
    volumes = np.array([volume(a) for a in coefficients])
    orientations = random_quaternions(count, rng)
    positions = rng.uniform(0.0, 1.0, (count, 3)) * box
    unit_support = np.array([radius_bounds(a)[1] for a in unit])
    support = sizes * unit_support
    skin = _skin(box, support.max(), min_gap, radius, what="support radius")
    rotations = rotation_matrices(orientations)
    tables = np.stack([build_table(a) for a in unit])
    table_slack = max(table_error(a, t) for a, t in zip(unit, tables)) * float(sizes.max())
    directions = fibonacci_directions(relax_points)
    geometry = [surface_geometry(a, directions) for a in unit]
    offsets = np.stack([(g.points @ r.T) * s for g, r, s in zip(geometry, rotations, sizes)])
    normals = np.stack([g.normals @ r.T for g, r in zip(geometry, rotations)])
    to_body = np.ascontiguousarray(np.transpose(rotations, (0, 2, 1)))
    working_gap = 1.01 * min_gap + 2.0 * table_slack
    steps = 0
    for attempt in range(6):
        steps += _relax(fire_grains, positions,
                        (sizes, unit_support, tables, offsets, normals, to_body), box,
                        working_gap, skin, 0.25 * (working_gap - min_gap), max_steps,
                        "sand grains", volume_fraction)
        gaps = grain_gaps(_wrap(positions, box), rotations, coefficients, support, box,
                          points=check_points)
        smallest = float(gaps.min()) if len(gaps) else math.inf
        if smallest >= min_gap:
            break
        log.info("exact check: smallest radial gap %.3g < min_gap %.3g with working gap %.3g; "
                 "relaxing again with a wider working gap", smallest, min_gap, working_gap)
        working_gap += 2.0 * (min_gap - smallest) + working_gap
    else:
        raise PackingError(f"sand grains still overlap (radial gap {smallest:.3g} < min_gap "
                           f"{min_gap:.3g}) after {attempt + 1} relaxations; raise relax_points "
                           f"(now {relax_points}) or lower the volume fraction")
    positions = _wrap(positions, box)
    details = {"relaxation_steps": steps, "wall_time_s": time.perf_counter() - started,
               "smallest_gap": smallest, "degree": int(degree), "roughness": float(roughness),
               "spectral_exponent": float(spectral_exponent),
               "elongation_range": [float(low), float(high)], "check_points": int(check_points),
               "relax_points": int(relax_points), "working_gap": float(working_gap)}
    log.info("packed %d sand grains at phi = %.6f in %d steps, %.2f s; smallest radial gap %.3g",
             count, volume_fraction, steps, details["wall_time_s"], smallest)
    return Packing("sand", box, positions, orientations,
                   np.cbrt(volumes * 3.0 / (4.0 * math.pi)), volumes, coefficients, support,
                   int(seed), float(polydispersity), float(size_ratio), float(min_gap), details)


def _check_common(box, volume_fraction, radius, polydispersity, size_ratio, min_gap, max_steps,
                  seed):
    """Validate the arguments both packers share; returns (box array, min_gap)."""
    box = np.asarray(box, dtype=np.float64).ravel()
    if box.shape != (3,) or not np.all(np.isfinite(box)) or np.any(box <= 0.0):
        raise InputError("box", f"the box needs three positive lengths, got {box.tolist()}")
    if not (math.isfinite(volume_fraction) and 0.0 < volume_fraction < MAX_VOLUME_FRACTION):
        raise InputError("volume_fraction", f"volume fraction must be in (0, "
                         f"{MAX_VOLUME_FRACTION}) (random close packing), got {volume_fraction}")
    if not (math.isfinite(radius) and radius > 0.0):
        raise InputError("radius", f"radius must be positive, got {radius}")
    if not (math.isfinite(polydispersity) and 0.0 <= polydispersity <= 1.0):
        raise InputError("polydispersity", "polydispersity (coefficient of variation of the "
                         f"radii) must be in [0, 1], got {polydispersity}")
    if not (math.isfinite(size_ratio) and 1.0 < size_ratio <= 5.0):
        raise InputError("size_ratio", f"size ratio (largest/smallest radius) must be in "
                         f"(1, 5] (SPEC §4), got {size_ratio}")
    if min_gap is None:
        min_gap = DEFAULT_GAP_FRACTION * radius
    if not (math.isfinite(min_gap) and 0.0 <= min_gap <= radius):
        raise InputError("min_gap", f"minimum gap must be in [0, radius = {radius}], "
                         f"got {min_gap}")
    if not isinstance(max_steps, (int, np.integer)) or max_steps < 1:
        raise InputError("max_steps", f"max_steps must be a positive integer, got {max_steps}")
    if not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError("seed", f"seed must be a non-negative integer, got {seed}")
    return box, float(min_gap)


def _skin(box: np.ndarray, largest: float, min_gap: float, radius: float,
          what: str = "radius") -> float:
    """Verlet skin [length]: 0.3 mean radii, less if the minimum image needs it."""
    # The minimum image is the only image searched: 2 (2 ρ_max + skin) ≤ min L.
    room = 0.5 * float(box.min()) - 2.0 * largest - min_gap
    if room <= 0.0:
        need = 2.0 * (2.0 * largest + min_gap)
        raise InputError("box", f"box side {float(box.min()):g} is too small for a body of "
                         f"{what} {largest:.4g}: every side must be at least {need:.4g} "
                         "(4 x the largest radius + 2 x the gap); enlarge the box or reduce "
                         "the radius")
    return min(0.3 * radius, room)


def _relax(kernel, positions, body_arrays, box, gap, skin, tolerance, max_steps, what,
           volume_fraction):
    """Run a FIRE kernel to convergence, growing its pair list as needed; returns steps."""
    count = len(positions)
    velocities = np.zeros_like(positions)
    reference = positions.copy()
    state = new_state()
    pairs = np.empty((16 * count + 16, 2), np.int64)
    while True:
        code, value = kernel(positions, velocities, *body_arrays, box, gap, skin, tolerance,
                             pairs, reference, state, max_steps)
        if code != PAIR_OVERFLOW:
            break
        pairs = np.empty((int(1.5 * value) + 16, 2), np.int64)
    steps = int(state[3])
    if code == BUDGET:
        raise PackingError(f"could not remove the overlaps of {count} {what} at volume fraction "
                           f"{volume_fraction:g} within {max_steps} relaxation steps (largest "
                           f"overlap left {value:.3g}); lower the volume fraction, raise "
                           "the step budget (max_steps, --max-steps) or use more polydisperse "
                           "sizes")
    assert code == CONVERGED
    return steps


def _wrap(positions: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Positions folded into [0, L) (the rounding of x − L⌊x/L⌋ may give L: fold that to 0)."""
    wrapped = positions - box * np.floor(positions / box)
    return np.where(wrapped >= box, wrapped - box, wrapped)

