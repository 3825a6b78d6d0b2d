"""Run one configuration of a validation case and record what its accuracy cost.

The cost is the wall time a user pays for the number: building the simulation (lattice,
neighbour list) and running it, on a fixed thread count, with numba's compiled code already
loaded (a warm-up of the same scene runs two steps first, so compilation or cache loading is
not counted). The CPU time is recorded beside it: on one thread it equals the wall time on an
idle core and does not grow when other jobs share the machine. Particle-steps per second is
N × steps / run time, the solver's throughput on this configuration.
"""
from __future__ import annotations

import logging
import time
from typing import Any, Mapping

from suspsim.convergence.cases import Case
from suspsim.sph.simulation import Simulation

log = logging.getLogger(__name__)

#: Steps of the untimed warm-up that loads the compiled code [choice].
WARM_UP_STEPS = 2


def run_configuration(case: Case, overrides: Mapping[str, Any] | None = None, *,
                      threads: int = 1) -> dict[str, Any]:
    """Measure ``case`` at its defaults updated by ``overrides`` on ``threads`` threads.

    Returns the full settings and: ``error`` |e| [1], ``signed_error`` e [1] (the Couette
    viscosity ratio − 1; the L2/peak norm for profiles), ``error_stderr`` [1] (NaN where not
    estimated), ``wall_time`` and ``cpu_time`` [s] (set-up + run), ``setup_time`` [s],
    ``n_particles``, ``n_steps``, ``particle_steps_per_s`` [s-1], ``dt`` [τ], ``sound_speed`` [h τ⁻¹],
    ``number_density`` [h⁻ᵈ] and ``resolution_used`` (q after snapping) [1]. A run that leaves
    its health limits raises :class:`~suspsim.errors.NumericalError`.
    """
    settings = case.settings(overrides)
    scene = case.build(settings)
    warm = Simulation(scene, threads=threads)
    warm.advance(WARM_UP_STEPS)
    if case.restart is not None:
        case.restart(warm).advance(WARM_UP_STEPS)
    del warm
    t0, c0 = time.perf_counter(), time.process_time()
    sim = Simulation(scene, threads=threads)
    if case.restart is not None:
        sim = case.restart(sim)
    t1 = time.perf_counter()
    reading = case.measure(sim, settings)
    t2, c2 = time.perf_counter(), time.process_time()
    n_steps = sim.step_count
    record = dict(settings)
    record.update(
        error=abs(reading.value), signed_error=reading.value, error_stderr=reading.stderr,
        wall_time=t2 - t0, cpu_time=c2 - c0, setup_time=t1 - t0, n_particles=sim.n_particles,
        n_steps=n_steps,
        particle_steps_per_s=sim.n_particles * n_steps / (t2 - t1), dt=sim.dt,
        sound_speed=sim.sound_speed, number_density=scene.number_density,
        resolution_used=scene.number_density ** (1.0 / scene.dimension), threads=threads)
    log.info("%s %s: error %.3g in %.1f s (%d particles, %d steps)", case.name,
             dict(overrides or {}), record["error"], record["wall_time"], sim.n_particles,
             n_steps)
    return record
