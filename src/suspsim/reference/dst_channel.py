"""Steady channel flow of the local Wyart–Cates model (SPEC §5.7; seed 002 Fig. 7–8).

A force density F (force per volume; a body acceleration g gives F = ρg) drives flow along x
between no-slip walls at y = 0 and y = d, half-gap H = d/2. Momentum balance fixes the shear
stress, σ_xy(y) = F (H − y); in the local model (α = 0) the microstructure is at its steady value
f = f̂(|σ|), so every layer sits on the single-valued steady curve γ̇(σ) = σ/η(f̂(σ)) of SPEC §1.3
— even on the S-curve's unstable branch, since each layer is stress-controlled. Then

    u(y) = ∫_0^y γ̇(F (H − y')) dy' = (1/F) ∫_{σ(y)}^{σ_w} γ̇(σ) dσ      (0 ≤ y ≤ H, u(0) = 0),
    ū = (1/H) ∫_0^H u dy = (1/(F² H)) ∫_0^{σ_w} σ γ̇(σ) dσ,          σ_w = F H,

mirrored about the centre line. Both integrals are done over σ with adaptive Gauss–Kronrod
(``scipy.integrate.quad``), split at σ* and at the S-curve's turning points where γ̇(σ) bends
sharply.

Symbols (SI in seed 002; any consistent units work the same way):

========= =============================================================== =========
symbol    meaning                                                         unit
========= =============================================================== =========
F         (force_density) driving force per volume                        Pa/m
d, H      (gap) wall-to-wall distance, half-gap d/2                        m
y         distance from the wall at y = 0                                 m
σ, σ_w    shear stress F (H − y), its wall value F H                      Pa
γ̇(σ)      steady shear rate σ/η(f̂(σ)) of the Wyart–Cates law               1/s
f̂         steady fraction of frictional contacts exp(−(σ*/σ)^β)            1
u, ū      velocity along x, its mean over the gap                         m/s
========= =============================================================== =========
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import quad

from suspsim.rheology.wyart_cates import WyartCates

_QUAD = {"epsabs": 0.0, "epsrel": 1e-11, "limit": 400}


def _breakpoints(law: WyartCates, upper: float) -> list[float]:
    """Stresses in (0, upper) where γ̇(σ) bends: σ* and the turning points (if any)."""
    points = [law.sigma_star]
    turning = law.turning_points()
    if turning is not None:
        points += [turning.sigma_beta, turning.sigma_alpha]
    return sorted(p for p in points if 0.0 < p < upper and np.isfinite(p))


def _integral(function, law: WyartCates, lower: float, upper: float) -> float:
    """∫_lower^upper function(σ) dσ, split at the law's break points."""
    if upper <= lower:
        return 0.0
    edges = [lower] + [p for p in _breakpoints(law, upper) if p > lower] + [upper]
    return float(sum(quad(function, a, b, **_QUAD)[0] for a, b in zip(edges[:-1], edges[1:])))


def _check(law: WyartCates, force_density: float, gap: float) -> None:
    if not isinstance(law, WyartCates):
        raise TypeError("law must be a suspsim.rheology.wyart_cates.WyartCates")
    if not (force_density > 0.0 and np.isfinite(force_density)):
        raise ValueError(f"force_density = {force_density!r} must be positive and finite")
    if not (gap > 0.0 and np.isfinite(gap)):
        raise ValueError(f"gap = {gap!r} must be positive and finite")
    if law.phi >= law.phi_m and force_density * gap / 2.0 >= law.jamming_stress():
        raise ValueError(f"wall stress F H = {force_density * gap / 2.0:g} reaches the jamming "
                         f"stress {law.jamming_stress():g}: no steady flow")


def dst_channel_profile(law: WyartCates, force_density: float, gap: float, y) -> np.ndarray:
    """Steady velocity u(y) [m/s] of the local model at heights ``y`` ∈ [0, gap] (see module).

    ``law`` the steady Wyart–Cates law (η_s, φ, φ_m, φ_0, σ*, β), ``force_density`` F [Pa/m],
    ``gap`` d [m]; u(0) = u(d) = 0, symmetric about d/2.
    """
    _check(law, force_density, gap)
    y = np.asarray(y, dtype=float)
    if np.any((y < 0.0) | (y > gap)):
        raise ValueError("heights y must lie in [0, gap]")
    half = gap / 2.0
    wall_stress = force_density * half

    def rate(s):
        return float(law.shear_rate(s))

    flat = np.minimum(y, gap - y).ravel()
    u = np.array([_integral(rate, law, force_density * (half - yy), wall_stress) / force_density
                  for yy in flat])
    return u.reshape(y.shape)[()]


def dst_channel_stress(force_density: float, gap: float, y) -> np.ndarray:
    """Shear stress σ_xy(y) = F (d/2 − y) [Pa] of the steady channel."""
    return force_density * (gap / 2.0 - np.asarray(y, dtype=float))


def dst_channel_fraction(law: WyartCates, force_density: float, gap: float, y) -> np.ndarray:
    """Steady frictional fraction f̂(|σ(y)|) [1] of the local model across the channel."""
    return law.frictional_fraction(np.abs(dst_channel_stress(force_density, gap, y)))


def dst_channel_mean_velocity(law: WyartCates, force_density: float, gap: float) -> float:
    """Gap-averaged velocity ū = ∫_0^{σ_w} σ γ̇(σ) dσ / (F² H) [m/s] of the local model."""
    _check(law, force_density, gap)
    half = gap / 2.0
    wall_stress = force_density * half
    integral = _integral(lambda s: s * float(law.shear_rate(s)), law, 0.0, wall_stress)
    return integral / (force_density ** 2 * half)
