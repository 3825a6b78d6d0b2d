"""Held-out validation of the tolerance picker (issue 7, deliverable 3): on cases the error model
was not fitted on, the picked configuration meets the tolerance (error + 2 standard errors)
and costs at most 2× the cheapest configuration that meets it among the candidates the picker
judged cheaper (suspsim.convergence.holdout).

The blind set of ``docs/figures/error_model/run_holdout_blind.sh``, fixed (commit d6d5936) before
the model of ``error_model.json`` was refitted on run_sweeps_4.sh and run once with it on
2026-12-03 (CPU seconds of one thread; log ``run_holdout_blind.log``):

- couette_papanastasiou_bn9.9_2d, 5 %: q = 2.5, side 5 h, C = 0.1, Wi = 0.01, bound 0.90 %
  (expected 3.0 %), ratio 1; 2 %: refused (smallest expected error 1.84 %, above 0.8 × 2 %);
- poiseuille_bingham7_3d, 10 %: W = 7.5 h, C = 0.3, bound 4.0 % (expected 7.7 %), 9.1 s against
  7.2 s for C = 0.4 (4.7 %), ratio 1.26; 7 %: W = 15 h, C = 0.3, bound 4.2 % (expected 5.0 %),
  72 s against 7.6 s for W = 7.5 h, C = 0.4 (4.7 %): ratio 9.5, a fail of the cost criterion
  (the model, inflated by 1.81 to bound every training point, over-predicts this channel about
  twofold);
- poiseuille_newtonian_re1_3d, 5 %: W = 3.75 h, C = 0.1, Wi = 0.01, bound 3.5 % (expected 3.1 %:
  above the bound, the model has no Reynolds driver), ratio 1; 2 %: W = 7.5 h, bound 1.4 %
  (expected 1.5 %), ratio 1.

Slow; ``SUSPSIM_REDUCED=1`` (CI) compares with at most 3 runs per case instead of 6 and skips a
pick the model expects to cost more than REDUCED_PICK_CPU (the Bn = 7 channel at 7 %: 55 s
expected, 72 s measured). The failures report xfail with their reason while they fail (a refusal
of the picker is a failure too); a fix belongs in the model (training data and drivers), not in
this test.
"""
import os

import pytest

from suspsim.convergence.cases import get_case
from suspsim.convergence.error_model import pick
from suspsim.convergence.holdout import COST_RATIO, check
from suspsim.errors import InputError

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
MAX_RUNS = 3 if REDUCED else 6
#: Largest expected CPU time of a pick run in the reduced size [s].
REDUCED_PICK_CPU = 20.0

CASES = [
    ("couette_papanastasiou_bn9.9_2d", 0.05, None),
    ("couette_papanastasiou_bn9.9_2d", 0.02, "refused: smallest expected error 1.84 % (needs "
                                             "<= 1.6 %)"),
    ("poiseuille_bingham7_3d", 0.1, None),
    ("poiseuille_bingham7_3d", 0.07, "9.5x the cheapest: W = 15 h picked (4.2 %) where "
                                     "W = 7.5 h, C = 0.4 measured 4.7 %"),
    ("poiseuille_newtonian_re1_3d", 0.05, None),
    ("poiseuille_newtonian_re1_3d", 0.02, None),
]


@pytest.mark.slow
@pytest.mark.parametrize("case, tolerance, known_failure", CASES)
def test_tolerance_meets_error_at_near_least_cost(case, tolerance, known_failure):
    try:
        expected_cost = pick(get_case(case), tolerance).expected_cost
    except InputError as err:
        if known_failure:
            pytest.xfail(f"{known_failure}: {err}")
        raise
    if REDUCED and expected_cost > REDUCED_PICK_CPU:
        pytest.skip(f"the pick is expected to take {expected_cost:.0f} s CPU (full size only)")
    ds = check(case, tolerance, max_runs=MAX_RUNS)
    print(case, tolerance, {k: ds.attrs[k] for k in (
        "expected_error", "picked_error_bound", "picked_cpu_time", "cheapest_meeting_cpu_time",
        "cost_ratio")})
    if known_failure and not ds.attrs["passed"]:
        pytest.xfail(known_failure)
    assert ds.attrs["picked_error_bound"] <= tolerance
    assert ds.attrs["cost_ratio"] <= COST_RATIO
