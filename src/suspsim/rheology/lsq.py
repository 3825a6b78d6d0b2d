"""Least-squares machinery of :mod:`suspsim.rheology.fitting`: data checks, the transformed
parameter space, multi-start minimisation, standard errors and information criteria.

Residuals r_i = log10 μ_model(γ̇_i) − log10(τ_i/γ̇_i) [decades] (= log-stress residuals); the
model is evaluated by the compiled :func:`suspsim.rheology.laws.viscosity_array` on a packed
parameter vector, so no law object is built per evaluation.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from suspsim.errors import NumericalError
from suspsim.rheology.laws import LAW_SPECS, MAX_PARAMETERS, viscosity_array

logger = logging.getLogger(__name__)

#: Floor and ceiling of log-scaled parameters, relative to their data scale.
SCALE_SPAN = 1e6
#: Residual [decades] substituted where a trial parameter set gives a non-positive viscosity.
_PENALTY = 10.0
#: Singular values of J below this fraction of the largest mark unidentified directions.
SVD_RTOL = 1e-7
#: Evaluation budget per start and fitted parameter. Well-posed fits of real flow curves converge
#: in ≤ 90 evaluations (5 parameters); degenerate ones (e.g. Carreau–Yasuda on Newtonian data)
#: would otherwise crawl along a flat valley for thousands.
_MAX_NFEV_PER_PARAMETER = 50
#: Central-difference step of the Jacobian in transformed units (decades or linear units).
_JAC_STEP = 1e-5


@dataclass(frozen=True)
class FlowData:
    """Validated flow-curve data: shear rate [1/s], stress [Pa], log10 viscosity [log Pa s]."""

    rate: np.ndarray
    stress: np.ndarray
    log_mu: np.ndarray

    @property
    def n(self) -> int:
        return self.rate.size

    def scale(self, unit: str) -> tuple[float, float]:
        """(low, high) data scale of a parameter with ``unit``, for its fitting bounds."""
        rate_lo, rate_hi = float(self.rate.min()), float(self.rate.max())
        tau_lo, tau_hi = float(self.stress.min()), float(self.stress.max())
        if unit == "Pa":
            return tau_lo, tau_hi
        if unit == "Pa s":
            return 10.0 ** self.log_mu.min(), 10.0 ** self.log_mu.max()
        if unit == "Pa s^n":
            # K = τ/γ̇^n with 0 < n ≤ 2 spans τ/max(1, γ̇)² … τ/min(1, γ̇)².
            return tau_lo / max(1.0, rate_hi) ** 2, tau_hi / min(1.0, rate_lo) ** 2
        if unit == "s":
            return 1.0 / rate_hi, 1.0 / rate_lo
        if unit == "1/s":
            return rate_lo, rate_hi
        return 1.0, 1.0


def validate_data(shear_rate, shear_stress) -> FlowData:
    """Check and convert the data; ``ValueError`` if mismatched, non-finite or non-positive."""
    rate = np.ascontiguousarray(np.asarray(shear_rate, dtype=float))
    stress = np.ascontiguousarray(np.asarray(shear_stress, dtype=float))
    if rate.ndim != 1 or stress.ndim != 1:
        raise ValueError("shear rate and shear stress must be one-dimensional arrays")
    if rate.size != stress.size:
        raise ValueError(f"shear rate has {rate.size} points but shear stress has {stress.size}")
    for name, values, unit in (("shear rate", rate, "1/s"), ("shear stress", stress, "Pa")):
        bad = np.nonzero(~np.isfinite(values) | (values <= 0.0))[0]
        if bad.size:
            raise ValueError(f"{name} must be finite and > 0 {unit}; point {bad[0]} is "
                             f"{float(values[bad[0]]):g} ({bad.size} bad point(s))")
    return FlowData(rate, stress, np.log10(stress / rate))


@dataclass
class Problem:
    """One least-squares problem: a law, which parameters are free, and the fixed values."""

    law: str
    data: FlowData
    values: dict[str, float]
    free: tuple[str, ...]

    def __post_init__(self):
        spec = LAW_SPECS[self.law]
        names = spec.parameter_names
        self.index = np.array([names.index(f) for f in self.free], dtype=np.int64)
        params = {p.name: p for p in spec.parameters}
        self.is_log = np.array([params[f].log for f in self.free])
        limits = [bounds(params[f], self.data) for f in self.free]
        self.lower = np.array([b[0] for b in limits])
        self.upper = np.array([b[1] for b in limits])
        self.packed = np.zeros(MAX_PARAMETERS)
        self.packed[: len(names)] = [self.values[n] for n in names]
        self.out = np.empty(self.data.n)

    def to_x(self, values: dict[str, float]) -> np.ndarray:
        v = np.array([values[f] for f in self.free], dtype=float)
        x = np.where(self.is_log, np.log10(np.maximum(v, 1e-300)), v)
        return np.clip(x, self.lower, self.upper)

    def to_params(self, x: np.ndarray) -> np.ndarray:
        return np.where(self.is_log, 10.0 ** x, x)

    def residual(self, x: np.ndarray) -> np.ndarray:
        self.packed[self.index] = self.to_params(x)
        viscosity_array(LAW_SPECS[self.law].code, self.packed, self.data.rate, self.out)
        with np.errstate(all="ignore"):
            r = np.log10(self.out) - self.data.log_mu
        r[~np.isfinite(r)] = _PENALTY
        return r


def bounds(p, data: FlowData) -> tuple[float, float]:
    """Transformed-space bounds of parameter ``p`` (log10 for log parameters)."""
    if not p.log:
        return p.lower, p.upper
    lo, hi = data.scale(p.unit)
    lower = max(p.lower, lo / SCALE_SPAN)
    upper = min(p.upper, hi * SCALE_SPAN)
    return math.log10(lower), math.log10(max(upper, 10.0 * lower))


def starts(problem: Problem, x0: list[np.ndarray], n_starts: int, rng) -> list[np.ndarray]:
    """The given starts and ``n_starts`` jittered copies of the first one.

    Copies alternate between local (σ = 1 decade for log parameters, 15 % of the range for linear
    ones) and global (σ = 3 decades, 45 %), so a guess in the wrong basin — e.g. a yield stress
    orders of magnitude off — is still escaped.
    """
    span = problem.upper - problem.lower
    inner = (problem.lower + 1e-9 * span, problem.upper - 1e-9 * span)
    starts = [np.clip(x, *inner) for x in x0]
    for i in range(n_starts):
        wide = 3.0 if i % 2 else 1.0
        sigma = np.where(problem.is_log, wide, 0.15 * wide * span)
        starts.append(np.clip(x0[0] + sigma * rng.standard_normal(x0[0].size), *inner))
    return starts


def minimise(problem: Problem, guesses: list[dict], n_starts: int, seed: int):
    """Best least-squares optimum over the multi-start set; NumericalError if every start fails."""
    rng = np.random.default_rng([seed, LAW_SPECS[problem.law].code, len(problem.free)])
    best = None
    trials = starts(problem, [problem.to_x(g) for g in guesses], n_starts, rng)
    for x_start in trials:
        try:
            res = least_squares(problem.residual, x_start, bounds=(problem.lower, problem.upper),
                                x_scale="jac", method="trf",
                                max_nfev=_MAX_NFEV_PER_PARAMETER * (len(x_start) + 1))
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            logger.debug("%s: start %s failed: %s", problem.law, x_start, exc)
            continue
        finite = np.isfinite(res.cost) and np.all(np.isfinite(res.x))
        if finite and (best is None or res.cost < best.cost):
            best = res
    if best is None:
        raise NumericalError(f"fitting {problem.law} failed from every start ({len(trials)}); "
                             "check the data or fit a simpler law")
    return best.x


def stderr_x(problem: Problem, x: np.ndarray, rss: float) -> np.ndarray:
    """Standard errors in transformed space, sqrt(diag s² (JᵀJ)⁺) by SVD; inf if unidentified."""
    k, n = x.size, problem.data.n
    jac = np.empty((n, k))
    for j in range(k):
        step = np.zeros(k)
        step[j] = _JAC_STEP
        jac[:, j] = (problem.residual(x + step) - problem.residual(x - step)) / (2 * _JAC_STEP)
    s2 = rss / (n - k) if n > k else math.nan
    _, sing, vt = np.linalg.svd(jac, full_matrices=False)
    keep = sing > SVD_RTOL * sing[0] if sing[0] > 0 else np.zeros(k, dtype=bool)
    var = (vt[keep].T ** 2 / sing[keep] ** 2).sum(axis=1) * s2
    sx = np.sqrt(var)
    if not keep.all():
        sx[np.abs(vt[~keep]).max(axis=0) > 1e-3] = math.inf
    return sx


def information(rss: float, n: int, k: int) -> tuple[float, float, float]:
    """(AIC, AICc, BIC) of a Gaussian least-squares fit; RSS floored at N·10⁻²⁴ (exact data)."""
    ll = n * math.log(max(rss, n * 1e-24) / n)
    aic = ll + 2 * k
    aicc = aic + 2 * k * (k + 1) / (n - k - 1) if n - k - 1 > 0 else math.inf
    return aic, aicc, ll + k * math.log(n)
