"""Plane Poiseuille flow of a generalized-Newtonian fluid (SPEC §6.2, §2.7) and its Bingham number.

A force density F (force per volume; a body acceleration g gives F = ρg) drives flow along x
between no-slip walls at y = 0 and y = W. Momentum balance gives the shear stress exactly,
σ_xy(y) = F (W/2 − y); inverting the flow curve gives the rate γ̇(σ) (:func:`inverse_stress`),
and the velocity follows by integrating from the wall. Substituting dy = −dσ/F turns the
integral over y, nearly singular at the plug edge of a stiffly regularised yield-stress fluid,
into one over σ, whose awkward points (σ = 0, the yield stress, kinks of the law) are known:

    u(y) = (1/F) ∫_{|σ(y)|}^{σ_w} γ̇(σ) dσ,        Q = ∫_0^W u dy = (2/F²) ∫_0^{σ_w} σ γ̇(σ) dσ.

Both integrals use composite Gauss–Legendre panels, graded geometrically towards every awkward
point and refined adaptively (each panel's 20-point rule against its two halves) until the
summed error estimate is below ``rtol``.

Symbols (SI units; any consistent units work the same way in simulation units):

========= =============================================================== =========
symbol    meaning                                                         unit
========= =============================================================== =========
F         (force_density) driving force per volume, ρg                    Pa/m
W         (width) wall-to-wall distance; h = W/2 the half-width           m
y         distance from the wall at y = 0                                 m
σ, σ_w    shear stress F (W/2 − y), its wall value F W/2                   Pa
γ̇(σ)      shear rate from the flow curve, |du/dy|                         1/s
u, U      velocity along x, centre-line velocity                          m/s
Q         volume flux per unit depth                                      m²/s
τ_y       yield stress (Papanastasiou: μ_0/M)                             Pa
K, n      consistency and flow index of the viscous part (Bingham: μ_pl, 1) Pa sⁿ, 1
ξ         plug fraction τ_y/σ_w = y_p/h, y_p the plug half-width           1
Bn        Bingham number τ_y/(K γ̇_c^n), γ̇_c = U/h of the ideal fluid     1
L_y       height of the periodic SPH box of the split-force set-up        m
========= =============================================================== =========

Bingham number [choice]. SPEC §1.1 writes Bn = τ_y/(μ_pl γ̇) with γ̇ = V/L the flow's actual rate
scale. For the channel we take V = U, the centre-line velocity of the ideal (M → ∞) fluid, and
L = h, so that Bn is fixed by the law's ideal parameters and the force alone:
U = (n/(n+1)) (F/K)^(1/n) h^((n+1)/n) (1 − ξ)^((n+1)/n), hence

    Bn = ξ (n+1)ⁿ / (nⁿ (1 − ξ)^(n+1))        (Bingham: Bn = 2ξ/(1 − ξ)²),

which increases from 0 to ∞ as the plug fills the channel (ξ → 1). Using the Newtonian velocity
F W²/(8μ_pl) instead would give Bn = 2ξ, which saturates at 2 where the flow stops.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy.optimize import brentq

from suspsim.errors import NumericalError
from suspsim.reference.shear import inverse_stress
from suspsim.rheology.laws import HERSCHEL_BULKLEY, PAPANASTASIOU, ConstitutiveLaw

_ORDER = 20
_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(_ORDER)
# Panels shrink by 2 towards each awkward point down to 2^-50 σ_w ≈ 1e-15 σ_w, where the
# remaining panel's contribution is below round-off for any integrable power singularity.
_GRADING_LEVELS = 50
_MAX_ROUNDS = 60
# Bounds the work (~60 rate inversions per panel) when a law defeats the error estimate.
_MAX_PANELS = 20_000


def _gauss(a, b):
    """Nodes and weights of the 20-point rule on each [a_k, b_k] and of its two halves."""
    mid = 0.5 * (a + b)
    half = 0.5 * (b - a)
    quarter = 0.5 * half
    x = np.concatenate([mid[:, None] + half[:, None] * _NODES,
                        (a + quarter)[:, None] + quarter[:, None] * _NODES,
                        (mid + quarter)[:, None] + quarter[:, None] * _NODES], axis=1)
    w = np.concatenate([half[:, None] * _WEIGHTS, quarter[:, None] * _WEIGHTS,
                        quarter[:, None] * _WEIGHTS], axis=1)
    return x, w


def _awkward_stresses(law: ConstitutiveLaw) -> list[float]:
    """Stresses [Pa] where γ̇(σ) bends sharply: the yield stress and the γ̇_min floor's kink."""
    points = [law.yield_stress]
    if law.params.get("gdot_min", 0.0) > 0:
        points.append(float(law.stress(law.params["gdot_min"])))
    return points


class _StressQuadrature:
    """Converged panels on [0, σ_w] [Pa] with ∫γ̇ dσ [Pa/s] and ∫σγ̇ dσ [Pa²/s] on each."""

    def __init__(self, law: ConstitutiveLaw, sigma_wall: float, rtol: float):
        self.law = law
        levels = sigma_wall * 0.5 ** np.arange(1, _GRADING_LEVELS + 1)
        points = [0.0, sigma_wall, *levels]
        for s in _awkward_stresses(law):
            if 0 < s < sigma_wall:
                points += [s, *(s - levels), *(s + levels)]
        edges = np.unique(np.clip(points, 0.0, sigma_wall))
        a, b = edges[:-1], edges[1:]
        values, errors = self._panels(a, b)
        # Round-off floor: a node's rate is only known to ε σ dγ̇/dσ (σ is a float, and τ(γ̇) is
        # rounded), which sums to ≲ 2ε ∫ σ^(1+j) dγ̇ ≤ 2ε σ_w^(1+j) γ̇_w over the integral
        # ∫ σ^j γ̇ dσ. It exceeds 1e-12 only when σ_w lies barely above a yield stress.
        wall_rate = inverse_stress(law, sigma_wall)
        totals = values.sum(axis=0)
        floor = 8 * np.finfo(float).eps * wall_rate * max(sigma_wall / totals[0],
                                                           sigma_wall ** 2 / totals[1])
        if floor > rtol:
            warnings.warn(f"{law.name}: round-off in γ̇(σ) limits the Poiseuille solution at wall "
                          f"stress {sigma_wall:.12g} Pa to ≈ {floor:.1g} relative, not rtol = "
                          f"{rtol:g} (the flow curve is nearly flat, e.g. just above a yield "
                          "stress)", RuntimeWarning, stacklevel=3)
            rtol = floor
        for _ in range(_MAX_ROUNDS):
            # Error estimate of each panel relative to the whole of each integral.
            error = (errors / values.sum(axis=0)).max(axis=1)
            if error.sum() <= rtol:
                break
            # Split the panels that carry more than their share of the allowed error, unless
            # they are already too narrow to split in floating point.
            split = (error > rtol / error.size) & (b - a > 8 * np.spacing(sigma_wall))
            if not split.any() or error.size + split.sum() > _MAX_PANELS:
                break
            mid = 0.5 * (a[split] + b[split])
            new_a, new_b = np.concatenate([a[split], mid]), np.concatenate([mid, b[split]])
            new_values, new_errors = self._panels(new_a, new_b)
            keep = ~split
            a, b = np.concatenate([a[keep], new_a]), np.concatenate([b[keep], new_b])
            values = np.concatenate([values[keep], new_values])
            errors = np.concatenate([errors[keep], new_errors])
        else:
            error = (errors / values.sum(axis=0)).max(axis=1)
        if not error.sum() <= rtol:
            raise NumericalError(f"{law.name}: Poiseuille quadrature did not reach rtol = {rtol:g} "
                                 f"(estimate {error.sum():.2g}); loosen rtol or check the law")
        order = np.argsort(a)
        self.a, self.b = a[order], b[order]
        self.rate, self.flux = values[order, 0], values[order, 1]
        # ∫_{a_k}^{σ_w} γ̇ dσ as a suffix sum: small near the wall without cancellation.
        self.rate_above = np.cumsum(self.rate[::-1])[::-1]

    def _panels(self, a, b):
        """(∫γ̇, ∫σγ̇) on each panel from the two half-panel rules, and |whole − halves|."""
        x, w = _gauss(a, b)
        g = inverse_stress(self.law, x)
        integrand = np.stack([g, x * g], axis=-1) * w[..., None]
        whole, halves = integrand[:, :_ORDER].sum(1), integrand[:, _ORDER:].sum(1)
        return halves, np.abs(whole - halves)

    def rate_integral_above(self, sigma) -> np.ndarray:
        """∫_σ^{σ_w} γ̇ ds [Pa/s] for each 0 ≤ σ ≤ σ_w [Pa] (the half-panel rules on the rest
        of the panel holding σ, plus the panels above it)."""
        sigma = np.asarray(sigma, dtype=float)
        k = np.clip(np.searchsorted(self.b, sigma, side="left"), 0, self.b.size - 1)
        x, w = _gauss(sigma, self.b[k])
        partial = (w[:, _ORDER:] * inverse_stress(self.law, x[:, _ORDER:])).sum(1)
        following = np.append(self.rate_above, 0.0)[k + 1]
        return partial + following


def _sigma_wall(force_density: float, width: float) -> float:
    """Wall stress |F| W/2 [Pa], after checking F [Pa/m] and W [m]."""
    if not np.isfinite(force_density):
        raise ValueError(f"force density must be finite, got {force_density!r} Pa/m")
    if not (np.isfinite(width) and width > 0):
        raise ValueError(f"width must be > 0 m, got {width!r}")
    return abs(float(force_density)) * (0.5 * float(width))


def poiseuille_profile(law: ConstitutiveLaw, force_density: float, width: float, y, *,
                       rtol: float = 1e-12):
    """Velocity u(y) [m/s] of plane Poiseuille flow at heights ``y`` [m] in [0, W].

    ``force_density`` F [Pa/m] (ρg; its sign is the flow direction), ``width`` W [m] between
    no-slip walls at y = 0 and y = W; u(y) = (1/F) ∫_{|σ(y)|}^{σ_w} γ̇(σ) dσ with
    σ(y) = F (W/2 − y), symmetric about the centre line. ``rtol`` bounds the quadrature's
    estimated error relative to ∫_0^{σ_w} γ̇ dσ (∝ the centre-line velocity). Where the flow
    curve is nearly flat (close to the supremum of a bounded one) the law itself fixes γ̇ only
    to ε d ln γ̇/d ln τ (ε = 2.2e-16), which then limits the accuracy instead.
    """
    sigma_wall = _sigma_wall(force_density, width)
    heights = np.asarray(y, dtype=float)
    if np.any(~((heights >= 0) & (heights <= width))):
        raise ValueError(f"heights must lie in [0, W = {width:g}] m")
    if sigma_wall == 0:
        u = np.zeros(heights.shape)
    else:
        quadrature = _StressQuadrature(law, sigma_wall, rtol)
        sigma = abs(force_density) * np.abs(0.5 * width - heights.ravel())
        u = np.sign(force_density) * quadrature.rate_integral_above(sigma) / abs(force_density)
        u = u.reshape(heights.shape)
    return u if np.ndim(y) else float(u)


def poiseuille_flow_rate(law: ConstitutiveLaw, force_density: float, width: float, *,
                         rtol: float = 1e-12) -> float:
    """Volume flux per unit depth Q = ∫_0^W u dy = (2/F²) ∫_0^{σ_w} σ γ̇(σ) dσ [m²/s].

    Arguments as in :func:`poiseuille_profile` (F [Pa/m], W [m]); Q has the sign of F.
    """
    sigma_wall = _sigma_wall(force_density, width)
    if sigma_wall == 0:
        return 0.0
    flux = _StressQuadrature(law, sigma_wall, rtol).flux.sum()
    return float(np.sign(force_density) * 2.0 * flux / force_density ** 2)


def split_force_poiseuille_profile(law: ConstitutiveLaw, g_density: float, box_height: float,
                                   y, *, rtol: float = 1e-12):
    """Velocity u(y) [m/s] of the body-force set-up of SPEC §2.7 in the periodic box [0, L_y).

    Force density +F (``g_density`` [Pa/m], i.e. ρg) on y ∈ [0, L_y/2) and −F on
    [L_y/2, L_y), ``box_height`` L_y [m]. By symmetry u = 0 on y = 0 (≡ L_y) and y = L_y/2, so
    each half is a plane Poiseuille flow of width L_y/2; u is antisymmetric, u(L_y − y) = −u(y).
    Heights outside the box are wrapped into it (the box is periodic).
    """
    if not (np.isfinite(box_height) and box_height > 0):
        raise ValueError(f"box height must be > 0 m, got {box_height!r}")
    half = 0.5 * box_height
    wrapped = np.mod(np.asarray(y, dtype=float), box_height)
    upper = wrapped >= half
    local = np.clip(np.where(upper, wrapped - half, wrapped), 0.0, half)
    u = poiseuille_profile(law, g_density, half, local, rtol=rtol)
    u = np.where(upper, -u, u)
    return u if np.ndim(y) else float(u)


def _plastic_parameters(law: ConstitutiveLaw) -> tuple[float, float, float]:
    """(τ_y [Pa], K [Pa sⁿ], n) of the law's ideal (M → ∞) Herschel–Bulkley form."""
    if law.code == PAPANASTASIOU:
        return law.yield_stress, law.params["mu_pl"], 1.0
    if law.code == HERSCHEL_BULKLEY:
        return law.params["tau_y"], law.params["K"], law.params["n"]
    if not law.spec.has_yield_stress:
        return 0.0, np.nan, np.nan
    raise ValueError(f"{law.name}: the Bingham number is defined for papanastasiou and "
                     "herschel_bulkley (a yield stress plus one viscous power law)")


def bingham_number(law: ConstitutiveLaw, force_density: float, width: float) -> float:
    """Bn = τ_y/(K γ̇_c^n) [1], γ̇_c = U/(W/2), U the ideal fluid's centre-line velocity.

    F [Pa/m], W [m]; see the module docstring: Bn = ξ (n+1)ⁿ/(nⁿ (1 − ξ)^(n+1)) with the plug
    fraction ξ = τ_y/σ_w. 0 for laws without a yield stress; ``inf`` when the ideal fluid does
    not flow (ξ ≥ 1) or has no viscous part (K = 0).
    """
    tau_y, consistency, n = _plastic_parameters(law)
    if tau_y == 0:
        return 0.0
    sigma_wall = _sigma_wall(force_density, width)
    if sigma_wall <= tau_y or consistency == 0:
        return float("inf")
    xi = tau_y / sigma_wall
    return float(xi * (n + 1.0) ** n / (n ** n * (1.0 - xi) ** (n + 1.0)))


def force_density_for_bingham(law: ConstitutiveLaw, width: float, bingham: float) -> float:
    """Force density F > 0 [Pa/m] at which :func:`bingham_number` of ``law`` in a channel of
    width W [m] equals ``bingham`` (0 < Bn < ∞).

    Solves ξ/(1 − ξ)^(n+1) = Bn nⁿ/(n+1)ⁿ for the plug fraction ξ (monotone; bracketed on its
    logit t = ln(ξ/(1 − ξ)) so ξ near 0 or 1 stays accurate), then F = τ_y/(ξ W/2).
    Bn = 0 is the Newtonian (power-law) limit τ_y = 0, which any force gives: not solvable here.
    """
    if not (np.isfinite(bingham) and bingham > 0):
        raise ValueError(f"Bingham number must be finite and > 0, got {bingham!r}; "
                         "Bn = 0 means τ_y = 0, where any force density does")
    if not (np.isfinite(width) and width > 0):
        raise ValueError(f"width must be > 0 m, got {width!r}")
    tau_y, consistency, n = _plastic_parameters(law)
    if not (tau_y > 0 and consistency > 0):
        raise ValueError(f"{law.name}: Bn > 0 needs a yield stress and a viscous part, "
                         f"got τ_y = {tau_y:g} Pa, K = {consistency:g}")
    log_c = np.log(bingham) + n * (np.log(n) - np.log1p(n))

    def residual(t):
        # ln ξ − (n+1) ln(1 − ξ) − ln c, with ln ξ = −ln(1 + e^−t), ln(1 − ξ) = −ln(1 + e^t).
        return -np.logaddexp(0.0, -t) + (n + 1.0) * np.logaddexp(0.0, t) - log_c

    t = brentq(residual, -800.0, 800.0, xtol=1e-14, rtol=4 * np.finfo(float).eps)
    xi = 1.0 / (1.0 + np.exp(-t))
    return float(tau_y / (xi * 0.5 * width))
