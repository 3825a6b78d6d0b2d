"""The dst-2d bench scene's pass timer: its parts make up an evaluation, and timing them leaves
the run unchanged."""
import numpy as np

from suspsim.dst import integrator as _int
from suspsim.dst.bench import dst_bench_scene, pass_times

PASSES = {"list build", "viscosity and pressure", "pair passes", "finish"}


def test_parts_of_an_evaluation_give_its_rates():
    """State, pair passes and finish in turn give the same rates, bit for bit, as
    ``evaluate``, which the step loop calls."""
    sim = dst_bench_scene(800).build(threads=1)
    sim.advance(5)
    cfg, x, v, rho, f = (sim.config, sim.positions_all, sim.velocity_all, sim.rho_all.copy(),
                         sim.f_all)
    whole = _int.Buffers(*(a.copy() for a in sim._buffers))
    parts = _int.Buffers(*(a.copy() for a in sim._buffers))
    lists = _int.ListArrays(*(a.copy() for a in sim._lists))
    wall_whole, wall_parts = sim.wall.copy(), sim.wall.copy()
    assert _int.evaluate(cfg, x, v, rho, f, wall_whole, whole, lists) == _int.STEP_OK
    assert _int.particle_state(cfg, v, rho, f, parts) == _int.STEP_OK
    _int.pair_passes(cfg, x, v, rho, f, wall_parts, parts, lists)
    _int.finish_rates(cfg, f, wall_parts, parts)
    for name in ("acc", "drho", "df", "sigma"):
        np.testing.assert_array_equal(getattr(parts, name), getattr(whole, name))
    assert wall_parts[_int.WALL_ACCELERATION] == wall_whole[_int.WALL_ACCELERATION]


def test_pass_times_leave_the_run_unchanged():
    """10 steps, the pass timer, 10 steps: the same state as 20 steps, and the list builds
    are counted."""
    timed, plain = (dst_bench_scene(800).build(threads=1) for _ in range(2))
    timed.advance(10)
    builds = timed.rebuild_count
    times = pass_times(timed, repeats=2)
    assert set(times) == PASSES and all(t > 0.0 for t in times.values())
    assert timed.rebuild_count == builds
    timed.advance(10)
    plain.advance(20)
    np.testing.assert_array_equal(timed.positions_all, plain.positions_all)
    np.testing.assert_array_equal(timed.velocity_all, plain.velocity_all)
    assert timed.rebuild_count == plain.rebuild_count >= 1
