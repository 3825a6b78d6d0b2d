"""Disordered fluid and dilute suspension against exact values (SPEC §6.1, §6.4).

Slow; ``SUSPSIM_REDUCED=1`` (CI) runs shorter. Newtonian matrix, μ = 1, n = 4.096 h⁻³,
γ̇ = 0.004 τ⁻¹ (particle Reynolds number ρ a² γ̇/μ ≈ 0.1 for a = 2.5 h). Stresses are averaged
over whole strain units after one unit of transient.

A lattice start hides the SPH viscosity's sensitivity to particle disorder, which a suspension
cannot avoid (the fluid is stirred around every body): the first test checks that a fully
disordered fluid with a softer equation of state (Wi = 10⁻²) and particle shifting (A = 30)
reads the viscosity within 1.5 %. The Einstein limit still fails with every setting tried —
the measured [η] is in the xfail reason.
"""
import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "unit" / "sph"))
from sph_helpers import measured_viscosity_ratio  # noqa: E402

from suspsim.scene import scene_from_dict  # noqa: E402

pytestmark = pytest.mark.slow
REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
RATE = 0.004


def scene(side, jitter=0.0, phi=0.0, wi=0.01, shifting=30.0):
    return scene_from_dict({
        "dimension": 3, "box": [side] * 3, "number_density": 4.096,
        "fluid": {"law": "newtonian", "params": {"mu": 1.0}},
        "flow": {"type": "couette", "shear_rate": RATE},
        "run": {"strain": 1.0, "start": "linear", "max_density_error": 0.2},
        "lattice": {"jitter": jitter, "relax": jitter > 0 or phi > 0},
        "inclusions": {"phi": phi, "radius": 2.5},
        "numerics": {"wi_target": wi, "shifting": shifting}})


def test_disordered_fluid_viscosity_with_shifting():
    """Lattice jittered by ±0.5 spacing and relaxed: σ_xy/(μγ̇) within 1.5 % of 1 (measured
    1.005; without shifting 1.22, and 1.64 at the lattice-tuned Wi = 10⁻³)."""
    ratio, _ = measured_viscosity_ratio(scene(6.25 if REDUCED else 7.5, jitter=0.5),
                                        units=3 if REDUCED else 6)
    assert ratio == pytest.approx(1.0, abs=0.015)


@pytest.mark.xfail(strict=True, reason=(
    "issue 4, open: one sphere a = 2.5 h at phi = 0.03 in a 12.5 h box gives [eta] = "
    "(eta_r - 1)/phi = 4.6 at Wi = 1e-3 without shifting (the disordered fluid near the sphere "
    "reads too viscous), 3.1 at Wi = 3e-3, 1.2 at Wi = 1e-2 with shifting A = 30 (the softer "
    "fluid lowers the sphere's stresslet from 0.074 to 0.065 and the fluid's share from 1.05 to "
    "0.96 mu gdot); Einstein needs 2.5 +- 0.4"))
def test_einstein_limit_of_one_sphere():
    """[η] = (η_r − 1)/φ = 2.5 ± 0.4 at φ = 0.03 (SPEC §6.4), η_r against the same fluid
    without the sphere at the same resolution (SPEC §3.1: a periodic array's O(φ^(5/3)) term is
    below 0.02 here)."""
    units = 3 if REDUCED else 8
    fluid, _ = measured_viscosity_ratio(scene(12.5), units=units)
    suspension, _ = measured_viscosity_ratio(scene(12.5, phi=0.03), units=units)
    intrinsic = (suspension / fluid - 1.0) / 0.03
    assert intrinsic == pytest.approx(2.5, abs=0.4)
