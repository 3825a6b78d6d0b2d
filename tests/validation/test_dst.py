"""DST solver against exact and reference flows in 2D and 3D (SPEC §5, §6; issue 5).

Slow; ``SUSPSIM_REDUCED=1`` (CI) runs smaller lattices. Each case logs its wall time and
particle-steps per second (fluid + wall particles × steps / s; run with ``-s`` to see them).

Scaled units [choice, SPEC §7]: length L_y (the gap) = 1, viscosity η_s = 1, stress σ* = 1
(Newtonian cases: η = σ = 1), so a time unit is η_s/σ* (0.2 s for seed 002) and a rate σ*/η_s
(5 /s). Seed 002's α = 1e−5 m²/s (strong non-locality) becomes α L_y⁻² η_s/σ* = 0.02; its
ρ = 1000 kg/m³ would be ρ L_y² σ*/η_s² = 500. Every steady state here is independent of ρ
(Stokes flow), so ρ is a numerical choice [justified below]; the viscous step
δt_ν = 0.125 ρ h_sl²/η_max is then what the density buys:

* Newtonian channel/Couette: ρ = 1 and 0.1 (Re = ρ U L_y/η ≤ 0.13).
* DST flow curve (stress control): the homogeneous state on the unstable branch is stable only
  while momentum (time ρ L_y²/η) follows the microstructure (time 1/(K_f γ̇)); we take the
  density with ε = K_f γ̇ ρ L_y²/η = 0.1, i.e. ρ = 0.1 σ/(K_f γ̇²): one strain unit then costs
  (L_y/h_sl)²/(0.3 ε) steps, whatever σ is (the set-up is :func:`suspsim.dst.study.flow_curve`).
* DST channel: ρ = 1 (ε ≤ 0.01): the velocity settles in ≈ 0.03 time units.

3D (issue 5, walls in 2D and 3D): the Newtonian channel and stress Couette and one strong
non-locality flow-curve point run on n_x × n_y × n_z lattices with z periodic (n_x, n_z the
smallest the neighbour list allows, 14 and 13); each 3D particle has ≈ 4.4 times the
neighbours of a 2D one, so the 3D lattices are coarser.

The sound speed follows the Morris criteria (c ≥ 10 V, c² ≥ σ/(ρ δ), c² ≥ g L_y/δ with
δ = 1 %); its step is 4–200 times the viscous one (viscous_number 0.3), so the viscous
limit binds everywhere.
"""
import math
import os
import time

import numpy as np
import pytest

from suspsim.dst import (Channel, DSTSimulation, Geometry, Numerics, StressCouette,
                         WyartCatesFluid)
from suspsim.dst.study import LOCAL, STRONG_NONLOCALITY, flow_curve, stress_splitting
from suspsim.reference.dst_channel import dst_channel_mean_velocity, dst_channel_profile

pytestmark = pytest.mark.slow
REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
THREADS = 1
N_X = 14
#: Periodic particles along z in 3D: the fewest the neighbour list allows (3 cells of
#: (3 + skin) h_sl at h_sl = 1.1 Δx).
N_Z = 13
#: Seed 002 at φ = 0.54 in scaled units (η_s = σ* = L_y = 1).
SEED_054 = dict(eta_s=1.0, phi=0.54, phi_m=0.562, phi_0=0.693, sigma_star=1.0, beta=2.0,
                K_f=1.0)


def _run(sim, steps, label, watch=None, every=10):
    """Advance ``steps`` and print wall time and particle-steps per second; with ``watch``,
    in pieces of ``every`` steps with ``watch(sim)`` after each."""
    start = time.perf_counter()
    if watch is None:
        sim.advance(steps)
    else:
        for done in range(0, steps, every):
            sim.advance(min(every, steps - done))
            watch(sim)
    wall = time.perf_counter() - start
    particles = sim.n_fluid + 2 * sim.n_wall
    print(f"\n[{label}] {sim.n_fluid} fluid + {2 * sim.n_wall} wall particles, {steps} steps "
          f"(dt {sim.dt:.3g}), wall {wall:.1f} s, {particles * steps / wall:.3g} particle-steps/s")
    return wall


def _l2_over_peak(u, exact):
    return float(np.sqrt(np.mean((u - exact) ** 2)) / np.max(np.abs(exact)))


def _geometry(n_y, dimension):
    """Unit gap, n_y across it; x periodic over max(N_X, n_y/2) spacings, z over N_Z (3D)."""
    return Geometry(max(N_X, n_y // 2), n_y, 1.0, n_z=None if dimension == 2 else N_Z)


def _cross_velocities(snap):
    """max |v_y|, |v_z| (3D) over the fluid."""
    return max(np.abs(snap["v_y"]).max(), np.abs(snap.get("v_z", 0.0)).max())


#: Lattice across the gap (reduced, full) per dimension. The 3D channel needs n_y = 20 for
#: the 1 % (measured L2/peak 1.49 % at n_y = 12, 1.02 % at 16, 0.80 % at 20); the reduced 3D
#: run (CI) is n_y = 12, a fifth of the cost (0.6 × the particles, 0.36 × the viscous steps),
#: and checks that measured 1.49 % against 2 %: the 1 % bound is the full size's.
CHANNEL_N_Y = {2: (20, 40), 3: (12, 24)}
CHANNEL_BOUND = {(2, True): 0.01, (2, False): 0.01, (3, True): 0.02, (3, False): 0.01}
#: The 3D stress Couette reads sigma_in/(V_w/L) 0.9938 at n_y = 8 (reduced) and 0.9939 at 12.
COUETTE_N_Y = {2: (16, 30), 3: (8, 16)}


@pytest.mark.parametrize("dimension", [2, 3])
def test_newtonian_channel_is_a_parabola(dimension):
    """Walls at rest, g = 1, η = ρ = 1: u = g y (1 − y)/2 within 1 % (L2 relative to peak),
    cross-stream velocities below 1e−3 of the peak, and no fluid particle ever reaches a wall
    (no penetration: 0 < y < L_y at every check, every 10 steps)."""
    n_y = CHANNEL_N_Y[dimension][0 if REDUCED else 1]
    sim = DSTSimulation(WyartCatesFluid.newtonian(1.0), Channel(1.0), _geometry(n_y, dimension),
                        Numerics(density=1.0), threads=THREADS)
    # slowest mode decays as exp(−π² ν t/L²): t = 1 leaves 5e−5 of the start-up
    extent = [1.0, 0.0]

    def watch(sim):
        y = sim.positions_all[:sim.n_fluid, 1]
        extent[:] = min(extent[0], y.min()), max(extent[1], y.max())

    _run(sim, int(math.ceil(1.0 / sim.dt)), f"Newtonian channel {dimension}D n_y={n_y}", watch)
    low, high = extent
    snap = sim.snapshot()
    exact = 0.5 * snap["y"] * (1.0 - snap["y"])
    error = _l2_over_peak(snap["v_x"], exact)
    print(f"  L2/peak {error:.4f}, max cross-stream |v|/u_max "
          f"{_cross_velocities(snap) / 0.125:.2e}, fluid y within [{low:.4f}, {high:.4f}]")
    assert error < CHANNEL_BOUND[dimension, REDUCED]
    assert _cross_velocities(snap) < 1e-3 * 0.125
    assert 0.0 < low and high < 1.0


@pytest.mark.parametrize("dimension", [2, 3])
def test_newtonian_stress_couette_recovers_viscosity(dimension):
    """σ_in = η = 1: linear profile, σ_in/(V_w/L_y) = η_s within 2 % (U = σ_in L_y/η)."""
    n_y = COUETTE_N_Y[dimension][0 if REDUCED else 1]
    sim = DSTSimulation(WyartCatesFluid.newtonian(1.0), StressCouette(1.0),
                        _geometry(n_y, dimension), Numerics(density=0.1), threads=THREADS)
    _run(sim, int(math.ceil(0.5 / sim.dt)), f"Newtonian stress Couette {dimension}D n_y={n_y}")
    snap = sim.snapshot()
    v_w = sim.wall_velocity
    linear = v_w * snap["y"]
    error = _l2_over_peak(snap["v_x"], linear)
    viscosity = 1.0 / (v_w / 1.0)
    sample = sim.sample()
    print(f"  L2/V_w {error:.2e}, sigma_in/(V_w/L) {viscosity:.4f}, <sigma> {sample['stress']:.4f}")
    assert error < 0.01
    assert viscosity == pytest.approx(1.0, rel=0.02)
    assert sample["stress"] == pytest.approx(1.0, rel=0.02)


@pytest.mark.parametrize("ratio", [1.0, 6.0, 10.0, 100.0])
def test_local_dst_channel_matches_reference(ratio):
    """φ = 0.54, α = 0, F H/σ* = ``ratio``: velocity within 2 % (L2/peak) of the ODE of SPEC
    §5.7 (ratios 1, 10, 100) and the mean velocity within 5 % (all four, the flow reduction
    between 1 and 6 included).

    Starts from rest with f = f̂(F |H − y|) (the local steady state of the imposed stress) and
    runs one momentum time ρ L_y²/η(f = 0), after which the slowest velocity mode has decayed
    to e^(−π²). The microstructure's own relaxation (time 1/(K_f γ̇) ≈ 30–70 here) is not
    waited for; the residual rms(f̂(σ_i) − f_i) is printed as the measure of how far the
    SPH stress leaves f from steady.
    """
    n_y = 16 if REDUCED else 30
    fluid = WyartCatesFluid(**SEED_054, alpha=0.0)
    law = fluid.steady_law()
    rho = 1.0
    force = ratio * fluid.sigma_star / 0.5
    sim = DSTSimulation(fluid, Channel(force / rho), Geometry(max(N_X, n_y // 2), n_y, 1.0),
                        Numerics(density=rho), threads=THREADS)
    t_end = rho * 1.0 ** 2 / fluid.viscosity(0.0)
    _run(sim, int(math.ceil(t_end / sim.dt)), f"DST channel FH/sigma*={ratio:g} n_y={n_y}")
    snap = sim.snapshot()
    exact = dst_channel_profile(law, force, 1.0, snap["y"])
    error = _l2_over_peak(snap["v_x"], exact)
    mean = float(snap["v_x"].mean())
    mean_ref = dst_channel_mean_velocity(law, force, 1.0)
    residual = np.sqrt(np.mean((law.frictional_fraction(snap["stress"]) - snap["f"]) ** 2))
    print(f"  L2/peak {error:.4f}, mean {mean:.4g} vs {mean_ref:.4g} ({mean / mean_ref - 1:+.2%}),"
          f" f residual rms {residual:.3g}")
    if ratio in (1.0, 10.0, 100.0):
        assert error < 0.02
    assert mean == pytest.approx(mean_ref, rel=0.05)


def test_local_dst_channel_with_relaxed_microstructure():
    """F H/σ* = 10 run for 100 time units (≈ 1.5 strain units at the wall rate, so f relaxes
    towards f̂(σ_i) of the SPH stress): the velocity stays within 2 % (L2/peak) of the ODE.

    ρ = 500 (seed 002's own density in these units; ε = K_f γ̇ ρ L_y²/η ≈ 0.1 in the transition
    layer) makes δt_ν 500 times that of the ρ = 1 runs above.
    """
    n_y = 12 if REDUCED else 20
    fluid = WyartCatesFluid(**SEED_054, alpha=0.0)
    law = fluid.steady_law()
    rho, force = 500.0, 10.0 * fluid.sigma_star / 0.5
    sim = DSTSimulation(fluid, Channel(force / rho), Geometry(N_X, n_y, 1.0),
                        Numerics(density=rho), threads=THREADS)
    t_end = 50.0 if REDUCED else 100.0
    _run(sim, int(math.ceil(t_end / sim.dt)), f"DST channel relaxed FH/sigma*=10 n_y={n_y}")
    snap = sim.snapshot()
    exact = dst_channel_profile(law, force, 1.0, snap["y"])
    error = _l2_over_peak(snap["v_x"], exact)
    residual = np.sqrt(np.mean((law.frictional_fraction(snap["stress"]) - snap["f"]) ** 2))
    mean_ref = dst_channel_mean_velocity(law, force, 1.0)
    print(f"  t {sim.time:.1f}: L2/peak {error:.4f}, mean {snap['v_x'].mean() / mean_ref - 1:+.2%}"
          f", f residual rms {residual:.3g}")
    assert error < 0.02


def _flow_curve_points():
    """(φ, imposed stress in units of σ*): across the S-curve of φ = 0.54 (σ_β = 0.76σ*,
    σ_α = 3.92σ*) and φ = 0.50 (σ_β = 0.964σ*, σ_α = 1.87σ*) — lower, unstable and upper
    branch — and along the CST curve of φ = 0.48. Full size: 12 stresses per φ."""
    if REDUCED:
        return ([(0.54, s) for s in (0.3, 1.5, 2.5, 3.5, 10.0)]
                + [(0.50, s) for s in (0.5, 1.4)] + [(0.48, 3.0)])
    grid = list(np.round(np.geomspace(0.2, 40.0, 12), 4))
    return [(phi, s) for phi in (0.54, 0.50, 0.48) for s in grid]


@pytest.mark.parametrize("phi, stress", _flow_curve_points())
def test_strong_nonlocality_flow_curve_point(phi, stress):
    """α = 0.02 (seed 002's 1e−5 m²/s scaled), stress control: domain-averaged (γ̇, σ) within
    5 % of the Wyart–Cates curve, on the unstable branch as well.

    The run is :func:`suspsim.dst.study.flow_curve` (its docstring gives the set-up): it starts
    at the fixed point of SPEC §5.4 (f = f̂(σ_in), V_w = γ̇(σ_in) L_y) and averages samples over
    strains 1.5–3 (γ̇ t): an unstable homogeneous state would have drifted by then
    (perturbations grow like e^(K_f γ̇ t · slope)). Density from ε = 0.1, so Re = 0.1.
    """
    _check_flow_curve_point(phi, stress, (N_X, 12 if REDUCED else 20))


def test_strong_nonlocality_flow_curve_point_3d():
    """The 2D test above in 3D (z periodic) on the unstable branch of φ = 0.54 (σ_in = 2.5σ*,
    between σ_β = 0.76σ* and σ_α = 3.92σ*): ⟨γ̇⟩, V_w/L_y and ⟨σ⟩ within 5 % of the
    Wyart–Cates curve; the driven wall's area is L_x L_z and γ̇ = sqrt(2 D:D) of the 3 × 3
    gradient."""
    # Reduced: half the strains too; the run starts at the steady f of σ_in and strong
    # non-locality keeps it homogeneous.
    _check_flow_curve_point(0.54, 2.5, (N_X, 8 if REDUCED else 12, N_Z),
                            strains=(0.75, 0.75) if REDUCED else (1.5, 1.5))


def _check_flow_curve_point(phi, stress, lattice, strains=(1.5, 1.5)):
    n_y = lattice[1]
    point = flow_curve(phi, [stress], alpha=STRONG_NONLOCALITY, lattice=lattice,
                       threads=THREADS, equilibration_strain=strains[0],
                       averaging_strain=strains[1]).isel(stress=0)
    law = WyartCatesFluid(**{**SEED_054, "phi": phi}).steady_law()
    rate = float(point["wyart_cates_shear_rate"])
    gdot, sigma = float(point["shear_rate"]), float(point["measured_stress"])
    wall_rate = float(point["wall_shear_rate"])
    steps, wall = int(point["steps"]), float(point["wall_time"])
    particles = point.attrs["n_particles"]
    print(f"\n[DST flow curve {len(lattice)}D phi={phi} sigma={stress:g} n_y={n_y}] {particles} "
          f"particles, "
          f"{steps} steps (dt {float(point['time_step']):.3g}), wall {wall:.1f} s, "
          f"{particles * steps / wall:.3g} particle-steps/s")
    print(f"  <gdot>/gdot_WC {gdot / rate:.4f} +- {float(point['shear_rate_stderr']) / rate:.1e}"
          f", V_w/L_y/gdot_WC {wall_rate / rate:.4f}, <sigma>/sigma_in {sigma / stress:.4f}, "
          f"f {float(point['frictional_fraction']):.4f} "
          f"(f_hat {float(point['steady_frictional_fraction']):.4f})")
    assert rate == pytest.approx(float(law.shear_rate(stress)), rel=1e-12)
    assert gdot == pytest.approx(rate, rel=0.05)
    assert wall_rate == pytest.approx(rate, rel=0.05)
    assert sigma == pytest.approx(stress, rel=0.05)
    assert float(law.shear_rate(sigma)) == pytest.approx(gdot, rel=0.05)


#: Zero non-locality: imposed stress, lattice and strains (γ̇_WC t) of the splitting test.
SPLIT_STRESS = 2.0
SPLIT_RUN = (dict(lattice=(N_X, 10), equilibration_strain=15.0, averaging_strain=10.0,
                  samples=16, n_blocks=8) if REDUCED else
             dict(lattice=(N_X, 12), equilibration_strain=20.0, averaging_strain=20.0,
                  samples=40, n_blocks=8))


@pytest.fixture(scope="session")
def split_run():
    """One zero-non-locality run (α = 0, φ = 0.54, σ_in = 2σ*) shared by the two tests below."""
    start = time.perf_counter()
    data = stress_splitting(0.54, [SPLIT_STRESS], alpha=LOCAL, threads=THREADS, **SPLIT_RUN)
    return data, time.perf_counter() - start


@pytest.mark.xdist_group("split_run")
def test_zero_nonlocality_splits_onto_both_branches(split_run):
    """α = 0, φ = 0.54, σ_in = 2σ* (q = 0.39, on the unstable branch): stress splitting.

    :func:`suspsim.dst.study.stress_splitting` starts at f̂(σ_in) with a 1 % uncorrelated
    perturbation and discards 20 strain units (15 reduced) — the split starts after ≈ 3 and
    settles after ≈ 10 — then averages over 20 (10). Checks (SPEC §5.6; seed 002 Fig. 5):

    * both stable branches are populated: ψ1 > 0.3 and ψ2 > 0.1 (the lever rule expects
      ≈ 0.7 / 0.3), and ψ1 + ψ2 > 0.9 (particles off the branches are in transit);
    * as in the seed, the shear rate drops below γ̇_WC(σ_in) and ψ1 lies below the lever rule
      evaluated at γ̇_WC (the Fig. 5 line) by more than 3 standard errors.
    """
    data, wall = split_run
    p = {k: float(v) for k, v in data.isel(stress=0).data_vars.items()}
    n_x, n_y = SPLIT_RUN["lattice"]
    print(f"\n[DST splitting sigma={SPLIT_STRESS:g} n={n_x}x{n_y}] {int(p['steps'])} steps, "
          f"wall {wall:.1f} s, {data.attrs['n_particles'] * p['steps'] / wall:.3g} "
          f"particle-steps/s")
    print(f"  q {p['q']:.3f}: psi1 {p['psi1']:.3f} +- {p['psi1_stderr']:.3f}, psi2 "
          f"{p['psi2']:.3f} +- {p['psi2_stderr']:.3f}, sum {p['psi_sum']:.3f}; lever(V_w/L_y) "
          f"{p['lever_rule']:.3f}, lever(<gdot>) {p['lever_rule_domain_rate']:.3f}, "
          f"lever(gdot_WC) {p['wyart_cates_lever_rule']:.3f}; psi1 - lever "
          f"{p['psi1_minus_lever']:+.3f} +- {p['psi1_minus_lever_stderr']:.3f}; V_w/L_y/gdot_WC "
          f"{p['wall_shear_rate'] / p['wyart_cates_shear_rate']:.3f}, <sigma>/sigma_in "
          f"{p['measured_stress'] / SPLIT_STRESS:.3f}")
    assert p["psi1"] > 0.3 and p["psi2"] > 0.1
    assert p["psi_sum"] > 0.9
    assert p["wall_shear_rate"] < p["wyart_cates_shear_rate"]
    assert p["psi1"] < p["wyart_cates_lever_rule"] - 3.0 * p["psi1_stderr"]


@pytest.mark.xfail(not REDUCED, strict=True, reason=(
    "measured (14x12, strains 20-40): psi1 0.649 +- 0.002 vs lever rule at V_w/L_y 0.683; "
    "<psi1 - lever> = -0.031 +- 0.0053 (batch means), tolerance 3 se + 1 particle = 0.022. "
    "Reduced (14x10, strains 15-25): -0.020 +- 0.006 < 0.025 passes. psi1 still creeps up "
    "(0.64 at strain 20, 0.69 at 60), so the offset may be the unfinished drift; not resolved"))
@pytest.mark.xdist_group("split_run")
def test_zero_nonlocality_split_follows_the_lever_rule(split_run):
    """ψ1 agrees with the vertical-split lever rule at the measured common rate V_w/L_y:
    |⟨ψ1 − lever(V_w/L_y)⟩| < 3 standard errors (batch means of the per-sample difference, so
    the fluctuations of V_w that move the prediction are in the error) + one particle."""
    data, _ = split_run
    p = {k: float(v) for k, v in data.isel(stress=0).data_vars.items()}
    n_x, n_y = SPLIT_RUN["lattice"]
    tolerance = 3.0 * p["psi1_minus_lever_stderr"] + 1.0 / (n_x * n_y)
    print(f"\n  psi1 - lever {p['psi1_minus_lever']:+.4f} +- {p['psi1_minus_lever_stderr']:.4f}"
          f", tolerance {tolerance:.4f}")
    assert abs(p["psi1_minus_lever"]) < tolerance
