"""Rigid placement of body particles (with Lees–Edwards images), body force, torque and virial."""
import numba
import numpy as np

from suspsim.bodies.coupling import body_force_torque, place_body_particles
from suspsim.bodies.rotations import random_quaternions, rotation_matrices
from suspsim.threads import use_threads

BOX = np.array([10.0, 8.0, 6.0])


def _bodies(rng, count=3, per_body=5):
    centres = rng.uniform(0.0, 1.0, (count, 3)) * BOX
    rotations = rotation_matrices(random_quaternions(count, rng))
    offsets = rng.normal(size=(count * per_body, 3))
    body_of = np.repeat(np.arange(count), per_body)
    members = np.arange(count * per_body)
    velocities, omegas = rng.normal(size=(count, 3)), rng.normal(size=(count, 3))
    return centres, rotations, offsets, body_of, members, velocities, omegas


def _place(centres, rotations, offsets, body_of, members, velocities, omegas, previous,
           le_offset=0.0, rate=0.0):
    x = previous.copy()
    v = np.zeros_like(x)
    place_body_particles(members, body_of, offsets, centres, rotations, velocities, omegas, BOX,
                         le_offset, rate, x, v)
    return x, v


def test_rigid_positions_and_velocities():
    rng = np.random.default_rng(1)
    centres, rot, offsets, body_of, members, vel, om = _bodies(rng)
    arms = np.einsum("nij,nj->ni", rot[body_of], offsets)
    exact = centres[body_of] + arms
    x, v = _place(centres, rot, offsets, body_of, members, vel, om, exact + 0.01)
    np.testing.assert_allclose(x, exact, atol=1e-12)
    np.testing.assert_allclose(v, vel[body_of] + np.cross(om[body_of], arms), atol=1e-12)


def test_particle_kept_at_the_lees_edwards_image_of_its_previous_position():
    """A particle last seen one box up sits there: x + Δ, y + L_y, v_x + γ̇ L_y (SPEC §2.7);
    one box along x or z: shifted by a whole box length, velocity unchanged."""
    rng = np.random.default_rng(2)
    centres, rot, offsets, body_of, members, vel, om = _bodies(rng)
    exact, v0 = _place(centres, rot, offsets, body_of, members, vel, om,
                       centres[body_of] + np.einsum("nij,nj->ni", rot[body_of], offsets))
    delta, rate = 3.7, 0.25
    previous = exact.copy()
    previous[0] += (delta, BOX[1], 0.0)
    previous[1] += (-delta - BOX[0], -BOX[1], BOX[2])
    x, v = _place(centres, rot, offsets, body_of, members, vel, om, previous + 0.05, delta,
                  rate)
    np.testing.assert_allclose(x[0], exact[0] + (delta, BOX[1], 0.0), atol=1e-12)
    np.testing.assert_allclose(x[1], exact[1] + (-delta - BOX[0], -BOX[1], BOX[2]), atol=1e-12)
    np.testing.assert_allclose(v[0], v0[0] + (rate * BOX[1], 0.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(v[1], v0[1] - (rate * BOX[1], 0.0, 0.0), atol=1e-12)
    np.testing.assert_allclose(x[2:], exact[2:], atol=1e-12)


def test_force_torque_and_constraint_virial_against_direct_sums():
    rng = np.random.default_rng(3)
    centres, rot, offsets, body_of, members, _, _ = _bodies(rng)
    n_fluid = 4
    width = 6
    forces = rng.normal(size=(n_fluid + len(members), 3))
    acc = np.zeros((n_fluid + len(members)) * width)
    acc.reshape(-1, width)[:, :3] = forces
    all_body_of = np.concatenate([np.full(n_fluid, -1), body_of])
    all_offsets = np.concatenate([np.zeros((n_fluid, 3)), offsets])
    shifted = members + n_fluid
    f_out, t_out, virial = np.zeros((3, 3)), np.zeros((3, 3)), np.zeros(5)
    body_force_torque(shifted, all_body_of, all_offsets, rot, acc, width, f_out, t_out, virial)
    arms = np.einsum("nij,nj->ni", rot[body_of], offsets)
    f_body = forces[n_fluid:]
    for b in range(3):
        mine = body_of == b
        np.testing.assert_allclose(f_out[b], f_body[mine].sum(axis=0), atol=1e-12)
        np.testing.assert_allclose(t_out[b], np.cross(arms[mine], f_body[mine]).sum(axis=0),
                                   atol=1e-12)
    outer = -np.einsum("na,nb->ab", f_body, arms)
    np.testing.assert_allclose(virial, [outer[0, 0], outer[1, 1], outer[2, 2], outer[0, 1],
                                        outer[1, 0]], atol=1e-12)


def test_force_torque_sums_do_not_depend_on_the_thread_count():
    """The members are summed in fixed slices, so one and two threads give the same bits."""
    rng = np.random.default_rng(4)
    centres, rot, offsets, body_of, members, _, _ = _bodies(rng, count=7, per_body=300)
    width = 6
    acc = rng.normal(size=len(members) * width)
    results, before = [], numba.get_num_threads()
    try:
        for threads in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            use_threads(threads)
            out = np.zeros((7, 3)), np.zeros((7, 3)), np.zeros(5)
            body_force_torque(members, body_of, offsets, rot, acc, width, *out)
            results.append(out)
    finally:
        numba.set_num_threads(before)
    for one, two in zip(*results):
        np.testing.assert_array_equal(one, two)
