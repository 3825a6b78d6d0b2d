"""Body sizes: a truncated lognormal distribution of volume-equivalent radii, and exact φ.

Sizes are volume-equivalent radii a (V = 4πa³/3) in [length] (h, the SPH kernel support radius).
``polydispersity`` is the coefficient of variation s of the untruncated lognormal,
ln a ~ Normal(ln a_med, σ²) with σ² = ln(1 + s²) and a_med = mean_radius / √(1 + s²)
(so the untruncated mean is ``mean_radius``). It is truncated symmetrically in ln a around the
median to [a_med/√ρ, a_med·√ρ], ρ = ``size_ratio`` (SPEC §4: sand sizes within ×5), so that
max/min ≤ ρ always holds; draws use the inverse normal CDF, one uniform number per body.

Exact volume fraction: the drawn radii t_i are scaled by one factor λ,
λ³ = φ V_box / Σ V(t_i), so that Σ V_i / V_box = φ to round-off (:func:`scale_to_volume_fraction`);
the count is the nearest integer to φ V_box / E[V] (:func:`body_count`), so λ is close to 1.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import ndtr, ndtri

__all__ = ["body_count", "draw_radii", "mean_cubed_radius", "scale_to_volume_fraction"]


def _log_parameters(mean_radius: float, polydispersity: float, size_ratio: float):
    sigma = math.sqrt(math.log1p(polydispersity ** 2))
    median = mean_radius / math.sqrt(1.0 + polydispersity ** 2)
    half_width = 0.5 * math.log(size_ratio)
    return median, sigma, half_width


def draw_radii(count: int, mean_radius: float, polydispersity: float, size_ratio: float,
               rng: np.random.Generator) -> np.ndarray:
    """``count`` radii [length] from the truncated lognormal of the module docstring.

    ``polydispersity`` 0 gives ``count`` copies of ``mean_radius`` (and draws nothing).
    """
    if polydispersity == 0.0:
        return np.full(count, float(mean_radius))
    median, sigma, half_width = _log_parameters(mean_radius, polydispersity, size_ratio)
    edge = ndtr(half_width / sigma)
    uniform = rng.uniform(1.0 - edge, edge, count)
    return median * np.exp(sigma * ndtri(uniform))


def mean_cubed_radius(mean_radius: float, polydispersity: float, size_ratio: float) -> float:
    """E[a³] [length³] of the truncated lognormal (closed form)."""
    if polydispersity == 0.0:
        return float(mean_radius) ** 3
    median, sigma, half_width = _log_parameters(mean_radius, polydispersity, size_ratio)
    z = half_width / sigma
    # E[exp(3σZ) | |Z| ≤ z] for a standard normal Z.
    shifted = ndtr(z - 3.0 * sigma) - ndtr(-z - 3.0 * sigma)
    return float(median ** 3 * math.exp(4.5 * sigma ** 2) * shifted / (ndtr(z) - ndtr(-z)))


def body_count(box_volume: float, volume_fraction: float, mean_radius: float,
               polydispersity: float, size_ratio: float) -> int:
    """Bodies needed for ``volume_fraction`` of ``box_volume`` at the distribution's mean volume
    (at least 1)."""
    mean_volume = 4.0 * math.pi / 3.0 * mean_cubed_radius(mean_radius, polydispersity, size_ratio)
    return max(1, round(volume_fraction * box_volume / mean_volume))


def scale_to_volume_fraction(volumes: np.ndarray, box_volume: float,
                             volume_fraction: float) -> float:
    """Length factor λ with Σ λ³ V_i = φ V_box; scale lengths by λ, volumes by λ³."""
    return float(np.cbrt(volume_fraction * box_volume / np.sum(volumes)))
