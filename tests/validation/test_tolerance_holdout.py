"""Held-out validation of the tolerance picker (issue 7, deliverable 3): on cases the error model
was not fitted on, the picked configuration meets the tolerance (error + 2 standard errors)
and costs at most 2× the cheapest configuration that meets it among the candidates the picker
judged cheaper (suspsim.convergence.holdout).

Slow; ``SUSPSIM_REDUCED=1`` (CI) compares with at most 3 runs per case instead of 6 (the
picker now refuses the Bingham channel, so no case runs minutes of CPU). Measured on 2026-12-03 with
``sh docs/figures/error_model/run_holdout.sh`` (CPU seconds of one thread; the model of
``error_model.json`` fitted on the six training cases, Bingham channels at Bn = 1, 3 and 5; the
previous pass, fitted without Bn = 5, is kept in ``docs/figures/error_model/second_pass/``):

- couette_papanastasiou_bn99_3d, 5 % and 2 %: picks q = 1.6, side 5 h, C = 0.1, Wi = 0.01,
  bound 0.58 % (expected 1.00 %), cost ratio 1;
- poiseuille_newtonian_2d, 10 %: picks q = 3, W = 3.75 h, bound 1.6 % (expected 4.0 %), ratio 1;
  5 %: picks q = 3, W = 5 h, bound 0.68 % (expected 3.1 %) at 0.46 s, but q = 3, W = 3.75 h met
  it at 0.19 s: ratio 2.4, a fail of the cost criterion (the model over-predicts the 2D channel,
  which it never saw, by 2.5-4.5x);
- poiseuille_bingham10_3d, 10 % and 5 %: the picker refuses (exit 1): the smallest expected
  error on the grid is 9.7 %, above 0.8 x 10 %. The yield term y Bn, refitted with the Bn = 5
  channel (floor 4.2-4.4 % at C down to 0.05), extrapolates to about 8 % at Bn = 10 on its
  own. At 10 % this is a refusal where q = 1.6, W = 7.5 h, C = 0.4 measured 8.9 % in the
  previous pass; at 5 % no configuration was expected to meet it, so none is picked.

The failures report xfail with their reason while they fail (a refusal of the picker is a
failure too); a fix belongs in the model (training data and drivers), not in this test.
"""
import os

import pytest

from suspsim.convergence.holdout import COST_RATIO, check
from suspsim.errors import InputError

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
MAX_RUNS = 3 if REDUCED else 6

CASES = [
    ("couette_papanastasiou_bn99_3d", 0.05, None),
    ("couette_papanastasiou_bn99_3d", 0.02, None),
    ("poiseuille_newtonian_2d", 0.1, None),
    ("poiseuille_newtonian_2d", 0.05, "2.4x the cheapest: the model over-predicts the 2D "
                                      "channel at W = 3.75 h (1.6 % measured)"),
    ("poiseuille_bingham10_3d", 0.1, "refused: smallest expected error 9.7 % (the yield term "
                                     "fitted up to Bn = 5 extrapolated to Bn = 10)"),
    ("poiseuille_bingham10_3d", 0.05, "refused: smallest expected error 9.7 %"),
]


@pytest.mark.slow
@pytest.mark.parametrize("case, tolerance, known_failure", CASES)
def test_tolerance_meets_error_at_near_least_cost(case, tolerance, known_failure):
    try:
        ds = check(case, tolerance, max_runs=MAX_RUNS)
    except InputError as err:
        if known_failure:
            pytest.xfail(f"{known_failure}: {err}")
        raise
    print(case, tolerance, {k: ds.attrs[k] for k in (
        "expected_error", "picked_error_bound", "picked_cpu_time", "cheapest_meeting_cpu_time",
        "cost_ratio")})
    if known_failure and not ds.attrs["passed"]:
        pytest.xfail(known_failure)
    assert ds.attrs["picked_error_bound"] <= tolerance
    assert ds.attrs["cost_ratio"] <= COST_RATIO
