"""SPH fluid against exact flows (SPEC §6.1, §6.2): Couette viscosity, start-up, Poiseuille.

Slow; ``SUSPSIM_REDUCED=1`` (CI) runs smaller boxes. Rates and viscosities keep the particle
Reynolds number ρ γ̇ h²/μ(γ̇) = 0.1 (SPEC §7: the dimensionless law is what matters), the
Papanastasiou law keeps seed 000's μ_0/μ_pl = 99 and M = 100. Stresses are averaged over whole
strain units after one unit of transient (a sheared lattice oscillates with period one).

Number densities. 3D: 4.096 per h³ (a 16-cube lattice per 10 h). 2D Couette: 6.25 per h²
(measured Papanastasiou viscosity: 1.38–1.44 μ at n = 4, +0.9 % at 6.25, +0.4 % at 16, for
γ̇ = 0.001–0.1). 2D Poiseuille: 16 per h² (at 6.25 the Newtonian profile is 5.6 % off).
Poiseuille profiles are time averages over whole periods of the lattice: rows sliding past
each other make the flow rate oscillate with period about spacing/u_max, by ±5–18 % in 3D at
n = 4.096 (invisible in 2D at n = 16).
"""
import math
import os
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "unit" / "sph"))
from sph_helpers import couette_scene, measured_viscosity_ratio  # noqa: E402

from suspsim.reference.poiseuille import poiseuille_profile  # noqa: E402
from suspsim.rheology.laws import make_law  # noqa: E402
from suspsim.validation.flows import (DENSITY_2D_POISEUILLE, DENSITY_3D,  # noqa: E402
                                      bingham_channel_error, channel_error,
                                      newtonian_channel_error)
from suspsim.validation.startup import papanastasiou_startup, profile_error  # noqa: E402

pytestmark = pytest.mark.slow
REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
RE_PARTICLE = 0.1
DENSITY_2D = 6.25
#: CI's two cores.
THREADS = 2


def papanastasiou_params(rate, density=DENSITY_3D, M=100.0):
    """μ_pl for particle Reynolds number 0.1 at ``rate``; μ_0 = 99 μ_pl (seed 000)."""
    x = M * rate
    mu_pl = density * rate / (RE_PARTICLE * (1.0 + 99.0 * -math.expm1(-x) / x))
    return {"mu_pl": mu_pl, "mu_0": 99.0 * mu_pl, "M": M}


def couette_side(dim):
    return (5.0 if REDUCED else 7.5) if dim == 3 else (6.0 if REDUCED else 10.0)


@pytest.mark.parametrize("dim", [3, 2])
def test_newtonian_couette_viscosity(dim):
    density = DENSITY_3D if dim == 3 else DENSITY_2D
    side = couette_side(dim)
    rate = RE_PARTICLE / density
    ratio, sim = measured_viscosity_ratio(couette_scene(dim, side, density, rate=rate,
                                                        jitter=0.1))
    assert ratio == pytest.approx(1.0, abs=0.015)
    profile = sim.profiles(5)
    expected = rate * (profile["y"] - 0.5 * side)
    assert np.max(np.abs(profile["velocity_profile"] - expected)) < 0.03 * rate * side


@pytest.mark.parametrize("dim, rate", [(3, 0.001), (3, 0.01), (3, 0.1),
                                       (2, 0.001), (2, 0.01), (2, 0.1)])
def test_papanastasiou_couette_viscosity_over_three_decades(dim, rate):
    """Bn = μ_0/(M μ_pl γ̇) = 990, 99, 9.9: the viscosity spans 10.9 to 95 μ_pl. Measured in
    2D (n = 6.25): +0.9 % at every rate (side 10 h and 6 h)."""
    density = DENSITY_3D if dim == 3 else DENSITY_2D
    scene = couette_scene(dim, couette_side(dim), density, law="papanastasiou",
                          params=papanastasiou_params(rate, density), rate=rate, jitter=0.1)
    ratio, _ = measured_viscosity_ratio(scene)
    assert ratio == pytest.approx(1.0, abs=0.03)


def test_papanastasiou_startup_matches_the_1d_reference():
    """Seed 000 Fig. 1 (Bn = 0.1, from rest) against the 1D finite-volume start-up of the same
    fluid (``reference.couette_startup``), profiles at strains 0.05 … 3, one bin per lattice
    row, instantaneous (a transient cannot be time-averaged). Measured max |v_SPH − v_1D|/(γ̇L)
    over bins and strains, always at strain 0.05 where the thinned layers are ≈ 1 h thick:
    0.016, 0.018 at L = 7.5 h (seeds 1, 2), 0.021, 0.019, 0.016, 0.017 at L = 5 h (seeds 1–4);
    from strain 0.1 on ≤ 0.01 (the lattice's instantaneous ripple, gone in time averages)."""
    data = papanastasiou_startup(side=5.0 if REDUCED else 7.5, threads=THREADS)
    assert data.attrs["healthy"], data.attrs["health"]
    errors = profile_error(data)
    assert float(errors.max()) < 0.025, errors.values


@pytest.mark.parametrize("dim, density", [(3, DENSITY_3D), (2, DENSITY_2D_POISEUILLE)])
def test_newtonian_poiseuille_profile(dim, density):
    """Re = ρ u_max W/μ ≈ 0.1 (μ = 1.25 ρ at g = 0.01, W = 5). At Re ≈ 40 the disordered
    lattice loses 10 % of the flow; in 2D at n = 6.25 the error is 5.6 % (open)."""
    assert newtonian_channel_error(dim, density, threads=THREADS) < 0.03


def test_bingham_1_poiseuille_profile():
    """Papanastasiou (seed 000: μ_0/μ_pl = 99, M = 100) at Bn = 1 in split-force Poiseuille,
    W = 5 h, averaged over 0.2 t_visc after 0.6 t_visc."""
    error = bingham_channel_error(1.0, 3, 10.0, 0.8 * 5.12, 0.2 * 5.12)
    assert error < 0.03


def test_bingham_10_poiseuille_profile_3d():
    """Bn = 10 in 3D, where the yielded layers are thin: the profile converges with the channel
    width W in units of h. The SPH shear rate, a kernel average, runs too high within ~1 h of
    the yield surface (its kink is smoothed), so the plug edge is too soft and the plug too
    fast (flow rate +2.5–3 % at W = 30 h); in addition the flow rate oscillates by ±5 % as
    lattice rows pass. Measured L2/peak: 29 % at W = 5 h, 4.1 % at 10 h, 3.2 % at 20 h,
    2.7 % at 30 h (the full size: 45 τ from the Newtonian profile of equal flow rate, the last
    15 τ averaged; 560 s on one thread with the other core busy).

    Reduced (CI): the convergence itself — W = 5 h and 10 h, the error must fall by at least
    4× (measured 7×); the 3 % bound is checked at full size."""
    if REDUCED:
        coarse = bingham_channel_error(10.0, 3, 10.0, 0.8 * 5.12, 0.2 * 5.12)
        fine = bingham_channel_error(10.0, 3, 20.0, 12.0, 4.0, lateral=3.75,
                                        newtonian_start=True)
        assert fine < coarse / 4, (coarse, fine)
    else:
        error = bingham_channel_error(10.0, 3, 60.0, 45.0, 15.0, lateral=3.75,
                                         newtonian_start=True)
        assert error < 0.03


def test_bingham_1_poiseuille_2d():
    """2D version of Bn = 1 at n = 16 per h², W = 5 h: measured 1.3 % (box 8 h or 3.75 h
    across; 42 s or 20 s on one thread)."""
    error = bingham_channel_error(1.0, 2, 10.0, 0.8 * 5.12, 0.2 * 5.12,
                                     lateral=3.75 if REDUCED else 8.0)
    assert error < 0.03


@pytest.mark.skipif(REDUCED, reason="needs W = 15 h and 18 τ: 4 min on one thread")
def test_bingham_10_poiseuille_2d():
    """Bn = 10 resolved in 2D (n = 16 per h²): W = 15 h, so the yielded layer is 2.7 h.

    From rest the flow rate reaches its plateau at t ≈ 14 τ (measured: 0.989 of the
    reference at 14 τ, then 0.990–0.996 up to 30 τ); the profile is averaged over 14–18 τ.
    Measured 2.2 % (2.1–2.35 % for any window up to 30 τ); 4.1 % at W = 10 h, where the SPH
    rate at the force-reversal plane (a cusp of |γ̇|, smoothed over h) is too low, hence the
    viscosity too high and the yielded layer 13 % slow near the plane. 2D at n = 16 has no
    visible lattice oscillation, unlike 3D at n = 4.096."""
    error = bingham_channel_error(10.0, 2, 30.0, 18.0, 4.0, lateral=3.75)
    assert error < 0.03


#: Carreau (a = 2), n = 0.4, μ_inf = 0, λ = 100 τ; μ_0 is set by the Reynolds number.
CARREAU_YASUDA = {"mu_inf": 0.0, "lam": 100.0, "a": 2.0, "n": 0.4}
#: λγ̇ at the walls (0 on the centre line).
CARREAU_WALL_WEISSENBERG = 30.0
#: Channel Reynolds number ρ u_max W/μ_wall with the smallest (wall) viscosity.
RE_CHANNEL = 0.1


def test_carreau_yasuda_poiseuille_profile():
    """Shear-thinning n = 0.4: λγ̇ runs from 0 on the centre line through 1 (at 0.2 W/2 from
    it) to 30 at the walls, so μ falls 7.7× across each channel. W = 10 h, μ_0 such that
    Re = ρ u_max W/μ_wall = 0.1; 4 diffusion times ρ(W/2)²/μ_wall of transient, then the
    average over four lattice periods spacing/u_max (the flow rate swings by ±8 %).
    Measured 1.7, 1.8, 2.0 % (seeds 1–3), 30 s on one thread, so CI runs it at this size. At
    W = 5 h: 6 % (the force-reversal cusp of |γ̇|, smoothed over h, and ±18 % swings)."""
    height = 20.0
    density = DENSITY_3D
    half = height / 4
    unit = make_law("carreau_yasuda", {"mu_0": 1.0, **CARREAU_YASUDA})
    wall_rate = CARREAU_WALL_WEISSENBERG / CARREAU_YASUDA["lam"]
    # At fixed λγ̇_w the velocity does not depend on μ_0 (the force scales with it).
    force_per_mu0 = float(unit.stress(wall_rate)) / half
    u_max = poiseuille_profile(unit, force_per_mu0, 2 * half, half)
    mu_wall_per_mu0 = float(unit.viscosity(wall_rate))
    mu_0 = density * u_max * 2 * half / (RE_CHANNEL * mu_wall_per_mu0)
    t_diff = density * half ** 2 / (mu_wall_per_mu0 * mu_0)
    t_avg = 4 * density ** (-1 / 3) / u_max
    error = channel_error("carreau_yasuda", {"mu_0": mu_0, **CARREAU_YASUDA},
                             force_per_mu0 * mu_0 / density, 3, density, height,
                             4 * t_diff + t_avg, t_avg, lateral=3.75)
    assert error < 0.03
