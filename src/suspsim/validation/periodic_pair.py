"""Stokes theory of two equal spheres in a periodic box, for the resolved forces of
:mod:`~suspsim.validation.squeeze` (SPEC §3.1, §3.3).

Squeeze (:func:`squeeze_theory`): the resistance of two equal spheres moving along their line
of centres with velocities ±U, F = 6πμ a U (X11A − X12A), Jeffrey & Onishi's (1984) exact
functions (:mod:`~suspsim.validation.jeffrey_onishi`). The box images are added at the
mobility level: the squeeze-mode mobility m = 1/(X11A − X12A) gains Δ = 6πμ a [(G_per − G)(0)
− (G_per − G)(r)]_xx (Hasimoto–Ewald periodic Oseen tensor, :func:`periodic_oseen`), the image
strain across the pair; near contact this relative motion is suppressed by lubrication, by
1 − A(r) (Batchelor & Green 1972,
A = 5/ρ³ − 8/ρ⁵ + 25/ρ⁶ − 35/ρ⁸ + 125/ρ⁹ − 102/ρ¹⁰ + 12.5/ρ¹¹ + 430/ρ¹², ρ = r/a, capped at
1 − 4.077 ξ near contact) [choice: an approximation; the size of the correction is reported,
the squeeze dataset's ``image_correction``, and is a few per cent at most in the default
boxes].

Sliding (:func:`sliding_theory`): the spheres, held from turning, move at ±U normal to their
line of centres: F = 6πμ a U (Y11A − Y12A), with the box images of that motion added in the
same way but without the near-contact suppression.

A single sphere's drag in the periodic box (:func:`hasimoto_factor`, SPEC §3.1):
F = 6πμaU / (1 + c₁ a + (4π/3) a³/V − 27.4 (a/L)⁶), c₁ the point-force periodic
self-correction (:func:`periodic_self_coefficient`; c₁ L = −2.837297 for a cube, Hasimoto
1959).

Units: lengths [h], forces [m h τ⁻²], viscosity [m h⁻¹ τ⁻¹], speeds [h τ⁻¹]. Symbols: a
radius; r centre distance; s = r − 2a gap; ρ = r/a; ξ = s/a; U speed of each sphere; μ
viscosity; L box side; V box volume.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import erfc

from .jeffrey_onishi import sliding_resistance, squeeze_resistance

#: Hasimoto's cubic-array constants (SPEC §3.1).
HASIMOTO = (2.837297, 4.19, 27.4)


def _ewald_split(box):
    return math.sqrt(math.pi) / float(np.prod(box)) ** (1.0 / 3.0)


def periodic_oseen(displacement, box, *, splitting: float | None = None,
                   images: int = 4, waves: int = 8) -> np.ndarray:
    """(G_per − G)(r) · μ (3, 3) for a point force in a periodic box [h⁻¹], where G is the free
    Oseen tensor and G_per its Hasimoto (1959) periodic sum without the k = 0 mode, by Ewald
    summation (real part (1/8πμ)[I(erfc(ξr)/r − 2ξe^{−ξ²r²}/√π) + r̂r̂(erfc(ξr)/r
    + 2ξe^{−ξ²r²}/√π)], Fourier part (1/μV) Σ (I − k̂k̂)(1 + k²/4ξ²) e^{−k²/4ξ²}/k² cos k·r).
    ``displacement`` r (3,) [h]; r = 0 gives the self term."""
    box = np.asarray(box, dtype=float)
    r0 = np.asarray(displacement, dtype=float)
    xi = _ewald_split(box) if splitting is None else splitting
    root_pi = math.sqrt(math.pi)
    total = np.zeros((3, 3))
    rng = range(-images, images + 1)
    for i in rng:
        for j in rng:
            for k in rng:
                vec = r0 + box * np.array([i, j, k])
                r = float(np.sqrt(vec @ vec))
                if r < 1e-12:
                    total += -4.0 * xi / root_pi / (8.0 * math.pi) * np.eye(3)
                    continue
                e = math.exp(-(xi * r) ** 2)
                c = float(erfc(xi * r))
                total += (np.eye(3) * (c / r - 2.0 * xi * e / root_pi)
                          + np.outer(vec, vec) / r ** 2 * (c / r + 2.0 * xi * e / root_pi)
                          ) / (8.0 * math.pi)
    r = float(np.linalg.norm(r0))
    if r > 1e-12:
        total -= (np.eye(3) + np.outer(r0, r0) / r ** 2) / (8.0 * math.pi * r)
    n = np.arange(-waves, waves + 1)
    wave = np.meshgrid(*(2.0 * math.pi * n / length for length in box), indexing="ij")
    k2 = sum(component ** 2 for component in wave)
    k2[waves, waves, waves] = 1.0
    weight = (1.0 + k2 / (4 * xi * xi)) * np.exp(-k2 / (4 * xi * xi)) / k2
    weight[waves, waves, waves] = 0.0
    weight *= np.cos(wave[0] * r0[0] + wave[1] * r0[1] + wave[2] * r0[2])
    for a in range(3):
        for b in range(3):
            projector = float(a == b) - wave[a] * wave[b] / k2
            total[a, b] += float(np.sum(weight * projector)) / float(np.prod(box))
    return total


def periodic_oseen_xx(displacement, box, **kwargs) -> float:
    """The xx component of :func:`periodic_oseen` [h⁻¹]."""
    return float(periodic_oseen(displacement, box, **kwargs)[0, 0])


def periodic_self_coefficient(box) -> float:
    """c₁ [h⁻¹]: the periodic self-mobility of a point force, 6π × (G_per − G)(0)_xx μ, so a
    sphere's mobility is (1 + c₁ a + …)/(6πμa); c₁ L = −2.837297 in a cube of side L."""
    return 6.0 * math.pi * periodic_oseen_xx(np.zeros(3), box)


def hasimoto_factor(radius: float, box) -> float:
    """Drag / (6πμaU) of a sphere in the periodic box (module docstring, SPEC §3.1)."""
    box = np.asarray(box, dtype=float)
    side = float(np.prod(box)) ** (1.0 / 3.0)
    mobility = (1.0 + periodic_self_coefficient(box) * radius
                + 4.0 * math.pi / 3.0 * radius ** 3 / float(np.prod(box))
                - HASIMOTO[2] * (radius / side) ** 6)
    return 1.0 / mobility


def _batchelor_a(distance_over_radius):
    rho = np.asarray(distance_over_radius, dtype=float)
    series = (5 / rho ** 3 - 8 / rho ** 5 + 25 / rho ** 6 - 35 / rho ** 8 + 125 / rho ** 9
              - 102 / rho ** 10 + 12.5 / rho ** 11 + 430 / rho ** 12)
    return np.clip(np.maximum(series, 1.0 - 4.077 * (rho - 2.0)), 0.0, 1.0)


def image_mobility(gap, radius: float, box, *, angle=0.0, mode: str = "squeeze") -> np.ndarray:
    """Δ of the module docstring (dimensionless, in units of 1/(6πμa)) for two spheres at
    surface gap ``gap`` [h] on a line in the xy plane at ``angle`` [rad] from x (one angle, or
    one per gap). ``mode`` "squeeze": relative motion along the line, suppressed near contact
    by 1 − A(r); "sliding": relative motion normal to it in the xy plane, unsuppressed
    [choice: Batchelor & Green's B(r) is not used, so Δ is an upper bound there]."""
    gap = np.atleast_1d(np.asarray(gap, dtype=float))
    angle = np.broadcast_to(np.asarray(angle, dtype=float), gap.shape)
    self_part = periodic_oseen(np.zeros(3), box)
    out = np.empty_like(gap)
    for i, (s, theta) in enumerate(zip(gap, angle)):
        line = np.array([math.cos(theta), math.sin(theta), 0.0])
        motion = line if mode == "squeeze" else np.array([-line[1], line[0], 0.0])
        cross = periodic_oseen((2.0 * radius + s) * line, box)
        out[i] = 6.0 * math.pi * radius * motion @ (self_part - cross) @ motion
    if mode == "squeeze":
        out *= 1.0 - _batchelor_a(2.0 + gap / radius)
    return out


def squeeze_theory(gap, radius: float, viscosity: float, speed: float, box=None, *,
                   angle=0.0):
    """Squeeze force [m h τ⁻²] on each of two equal spheres of ``radius`` [h] at surface
    ``gap`` [h] moving at ±``speed`` [h τ⁻¹]: 6πμaU/(m + Δ), m = 1/(X11A − X12A) (JO 1984),
    Δ the periodic-image term of ``box`` (None: free space) for the pair at ``angle``."""
    gap = np.asarray(gap, dtype=float)
    mobility = 1.0 / squeeze_resistance(gap, radius)
    if box is not None:
        mobility = mobility + image_mobility(gap, radius, box, angle=angle).reshape(gap.shape)
    return 6.0 * math.pi * viscosity * radius * speed / mobility


def sliding_theory(gap, radius: float, viscosity: float, speed: float, box=None, *,
                   angle=0.0):
    """Sliding force [m h τ⁻²] on each of two equal spheres, held from turning, moving at
    ±``speed`` [h τ⁻¹] normal to their line of centres: 6πμaU/(m + Δ), m = 1/(Y11A − Y12A),
    Δ as in :func:`squeeze_theory` for the sliding mode."""
    gap = np.asarray(gap, dtype=float)
    mobility = 1.0 / sliding_resistance(gap, radius)
    if box is not None:
        mobility = mobility + image_mobility(gap, radius, box, angle=angle,
                                             mode="sliding").reshape(gap.shape)
    return 6.0 * math.pi * viscosity * radius * speed / mobility


# ---------------------------------------------------------------- SPH runs
