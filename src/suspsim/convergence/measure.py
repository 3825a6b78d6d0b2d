"""Run one configuration of a validation case and record what its accuracy cost.

The cost is the wall time a user pays for the number: building the simulation (lattice, neighbour
list) and running it, on a fixed thread count, with numba's compiled code already loaded (each
case's warm-up first runs two steps of the same SPH scene, or 0.02 strain of the same DST point, so
compilation or cache loading is not counted). The CPU time is recorded beside it: on one thread it
equals the wall time on an idle core and does not grow when other jobs share the machine.
Particle-steps per second is N × steps / run time, the solver's throughput on this configuration.
"""
from __future__ import annotations

import logging
import time
from typing import Any, Mapping

from suspsim.convergence.cases import AnyCase
from suspsim.errors import NumericalError

log = logging.getLogger(__name__)


def run_configuration(case: AnyCase, overrides: Mapping[str, Any] | None = None, *,
                      threads: int = 1) -> dict[str, Any]:
    """Measure ``case`` (:mod:`.cases`) at its defaults updated by ``overrides`` on
    ``threads`` threads, after its warm-up.

    Returns the full settings and: ``error`` |e| [1], ``signed_error`` e [1] (a ratio − 1, or
    the L2/peak norm for profiles), ``error_stderr`` [1] (NaN where not estimated),
    ``wall_time`` and ``cpu_time`` [s] (set-up + run), ``setup_time`` [s], ``n_particles``,
    ``n_steps``, ``particle_steps_per_s`` [s-1], ``dt``, ``sound_speed``, ``number_density``
    and ``resolution_used`` (:class:`~.case_base.Run`). A run that leaves its health limits raises
    :class:`~suspsim.errors.NumericalError`.
    """
    settings = case.settings(overrides)
    case.warm_up(settings, threads)
    t0, c0 = time.perf_counter(), time.process_time()
    run = case.execute(settings, threads)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    reading = run.reading
    record = dict(settings)
    record.update(
        error=abs(reading.value), signed_error=reading.value, error_stderr=reading.stderr,
        wall_time=wall, cpu_time=cpu, setup_time=run.setup_time, n_particles=run.n_particles,
        n_steps=run.n_steps, particle_steps_per_s=run.n_particles * run.n_steps / run.run_time,
        dt=run.dt, sound_speed=run.sound_speed, number_density=run.number_density,
        resolution_used=run.resolution_used, threads=threads)
    log.info("%s %s: error %.3g in %.1f s (%d particles, %d steps)", case.name,
             dict(overrides or {}), record["error"], wall, run.n_particles, run.n_steps)
    return record


def run_or_failure(case: AnyCase, overrides: Mapping[str, Any] | None = None, *,
                   threads: int = 1) -> dict[str, Any]:
    """:func:`run_configuration`, or for a run that blew up (NumericalError) the settings with
    its ``failure`` message (the sweep keeps it as a configuration with NaN measurements). Any
    other error propagates: a bad setting or a bug is not a blow-up."""
    try:
        return run_configuration(case, overrides, threads=threads)
    except NumericalError as err:
        log.warning("%s %s blew up: %s: %s", case.name, dict(overrides or {}),
                    type(err).__name__, err)
        return {**case.settings(overrides), "failure": f"{type(err).__name__}: {err}",
                "threads": threads}
