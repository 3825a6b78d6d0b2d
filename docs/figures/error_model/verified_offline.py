"""The inflated bound against the verified picker, offline on the training sweeps.

    python docs/figures/error_model/verified_offline.py [-v]

For every training case of the packaged model (its ``provenance.datasets``), the model is
refitted without that case (exponents within one grid step of the full fit's, as the
cross-validation does), and the case's measured runs inside the fold's domain are the
candidates. For each tolerance in TOLERANCES that some run meets (error + 2 standard errors):

- bound: the cheapest run (by the fold's expected cost) whose fold model × the packaged
  class inflation is ≤ ε, charged its measured CPU time;
- verified: :func:`suspsim.convergence.picker.next_attempt` in a loop as
  :func:`~suspsim.convergence.picker.verified_pick` runs it, each attempt charged its measured
  CPU time (a blow-up its expected cost), until a measured bound is ≤ ε.

A check passes when the answer meets ε at ≤ 2× the CPU time of the cheapest measured run that
meets it. The candidates are the measured runs only, a sparser grid than the picker's, the
same for both. Prints the counts (and with ``-v`` every check); writes nothing.
"""
import collections
import json
import math
import sys
from importlib import resources

import numpy as np
import xarray as xr

from suspsim.convergence import error_fit, error_model
from suspsim.convergence.error_model import inflation_class
from suspsim.convergence.picker import START_CALIBRATION, next_attempt

TOLERANCES = (0.01, 0.02, 0.03, 0.05, 0.07, 0.1)


def candidates(points, case, fold, model):
    """(settings key, drivers, fold model error, fold expected cost, measured bound, CPU [s],
    class inflation) of the case's runs inside the fold's domain, by expected cost."""
    rows = []
    for i, (d, bound, cpu, c) in enumerate(points):
        if c != case or not fold.in_domain(d) or inflation_class(d) not in fold.class_inflation:
            continue
        cost = fold.expected_cost(d)
        rows.append(({"run": i}, d, fold.model_error(d), cost,
                     bound if math.isfinite(bound) else math.inf,
                     cpu if math.isfinite(cpu) else cost, model.class_inflation[
                         inflation_class(d)]))
    return sorted(rows, key=lambda r: r[3])


def verified(rows, tolerance):
    """(met, CPU paid [s]) of the verified loop on measured ``rows``."""
    calibration, cap, tried, paid = START_CALIBRATION, math.inf, set(), 0.0
    by_key = {json.dumps(r[0]): r for r in rows}
    while True:
        row = next_attempt([r[:4] for r in rows], tolerance, calibration, tried, cap)
        if row is None:
            return False, paid
        key = json.dumps(row[0], sort_keys=True)
        tried.add(key)
        _, d, error, _, measured, cpu, _ = by_key[key]
        paid += cpu
        if measured <= tolerance:
            return True, paid
        if math.isfinite(measured):
            calibration = measured / error
        else:
            cap = min(cap, d.courant)


def main() -> None:
    model = error_model.load_model()
    text = resources.files("suspsim.convergence").joinpath(error_model.MODEL_FILE).read_text()
    files = json.loads(text)["provenance"]["datasets"]
    points = error_fit.training_points([xr.load_dataset(f) for f in files])
    grid = error_fit.neighbouring_exponents(model.exponents)
    results = collections.defaultdict(list)
    for case in sorted({c for *_, c in points}):
        fold = error_fit.fit_in_sample([p for p in points if p[3] != case], grid)
        rows = candidates(points, case, fold, model)
        for tol in TOLERANCES:
            meeting = [r[5] for r in rows if r[4] <= tol]
            if not meeting:
                continue
            best = min(meeting)
            bound = next((r for r in rows if r[2] * r[6] <= tol), None)
            results["bound"].append((case, tol, bound is not None and bound[4] <= tol,
                                     bound[5] / best if bound else math.nan))
            met, paid = verified(rows, tol)
            results["verified"].append((case, tol, met, paid / best))
    for name, checks in results.items():
        met = [c for c in checks if c[2]]
        passed = [c for c in met if c[3] <= 2.0]
        print(f"{name:9s} checks {len(checks)}, met {len(met)}, within 2x {len(passed)}; cost "
              f"ratio median {np.median([c[3] for c in met]):.2f}, largest "
              f"{max(c[3] for c in met):.2f}")
        if "-v" in sys.argv:
            for c in checks:
                print(f"    {c[0]:34s} {c[1]:5.2f} {'met' if c[2] else 'MISSED/REFUSED':15s} "
                      f"{c[3]:.2f}")


if __name__ == "__main__":
    main()
