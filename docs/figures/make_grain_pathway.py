"""Spheres through the sand pathway: is the low η_r of dense sand shape or pathway? (issue 4)

    python docs/figures/make_grain_pathway.py [--phi 0.5] [--seeds 1 2 3] [--strain 1 4]
        [--pathways sphere grain] [--elongation LOW HIGH] [--out DIR] [--set KEY=VALUE ...]

At φ = 0.5 sand grains read η_r ≈ 7.5 against 13.3 for spheres (make_shape_seeds.py with
``--set run.sound_speed=1.4 --set inclusions.lubrication.min_gap=0.05``). Sand differs from
spheres in two ways: the shape, and the code that handles it — body particles from the
harmonic radius, closest points and osculating spheres for lubrication
(:mod:`suspsim.bodies.grain_contacts`, :mod:`suspsim.bodies.grain_lubrication_pass`). This
script removes the shape: each sphere packing (the one ``suspension_scene`` packs for the seed)
is written again as a sand packing whose grains are those spheres, radius expansions with only
the degree-0 coefficient a_00 = 2√π a (degree 20, the sand default, so every array has the
sand size), the same centres and orientations. For each seed it prints

* the checks: the file reads back as shape sand at the packing's φ, and the body particles of
  the two constructions (shell and full lattice counts, per body);
* step 0 of both pathways on the same relaxed state: pairs within the lubrication cutoff gap,
  the largest gap difference over those pairs, and the lubrication virial σ_xy of one pass;
* the run of each pathway (``--pathways``): η_r ± stderr over the strain units after the
  transient, the CPU time of set-up and run, the largest density error and smallest gap (as
  make_shape_seeds.py), and the time-averaged shear stress over μγ̇ split into the fluid
  (kinetic + pair virial), the body-particle correction and the lubrication + repulsion parts,
  with the mean number of lubricated pairs per step.

``--elongation LOW HIGH`` instead runs real sand grains (``pack_sand`` defaults, elongation
range LOW–HIGH, flatness the same range) through the grain pathway. ``--out`` keeps the packing
files (default: a temporary directory). One thread per run; prints Markdown and writes nothing
else.
"""
import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np

from suspsim.bodies.construction import build_body_particles
from suspsim.bodies.grain_contacts import (C_A, C_B, CONTACT_WIDTH, GAP, INDEX_A, INDEX_B,
                                           RADIUS_A, RADIUS_B, grain_pair_contact)
from suspsim.bodies.grain_lubrication_pass import grain_lubrication_pass
from suspsim.bodies.grains import DEFAULT_DEGREE
from suspsim.bodies.lubrication import curved_squeeze_coefficient_frames
from suspsim.bodies.lubrication_pass import PAIRS, SMALLEST_GAP, lubrication_pass
from suspsim.bodies.packing import Packing, pack_sand
from suspsim.bodies.shapes import radius_bounds, sphere_coefficients, volume
from suspsim.errors import NumericalError
from suspsim.io.packing_file import read_packing, write_packing
from suspsim.sph.boundaries import minimum_image_3d
from suspsim.sph.inclusions import scene_packing
from suspsim.sph.simulation import Simulation
from suspsim.sph.stress import VXY, kinetic_tensor
from suspsim.validation.flows import couette_viscosity_ratio
from suspsim.validation.suspension import (RATE, HealthWatch, add_run_options, overrides_text,
                                           parse_overrides, suspension_scene)

BOX = 16.875
RADIUS = 2.5


def spherical_sand(spheres: Packing) -> Packing:
    """The sphere packing as a sand packing: a_00 = 2√π a only (module docstring)."""
    coefficients = np.stack([sphere_coefficients(a, DEFAULT_DEGREE) for a in spheres.radii])
    volumes = np.array([volume(a) for a in coefficients])
    support = np.array([radius_bounds(a)[1] for a in coefficients])
    return Packing("sand", spheres.box, spheres.centres, spheres.orientations,
                   np.cbrt(volumes * 3.0 / (4.0 * math.pi)), volumes, coefficients, support,
                   spheres.seed, spheres.polydispersity, spheres.size_ratio, spheres.min_gap,
                   {"smallest_gap": spheres.details["smallest_gap"], "degree": DEFAULT_DEGREE})


def compare_particles(spheres: Packing, grains: Packing) -> str:
    """Body particles of both constructions: totals and the bodies whose counts differ."""
    a = build_body_particles(spheres, 4.096)
    b = build_body_particles(grains, 4.096)
    full = int(np.abs(a.particle_count_full - b.particle_count_full).max())
    shell = int(np.abs(a.particle_count_shell - b.particle_count_shell).max())
    same = a.count == b.count and np.allclose(a.offsets, b.offsets, atol=1e-12)
    return (f"particles: sphere shell {a.count}, full {a.particle_count_full.sum()}; grain "
            f"shell {b.count}, full {b.particle_count_full.sum()}; largest per-body difference "
            f"shell {shell}, full {full}; same offsets {same}; moments differ by "
            f"{np.abs(a.principal_moments - b.principal_moments).max():.2e} m h²")


def step_zero(sphere_sim: Simulation, grain_sim: Simulation) -> str:
    """Pairs, gaps and one lubrication pass of both pathways on the sphere run's first state."""
    cutoff, min_gap, strength, friction, rolling, _, surfaces = grain_sim._lubrication
    bodies = sphere_sim.bodies
    centres, box = bodies.centres, sphere_sim._box
    radii = sphere_sim._body_radii
    rotations = grain_sim.bodies.rotations()
    contact = np.zeros(CONTACT_WIDTH)
    rows = []
    for p in range(bodies.count):
        for q in range(p + 1, bodies.count):
            dx, dy, dz, _ = minimum_image_3d(*(centres[p] - centres[q]), *box[:3], 0.0)
            sphere_gap = math.sqrt(dx * dx + dy * dy + dz * dz) - radii[p] - radii[q]
            r12 = np.array([dx, dy, dz])
            found = grain_pair_contact(p, q, r12, rotations[p], rotations[q], surfaces.points,
                                       surfaces.normals, surfaces.osculating, surfaces.tables,
                                       surfaces.to_packing, surfaces.centroids, surfaces.reach,
                                       cutoff, contact)
            grain_gap = contact[GAP] if found else math.inf
            if min(sphere_gap, grain_gap) < cutoff:
                rows.append((sphere_gap, grain_gap))
    rows = np.array(rows)
    in_sphere = int((rows[:, 0] < cutoff).sum())
    in_grain = int((rows[:, 1] < cutoff).sum())
    both = (rows[:, 0] < cutoff) & (rows[:, 1] < cutoff)
    virials = []
    for sim, grains in ((sphere_sim, False), (grain_sim, True)):
        b = sim.bodies
        velocities, omegas = b.velocities.copy(), b.angular_velocities().copy()
        virial, stats = np.zeros(5), np.zeros(3)
        law = sim.scene.fluid.law
        if grains:
            sf = surfaces
            grain_lubrication_pass(b.centres, b.rotations(), velocities, omegas, b.mass,
                                   b.moments, box, 0.0, sim._rate, sim.dt, law.code, law.packed,
                                   cutoff, min_gap, strength, friction, rolling, sf.points,
                                   sf.normals, sf.first_directions, sf.osculating,
                                   sf.principal_curvatures, sf.tables, sf.to_packing,
                                   sf.centroids, sf.reach, virial, stats)
        else:
            lubrication_pass(b.centres, sim._body_radii, velocities, omegas, b.mass,
                             b.moments.mean(axis=1), box, 0.0, sim._rate, sim.dt, law.code,
                             law.packed, cutoff, min_gap, strength, friction, rolling,
                             virial, stats)
        scale = float(law.viscosity(sim._rate)) * sim._rate * sim.scene.volume
        virials.append((-virial[VXY] / scale, int(stats[PAIRS]), stats[SMALLEST_GAP]))
    return (f"step 0: pairs within s_c = {cutoff} h: sphere {in_sphere}, grain {in_grain}; "
            f"largest |gap difference| {np.abs(rows[both, 0] - rows[both, 1]).max():.2e} h; "
            f"smallest gap sphere {rows[:, 0].min():.4f}, grain {rows[:, 1].min():.4f} h; "
            f"one pass σ_xy/(μγ̇): sphere {virials[0][0]:.4g} ({virials[0][1]} pairs), "
            f"grain {virials[1][0]:.4g} ({virials[1][1]} pairs)")


def contact_law(grain_sim: Simulation) -> str:
    """At step 0, over the grain pairs within the cutoff gap: the osculating radii R/a and the
    squeeze coefficient c1 (SPEC §3.4) over that of two spheres of the grains' equivalent
    radii, c1 = 6π (a1 a2/(a1 + a2))²: what the grain pathway makes of the shape."""
    cutoff, sf = grain_sim._lubrication.cutoff_gap, grain_sim._lubrication.surfaces
    b, box, radii = grain_sim.bodies, grain_sim._box, grain_sim._body_radii
    rotations = b.rotations()
    contact = np.zeros(CONTACT_WIDTH)
    osculating, ratios = [], []
    for p in range(b.count):
        for q in range(p + 1, b.count):
            dx, dy, dz, _ = minimum_image_3d(*(b.centres[p] - b.centres[q]), *box[:3], 0.0)
            r12 = np.array([dx, dy, dz])
            if not grain_pair_contact(p, q, r12, rotations[p], rotations[q], sf.points,
                                      sf.normals, sf.osculating, sf.tables, sf.to_packing,
                                      sf.centroids, sf.reach, cutoff, contact):
                continue
            if contact[GAP] >= cutoff:
                continue
            ka, kb = int(contact[INDEX_A]), int(contact[INDEX_B])
            centre_a = contact[C_A:C_A + 3]
            centre_b = contact[C_B:C_B + 3]
            normal = r12 + centre_a - centre_b
            normal = -normal / np.linalg.norm(normal)
            c1 = curved_squeeze_coefficient_frames(
                *sf.principal_curvatures[p, ka], rotations[p] @ sf.first_directions[p, ka],
                *sf.principal_curvatures[q, kb], rotations[q] @ sf.first_directions[q, kb],
                normal)
            reduced = radii[p] * radii[q] / (radii[p] + radii[q])
            ratios.append(c1 / (6.0 * math.pi * reduced ** 2))
            osculating += [contact[RADIUS_A] / radii[p], contact[RADIUS_B] / radii[q]]
    ratios, osculating = np.array(ratios), np.array(osculating)
    return (f"step 0 contact law, {len(ratios)} pairs within s_c: osculating R/a median "
            f"{np.median(osculating):.3f} (quartiles {np.quantile(osculating, 0.25):.3f}, "
            f"{np.quantile(osculating, 0.75):.3f}); c1/c1(spheres) median "
            f"{np.median(ratios):.3f}, mean {ratios.mean():.3f} (quartiles "
            f"{np.quantile(ratios, 0.25):.3f}, {np.quantile(ratios, 0.75):.3f})")


class StressSplit:
    """The health watch of suspension.py plus σ_xy/(μγ̇) by part, sampled after the
    transient (the same samples couette_viscosity_ratio averages)."""

    def __init__(self, transient_time: float) -> None:
        self.watch = HealthWatch()
        self.transient_time = transient_time
        self.parts: list[tuple[float, float, float, float]] = []

    def __call__(self, sim: Simulation) -> None:
        self.watch(sim)
        if sim.time <= self.transient_time * (1.0 + 1e-9):
            return
        scale = float(sim.scene.fluid.law.viscosity(sim._rate)) * sim._rate * sim.scene.volume
        fluid = kinetic_tensor(sim._peculiar(), sim._mass) + sim._virial.sum(axis=0)
        self.parts.append((-fluid[VXY] / scale, -sim._body_virial[VXY] / scale,
                           -sim._lubrication_virial[VXY] / scale,
                           sim._lubrication_stats[PAIRS]))


def run(scene, transient: float, units: int) -> tuple[str, float]:
    """One run (η_r row of the table) and its η_r."""
    started = time.process_time()
    sim = Simulation(scene, threads=1)
    split = StressSplit(transient / RATE)
    reading = couette_viscosity_ratio(sim, transient=transient, units=units, on_sample=split)
    cpu = time.process_time() - started
    fluid, body, lub, pairs = np.mean(split.parts, axis=0)
    w = split.watch
    return (f"{1.0 + reading.value:.3f} ± {reading.stderr:.3f} | {cpu:.0f} | "
            f"{w.density_error:.3f} | {w.smallest_gap:.3f} | {fluid:.3f} | {body:.3f} | "
            f"{lub:.3f} | {pairs:.1f} |"), 1.0 + reading.value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--phi", type=float, default=0.5)
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    parser.add_argument("--pathways", nargs="+", default=["sphere", "grain"],
                        choices=("sphere", "grain"))
    parser.add_argument("--elongation", type=float, nargs=2, default=None,
                        metavar=("LOW", "HIGH"))
    parser.add_argument("--roughness", type=float, default=None,
                        help="with --elongation: grain roughness (default: pack_sand's)")
    parser.add_argument("--no-run", action="store_true",
                        help="checks and step-0 diagnostics only")
    parser.add_argument("--out", default=None, help="directory for the packing files")
    add_run_options(parser)
    args = parser.parse_args()
    transient, units = args.strain[0], int(args.strain[1])
    overrides = parse_overrides(args.set)
    out = Path(args.out or tempfile.mkdtemp(prefix="grain_pathway_"))
    out.mkdir(parents=True, exist_ok=True)
    settings = overrides_text(overrides)
    print(f"φ = {args.phi}, box {BOX} h, a = {RADIUS} h, strain {transient:g} + {units}"
          f"{settings}; packings in {out}", flush=True)
    rows = []
    for seed in args.seeds:
        spheres = scene_packing(suspension_scene(shape="sphere", phi=args.phi, radius=RADIUS,
                                                 box=BOX, seed=seed, overrides=overrides))
        if args.elongation is not None:
            shape = {"elongation_range": tuple(args.elongation)}
            if args.roughness is not None:
                shape["roughness"] = args.roughness
            grains = pack_sand([BOX] * 3, args.phi, RADIUS, seed=seed, min_gap=spheres.min_gap,
                               **shape)
            label = (f"sand {args.elongation[0]:g}–{args.elongation[1]:g} roughness "
                     f"{grains.details['roughness']:g}")
        else:
            grains = spherical_sand(spheres)
            label = "grain"
        tag = ("spherical-sand" if args.elongation is None else
               f"sand-elongation{args.elongation[0]:g}-{args.elongation[1]:g}"
               f"-roughness{grains.details['roughness']:g}")
        path = out / f"{tag}_phi{args.phi:g}_seed{seed}.nc"
        write_packing(path, grains)
        back = read_packing(path)
        print(f"\nseed {seed}: {path.name} reads back as {back.shape}, {back.count} bodies, "
              f"φ = {back.volume_fraction:.6f} (spheres {spheres.volume_fraction:.6f})",
              flush=True)
        scenes = {"sphere": suspension_scene(shape="sphere", phi=args.phi, radius=RADIUS,
                                             box=BOX, seed=seed, strain=transient + units,
                                             overrides=overrides),
                  "grain": suspension_scene(shape="sand", phi=args.phi, radius=RADIUS, box=BOX,
                                            seed=seed, strain=transient + units,
                                            overrides={**overrides,
                                                       "inclusions.packing": str(path)})}
        if args.elongation is None:
            print(compare_particles(spheres, back), flush=True)
            grain_sim = Simulation(scenes["grain"], threads=1)
            print(step_zero(Simulation(scenes["sphere"], threads=1), grain_sim), flush=True)
            pathways = args.pathways
        else:
            grain_sim = Simulation(scenes["grain"], threads=1)
            pathways = ["grain"]
        print(contact_law(grain_sim), flush=True)
        if args.no_run:
            continue
        for pathway in pathways:
            name = label if pathway == "grain" else "sphere"
            try:
                row, _ = run(scenes[pathway], transient, units)
            except NumericalError as err:
                row = f"stopped: {err} | | | | | | | |"
            rows.append(f"| {seed} | {name} | {row}")
            print(rows[-1], flush=True)
    print("\n| seed | pathway | η_r | CPU [s] | density error | smallest gap [h] | fluid | "
          "body | lubrication | pairs |\n|---|---|---|---|---|---|---|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
