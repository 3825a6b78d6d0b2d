"""Combining runs of several packing seeds: the mean and its error.

    η̄ = (1/n) Σ η_i,    s² = (1/n²) Σ s_i² + Var_seeds(η)/n    (Var = 0 for one seed),

η_i the run values, s_i their standard errors (block averages of each run), n the runs present
(NaN runs are skipped). The first term is the runs' own statistical error, the second the
scatter between packings. Units: those of the variable.
"""
from __future__ import annotations

import numpy as np
import xarray as xr


def seed_mean(summary: xr.Dataset, name: str) -> tuple[xr.DataArray, xr.DataArray]:
    """Mean of ``name`` over seeds and its error (module docstring); NaN runs are skipped."""
    values, errors = summary[name], summary[f"{name}_stderr"]
    n = values.notnull().sum("seed")
    mean = values.mean("seed")
    spread = values.var("seed", ddof=1).fillna(0.0) if summary.sizes["seed"] > 1 else 0.0 * mean
    error = np.sqrt((errors ** 2).sum("seed") / n ** 2 + spread / n)
    return mean.where(n > 0), error.where(n > 0)
