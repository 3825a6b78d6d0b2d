"""Data-driven starting values for fitting the laws of :mod:`suspsim.rheology.laws` to a flow curve.

:func:`initial_guess` reads the shape of a measured flow curve τ(γ̇) (shear rate γ̇ [1/s], shear
stress τ [Pa], viscosity μ = τ/γ̇ [Pa s]) and returns one value for every parameter of a law, so a
least-squares fit (:mod:`suspsim.rheology.fitting`) starts in the right basin:

* power law: log-log regression log τ = log K + n log γ̇;
* plateau laws (Cross, Carreau–Yasuda): μ_0 from the low-rate end of the viscosity, μ_inf a
  decade below its high-rate end, λ = 1/γ̇_½ where the viscosity has fallen halfway between them
  (exact for Cross: μ(1/λ) = (μ_0 + μ_inf)/2), and the thinning exponent from the high-rate
  slope d log μ/d log γ̇ → −m = n − 1;
* yield-stress laws: τ_y from the low-rate stress plateau, refined with K and n by the classic
  linearisation log(τ − τ_y) = log K + n log γ̇ (Herschel & Bulkley 1926) over a grid of τ_y;
  the regularisation M = μ(0)/τ_y when the data reach a low-rate viscosity plateau, otherwise
  M = 100/γ̇_min, i.e. 1/M two decades below the lowest measured rate (Papanastasiou 1987).

Guesses are starting points only; they need not be accurate, but they are always inside the
parameter bounds of :data:`~suspsim.rheology.laws.LAW_SPECS`.
"""
from __future__ import annotations

import logging

import numpy as np

from suspsim.rheology.laws import LAW_SPECS

logger = logging.getLogger(__name__)

#: 1/M is put this factor below the lowest measured rate when the data show no viscosity plateau.
M_FACTOR = 100.0


def _sorted_logs(shear_rate, stress):
    rate = np.asarray(shear_rate, dtype=float)
    tau = np.asarray(stress, dtype=float)
    order = np.argsort(rate, kind="stable")
    return np.log10(rate[order]), np.log10(tau[order])


def _local_slopes(x, y):
    """d y/d x at each point (x = log10 γ̇, y = log10 τ or log10 μ), smoothed over 5 neighbours.

    Central differences over a span of ±2 points damp the noise of single points; duplicated
    rates (up and down sweeps) are merged first by averaging.
    """
    ux, inverse = np.unique(np.round(x, 6), return_inverse=True)
    uy = np.bincount(inverse, weights=y) / np.bincount(inverse)
    if ux.size < 2:
        return ux, np.zeros_like(ux), uy
    span = min(2, ux.size - 1)
    lo = np.clip(np.arange(ux.size) - span, 0, ux.size - 1)
    hi = np.clip(np.arange(ux.size) + span, 0, ux.size - 1)
    return ux, (uy[hi] - uy[lo]) / (ux[hi] - ux[lo]), uy


def has_viscosity_plateau(shear_rate, stress) -> bool:
    """True when the lowest-rate points show a viscosity plateau (τ ∝ γ̇ there).

    Criterion: the local slope d log τ/d log γ̇ at the low-rate end exceeds 0.6 while somewhere
    above it the curve is flatter (slope below 0.4) — the signature of a regularised yield stress,
    whose low-rate Newtonian regime must be visible for M to be identifiable.
    """
    x, s, _ = _local_slopes(*_sorted_logs(shear_rate, stress))
    if x.size < 5:
        return False
    return bool(s[0] > 0.6 and np.min(s) < 0.4)


def _bingham_like(x, y):
    """(τ_y, K, n) of τ = τ_y + K γ̇^n from a grid over τ_y (τ_y = 0 included).

    For each trial τ_y the points with τ > 1.05 τ_y are regressed as log(τ − τ_y) on log γ̇; the
    trial whose implied curve has the smallest RMS log-stress residual wins. When the data reach
    a low-rate viscosity plateau only the rates from the flattest point upward (the plastic and
    flow regimes, where τ ≈ τ_y + K γ̇^n holds) are used.
    """
    ux, slopes, uy = _local_slopes(x, y)
    if has_viscosity_plateau(10.0 ** x, 10.0 ** y):
        flattest = int(np.argmin(slopes))
        keep_rates = x >= ux[flattest] - 1e-9
        x, y = x[keep_rates], y[keep_rates]
    rate, tau = 10.0 ** x, 10.0 ** y
    best = (np.inf, 0.0, 1.0, 1.0)
    for frac in (0.0, 0.1, 0.3, 0.5, 0.7, 0.8, 0.9, 0.95, 0.98):
        tau_y = frac * tau.min()
        keep = tau > 1.05 * tau_y
        if np.count_nonzero(keep) < 3:
            continue
        n, log_k = np.polyfit(x[keep], np.log10(tau[keep] - tau_y), 1)
        n = float(np.clip(n, 0.05, 1.5))
        model = tau_y + 10.0 ** log_k * rate ** n
        rms = np.sqrt(np.mean((np.log10(model) - y) ** 2))
        if rms < best[0]:
            best = (rms, tau_y, 10.0 ** log_k, n)
    return best[1], best[2], best[3]


def _half_rate(x, log_mu, mu_0, mu_inf):
    """Rate [1/s] where μ first falls below (μ_0 + μ_inf)/2 (log interpolation); γ̇_max if never."""
    target = np.log10(0.5 * (mu_0 + mu_inf))
    below = np.nonzero(log_mu <= target)[0]
    if below.size == 0:
        return 10.0 ** x[-1]
    i = below[0]
    if i == 0:
        return 10.0 ** x[0]
    t = (log_mu[i - 1] - target) / (log_mu[i - 1] - log_mu[i])
    return 10.0 ** (x[i - 1] + t * (x[i] - x[i - 1]))


def _high_rate_slope(x, log_mu):
    """Slope d log μ/d log γ̇ over the upper third of the rate range (≤ 0 for thinning)."""
    upper = x >= x[0] + 2.0 * (x[-1] - x[0]) / 3.0
    if np.count_nonzero(upper) < 2 or np.ptp(x[upper]) == 0:
        return 0.0
    return float(np.polyfit(x[upper], log_mu[upper], 1)[0])


def _clip_to_bounds(law_name, guess):
    """Keep every value strictly positive where required and inside the Parameter bounds."""
    out = {}
    for p in LAW_SPECS[law_name].parameters:
        v = float(guess[p.name]) if p.name in guess else float(p.default)
        lower = p.lower if not (p.log and p.lower <= 0.0) else 1e-300
        out[p.name] = float(np.clip(v, lower, p.upper))
    return out


def initial_guess(law_name: str, shear_rate, stress) -> dict[str, float]:
    """Starting values {parameter: value} (SI units) of law ``law_name`` for data τ(γ̇).

    Parameters
    ----------
    law_name : str
        A key of :data:`~suspsim.rheology.laws.LAW_SPECS`.
    shear_rate, stress : array-like
        Positive, finite shear rates [1/s] and shear stresses [Pa] of equal length (≥ 3 points).

    Returns
    -------
    dict
        A value for every parameter of the law, including the fixed extras (``gdot_min`` at its
        default), inside the parameter bounds.
    """
    if law_name not in LAW_SPECS:
        raise ValueError(f"unknown law {law_name!r}; known laws: {', '.join(LAW_SPECS)}")
    x, y = _sorted_logs(shear_rate, stress)
    log_mu = y - x
    mu = 10.0 ** log_mu
    rate_min, rate_max = 10.0 ** x[0], 10.0 ** x[-1]
    # Ends of the viscosity curve: averages of the 3 outermost points damp single-point noise.
    mu_lo_rate = float(np.mean(mu[:3]))
    mu_hi_rate = float(np.mean(mu[-3:]))
    mu_0 = max(mu_lo_rate, float(mu.max()))
    # The high-rate plateau is rarely reached: start μ_inf a decade below the lowest viscosity.
    mu_inf = 0.1 * min(mu_hi_rate, float(mu.min()))
    slope = _high_rate_slope(x, log_mu)

    if law_name == "newtonian":
        guess = {"mu": 10.0 ** np.mean(log_mu)}
    elif law_name == "power_law":
        n, log_k = np.polyfit(x, y, 1)
        guess = {"K": 10.0 ** log_k, "n": np.clip(n, 0.05, 1.5)}
    elif law_name in ("cross", "carreau_yasuda"):
        lam = 1.0 / _half_rate(x, log_mu, mu_0, mu_inf)
        guess = {"mu_0": mu_0, "mu_inf": mu_inf, "lam": lam}
        if law_name == "cross":
            guess["m"] = np.clip(-slope, 0.1, 1.0)
        else:
            guess.update(a=2.0, n=np.clip(1.0 + slope, 0.05, 1.0))
    else:
        tau_y, K, n = _bingham_like(x, y)
        tau_y = max(tau_y, 1e-3 * 10.0 ** y[0])
        plateau = has_viscosity_plateau(10.0 ** x, 10.0 ** y)
        # On the plateau μ(0) ≈ τ_y M; without one, 1/M goes two decades below the data.
        M = mu_lo_rate / tau_y if plateau else M_FACTOR / rate_min
        if law_name == "herschel_bulkley":
            guess = {"tau_y": tau_y, "K": K, "n": n, "M": M}
        elif law_name == "papanastasiou":
            mu_pl = max((10.0 ** y[-1] - tau_y) / rate_max, 1e-3 * mu_hi_rate)
            guess = {"mu_pl": mu_pl, "mu_0": tau_y * M, "M": M}
        else:
            # Three-component: the sqrt term equals τ_y at γ̇ = γ̇_c, i.e. where τ ≈ 2 τ_y.
            above = np.nonzero(y >= np.log10(2.0 * tau_y))[0]
            gdot_c = 10.0 ** x[above[0]] if above.size else rate_max
            excess = 10.0 ** y[-1] - tau_y * (1.0 + np.sqrt(rate_max / gdot_c))
            eta_bg = excess / rate_max if excess > 0 else 0.1 * mu_hi_rate
            guess = {"tau_y": tau_y, "gdot_c": gdot_c, "eta_bg": eta_bg, "M": M}
    logger.debug("initial guess %s: %s", law_name, guess)
    return _clip_to_bounds(law_name, guess)
