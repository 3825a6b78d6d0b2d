"""Held-out validation of ``--tolerance`` (issue 7, deliverable 3): on cases the error model was
not fitted on, what ``suspsim run --tolerance`` runs (the verified picker's attempts,
suspsim.convergence.picker.verified_pick) meets the tolerance (error + 2 standard errors) and
costs, all attempts summed, at most 2× the cheapest configuration that meets it among every
distinct configuration the picker could have chosen for less than 1.5 × half that cost
(suspsim.convergence.holdout).

The fifth blind set, ``docs/figures/error_model/run_holdout_blind_5.sh``, fixed (commit
198ba18) before any run of its cases and run with the packaged model of 2026-12-03; CPU
seconds of one thread, log ``run_holdout_blind_5.log``. Four of six passed:

- couette_papanastasiou_bn6_2d, 5 % and 2 %: one attempt, q = 2.5, side 5 h, C = 0.1, bound
  1.11 % (model 1.64 %), the cheapest candidate: ratio 1;
- poiseuille_newtonian_re1_2d, 5 %: one attempt, W = 2.5 h, 3.89 % (model 4.36 %), the
  cheapest candidate; 2 %: one attempt, W = 4.375 h, 1.08 % (model 1.30 %), 0.199 s, nothing
  cheaper meets 2 % (W = 3.125 h: 2.26 %): ratio 1;
- poiseuille_bingham8_3d, 10 %: three attempts (W = 6.25 h at C = 0.4 and 0.3: 11.7 and
  12.6 %; W = 7.5 h at C = 0.2: 6.50 %), 19.9 s against 5.73 s for W = 7.5 h, C = 0.4 (8.14 %):
  ratio 3.47; 7 %: two attempts (W = 6.25 h, C = 0.3: 12.6 %; W = 10 h, C = 0.2: 3.38 %),
  32.4 s against 11.3 s for W = 7.5 h, C = 0.2 (6.50 %): ratio 2.86. The model puts part of
  the error at W = 6.25 h in the plug's time-step term, but there it grows as the step shrinks
  (11.7, 12.6, 13.1, 13.5 % at C = 0.4, 0.3, 0.2, 0.1), so the first recalibration bought a
  smaller step instead of a wider channel.

Every answer met its tolerance. Slow; ``SUSPSIM_REDUCED=1`` (CI) compares with at most 3 runs
instead of 12. A failure of the cost criterion reports xfail with its reason while it fails; a
fix belongs in the model or the picker, not in this test.
"""
import os

import pytest

from suspsim.convergence.holdout import COST_RATIO, MAX_COMPARISONS, check

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
COMPARISONS = 3 if REDUCED else MAX_COMPARISONS

CASES = [
    ("couette_papanastasiou_bn6_2d", 0.05, None),
    ("couette_papanastasiou_bn6_2d", 0.02, None),
    ("poiseuille_bingham8_3d", 0.1, "3.5x the cheapest: W = 6.25 h at C = 0.4 then 0.3 "
                                    "missed, W = 7.5 h at C = 0.4 would have met"),
    ("poiseuille_bingham8_3d", 0.07, "2.9x the cheapest: W = 6.25 h missed, then W = 10 h "
                                     "where W = 7.5 h at C = 0.2 meets"),
    ("poiseuille_newtonian_re1_2d", 0.05, None),
    ("poiseuille_newtonian_re1_2d", 0.02, None),
]


@pytest.mark.slow
@pytest.mark.parametrize("case, tolerance, known_failure", CASES)
def test_tolerance_meets_error_at_near_least_cost(case, tolerance, known_failure):
    ds = check(case, tolerance, max_runs=COMPARISONS)
    print(case, tolerance, {k: ds.attrs[k] for k in (
        "attempts", "expected_error", "picked_error_bound", "paid_cpu_time",
        "cheapest_meeting_cpu_time", "cost_ratio")})
    assert ds.attrs["picked_error_bound"] <= tolerance
    if known_failure and ds.attrs["cost_ratio"] > COST_RATIO:
        pytest.xfail(known_failure)
    assert ds.attrs["cost_ratio"] <= COST_RATIO
