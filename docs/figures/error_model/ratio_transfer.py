"""Would one pilot run calibrate the error model to a case? How far the measured/model ratio of
a case's cheapest training run predicts the ratio of its other runs.

    python docs/figures/error_model/ratio_transfer.py

For every training case of the packaged model (its ``provenance.datasets``), the finished runs
inside the model's domain, the ratio r = measured bound / uninflated model at each, and the
transfer r_i / r_pilot of every run i from the cheapest one (by the cost model). A pilot-run
calibration would scale the model by r_pilot and still need a margin as large as the largest
transfer. Prints one line per case and the largest transfer; writes nothing.
"""
import collections
import json
import math
from importlib import resources

import numpy as np
import xarray as xr

from suspsim.convergence import error_fit, error_model


def main() -> None:
    model = error_model.load_model()
    text = resources.files("suspsim.convergence").joinpath(error_model.MODEL_FILE).read_text()
    files = json.loads(text)["provenance"]["datasets"]
    points = error_fit.training_points([xr.load_dataset(f) for f in files])
    by_case = collections.defaultdict(list)
    for d, bound, _, case in points:
        if math.isfinite(bound) and model.in_domain(d):
            by_case[case].append((model.expected_cost(d), bound / model.model_error(d)))
    largest = []
    for case, rows in sorted(by_case.items()):
        rows.sort()
        transfer = [ratio / rows[0][1] for _, ratio in rows[1:]]
        if transfer:
            largest.append(max(transfer))
            print(f"{case:34s} runs {len(rows):3d}  pilot ratio {rows[0][1]:.2f}  transfer "
                  f"{min(transfer):.2f}–{max(transfer):.2f} (median {np.median(transfer):.2f})")
    print(f"largest transfer {max(largest):.2f}")


if __name__ == "__main__":
    main()
