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
is not reported) and are stopped at ``end_gap``. Squeeze force F = (F_2 − F_1)·d/2 > 0 along
the line of centres d (the fluid resists the approach). Samples are averaged in logarithmic gap
bins, pooled over runs at several lattice phases (:func:`pooled_runs`: below half a spacing one
run's force depends on where the spheres meet the start lattice).

Hydrodynamic radius (:func:`stokes_drag`): one sphere at prescribed speed U relative to the
mean fluid velocity in the same box. SPH conserves momentum, so the fluid's mean velocity grows
as ū_f = −Σ F δt / M_fluid; the sphere is driven at U + ū_f so that its speed relative to the
fluid is U, the frame of Hasimoto's periodic-array result. a_h solves
F = 6πμ a_h U × :func:`~suspsim.validation.periodic_pair.hasimoto_factor` (a_h, box) (SPEC §3.1).

Theory: Jeffrey & Onishi's two-sphere resistances with the box's periodic images
(:mod:`~suspsim.validation.periodic_pair`: :func:`squeeze_theory`, :func:`sliding_theory`).

Approach while sliding (``slide_ratio`` k > 0): the spheres also move at ∓kU normal to the
line of centres in the xy plane, so the line turns as they pass and the pair's relative motion
is that of a shear flow's compressional quadrant (k = 1: at 45°). The force resisting the
sliding is compared with 6πμaU k (Y11A − Y12A) (:func:`sliding_theory`, spheres held from
turning), and the squeeze force with the theory for the line's present angle.

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

import math
import os
import tempfile
import time as wallclock
from pathlib import Path

import numpy as np
import xarray as xr
from scipy.optimize import brentq

from suspsim.bodies.lubrication import pair_mode_resistances
from suspsim.io.provenance import provenance
from suspsim.io.variables import UNIT_SYSTEM
from suspsim.scene_rules import AUTO_SHIFTING_WITH_INCLUSIONS

from .periodic_pair import hasimoto_factor, sliding_theory, squeeze_theory

REFERENCES = (
    "Jeffrey & Onishi, J. Fluid Mech. 139, 261 (1984) (X^A resistance functions); "
    "Townsend, arXiv:1802.08226 (2018) (corrected JO recurrence and near-field forms); "
    "Hasimoto, J. Fluid Mech. 5, 317 (1959) (periodic Stokeslet, drag in a cubic array); "
    "Batchelor & Green, J. Fluid Mech. 56, 375 (1972) (A(r)); "
    "Martys, George, Chun & Lootens, Rheol. Acta 49, 1059 (2010)")

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


def _pair_frame(centres):
    """(d, n, r): the unit vector along the line from body 0 to body 1, the unit normal to it in
    the xy plane, and the centre distance r [h]."""
    line = centres[1] - centres[0]
    distance = math.sqrt(line @ line)
    line = line / distance
    return line, np.array([-line[1], line[0], 0.0]), distance


def squeeze_run(radius: float = 2.5, box=(25.0, 17.5, 17.5), *, viscosity: float = 1.0,
                reynolds: float = REYNOLDS, start_gap: float | None = None,
                end_gap: float = 0.05, sound_speed: float = SOUND_SPEED,
                number_density: float = 4.096, threads: int = 1,
                numerics: dict | None = None, slide_ratio: float = 0.0,
                shift: float = 0.0) -> dict:
    """Raw time series of the prescribed approach (module docstring); ``numerics`` scene
    keys over the runs' own (e.g. ``{"spin_correction": True}``). ``shift`` [h] moves the
    pair's midpoint from the box centre along z, normal to the plane of the motion, so the
    spheres meet the fluid's start lattice at another phase (:func:`lattice_shifts`).

    The speed of each sphere is U = Re μ/(ρ_f a) along the line of centres. With
    ``slide_ratio`` k > 0 the spheres also slide past each other at ±kU normal to the line, in
    the xy plane (the line turns as they pass; k = 1 is the relative motion of a pair at 45°
    in the compressional quadrant of a simple shear). ``start_gap`` default 2a + 2 h. Returns
    a dict of arrays ``gap`` (nominal, [h]), ``force`` (squeeze force, [m h τ⁻²]),
    ``sliding_force`` (the force resisting the sliding, [m h τ⁻²]) and ``angle`` (of the line
    from x, [rad]) per step, and scalars (speed, dt, n_particles, wall_time_s, health).
    """
    box = np.asarray(box, dtype=float)
    start_gap = 2.0 * radius + 2.0 if start_gap is None else float(start_gap)
    speed = _speed(radius, viscosity, reynolds, number_density)
    centre = box / 2.0 + np.array([0.0, 0.0, shift])
    half = radius + 0.5 * start_gap
    centres = [centre - [half, 0, 0], centre + [half, 0, 0]]
    from suspsim.sph.simulation import Simulation

    started = wallclock.perf_counter()
    with tempfile.TemporaryDirectory() as workdir:
        scene = _two_sphere_scene(box, radius, centres, viscosity, sound_speed, workdir,
                                  number_density=number_density,
                                  shifting_rate=speed / radius, numerics=numerics)
        sim = Simulation(scene, threads=threads)
    still = np.zeros((2, 3))
    steps = int(math.floor((start_gap - end_gap) / (2.0 * speed * sim.dt)))
    gaps, forces, sliding, angles = (np.empty(steps) for _ in range(4))
    for k in range(steps):
        line, normal, _ = _pair_frame(sim.bodies.centres)
        velocity = speed * (line - slide_ratio * normal)
        sim.bodies.set_motion(np.array([velocity, -velocity]), still)
        sim.advance(1)
        line, normal, distance = _pair_frame(sim.bodies.centres)
        difference = sim.bodies.forces[1] - sim.bodies.forces[0]
        gaps[k] = distance - 2.0 * radius
        forces[k] = 0.5 * difference @ line
        sliding[k] = -0.5 * difference @ normal
        angles[k] = math.atan2(line[1], line[0])
    ok, message = sim.health()
    lub = sim.scene.inclusions.lubrication
    return {"gap": gaps, "force": forces, "sliding_force": sliding, "angle": angles,
            "slide_ratio": float(slide_ratio), "speed": speed, "dt": sim.dt,
            "lubrication_cutoff_gap": lub.cutoff_gap, "lubrication_min_gap": lub.min_gap,
            "n_particles": sim.n_particles, "n_body_particles": sim.n_body_particles,
            "wall_time_s": wallclock.perf_counter() - started, "health": message,
            "healthy": int(ok), "start_gap": start_gap, "sound_speed": sim.sound_speed}


def lattice_shifts(count: int, number_density: float = 4.096) -> list[float]:
    """``count`` shifts [h] spread evenly over one spacing n^(−1/3) of the start lattice."""
    spacing = number_density ** (-1.0 / 3.0)
    return [k * spacing / count for k in range(count)]


def pooled_runs(shifts, **kwargs) -> dict:
    """:func:`squeeze_run` (``kwargs``) at each of ``shifts`` [h], one run per lattice phase,
    with their series joined and ``phase`` the index of each sample's run.

    Why: at gaps below about half a lattice spacing the resolved force of one run depends on
    where the spheres meet the fluid's start lattice, most of all the sliding force (reduced
    size, six shifts 0.1 h apart: 0.32–1.12 of Jeffrey–Onishi at 0.12 h, mean 0.69;
    the squeeze 0.45–0.50). A suspension's fluid is disordered, so the calibration takes the
    mean over phases. Every run covers the same gaps in the same steps, so each phase weighs
    alike in a gap bin. Scalars are the first run's, with the wall times added and the health
    of every run.
    """
    runs = [squeeze_run(shift=shift, **kwargs) for shift in shifts]
    pooled = dict(runs[0])
    for key in ("gap", "force", "sliding_force", "angle"):
        pooled[key] = np.concatenate([run[key] for run in runs])
    pooled["phase"] = np.concatenate([np.full(run["gap"].size, k) for k, run in enumerate(runs)])
    pooled["shifts"] = [float(shift) for shift in shifts]
    pooled["wall_time_s"] = sum(run["wall_time_s"] for run in runs)
    pooled["healthy"] = int(all(run["healthy"] for run in runs))
    pooled["health"] = "; ".join(run["health"] for run in runs)
    return pooled


def phase_means(run: dict, series: str, edges) -> np.ndarray:
    """(phases, bins) bin means of ``run[series]`` for each phase of a :func:`pooled_runs`
    result; NaN where a bin is empty."""
    phase = run["phase"]
    return np.array([bin_series(run["gap"][phase == k], run[series][phase == k], edges)[1]
                     for k in range(int(phase.max()) + 1)])


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
    """Binned SPH squeeze force of a :func:`pooled_runs` result against theory (nominal a and
    hydrodynamic a_h) on ``gap``, with each phase's ratio."""
    box = np.asarray(box, dtype=float)
    edges = gap_edges(radius, end_gap, per_decade)
    centre, mean, error = bin_series(run["gap"], run["force"], edges)
    angle = bin_series(run["gap"], run["angle"], edges)[1]
    keep = np.isfinite(mean)
    centre, mean, error, angle = centre[keep], mean[keep], error[keep], angle[keep]
    speed, a_h = run["speed"], drag["hydrodynamic_radius"]
    distance = centre + 2.0 * radius
    gap_h = distance - 2.0 * a_h
    theory_h = np.where(gap_h > 0, squeeze_theory(np.maximum(gap_h, 1e-9), a_h, viscosity,
                                                  speed, box, angle=angle), np.nan)
    theory = squeeze_theory(centre, radius, viscosity, speed, box, angle=angle)
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
        "phase_ratio_nominal": (("phase", "gap"), phase_means(run, "force", edges)[:, keep]
                                / theory, {"units": "1", "long_name": "F_SPH / F_theory(a) "
                                           "of each lattice phase (pooled_runs)"}),
    }
    slide_ratio = run.get("slide_ratio", 0.0)
    if slide_ratio > 0:
        sliding = bin_series(run["gap"], run["sliding_force"], edges)[1][keep]
        sliding_speed = slide_ratio * speed
        theory_sliding = sliding_theory(centre, radius, viscosity, sliding_speed, box,
                                        angle=angle)
        data.update({
            "sliding_force": ("gap", sliding, {**force_units, "long_name": "SPH force "
                              "resisting the sliding, bin mean"}),
            "theory_sliding_force": ("gap", theory_sliding, {**force_units, "long_name":
                                     "Jeffrey-Onishi sliding force with radius a, periodic "
                                     "images"}),
            "ratio_sliding": ("gap", sliding / theory_sliding, {"units": "1", "long_name":
                              "F_SPH,sliding / F_theory,sliding(a)"}),
            "phase_ratio_sliding": (("phase", "gap"),
                                    phase_means(run, "sliding_force", edges)[:, keep]
                                    / theory_sliding, {"units": "1", "long_name": "the same "
                                                       "for each lattice phase"}),
            "angle": ("gap", angle, {"units": "rad", "long_name": "line of centres from x, "
                      "bin mean"}),
        })
    ds = xr.Dataset(data, coords={
        "gap": ("gap", centre, {**length, "long_name": "nominal surface gap r - 2a, bin mean"}),
        "phase": ("phase", np.asarray(run["shifts"], dtype=float),
                  {**length, "long_name": "shift of the pair along z against the start lattice"})})
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
        "motion": ("prescribed: body velocities reset before every step to +-U along the "
                   f"line of centres and -+{slide_ratio:g} U normal to it in the xy plane"),
        "slide_ratio": slide_ratio,
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
                  numerics: dict | None = None, shifts=(0.0,), **kwargs) -> xr.Dataset:
    """Single-sphere calibration plus the approach runs at the lattice ``shifts`` [h]
    (:func:`pooled_runs`), as one Dataset (module docstring); ``numerics`` scene keys of all
    runs (:func:`squeeze_run`)."""
    if drag is None:
        drag = stokes_drag(radius, box, viscosity=viscosity, reynolds=reynolds,
                           threads=threads, numerics=numerics)
    run = pooled_runs(shifts, radius=radius, box=box, viscosity=viscosity, reynolds=reynolds,
                      threads=threads, end_gap=end_gap, numerics=numerics, **kwargs)
    run["reynolds"] = reynolds
    return squeeze_dataset(run, drag, radius, box, viscosity=viscosity, per_decade=per_decade,
                           end_gap=end_gap)


def reduced() -> bool:
    """True when SUSPSIM_REDUCED=1 (tests run the reduced case)."""
    return os.environ.get("SUSPSIM_REDUCED", "0") == "1"
