"""The SPH fluid simulation: one scene, its particles and buffers, advanced in compiled code.

:class:`Simulation` builds the lattice (``lattice``), picks the sound speed and time step
(``timestep``, or the scene's values), allocates every buffer once, and advances with the
Groot–Warren integrator (``integrator``). Only what the scene needs is computed: the velocity
gradient pass runs for a non-Newtonian law or the dissipation normalisation, the normalisation
pass when ``numerics.viscous_normalisation`` is on (for a Newtonian fluid, whose only use of
both is the factor s, every ``numerics.normalisation_interval`` steps), the ∇a sums when
``numerics.bulk_correction`` is on and μ varies. Couette flow uses Lees–Edwards boundaries; Poiseuille a periodic box with
the split body force (SPEC §2.7).

Rigid inclusions (``scene.inclusions``, SPEC §3): :mod:`~suspsim.sph.inclusions` builds the
fluid and body particles; the bodies' state (:class:`~suspsim.bodies.system.RigidBodies`)
advances beside the fluid's in a Python step loop that calls the same compiled passes, places
the body particles rigidly (:mod:`~suspsim.bodies.coupling`) and sums their forces and torques.
A scene without inclusions keeps the fully compiled loop and none of this.

Particles are reordered (cell sort) and wrapped into the box at every neighbour-list rebuild,
so per-particle arrays have no fixed identity. :meth:`Simulation.state` holds everything needed
to continue bit for bit, including the positions at the last build (the list is rebuilt from
them) and the chunk count of the pair passes, which fixes the summation order whatever the
thread count of the resumed run.
"""
from __future__ import annotations

import contextlib
import dataclasses
import logging
import time as time_module
from typing import Any, NamedTuple

import numba
import numpy as np

from suspsim.analysis.orientation import nematic_order, spin_ratio
from suspsim.bodies.coupling import body_force_torque, place_body_particles
from suspsim.bodies.grain_contacts import grain_surfaces
from suspsim.bodies.grain_lubrication_pass import grain_lubrication_pass
from suspsim.bodies.lubrication_pass import OVERLAPS, SMALLEST_GAP, lubrication_pass
from suspsim.errors import NumericalError
from suspsim.rheology.laws import make_law
from suspsim.scene import Scene
from suspsim.sph import kernels
from suspsim.sph.boundaries import lees_edwards_offset
from suspsim.sph.density import (TABLE_OK, allocate_pair_table, fluid_mean_density,
                                 pair_capacity)
from suspsim.sph.health import density_verdict
from suspsim.sph.integrator import (GROW_TABLE, REBUILD, accelerations, advance_steps, drift,
                                    kick, predict)
from suspsim.sph.lattice import imposed_velocity, initial_velocities, lattice_positions
from suspsim.sph.list_validity import MAX_CHECKED_OUTLIERS, list_outdated, needs_rebuild
from suspsim.sph.neighbours import (NeighbourListOverflowError, allocate_neighbour_list,
                                    build_neighbour_list, raise_for_code,
                                    rebuild_neighbour_list, sort_by_cell)
from suspsim.sph.stress import mean_pressure, pressure_tensor, shear_stress
from suspsim.sph.terms.force_pass import VXY, concentration_column, force_width
from suspsim.sph.terms.shifting import shift_particles
from suspsim.sph.terms.velocity_pass import GRADIENT_WIDTH
from suspsim.sph.terms.viscous import bulk_factor, viscous_weights
from suspsim.sph.timestep import auto_sound_speed, max_viscosity, stable_time_step
from suspsim.threads import use_threads

log = logging.getLogger(__name__)


class LubricationSetup(NamedTuple):
    """What the lubrication pass of a run takes from its scene (``inclusions.lubrication``):
    cutoff gap s_c and inner cap s_min [h], repulsion strength C = k μ(γ̇) γ̇ ā² s_min⁸ (ā the
    bodies' mean radius), sliding and rolling friction μ_c, μ_r [1], the bodies' scalar moments
    of inertia [m h²] and, for grains, their surface samples (``bodies.grain_contacts``)."""

    cutoff_gap: float
    min_gap: float
    strength: float
    friction: float
    rolling_friction: float
    inertia: np.ndarray
    surfaces: Any


#: Verlet skin [h] (list cutoff h + skin) [choice; the foundation's benchmark value].
SKIN = 0.2
#: Support radius in scene units.
SUPPORT = 1.0
#: Neighbour-list slots per ideal-gas pair within h + skin [choice]: a fluid lists 0.91 of them
#: (benchmark box), so 1.2 leaves 30 %; an overflow grows the list and repeats the build.
LIST_CAPACITY = 1.2
#: Velocity damping per relaxation step [1] and steps between its density checks [choice].
RELAX_DAMPING = 0.05
RELAX_CHECK = 10
#: Per-particle arrays of :meth:`Simulation.state` (name → attribute).
_STATE_ARRAYS = {"positions": "_x", "velocities": "_v", "accelerations": "_a",
                 "density": "_rho", "shear_rate": "_gdot", "viscosity": "_mu",
                 "normalisation_factor": "_factor", "viscosity_hat": "_mu_hat",
                 "velocity_gradient": "_gradient", "inverse_moment": "_inverse_moment",
                 "virial": "_virial", "reference": "_reference", "body_of": "_body_of",
                 "body_offsets": "_offsets"}


class Simulation:
    """An SPH fluid run of ``scene`` (see the module docstring); ``threads`` None: the scene's."""

    def __init__(self, scene: Scene, *, threads: int | None = None, _state: dict | None = None):
        self.scene = scene
        requested = threads if threads is not None else scene.run.threads
        self.threads = int(min(requested or numba.config.NUMBA_NUM_THREADS,
                               numba.config.NUMBA_NUM_THREADS))
        self._n_chunks = int(_state["n_chunks"]) if _state is not None else self.threads
        law = scene.fluid.law
        self._law = law
        self._newtonian = bool(law.is_newtonian)
        self._normalise = bool(scene.numerics.viscous_normalisation)
        self._spin_correction = bool(scene.numerics.spin_correction)
        # the spin-corrected pair sum is already the divergence of its stress (viscous.local_spin)
        self._bulk_gradient = (bool(scene.numerics.bulk_correction) and not self._newtonian
                               and not self._spin_correction)
        self._velocity_gradient = (not self._newtonian) or self._normalise or self._spin_correction
        self._alpha, self._beta = viscous_weights(scene.dimension, scene.numerics.bulk_correction,
                                                  self._spin_correction)
        self._bulk_factor = bulk_factor(scene.dimension)
        self._box = np.array([*scene.box, *([1.0] if scene.dimension == 2 else [])], dtype=float)
        self._kernel = kernels.kernel_code(scene.kernel, scene.dimension)
        self._rate = scene.flow.shear_rate if scene.flow.type == "couette" else 0.0
        self._body_force = scene.flow.body_force if scene.flow.type == "poiseuille" else 0.0
        self._mass = scene.mass
        self.bodies = None
        self.packing = None
        self._grains = None
        reference_count = None
        if _state is not None:
            positions, velocities = _state["positions"], _state["velocities"]
            if "bodies" in _state:
                from suspsim.bodies.system import RigidBodies

                self.bodies = RigidBodies.from_state(_state["bodies"])
                self._body_volume = float(_state["body_volume"])
                self._body_radii = np.asarray(_state["body_radii"], dtype=float)
                reference_count = int(_state["reference_count"])
                if "grains" in _state:
                    self._grains = {key: np.asarray(value, dtype=float)
                                    for key, value in _state["grains"].items()}
        elif scene.inclusions.present:
            from suspsim.sph.inclusions import build_inclusions

            setup = build_inclusions(scene)
            positions, velocities = setup.positions, setup.velocities
            self.bodies, self.packing = setup.bodies, setup.packing
            self._body_volume = float(setup.packing.volumes.sum())
            self._body_radii = np.asarray(setup.packing.radii, dtype=float)
            reference_count = setup.reference_count
            if setup.packing.coefficients is not None:
                self._grains = {"coefficients": setup.packing.coefficients,
                                "support_radii": setup.packing.support_radii,
                                "centre_shift": setup.centre_shift,
                                "body_to_principal": setup.body_to_principal}
        else:
            positions = lattice_positions(scene)
            velocities = initial_velocities(scene, positions)
        self.n_particles = int(positions.shape[0])
        self._rho_eq = (reference_count or self.n_particles) * self._mass / scene.volume
        self._lubrication = self._lubrication_setup()
        # Shifting acts only with a rate scale (numerics.shifting_rate; auto: the imposed rate).
        self._shifting_rate = float(scene.numerics.shifting_rate)
        self._shifting = float(scene.numerics.shifting) if self._shifting_rate > 0.0 else 0.0
        self._tangential_shift = (self.bodies is not None
                                  and scene.numerics.shifting_at_bodies == "tangential")
        self._mean_reference = scene.numerics.pressure_reference == "fluid_mean"
        self._smooth_rate = bool(scene.numerics.rate_smoothing)
        if _state is None:
            self.sound_speed = (float(scene.run.sound_speed) if scene.run.sound_speed is not None
                                else auto_sound_speed(scene, self.packing_phi))
            self.dt = (float(scene.run.dt) if scene.run.dt is not None
                       else stable_time_step(scene, self.sound_speed))
            self.step_count = 0
            self._build_time = 0.0
        else:
            self.sound_speed = float(_state["sound_speed"])
            self.dt = float(_state["dt"])
            self.step_count = int(_state["step_count"])
            self._build_time = float(_state["build_time"])
        self.rebuild_count = 0
        self.rebuild_seconds = 0.0
        self._allocate(positions, velocities, capacity_factor=LIST_CAPACITY)
        if _state is None and self.bodies is not None:
            self._body_of[:] = setup.body_of
            self._offsets[:] = setup.offsets
            # A body particle's μ̂ is the fluid's beside it; one without fluid neighbours keeps
            # its value (``density.body_particle_density``), so it starts at the imposed rate's.
            self._mu_hat[self._body_of >= 0] = float(scene.fluid.law.viscosity(self._rate))
        if _state is None:
            self._rebuild(0.0)
            if scene.lattice.relax:
                self.relax(scene.lattice.relax_tolerance, scene.lattice.relax_max_steps)
            if self._mean_reference:
                self._compute_accelerations(self._v, self._a)
                self._rho_eq = self._fluid_mean_density()
            self._compute_accelerations(self._v, self._a)
            if self.bodies is not None:
                self.bodies.set_forces(*self._body_forces(self.bodies.rotations()))
        else:
            for name, attribute in _STATE_ARRAYS.items():
                target = getattr(self, attribute)
                if target.size:  # body offsets of a run without bodies: empty
                    target[...] = _state[name]
            if self.bodies is not None:
                self._body_virial[:] = _state["body_virial"]
                self._lubrication_virial[:] = _state["lubrication_virial"]
            self._relist_from_reference()
            self._members = np.flatnonzero(self._body_of >= 0)
            self._rho_eq = float(_state.get("rho_eq", self._rho_eq))
            self._normalisation_age[0] = int(_state.get("normalisation_age", 0))
        log.info("simulation: %d particles, dt = %.4g, c = %.4g, %d chunk(s) on %d thread(s)",
                 self.n_particles, self.dt, self.sound_speed, self._n_chunks, self.threads)

    # ------------------------------------------------------------------ set-up
    def _allocate(self, positions, velocities, capacity_factor: float) -> None:
        n, t = self.n_particles, self._n_chunks
        self._x = np.ascontiguousarray(positions, dtype=float).copy()
        self._v = np.ascontiguousarray(velocities, dtype=float).copy()
        self._a = np.zeros((n, 3))
        self._a_new = np.zeros((n, 3))
        self._v_pred = np.zeros((n, 3))
        self._rho = np.zeros(n)
        self._volume = np.zeros(n)
        self._strain = np.zeros((n, 6))
        self._dissipation = np.zeros(n)
        self._gdot = np.zeros(n)
        viscosity = float(self.scene.fluid.law.viscosity(0.0))
        self._mu = np.full(n, viscosity)
        self._mu_hat = np.full(n, viscosity)
        self._factor = np.ones(n)
        # Steps still to hold s (``velocity_pass.normalisation_due``); 0: update on the next.
        self._normalisation_age = np.zeros(1, dtype=np.int64)
        self._gradient = np.zeros((n, 9))
        self._inverse_moment = np.zeros((n, 6))
        self._moment_trace = np.zeros(n)
        # The passes' accumulators and chunk buffers live one pass each (density → body
        # density → gradient → smoothing → dissipation → force → body forces → shifting, one
        # after the other), so the narrower ones, and the force pass's pressure and spin
        # scratch, are views of the 15-wide ones: 176 bytes per particle and chunk fewer. The
        # force sums stay readable until the next step (bodies and shifting read them).
        self._grad_acc = np.zeros(n * GRADIENT_WIDTH)
        self._diss_acc = self._grad_acc[(GRADIENT_WIDTH - 1) * n:]
        self._scratch_15 = np.zeros((t - 1, n * GRADIENT_WIDTH))
        self._scratch_1 = self._scratch_15.reshape(-1)[:(t - 1) * n].reshape(t - 1, n)
        self._force_views()
        self._bounds = np.zeros(t + 1, dtype=np.int64)
        self._virial = np.zeros((t, 5))
        self._body_of = np.full(n, -1, dtype=np.int64)
        self._offsets = np.zeros((n if self.bodies is not None else 0, 3))
        # The bodies' angular velocities at the force pass's time level (``_place_bodies``).
        self._body_spin = (self.bodies.angular_velocities() if self.bodies is not None
                           else np.zeros((1, 3)))
        self._members = np.zeros(0, dtype=np.int64)
        self._body_virial = np.zeros(5)
        self._lubrication_virial = np.zeros(5)
        self._lubrication_stats = np.array([np.inf, 0.0, 0.0])
        self._allocate_list(capacity_factor)
        self._table = allocate_pair_table(n, pair_capacity(
            n, self.scene.number_density, SUPPORT, self.scene.dimension,
            self._nlist.neighbours.shape[0]))

    def _force_views(self) -> None:
        """The force pass's accumulator, chunk buffers and pressure scratch as views of the
        gradient pass's, :func:`~suspsim.sph.terms.force_pass.force_width` values per particle
        for the current bulk-gradient and shifting settings."""
        n, rows = self.n_particles, self._scratch_15.shape[0]
        width = force_width(self._bulk_gradient, self._shifting > 0.0, self._tangential_shift)
        self._force_width = width
        self._force_acc = self._grad_acc[:n * width]
        self._pressure = self._grad_acc[width * n:(width + 1) * n]
        # The spin correction holds no bulk gradient, so its width leaves room for the spins.
        spins = self._grad_acc[(width + 1) * n:(width + 4) * n]
        self._spin = spins.reshape(n, 3) if spins.shape[0] == 3 * n else np.zeros((n, 3))
        self._force_scratch = self._scratch_15.reshape(-1)[:rows * n * width].reshape(
            rows, n * width)

    def _allocate_list(self, capacity_factor: float) -> None:
        self._nlist = allocate_neighbour_list(self.n_particles, self._box, SUPPORT, SKIN,
                                              self.scene.dimension, self.scene.number_density,
                                              capacity_factor=capacity_factor)
        self._reference = self._nlist.reference
        self._capacity_factor = capacity_factor

    def _grow_table(self) -> None:
        """A pair table 1.15 × larger (at most a row per listed pair, which cannot overflow)."""
        rows = min(int(1.15 * self._table.pair_j.shape[0]) + 64,
                   int(self._nlist.neighbours.shape[0]))
        log.info("pair table overflow; %d rows (%.1f per particle)", rows,
                 rows / self.n_particles)
        self._table = allocate_pair_table(self.n_particles, rows)

    def _offset(self, time: float) -> float:
        return float(lees_edwards_offset(self._rate, self._box[0], self._box[1], time))

    def _permuted_arrays(self) -> tuple:
        """Particle arrays a rebuild reorders besides x and v. With bodies also their offsets
        and μ̂ (the next step's body particles average the fluid's, and keep their own without
        fluid beside them: ``density.body_particle_density``)."""
        return (self._a, self._body_of) + ((self._offsets, self._mu_hat)
                                           if self.bodies is not None else ())

    def _rebuild(self, time: float) -> None:
        """Wrap, sort and list at ``time``; grows the list once per overflow."""
        started = time_module.perf_counter()
        while True:
            try:
                rebuild_neighbour_list(self._nlist, self._x, self._v, self._box,
                                       self._offset(time), self._rate,
                                       particle_arrays=self._permuted_arrays(),
                                       group=self._body_of if self.bodies is not None else None)
                break
            except NeighbourListOverflowError as err:
                factor = 1.3 * err.required / err.capacity * self._capacity_factor
                log.info("neighbour list overflow; capacity factor %.3g", factor)
                self._allocate_list(factor)
        self._build_time = time
        # The held s is per particle, and the rebuild reordered the particles.
        self._normalisation_age[0] = 0
        if self.bodies is not None:
            self._members = np.flatnonzero(self._body_of >= 0)
            self.bodies.wrap(self._box, self._offset(time), self._rate)
        self.rebuild_count += 1
        self.rebuild_seconds += time_module.perf_counter() - started

    def _relist_from_reference(self) -> None:
        """Rebuild the list of the last build from its (sorted) positions, without reordering."""
        nl, box = self._nlist, self._box
        sort_by_cell(self._reference, box, nl.cells, nl.cell_of, nl.order, nl.cell_start)
        if not np.array_equal(nl.order, np.arange(self.n_particles)):
            raise ValueError("state: the reference positions are not in cell order")
        code, n_pairs = build_neighbour_list(self._reference, box, self._offset(self._build_time),
                                             nl.cutoff, nl.cells, nl.cell_start, nl.start,
                                             nl.image_start, nl.neighbours, True,
                                             group=self._body_of if self.bodies is not None
                                             else None)
        raise_for_code(code, n_pairs, nl.neighbours.shape[0])
        nl.n_pairs = int(n_pairs)

    def _physics_args(self):
        s, nl, tb = self.scene, self._nlist, self._table
        return (self._box, nl.start, nl.image_start, nl.neighbours, self._kernel, SUPPORT,
                self._mass, self._rho_eq, self.sound_speed ** 2, self._rate, self._body_force,
                s.dimension, self._law.code, self._law.packed, self._newtonian,
                self._velocity_gradient, self._smooth_rate, self._normalise,
                self.scene.numerics.normalisation_interval, self._normalisation_age, self._alpha,
                self._beta, self._bulk_factor, self._bulk_gradient, self.bodies is not None,
                self._body_of, self._body_spin, self._spin_correction, self._rho, self._volume,
                self._pressure, self._spin, tb.pair_start, tb.pair_end, tb.pair_j,
                tb.pair_geometry, tb.pair_cross, tb.pair_image, self._gradient,
                self._inverse_moment, self._moment_trace, self._strain, self._dissipation,
                self._gdot, self._mu, self._factor, self._mu_hat, self._grad_acc,
                self._diss_acc, self._force_acc, self._scratch_1, self._scratch_15,
                self._force_scratch, self._bounds, self._virial)

    def _compute_accelerations(self, predicted, out, time: float | None = None) -> None:
        """a = f(x, ``predicted``)/m into ``out`` at ``time`` (default: now), growing the pair
        table until it holds the step's pairs."""
        use_threads(self.threads)
        offset = self._offset(self.time if time is None else time)
        while True:
            box, *rest = self._physics_args()
            if accelerations(self._x, predicted, box, offset, *rest, out) == TABLE_OK:
                return
            self._grow_table()

    # ------------------------------------------------------------------ API
    @property
    def time(self) -> float:
        """Simulated time step_count · δt [τ]."""
        return self.step_count * self.dt

    @property
    def strain(self) -> float:
        """γ̇ · time for Couette, 0 otherwise."""
        return self._rate * self.time

    def advance(self, n_steps: int) -> None:
        """Run ``n_steps`` steps in compiled code; Python only rebuilds the neighbour list."""
        use_threads(self.threads)
        if self.bodies is not None or self._shifting > 0.0 or self._mean_reference:
            self._advance_python(int(n_steps))
            return
        remaining, resume = int(n_steps), False
        nl = self._nlist
        while remaining > 0:
            box, *physics = self._physics_args()
            done, stop = advance_steps(
                remaining, resume, self.step_count, self.dt, self._build_time, nl.cutoff,
                nl.skin, self._reference, nl.cells, nl.cell_start, self._x, self._v, self._a,
                self._v_pred, self._a_new, box, *physics)
            self.step_count += int(done)
            remaining -= int(done)
            resume = stop in (REBUILD, GROW_TABLE)
            if stop == REBUILD:
                self._rebuild((self.step_count + 1) * self.dt)
                nl = self._nlist
            elif stop == GROW_TABLE:
                self._grow_table()

    @property
    def n_body_particles(self) -> int:
        """SPH particles in the bodies' shells (0 without inclusions)."""
        return int(self._members.shape[0])

    @property
    def packing_phi(self) -> float:
        """Solid volume fraction Σ V_b / V of the bodies (0 without inclusions)."""
        return 0.0 if self.bodies is None else float(self._body_volume / self.scene.volume)

    def _place_bodies(self, rotations, velocities, omegas, time: float, out) -> None:
        """Body particles at their rigid positions (``rotations`` (B, 3, 3) of the bodies'
        current orientations); their velocities into ``out``, and ``omegas`` into the force
        pass's body spins."""
        self._body_spin[:] = omegas
        place_body_particles(self._members, self._body_of, self._offsets, self.bodies.centres,
                             rotations, velocities, omegas, self._box, self._offset(time),
                             self._rate, self._x, out)

    def _body_forces(self, rotations) -> tuple[np.ndarray, np.ndarray]:
        """(F, T) of every body from the last force pass; updates the stress correction."""
        b = self.bodies.count
        forces, torques = np.zeros((b, 3)), np.zeros((b, 3))
        body_force_torque(self._members, self._body_of, self._offsets, rotations,
                          self._force_acc, self._force_width, forces, torques,
                          self._body_virial)
        return forces, torques

    def _lubrication_setup(self) -> LubricationSetup | None:
        """The :class:`LubricationSetup` of the scene, None without bodies or lubrication."""
        spec = self.scene.inclusions.lubrication
        if self.bodies is None or not spec.enabled:
            return None
        rate = self._rate
        strength = (spec.repulsion * float(self.scene.fluid.law.viscosity(rate)) * rate
                    * float(np.mean(self._body_radii)) ** 2 * spec.min_gap ** 8)
        surfaces = None
        if self._grains is not None:
            g = self._grains
            surfaces = grain_surfaces(g["coefficients"], self._body_radii, g["support_radii"],
                                      g["centre_shift"], g["body_to_principal"])
        return LubricationSetup(spec.cutoff_gap, spec.min_gap, strength, spec.friction,
                                spec.rolling_friction, self.bodies.moments.mean(axis=1),
                                surfaces)

    def _lubricate(self, time: float, rotations) -> None:
        """Implicit lubrication impulses on the kicked bodies (``bodies.lubrication_pass``;
        grains at their closest points, ``bodies.grain_lubrication_pass``, with ``rotations``
        the step's orientations (B, 3, 3))."""
        bodies, law = self.bodies, self.scene.fluid.law
        cutoff, min_gap, strength, friction, rolling, inertia, surfaces = self._lubrication
        omegas = bodies.angular_velocities()
        if surfaces is None:
            lubrication_pass(bodies.centres, self._body_radii, bodies.velocities, omegas,
                             bodies.mass, inertia, self._box, self._offset(time), self._rate,
                             self.dt, law.code, law.packed, cutoff, min_gap, strength,
                             friction, rolling, self._lubrication_virial,
                             self._lubrication_stats)
        else:
            sf = surfaces
            grain_lubrication_pass(bodies.centres, rotations, bodies.velocities, omegas,
                                   bodies.mass, bodies.moments, self._box, self._offset(time),
                                   self._rate, self.dt, law.code, law.packed, cutoff, min_gap,
                                   strength, friction, rolling, sf.points, sf.normals,
                                   sf.first_directions, sf.osculating, sf.principal_curvatures,
                                   sf.tables, sf.to_packing, sf.centroids, sf.reach,
                                   self._lubrication_virial, self._lubrication_stats)
        bodies.set_angular_velocities(omegas)

    def _advance_python(self, n_steps: int) -> None:
        """The step of :mod:`~suspsim.sph.integrator` with rigid bodies or shifting (module
        docstrings of ``integrator``, ``bodies.system``, ``terms.shifting``): drift fluid and
        bodies, predict, place the body particles with the predicted body motion, rebuild if
        needed (and predict and place again), forces, kick both, lubrication, shift; with the
        fluid_mean pressure reference ρ_0 becomes the step's mean fluid density (used from the
        next step on)."""
        bodies, dt = self.bodies, self.dt
        for _ in range(n_steps):
            time = (self.step_count + 1) * self.dt
            drift(self._x, self._v, self._a, dt)
            predict(self._v, self._a, dt, self._v_pred)
            if bodies is not None:
                bodies.drift(dt)
                # Orientations change only in the drift: one set of rotations for the step.
                rotations = bodies.rotations()
                predicted = bodies.predicted(dt)
                self._place_bodies(rotations, *predicted, time, self._v_pred)
            nl = self._nlist
            if list_outdated(self._x, self._reference, self._rate * (time - self._build_time),
                             nl.cutoff, nl.skin, 0.5 * self._box[1], self._box,
                             self._offset(time), nl.cells, nl.cell_start, nl.start,
                             nl.neighbours, self._body_of, MAX_CHECKED_OUTLIERS):
                self._rebuild(time)
                # The rebuild wrapped and reordered x, v and a, not ṽ.
                predict(self._v, self._a, dt, self._v_pred)
                if bodies is not None:
                    self._place_bodies(rotations, *predicted, time, self._v_pred)
            self._compute_accelerations(self._v_pred, self._a_new, time)
            kick(self._v, self._a, self._a_new, dt)
            if bodies is not None:
                bodies.kick(*self._body_forces(rotations), dt)
                if self._lubrication is not None:
                    self._lubricate(time, rotations)
                self._place_bodies(rotations, bodies.velocities, bodies.angular_velocities(),
                                   time, self._v)
            if self._shifting > 0.0:
                shift_particles(self._force_acc, concentration_column(self._bulk_gradient),
                                self._tangential_shift, self._body_of, self._shifting,
                                self._shifting_rate, dt, SUPPORT, self._gradient, self._x,
                                self._v)
            if self._mean_reference:
                self._rho_eq = self._fluid_mean_density()
            self.step_count += 1

    def relax(self, tolerance: float, max_steps: int) -> int:
        """Relax the start; returns the steps taken (scene key ``lattice.relax``).

        The fluid moves under its own pressure and viscous forces (a Newtonian viscosity μ_max
        of the time step, ``timestep.max_viscosity``) with the bodies held still, no imposed
        flow and velocities damped by :data:`RELAX_DAMPING` per step, until the
        density error is at most ``tolerance`` (checked every :data:`RELAX_CHECK` steps) or
        ``max_steps`` have run. Then time restarts at 0 with the initial velocities of the
        scene (imposed profile or rest) at the relaxed positions.
        """
        rate, self._rate = self._rate, 0.0
        with self._constant_viscosity(max_viscosity(self.scene)):
            steps, error = self._relax_steps(tolerance, max_steps)
        self._rate = rate
        self._start_flow()
        log.info("relaxed the start in %d steps: density error %.3g (tolerance %.3g)", steps,
                 error, tolerance)
        if error > tolerance:
            log.warning("the start is still %.3g from rho_eq after lattice.relax_max_steps = %d "
                        "steps (lattice.relax_tolerance %.3g)", error, max_steps, tolerance)
        return steps

    @contextlib.contextmanager
    def _constant_viscosity(self, mu: float):
        """Run the physics with a Newtonian viscosity ``mu`` inside the block. The relaxation
        has no imposed flow, so a shear-thinning law would read its zero-rate viscosity, up to
        10⁶ times the μ_max the time step was chosen for (a yield-stress matrix blew up)."""
        saved = (self._law, self._newtonian, self._velocity_gradient, self._bulk_gradient,
                 self._mu.copy(), self._mu_hat.copy())
        self._law = make_law("newtonian", {"mu": mu})
        self._newtonian, self._bulk_gradient = True, False
        self._velocity_gradient = self._normalise or self._spin_correction
        self._mu[:] = mu
        self._mu_hat[:] = mu
        try:
            yield
        finally:
            (self._law, self._newtonian, self._velocity_gradient, self._bulk_gradient,
             mu_saved, mu_hat_saved) = saved
            self._mu[:] = mu_saved
            self._mu_hat[:] = mu_hat_saved

    def _relax_steps(self, tolerance: float, max_steps: int) -> tuple[int, float]:
        """The relaxation loop of :meth:`relax`: (steps taken, final density error)."""
        dt = self.dt
        self._v[:] = 0.0
        self._a[:] = 0.0
        still = np.zeros((self.bodies.count if self.bodies is not None else 0, 3))
        rotations = self.bodies.rotations() if self.bodies is not None else None
        error, steps = self._density_error(), 0
        while error > tolerance and steps < max_steps:
            drift(self._x, self._v, self._a, dt)
            if self.bodies is not None:
                self._place_bodies(rotations, still, still, 0.0, self._v)
            nl = self._nlist
            if needs_rebuild(self._x, self._reference, 0.0, nl.cutoff, nl.skin):
                self._rebuild(0.0)
            predict(self._v, self._a, dt, self._v_pred)
            if self.bodies is not None:
                self._place_bodies(rotations, still, still, 0.0, self._v_pred)
            self._compute_accelerations(self._v_pred, self._a_new)
            kick(self._v, self._a, self._a_new, dt)
            self._v *= 1.0 - RELAX_DAMPING
            if self.bodies is not None:
                self._place_bodies(rotations, still, still, 0.0, self._v)
            steps += 1
            if steps % RELAX_CHECK == 0:
                error = self._density_error()
        return steps, self._density_error()

    def _start_flow(self) -> None:
        """Velocities of the scene's start at the current positions; list rebuilt at time 0."""
        self._rebuild(0.0)
        fluid = self._body_of < 0
        self._v[fluid] = initial_velocities(self.scene, self._x[fluid])
        self._a[:] = 0.0
        if self.bodies is not None:
            from suspsim.sph.inclusions import initial_body_motion

            velocities, omegas = initial_body_motion(self.scene, self.bodies.centres)
            self.bodies.set_motion(velocities, omegas)
            self._place_bodies(self.bodies.rotations(), velocities, omegas, 0.0, self._v)

    def memory_bytes(self) -> int:
        """Bytes held by the particle arrays, the neighbour list, the pair table and scratch."""
        held = [value for value in vars(self).values() if isinstance(value, np.ndarray)]
        for group in (self._nlist, self._table):
            held += [getattr(group, f.name) for f in dataclasses.fields(group)
                     if isinstance(getattr(group, f.name), np.ndarray)]
        owners = [a if a.base is None else a.base for a in held]  # a view counts as its buffer
        return sum({id(a): a.nbytes for a in owners}.values())

    def _peculiar(self) -> np.ndarray:
        """Velocities relative to the imposed flow (positions unwrapped since the last build)."""
        out = self._v.copy()
        out[:, 0] -= imposed_velocity(self.scene, self._x[:, 1])
        return out

    def _fluid_mean_density(self) -> float:
        """Mean summation density of the fluid particles [m h^-d] (body shells excluded)."""
        return float(fluid_mean_density(self._rho, self._body_of))

    def _density_errors(self) -> np.ndarray:
        """|ρ/ρ_eq − 1| of each fluid particle [1] (a rigid body's particles cannot follow)."""
        rho = self._rho if self.bodies is None else self._rho[self._body_of < 0]
        return np.abs(rho / self._rho_eq - 1.0)

    def _density_error(self) -> float:
        """max |ρ/ρ_eq − 1| over the fluid particles [1]."""
        return float(np.max(self._density_errors()))

    def _mach(self) -> float:
        peculiar = self._peculiar()
        return float(np.sqrt(np.max(np.einsum("ij,ij->i", peculiar, peculiar)))
                     / self.sound_speed)

    def health(self) -> tuple[bool, str]:
        """(ok, message): NaN/inf, density error and Mach number against the scene's limits."""
        run = self.scene.run
        where = f"at step {self.step_count} (time {self.time:.4g})"
        settings = f"run.dt = {self.dt:.4g}, run.sound_speed = {self.sound_speed:.4g}"
        if not (np.all(np.isfinite(self._x)) and np.all(np.isfinite(self._v))
                and np.all(np.isfinite(self._a)) and np.all(np.isfinite(self._rho))):
            return False, (f"non-finite positions or velocities {where}: the run blew up; lower "
                           f"run.dt or raise run.sound_speed ({settings})")
        errors = self._density_errors()
        error = float(np.max(errors))
        density = density_verdict(errors, run.max_density_error, run.density_outlier_fraction,
                                  run.max_outlier_density_error)
        if density:
            return False, (f"{density} {where}: raise run.sound_speed or lower run.dt "
                           f"({settings})")
        if self._lubrication is not None and (self._lubrication_stats[OVERLAPS] > 0
                                              or self._lubrication_stats[SMALLEST_GAP] < 0):
            return False, (f"bodies overlap {where} (smallest gap "
                           f"{self._lubrication_stats[SMALLEST_GAP]:.3g} h): raise "
                           f"inclusions.lubrication.repulsion or lower run.dt ({settings})")
        mach = self._mach()
        if mach > run.max_mach:
            return False, (f"Mach number {mach:.3g} exceeds run.max_mach {run.max_mach:g} "
                           f"{where}: raise run.sound_speed or lower run.dt ({settings})")
        return True, f"ok {where}: density error {error:.3g}, Mach {mach:.3g}"

    def sample(self) -> dict[str, float]:
        """Instantaneous scalars: shear_stress σ_xy, pressure tr Π/d, kinetic_energy of ṽ,
        density_error, mach (SPEC §2.8); with bodies also particle_stress, the bodies' share
        of σ_xy: their stresslets (the move of the body particles' forces to the centre, SPEC
        §3.5) plus lubrication and repulsion, (1/V) Σ_B S_B,xy of Batchelor (1970) [m h^(2−d)
        τ⁻²], and body_spin, their mean Ω_z over −γ̇/2 [1]; with grains also body_order, the
        nematic order S of their long axes [1] (``analysis.orientation``; a sphere's axes are
        arbitrary)."""
        peculiar = self._peculiar()
        rows = self._virial if self.bodies is None else np.vstack(
            [self._virial, self._body_virial, self._lubrication_virial])
        pi = pressure_tensor(rows, peculiar, self._mass, self.scene.volume)
        out = {"shear_stress": shear_stress(pi),
               "pressure": mean_pressure(pi, self.scene.dimension),
               "kinetic_energy": 0.5 * self._mass * float(np.sum(peculiar * peculiar)),
               "density_error": self._density_error(), "mach": self._mach()}
        if self.bodies is not None:
            out["particle_stress"] = -float(self._body_virial[VXY]
                                            + self._lubrication_virial[VXY]) / self.scene.volume
            out.update(self.body_orientation())
        return out

    def body_orientation(self) -> dict[str, float]:
        """body_spin, the bodies' mean Ω_z over −γ̇/2, and with grains body_order, the nematic
        order S of their long axes [1] (``analysis.orientation``; part of :meth:`sample`)."""
        out = {"body_spin": spin_ratio(self.bodies.angular_velocities(), self._rate)}
        if self._grains is not None:
            out["body_order"] = nematic_order(self.bodies.rotations()[:, :, 0])[0]
        return out

    def profiles(self, bins: int) -> dict[str, np.ndarray]:
        """Bin means over y ∈ [0, L_y): y, velocity_profile (v_x), viscosity_profile (μ),
        shear_rate_profile (γ̇; NaN when no gradient pass runs), density_profile (ρ).
        Raises NumericalError (the message of :meth:`health`) when a position is not finite:
        a run that blew up since its last health check has no bin to put it in."""
        if not np.all(np.isfinite(self._x)):
            raise NumericalError(self.health()[1])
        ly = self.scene.box[1]
        crossings = np.floor(self._x[:, 1] / ly)
        y = self._x[:, 1] - crossings * ly
        vx = self._v[:, 0] - crossings * self._rate * ly
        index = np.minimum((y / ly * bins).astype(np.int64), bins - 1)
        count = np.bincount(index, minlength=bins).astype(float)
        with np.errstate(invalid="ignore", divide="ignore"):
            def mean(values):
                return np.bincount(index, weights=values, minlength=bins) / count
            gdot = mean(self._gdot) if self._velocity_gradient else np.full(bins, np.nan)
            return {"y": (np.arange(bins) + 0.5) * ly / bins, "velocity_profile": mean(vx),
                    "viscosity_profile": mean(self._mu), "shear_rate_profile": gdot,
                    "density_profile": mean(self._rho)}

    def state(self) -> dict[str, np.ndarray | float | int]:
        """Everything needed to resume bit for bit (copies)."""
        out = {name: getattr(self, attribute).copy() for name, attribute in _STATE_ARRAYS.items()}
        out.update(time=self.time, step_count=self.step_count, dt=self.dt,
                   sound_speed=self.sound_speed, build_time=self._build_time,
                   n_chunks=self._n_chunks, rho_eq=self._rho_eq,
                   normalisation_age=int(self._normalisation_age[0]))
        if self.bodies is not None:
            out.update(bodies=self.bodies.state(), body_volume=self._body_volume,
                       body_radii=self._body_radii.copy(),
                       lubrication_virial=self._lubrication_virial.copy(),
                       reference_count=round(self._rho_eq * self.scene.volume / self._mass),
                       body_virial=self._body_virial.copy())
            if self._grains is not None:
                out["grains"] = {key: np.array(value) for key, value in self._grains.items()}
        return out

    @classmethod
    def from_state(cls, scene: Scene, state, *, threads: int | None = None) -> "Simulation":
        """Resume from :meth:`state` (same scene); results continue bit for bit."""
        return cls(scene, threads=threads, _state=state)
