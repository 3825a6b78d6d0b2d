"""Held-out validation of ``--tolerance`` (issue 7, deliverable 3): on cases the error model was
not fitted on, what ``suspsim run --tolerance`` runs (the verified picker's attempts,
suspsim.convergence.picker.verified_pick) meets the tolerance (error + 2 standard errors) and
costs, all attempts summed, at most 2× the cheapest configuration that meets it among the
distinct configurations the picker could have chosen for less than 1.5 × half that cost
(suspsim.convergence.holdout).

The fifth and sixth blind sets, ``docs/figures/error_model/run_holdout_blind_5.sh`` and
``run_holdout_blind_6.sh``, each fixed (commits 198ba18 and 2861aa9) before any run of
its cases and run with the packaged model of 2026-12-03; CPU seconds of one thread, logs
``run_holdout_blind_5.log`` and ``run_holdout_blind_6.log``. Every answer met its tolerance;
11 of 14 checks passed:

- couette_papanastasiou_bn6_2d and _bn45_2d, 5 % and 2 %: one attempt, q = 2.5, side 5 h,
  C = 0.1, bound 1.11 % (model 1.64 %), the cheapest candidate: ratio 1;
- poiseuille_newtonian_re1_2d, 5 %: one attempt, W = 2.5 h, 3.89 %, the cheapest candidate;
  2 %: one attempt, W = 4.375 h, 1.08 %, nothing cheaper meets 2 % (W = 3.125 h: 2.26 %);
- poiseuille_bingham2.5_3d, 10 % and 7 %: one attempt, W = 3.75 h, 4.70 %, the cheapest;
- poiseuille_bingham9_3d, 10 %: one attempt, W = 6.25 h, C = 0.3, 5.90 %, ratio 1; 7 %: one
  attempt, C = 0.2, 5.65 %, 6.76 s against 3.71 s for C = 0.4 (6.55 %): ratio 1.82. The
  picked run takes twice the steps of the cheapest, so the ratio is 2 less the set-up's share
  and crosses the bound with the timing: a reduced CI run on 2026-12-06 (after retiming) read
  5.78 s against 2.87 s, 2.01, so the case carries its known failure;
- poiseuille_newtonian_re0.5_3d, 5 %: W = 2.5 h missed (6.14 %), W = 3.125 h met (4.61 %),
  ratio 1.64; 2 %: W = 3.75 h missed (3.19 %), W = 6.25 h met (1.61 %), 0.83 s; the blind run's
  comparison (capped at 12) found nothing cheaper, the full one (cap 40) found W = 5 h, C = 0.05
  at 1.997 % in 0.40 s: ratio 2.55 (with that re-run's 1.02 s paid) — a failure;
- poiseuille_bingham8_3d, 10 %: three attempts (W = 6.25 h at C = 0.4 and 0.3: 11.7 and
  12.6 %; W = 7.5 h at C = 0.2: 6.50 %), 19.9 s against 5.73 s for W = 7.5 h, C = 0.4 (8.14 %):
  ratio 3.47; 7 %: two attempts (W = 6.25 h, C = 0.3: 12.6 %; W = 10 h, C = 0.2: 3.38 %),
  32.4 s against 11.3 s for W = 7.5 h, C = 0.2 (6.50 %): ratio 2.86. The model puts part of
  the error at W = 6.25 h in the plug's time-step term, but there it grows as the step shrinks
  (11.7, 12.6, 13.1, 13.5 % at C = 0.4, 0.3, 0.2, 0.1), so the first recalibration bought a
  smaller step instead of a wider channel.

Slow; ``SUSPSIM_REDUCED=1`` (CI) compares with at most 3 runs instead of 40, which can miss the
cheaper configuration that fails a check, and skips the Bn = 8 channel (20-32 s of attempts).
A failure of the cost criterion reports xfail with its reason while it fails; a fix belongs in
the model or the picker, not in this test.
"""
import os

import pytest

from suspsim.convergence.holdout import COST_RATIO, MAX_COMPARISONS, check

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
COMPARISONS = 3 if REDUCED else MAX_COMPARISONS
#: Cases whose attempts took more than 15 s of CPU in the blind pass (full size only).
SLOW_CASES = {"poiseuille_bingham8_3d"}

CASES = [
    ("couette_papanastasiou_bn6_2d", 0.05, None),
    ("couette_papanastasiou_bn6_2d", 0.02, None),
    ("poiseuille_bingham8_3d", 0.1, "3.5x the cheapest: W = 6.25 h at C = 0.4 then 0.3 "
                                    "missed, W = 7.5 h at C = 0.4 would have met"),
    ("poiseuille_bingham8_3d", 0.07, "2.9x the cheapest: W = 6.25 h missed, then W = 10 h "
                                     "where W = 7.5 h at C = 0.2 meets"),
    ("poiseuille_newtonian_re1_2d", 0.05, None),
    ("poiseuille_newtonian_re1_2d", 0.02, None),
    ("couette_papanastasiou_bn45_2d", 0.05, None),
    ("couette_papanastasiou_bn45_2d", 0.02, None),
    ("poiseuille_bingham2.5_3d", 0.1, None),
    ("poiseuille_bingham2.5_3d", 0.07, None),
    ("poiseuille_bingham9_3d", 0.1, None),
    ("poiseuille_bingham9_3d", 0.07, "2.0x the cheapest: C = 0.2 (twice the steps) where "
                                     "C = 0.4 meets; 1.82 in the blind pass, 2.01 in CI"),
    ("poiseuille_newtonian_re0.5_3d", 0.05, None),
    ("poiseuille_newtonian_re0.5_3d", 0.02, "2.6x the cheapest: W = 3.75 h missed, then "
                                            "W = 6.25 h where W = 5 h at C = 0.05 meets"),
]


@pytest.mark.slow
@pytest.mark.parametrize("case, tolerance, known_failure", CASES)
def test_tolerance_meets_error_at_near_least_cost(case, tolerance, known_failure):
    if REDUCED and case in SLOW_CASES:
        pytest.skip("its attempts took 20-32 s of CPU in the blind pass (full size only)")
    ds = check(case, tolerance, max_runs=COMPARISONS)
    print(case, tolerance, {k: ds.attrs[k] for k in (
        "attempts", "expected_error", "picked_error_bound", "paid_cpu_time",
        "cheapest_meeting_cpu_time", "cost_ratio")})
    assert ds.attrs["picked_error_bound"] <= tolerance
    if known_failure and ds.attrs["cost_ratio"] > COST_RATIO:
        pytest.xfail(known_failure)
    assert ds.attrs["cost_ratio"] <= COST_RATIO
