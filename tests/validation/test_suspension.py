"""Disordered fluid and dilute suspension against exact values (SPEC §6.1, §6.4).

Slow; ``SUSPSIM_REDUCED=1`` (CI) runs shorter. Newtonian matrix, μ = 1 (or a power law with
μ(γ̇) = 1), n = 4.096 h⁻³, γ̇ = 0.004 τ⁻¹ (particle Reynolds number ρ a² γ̇/μ ≈ 0.1 for
a = 2.5 h). Stresses are averaged over whole strain units after one unit of transient.

A lattice start hides the SPH viscosity's sensitivity to particle disorder, which a suspension
cannot avoid (the fluid is stirred around every body). Two numerical choices make the stirred
fluid read its viscosity: particle shifting (``numerics.shifting``) keeps the particles evenly
spread, and the ``fluid_mean`` pressure reference keeps the mean pressure at zero, since on a
disordered configuration a uniform pressure exerts forces and an anisotropic stress. Scenes
with inclusions get both by default (A = 30 in a Newtonian matrix; A = 3 and the smoothed rate of
``terms.rate_smoothing`` in a non-Newtonian one; the schema documents the measurements).
"""
import functools
import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "unit" / "sph"))
from sph_helpers import measured_viscosity_ratio  # noqa: E402

from suspsim.rheology.laws import make_law  # noqa: E402
from suspsim.rheology.suspension import (BATCHELOR_HYDRODYNAMIC,  # noqa: E402
                                         chateau_ovarlez_trung_viscosity, published_envelope)
from suspsim.scene import scene_from_dict  # noqa: E402
from suspsim.scene_rules import (AUTO_SHIFTING_NON_NEWTONIAN,  # noqa: E402
                                 AUTO_SHIFTING_WITH_INCLUSIONS)
from suspsim.sph.simulation import Simulation  # noqa: E402
from suspsim.stages.bingham_suspension import matrix_law  # noqa: E402
from suspsim.validation.flows import couette_stress_ratios  # noqa: E402
from suspsim.validation.suspension import (relative_viscosity, sampled_run,  # noqa: E402
                                           suspension_scene)

pytestmark = pytest.mark.slow
REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
FULL_SIZE = pytest.mark.skipif(REDUCED, reason="the reduced run checks φ = 0.2 with one packing")
RATE = 0.004


def scene(side, jitter=0.0, phi=0.0, wi=0.001, shifting="auto", reference="auto", fluid=None,
          seed=1, spin_correction="auto"):
    return scene_from_dict({
        "dimension": 3, "box": [side] * 3, "number_density": 4.096,
        "fluid": fluid or {"law": "newtonian", "params": {"mu": 1.0}},
        "flow": {"type": "couette", "shear_rate": RATE},
        "run": {"strain": 1.0, "start": "linear", "max_density_error": 0.2},
        "lattice": {"jitter": jitter, "relax": jitter > 0 or phi > 0},
        "inclusions": {"phi": phi, "radius": 2.5, "seed": seed},
        "numerics": {"wi_target": wi, "shifting": shifting, "pressure_reference": reference,
                     "spin_correction": spin_correction}})


def test_disordered_fluid_viscosity_with_shifting():
    """Lattice jittered by ±0.5 spacing and relaxed, Wi = 10⁻², A = 30 with the nominal
    pressure reference: σ_xy/(μγ̇) within 1.5 % of 1 (measured 1.005; without shifting 1.22,
    and 1.64 at the lattice-tuned Wi = 10⁻³). The inclusions' defaults (Wi = 10⁻³, A = 30,
    fluid_mean) read 1.043 on this fully disordered fluid: a dense suspension's fluid share
    may be up to 4 % high."""
    ratio, _ = measured_viscosity_ratio(scene(6.25 if REDUCED else 7.5, jitter=0.5, wi=0.01,
                                              shifting=30.0, reference="nominal"),
                                        units=3 if REDUCED else 6)
    assert ratio == pytest.approx(1.0, abs=0.015)


EINSTEIN_DEFAULT_FAILS = pytest.mark.xfail(strict=True, reason=(
    "with the defaults (spin correction, A = 30) one sphere reads eta_r = 1.110 +- 0.003, "
    "[eta] = 3.51 (2026-12-06): its stresslet is 2.81 per unit phi, inside 2.5 to 2.5 (a_h/a)^3, "
    "but the disordered fluid's own pressure-pair stress adds +0.059 mu gdot (README, "
    "Suspensions; issue 4)"))
ONE_SPHERE_PHI = 0.03


@functools.cache
def _one_sphere(spin_correction):
    """(η_r, η_r^p, packing φ, shifting A) of one sphere at φ = 0.03 in a 12.5 h box:
    σ_xy/(μγ̇) and 1 + σ^p_xy/(μγ̇) from the bodies' share alone (``run._batchelor_split``),
    over strain 1 + 8 (1 + 3 at CI size); cached, two tests read each setting."""
    sim = Simulation(scene(12.5, phi=ONE_SPHERE_PHI, spin_correction=spin_correction),
                     threads=2)
    ratios = couette_stress_ratios(sim, ("shear_stress", "particle_stress"),
                                   units=3 if REDUCED else 8)
    return (ratios["shear_stress"].value, 1.0 + ratios["particle_stress"].value,
            sim.packing_phi, sim.scene.numerics.shifting)


def _intrinsic(relative, phi):
    """[η] = (η_r − 1 − 5.2 φ²)/φ (test_einstein_limit_of_one_sphere's docstring)."""
    return (relative - 1.0 - BATCHELOR_HYDRODYNAMIC * phi ** 2) / phi


@pytest.mark.xdist_group("one_sphere")
@pytest.mark.parametrize("spin_correction", [
    pytest.param("auto", marks=EINSTEIN_DEFAULT_FAILS, id="defaults"),
    pytest.param(False, id="uncorrected")])
def test_einstein_limit_of_one_sphere(spin_correction):
    """[η] = 2.5 ± 0.4 at φ = 0.03 (SPEC §6.4), η_r = σ_xy/(γ̇ μ) against the matrix law as
    ``suspsim run`` reports it, and the same fluid without the sphere within 1.5 % of μ. [η] is
    (η_r − 1 − 5.2 φ²)/φ: the dilute expansion to second order (Batchelor & Green 1972,
    hydrodynamic pairs; ``rheology.suspension.batchelor``) takes out the pair term, 0.16 of [η]
    at φ = 0.03, which (η_r − 1)/φ alone carries. (One sphere in a sheared periodic box meets
    only its images, so 5.2 is the size of that term, not its exact value.) The defaults fail it
    (the mark gives the numbers); the uncorrected form passes, from errors that cancel (README).

    Measured without the spin correction (strain 1–9, 2026-12-06, fluid–body pairs relative to
    the body's spin, ``terms.viscous.spin_free_velocity``): η_r = 1.080 ± 0.003, [η] = 2.51.
    Before it (2026-12-05): η_r = 1.0873 ± 0.0030, (η_r − 1)/φ = 2.91 ± 0.10 and [η] = 2.75.
    The rest of the excess over 2.5 is the hydrodynamic radius, a_h/a = 1.027
    (``make_squeeze.py``'s drag): 2.5 × 1.027³ = 2.71. Before the fluid_mean reference the
    fluid's share followed the mean pressure: (η_r − 1)/φ = 4.6 without shifting, 1.2 at
    A = 30 and Wi = 10⁻²."""
    fluid, _ = measured_viscosity_ratio(scene(12.5), units=3 if REDUCED else 8)
    suspension, _, phi, shifting = _one_sphere(spin_correction)
    assert shifting == AUTO_SHIFTING_WITH_INCLUSIONS
    assert fluid == pytest.approx(1.0, abs=0.015)
    intrinsic = _intrinsic(suspension, phi)
    print(f"\n[Einstein, spin correction {spin_correction}] eta_r {suspension:.4f}, "
          f"[eta] {intrinsic:.2f}")
    assert intrinsic == pytest.approx(2.5, abs=0.4)


@pytest.mark.xdist_group("one_sphere")
def test_einstein_limit_from_the_particle_stress():
    """With the defaults, one sphere's own share of the stress gives Einstein's [η] = 2.5 ± 0.4:
    η_r^p = 1 + σ^p_xy/(μγ̇), the sphere's stresslet (SPEC §3.5's move of its particles' forces
    to the centre) with the fluid's share taken at its law, Batchelor's (1970) bulk stress for
    a Newtonian matrix, where the fluid's share around rigid bodies is exactly 2μE. This checks
    the body–fluid coupling apart from the disordered fluid's own error, which the total
    η_r of the test above carries and ``suspsim run`` reports as ``fluid_stress_error``. That
    error may not exceed the fully disordered fluid's, 4.5 % of μγ̇ (σ_xy/(μγ̇) = 1.043 with
    these numerics, the docstring of ``test_disordered_fluid_viscosity_with_shifting``).
    Measured (2026-12-06, full size): η_r^p = 1.0861, [η] = 2.71, fluid error +0.0231; the
    stress split (``make_stress_split.py``) reads the stresslet at 2.81 per unit φ, against
    2.5 × (a_h/a)³ = 2.94 with the squeeze's a_h/a = 1.056."""
    total, particle, phi, _ = _one_sphere("auto")
    intrinsic = _intrinsic(particle, phi)
    print(f"\n[Einstein from the particle stress] eta_r^p {particle:.4f}, [eta] {intrinsic:.2f}; "
          f"fluid stress error {total - particle:+.4f}")
    assert intrinsic == pytest.approx(2.5, abs=0.4)
    assert abs(total - particle) < 0.045


TANGENTIAL_A100 = {"numerics.shifting": 100.0, "numerics.shifting_at_bodies": "tangential"}


def test_strong_tangential_shifting_gives_einstein_from_the_total_stress():
    """With ``numerics.shifting_at_bodies: tangential`` and A = 100 (``terms.shifting``), one
    sphere a = 2.5 h at φ = 0.03 (12.5 h box, strain 1 + 8; 1 + 3 at CI size) reads Einstein's
    [η] = 2.5 ± 0.4 from its total stress, η_r = σ_xy/(μγ̇) as ``suspsim run`` reports it, and
    the disordered fluid around it is no further from its law than the band's half-width
    (|η_r − η_r^p| < 0.4 φ): shifting relaxes the elastic stress of the fluid's structure (the
    fluid alone reads 0.993 μγ̇ at A = 100, 1.042 at 30). Measured (2026-12-06): η_r =
    1.0751, η_r^p = 1.0760, [η] = 2.35 (CI size 1.0748–1.0751, [η] 2.34–2.35;
    ``make_shape_seeds.py --shapes sphere --box 12.5 --phi 0.03 --strain 1 8 --set
    numerics.shifting=100 --set numerics.shifting_at_bodies='"tangential"'``: 1.075, [η] =
    2.34). With the defaults (A = 30, full) the same sphere reads [η] = 3.51
    (``test_einstein_limit_of_one_sphere``). The sphere's spin is not checked here: over these
    runs it read 0.976 (strain 1 + 8), 0.999 and 0.928 × γ̇/2 (1 + 3), too scattered for a
    5 % check at this size."""
    units = 3 if REDUCED else 8
    sc = suspension_scene(phi=ONE_SPHERE_PHI, radius=2.5, box=12.5, seed=1,
                          strain=1.0 + units, overrides=TANGENTIAL_A100)
    assert (sc.numerics.shifting, sc.numerics.shifting_at_bodies) == (100.0, "tangential")
    samples = [sim.sample() for sim in sampled_run(sc, transient=1.0, units=units)]
    relative = sum(s["shear_stress"] for s in samples) / (RATE * len(samples))
    relative_p = 1.0 + sum(s["particle_stress"] for s in samples) / (RATE * len(samples))
    intrinsic = _intrinsic(relative, ONE_SPHERE_PHI)
    print(f"\n[A = 100, tangential] eta_r {relative:.4f}, eta_r^p {relative_p:.4f}, "
          f"[eta] {intrinsic:.2f}")
    assert intrinsic == pytest.approx(2.5, abs=0.4)
    assert abs(relative - relative_p) < 0.4 * ONE_SPHERE_PHI


@functools.cache
def _dense(phi, fluid=None, seed=1, shifting="auto"):
    """η_r of spheres a = 2.5 h at ``phi`` in a 15 h box with the defaults (packing ``seed``) in
    the Newtonian matrix or ``fluid`` (a hashable (law, params items) pair), with ``shifting``;
    cached, several tests read φ = 0.1 and 0.4."""
    law = None if fluid is None else {"law": fluid[0], "params": dict(fluid[1])}
    ratio, sim = measured_viscosity_ratio(scene(15.0, phi=phi, fluid=law, seed=seed,
                                                shifting=shifting),
                                          transient=1 if REDUCED else 2,
                                          units=3 if REDUCED else 8)
    assert sim.packing_phi == pytest.approx(phi)
    return ratio


# The two dense tests share _dense(0.4)'s cached run: one xdist worker.
@pytest.mark.xdist_group("dense")
def test_dense_suspension_runs_and_thickens_above_einstein():
    """φ = 0.2 and 0.4 run healthy with the defaults, each η_r above Einstein's 1 + 2.5 φ and
    rising with φ. Measured before the spin correction was a default (seeds 1 and 2, strain
    2–10): 1.64, 1.66 at 0.2; 3.69, 3.62 at 0.4."""
    low, high = _dense(0.2), _dense(0.4)
    assert 1.0 + 2.5 * 0.2 < low < high
    assert high > 1.0 + 2.5 * 0.4


def test_torque_free_sphere_turns_with_the_fluid():
    """A torque-free sphere in simple shear turns at Ω = −γ̇/2 (Stokes; its images at φ = 0.03
    change that by O(φ)): with ``numerics.spin_correction`` the mean Ω_z over strain 1 + 4
    (1 + 2 at CI size) is within 5 % of it, where the uncorrected form reads 1.26. The
    correction is on by default with inclusions. The 5 % is
    the strain units' scatter: measured (one sphere, a = 2.5 h, 12.5 h box, 2026-12-06, the
    correction's bulk viscosity removed) single units read 0.963, 1.066, 1.064 and 1.032 × γ̇/2
    (standard deviation 0.048), the mean of four 1.031, of the first two 1.014 (one unit alone
    missed 3 % in CI). Before the bulk viscosity went through the pressure two units read
    1.001, and 0.995 before fluid–body pairs took the mean spin; A = 100 reads 0.866
    (``docs/figures/make_sphere_spin.py``)."""
    units = 2.0 if REDUCED else 4.0
    sc = suspension_scene(phi=0.03, radius=2.5, box=12.5, seed=1, strain=1.0 + units)
    assert sc.numerics.spin_correction
    spins = [sim.bodies.angular_velocities()[0, 2] / (0.5 * RATE)
             for sim in sampled_run(sc, transient=1.0, units=units)]
    assert sum(spins) / len(spins) == pytest.approx(-1.0, abs=0.05)


@pytest.mark.xfail(strict=True, reason="frictionless dense spheres read below the fits "
                   "(5.61-8.78 at phi = 0.4): with the spin correction and its cutoff 0.185 h "
                   "4.45, 4.47 (16.875 h box, seeds 1/2, strain 1 + 4; 3.85, 4.31 in this "
                   "15 h box, strain 1 + 8; README); contact friction puts them inside "
                   "(the frictional test below; issue 4)")
@pytest.mark.xdist_group("dense")
def test_dense_suspension_inside_published_envelope():
    """REFERENCE_NUMBERS §2a: the min–max of the experimental fits, 5.61–8.78 at φ = 0.4."""
    low, high = published_envelope(0.4)
    assert low <= _dense(0.4) <= high


def _envelope_check(phi, box, seeds, overrides=None):
    """Assert the mean η_r of Newtonian spheres a = 2.5 h at ``phi`` in a ``box`` [h] over
    packing ``seeds`` (strain 1 + 4) lies inside the experimental fits' min–max."""
    readings = [relative_viscosity(phi=phi, radius=2.5, box=box, seed=seed, transient=1.0,
                                   units=4, overrides=overrides)
                for seed in seeds]
    mean = sum(r.relative_viscosity for r in readings) / len(readings)
    low, high = published_envelope(phi)
    print(f"\n[phi {phi}, {overrides or 'defaults'}] eta_r "
          + ", ".join(f"{r.relative_viscosity:.3f} ± {r.stderr:.3f}" for r in readings))
    assert low <= mean <= high


PHI_03_BELOW = pytest.mark.xfail(strict=True, reason=(
    "frictionless spheres at phi = 0.3 read 2.985, 2.795, 2.723, 2.496 (seeds 1-4, mean 2.750) "
    "against 2.90-3.93 with the spin correction and its cutoff 0.185 h (one-phase 0.328 h: mean "
    "2.842; 0.6 h, which counts the resolved squeeze twice: 3.45, 2.95); mu_c = 0.5 reads 3.50, "
    "3.15 (README; issue 4)"))


@pytest.mark.parametrize("phi, seeds", [
    pytest.param(0.1, (1, 2), marks=FULL_SIZE), (0.2, (1,) if REDUCED else (1, 2)),
    pytest.param(0.3, (1, 2, 3, 4), marks=[FULL_SIZE, PHI_03_BELOW])])
def test_spheres_inside_published_envelope(phi, seeds):
    """Frictionless Newtonian spheres a = 2.5 h with the defaults (spin correction and its
    squeeze cutoff 0.185 h) in a 15 h box (strain 1 + 4): the mean η_r of the packing ``seeds``
    inside the min–max of the experimental fits (REFERENCE_NUMBERS §2a), where the uncorrected
    form reads 5–25 % below it. φ = 0.3 reads below (the mark); its packings scatter by ±9 %,
    so it takes four.

    Measured (2026-12-07, evening, this test): φ = 0.1: 1.334 ± 0.008, 1.305 ± 0.008 (mean
    1.320) against 1.316–1.435 (Batchelor & Green 1.302); φ = 0.2: 1.937 ± 0.030, 1.862 ±
    0.026 (mean 1.900) against 1.851–2.232. With the one-phase cutoff 0.328 h: 1.334, 1.307;
    1.951, 1.894. With μ_c = 0.5 as well (0.185 h, 2026-12-06): 1.337, 1.306; 2.044, 2.015;
    3.56, 3.20 at φ = 0.3."""
    _envelope_check(phi, 15.0, seeds)


@pytest.mark.parametrize("phi", [0.4, pytest.param(0.5, marks=pytest.mark.skipif(
    REDUCED, reason="the reduced run checks φ = 0.4; φ = 0.5 costs as much again"))])
def test_frictional_dense_spheres_inside_published_envelope(phi):
    """With contact friction μ_c = 0.5 (``inclusions.lubrication.friction``, a [choice] beyond
    seed 000's frictionless model) and the other defaults: Newtonian spheres a = 2.5 h in the
    16.875 h box of the shape comparison, strain 1 + 4, the mean η_r of packing seeds 1 and 2
    inside the min–max of the experimental fits (REFERENCE_NUMBERS §2a), where the frictionless
    default reads below it. The CI size runs both seeds too: one dense packing alone scatters
    across the band's edge (seed 1 read 5.67 or 5.56 against 5.61 depending on round-off).

    Measured (2026-12-06, with the spin correction and its cutoff): φ = 0.4: 6.92 ± 0.87,
    7.61 ± 0.36 against 5.61–8.78; φ = 0.5: 35.6 ± 2.0, 38.7 ± 4.5 against 17.7–42.8. Without
    the correction: 5.77 ± 0.57, 8.16 ± 0.71 and 28.3 ± 1.5, 45.7 ± 4.9. With the one-phase
    cutoff 0.328 h (2026-12-07, ``make_shape_seeds.py``): 7.65 ± 1.13, 7.73 ± 0.57 and 33.9 ±
    5.3, 32.4 ± 3.5; with 0.185 h (2026-12-07, evening, this test): 6.96 ± 0.89, 7.49 ± 0.49
    and 33.3 ± 1.8, 34.1 ± 3.7."""
    _envelope_check(phi, 16.875, (1, 2), {"inclusions.lubrication.friction": 0.5})


@pytest.mark.parametrize("phi, seeds", [(0.1, (1,)), pytest.param(
    0.3, (1, 2), marks=pytest.mark.skipif(
        REDUCED, reason="at φ = 0.3 single strain units scatter by ±15 %: the reduced run's "
        "three units do not resolve 5 % (measured −5.3 % reduced, −4.6 % at full size)"))])
def test_power_law_matrix_follows_homogenisation(phi, seeds):
    """Spheres in a power-law matrix, n = 0.5, K such that μ(γ̇) = 1: η_r against Chateau,
    Ovarlez & Trung (REFERENCE_NUMBERS §4) with the Newtonian η_r of the same packing as g(φ),
    K(φ)/K = (1 − φ)^((1−n)/2) g^((1+n)/2), within 5 % for the mean of the packings' ratios.
    Rigid spheres in a thinning matrix thicken it less than in a Newtonian one, but never below
    the matrix (η_r ≥ 1). At φ = 0.3 one packing's ratio moves by more than 5 % between packings
    (−2.7 % and +5.3 % for seeds 1 and 2, below), so that check takes two. g is measured with
    the non-Newtonian matrix's numerics (shifting A = 3, hence the lubrication cutoff 0.44 h
    with the spin correction): a Newtonian matrix alone would take A = 30 and its cutoff
    0.185 h, which read g(0.1) = 1.339 against 1.417 at A = 3, and the estimate must compare
    one numerical model in two matrices.

    Measured (2026-12-07, evening, this test, the cutoff 0.44 h): φ = 0.1: g = 1.416, η_r =
    1.263 against 1.265 (−0.2 %); φ = 0.3, seed 1: g = 3.133, η_r = 2.105 against 2.154
    (−2.3 %); seed 2: g = 3.040, η_r = 2.179 against 2.106 (+3.5 %); mean +0.6 %. With the
    one-phase cutoff 0.58 h (strain 2–10, 2026-12-06 evening): φ = 0.1:
    g = 1.417, η_r = 1.262 against 1.265 (−0.2 %); φ = 0.3, seed 1: g = 3.203, η_r = 2.130
    against 2.190 (−2.7 %); seed 2: g = 3.068, η_r = 2.233 against 2.120 (+5.3 %); mean
    +1.3 %. With μ_c = 0.5 as well: 0.0 %, +1.7 %, +7.1 %. Without the correction (2026-12-06,
    with fluid–body pairs relative to the body's spin, g at A = 30):
    φ = 0.1: g = 1.226, η_r = 1.133 against 1.135; φ = 0.3, seed 1: g = 2.429, η_r = 1.683
    against 1.780 (−5.4 %); seed 2: g = 2.426, η_r = 1.752 against 1.778 (−1.5 %); mean −3.5 %.
    (Before that, seed 1: φ = 0.1 g = 1.247, η_r = 1.149 against 1.149; φ = 0.3 g = 2.490,
    η_r = 1.729 against 1.813, −4.6 %.) Before the non-Newtonian defaults (shifting A = 3,
    ``terms.rate_smoothing``) the matrix read η_r = 0.68 at φ = 0.1 (rate 0.01, Re 0.025): with
    A = 30 the stirred fluid's rate read 3.4 × γ̇."""
    n = 0.5
    power_law = ("power_law", (("K", RATE ** (1.0 - n)), ("n", n)))
    ratios = []
    for seed in seeds:
        g = _dense(phi, seed=seed, shifting=AUTO_SHIFTING_NON_NEWTONIAN)
        expected = (1.0 - phi) ** ((1.0 - n) / 2.0) * g ** ((1.0 + n) / 2.0)
        measured = _dense(phi, power_law, seed)
        print(f"\n[power law, phi {phi}, seed {seed}] g {g:.3f}, eta_r {measured:.3f}, "
              f"COT {expected:.3f}")
        assert 1.0 < measured < g
        ratios.append(measured / expected)
    assert sum(ratios) / len(ratios) == pytest.approx(1.0, rel=0.05)


FULL_ONLY = pytest.mark.skipif(REDUCED, reason="the reduced run checks the middle rate, where "
                               "the matrix's yield stress lowers eta_r most; the ends cost as much")


@pytest.mark.xdist_group("dense")
@pytest.mark.parametrize("x", [pytest.param(0.01, marks=FULL_ONLY), 1.0,
                               pytest.param(3.16, marks=FULL_ONLY),
                               pytest.param(100.0, marks=FULL_ONLY)])
def test_bingham_matrix_follows_homogenisation(x):
    """Seed 000's Fig. 3 (issue 4): spheres at φ = 0.4 in its Papanastasiou matrix
    (μ_0/μ_pl = 99) at x = Mγ̇, the law scaled so μ_m(γ̇) = 1 (``stages.bingham_suspension``):
    η/μ_m(γ̇) within 20 % of Chateau–Ovarlez–Trung, η_COT = g μ_m(γ̇ sqrt(g/(1 − φ))), with g
    the Newtonian η_r of the same packing, at both ends, where the matrix is nearly Newtonian,
    at the yield-dominated x = 1 and at the dip x = 3.16; and at x = 1 well below g (seed 000:
    "only about a factor of two to three higher" than the matrix). This packing is the
    ``bingham_suspension`` study's packing 1; the study measures all 11 rates on three packings.

    g is measured with the non-Newtonian matrix's numerics (the power-law test says why).
    Measured (2026-12-07 evening, the defaults with the spin correction and the cutoff 0.44 h,
    this test's packing): g = 4.751; η_r = 4.96, 2.72, 3.41 at x = 0.01, 1, 100 against COT
    4.71, 2.55, 3.23 (+5.4, +6.9, +5.7 %); x = 3.16 (2026-12-07 night): g = 4.753, η_r = 2.046
    against 1.860 (+10.0 %). With the one-phase cutoff 0.58 h (2026-12-06
    evening, strain 2–10): g = 4.856; η_r = 5.02, 2.76, 3.57 against COT 4.81, 2.58, 3.29
    (+4.3, +7.0, +8.6 %). With μ_c = 0.5 as well: g = 7.90; 7.50, 4.13, 7.07 against 7.80,
    3.43, 5.05 (−3.9, +21, +40 %), so friction is not the default. Without the correction
    (the ``bingham_suspension`` study's packing, strain 2–10, g = 3.70 ± 0.12):
    η_r = 3.80, 2.00, 2.76 at x = 0.01, 1, 100 against COT 3.68, 2.19, 2.60, and within
    −8.4 … +7.6 % at all 11 rates from 0.01 to 1000; this test's packing at CI size (strain 1–4)
    x = 1: 1.975 against 2.133. g with the non-Newtonian shifting A = 3 instead of the
    Newtonian default 30: 3.47 ± 0.16 against 3.54 ± 0.12 (strain 1–5)."""
    phi = 0.4
    name, params = matrix_law(x, 99.0, RATE)
    law = make_law(name, params)
    assert float(law.viscosity(RATE)) == pytest.approx(1.0, rel=1e-12)
    g = _dense(phi, shifting=AUTO_SHIFTING_NON_NEWTONIAN)
    measured = _dense(phi, (name, tuple(sorted(params.items()))))
    expected = float(chateau_ovarlez_trung_viscosity(law.viscosity, RATE, phi, g))
    print(f"\n[bingham matrix x={x:g}] g {g:.3f}, eta_r {measured:.3f}, COT {expected:.3f}")
    assert measured == pytest.approx(expected, rel=0.2)
    if x == 1.0:
        assert measured < 0.75 * g
