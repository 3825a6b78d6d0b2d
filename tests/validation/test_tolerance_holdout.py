"""Held-out validation of the tolerance picker (issue 7, deliverable 3): on cases the error model
was not fitted on, the picked configuration meets the tolerance (error + 2 standard errors)
and costs at most 2× the cheapest configuration that meets it among the candidates the picker
judged cheaper (suspsim.convergence.holdout).

The fourth blind set, ``docs/figures/error_model/run_holdout_blind_4.sh``, fixed (commit
9b6e4b3) before any run of its cases and run once on 2026-12-05 with the packaged model of
2026-12-03 (not refitted; the picker's grid steps widths and sides by 1.25 h and adds 2D q 2.75
and 3.5); CPU seconds of one thread, log ``run_holdout_blind_4.log``. Two of six passed:

- couette_papanastasiou_bn20_2d, 5 %: q = 2.5, side 5 h, C = 0.1, bound 1.10 % (expected
  2.67 %), ratio 1; 2 %: q = 2.75, side 5 h, C = 0.05, bound 1.17 % (expected 1.84 %), 0.161 s
  against 0.084 s for q = 2.5, C = 0.1 (1.10 %): ratio 1.91;
- poiseuille_bingham6_3d, 10 %: W = 7.5 h, C = 0.3, bound 4.32 % (expected 9.56 %), 7.44 s
  against 2.21 s for W = 5 h, C = 0.4 (8.16 %): ratio 3.36; 7 %: W = 10 h, C = 0.2, bound
  4.71 % (expected 6.77 %), 24.6 s against 3.63 s for W = 6.25 h, C = 0.4 (6.92 %): ratio 6.77;
- poiseuille_newtonian_re0.25_3d, 5 % and 2 %: every run blew up (the picks and all cheaper
  candidates, Wi = 0.01 with C = 0.1-0.2): the picker's time-step range for 3D Newtonian channels
  was in C_Δx = δt μ_max/(ρΔx²) only, but these blow up from δt ν/h² ≈ 0.1 at q = 1.6 (C_Δx
  0.26) where q = 2.4 ran calm at C_Δx 0.29 (δt ν/h² 0.05); the same holds for the trained
  Re = 0.1 channel at Wi ≥ 0.003, C ≥ 0.1, which no training run had tried.

After the pass the domain also bounds δt μ_max/(ρh²) per class (same fit, same coefficients;
``error_model`` module docstring), so this case is no longer blind: re-run
(``docs/figures/error_model/fourth_set_step_bound/``), 5 %: W = 3.75 h, Wi = 0.003, C = 0.1,
bound 3.16 % (expected 4.43 %), 0.133 s against 0.093 s for W = 3.125 h (4.04 %): ratio 1.44;
2 %: W = 8.75 h, Wi = 0.001, bound 0.99 % (expected 1.90 %), 1.67 s against 0.262 s for
W = 5 h, Wi = 0.003 (1.84 %): ratio 6.38. Both run calm.

Slow; ``SUSPSIM_REDUCED=1`` (CI) compares with at most 3 runs per case instead of 6 and skips a
pick the model expects to cost more than REDUCED_PICK_CPU (the Bn = 6 channel at 7 %, 27 s). The
failures report xfail with their reason while they fail (a refusal of the picker, or a pick
that blows up, is a failure too); a fix belongs in the model (training data and drivers), not in
this test.
"""
import os

import pytest

from suspsim.convergence.cases import get_case
from suspsim.convergence.picker import pick
from suspsim.convergence.holdout import COST_RATIO, check
from suspsim.errors import InputError

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
MAX_RUNS = 3 if REDUCED else 6
#: Largest expected CPU time of a pick run in the reduced size [s].
REDUCED_PICK_CPU = 20.0

CASES = [
    ("couette_papanastasiou_bn20_2d", 0.05, None),
    ("couette_papanastasiou_bn20_2d", 0.02, "measured 1.91x the cheapest: runs of 0.08-0.16 s "
                                            "carry a few per cent of timing scatter"),
    ("poiseuille_bingham6_3d", 0.1, "3.4x the cheapest: W = 7.5 h picked (4.3 %) where W = 5 h "
                                    "measured 8.2 %"),
    ("poiseuille_bingham6_3d", 0.07, "6.8x the cheapest: W = 10 h picked (4.7 %) where "
                                     "W = 6.25 h measured 6.9 %"),
    ("poiseuille_newtonian_re0.25_3d", 0.05, None),
    ("poiseuille_newtonian_re0.25_3d", 0.02, "6.4x the cheapest: W = 8.75 h, Wi = 0.001 picked "
                                             "(1.0 %) where W = 5 h, Wi = 0.003 measured 1.8 %"),
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
