"""Held-out validation of the tolerance picker (issue 7, deliverable 3): on cases the error model
was not fitted on, the picked configuration meets the tolerance (error + 2 standard errors)
and costs at most 2× the cheapest configuration that meets it among the candidates the picker
judged cheaper (suspsim.convergence.holdout).

Slow; ``SUSPSIM_REDUCED=1`` (CI) compares with at most 3 runs per case instead of 6 and skips
the Bingham channel (about a minute of CPU). Measured on 2026-12-03 with
``python -m suspsim.convergence.holdout CASE TOL OUT.nc 6`` (docs/figures/error_model/):
couette_papanastasiou_bn99_3d meets 5 % and 2 % at the cheapest configuration (bound 0.58 %);
poiseuille_newtonian_2d at 5 % picks q = 2.5, which blew up in the 2D channel (the model had no
2D channel data: its 2D resolutions come from Couette, where q = 2.5 is accurate);
poiseuille_bingham10_3d at 5 % measured 7.8 % against 3.4 % expected (the flow-resolution term
fitted on Bn = 1 misses the Bn = 10 channel's error, which barely falls with W: 8.9 % at W = 7.5
h, 7.8 % at 10 h). Those two report xfail with their reason while they fail; a fix belongs in
the model (more training flows), not in this test.
"""
import os

import pytest

from suspsim.convergence.holdout import COST_RATIO, check

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
MAX_RUNS = 3 if REDUCED else 6

CASES = [
    ("couette_papanastasiou_bn99_3d", 0.05, None),
    ("couette_papanastasiou_bn99_3d", 0.02, None),
    ("poiseuille_newtonian_2d", 0.05, "picks q = 2.5, which blows up in the 2D channel"),
    pytest.param("poiseuille_bingham10_3d", 0.05,
                 "measured 7.8 % against 3.4 % expected at Bn = 10",
                 marks=pytest.mark.skipif(REDUCED, reason="about a minute of CPU")),
]


@pytest.mark.slow
@pytest.mark.parametrize("case, tolerance, known_failure", CASES)
def test_tolerance_meets_error_at_near_least_cost(case, tolerance, known_failure):
    ds = check(case, tolerance, max_runs=MAX_RUNS)
    print(case, tolerance, {k: ds.attrs[k] for k in (
        "expected_error", "picked_error_bound", "picked_cpu_time", "cheapest_meeting_cpu_time",
        "cost_ratio")})
    if known_failure and not ds.attrs["passed"]:
        pytest.xfail(known_failure)
    assert ds.attrs["picked_error_bound"] <= tolerance
    assert ds.attrs["cost_ratio"] <= COST_RATIO
