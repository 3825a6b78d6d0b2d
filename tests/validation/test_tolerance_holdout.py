"""Held-out validation of the tolerance picker (issue 7, deliverable 3): on cases the error model
was not fitted on, the picked configuration meets the tolerance (error + 2 standard errors)
and costs at most 2× the cheapest configuration that meets it among the candidates the picker
judged cheaper (suspsim.convergence.holdout).

The second blind set, ``docs/figures/error_model/run_holdout_blind_2.sh``, fixed (commit
e24cb56) before the model of ``error_model.json`` was refitted with per-class inflation on the
first blind set's outputs (which are training data now) and run once with it on 2026-12-03
(CPU seconds of one thread; log ``run_holdout_blind_2.log``):

- couette_papanastasiou_bn30_3d, 5 % and 2 %: q = 1.6, side 5 h, C = 0.2, Wi = 0.01, bound
  0.60 % (expected 1.00 %), ratio 1;
- poiseuille_newtonian_re0.5_2d, 5 %: q = 3, W = 3.75 h, C = 0.1, Wi = 0.01, bound 1.48 %
  (expected 2.05 %), 0.145 s against 0.051 s for q = 2.5, W = 2.5 h (3.67 %, the model
  4.38 % before its 1.26 inflation): ratio 2.81, a fail of the cost criterion; 2 %: q = 2.5,
  W = 7.5 h, C = 0.2 blew up at C_Δx = 0.67, inside the trained range of the Re = 0.1 channel
  (the model has no Reynolds driver);
- poiseuille_bingham2_3d, 5 %: W = 7.5 h, C = 0.3, bound 1.65 % (expected 3.99 %), 8.3 s against
  2.8 s for W = 5 h, C = 0.4 (4.34 %, above 0.8 × 5 % and expected 6.3 %): ratio 2.98; 3 %:
  refused (smallest expected error 2.67 %, above 0.8 × 3 %) where W = 7.5 h measured
  1.65-1.89 %.

Slow; ``SUSPSIM_REDUCED=1`` (CI) compares with at most 3 runs per case instead of 6 and skips a
pick the model expects to cost more than REDUCED_PICK_CPU (none in this set). The failures
report xfail with their reason while they fail (a refusal of the picker is a failure too); a
fix belongs in the model (training data and drivers), not in this test.
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
    ("couette_papanastasiou_bn30_3d", 0.05, None),
    ("couette_papanastasiou_bn30_3d", 0.02, None),
    ("poiseuille_newtonian_re0.5_2d", 0.05, "2.8x the cheapest: q = 3, W = 3.75 h picked (1.5 %) "
                                            "where q = 2.5, W = 2.5 h measured 3.7 %"),
    ("poiseuille_newtonian_re0.5_2d", 0.02, "the pick (q = 2.5, W = 7.5 h, C = 0.2) blew up at "
                                            "Re = 0.5"),
    ("poiseuille_bingham2_3d", 0.05, "3.0x the cheapest: W = 7.5 h picked (1.7 %) where W = 5 h, "
                                     "C = 0.4 measured 4.3 %"),
    ("poiseuille_bingham2_3d", 0.03, "refused: smallest expected error 2.67 % (needs <= 2.4 %)"),
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
