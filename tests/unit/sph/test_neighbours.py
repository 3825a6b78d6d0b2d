"""Cell sort, neighbour list and summation density against brute force."""
import math

import numba
import numpy as np
import pytest

from neighbour_helpers import (BOXES, CUTOFF, brute_force_distances, brute_force_pairs, build,
                               listed, listed_arrays, scene)
from suspsim.sph import kernels as K
from suspsim.sph import neighbours as nb
from suspsim.sph.density import (DX, DZ, F, GEOMETRY_DTYPE, TABLE_OK, TABLE_OVERFLOW,
                                 allocate_pair_table, summation_density,
                                 summation_density_serial)


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("kind", ["random", "lattice"])
@pytest.mark.parametrize("box_index", [0, 1])
@pytest.mark.parametrize("offset_fraction", [0.0, 0.37, 1.0, 1.5, 2.9])
def test_list_equals_brute_force(dim, kind, box_index, offset_fraction):
    rng = np.random.default_rng(11)
    box, positions = scene(kind, BOXES[dim][box_index], dim, rng)
    cell = box[0] / nb.cell_grid(box, CUTOFF, dim)[0]
    offset = (offset_fraction * cell) % box[0]  # multiples and non-multiples of the cell size
    for half in (True, False):
        p = positions.copy()
        nlist, _ = build(p, box, dim, offset, half=half)
        pairs = listed(nlist)
        assert len(pairs) == len(set(pairs)) == nlist.n_pairs
        expected = brute_force_pairs(p, box, offset, CUTOFF, dim)
        if half:
            assert all(i < j for i, j in pairs)
            assert set(pairs) == expected
        else:
            assert set(pairs) == expected | {(j, i) for i, j in expected}
        # first part of each segment: pairs whose plain difference is the nearest image
        i, j, k = listed_arrays(nlist)
        plain = np.linalg.norm(p[i] - p[j], axis=1) < CUTOFF
        np.testing.assert_array_equal(plain, k < nlist.image_start[i])


@pytest.mark.parametrize("offset_fraction", [0.0, 0.37, 1.5])
def test_pairs_inside_one_group_are_not_listed(offset_fraction):
    """With ``group`` (rigid bodies), the list is the brute-force one minus the pairs of two
    particles of one group; ungrouped particles (−1) keep every pair, including those with
    each other, and the plain/image split still holds. A small share of every particle's
    candidates forces the checked compaction for some particles (capacity 1.05 pairs)."""
    rng = np.random.default_rng(5)
    box, positions = scene("random", BOXES[3][1], 3, rng)
    group = rng.integers(-1, 4, len(positions)).astype(np.int64)
    offset = offset_fraction * box[0] / 3.0
    for capacity in (None, 1.05):
        p, g = positions.copy(), group.copy()
        nlist = nb.allocate_neighbour_list(len(p), box, CUTOFF, 0.0, 3, len(p) / np.prod(box))
        if capacity is not None:
            nlist.neighbours = np.zeros(int(capacity * len(brute_force_pairs(
                p, box, offset, CUTOFF, 3))), dtype=nlist.neighbours.dtype)
        nb.rebuild_neighbour_list(nlist, p, np.zeros_like(p), box, offset, 0.0, (g,), group=g)
        pairs = listed(nlist)
        expected = {(i, j) for i, j in brute_force_pairs(p, box, offset, CUTOFF, 3)
                    if g[i] < 0 or g[i] != g[j]}
        assert len(pairs) == len(set(pairs)) == nlist.n_pairs
        assert set(pairs) == expected
        assert any(g[i] < 0 and g[j] < 0 for i, j in pairs)
        i, j, k = listed_arrays(nlist)
        plain = np.linalg.norm(p[i] - p[j], axis=1) < CUTOFF
        np.testing.assert_array_equal(plain, k < nlist.image_start[i])


def test_sort_and_permutation():
    rng = np.random.default_rng(2)
    box = np.array([4.0, 5.0, 3.0])
    cells = nb.cell_grid(box, 1.0, 3)
    positions = rng.uniform(0, 1, (300, 3)) * box
    cell_of = np.zeros(300, dtype=np.int64)
    order = np.zeros(300, dtype=np.int64)
    cell_start = np.zeros(np.prod(cells) + 1, dtype=np.int64)
    nb.sort_by_cell(positions, box, cells, cell_of, order, cell_start)
    assert sorted(order) == list(range(300))
    sorted_positions = np.empty_like(positions)
    nb.apply_permutation(positions, order, sorted_positions)
    np.testing.assert_array_equal(sorted_positions, positions[order])
    ids = np.empty(300, dtype=np.int64)
    nb.apply_permutation(np.arange(300), order, ids)
    np.testing.assert_array_equal(ids, order)
    c = np.floor(sorted_positions / (box / cells)).astype(int)
    linear = (c[:, 0] * cells[1] + c[:, 1]) * cells[2] + c[:, 2]
    assert np.all(np.diff(linear) >= 0)
    np.testing.assert_array_equal(np.searchsorted(linear, np.arange(np.prod(cells) + 1)),
                                  cell_start)


def test_rebuild_permutes_particle_arrays_and_wraps():
    rng = np.random.default_rng(4)
    box = np.array([4.0, 5.0, 3.5])
    positions = rng.uniform(-0.5, 1.1, (200, 3)) * box
    velocities = rng.normal(size=(200, 3))
    ids = np.arange(200)
    nlist = nb.allocate_neighbour_list(200, box, 1.0, 0.1, 3, 200 / np.prod(box))
    nb.rebuild_neighbour_list(nlist, positions, velocities, box, 0.5, 0.2, (ids,))
    np.testing.assert_array_equal(ids, nlist.order)
    assert np.all((positions >= 0) & (positions < box))
    np.testing.assert_array_equal(nlist.reference, positions)


def test_overflow_code_and_error():
    rng = np.random.default_rng(8)
    box, positions = scene("random", (4.0, 4.0, 4.0), 3, rng)
    nlist = nb.allocate_neighbour_list(len(positions), box, 1.0, 0.2, 3, 1.0,
                                       capacity_factor=0.05)
    with pytest.raises(nb.NeighbourListOverflowError, match="capacity") as info:
        nb.rebuild_neighbour_list(nlist, positions, np.zeros_like(positions), box, 0.0, 0.0)
    code, required = nb.build_neighbour_list(positions, box, 0.0, nlist.cutoff, nlist.cells,
                                             nlist.cell_start, nlist.start, nlist.image_start,
                                             nlist.neighbours)
    assert code == nb.PAIR_OVERFLOW and required == info.value.required
    nlist.neighbours = np.zeros(required, dtype=np.int32)
    code, n_pairs = nb.build_neighbour_list(positions, box, 0.0, nlist.cutoff, nlist.cells,
                                            nlist.cell_start, nlist.start, nlist.image_start,
                                            nlist.neighbours)
    assert code == nb.OK and n_pairs <= required
    assert set(listed(nlist)) == brute_force_pairs(positions, box, 0.0, nlist.cutoff, 3)


def test_box_too_small():
    with pytest.raises(ValueError, match="fewer than 3 cells"):
        nb.cell_grid(np.array([3.0, 2.9, 3.0]), 1.0, 3)
    assert list(nb.cell_grid(np.array([3.0, 3.5, 0.1]), 1.0, 2)) == [3, 3, 1]


# ------------------------------------------------------------------------------ density

def density_pass(positions, box, offset, nlist, kernel, h, n_chunks=2, table=None,
                 code=TABLE_OK):
    density = np.empty(len(positions))
    table = table or allocate_pair_table(len(positions), len(nlist.neighbours))
    scratch = np.empty((n_chunks - 1, len(positions)))
    bounds = np.empty(n_chunks + 1, dtype=np.int64)
    assert code == summation_density(positions, box, offset, nlist.start, nlist.image_start,
                                     nlist.neighbours, kernel, h, density, table.pair_start,
                                     table.pair_end, table.pair_j, table.pair_geometry,
                                     table.pair_cross, table.pair_image, scratch, bounds)
    return density


@pytest.mark.parametrize("dim,kernel", [(3, K.LUCY_3D), (2, K.LUCY_2D), (3, K.QUINTIC_3D),
                                        (2, K.QUINTIC_2D)])
@pytest.mark.parametrize("offset", [0.0, 1.37])
def test_density_equals_brute_force(dim, kernel, offset):
    rng = np.random.default_rng(9)
    box, positions = scene("random", BOXES[dim][0], dim, rng)
    h = 0.9
    nlist, _ = build(positions, box, dim, offset, skin=0.1, support=h)
    moved = positions + rng.uniform(-0.02, 0.02, positions.shape) * [1, 1, dim == 3]
    r = brute_force_distances(moved, box, offset, dim)
    expected = np.vectorize(lambda x: K.kernel_w(kernel, x, h))(r).sum(axis=1)
    serial = np.empty(len(moved))
    table = allocate_pair_table(len(moved), len(nlist.neighbours))
    summation_density_serial(moved, box, offset, nlist.start, nlist.image_start,
                             nlist.neighbours, kernel, h, serial, table.pair_start,
                             table.pair_end, table.pair_j,
                             table.pair_geometry, table.pair_cross, table.pair_image)
    np.testing.assert_allclose(serial, expected, rtol=1e-12)
    np.testing.assert_array_equal(density_pass(moved, box, offset, nlist, kernel, h, 1), serial)
    for chunks in (2, 3):
        parallel_table = allocate_pair_table(len(moved), len(nlist.neighbours))
        np.testing.assert_allclose(
            density_pass(moved, box, offset, nlist, kernel, h, chunks, parallel_table),
            serial, rtol=1e-14)
        np.testing.assert_array_equal(parallel_table.pair_end - parallel_table.pair_start,
                                      table.pair_end - table.pair_start)
        np.testing.assert_array_equal(parallel_table.pair_cross - parallel_table.pair_start,
                                      table.pair_cross - table.pair_start)
    # pair table: exactly the pairs within h, with nearest-image vector, F and image index (in
    # pair_image from pair_cross on, the pairs across a face; the others are inside the box)
    counts = table.pair_end - table.pair_start
    i = np.repeat(np.arange(len(moved)), counts)
    k = np.concatenate([np.arange(a, b) for a, b in zip(table.pair_start, table.pair_end)])
    j = table.pair_j[k].astype(np.int64)
    assert set(zip(i.tolist(), j.tolist())) == {
        (min(a, b), max(a, b)) for a, b in zip(*np.nonzero(np.triu(r < h, 1)))}
    rows = table.pair_geometry[k]
    crossing = k >= np.repeat(table.pair_cross, counts)
    for a, b, row, across, image in zip(i, j, rows, crossing, table.pair_image[k]):
        d = moved[a] - moved[b]
        n = np.rint(d[1] / box[1])
        shift = [n * offset + box[0] * np.rint((d[0] - n * offset) / box[0]), n * box[1],
                 box[2] * np.rint(d[2] / box[2]) if dim == 3 else 0.0]
        np.testing.assert_allclose(row[DX:DZ + 1], d - shift,
                                   rtol=np.finfo(GEOMETRY_DTYPE).eps, atol=1e-12)
        assert (image if across else 0) == n
        assert across or not np.any(shift)
        assert row[F] == pytest.approx(K.kernel_f(kernel, np.linalg.norm(d - shift), h))


@pytest.mark.parametrize("n_chunks", [1, 2, 3])
def test_compact_table_overflows_cleanly_and_its_size_changes_nothing(n_chunks):
    """A table too small for the pairs within h reports TABLE_OVERFLOW without writing past any
    chunk's rows; a compact table, with fewer rows than listed pairs,
    gives the density and every pair's row bit for bit as a table with a row per listed pair."""
    rng = np.random.default_rng(4)
    box, positions = scene("random", BOXES[3][0], 3, rng)
    h = 0.7
    nlist, _ = build(positions, box, 3, 0.37, skin=0.3, support=h)
    full = allocate_pair_table(len(positions), len(nlist.neighbours))
    expected = density_pass(positions, box, 0.37, nlist, K.LUCY_3D, h, n_chunks, full)
    within = int(np.sum(full.pair_end - full.pair_start))
    rows = 2 * within  # room for each chunk's share; still fewer rows than listed pairs
    assert rows < nlist.start[-1]
    # a small table whose arrays are the head of larger ones: nothing may land in the tails
    small, guarded = allocate_pair_table(len(positions), within // 2), within // 2
    j_tail, geometry_tail = np.full(guarded + 100, 7, np.uint32), np.full((guarded + 100, 4), 7.0)
    small.pair_j, small.pair_geometry = j_tail[:guarded], geometry_tail[:guarded]
    density_pass(positions, box, 0.37, nlist, K.LUCY_3D, h, n_chunks, small, TABLE_OVERFLOW)
    assert np.all(j_tail[guarded:] == 7) and np.all(geometry_tail[guarded:] == 7.0)
    compact = allocate_pair_table(len(positions), rows)
    np.testing.assert_array_equal(
        density_pass(positions, box, 0.37, nlist, K.LUCY_3D, h, n_chunks, compact), expected)
    np.testing.assert_array_equal(full.pair_end - full.pair_start,
                                  compact.pair_end - compact.pair_start)
    np.testing.assert_array_equal(full.pair_cross - full.pair_start,
                                  compact.pair_cross - compact.pair_start)
    rows_full = np.concatenate([np.arange(p, q) for p, q in zip(full.pair_start, full.pair_end)])
    rows_compact = np.concatenate([np.arange(p, q)
                                   for p, q in zip(compact.pair_start, compact.pair_end)])
    for name in ("pair_j", "pair_geometry", "pair_image"):
        np.testing.assert_array_equal(getattr(full, name)[rows_full],
                                      getattr(compact, name)[rows_compact])


@pytest.mark.parametrize("dim,number_density", [(3, 4.096), (2, 4.0)])
def test_density_on_a_lattice(dim, number_density):
    spacing = number_density ** (-1 / dim)
    cells = 6 if dim == 3 else 8
    length = cells * spacing
    box = np.array([length, length, length if dim == 3 else 1.0])
    axes = [np.arange(cells) * spacing + 0.1] * dim + [np.zeros(1)] * (3 - dim)
    positions = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    kernel = K.LUCY_3D if dim == 3 else K.LUCY_2D
    # exact lattice sum Σ_R W(|R|) over lattice vectors
    m = np.arange(-3, 4) * spacing
    vectors = np.stack(np.meshgrid(*([m] * dim), indexing="ij"), -1).reshape(-1, dim)
    lattice_sum = sum(K.kernel_w(kernel, float(np.linalg.norm(v)), 1.0) for v in vectors)
    assert lattice_sum / number_density == pytest.approx(1.0, abs=0.021)
    offset = 3 * spacing  # Lees–Edwards offset by whole lattice rows, not whole cells
    nlist, _ = build(positions, box, dim, offset, skin=0.2)
    for chunks in (1, 2):
        density = density_pass(positions, box, offset, nlist, kernel, 1.0, chunks)
        np.testing.assert_allclose(density, lattice_sum, rtol=1e-12)


def test_density_rejects_1d_kernel():
    rng = np.random.default_rng(12)
    box, positions = scene("random", (4.0, 4.0, 4.0), 3, rng)
    nlist, _ = build(positions, box, 3, 0.0)
    with pytest.raises(ValueError, match="2D and 3D"):
        density_pass(positions, box, 0.0, nlist, K.QUINTIC_1D, 1.0)


def test_parallel_density_independent_of_threads():
    rng = np.random.default_rng(10)
    box, positions = scene("random", (4.0, 4.0, 4.0), 3, rng)
    nlist, _ = build(positions, box, 3, 0.7, skin=0.1)
    results = []
    for threads in {1, numba.config.NUMBA_NUM_THREADS}:
        numba.set_num_threads(threads)
        results.append(density_pass(positions, box, 0.7, nlist, K.LUCY_3D, 1.0, 2))
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    np.testing.assert_array_equal(results[0], results[-1])
    assert math.isfinite(results[0].sum())
