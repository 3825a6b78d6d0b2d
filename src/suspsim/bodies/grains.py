"""Random realistic sand-grain shapes from spherical-harmonic radii (SPEC §4; Garboczi 2002).

A grain of unit volume-equivalent radius (V = 4π/3) is built as follows, every random number
drawn from the caller's :class:`numpy.random.Generator`:

1. an ellipsoidal base with axes a ≥ b ≥ c: the radius (Σ u_k²/a_k²)^(−½) projected exactly
   onto degree N (truncation error ~1e-5 of the radius for a/c = 2.6). Its degree-2 part
   carries the elongation; its higher even degrees keep it convex. [choice: SPEC §4 lets
   degree 2 alone set the elongation, but a pure quadrupole with L/W = 1.6 has a concave waist
   (a peanut), which sand grains do not have];
2. roughness, degrees 3 ≤ n ≤ N: random phases ψ, amplitude A_n ∝ n^(−p), added to the base:
   a_n0 = A_n cos ψ_n0 and (a_nm, a_n,−m) = A_n (cos ψ_nm, sin ψ_nm) for m > 0, an isotropic
   random field. The exponent p = ``spectral_exponent`` = 2.2 [choice: 2D sand outlines have a
   power spectrum ∝ n^(−10/3); |a_nm| ∼ n^(−2.2) is the 3D estimate of SPEC §4]. Its
   root-mean-square over the sphere is ``roughness`` [choice, default 0.02 of the equivalent
   radius: rounded grains];
3. elongation L/W drawn uniformly from ``elongation_range`` [choice, (1.2, 1.6): natural sands,
   to be checked against measured shapes] and met exactly by adjusting a/b (Brent's method),
   flatness W/T ≈ b/c drawn uniformly from the same range [choice]. L ≥ W ≥ T are the extents
   (max − min of the surface coordinates) along the principal axes of inertia. A draw is
   rejected and repeated if r ≤ 0 anywhere (:func:`~suspsim.bodies.shapes.radius_bounds`,
   rigorous) or the elongation cannot be met;
4. degree 1 is then set by a few Newton steps so that the centroid is at the origin
   (adding t·u = √(4π/3)(t_x Y_11 + t_y Y_1,−1 + t_z Y_10) to r shifts the centroid by ≈ t);
5. the coefficients are rotated exactly into the principal frame (I_xx ≤ I_yy ≤ I_zz: the
   long axis is x, the short axis z) and scaled to V = 4π/3.

So the body frame of every grain is its principal frame with the centroid at the origin, as the
rigid-body integrator wants (SPEC §3.2).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from . import harmonics as sh
from .shapes import mass_properties, radius_bounds

__all__ = ["DEFAULT_DEGREE", "DEFAULT_ELONGATION_RANGE", "DEFAULT_ROUGHNESS",
           "DEFAULT_SPECTRAL_EXPONENT", "ellipsoid_coefficients", "elongation_and_flatness",
           "principal_frame", "random_grain"]

DEFAULT_DEGREE = 20
DEFAULT_SPECTRAL_EXPONENT = 2.2
DEFAULT_ROUGHNESS = 0.02
DEFAULT_ELONGATION_RANGE = (1.2, 1.6)
_UNIT_VOLUME = 4.0 * math.pi / 3.0
_Y1_FACTOR = math.sqrt(4.0 * math.pi / 3.0)


def _surface_grid(degree: int) -> sh.GaussGrid:
    """Grid for the extents and for projecting the ellipsoid (four times the degree)."""
    return sh.gauss_grid(degree, 4 * degree)


def elongation_and_flatness(coefficients: np.ndarray) -> tuple[float, float]:
    """(L/W, W/T) from the extents along the principal axes of inertia (see the module docstring).

    The extents are sampled on a Gauss grid four times finer than the degree (relative error
    ≲ 1e-3, enough for a shape descriptor).
    """
    _, axes = np.linalg.eigh(mass_properties(coefficients).inertia)
    grid = _surface_grid(sh.degree_of(coefficients))
    points = sh.synthesize(coefficients, grid)[..., None] * grid.directions
    along = points.reshape(-1, 3) @ axes
    extent = np.sort(along.max(0) - along.min(0))[::-1]
    return float(extent[0] / extent[1]), float(extent[1] / extent[2])


def principal_frame(coefficients: np.ndarray) -> np.ndarray:
    """Rotation R (3 × 3, det +1) whose rows are the principal axes, I_xx ≤ I_yy ≤ I_zz first."""
    _, axes = np.linalg.eigh(mass_properties(coefficients).inertia)
    if np.linalg.det(axes) < 0:
        axes[:, 2] *= -1.0
    return axes.T


def random_grain(rng: np.random.Generator, *, degree: int = DEFAULT_DEGREE,
                 spectral_exponent: float = DEFAULT_SPECTRAL_EXPONENT,
                 roughness: float = DEFAULT_ROUGHNESS,
                 elongation_range: tuple[float, float] = DEFAULT_ELONGATION_RANGE,
                 max_attempts: int = 100) -> np.ndarray:
    """Coefficients (flat, (N+1)²) of one random grain of unit volume-equivalent radius.

    Principal frame, centroid at the origin, V = 4π/3 to round-off (module docstring).

    Raises
    ------
    ValueError : no acceptable shape in ``max_attempts`` draws (roughness too large for r > 0
        or for the elongation range).
    """
    low, high = elongation_range
    if not 1.0 <= low <= high:
        raise ValueError(f"elongation_range must satisfy 1 <= low <= high, got {elongation_range}")
    if degree < 2:
        raise ValueError(f"a grain needs degree >= 2 for its elongation, got {degree}")
    for _ in range(max_attempts):
        coefficients = _try_grain(rng, degree, spectral_exponent, roughness, low, high)
        if coefficients is not None:
            return coefficients
    raise ValueError(f"no grain with r > 0 and elongation in {elongation_range} after "
                     f"{max_attempts} draws; lower the roughness ({roughness})")


def _random_phase_coefficients(rng, degree: int) -> np.ndarray:
    """Unit-amplitude random-phase coefficients of one degree (2n + 1 values)."""
    psi = rng.uniform(0.0, 2.0 * math.pi, degree + 1)
    out = np.empty(2 * degree + 1)
    out[degree] = math.cos(psi[0])
    out[degree + 1:] = np.cos(psi[1:])
    out[:degree] = np.sin(psi[1:])[::-1]
    return out


def ellipsoid_coefficients(axes, radius: float, degree: int = DEFAULT_DEGREE) -> np.ndarray:
    """Degree-``degree`` coefficients of the ellipsoid with semi-axes proportional to ``axes``
    along x, y, z and volume-equivalent ``radius`` [length]: a grain's base shape (step 1 of
    the module docstring) without roughness, e.g. the spheroid of ``validation.jeffery``."""
    axes = np.asarray(axes, dtype=float)
    unit = _ellipsoid_coefficients(axes / np.cbrt(axes.prod()), _surface_grid(degree))
    return unit * radius * (_UNIT_VOLUME / mass_properties(unit).volume) ** (1.0 / 3.0)


def _ellipsoid_coefficients(axes, grid: sh.GaussGrid) -> np.ndarray:
    """Degree-N projection of the ellipsoid radius r(u) = (Σ u_k²/a_k²)^(−½)."""
    return sh.project(1.0 / np.sqrt(((grid.directions / axes) ** 2).sum(-1)), grid)


def _try_grain(rng, degree, exponent, roughness, low, high) -> np.ndarray | None:
    rough = np.zeros(sh.coefficient_count(degree))
    for n in range(3, degree + 1):
        rough[n * n:(n + 1) ** 2] = n ** (-exponent) * _random_phase_coefficients(rng, n)
    power = float(rough @ rough)
    if power > 0.0:
        # rms over the sphere of Σ a_nm Y_nm is √(Σ a_nm² / 4π) (orthonormal basis).
        rough *= roughness * math.sqrt(4.0 * math.pi / power)
    elongation = rng.uniform(low, high)
    flatness = rng.uniform(low, high)

    def grain(stretch: float) -> np.ndarray:
        axes = np.array([stretch, 1.0, 1.0 / flatness])
        return _ellipsoid_coefficients(axes / np.cbrt(axes.prod()), _surface_grid(degree)) + rough

    def mismatch(stretch: float) -> float:
        return elongation_and_flatness(grain(stretch))[0] - elongation

    lower, upper = 1.0, 2.0 * high
    if mismatch(lower) >= 0.0:
        stretch = lower
    elif mismatch(upper) <= 0.0:
        return None
    else:
        stretch = brentq(mismatch, lower, upper, xtol=1e-6)
    coefficients = grain(stretch)
    if radius_bounds(coefficients)[0] <= 0.0:
        return None
    coefficients = _centre(coefficients)
    coefficients = sh.rotate_coefficients(coefficients, principal_frame(coefficients))
    vol = mass_properties(coefficients).volume
    return coefficients * (_UNIT_VOLUME / vol) ** (1.0 / 3.0)


def _centre(coefficients: np.ndarray, steps: int = 20) -> np.ndarray:
    """Set degree 1 so that the centroid is at the origin (chord Newton iteration).

    The Jacobian of the centroid with respect to the shift t of r → r + t·u is taken once by
    finite differences; the iteration then converges linearly at a rate of the Jacobian's
    variation, ≈ 1e-3 per step for these shapes.
    """
    a = coefficients.copy()
    scale = a[0] / (2.0 * math.sqrt(math.pi))

    def centroid_of(shift: np.ndarray) -> np.ndarray:
        b = a.copy()
        # Y_1,-1 ∝ y, Y_10 ∝ z, Y_11 ∝ x (flat indices 1, 2, 3).
        b[1:4] += _Y1_FACTOR * shift[[1, 2, 0]]
        return mass_properties(b).centroid

    shift = np.zeros(3)
    centroid = centroid_of(shift)
    step = 1e-4 * scale
    jacobian = np.column_stack([(centroid_of(step * e) - centroid) / step for e in np.eye(3)])
    for _ in range(steps):
        if np.abs(centroid).max() <= 1e-14 * scale:
            break
        shift -= np.linalg.solve(jacobian, centroid)
        centroid = centroid_of(shift)
    a[1:4] += _Y1_FACTOR * shift[[1, 2, 0]]
    return a
