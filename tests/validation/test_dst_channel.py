"""DST channel sweep (seed 002 Fig. 7–8; issue 5): SPH mean velocity against the local ODE.

Slow; ``SUSPSIM_REDUCED=1`` (CI) runs a 14 × 12 lattice, full size the study's 14 × 20. Scaled
units (L_y = η_s = σ* = 1), φ = 0.54 with seed 002's φ_m, φ_0 — see
:mod:`suspsim.dst.channel_study`.
"""
import os

import numpy as np
import pytest

from suspsim.dst.channel_study import channel_sweep
from suspsim.dst.study import STRONG_NONLOCALITY

pytestmark = pytest.mark.slow
REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
LATTICE = (14, 12) if REDUCED else (14, 20)


def test_local_sweep_reproduces_the_flow_reduction():
    """Local model, F H/σ* = 1 and 6 (the two ends of SPEC §5.7's flow reduction): each mean
    velocity within 5 % of the ODE, and ū(6) < ū(1) as in the ODE (3.16e−3 < 6.16e−3)."""
    data = channel_sweep(0.54, [1.0, 6.0], lattice=LATTICE)
    u, ode = data["mean_velocity"].values, data["local_mean_velocity"].values
    print(f"\n[DST channel sweep {LATTICE}] u_SPH {u}, u_ODE {ode}, "
          f"errors {data['mean_velocity_error'].values}, L2/peak "
          f"{data['velocity_l2_error'].values}, wall {data.attrs['wall_time_s']:.1f} s")
    np.testing.assert_allclose(u, ode, rtol=0.05)
    assert ode[1] < ode[0]
    assert u[1] < 0.6 * u[0]


def test_relaxed_strong_nonlocality_balances_momentum_with_its_own_f():
    """α = 0.02, F H/σ* = 1: the relaxed run stops on its drift rule, and its velocity is the
    one momentum balance gives for the f it reached: u(y) = ∫_0^y F (H − y')/η(f(y')) dy'
    with f the SPH row averages (linearly interpolated) — within the issue's 5 % (mean): the
    same discretisation error as the local runs (at 14 × 12 the local model's ū at F H/σ* = 1
    is 3.8 % above its exact ODE, measured with this file's first test)."""
    data = channel_sweep(0.54, [1.0], alpha=STRONG_NONLOCALITY, lattice=LATTICE)
    point = data.isel(force_ratio=0)
    a = data.attrs
    drift, strain = float(point["mean_velocity_drift"]), float(point["microstructure_strain"])
    assert strain >= a["min_strain"] and abs(drift) < a["tolerance"]
    y = np.linspace(0.0, 0.5, 2001)
    rows = data["y"].values
    f = np.interp(y, rows, point["fraction"].values)
    phi_j = f * a["phi_m"] + (1 - f) * a["phi_0"]
    eta = a["eta_s"] * (1 - a["phi"] / phi_j) ** -2
    force = 2.0 * float(point["force_ratio"])
    rate = force * (0.5 - y) / eta
    u = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(y))])
    balanced = np.trapezoid(u, y) / 0.5
    measured = float(point["mean_velocity"])
    print(f"\n[DST channel alpha=0.02 {LATTICE}] u_SPH {measured:.5g}, balance with its own f "
          f"{balanced:.5g} ({measured / balanced - 1:+.2%}), local ODE "
          f"{float(point['local_mean_velocity']):.5g}, strain {strain:.2f}, drift {drift:.1e}")
    assert measured == pytest.approx(balanced, rel=0.05)
