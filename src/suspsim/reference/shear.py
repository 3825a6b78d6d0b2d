"""Simple shear of a generalized-Newtonian fluid (SPEC §6.1) and the inverse flow curve.

In steady simple shear every point carries the same shear rate γ̇, so the shear stress is the
flow curve itself, σ_xy = μ(|γ̇|) γ̇, and the viscosity an SPH run measures as σ_xy/γ̇ must equal
μ(γ̇) of SPEC §1.1. :func:`inverse_stress` inverts the flow curve, γ̇(τ), which the Poiseuille
solutions (:mod:`suspsim.reference.poiseuille`) integrate.

Symbols (SI units; any consistent units work the same way in simulation units):

======== ============================================== =======
symbol   meaning                                        unit
======== ============================================== =======
γ̇        shear rate dv_x/dy                             1/s
μ(γ̇)     viscosity of the law (SPEC §1.1)               Pa s
τ, σ_xy  shear stress τ(γ̇) = μ(|γ̇|) γ̇                  Pa
y        gradient coordinate, SPH box [0, L_y)          m
L_y      box height (gradient direction)                m
v_x      flow velocity                                  m/s
v_0      (offset) velocity added to the affine field    m/s
======== ============================================== =======

Equations:

* flow curve, odd in γ̇:            τ(γ̇) = μ(|γ̇|) γ̇
* Lees–Edwards Couette (SPEC §2.7): v_x(y) = γ̇ y + v_0,  y ∈ [0, L_y)
* inverse flow curve:              γ̇(τ) = the root of μ(γ̇) γ̇ = τ
"""
from __future__ import annotations

import numpy as np

from suspsim.rheology.laws import ConstitutiveLaw

#: Search range of the inverse flow curve [1/s]: wide enough for any unit system, yet with
#: products of two bounds still representable (so no bracket arithmetic overflows).
RATE_MIN = 1e-300
RATE_MAX = 1e300

# A bracket is widened by this factor per step; 1e4 reaches RATE_MIN or RATE_MAX from any
# starting guess in 150 steps.
_EXPANSION = 1e4
_MAX_EXPANSIONS = 160
# Geometric bisection shrinks a 1e600-wide bracket to a factor of 2 in ~11 halvings of its log
# width, arithmetic bisection then takes ≤ 53 steps to adjacent floats: 100 always suffices.
_MAX_BISECTIONS = 100


def simple_shear_stress(law: ConstitutiveLaw, shear_rate) -> np.ndarray:
    """Shear stress σ_xy = μ(|γ̇|) γ̇ [Pa] of ``law`` in steady simple shear at γ̇ [1/s].

    Odd in γ̇ (the sign follows the shear direction); array-like in, array (or float) out.
    """
    rate = np.asarray(shear_rate, dtype=float)
    out = law.viscosity(np.abs(rate)) * rate
    return out if np.ndim(shear_rate) else float(out)


def couette_velocity_profile(y, shear_rate: float, box_height: float, offset: float = 0.0):
    """Lees–Edwards Couette velocity v_x [m/s] at heights ``y`` [m] for the SPH box [0, L_y).

    Convention of the SPH solver (SPEC §2.7): the affine field v_x = γ̇ y + v_0 on the box
    [0, L_y), with ``shear_rate`` γ̇ [1/s], ``box_height`` L_y [m] and ``offset`` v_0 [m/s]
    (default 0: the bottom face is at rest; ``offset = -γ̇ L_y/2`` gives zero mean velocity).
    Heights outside the box are wrapped into it, as the solver does with a particle crossing a
    sheared face (it subtracts γ̇ L_y from v_x), so the result is what the solver stores.
    """
    if not box_height > 0:
        raise ValueError(f"box height must be > 0 m, got {box_height!r}")
    return shear_rate * np.mod(np.asarray(y, dtype=float), box_height) + offset


def inverse_stress(law: ConstitutiveLaw, stress) -> np.ndarray:
    """Shear rate γ̇ [1/s] with μ(|γ̇|) γ̇ = τ for each stress τ [Pa] (vectorised, odd in τ).

    Precondition: τ(γ̇) strictly increasing, true for every law of SPEC §1.1 with physical
    parameters (Carreau–Yasuda with μ_inf > μ_0 and n > 1 is not: its viscosity turns
    negative). A regularised yield-stress law has a finite zero-rate viscosity, so a stress
    below its yield stress maps to a small but positive rate, which is returned.

    The root is bracketed by widening [γ̇_lo, γ̇_hi] by factors of 1e4 from τ/μ(0), then
    bisected, geometrically while the bracket spans more than a factor 2 (rates span hundreds
    of decades) and arithmetically after, down to adjacent floats; of the two, the one whose
    stress is closer to τ is returned. Raises ``ValueError`` for a non-finite stress or a
    stress the law cannot reach (bounded flow curves: Cross with m = 1 and μ_inf = 0 tends to
    μ_0/λ; Papanastasiou with μ_pl = 0 to μ_0/M).
    """
    tau = np.asarray(stress, dtype=float)
    if not np.all(np.isfinite(tau)):
        raise ValueError(f"{law.name}: stress must be finite, got {tau[~np.isfinite(tau)][:3]} Pa")
    target = np.abs(tau).ravel()
    rate = np.zeros_like(target)
    positive = target > 0
    if positive.any():
        rate[positive] = _invert_positive(law, target[positive])
    out = np.copysign(rate, tau.ravel()).reshape(tau.shape)
    return out if np.ndim(stress) else float(out)


def _first_guess(law: ConstitutiveLaw, target: np.ndarray) -> np.ndarray:
    """τ/μ(0) [1/s]: exact for small τ; μ(1) stands in when μ(0) is not finite and positive."""
    for rate in (0.0, 1.0):
        mu = float(law.viscosity(rate))
        if np.isfinite(mu) and mu > 0:
            return np.clip(target / mu, RATE_MIN, RATE_MAX)
    return np.clip(target, RATE_MIN, RATE_MAX)


def _invert_positive(law: ConstitutiveLaw, target: np.ndarray) -> np.ndarray:
    """γ̇ > 0 [1/s] with τ(γ̇) = target > 0 [Pa]; see :func:`inverse_stress`."""
    lo = _first_guess(law, target)
    hi = lo.copy()
    # Widen until τ(lo) ≤ target ≤ τ(hi), only where the invariant does not hold yet.
    for _ in range(_MAX_EXPANSIONS):
        move = (law.stress(lo) > target) & (lo > RATE_MIN)
        if not move.any():
            break
        lo[move] = np.maximum(lo[move] / _EXPANSION, RATE_MIN)
    for _ in range(_MAX_EXPANSIONS):
        move = (law.stress(hi) < target) & (hi < RATE_MAX)
        if not move.any():
            break
        hi[move] = np.minimum(hi[move] * _EXPANSION, RATE_MAX)
    unreachable = law.stress(hi) < target
    if unreachable.any():
        sup = float(law.stress(RATE_MAX))
        raise ValueError(f"{law.name}: stress {target[unreachable].max():g} Pa is beyond the "
                         f"flow curve's supremum ≈ {sup:g} Pa; no shear rate reaches it")
    for _ in range(_MAX_BISECTIONS):
        geometric = hi > 2.0 * lo
        # sqrt(lo)·sqrt(hi): the geometric mean without overflow or underflow of lo·hi.
        mid = np.where(geometric, np.sqrt(lo) * np.sqrt(hi), lo + 0.5 * (hi - lo))
        active = np.flatnonzero((mid > lo) & (mid < hi))
        if active.size == 0:
            break
        below = law.stress(mid[active]) <= target[active]
        lo[active[below]] = mid[active[below]]
        hi[active[~below]] = mid[active[~below]]
    closer_hi = np.abs(law.stress(hi) - target) < np.abs(law.stress(lo) - target)
    return np.where(closer_hi, hi, lo)
