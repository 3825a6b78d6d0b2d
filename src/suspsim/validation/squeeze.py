"""Resolved SPH squeeze force between two equal spheres against Stokes theory (SPEC §3.1, §3.3).

Purpose: choose the lubrication cutoff gap s_c. SPEC §3.3 adds F_lub(s) − F_lub(s_c) only
below s_c, so the force the SPH fluid itself resolves must follow theory down to s_c. This
module measures that resolved force and compares it with the exact two-sphere result.

Set-up (:func:`squeeze_run`): two spheres of nominal radius a (rigid SPH shells, SPEC §3.1) on
a line parallel to x through the centre of a periodic box, Newtonian fluid at rest (a Couette
scene with a negligible rate, ``run.start: rest``, the start relaxed as every inclusion scene).
The motion is **prescribed**: before every step the bodies' velocities are reset with
:meth:`~suspsim.bodies.system.RigidBodies.set_motion` to ±U x̂ (relative speed 2U, no rotation),
so the integrator's kick never changes them; the force recorded after the step is the fluid
force of that step's force pass. The spheres start at gap ``start_gap`` (a spin-up stretch that
is not reported) and are stopped at ``end_gap``. Squeeze force F = (F_2,x − F_1,x)/2 > 0 (the
fluid resists the approach). Samples are averaged in logarithmic gap bins.

Hydrodynamic radius (:func:`stokes_drag`): one sphere at prescribed speed U relative to the
mean fluid velocity in the same box. SPH conserves momentum, so the fluid's mean velocity grows
as ū_f = −Σ F δt / M_fluid; the sphere is driven at U + ū_f so that its speed relative to the
fluid is U, the frame of Hasimoto's periodic-array result. a_h solves (SPEC §3.1)

    F = 6πμ a_h U / (1 + c₁ a_h + (4π/3) a_h³/V − 27.4 (a_h/L)⁶),

with c₁ the point-force periodic self-correction of the box (:func:`periodic_self_coefficient`,
c₁ L = −2.837297 for a cube: Hasimoto 1959) and (4π/3)a³/V ≈ 4.19 (a/L)³ for a cube.

Theory (:func:`squeeze_theory`): the resistance of two equal spheres moving along their line
of centres with velocities ±U, F = 6πμ a U (X11A − X12A), from Jeffrey & Onishi (1984, J. Fluid
Mech. 139, 261): the twin-multipole coefficients f_k (their Eqs. 3.6–3.9, 3.15, the recurrence
as printed in Townsend, arXiv:1802.08226, and checked against the tabulated f_0…f_6 of
K. Ichiki's libstokes ``src/XA.c``: f_2 = 9λ, f_3 = −4λ + 27λ² − 4λ³, …) summed in JO's
uniformly valid "near-field" form (JO Eqs. 3.20–3.21, Townsend's corrected version) that
subtracts the singular g₁/ξ + g₂ ln(1/ξ) + g₃ ξ ln(1/ξ) behaviour (SPEC §3.3 table: 1/4, 9/40,
3/112 at λ = 1) and adds it back in closed form, so the sum is accurate from contact to
infinity. The box images are added at the mobility level: the squeeze-mode mobility
m = 1/(X11A − X12A) gains Δ = 6πμ a [(G_per − G)(0) − (G_per − G)(r)]_xx (Hasimoto–Ewald
periodic Oseen tensor, :func:`periodic_oseen_xx`), the image strain across the pair; near
contact this relative motion is suppressed by lubrication, by 1 − A(r) (Batchelor & Green 1972,
A = 5/ρ³ − 8/ρ⁵ + 25/ρ⁶ − 35/ρ⁸ + 125/ρ⁹ − 102/ρ¹⁰ + 12.5/ρ¹¹ + 430/ρ¹², ρ = r/a, capped at
1 − 4.077 ξ near contact) [choice: an approximation; the size of the correction is reported,
``image_correction``, and is a few per cent at most in the default boxes].

Comparison: theory evaluated with the hydrodynamic radius a_h (gap s_h = r − 2a_h) and with
the nominal a; the reported gap is the nominal s = r − 2a. The recommended cutoff s_c is the
largest gap below which F_SPH/F_theory(a) stays under 0.9 (:func:`cutoff_gap`), with the
nominal radius, the one the simulation's lubrication takes. The single-sphere drag's a_h
settles slowly and scatters by about 15 % over a run, so it is reported beside the comparison,
not used for the cutoff: with the spin correction (the default with bodies) a_h/a = 1.056 at
a = 2.5 h and 1.049 at 4 h, without it 1.027 and 1.021 (README). ``ratio_combined`` adds the
lubrication correction the run's scene applies at its own cutoff (:func:`lubrication_correction`):
the total squeeze force a suspension's pair feels, against theory.

Units: simulation units, lengths [h], mass [m] (particle mass 1), time [τ]; forces
[m h τ⁻²], viscosity [m h⁻¹ τ⁻¹]. Symbols: a nominal and a_h hydrodynamic radius; r centre
distance; s = r − 2a gap; ξ = s/a; U speed of each sphere; μ viscosity; ρ_f = n m density;
L box side; V box volume; Re = ρ_f U a/μ particle Reynolds number.
"""
from __future__ import annotations

import functools
import math
import os
import tempfile
import time as wallclock
from pathlib import Path

import numpy as np
import xarray as xr
from numba import njit
from scipy.optimize import brentq
from scipy.special import erfc

from suspsim.bodies.lubrication import pair_mode_resistances
from suspsim.io.provenance import provenance
from suspsim.io.variables import UNIT_SYSTEM
from suspsim.scene_rules import AUTO_SHIFTING_WITH_INCLUSIONS

REFERENCES = (
    "Jeffrey & Onishi, J. Fluid Mech. 139, 261 (1984) (X^A resistance functions); "
    "Townsend, arXiv:1802.08226 (2018) (corrected JO recurrence and near-field forms); "
    "Hasimoto, J. Fluid Mech. 5, 317 (1959) (periodic Stokeslet, drag in a cubic array); "
    "Batchelor & Green, J. Fluid Mech. 56, 375 (1972) (A(r)); "
    "Martys, George, Chun & Lootens, Rheol. Acta 49, 1059 (2010)")

#: Hasimoto's cubic-array constants (SPEC §3.1).
HASIMOTO = (2.837297, 4.19, 27.4)
#: Terms of the twin-multipole sums [choice: converged to < 1e-6 for ξ ≥ 0.01].
SERIES_TERMS = 160
#: F_SPH/F_theory below this counts as failing theory (the brief: 10 %).
CUTOFF_RATIO = 0.9
#: Default sound speed [h τ⁻¹] and particle Reynolds number of the runs [choice].
SOUND_SPEED = 1.5
REYNOLDS = 0.05
#: Shifting of the runs, with the rate U/a in place of a shear rate (``numerics.shifting_rate``)
#: [choice: the Newtonian inclusions' default A]. Without it the single-sphere drag never
#: settles: the fluid the sphere pushes through turns disordered and its SPH viscosity rises (L = 15 h,
#: a = 2.5 h: 1.78 → 2.61 × Stokes over 470 τ, Hasimoto's steady value 1.83; with it, 1.77).
SHIFTING_COEFFICIENT = AUTO_SHIFTING_WITH_INCLUSIONS


# ---------------------------------------------------------------- Jeffrey & Onishi X^A
@njit(cache=True)
def _p_table(m):
    """P_{n,p,q} and V_{n,p,q} of JO (1984) Eqs. 3.6–3.9 for n ≤ m, p + q ≤ m."""
    size = m + 2
    p_ = np.zeros((size, size, size))
    v_ = np.zeros((size, size, size))
    p_[1, 0, 0] = 1.0
    v_[1, 0, 0] = 1.0
    for total in range(1, m + 1):
        for q in range(total + 1):
            p = total - q
            for n in range(1, m + 1):
                acc = 0.0
                acc_v = 0.0
                c1 = n * (2.0 * n + 1.0) / (2.0 * (n + 1.0))
                c2 = -n * (2.0 * n - 1.0) / (2.0 * (n + 1.0))
                c3 = -n * (4.0 * n * n - 1.0) / (2.0 * (n + 1.0))
                binomial = 1.0
                for s in range(1, q + 1):
                    binomial *= (n + s) / s          # C(n+s, n)
                    up, down = p - n + 1, p - n - 1
                    if up >= 0:
                        acc += binomial * c1 * (2.0 * n * s - n - s + 2.0) / (
                            (2.0 * s - 1.0) * (n + s)) * p_[s, q - s, up]
                        if q - s - 2 >= 0:
                            acc += binomial * c3 / (2.0 * s + 1.0) * v_[s, q - s - 2, up]
                    if down >= 0:
                        acc += binomial * c2 * p_[s, q - s, down]
                        acc_v += binomial * p_[s, q - s, down]
                p_[n, p, q] = acc
                v_[n, p, q] = acc - 2.0 * n / ((n + 1.0) * (2.0 * n + 3.0)) * acc_v
    return p_


@functools.lru_cache(maxsize=4)
def xa_coefficients(size_ratio: float = 1.0, terms: int = SERIES_TERMS) -> np.ndarray:
    """f_k(λ), k = 0 … terms, of JO Eq. 3.15: f_k = 2^k Σ_q P_{1,k−q,q} λ^q."""
    table = _p_table(terms)
    out = np.zeros(terms + 1)
    for k in range(terms + 1):
        out[k] = 2.0 ** k * sum(table[1, k - q, q] * size_ratio ** q for q in range(k + 1))
    return out


def _g(size_ratio):
    lam = size_ratio
    return (2.0 * lam ** 2 / (1 + lam) ** 3,
            lam * (1 + 7 * lam + lam ** 2) / (5.0 * (1 + lam) ** 3),
            (1 + 18 * lam - 29 * lam ** 2 + 18 * lam ** 3 + lam ** 4) / (42.0 * (1 + lam) ** 3))


def xa_functions(distance, size_ratio: float = 1.0, terms: int = SERIES_TERMS):
    """(X11A, X12A) at dimensionless centre distance t = 2r/(a₁ + a₂) > 2 (JO's s).

    Uniformly valid form (module docstring): singular parts in closed form plus the
    rapidly convergent remainder series; normalisation of Kim & Karrila (F₁ = −6πμa₁ X11A U₁
    − 6πμa₁ X12A U₂ for λ = 1 along the line of centres).
    """
    t = np.asarray(distance, dtype=float)
    if np.any(t <= 2.0):
        raise ValueError("xa_functions: the spheres overlap (t = 2r/(a1+a2) must exceed 2)")
    f = xa_coefficients(float(size_ratio), terms)
    g1, g2, g3 = _g(size_ratio)
    u = 2.0 / t
    arg = 1.0 - u * u
    x11 = np.zeros_like(t)
    x12 = np.zeros_like(t)
    for m in range(1, terms + 1):
        m1 = -2.0 if m == 2 else m - 2.0
        coefficient = 2.0 ** -m * (1.0 + size_ratio) ** -m * f[m] - g1 - 2.0 / m * g2
        coefficient += 4.0 / (m * m1) * g3
        if m % 2 == 0:
            x11 += coefficient * u ** m
        else:
            x12 += coefficient * u ** m
    x11 += g1 / arg - g2 * np.log(arg) - g3 * arg * np.log(arg) + f[0] - g1
    log_term = np.log((t + 2.0) / (t - 2.0))
    x12 += u * g1 / arg + g2 * log_term + g3 * arg * log_term + 4.0 * g3 / t
    return x11, -x12


def squeeze_resistance(gap, radius: float):
    """X11A − X12A for equal spheres of ``radius`` at surface gap ``gap`` [h]: the free-space
    squeeze force is 6πμ a U (X11A − X12A) for velocities ±U."""
    x11, x12 = xa_functions(2.0 + np.asarray(gap, dtype=float) / radius)
    return x11 - x12


# ---------------------------------------------------------------- periodic images
def _ewald_split(box):
    return math.sqrt(math.pi) / float(np.prod(box)) ** (1.0 / 3.0)


def periodic_oseen_xx(displacement, box, *, splitting: float | None = None,
                      images: int = 4, waves: int = 8) -> float:
    """xx component of (G_per − G)(r) · μ for a point force in a periodic box [h⁻¹], where G is
    the free Oseen tensor and G_per its Hasimoto (1959) periodic sum without the k = 0 mode,
    by Ewald summation (real part (1/8πμ)[I(erfc(ξr)/r − 2ξe^{−ξ²r²}/√π) + r̂r̂(erfc(ξr)/r
    + 2ξe^{−ξ²r²}/√π)], Fourier part (1/μV) Σ (I − k̂k̂)(1 + k²/4ξ²) e^{−k²/4ξ²}/k² cos k·r).
    ``displacement`` r (3,) [h]; r = 0 gives the self term."""
    box = np.asarray(box, dtype=float)
    r0 = np.asarray(displacement, dtype=float)
    xi = _ewald_split(box) if splitting is None else splitting
    total = 0.0
    rng = range(-images, images + 1)
    for i in rng:
        for j in rng:
            for k in rng:
                vec = r0 + box * np.array([i, j, k])
                r = float(np.sqrt(vec @ vec))
                if r < 1e-12:
                    total += -4.0 * xi / math.sqrt(math.pi) / (8.0 * math.pi)
                    continue
                e = math.exp(-(xi * r) ** 2)
                c = float(erfc(xi * r))
                real = (c / r - 2.0 * xi * e / math.sqrt(math.pi)
                        + (vec[0] / r) ** 2 * (c / r + 2.0 * xi * e / math.sqrt(math.pi)))
                total += real / (8.0 * math.pi)
    if np.linalg.norm(r0) > 1e-12:
        r = float(np.linalg.norm(r0))
        total -= (1.0 + (r0[0] / r) ** 2) / (8.0 * math.pi * r)
    n = np.arange(-waves, waves + 1)
    kx, ky, kz = np.meshgrid(*(2.0 * math.pi * n / length for length in box), indexing="ij")
    k2 = kx ** 2 + ky ** 2 + kz ** 2
    k2[waves, waves, waves] = 1.0
    weight = (1.0 - kx ** 2 / k2) * (1.0 + k2 / (4 * xi * xi)) * np.exp(-k2 / (4 * xi * xi)) / k2
    weight[waves, waves, waves] = 0.0
    phase = np.cos(kx * r0[0] + ky * r0[1] + kz * r0[2])
    total += float(np.sum(weight * phase)) / float(np.prod(box))
    return total


def periodic_self_coefficient(box) -> float:
    """c₁ [h⁻¹]: the periodic self-mobility of a point force, 6π × (G_per − G)(0)_xx μ, so a
    sphere's mobility is (1 + c₁ a + …)/(6πμa); c₁ L = −2.837297 in a cube of side L."""
    return 6.0 * math.pi * periodic_oseen_xx(np.zeros(3), box)


def hasimoto_factor(radius: float, box) -> float:
    """Drag / (6πμaU) of a sphere in the periodic box (module docstring, SPEC §3.1)."""
    box = np.asarray(box, dtype=float)
    side = float(np.prod(box)) ** (1.0 / 3.0)
    mobility = (1.0 + periodic_self_coefficient(box) * radius
                + 4.0 * math.pi / 3.0 * radius ** 3 / float(np.prod(box))
                - HASIMOTO[2] * (radius / side) ** 6)
    return 1.0 / mobility


def _batchelor_a(distance_over_radius):
    rho = np.asarray(distance_over_radius, dtype=float)
    series = (5 / rho ** 3 - 8 / rho ** 5 + 25 / rho ** 6 - 35 / rho ** 8 + 125 / rho ** 9
              - 102 / rho ** 10 + 12.5 / rho ** 11 + 430 / rho ** 12)
    return np.clip(np.maximum(series, 1.0 - 4.077 * (rho - 2.0)), 0.0, 1.0)


def image_mobility(gap, radius: float, box) -> np.ndarray:
    """Δ of the module docstring (dimensionless, in units of 1/(6πμa)) for the squeeze mode of
    two spheres on a line parallel to x at surface gap ``gap`` [h]."""
    gap = np.atleast_1d(np.asarray(gap, dtype=float))
    self_part = periodic_oseen_xx(np.zeros(3), box)
    out = np.empty_like(gap)
    for i, s in enumerate(gap):
        r = 2.0 * radius + s
        cross = periodic_oseen_xx(np.array([r, 0.0, 0.0]), box)
        out[i] = 6.0 * math.pi * radius * (self_part - cross)
    return out * (1.0 - _batchelor_a(2.0 + gap / radius))


def squeeze_theory(gap, radius: float, viscosity: float, speed: float, box=None):
    """Squeeze force [m h τ⁻²] on each of two equal spheres of ``radius`` [h] at surface
    ``gap`` [h] moving at ±``speed`` [h τ⁻¹]: 6πμaU/(m + Δ), m = 1/(X11A − X12A) (JO 1984),
    Δ the periodic-image term of ``box`` (None: free space)."""
    gap = np.asarray(gap, dtype=float)
    mobility = 1.0 / squeeze_resistance(gap, radius)
    if box is not None:
        mobility = mobility + image_mobility(gap, radius, box).reshape(gap.shape)
    return 6.0 * math.pi * viscosity * radius * speed / mobility


# ---------------------------------------------------------------- SPH runs
def _two_sphere_scene(box, radius, centres, viscosity, sound_speed, workdir, *,
                      number_density=4.096, shifting_rate=0.0, numerics=None):
    from suspsim.bodies.packing import Packing
    from suspsim.io.packing_file import write_packing
    from suspsim.scene import scene_from_dict

    count = len(centres)
    packing = Packing("sphere", np.asarray(box, dtype=float), np.asarray(centres, dtype=float),
                      np.tile([1.0, 0.0, 0.0, 0.0], (count, 1)), np.full(count, radius),
                      np.full(count, 4.0 / 3.0 * math.pi * radius ** 3), None,
                      np.full(count, radius), 0, 0.0, 1.5, 0.0, {})
    path = Path(workdir) / "packing.nc"
    write_packing(path, packing, command="suspsim.validation.squeeze")
    return scene_from_dict({
        "dimension": 3, "box": [float(b) for b in box], "number_density": number_density,
        "fluid": {"law": "newtonian", "params": {"mu": float(viscosity)}},
        "flow": {"type": "couette", "shear_rate": 1e-9},
        "run": {"time": 1.0, "start": "rest", "sound_speed": float(sound_speed)},
        # No imposed shear: shifting takes the bodies' own rate U/a (SHIFTING_COEFFICIENT).
        "numerics": {"shifting": SHIFTING_COEFFICIENT if shifting_rate > 0 else 0.0,
                     "shifting_rate": float(shifting_rate),
                     "pressure_reference": "fluid_mean" if shifting_rate > 0 else "nominal",
                     **(numerics or {})},
        "inclusions": {"packing": str(path)}})


def _speed(radius, viscosity, reynolds, number_density):
    return reynolds * viscosity / (number_density * radius)


def squeeze_run(radius: float = 2.5, box=(25.0, 17.5, 17.5), *, viscosity: float = 1.0,
                reynolds: float = REYNOLDS, start_gap: float | None = None,
                end_gap: float = 0.05, sound_speed: float = SOUND_SPEED,
                number_density: float = 4.096, threads: int = 1,
                numerics: dict | None = None) -> dict:
    """Raw time series of the prescribed approach (module docstring); ``numerics`` scene
    keys over the runs' own (e.g. ``{"spin_correction": True}``).

    The speed of each sphere is U = Re μ/(ρ_f a). ``start_gap`` default 2a + 2 h. Returns a
    dict of arrays ``gap`` (nominal, [h]) and ``force`` (squeeze force, [m h τ⁻²]) per step,
    and scalars (speed, dt, n_particles, wall_time_s, health).
    """
    box = np.asarray(box, dtype=float)
    start_gap = 2.0 * radius + 2.0 if start_gap is None else float(start_gap)
    speed = _speed(radius, viscosity, reynolds, number_density)
    centre = box / 2.0
    half = radius + 0.5 * start_gap
    centres = [centre - [half, 0, 0], centre + [half, 0, 0]]
    from suspsim.sph.simulation import Simulation

    started = wallclock.perf_counter()
    with tempfile.TemporaryDirectory() as workdir:
        scene = _two_sphere_scene(box, radius, centres, viscosity, sound_speed, workdir,
                                  number_density=number_density,
                                  shifting_rate=speed / radius, numerics=numerics)
        sim = Simulation(scene, threads=threads)
    motion = np.array([[speed, 0.0, 0.0], [-speed, 0.0, 0.0]])
    still = np.zeros((2, 3))
    distance = 2.0 * half
    steps = int(math.floor((start_gap - end_gap) / (2.0 * speed * sim.dt)))
    gaps, forces = np.empty(steps), np.empty(steps)
    for k in range(steps):
        sim.bodies.set_motion(motion, still)
        sim.advance(1)
        distance -= 2.0 * speed * sim.dt
        gaps[k] = distance - 2.0 * radius
        forces[k] = 0.5 * (sim.bodies.forces[1, 0] - sim.bodies.forces[0, 0])
    ok, message = sim.health()
    lub = sim.scene.inclusions.lubrication
    return {"gap": gaps, "force": forces, "speed": speed, "dt": sim.dt,
            "lubrication_cutoff_gap": lub.cutoff_gap, "lubrication_min_gap": lub.min_gap,
            "n_particles": sim.n_particles, "n_body_particles": sim.n_body_particles,
            "wall_time_s": wallclock.perf_counter() - started, "health": message,
            "healthy": int(ok), "start_gap": start_gap, "sound_speed": sim.sound_speed}


def stokes_drag(radius: float = 2.5, box=(25.0, 17.5, 17.5), *, viscosity: float = 1.0,
                reynolds: float = REYNOLDS, time: float | None = None,
                sound_speed: float = SOUND_SPEED, number_density: float = 4.096,
                threads: int = 1, numerics: dict | None = None) -> dict:
    """Single-sphere drag at speed U relative to the mean fluid velocity (module docstring);
    F averaged over the last third of ``time`` [τ] (default 6 ρ_f L_x²/(4π²μ), six decay
    times of the box's slowest viscous mode). Returns drag, its standard error over 10 blocks,
    the hydrodynamic radius a_h and the inputs."""
    box = np.asarray(box, dtype=float)
    density = number_density
    time = 6.0 * density * box.max() ** 2 / (4 * math.pi ** 2 * viscosity) if time is None \
        else float(time)
    speed = _speed(radius, viscosity, reynolds, number_density)
    from suspsim.sph.simulation import Simulation

    started = wallclock.perf_counter()
    with tempfile.TemporaryDirectory() as workdir:
        scene = _two_sphere_scene(box, radius, [box / 2.0], viscosity, sound_speed, workdir,
                                  number_density=number_density,
                                  shifting_rate=speed / radius, numerics=numerics)
        sim = Simulation(scene, threads=threads)
    fluid_mass = (sim.n_particles - sim.n_body_particles) * scene.mass
    momentum = 0.0
    steps = int(math.ceil(time / sim.dt))
    forces = np.empty(steps)
    for k in range(steps):
        fluid_velocity = momentum / fluid_mass
        sim.bodies.set_motion(np.array([[speed + fluid_velocity, 0.0, 0.0]]), np.zeros((1, 3)))
        sim.advance(1)
        forces[k] = -sim.bodies.forces[0, 0]
        momentum += forces[k] * sim.dt
    tail = forces[2 * steps // 3:]
    blocks = np.array([b.mean() for b in np.array_split(tail, 10)])
    drag = float(tail.mean())
    factor = lambda a: 6 * math.pi * viscosity * a * speed * hasimoto_factor(a, box) - drag
    radius_h = brentq(factor, 0.3 * radius, 2.0 * radius)
    ok, message = sim.health()
    return {"drag": drag, "drag_error": float(blocks.std(ddof=1) / math.sqrt(len(blocks))),
            "hydrodynamic_radius": radius_h, "speed": speed, "time": steps * sim.dt,
            "final_fluid_velocity": momentum / fluid_mass, "n_particles": sim.n_particles,
            "wall_time_s": wallclock.perf_counter() - started, "health": message,
            "healthy": int(ok), "force_series": forces, "dt": sim.dt}


def lubrication_correction(gap, radius: float, viscosity: float, speed: float,
                           cutoff_gap: float, min_gap: float) -> np.ndarray:
    """The squeeze force the simulation adds to the resolved one for two equal spheres of
    radius a approaching at ``speed`` U each: μ M_n(s) (2U), with the correction-form squeeze
    resistance of ``bodies.lubrication.pair_mode_resistances``, 6πa [X11A(ξ) − X11A(ξ_c)] for
    s < s_c and 0 beyond, ξ = max(s, s_min)/a [m h τ⁻²]; ``gap`` s, ``cutoff_gap`` s_c and
    ``min_gap`` s_min [h]."""
    gap = np.asarray(gap, dtype=float)
    squeeze = [pair_mode_resistances(radius, radius, s, cutoff_gap, min_gap)[0]
               for s in gap.ravel()]
    return viscosity * 2.0 * speed * np.array(squeeze).reshape(gap.shape)


def bin_series(gap, force, edges):
    """Mean force and its standard error in each gap bin (NaN where empty)."""
    index = np.digitize(gap, edges) - 1
    count = len(edges) - 1
    mean, error, centre = np.full(count, np.nan), np.full(count, np.nan), np.full(count, np.nan)
    for b in range(count):
        chosen = index == b
        if chosen.sum() >= 2:
            mean[b] = force[chosen].mean()
            error[b] = force[chosen].std(ddof=1) / math.sqrt(chosen.sum())
            centre[b] = gap[chosen].mean()
    return centre, mean, error


def gap_edges(radius: float, end_gap: float = 0.05, per_decade: int = 8) -> np.ndarray:
    """Logarithmic bin edges from ``end_gap`` to 2a [h]."""
    count = int(math.ceil(per_decade * math.log10(2.0 * radius / end_gap)))
    return np.geomspace(end_gap, 2.0 * radius, count + 1)


def squeeze_dataset(run: dict, drag: dict, radius: float, box, *, viscosity: float = 1.0,
                    per_decade: int = 8, end_gap: float = 0.05) -> xr.Dataset:
    """Binned SPH squeeze force against theory (nominal a and hydrodynamic a_h) on ``gap``."""
    box = np.asarray(box, dtype=float)
    edges = gap_edges(radius, end_gap, per_decade)
    centre, mean, error = bin_series(run["gap"], run["force"], edges)
    keep = np.isfinite(mean)
    centre, mean, error = centre[keep], mean[keep], error[keep]
    speed, a_h = run["speed"], drag["hydrodynamic_radius"]
    distance = centre + 2.0 * radius
    gap_h = distance - 2.0 * a_h
    theory_h = np.where(gap_h > 0, squeeze_theory(np.maximum(gap_h, 1e-9), a_h, viscosity,
                                                  speed, box), np.nan)
    theory = squeeze_theory(centre, radius, viscosity, speed, box)
    free_h = np.where(gap_h > 0, squeeze_theory(np.maximum(gap_h, 1e-9), a_h, viscosity, speed),
                      np.nan)
    lubrication = lubrication_correction(centre, radius, viscosity, speed,
                                         run["lubrication_cutoff_gap"],
                                         run["lubrication_min_gap"])
    force_units = {"units": "1", "simulation_units": "m h tau-2"}
    length = {"units": "1", "simulation_units": "h"}
    data = {
        "force": ("gap", mean, {**force_units, "long_name": "SPH squeeze force, bin mean"}),
        "force_error": ("gap", error, {**force_units, "long_name": "standard error of the bin "
                                       "mean (step-to-step scatter; correlated)"}),
        "theory_force": ("gap", theory_h, {**force_units, "long_name": "Jeffrey-Onishi squeeze "
                                           "force with radius a_h, periodic images"}),
        "theory_force_nominal": ("gap", theory, {**force_units, "long_name": "the same with "
                                                 "the nominal radius a"}),
        "ratio": ("gap", mean / theory_h, {"units": "1", "long_name": "F_SPH / F_theory(a_h)"}),
        "ratio_nominal": ("gap", mean / theory, {"units": "1",
                                                 "long_name": "F_SPH / F_theory(a)"}),
        "image_correction": ("gap", theory_h / free_h, {"units": "1", "long_name":
                             "periodic-box theory / free-space theory (a_h)"}),
        "hydrodynamic_gap": ("gap", gap_h, {**length, "long_name": "r - 2 a_h"}),
        "lubrication_force": ("gap", lubrication, {**force_units, "long_name": "lubrication "
                              "correction the simulation adds at this gap, F(s) - F(s_c)"}),
        "ratio_combined": ("gap", (mean + lubrication) / theory, {"units": "1", "long_name":
                           "(F_SPH + lubrication correction) / F_theory(a)"}),
        "normalised_force": ("gap", mean / (6 * math.pi * viscosity * radius * speed),
                             {"units": "1", "long_name": "F_SPH / (6 pi mu a U)"}),
    }
    ds = xr.Dataset(data, coords={"gap": ("gap", centre, {**length,
                                  "long_name": "nominal surface gap r - 2a, bin mean"})})
    ds.attrs.update({
        "title": "Resolved SPH squeeze force between two equal spheres vs Jeffrey-Onishi",
        "references": REFERENCES, "unit_system": UNIT_SYSTEM, "radius": radius,
        "hydrodynamic_radius": a_h, "hydrodynamic_radius_ratio": a_h / radius,
        "box": box, "viscosity": viscosity, "speed": speed,
        "particle_reynolds_number": run.get("reynolds", float("nan")),
        "single_sphere_drag": drag["drag"], "single_sphere_drag_error": drag["drag_error"],
        "hasimoto_factor": hasimoto_factor(a_h, box), "dt": run["dt"],
        "sound_speed": run["sound_speed"], "start_gap": run["start_gap"],
        "n_particles": run["n_particles"], "squeeze_wall_time_s": run["wall_time_s"],
        "drag_wall_time_s": drag["wall_time_s"], "health": run["health"],
        "motion": "prescribed: body velocities reset to +-U x before every step",
        "cutoff_gap": cutoff_gap(centre, mean / theory),
        "lubrication_cutoff_gap": run["lubrication_cutoff_gap"],
        "lubrication_min_gap": run["lubrication_min_gap"], **provenance()})
    return ds


def cutoff_gap(gap, ratio, threshold: float = CUTOFF_RATIO) -> float:
    """Largest gap at which the ratio is below ``threshold`` with every larger gap above it
    (NaN if it never falls below). A NaN ratio (theory undefined: r < 2a_h) counts as failing."""
    gap, ratio = np.asarray(gap), np.asarray(ratio)
    order = np.argsort(gap)[::-1]
    for g, q in zip(gap[order], ratio[order]):
        if not q >= threshold:
            return float(g)
    return float("nan")


def squeeze_study(radius: float = 2.5, box=(25.0, 17.5, 17.5), *, reynolds: float = REYNOLDS,
                  viscosity: float = 1.0, threads: int = 1, per_decade: int = 8,
                  end_gap: float = 0.05, drag: dict | None = None,
                  numerics: dict | None = None, **kwargs) -> xr.Dataset:
    """Single-sphere calibration plus the approach run, as one Dataset (module docstring);
    ``numerics`` scene keys of both runs (:func:`squeeze_run`)."""
    if drag is None:
        drag = stokes_drag(radius, box, viscosity=viscosity, reynolds=reynolds,
                           threads=threads, numerics=numerics)
    run = squeeze_run(radius, box, viscosity=viscosity, reynolds=reynolds, threads=threads,
                      end_gap=end_gap, numerics=numerics, **kwargs)
    run["reynolds"] = reynolds
    return squeeze_dataset(run, drag, radius, box, viscosity=viscosity, per_decade=per_decade,
                           end_gap=end_gap)


def reduced() -> bool:
    """True when SUSPSIM_REDUCED=1 (tests run the reduced case)."""
    return os.environ.get("SUSPSIM_REDUCED", "0") == "1"
