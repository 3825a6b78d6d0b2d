"""Steady Wyart–Cates law of discontinuous shear thickening (SPEC §1.3; seed 002).

Wyart & Cates, PRL 112, 098302 (2014), in the form used by seed 002: frictional contacts
proliferate above an onset stress σ*, moving the jamming fraction from φ_0 (frictionless) to
φ_m (frictional); the viscosity diverges Maron–Pierce-like at φ_J:

    f̂(σ) = exp(−(σ*/σ)^β),   φ_J(f) = f φ_m + (1 − f) φ_0,   η(f) = η_s (1 − φ/φ_J(f))^(−2),
    γ̇(σ) = σ/η(f̂(σ)).

γ̇(σ) is single valued, so flow curves are parametrised by σ; σ(γ̇) is S-shaped (DST) where
S = d ln γ̇/d ln σ < 0 (the slope is derived in :meth:`WyartCates.log_slope`). Regimes:

* ``"CST"`` (φ < φ_m, S > 0 everywhere): continuous shear thickening;
* ``"DST"`` (φ < φ_m, S < 0 between the turning points σ_β < σ_α): γ̇ has a local maximum
  γ̇_max at σ_β and a local minimum γ̇_min at σ_α, so σ jumps discontinuously with γ̇;
* ``"jammed_at_high_stress"`` (φ_m ≤ φ < φ_0): the frictional packing cannot flow; γ̇ rises to
  γ̇_max at σ_β and falls to 0 at the jamming stress σ_J (φ_J(f̂(σ_J)) = φ) and stays 0 above.
  At φ = φ_m exactly, σ_J = ∞: γ̇ ∝ σ^(1−2β) → 0 only asymptotically, and for β ≤ ½ it has no
  maximum at all (the viscosity still diverges). φ ≥ φ_0 (jammed at every stress) is rejected
  when the model is built.

Symbols (SI units):

========= ================================================= ======
symbol    meaning                                           unit
========= ================================================= ======
σ         (stress) shear-stress magnitude                   Pa
γ̇         (shear_rate) shear-rate magnitude                 1/s
η, η_s    suspension viscosity, solvent viscosity           Pa s
φ         volume fraction                                   1
φ_m, φ_0  frictional, frictionless jamming fraction         1
Δ         φ_0 − φ_m                                         1
f, f̂      fraction of frictional contacts, its steady value 1
σ*        onset stress of frictional contacts               Pa
β         sharpness of the onset (1: Wyart–Cates, 2: seed)  1
x         (σ*/σ)^β, so f̂ = e^(−x)                           1
S         d ln γ̇/d ln σ                                     1
========= ================================================= ======
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np
from numba import njit
from scipy.optimize import brentq

CST, DST, JAMMED_AT_HIGH_STRESS = "CST", "DST", "jammed_at_high_stress"

#: Brent tolerances: purely relative, since roots x = (σ*/σ)^β may be tiny near φ_m.
_BRENT = {"xtol": 1e-300, "rtol": 4.0 * np.finfo(float).eps}


@njit(cache=True)
def wc_frictional_fraction(stress, sigma_star, beta):
    """Steady fraction of frictional contacts f̂ = exp(−(σ*/σ)^β) [1]; 0 for σ ≤ 0.

    Wyart & Cates, PRL 112, 098302 (2014) (β = 1); seed 002 uses β = 2. σ, σ* in Pa.
    """
    if stress <= 0.0:
        return 0.0
    return math.exp(-(sigma_star / stress) ** beta)


@njit(cache=True)
def wc_viscosity(f, eta_s, phi, phi_m, phi_0):
    """η(f) = η_s (1 − φ/φ_J)^(−2) [Pa s] with φ_J = f φ_m + (1 − f) φ_0.

    Wyart & Cates, PRL 112, 098302 (2014), Maron–Pierce form of seed 002. Returns inf when
    φ ≥ φ_J (jammed); the solver must cap the viscosity explicitly.
    """
    phi_j = f * phi_m + (1.0 - f) * phi_0
    if phi >= phi_j:
        return math.inf
    r = 1.0 - phi / phi_j
    return eta_s / (r * r)


class TurningPoints(NamedTuple):
    """Turning points of the S-curve: γ̇ has a local maximum at σ_β and a minimum at σ_α."""

    sigma_beta: float
    gdot_max: float
    sigma_alpha: float
    gdot_min: float


@dataclass(frozen=True)
class WyartCates:
    """Steady Wyart–Cates suspension: η_s [Pa s], φ, φ_m, φ_0 [1], σ* [Pa], β [1].

    Requires η_s > 0, σ* > 0, β > 0, 0 < φ_m < φ_0 ≤ 1 and 0 < φ < φ_0 (``ValueError``).
    """

    eta_s: float
    phi: float
    phi_m: float
    phi_0: float
    sigma_star: float
    beta: float = 2.0

    def __post_init__(self):
        for field in fields(self):
            value = getattr(self, field.name)
            try:
                object.__setattr__(self, field.name, float(value))
            except (TypeError, ValueError):
                raise ValueError(f"WyartCates: {field.name} = {value!r} is not a number") from None
        for name, unit in (("eta_s", " Pa s"), ("sigma_star", " Pa"), ("beta", "")):
            value = getattr(self, name)
            if not (0.0 < value < math.inf):
                raise ValueError(f"WyartCates: {name} = {value!r}{unit} must be positive "
                                 f"and finite")
        if not (0.0 < self.phi_m < self.phi_0 <= 1.0):
            raise ValueError(f"WyartCates: need 0 < phi_m < phi_0 <= 1 (frictional jamming below "
                             f"frictionless); got phi_m = {self.phi_m}, phi_0 = {self.phi_0}")
        if not (0.0 < self.phi < self.phi_0):
            raise ValueError(f"WyartCates: need 0 < phi < phi_0 = {self.phi_0} (at phi_0 the "
                             f"suspension is jammed at every stress); got phi = {self.phi}")

    def frictional_fraction(self, stress):
        """f̂(σ) = exp(−(σ*/σ)^β) [1]; 0 for σ ≤ 0, → 1 as σ → ∞."""
        s = np.asarray(stress, dtype=float)
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            f = np.exp(-((self.sigma_star / s) ** self.beta))
        return np.where(s > 0.0, f, np.where(s <= 0.0, 0.0, np.nan))[()]

    def jamming_fraction(self, f):
        """φ_J(f) = f φ_m + (1 − f) φ_0 [1] for 0 ≤ f ≤ 1."""
        f = np.asarray(f, dtype=float)
        if np.any(~((f >= 0.0) & (f <= 1.0))):
            raise ValueError("frictional fraction f must satisfy 0 <= f <= 1")
        return (f * self.phi_m + (1.0 - f) * self.phi_0)[()]

    def viscosity_from_fraction(self, f):
        """η(f) = η_s (1 − φ/φ_J(f))^(−2) [Pa s]; inf where φ ≥ φ_J(f) (jammed)."""
        phi_j = np.asarray(self.jamming_fraction(f))
        with np.errstate(divide="ignore"):
            r = 1.0 - self.phi / phi_j
            return np.where(self.phi < phi_j, self.eta_s / (r * r), np.inf)[()]

    def viscosity(self, stress):
        """Steady viscosity η(f̂(σ)) [Pa s] at stress σ [Pa]."""
        return self.viscosity_from_fraction(self.frictional_fraction(stress))

    def shear_rate(self, stress):
        """Steady shear rate γ̇ = σ/η(f̂(σ)) [1/s] at stress σ ≥ 0 [Pa]; 0 where jammed."""
        s = np.asarray(stress, dtype=float)
        if np.any(~(s >= 0.0)):
            raise ValueError("stress is a magnitude and must be >= 0 Pa")
        eta = np.asarray(self.viscosity(s))
        return np.where(np.isinf(eta), 0.0, s / eta)[()]

    def log_slope(self, stress):
        """S = d ln γ̇/d ln σ = 1 − 2βφΔ x e^(−x)/(φ_J (φ_J − φ)) [1], x = (σ*/σ)^β, σ > 0 [Pa].

        From ln γ̇ = ln σ − ln η_s + 2 ln(1 − φ/φ_J), dφ_J/d ln σ = −Δ df̂/d ln σ = −Δ β x e^(−x).
        NaN where jammed (γ̇ ≡ 0).
        """
        s = np.asarray(stress, dtype=float)
        if np.any(~(s > 0.0)):
            raise ValueError("log_slope needs stress > 0 Pa")
        with np.errstate(over="ignore", invalid="ignore"):
            x = (self.sigma_star / s) ** self.beta
            f = np.exp(-x)
            fx = np.where(f > 0.0, f * x, 0.0)
            phi_j = f * self.phi_m + (1.0 - f) * self.phi_0
            gap = phi_j - self.phi
            delta = self.phi_0 - self.phi_m
            slope = 1.0 - 2.0 * self.beta * self.phi * delta * fx / (phi_j * gap)
        return np.where(gap > 0.0, slope, np.nan)[()]

    def flow_curve(self, stress_min, stress_max, n=200):
        """(σ [Pa], γ̇ [1/s]) on n log-spaced stresses from stress_min to stress_max."""
        if not (0.0 < stress_min < stress_max < math.inf) or int(n) < 2:
            raise ValueError("flow_curve needs 0 < stress_min < stress_max and n >= 2")
        stress = np.geomspace(stress_min, stress_max, int(n))
        return stress, self.shear_rate(stress)

    def viscosity_ratio(self):
        """η(f = 1)/η(f = 0) [1], frictional over frictionless viscosity; inf for φ ≥ φ_m."""
        return float(self.viscosity_from_fraction(1.0) / self.viscosity_from_fraction(0.0))

    def jamming_stress(self):
        """σ_J [Pa] with φ_J(f̂(σ_J)) = φ: x_J = ln(Δ/(φ_0 − φ)); inf for φ ≤ φ_m."""
        if self.phi <= self.phi_m:
            return math.inf
        return self._stress(math.log((self.phi_0 - self.phi_m) / (self.phi_0 - self.phi)))

    def turning_points(self):
        """The S-curve's turning points as :class:`TurningPoints`, or None if γ̇(σ) is monotone.

        They are the roots of S = −G(x)/(φ_J (φ_J − φ)), i.e. of
        G(x) = 2βφΔ x e^(−x) − φ_J (φ_J − φ), which is strictly concave in f = e^(−x), so it
        has at most two roots; G'(x) = −Δ e^(−x) P(x) with P increasing, so the maximum of G is
        the root x* of P. For φ < φ_m, G(0) < 0 and G(∞) < 0: two roots iff G(x*) > 0. For
        φ ≥ φ_m the domain is x > x_J (σ < σ_J) and G(x_J) ≥ 0: one root σ_β, and σ_α = σ_J
        with γ̇_min = 0 (None at φ = φ_m with β ≤ ½, where G < 0 throughout). Each root is
        bracketed and found with Brent's method.
        """
        x_star = self._argmax_numerator()
        if self.phi < self.phi_m:
            if x_star is None or self._numerator(x_star) <= 0.0:
                return None
            x_alpha = brentq(self._numerator, 0.0, x_star, **_BRENT)
            sigma_alpha = self._stress(x_alpha)
            gdot_min = float(self.shear_rate(sigma_alpha))
            lower = x_star
        else:
            x_jam = math.log((self.phi_0 - self.phi_m) / (self.phi_0 - self.phi))
            lower = x_jam if x_star is None else max(x_jam, x_star)
            if self._numerator(lower) <= 0.0:
                return None
            sigma_alpha, gdot_min = self.jamming_stress(), 0.0
        # G → −φ_0 (φ_0 − φ) < 0 as x → ∞ (σ → 0), so doubling closes the low-stress bracket.
        upper = max(2.0 * lower, 1.0)
        while self._numerator(upper) >= 0.0:
            upper *= 2.0
        x_beta = brentq(self._numerator, lower, upper, **_BRENT)
        sigma_beta = self._stress(x_beta)
        return TurningPoints(sigma_beta, float(self.shear_rate(sigma_beta)), sigma_alpha, gdot_min)

    def branch_stress(self, rate, branch):
        """Stress σ [Pa] of a stable branch of the S-curve at shear rate ``rate`` [1/s].

        ``branch = "lower"``: the root of γ̇(σ) = rate with σ < σ_β (γ̇ rises from 0 to
        γ̇_max there), NaN where rate ≥ γ̇_max; ``"upper"``: the root with σ > σ_α (γ̇ rises
        from γ̇_min to ∞ for φ < φ_m), NaN where rate ≤ γ̇_min and always NaN for φ ≥ φ_m (no
        flowing upper branch). Without turning points (CST) γ̇(σ) is monotone and both branches
        are the whole curve, so both return its single root. These are σ1, σ2 of the vertical-
        split lever rule (SPEC §5.6); rate may be an array (elementwise).
        """
        if branch not in ("lower", "upper"):
            raise ValueError(f"branch must be 'lower' or 'upper', got {branch!r}")
        rates = np.asarray(rate, dtype=float)
        if np.any(~(rates > 0.0)):
            raise ValueError("branch_stress needs rate > 0 1/s")
        turning = self.turning_points()
        out = np.array([self._branch_root(float(g), branch, turning) for g in rates.ravel()])
        return out.reshape(rates.shape)[()]

    def _branch_root(self, rate, branch, turning):
        def residual(s):
            return float(self.shear_rate(s)) - rate

        if turning is None:
            low, high = 0.0, self.sigma_star
        elif branch == "lower":
            if rate >= turning.gdot_max:
                return math.nan
            low, high = 0.0, turning.sigma_beta
        else:
            # φ ≥ φ_m: σ_α is the jamming stress, γ̇ = 0 beyond it (no flowing upper branch)
            if self.phi >= self.phi_m or rate <= turning.gdot_min:
                return math.nan
            low, high = turning.sigma_alpha, 2.0 * turning.sigma_alpha
        # γ̇ is increasing on the bracket and unbounded above it (stable branches, CST).
        while residual(high) < 0.0:
            low, high = high, 2.0 * high
        return brentq(residual, low, high, **_BRENT)

    def lever_rule(self, stress, rate):
        """Lower-branch share ψ1 = (σ2 − σ)/(σ2 − σ1) of a vertical split of σ at rate γ̇.

        σ1, σ2 = :meth:`branch_stress` (lower, upper) at ``rate`` (SPEC §5.6). NaN where
        either branch lacks that rate (γ̇ outside (γ̇_min, γ̇_max)) or the curve is CST. The
        share lies in [0, 1] only for σ1 ≤ σ ≤ σ2; it is returned unclipped.
        """
        if self.turning_points() is None:
            return np.full(np.shape(stress), math.nan)[()]
        s1 = np.asarray(self.branch_stress(rate, "lower"))
        s2 = np.asarray(self.branch_stress(rate, "upper"))
        return ((s2 - np.asarray(stress, dtype=float)) / (s2 - s1))[()]

    def regime(self):
        """``"CST"``, ``"DST"`` or ``"jammed_at_high_stress"`` (see the module docstring)."""
        if self.phi >= self.phi_m:
            return JAMMED_AT_HIGH_STRESS
        return CST if self.turning_points() is None else DST

    def _stress(self, x):
        """σ = σ* x^(−1/β) [Pa], the inverse of x = (σ*/σ)^β; inf at x = 0."""
        return math.inf if x == 0.0 else self.sigma_star * x ** (-1.0 / self.beta)

    def _numerator(self, x):
        """G(x) = 2βφΔ x e^(−x) − φ_J (φ_J − φ), with expm1 so φ_J − φ keeps its digits."""
        delta = self.phi_0 - self.phi_m
        em1 = math.expm1(-x)
        phi_j = self.phi_m - delta * em1
        return (2.0 * self.beta * self.phi * delta * x * (1.0 + em1)
                - phi_j * (self.phi_m - self.phi - delta * em1))

    def _argmax_numerator(self):
        """Root x* of P(x) = 2βφ(x − 1) + 2φ_J − φ, or None when P(0) ≥ 0.

        P is increasing and P(1 + 1/(2β)) = 2φ_J > 0, which closes the bracket.
        """
        delta = self.phi_0 - self.phi_m

        def p(x):
            phi_j = self.phi_m - delta * math.expm1(-x)
            return 2.0 * self.beta * self.phi * (x - 1.0) + 2.0 * phi_j - self.phi

        if p(0.0) >= 0.0:
            return None
        return brentq(p, 0.0, 1.0 + 0.5 / self.beta, **_BRENT)
