"""Steady-state summaries of a run: the mean stress with its error, the Reynolds number.

Mean stress of a couette run: batch means over ≥ 8 blocks of whole strain units
(:func:`~suspsim.analysis.blocking.periodic_batch_means`), since a sheared lattice makes the
stress oscillate with period one strain (SPEC §2.3); a window under 8 strain units falls back
to Flyvbjerg–Petersen blocking with a warning.

Reynolds number Re = ρ U L/μ [choice of scales]: couette U = γ̇ L_y/2 (wall speed relative to
the centre plane), L = L_y/2, μ = μ(γ̇) of the law; poiseuille (split body force, SPEC §2.7):
each half of the box is a channel of width L_y/2, so L = L_y/4 (its half-width), U = the
largest |v_x| of the steady velocity profile, μ = μ(U/L).
"""
from __future__ import annotations

import logging

import numpy as np

from ..scene import Scene
from .blocking import MeanEstimate, blocking_mean, periodic_batch_means

log = logging.getLogger(__name__)

#: Strain period of the stress oscillation of a sheared lattice (SPEC §2.3).
LATTICE_PERIOD_STRAIN = 1.0


def steady_mean(strain: np.ndarray, stress: np.ndarray) -> MeanEstimate:
    """Mean and standard error of the steady stress [m h^(2−d) τ^-2] of a couette run.

    ``strain`` and ``stress`` are the samples of the steady window. Batch means over blocks of
    whole strain units (≥ 8 of them); a shorter window falls back to blocking analysis.
    """
    estimate = (periodic_batch_means(strain, stress, LATTICE_PERIOD_STRAIN)
                if strain.size >= 2 else None)
    if estimate is None:
        log.warning("the averaging window holds fewer than 8 strain units: the viscosity's "
                    "error comes from blocking analysis and the lattice's oscillation (period "
                    "one strain) may bias it; lengthen run.strain or shorten run.transient")
        estimate = blocking_mean(stress)
    return estimate


def reynolds_number(scene: Scene, velocity_profile: np.ndarray) -> float:
    """Re = ρ U L / μ [1] with the scales of the module docstring; ``velocity_profile`` [h/τ]."""
    height = scene.box[1]
    if scene.flow.type == "couette":
        speed, length = scene.flow.shear_rate * height / 2, height / 2
    else:
        speed, length = float(np.max(np.abs(velocity_profile))), height / 4
    viscosity = float(scene.fluid.law.viscosity(speed / length))
    return scene.density * speed * length / viscosity
