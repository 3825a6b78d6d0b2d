"""Automatic choice of a constitutive law for a flow curve (``fit_flow_curve(..., law="auto")``).

Every candidate law is fitted (:func:`suspsim.rheology.fitting.fit_law`) and scored by an
information criterion (BIC by default; AIC, AICc). The winner is chosen by three rules:

1. **Degenerate yield stress.** A yield-stress law (papanastasiou, herschel_bulkley,
   three_component) is eligible only if it describes a yield-stress fluid *on these data*:
   (a) τ_y ≥ 1 % of the lowest measured stress — below that the "yield stress" has no effect and
   the fluid is really a plateau or power-law fluid; and (b) the fitted curve shows a plastic
   regime followed by flow inside the measured window: at some measured rate γ̇_p the yield term
   τ_y(1 − e^(−Mγ̇)) carries at least half the stress while the local slope d log τ/d log γ̇ ≤ 0.5,
   and at a higher measured rate the slope is larger by at least 0.1. A regularised yield-stress
   law can imitate a zero-shear viscosity plateau followed by ever stronger thinning (1/M inside
   the data, the "plastic" stress saturation only at the highest rates); rule (b) rejects such
   fits, which belong to Cross or Carreau–Yasuda.
2. **Minimum criterion** among the eligible laws.
3. **Parsimony.** Of the eligible laws whose criterion is within
   :data:`~suspsim.rheology.fitting.PREFER_SIMPLER_WITHIN` (= 2) of the minimum — differences
   below 2 are "not worth more than a bare mention" (Kass & Raftery, JASA 90, 773 (1995)) — the
   one with the fewest fitted parameters wins; among equally many, a law without a yield stress
   (a yield stress is a physical claim the data must support decisively); then the lower criterion.

The result's ``notes`` state the choice and the margin; ``candidates`` lists every law tried.
"""
from __future__ import annotations

import logging
from dataclasses import replace

import numpy as np

from suspsim.errors import NumericalError
from suspsim.rheology.fitting import PREFER_SIMPLER_WITHIN, FitResult, FlowData, fit_law
from suspsim.rheology.laws import LAW_SPECS

logger = logging.getLogger(__name__)

#: Rule 1a: τ_y below this fraction of the lowest measured stress is degenerate.
MIN_YIELD_FRACTION = 0.01
#: Rule 1b: a plastic regime has the yield term carrying ≥ this share of the stress …
PLASTIC_SHARE = 0.5
#: … where the flow curve's local slope d log τ/d log γ̇ is at most this …
PLASTIC_SLOPE = 0.5
#: … and the slope must rise by at least this at a higher measured rate (the flow regime).
FLOW_SLOPE_RISE = 0.1


def yield_stress_objection(result: FitResult, data: FlowData) -> str | None:
    """Why a yield-stress fit is not a yield-stress fluid on ``data`` (rules 1a, 1b), or None."""
    law = result.constitutive_law()
    tau_y, tau_min = law.yield_stress, float(data.stress.min())
    if tau_y < MIN_YIELD_FRACTION * tau_min:
        return (f"tau_y = {tau_y:.3g} Pa << lowest measured stress {tau_min:.3g} Pa: "
                "a plateau or power-law fluid")
    rate = np.unique(data.rate)
    stress = law.stress(rate)
    share = tau_y * -np.expm1(-result.params["M"] * rate) / stress
    # Local slope of the fitted curve by a centred difference in log γ̇ (±0.1 %).
    eps = 1e-3
    slope = (np.log(law.stress(rate * (1 + eps))) - np.log(law.stress(rate * (1 - eps)))) / (
        np.log1p(eps) - np.log1p(-eps))
    # Highest slope reached at or above each rate: the flow regime must follow the plastic one.
    later_max = np.maximum.accumulate(slope[::-1])[::-1]
    plastic = (share >= PLASTIC_SHARE) & (slope <= PLASTIC_SLOPE)
    if not np.any(plastic & (later_max >= slope + FLOW_SLOPE_RISE)):
        return (f"no plastic regime followed by flow in the data (tau_y = {tau_y:.3g} Pa): the "
                "regularised yield stress only imitates a viscosity plateau and thinning")
    return None


def _summary(name: str, fit: FitResult, objection: str | None, won: bool) -> dict:
    return {"law": name, "k": fit.k, "aic": fit.aic, "aicc": fit.aicc, "bic": fit.bic,
            "rms_log_residual": fit.rms_log_residual, "params": dict(fit.params),
            "fixed": dict(fit.fixed), "eligible": objection is None,
            "objection": objection or "", "won": won}


def select_law(data: FlowData, candidates, *, criterion: str = "bic", source: str = "",
               n_starts: int = 8, seed: int = 0) -> FitResult:
    """Fit every law in ``candidates`` and return the chosen one (rules in the module docstring).

    Raises ``ValueError`` for unknown or no candidates, or when no candidate has enough points;
    ``NumericalError`` when every candidate's fit fails.
    """
    names = tuple(dict.fromkeys(candidates))
    unknown = [n for n in names if n not in LAW_SPECS]
    if not names or unknown:
        raise ValueError(f"candidates must be known laws ({', '.join(LAW_SPECS)}); got "
                         f"{list(candidates)!r}")
    fits: dict[str, FitResult] = {}
    skipped: list[str] = []
    for name in names:
        k = len(LAW_SPECS[name].fitted_parameters)
        if data.n < k + 1:
            skipped.append(f"{name} skipped: {k} parameters need at least {k + 1} points")
            continue
        try:
            fits[name] = fit_law(name, data, criterion=criterion, source=source,
                                 n_starts=n_starts, seed=seed)
        except NumericalError as exc:
            logger.warning("auto fit: %s", exc)
            skipped.append(f"{name} skipped: {exc}")
    if not fits:
        if all("points" in s for s in skipped):
            raise ValueError(f"too few points ({data.n}) for any candidate law: "
                             + "; ".join(skipped))
        raise NumericalError("every candidate law failed to fit: " + "; ".join(skipped))

    objections = {n: yield_stress_objection(f, data) for n, f in fits.items()
                  if LAW_SPECS[n].has_yield_stress}
    eligible = [n for n in fits if objections.get(n) is None] or list(fits)
    score = {n: fits[n].score(criterion) for n in fits}
    ranked = sorted(eligible, key=score.__getitem__)
    close = [n for n in ranked if score[n] - score[ranked[0]] < PREFER_SIMPLER_WITHIN]
    winner = min(close, key=lambda n: (fits[n].k, LAW_SPECS[n].has_yield_stress, score[n]))

    label, best = criterion.upper(), ranked[0]
    if winner == best:
        note = f"auto: {winner} chosen by {label} {score[winner]:.1f}"
        if len(ranked) > 1:
            note += (f"; next {ranked[1]} {score[ranked[1]]:.1f} "
                     f"(delta = {score[ranked[1]] - score[winner]:.1f})")
    else:
        why = ("fewer fitted parameters" if fits[winner].k < fits[best].k
               else "as many fitted parameters and no yield stress")
        note = (f"auto: {winner} chosen ({label} {score[winner]:.1f}) over the lowest, {best} "
                f"{score[best]:.1f}: delta = {score[winner] - score[best]:.1f} < "
                f"{PREFER_SIMPLER_WITHIN:g} and {winner} has {why}")
    notes = [note]
    notes += [f"{n} not eligible: {why}" for n, why in objections.items() if why]
    notes += skipped
    summaries = tuple(_summary(n, fits[n], objections.get(n), n == winner) for n in fits)
    logger.info("auto fit %s: %s", source, notes[0])
    chosen = fits[winner]
    return replace(chosen, notes=tuple(notes) + chosen.notes, candidates=summaries)
