"""Periodic and Lees–Edwards boundaries (SPEC §2.7): wrap, minimum image, image velocity."""
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from suspsim.sph import boundaries as B

lengths = st.floats(2.0, 9.0)
fractions = st.floats(-0.4, 1.4)  # positions up to 40 % of a box outside it (unwrapped)


def brute_force_image(d, box, offset):
    """Shortest of r_p − r_q − image over images (m_x L_x + n Δ, n L_y, m_z L_z), |n|, |m| ≤ 3."""
    best, best_n = None, None
    for n, mx, mz in itertools.product(range(-3, 4), repeat=3):
        v = d - np.array([mx * box[0] + n * offset, n * box[1], mz * box[2]])
        if best is None or v @ v < best @ best:
            best, best_n = v, n
    return best, best_n


@settings(max_examples=300, deadline=None)
@given(lx=lengths, ly=lengths, lz=lengths, t=st.floats(0.0, 50.0), rate=st.floats(-2.0, 2.0),
       p=st.tuples(fractions, fractions, fractions), q=st.tuples(fractions, fractions, fractions))
def test_minimum_image_3d_against_brute_force(lx, ly, lz, t, rate, p, q):
    box = np.array([lx, ly, lz])
    offset = B.lees_edwards_offset(rate, lx, ly, t)
    d = (np.array(p) - np.array(q)) * box
    dx, dy, dz, n = B.minimum_image_3d(d[0], d[1], d[2], lx, ly, lz, offset)
    got = np.array([dx, dy, dz])
    # always an image of d, reduced to the central box
    assert abs(dy) <= ly / 2 + 1e-12 and abs(dx) <= lx / 2 + 1e-12 and abs(dz) <= lz / 2 + 1e-12
    shift = d - got
    assert shift[1] == pytest.approx(n * ly, abs=1e-9)
    mx = (shift[0] - n * offset) / lx
    assert mx == pytest.approx(round(mx), abs=1e-9)
    # and the nearest image whenever that is unique (closer than half the smallest length)
    best, best_n = brute_force_image(d, box, offset)
    if np.sqrt(best @ best) < 0.5 * min(lx, ly, lz) - 1e-9:
        np.testing.assert_allclose(got, best, atol=1e-9)
        assert n == best_n


@settings(max_examples=200, deadline=None)
@given(lx=lengths, ly=lengths, t=st.floats(0.0, 50.0), rate=st.floats(-2.0, 2.0),
       p=st.tuples(fractions, fractions), q=st.tuples(fractions, fractions))
def test_minimum_image_2d_matches_3d(lx, ly, t, rate, p, q):
    offset = B.lees_edwards_offset(rate, lx, ly, t)
    dx, dy = (p[0] - q[0]) * lx, (p[1] - q[1]) * ly
    assert B.minimum_image_2d(dx, dy, lx, ly, offset) == pytest.approx(
        tuple(np.array(B.minimum_image_3d(dx, dy, 0.0, lx, ly, 1.0, offset))[[0, 1, 3]]))


@settings(max_examples=200, deadline=None)
@given(lx=lengths, ly=lengths, lz=lengths, t=st.floats(0.0, 50.0), rate=st.floats(-2.0, 2.0),
       p=st.tuples(st.floats(0, 0.999), st.floats(0, 0.999), st.floats(0, 0.999)),
       q=st.tuples(st.floats(0, 0.999), st.floats(0, 0.999), st.floats(0, 0.999)))
def test_image_velocity_matches_affine_flow(lx, ly, lz, t, rate, p, q):
    # v_x = γ̇ y in the box: the corrected relative velocity of the pair is γ̇ dy
    box = np.array([lx, ly, lz])
    rp, rq = np.array(p) * box, np.array(q) * box
    offset = B.lees_edwards_offset(rate, lx, ly, t)
    _, dy, _, n = B.minimum_image_3d(*(rp - rq), lx, ly, lz, offset)
    relative = rate * rp[1] - rate * rq[1] - B.image_velocity(n, rate, ly)
    assert relative == pytest.approx(rate * dy, abs=1e-9)


def test_offset():
    assert B.lees_edwards_offset(0.5, 4.0, 3.0, 2.0) == pytest.approx(3.0)
    assert B.lees_edwards_offset(0.5, 4.0, 3.0, 3.0) == pytest.approx(0.5)
    assert B.lees_edwards_offset(-0.5, 4.0, 3.0, 1.0) == pytest.approx(2.5)
    assert B.lees_edwards_offset(0.0, 4.0, 3.0, 7.0) == 0.0


@pytest.mark.parametrize("dim", [2, 3])
def test_crossing_a_sheared_face(dim):
    lx, ly, lz, rate, offset = 5.0, 4.0, 3.0, 0.7, 1.25
    jump = rate * ly
    for y, k in ((ly + 0.1, 1), (-0.1, -1)):
        if dim == 3:
            x, y2, z, vx, crossings = B.wrap_3d(2.0, y, 1.0, 0.3, lx, ly, lz, offset, rate)
            assert z == 1.0
        else:
            x, y2, vx, crossings = B.wrap_2d(2.0, y, 0.3, lx, ly, offset, rate)
        assert crossings == k
        assert y2 == pytest.approx(y - k * ly)
        assert x == pytest.approx((2.0 - k * offset) % lx)  # top: x −= Δ; bottom: x += Δ
        assert vx == pytest.approx(0.3 - k * jump)          # top: v_x −= γ̇ L_y; bottom: +=


@settings(max_examples=200, deadline=None)
@given(lx=lengths, ly=lengths, lz=lengths, t=st.floats(0.0, 50.0), rate=st.floats(-2.0, 2.0),
       p=st.tuples(st.floats(-3, 4), st.floats(-3, 4), st.floats(-3, 4)))
def test_wrap_lands_in_box_and_keeps_affine_velocity(lx, ly, lz, t, rate, p):
    box = np.array([lx, ly, lz])
    offset = B.lees_edwards_offset(rate, lx, ly, t)
    r = np.array(p) * box
    vx = rate * r[1] + 0.01  # affine flow plus a peculiar part
    x, y, z, vx2, k = B.wrap_3d(r[0], r[1], r[2], vx, lx, ly, lz, offset, rate)
    assert 0 <= x < lx and 0 <= y < ly and 0 <= z < lz
    assert vx2 - rate * y == pytest.approx(0.01, abs=1e-9)
    # the wrapped particle is an image of the original one
    d = r - np.array([x, y, z])
    assert d[1] == pytest.approx(k * ly, abs=1e-9)
    mx = (d[0] - k * offset) / lx
    assert mx == pytest.approx(round(mx), abs=1e-9)


def test_wrap_particles_matches_scalar_wrap():
    rng = np.random.default_rng(3)
    box = np.array([4.0, 5.0, 3.0])
    positions = rng.uniform(-1.0, 6.0, (50, 3))
    velocities = rng.normal(size=(50, 3))
    expected = [B.wrap_3d(*positions[i], velocities[i, 0], *box, 1.7, 0.3) for i in range(50)]
    p, v = positions.copy(), velocities.copy()
    B.wrap_particles(p, v, box, 1.7, 0.3)
    np.testing.assert_array_equal(p, np.array([e[:3] for e in expected]))
    np.testing.assert_array_equal(v[:, 0], [e[3] for e in expected])
    np.testing.assert_array_equal(v[:, 1:], velocities[:, 1:])


def test_periodic_is_lees_edwards_without_shear():
    d = np.array([3.9, -2.2, 1.6])
    dx, dy, dz, n = B.minimum_image_3d(*d, 4.0, 4.0, 3.0, 0.0)
    np.testing.assert_allclose([dx, dy, dz], [-0.1, 1.8, -1.4])
    assert n == -1 and B.image_velocity(n, 0.0, 4.0) == 0.0
