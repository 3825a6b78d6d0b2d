"""Least-squares fits of the constitutive laws (SPEC §1.1) to measured flow curves τ(γ̇).

Method
------
For a law with fitted parameters p (k of them) and N data (γ̇_i [1/s], τ_i [Pa]), minimise

    RSS = Σ_i r_i²,   r_i = log10 τ_model(γ̇_i; p) − log10 τ_i

(stress residuals in decades; they equal the log-viscosity residuals, since τ = μ γ̇) with
``scipy.optimize.least_squares`` (trust-region reflective, ``x_scale="jac"``) in a transformed
space x: x = log10 p for parameters with ``Parameter.log``, x = p otherwise. Bounds are the
``Parameter`` bounds; a log parameter whose lower bound is 0 gets a floor 10⁻⁶ × its data scale
(μ: lowest viscosity, τ_y: lowest stress, λ and M: 1/γ̇_max, ...) so that a zero yield stress or a
zero μ_inf is reachable in practice. The initial guess (:mod:`suspsim.rheology.guesses`) and
``n_starts`` jittered copies of it (seeded) are refined; the lowest cost wins. The power-law floor
γ̇_min (``gdot_min``, never fitted) is held at min(10⁻⁶ 1/s, lowest rate/100) so it never acts
on measured rates. Machinery: :mod:`suspsim.rheology.lsq`.

Uncertainty: cov_x = s² (JᵀJ)⁻¹ with s² = RSS/(N − k) and J the central-difference Jacobian at
the optimum, by SVD; directions with singular value < 10⁻⁷ σ_max are dropped, and a parameter
loading on a dropped direction gets an infinite standard error (unidentified). Delta method
back to parameters: σ_p = p ln(10) σ_x for log parameters (e.g. Bates & Watts 1988, ch. 2).

Information criteria (Burnham & Anderson 2002, ch. 2), with k the number of FITTED parameters:
AIC = N ln(RSS/N) + 2k, AICc = AIC + 2k(k + 1)/(N − k − 1), BIC = N ln(RSS/N) + k ln N.

Regularisation M (papanastasiou, herschel_bulkley, three_component): the law is fitted twice,
with 1/M = γ̇_min/100 fixed (γ̇_min: the lowest measured rate) and with M free, the free fit also
starting from the fixed optimum. M counts as identified — the data reach the low-rate
viscosity plateau — only if the free fit has (a) σ_M/M < 0.5, (b) M γ̇_min ≤ 0.5, i.e. the
lowest measured rate lies on the regularisation's Newtonian plateau (there the viscosity is
≥ 79 % of its zero-rate value, (1 − e^(−x))/x at x = 0.5), and (c) a criterion better by more than
:data:`PREFER_SIMPLER_WITHIN`; otherwise M stays fixed and the result's ``notes`` say so.

``law="auto"``: see :func:`suspsim.rheology.selection.select_law`.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field, replace

import numpy as np

from suspsim.rheology.guesses import M_FACTOR, initial_guess
from suspsim.rheology.laws import DEFAULT_GDOT_MIN, LAW_SPECS, ConstitutiveLaw, make_law
from suspsim.rheology.lsq import FlowData, Problem, information, minimise, stderr_x, validate_data

logger = logging.getLogger(__name__)

DEFAULT_CANDIDATES = ("newtonian", "power_law", "cross", "carreau_yasuda", "herschel_bulkley",
                      "three_component", "papanastasiou")
#: Selection criteria understood by :func:`fit_flow_curve`: "bic" (default; consistent, favours
#: parsimony), "aic" and "aicc" (AIC with the small-sample correction; use for N/k ≲ 40).
CRITERIA = ("bic", "aic", "aicc")
#: Criterion differences below this are "not worth mentioning" (Kass & Raftery 1995; Burnham &
#: Anderson 2002): the law with fewer fitted parameters is preferred.
PREFER_SIMPLER_WITHIN = 2.0
#: Largest relative standard error σ_M/M for which the regularisation counts as identified.
M_MAX_REL_STDERR = 0.5
#: Largest M γ̇_min for which the lowest measured rate counts as on the low-rate plateau.
M_PLATEAU_MAX = 0.5
#: Stress ratio beyond which points at one shear rate are flagged (:func:`repeated_rate_notes`)
#: [choice: repeated measurements at one rate differ by tens of per cent at most (thixotropy, edge
#: fracture); of the 55 shared and shipped files only ec_shear_viscosity_04-00 has a pair
#: beyond 2× — 2.7×, its last row copied from 03-00].
REPEAT_DISAGREEMENT = 2.0


@dataclass(frozen=True)
class FitResult:
    """A fitted law with its statistics; all values SI (Pa, Pa s, 1/s, s).

    ``params`` holds every parameter of the law (fitted and fixed); ``stderr`` the standard error
    of each (inf: unidentified, NaN: held fixed); ``rms_log_residual`` is sqrt(RSS/N) in decades
    of stress; ``aic``, ``bic``, ``aicc`` the information criteria (k = fitted parameters) and
    ``criterion`` the one used for choices; ``fixed`` the parameters held fixed (reasons in
    ``notes``); ``candidates`` the per-law summaries when the law was chosen automatically (law,
    k, aic, aicc, bic, rms_log_residual, params, fixed, eligible, objection, won).
    """

    law: str
    params: dict[str, float]
    stderr: dict[str, float]
    rms_log_residual: float
    n_points: int
    shear_rate_range: tuple[float, float]
    source: str
    aic: float
    bic: float
    fixed: dict[str, float]
    notes: tuple[str, ...]
    candidates: tuple[dict, ...] = ()
    aicc: float = math.nan
    criterion: str = "bic"
    rss: float = field(default=math.nan, repr=False)

    @property
    def k(self) -> int:
        """Number of fitted parameters."""
        return len(self.params) - len(self.fixed)

    def score(self, criterion: str | None = None) -> float:
        """Value of an information criterion ("bic", "aic" or "aicc"; default: the one used)."""
        return {"bic": self.bic, "aic": self.aic, "aicc": self.aicc}[criterion or self.criterion]

    def constitutive_law(self) -> ConstitutiveLaw:
        """The fitted law as a :class:`~suspsim.rheology.laws.ConstitutiveLaw`."""
        return make_law(self.law, self.params)

    def to_dict(self) -> dict:
        """JSON-ready summary: plain floats in SI units, non-finite values (NaN, inf) as None.

        A ``None`` standard error means unidentified, or held fixed if the parameter is listed
        under ``"fixed"``.
        """
        return {
            "law": self.law, "params": _clean(self.params), "stderr": _clean(self.stderr),
            "rms_log_residual": _clean(self.rms_log_residual), "n_points": int(self.n_points),
            "shear_rate_range": _clean(list(self.shear_rate_range)), "source": str(self.source),
            "aic": _clean(self.aic), "bic": _clean(self.bic), "aicc": _clean(self.aicc),
            "fixed": _clean(self.fixed), "notes": list(self.notes),
            "candidates": _clean(list(self.candidates)), "criterion": self.criterion,
            "residual_space": "log10 stress",
        }


def _clean(value):
    """Recursively turn numpy scalars into Python ones and NaN/inf into None (strict JSON)."""
    if isinstance(value, dict):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def _solve(law: str, data: FlowData, values: dict, free: tuple[str, ...], n_starts: int,
           seed: int, criterion: str, source: str, notes: list[str],
           extra: tuple[dict, ...] = ()) -> FitResult:
    """Fit the ``free`` parameters of ``law`` with the others held at ``values``.

    ``values`` is also the first start; ``extra`` are further starts (e.g. another fit's optimum).
    """
    problem = Problem(law, data, dict(values), free)
    x = minimise(problem, [values, *extra], n_starts, seed)
    r = problem.residual(x)
    rss = float(r @ r)
    sx = stderr_x(problem, x, rss)
    p = problem.to_params(x)
    params = dict(values)
    stderr = {name: math.nan for name in values}
    for j, name in enumerate(free):
        params[name] = float(p[j])
        stderr[name] = float(p[j] * math.log(10.0) * sx[j] if problem.is_log[j] else sx[j])
        span = problem.upper[j] - problem.lower[j]
        for side, bound in (("lower", problem.lower[j]), ("upper", problem.upper[j])):
            if abs(x[j] - bound) < 1e-6 * span:
                notes.append(f"{name} = {p[j]:.4g} at its {side} fitting bound")
    aic, aicc, bic = information(rss, data.n, len(free))
    return FitResult(law=law, params=params, stderr=stderr,
                     rms_log_residual=math.sqrt(rss / data.n), n_points=data.n,
                     shear_rate_range=(float(data.rate.min()), float(data.rate.max())),
                     source=source, aic=aic, bic=bic, aicc=aicc, criterion=criterion, rss=rss,
                     fixed={n: params[n] for n in values if n not in free}, notes=tuple(notes))


def fit_law(law: str, data: FlowData, *, criterion: str = "bic", source: str = "",
            n_starts: int = 8, seed: int = 0) -> FitResult:
    """Fit one law to validated data, deciding whether the regularisation M is identifiable."""
    spec = LAW_SPECS[law]
    fitted = tuple(p.name for p in spec.fitted_parameters)
    if data.n < len(fitted) + 1:
        raise ValueError(f"{law} has {len(fitted)} fitted parameters and needs at least "
                         f"{len(fitted) + 1} points; got {data.n}")
    guess = initial_guess(law, data.rate, data.stress)
    rate_min = float(data.rate.min())
    notes: list[str] = []
    if "gdot_min" in guess:
        # The power-law floor must never act on measured rates.
        guess["gdot_min"] = min(DEFAULT_GDOT_MIN, rate_min / 100.0)
    if "M" not in fitted:
        return _solve(law, data, guess, fitted, n_starts, seed, criterion, source, notes)

    m_fixed = M_FACTOR / rate_min
    held = dict(guess, M=m_fixed)
    if law == "papanastasiou":
        held["mu_0"] = guess["mu_0"] / guess["M"] * m_fixed  # keep τ_y = μ_0/M of the guess
    rest = tuple(f for f in fitted if f != "M")
    fixed = _solve(law, data, held, rest, n_starts, seed, criterion, source, [])
    # Starting the free fit also from the fixed optimum makes it at least as good as that one.
    free = _solve(law, data, guess, fitted, n_starts, seed, criterion, source, [],
                  extra=(fixed.params,))
    m, rel = free.params["M"], free.stderr["M"] / free.params["M"]
    gain = fixed.score() - free.score()
    if rel < M_MAX_REL_STDERR and m * rate_min <= M_PLATEAU_MAX and gain > PREFER_SIMPLER_WITHIN:
        why = (f"M fitted: the data reach the low-rate viscosity plateau (1/M = {1 / m:.3g} 1/s "
               f">= {1 / M_PLATEAU_MAX:g} x lowest rate {rate_min:.3g} 1/s, sigma_M/M = {rel:.2f}, "
               f"{criterion.upper()} better by {gain:.1f} than with M fixed)")
        chosen = free
    else:
        why = (f"M fixed: 1/M = lowest rate/{M_FACTOR:g} = {1 / m_fixed:.3g} 1/s since the data do "
               f"not reach the low-rate viscosity plateau (free fit: 1/M = {1 / m:.3g} 1/s, "
               f"sigma_M/M = {rel:.3g}, {criterion.upper()} gain {gain:.1f})")
        chosen = fixed
    logger.debug("%s: %s", law, why)
    return replace(chosen, notes=(why,) + chosen.notes)


def fit_flow_curve(shear_rate, shear_stress, law: str = "auto", *,
                   candidates: tuple[str, ...] = DEFAULT_CANDIDATES, criterion: str = "bic",
                   source: str = "", n_starts: int = 8, seed: int = 0) -> FitResult:
    """Fit a generalized-Newtonian law to a flow curve (shear rate [1/s], shear stress [Pa]).

    Parameters
    ----------
    shear_rate, shear_stress : array-like
        Equal-length, finite, positive data (any order; repeated sweeps may be concatenated).
    law : str
        A key of :data:`~suspsim.rheology.laws.LAW_SPECS`, or "auto" to fit every law in
        ``candidates`` and keep the best by ``criterion`` (rules in
        :func:`suspsim.rheology.selection.select_law`).
    criterion : {"bic", "aic", "aicc"}
        Information criterion used for model choice and for deciding whether M is identifiable.
    source : str
        Free text recorded in the result (file name, sample).
    n_starts, seed : int
        Number of jittered extra starts, and the seed of their generator.

    Raises
    ------
    ValueError
        Bad data, unknown law or criterion, or fewer points than fitted parameters + 1.
    suspsim.errors.NumericalError
        Every start of a requested law failed.
    """
    if criterion not in CRITERIA:
        raise ValueError(f"unknown criterion {criterion!r}; choose one of {', '.join(CRITERIA)}")
    data = validate_data(shear_rate, shear_stress)
    if law != "auto" and law not in LAW_SPECS:
        raise ValueError(f"unknown law {law!r}; known laws: auto, {', '.join(LAW_SPECS)}")
    suspicious = repeated_rate_notes(data)
    for note in suspicious:
        logger.warning("%s: %s", source or "flow curve", note)
    if law == "auto":
        from suspsim.rheology.selection import select_law
        result = select_law(data, candidates, criterion=criterion, source=source,
                            n_starts=n_starts, seed=seed)
    else:
        result = fit_law(law, data, criterion=criterion, source=source, n_starts=n_starts,
                         seed=seed)
    return replace(result, notes=result.notes + suspicious) if suspicious else result


def repeated_rate_notes(data: FlowData) -> tuple[str, ...]:
    """Notes on points measured at the same shear rate whose stresses differ by more than
    :data:`REPEAT_DISAGREEMENT` ×: up and down sweeps agree far better, so such a pair is more
    likely a row copied from another file or sample than a measurement (it is kept in the fit;
    the note lets the user decide)."""
    notes = []
    order = np.argsort(data.rate, kind="stable")
    rate, stress = data.rate[order], data.stress[order]
    start = 0
    for k in range(1, rate.size + 1):
        if k < rate.size and rate[k] == rate[start]:
            continue
        group = stress[start:k]
        if group.size > 1 and group.max() > REPEAT_DISAGREEMENT * group.min():
            notes.append(f"{group.size} points at shear rate {rate[start]:.4g} 1/s have stresses "
                         f"{group.min():.4g} to {group.max():.4g} Pa (more than "
                         f"{REPEAT_DISAGREEMENT:g}x apart): a row copied from another file?")
        start = k
    return tuple(notes)
