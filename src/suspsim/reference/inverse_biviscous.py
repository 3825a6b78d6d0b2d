"""Inverse-biviscous fluid: a monotonic DST flow curve with a rate plateau, and its channel flow.

Seed 002 (Fig. 8) compares its channel flow with the "inverse-biviscous" model of
Vázquez-Quesada, Wagner & Ellero (2017). That paper was not available to this project (the
reference search found no copy), so the form below is derived here from the description in
SPEC §5.7 and the project brief, and every closed form is checked against quadrature in
``tests/unit/dst/test_inverse_biviscous.py``.

Flow curve [derived]. Two Newtonian viscosities — η_1 = η(f = 0), the frictionless
(Maron–Pierce with φ_0) branch, and η_2 = η(f = 1), the frictional (φ_m) branch — joined at a
critical rate γ̇_c by a vertical stress jump, which a DST fluid covers by splitting into
bands at a common rate instead of following the unstable branch:

    γ̇(σ) = σ/η_1        for 0 ≤ σ ≤ σ_1 = η_1 γ̇_c,
    γ̇(σ) = γ̇_c          for σ_1 ≤ σ ≤ σ_2 = η_2 γ̇_c       (the plateau),
    γ̇(σ) = σ/η_2        for σ ≥ σ_2.

γ̇(σ) is continuous and non-decreasing; its inverse σ(γ̇) is single valued except at γ̇_c,
where it is the interval [σ_1, σ_2] (the inverse of a biviscous/Bingham-like curve, whose
plateau is in stress; hence the name). With η_1 = η_2 it is Newtonian.

Channel flow [derived]. Walls at y = 0 and d, body force F per volume, H = d/2; momentum
balance gives σ_xy = F (H − y), so on the half channel σ runs from σ_w = F H at the wall to 0
at the centre line. With dy = −dσ/F (SPEC §6.2, as :mod:`suspsim.reference.dst_channel`):

    u(y) = (1/F) [G(σ_w) − G(σ(y))],            G(s) = ∫_0^s γ̇(σ) dσ,
    ū    = (1/(H F²)) M(σ_w),                    M(s) = ∫_0^s σ γ̇(σ) dσ,

mirrored about y = H. Piecewise, using σ_1²/(2η_1) = γ̇_c σ_1/2 and σ_2³/(3η_2) = γ̇_c σ_2²/3:

    G(s) = s²/(2η_1)                             s ≤ σ_1
         = γ̇_c (s − σ_1/2)                        σ_1 ≤ s ≤ σ_2
         = s²/(2η_2) + γ̇_c (σ_2 − σ_1)/2           s ≥ σ_2,
    M(s) = s³/(3η_1)                             s ≤ σ_1
         = γ̇_c (s²/2 − σ_1²/6)                    σ_1 ≤ s ≤ σ_2
         = s³/(3η_2) + γ̇_c (σ_2² − σ_1²)/6         s ≥ σ_2.

Both are continuous at σ_1 and σ_2 (so is u(y)); in the plateau layer, where
σ_1 < F (H − y) < σ_2, du/dy = γ̇_c exactly. The mean velocity is
ū = F H²/(3η_1) for F H ≤ σ_1, γ̇_c (H/2 − σ_1²/(6 H F²)) on the plateau and
F H²/(3η_2) + γ̇_c (σ_2² − σ_1²)/(6 H F²) above; dū/dF > 0 on each piece (at F H = σ_2 it is
H² σ_1²/(3 η_2 σ_2²) > 0), so ū(F) rises monotonically: this model has no flow reduction,
unlike the local Wyart–Cates channel of SPEC §5.7, whose unstable branch gives one.

Critical rate [derived; choice of default]. A vertical split at rate γ̇ needs both stable
branches of the Wyart–Cates S-curve at that rate, so γ̇_min < γ̇_c < γ̇_max (turning points
σ_α, σ_β of :meth:`~suspsim.rheology.wyart_cates.WyartCates.turning_points`); the local model
(α = 0) leaves the rate undetermined within that range. With non-locality,
Df/Dt = K_f γ̇ (f̂(σ) − f) + α ∇²f at a common rate γ̇ (σ = η(f) γ̇) is a bistable
reaction–diffusion equation with R(f) = K_f γ̇ (f̂(η(f) γ̇) − f), whose stable roots f_1, f_2
are the two branches at γ̇. A planar front between them is stationary only if
∫_{f_1}^{f_2} R df = 0 (the equal-area rule of bistable fronts, e.g. Fife & McLeod 1977; it
follows from multiplying α f'' + R(f) = 0 by f' and integrating across the front). That rule
picks one rate, :func:`front_selected_rate`, independent of α > 0 and K_f; it is the default
γ̇_c of :meth:`InverseBiviscous.from_wyart_cates`. At φ = 0.54, σ* = η_s = 1 it gives
γ̇_c = 0.02313 (γ̇_min = 0.01103, γ̇_max = 0.02854; σ_1 = 0.475, σ_2 = 15.1) with seed
002's φ_m = 0.562, φ_0 = 0.693, and γ̇_c = 0.01199 (γ̇_min = 0.00748, γ̇_max = 0.01430;
σ_1 = 0.491, σ_2 = 9.40) with its Fig. 8 pair φ_m = 0.56, φ_0 = 0.64 [computed:
``InverseBiviscous.from_wyart_cates(WyartCates(1, 0.54, φ_m, φ_0, 1, 2))``].

Symbols (SI in seed 002; any consistent units work the same way):

========= =============================================================== =========
symbol    meaning                                                         unit
========= =============================================================== =========
η_1, η_2  (low_viscosity, high_viscosity) Newtonian viscosities           Pa s
γ̇_c       (critical_rate) rate of the plateau                             1/s
σ_1, σ_2  η_1 γ̇_c, η_2 γ̇_c: stresses at the ends of the plateau           Pa
F         (force_density) driving force per volume                        Pa/m
d, H      (gap) wall-to-wall distance, half-gap d/2                        m
y         distance from the wall at y = 0                                 m
u, ū      velocity along x, its mean over the gap                         m/s
========= =============================================================== =========
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from suspsim.rheology.wyart_cates import WyartCates

_BRENT = {"xtol": 1e-300, "rtol": 4.0 * np.finfo(float).eps}


@dataclass(frozen=True)
class InverseBiviscous:
    """Inverse-biviscous flow curve (module docstring): η_1 ≤ η_2 [Pa s], γ̇_c [1/s].

    Raises ValueError unless 0 < η_1 ≤ η_2 < ∞ and 0 < γ̇_c < ∞.
    """

    low_viscosity: float
    high_viscosity: float
    critical_rate: float

    def __post_init__(self):
        for name in ("low_viscosity", "high_viscosity", "critical_rate"):
            value = float(getattr(self, name))
            if not (0.0 < value < math.inf):
                raise ValueError(f"InverseBiviscous: {name} = {value!r} must be positive and "
                                 "finite")
            object.__setattr__(self, name, value)
        if self.low_viscosity > self.high_viscosity:
            raise ValueError(f"InverseBiviscous: need low_viscosity <= high_viscosity, got "
                             f"{self.low_viscosity} > {self.high_viscosity}")

    @classmethod
    def from_wyart_cates(cls, law: WyartCates, critical_rate: float | None = None
                         ) -> "InverseBiviscous":
        """η_1 = η(f = 0), η_2 = η(f = 1) of ``law``; γ̇_c [1/s] default
        :func:`front_selected_rate` (needs an S-curve with a flowing upper branch, φ < φ_m)."""
        if critical_rate is None:
            critical_rate = front_selected_rate(law)
        return cls(float(law.viscosity_from_fraction(0.0)),
                   float(law.viscosity_from_fraction(1.0)), critical_rate)

    @property
    def lower_stress(self) -> float:
        """σ_1 = η_1 γ̇_c [Pa], where the plateau starts."""
        return self.low_viscosity * self.critical_rate

    @property
    def upper_stress(self) -> float:
        """σ_2 = η_2 γ̇_c [Pa], where the plateau ends."""
        return self.high_viscosity * self.critical_rate

    def shear_rate(self, stress):
        """γ̇(σ) [1/s] at stress magnitude σ ≥ 0 [Pa] (module docstring); elementwise."""
        s = _magnitude(stress, "stress")
        return np.where(s <= self.lower_stress, s / self.low_viscosity,
                        np.where(s < self.upper_stress, self.critical_rate,
                                 s / self.high_viscosity))[()]

    def stress(self, rate):
        """σ(γ̇) [Pa] as the pair (lowest, highest) stress at rate γ̇ ≥ 0 [1/s]; elementwise.

        Both equal η_1 γ̇ below γ̇_c and η_2 γ̇ above; at γ̇ = γ̇_c they are the ends of the
        vertical jump, (σ_1, σ_2).
        """
        g = _magnitude(rate, "rate")
        low = np.where(g <= self.critical_rate, self.low_viscosity * g,
                       self.high_viscosity * g)
        high = np.where(g < self.critical_rate, self.low_viscosity * g,
                        self.high_viscosity * g)
        return low[()], high[()]

    def rate_integral(self, stress):
        """G(s) = ∫_0^s γ̇(σ) dσ [Pa/s], closed form (module docstring); elementwise."""
        s = _magnitude(stress, "stress")
        s1, s2, gc = self.lower_stress, self.upper_stress, self.critical_rate
        return np.where(s <= s1, s * s / (2.0 * self.low_viscosity),
                        np.where(s <= s2, gc * (s - 0.5 * s1),
                                 s * s / (2.0 * self.high_viscosity) + 0.5 * gc * (s2 - s1))
                        )[()]

    def stress_moment(self, stress):
        """M(s) = ∫_0^s σ γ̇(σ) dσ [Pa²/s], closed form (module docstring); elementwise."""
        s = _magnitude(stress, "stress")
        s1, s2, gc = self.lower_stress, self.upper_stress, self.critical_rate
        return np.where(s <= s1, s ** 3 / (3.0 * self.low_viscosity),
                        np.where(s <= s2, gc * (0.5 * s * s - s1 * s1 / 6.0),
                                 s ** 3 / (3.0 * self.high_viscosity)
                                 + gc * (s2 * s2 - s1 * s1) / 6.0))[()]

    def channel_profile(self, force_density: float, gap: float, y):
        """Steady channel velocity u(y) = [G(F H) − G(F |H − y|)]/F [m/s] at y ∈ [0, gap] [m].

        ``force_density`` F [Pa/m], ``gap`` d [m]; u(0) = u(d) = 0, symmetric about d/2.
        """
        _check_channel(force_density, gap)
        y = np.asarray(y, dtype=float)
        if np.any((y < 0.0) | (y > gap)):
            raise ValueError("heights y must lie in [0, gap]")
        half = gap / 2.0
        stress = force_density * np.abs(half - y)
        return ((self.rate_integral(force_density * half) - self.rate_integral(stress))
                / force_density)[()]

    def channel_mean_velocity(self, force_density: float, gap: float):
        """Gap-averaged velocity ū = M(F H)/(H F²) [m/s] for F [Pa/m] (scalar or array), d [m]."""
        force = np.asarray(force_density, dtype=float)
        if np.any(~(force > 0.0)) or np.any(~np.isfinite(force)):
            raise ValueError("force_density must be positive and finite")
        _check_channel(1.0, gap)
        half = gap / 2.0
        return (self.stress_moment(force * half) / (half * force * force))[()]


def front_selected_rate(law: WyartCates) -> float:
    """Rate γ̇_c [1/s] at which a non-local Wyart–Cates front between the branches is stationary.

    The root in (γ̇_min, γ̇_max) of I(γ̇) = ∫_{f_1}^{f_2} (f̂(η(f) γ̇) − f) df, with f_1, f_2 the
    frictional fractions f̂(σ_1), f̂(σ_2) of the lower and upper stable branches at γ̇
    (:meth:`~suspsim.rheology.wyart_cates.WyartCates.branch_stress`) — the equal-area rule
    of the bistable reaction–diffusion equation Df/Dt = K_f γ̇ (f̂(σ) − f) + α ∇²f at a
    common rate (module docstring). I > 0 near γ̇_max (the upper branch invades), I < 0 near
    γ̇_min; the root is bracketed and found with Brent's method. Raises ValueError when the law
    has no flowing upper branch (CST, or φ ≥ φ_m).
    """
    turning = law.turning_points()
    if turning is None or not math.isfinite(turning.sigma_alpha) or turning.gdot_min <= 0.0:
        raise ValueError(f"phi = {law.phi} has no S-curve with a flowing upper branch: no "
                         "rate plateau to select")
    span = turning.gdot_max - turning.gdot_min
    margin = 1e-9 * span
    return float(brentq(lambda g: front_integral(law, g), turning.gdot_min + margin,
                        turning.gdot_max - margin, **_BRENT))


def front_integral(law: WyartCates, rate: float) -> float:
    """I(γ̇) = ∫_{f_1}^{f_2} (f̂(η(f) γ̇) − f) df [1] at rate γ̇ in (γ̇_min, γ̇_max) [1/s].

    See :func:`front_selected_rate`; the integrand is the reaction rate of f per K_f γ̇.
    Integrated with adaptive Gauss–Kronrod (``scipy.integrate.quad``), split at the unstable
    root (the stress on the unstable branch at γ̇), where the integrand changes sign.
    """
    f1 = float(law.frictional_fraction(law.branch_stress(rate, "lower")))
    f2 = float(law.frictional_fraction(law.branch_stress(rate, "upper")))
    if not (math.isfinite(f1) and math.isfinite(f2)):
        raise ValueError(f"rate {rate!r} lies outside (gdot_min, gdot_max): one branch lacks it")
    turning = law.turning_points()
    middle = brentq(lambda s: float(law.shear_rate(s)) - rate, turning.sigma_beta,
                    turning.sigma_alpha, **_BRENT)
    fm = float(law.frictional_fraction(middle))

    def reaction(f):
        return float(law.frictional_fraction(law.viscosity_from_fraction(f) * rate)) - f

    options = {"epsabs": 1e-14, "epsrel": 1e-10, "limit": 200}
    return quad(reaction, f1, fm, **options)[0] + quad(reaction, fm, f2, **options)[0]


def _magnitude(value, name):
    v = np.asarray(value, dtype=float)
    if np.any(~(v >= 0.0)):
        raise ValueError(f"{name} is a magnitude and must be >= 0")
    return v


def _check_channel(force_density, gap):
    if not (force_density > 0.0 and math.isfinite(force_density)):
        raise ValueError(f"force_density = {force_density!r} must be positive and finite")
    if not (gap > 0.0 and math.isfinite(gap)):
        raise ValueError(f"gap = {gap!r} must be positive and finite")
