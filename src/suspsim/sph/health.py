"""Blow-up checks on per-particle fields, pure functions of arrays (SPEC §2.8).

A dense suspension squeezes single fluid particles in the narrowest gaps between bodies: their
density errors rise to 0.25–0.37 and fall again as the gap opens, while the rest stay below
0.15. A blow-up instead drives hundreds of particles past the limit within a few steps. So the
density check lets a small fraction of outliers past the bulk limit, up to a ceiling.
"""
from __future__ import annotations

import math

import numpy as np


def density_verdict(errors: np.ndarray, limit: float, outlier_fraction: float,
                    outlier_ceiling: float) -> str:
    """Why the density errors stop a run, or "" when they do not.

    ``errors`` |ρ/ρ_eq − 1| per fluid particle [1]; ``limit`` the bulk limit
    (``run.max_density_error``) that all but ⌊``outlier_fraction`` × N⌋ particles keep;
    ``outlier_ceiling`` (``run.max_outlier_density_error``, ≥ ``limit``) the limit of every
    particle. The message names the setting that was passed.
    """
    if errors.size == 0:
        return ""
    largest = float(np.max(errors))
    if largest > outlier_ceiling:
        return (f"density error {largest:.3g} exceeds run.max_outlier_density_error "
                f"{outlier_ceiling:g}")
    allowed = math.floor(outlier_fraction * errors.size)
    beyond = int(np.count_nonzero(errors > limit))
    if beyond > allowed:
        more = ("" if allowed == 0 else
                f" on {beyond} particles, more than the {allowed} that "
                f"run.density_outlier_fraction lets pass")
        return f"density error {largest:.3g} exceeds run.max_density_error {limit:g}{more}"
    return ""
