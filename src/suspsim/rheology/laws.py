"""Generalized-Newtonian constitutive laws μ(γ̇) of the matrix fluid (SPEC §1.1).

Each law is one small ``@njit`` function of the shear rate and named scalar parameters; the
solver calls them through :func:`viscosity_kernel`, which dispatches on an integer law code so a
scene passes ``(code, packed parameters)`` into compiled loops. :class:`ConstitutiveLaw` binds
parameter values and gives the vectorised NumPy-facing API.

Symbols (SI units; any consistent units work the same way in simulation units):

======== ============================================ ===========
symbol   meaning                                      unit
======== ============================================ ===========
γ̇        shear-rate magnitude sqrt(2 D:D)             1/s
μ        (apparent) viscosity                         Pa s
τ        shear stress τ = μ(γ̇) γ̇                      Pa
K        consistency                                  Pa s^n
n        flow index                                   1
λ        (lam) time constant                          s
m, a     Cross exponent, Carreau–Yasuda transition    1
μ_0      zero-rate viscosity (Papanastasiou: excess)  Pa s
μ_inf    infinite-rate viscosity                      Pa s
μ_pl     plastic viscosity                            Pa s
M        Papanastasiou regularisation (τ_y = μ_0/M)   s
τ_y      yield stress                                 Pa
γ̇_c      (gdot_c) crossover rate, three-component     1/s
η_bg     (eta_bg) background viscosity                Pa s
γ̇_min    (gdot_min) floor of γ̇ in γ̇^(n−1) [choice]    1/s
======== ============================================ ===========
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

import numpy as np
from numba import njit

#: Length of the packed parameter vector handed to compiled code.
MAX_PARAMETERS = 5

#: Default floor of γ̇ inside γ̇^(n−1) [1/s] [choice]: far below any rheometer's lowest rate, it
#: only keeps power-law viscosities finite at rest. Scenes in simulation units may set their own.
DEFAULT_GDOT_MIN = 1e-6

NEWTONIAN, POWER_LAW, CROSS, CARREAU_YASUDA, PAPANASTASIOU, HERSCHEL_BULKLEY, THREE_COMPONENT = range(7)


@njit(cache=True)
def relaxation_factor(x):
    """(1 − e^(−x))/x, the Papanastasiou regularisation factor [1]; → 1 as x → 0.

    Evaluated with ``expm1`` for accuracy at small x (the solver's hot path), with the series
    1 − x/2 + x²/6 below 1e−8 to avoid 0/0 at rest.
    """
    if x < 1e-8:
        return 1.0 - 0.5 * x + x * x / 6.0
    return -math.expm1(-x) / x


@njit(cache=True)
def newtonian_viscosity(shear_rate, mu):
    """μ(γ̇) = μ [Pa s]."""
    return mu


@njit(cache=True)
def power_law_viscosity(shear_rate, K, n, gdot_min):
    """μ(γ̇) = K max(γ̇, γ̇_min)^(n−1) [Pa s] (Ostwald–de Waele; floor γ̇_min [choice])."""
    return K * max(shear_rate, gdot_min) ** (n - 1.0)


@njit(cache=True)
def cross_viscosity(shear_rate, mu_0, mu_inf, lam, m):
    """μ(γ̇) = μ_inf + (μ_0 − μ_inf)/(1 + (λγ̇)^m) [Pa s] (Cross 1965, J. Colloid Sci. 20, 417)."""
    return mu_inf + (mu_0 - mu_inf) / (1.0 + (lam * shear_rate) ** m)


@njit(cache=True)
def carreau_yasuda_viscosity(shear_rate, mu_0, mu_inf, lam, a, n):
    """μ(γ̇) = μ_inf + (μ_0 − μ_inf)[1 + (λγ̇)^a]^((n−1)/a) [Pa s] (Yasuda, Armstrong & Cohen 1981)."""
    return mu_inf + (mu_0 - mu_inf) * (1.0 + (lam * shear_rate) ** a) ** ((n - 1.0) / a)


@njit(cache=True)
def papanastasiou_viscosity(shear_rate, mu_pl, mu_0, M):
    """μ(γ̇) = μ_pl + μ_0 (1 − e^(−Mγ̇))/(Mγ̇) [Pa s].

    Regularised Bingham fluid (Papanastasiou 1987, J. Rheol. 31, 385; seed 000 Eq. 28): zero-rate
    viscosity μ_pl + μ_0, infinite-rate μ_pl, effective yield stress τ_y = μ_0/M.
    """
    return mu_pl + mu_0 * relaxation_factor(M * shear_rate)


@njit(cache=True)
def herschel_bulkley_viscosity(shear_rate, tau_y, K, n, M, gdot_min):
    """μ(γ̇) = (τ_y (1 − e^(−Mγ̇)) + K γ̇^n)/γ̇ [Pa s], Papanastasiou-regularised Herschel–Bulkley.

    Written as τ_y M (1 − e^(−Mγ̇))/(Mγ̇) + K max(γ̇, γ̇_min)^(n−1) so it is finite at rest.
    Herschel & Bulkley 1926; regularisation: Papanastasiou 1987.
    """
    return tau_y * M * relaxation_factor(M * shear_rate) + K * max(shear_rate, gdot_min) ** (n - 1.0)


@njit(cache=True)
def three_component_viscosity(shear_rate, tau_y, gdot_c, eta_bg, M):
    """μ(γ̇) = (τ_y (1 − e^(−Mγ̇))(1 + (γ̇/γ̇_c)^½) + η_bg γ̇)/γ̇ [Pa s].

    Caggioni, Trappe & Spicer 2020 (J. Rheol. 64, 413), Papanastasiou-regularised at low rate.
    """
    return tau_y * M * relaxation_factor(M * shear_rate) * (1.0 + math.sqrt(shear_rate / gdot_c)) + eta_bg


@njit(cache=True)
def viscosity_kernel(code, p, shear_rate):
    """Viscosity [Pa s] of law ``code`` with packed parameters ``p`` at ``shear_rate`` [1/s].

    The compiled entry point used by the solver: ``p`` is :attr:`ConstitutiveLaw.packed`.
    """
    if code == NEWTONIAN:
        return newtonian_viscosity(shear_rate, p[0])
    if code == PAPANASTASIOU:
        return papanastasiou_viscosity(shear_rate, p[0], p[1], p[2])
    if code == POWER_LAW:
        return power_law_viscosity(shear_rate, p[0], p[1], p[2])
    if code == CROSS:
        return cross_viscosity(shear_rate, p[0], p[1], p[2], p[3])
    if code == CARREAU_YASUDA:
        return carreau_yasuda_viscosity(shear_rate, p[0], p[1], p[2], p[3], p[4])
    if code == HERSCHEL_BULKLEY:
        return herschel_bulkley_viscosity(shear_rate, p[0], p[1], p[2], p[3], p[4])
    if code == THREE_COMPONENT:
        return three_component_viscosity(shear_rate, p[0], p[1], p[2], p[3])
    return math.nan


@njit(cache=True)
def viscosity_array(code, p, shear_rate, out):
    """Fill ``out`` with the viscosity [Pa s] at each ``shear_rate`` [1/s] (compiled loop)."""
    for i in range(shear_rate.shape[0]):
        out[i] = viscosity_kernel(code, p, shear_rate[i])
    return out


@dataclass(frozen=True)
class Parameter:
    """One parameter of a law: name, unit, closed bounds and whether fitting uses log10 scale."""

    name: str
    unit: str
    lower: float
    upper: float
    description: str
    log: bool = True
    fitted: bool = True
    default: float | None = None


@dataclass(frozen=True)
class LawSpec:
    """A constitutive law's identity: name, compiled code, parameters, equation and source."""

    name: str
    code: int
    parameters: tuple[Parameter, ...]
    equation: str
    reference: str
    has_yield_stress: bool = False

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    @property
    def fitted_parameters(self) -> tuple[Parameter, ...]:
        return tuple(p for p in self.parameters if p.fitted)


_BIG = 1e12
_VISC = dict(unit="Pa s", lower=0.0, upper=_BIG)
_GDOT_MIN = Parameter("gdot_min", "1/s", 0.0, _BIG, "floor of γ̇ in γ̇^(n−1) [choice]",
                      fitted=False, default=DEFAULT_GDOT_MIN)
# Flow-index and exponent bounds keep τ(γ̇) monotone increasing (n, m > 0; Cross m ≤ 1 so the
# stress does not fall at high rate when μ_inf → 0).
_N = Parameter("n", "1", 0.01, 2.0, "flow index", log=False)

LAW_SPECS: Mapping[str, LawSpec] = MappingProxyType({s.name: s for s in (
    LawSpec("newtonian", NEWTONIAN,
            (Parameter("mu", description="viscosity", **_VISC),),
            "μ", "Newton"),
    LawSpec("power_law", POWER_LAW,
            (Parameter("K", "Pa s^n", 0.0, _BIG, "consistency"), _N, _GDOT_MIN),
            "K max(γ̇, γ̇_min)^(n−1)", "Ostwald (1925); de Waele (1923)"),
    LawSpec("cross", CROSS,
            (Parameter("mu_0", description="zero-rate viscosity", **_VISC),
             Parameter("mu_inf", description="infinite-rate viscosity", **_VISC),
             Parameter("lam", "s", 0.0, _BIG, "time constant"),
             Parameter("m", "1", 0.05, 1.0, "Cross exponent", log=False)),
            "μ_inf + (μ_0 − μ_inf)/(1 + (λγ̇)^m)", "Cross, J. Colloid Sci. 20, 417 (1965)"),
    LawSpec("carreau_yasuda", CARREAU_YASUDA,
            (Parameter("mu_0", description="zero-rate viscosity", **_VISC),
             Parameter("mu_inf", description="infinite-rate viscosity", **_VISC),
             Parameter("lam", "s", 0.0, _BIG, "time constant"),
             Parameter("a", "1", 0.1, 10.0, "transition sharpness", log=False),
             Parameter("n", "1", 0.0, 2.0, "flow index", log=False)),
            "μ_inf + (μ_0 − μ_inf)[1 + (λγ̇)^a]^((n−1)/a)",
            "Yasuda, Armstrong & Cohen, Rheol. Acta 20, 163 (1981)"),
    LawSpec("papanastasiou", PAPANASTASIOU,
            (Parameter("mu_pl", description="plastic viscosity", **_VISC),
             Parameter("mu_0", description="excess zero-rate viscosity (τ_y = μ_0/M)", **_VISC),
             Parameter("M", "s", 0.0, _BIG, "regularisation time")),
            "μ_pl + μ_0 (1 − e^(−Mγ̇))/(Mγ̇)",
            "Papanastasiou, J. Rheol. 31, 385 (1987); Martys et al. (2010) Eq. 28",
            has_yield_stress=True),
    LawSpec("herschel_bulkley", HERSCHEL_BULKLEY,
            (Parameter("tau_y", "Pa", 0.0, _BIG, "yield stress"),
             Parameter("K", "Pa s^n", 0.0, _BIG, "consistency"), _N,
             Parameter("M", "s", 0.0, _BIG, "regularisation time"), _GDOT_MIN),
            "(τ_y (1 − e^(−Mγ̇)) + K γ̇^n)/γ̇",
            "Herschel & Bulkley, Kolloid-Z. 39, 291 (1926); Papanastasiou (1987)",
            has_yield_stress=True),
    LawSpec("three_component", THREE_COMPONENT,
            (Parameter("tau_y", "Pa", 0.0, _BIG, "yield stress"),
             Parameter("gdot_c", "1/s", 0.0, _BIG, "crossover rate"),
             Parameter("eta_bg", description="background viscosity", **_VISC),
             Parameter("M", "s", 0.0, _BIG, "regularisation time")),
            "(τ_y (1 − e^(−Mγ̇))(1 + (γ̇/γ̇_c)^½) + η_bg γ̇)/γ̇",
            "Caggioni, Trappe & Spicer, J. Rheol. 64, 413 (2020)",
            has_yield_stress=True),
)})


@dataclass(frozen=True)
class ConstitutiveLaw:
    """A law with bound parameter values; build it with :func:`make_law` or a named factory."""

    spec: LawSpec
    params: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self):
        names = self.spec.parameter_names
        unknown = sorted(set(self.params) - set(names))
        if unknown:
            raise ValueError(f"{self.spec.name}: unknown parameter(s) {', '.join(unknown)}; "
                             f"expected {', '.join(names)}")
        values = {}
        for p in self.spec.parameters:
            if p.name not in self.params:
                if p.default is None:
                    raise ValueError(f"{self.spec.name}: missing parameter {p.name} [{p.unit}]")
                values[p.name] = float(p.default)
                continue
            try:
                v = float(self.params[p.name])
            except (TypeError, ValueError):
                raise ValueError(f"{self.spec.name}: parameter {p.name} = {self.params[p.name]!r} "
                                 "is not a number") from None
            if not (p.lower <= v <= p.upper):
                raise ValueError(f"{self.spec.name}: {p.name} = {v:g} {p.unit} is outside "
                                 f"[{p.lower:g}, {p.upper:g}]")
            values[p.name] = v
        if self.spec.code in (PAPANASTASIOU, HERSCHEL_BULKLEY, THREE_COMPONENT) and values["M"] <= 0:
            raise ValueError(f"{self.spec.name}: M must be > 0 s")
        if self.spec.code == THREE_COMPONENT and values["gdot_c"] <= 0:
            raise ValueError("three_component: gdot_c must be > 0 1/s")
        object.__setattr__(self, "params", MappingProxyType(values))

    @property
    def name(self) -> str:
        return self.spec.name

    @property
    def code(self) -> int:
        return self.spec.code

    @property
    def packed(self) -> np.ndarray:
        """Parameters in declaration order, zero-padded to :data:`MAX_PARAMETERS` (float64)."""
        out = np.zeros(MAX_PARAMETERS)
        out[: len(self.spec.parameters)] = [self.params[p.name] for p in self.spec.parameters]
        return out

    def viscosity(self, shear_rate) -> np.ndarray:
        """Viscosity μ(γ̇) [Pa s] at each shear rate [1/s] (array-like, ≥ 0)."""
        rate = np.ascontiguousarray(np.atleast_1d(np.asarray(shear_rate, dtype=float)))
        out = viscosity_array(self.code, self.packed, rate.ravel(), np.empty(rate.size))
        out = out.reshape(rate.shape)
        return out if np.ndim(shear_rate) else out[0]

    def stress(self, shear_rate) -> np.ndarray:
        """Shear stress τ = μ(γ̇) γ̇ [Pa] at each shear rate [1/s]."""
        return self.viscosity(shear_rate) * np.asarray(shear_rate, dtype=float)

    @property
    def zero_rate_viscosity(self) -> float:
        """lim γ̇→0 μ [Pa s] (finite for every law thanks to regularisation and γ̇_min)."""
        return float(self.viscosity(0.0))

    @property
    def yield_stress(self) -> float:
        """Apparent yield stress [Pa]: τ_y, μ_0/M for Papanastasiou, 0 for laws without one."""
        if self.code == PAPANASTASIOU:
            return self.params["mu_0"] / self.params["M"]
        return self.params.get("tau_y", 0.0) if self.spec.has_yield_stress else 0.0

    @property
    def is_newtonian(self) -> bool:
        """True when μ does not depend on γ̇, so a scene can skip the shear-rate pass."""
        return self.code == NEWTONIAN or (self.code == POWER_LAW and self.params["n"] == 1.0)

    def to_dict(self) -> dict:
        return {"law": self.name, "params": dict(self.params)}


def make_law(name: str, params: Mapping[str, float]) -> ConstitutiveLaw:
    """Build a law by name; raises ``ValueError`` naming the law, parameter and problem."""
    try:
        spec = LAW_SPECS[name]
    except KeyError:
        raise ValueError(f"unknown law {name!r}; known laws: {', '.join(LAW_SPECS)}") from None
    return ConstitutiveLaw(spec, dict(params))


def newtonian(mu):
    """Newtonian fluid, viscosity ``mu`` [Pa s]."""
    return make_law("newtonian", dict(mu=mu))


def power_law(K, n, *, gdot_min=DEFAULT_GDOT_MIN):
    """Power-law fluid μ = K γ̇^(n−1): ``K`` [Pa s^n], ``n`` [1], floor ``gdot_min`` [1/s]."""
    return make_law("power_law", dict(K=K, n=n, gdot_min=gdot_min))


def cross(mu_0, mu_inf, lam, m):
    """Cross fluid: ``mu_0``, ``mu_inf`` [Pa s], ``lam`` [s], ``m`` [1]."""
    return make_law("cross", dict(mu_0=mu_0, mu_inf=mu_inf, lam=lam, m=m))


def carreau_yasuda(mu_0, mu_inf, lam, a, n):
    """Carreau–Yasuda fluid: ``mu_0``, ``mu_inf`` [Pa s], ``lam`` [s], ``a``, ``n`` [1]."""
    return make_law("carreau_yasuda", dict(mu_0=mu_0, mu_inf=mu_inf, lam=lam, a=a, n=n))


def papanastasiou(mu_pl, mu_0, M):
    """Regularised Bingham fluid: ``mu_pl``, ``mu_0`` [Pa s], ``M`` [s]; τ_y = μ_0/M."""
    return make_law("papanastasiou", dict(mu_pl=mu_pl, mu_0=mu_0, M=M))


def herschel_bulkley(tau_y, K, n, M, *, gdot_min=DEFAULT_GDOT_MIN):
    """Regularised Herschel–Bulkley fluid: ``tau_y`` [Pa], ``K`` [Pa s^n], ``n`` [1], ``M`` [s]."""
    return make_law("herschel_bulkley", dict(tau_y=tau_y, K=K, n=n, M=M, gdot_min=gdot_min))


def three_component(tau_y, gdot_c, eta_bg, M):
    """Three-component yield-stress fluid: ``tau_y`` [Pa], ``gdot_c`` [1/s], ``eta_bg`` [Pa s], ``M`` [s]."""
    return make_law("three_component", dict(tau_y=tau_y, gdot_c=gdot_c, eta_bg=eta_bg, M=M))
