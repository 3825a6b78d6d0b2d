"""Cell list, spatial sort and half Verlet list with skin for periodic and Lees–Edwards boxes.

Life cycle (the LAMMPS pattern: particles are wrapped into the box only when the list is rebuilt,
so displacements since the build are plain differences, exact across Lees–Edwards faces):

1. rebuild (:func:`rebuild_neighbour_list`, or the compiled pieces in this order):
   ``wrap_particles`` → :func:`sort_by_cell` → :func:`apply_permutation` on every particle array
   → :func:`build_neighbour_list` → ``reference[:] = positions``;
2. each step, after moving the particles and before any pair pass,
   ``list_validity.list_outdated`` decides whether to rebuild; then the pair passes read the
   list (see ``density``).

The list is a CSR half list: the neighbours of sorted particle i are ``neighbours[start[i]:
start[i + 1]]``, all j > i with |r_ij| < r_c = h + skin (each pair once). The first part,
up to ``image_start[i]``, are pairs inside the box, whose vector is simply r_i − r_j; the rest
cross a face and take the minimum image (6 % of the pairs of the 32,768-particle benchmark box;
skipping the three roundings for the others halves the density pass). Because positions are
not wrapped between builds, both parts stay valid for the life of the list. The list stores
only j; each step's geometry of the pairs within h (r_ij, F, image index n) is the pair table
that the density pass writes for the later passes (see ``density``). Positions are always
(N, 3) float64; a 2D scene keeps z ≡ 0 and has one cell layer in z. Build: 11 ms on one
thread, 6 ms on two for the 32,768-particle benchmark box (≈ 4 density passes); callers keep
the strain at the build to pass ∫γ̇ dt since then to the rebuild test (``list_validity``).

Symbols:

=========== ================================================================== ==========
symbol      meaning                                                            unit
=========== ================================================================== ==========
h           kernel support radius                                              [length]
skin        Verlet skin; r_c = h + skin is the list cutoff (cutoff)            [length]
cells       cells per direction (n_x, n_y, n_z), each cell ≥ r_c wide         1
cell_start  sorted particles of cell c are cell_start[c] .. cell_start[c+1]−1 1
order       order[new] = old index: sorted array = old array[order]           1
start       CSR offsets (N + 1,) int64 into neighbours (int32)                1
image_start first slot of i whose pair crosses a face (N,) int64              1
=========== ================================================================== ==========
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from suspsim.errors import SuspsimError
from suspsim.sph.boundaries import wrap_particles

#: Error codes returned by compiled functions.
OK, PAIR_OVERFLOW = 0, 1


class NeighbourListOverflowError(SuspsimError):
    """The neighbour list needs more pair slots than were allocated.

    ``required`` is the number of pairs found; allocate again with at least that capacity.
    """

    def __init__(self, required: int, capacity: int):
        self.required = int(required)
        self.capacity = int(capacity)
        super().__init__(
            f"neighbour list overflow: {self.required} pairs found but the capacity is "
            f"{self.capacity}; allocate with capacity >= {int(1.2 * self.required) + 1} "
            "(particles denser or more clustered than assumed?)")


def cell_grid(box, cutoff: float, dimension: int) -> np.ndarray:
    """Cells per direction, each at least ``cutoff`` wide (3 cells minimum; z = 1 in 2D)."""
    box = np.asarray(box, dtype=np.float64)
    cells = np.floor(box / cutoff).astype(np.int64)
    if dimension == 2:
        cells[2] = 1
    for axis in range(dimension):
        if cells[axis] < 3:
            raise ValueError(
                f"box length {box[axis]:g} in direction {'xyz'[axis]} holds fewer than 3 cells of "
                f"the list cutoff {cutoff:g}; enlarge the box or reduce h + skin")
    return cells


@njit(cache=True)
def _cell_index(x, length, n):
    """Cell of coordinate x ∈ [0, length), clamped against round-off at the faces."""
    c = int(x / length * n)
    if c < 0:
        return 0
    if c >= n:
        return n - 1
    return c


@njit(cache=True)
def sort_by_cell(positions, box, cells, cell_of, order, cell_start):
    """Counting sort of wrapped particles by cell; fills ``order`` and ``cell_start`` (O(N)).

    Cells are numbered c = (c_x n_y + c_y) n_z + c_z; particles keep their relative order within
    a cell. ``cell_of`` (N,) int64 is scratch.
    """
    nx, ny, nz = cells[0], cells[1], cells[2]
    n_cells = nx * ny * nz
    n_particles = positions.shape[0]
    cell_start[:] = 0
    for i in range(n_particles):
        c = ((_cell_index(positions[i, 0], box[0], nx) * ny
              + _cell_index(positions[i, 1], box[1], ny)) * nz
             + _cell_index(positions[i, 2], box[2], nz))
        cell_of[i] = c
        cell_start[c] += 1
    for c in range(1, n_cells):
        cell_start[c] += cell_start[c - 1]
    # cell_start[c] is now the end of cell c; filling backwards leaves it at the start.
    for i in range(n_particles - 1, -1, -1):
        c = cell_of[i]
        cell_start[c] -= 1
        order[cell_start[c]] = i
    cell_start[n_cells] = n_particles


@njit(cache=True)
def apply_permutation(source, order, destination):
    """destination[k] = source[order[k]] along the first axis (C-contiguous 1D or 2D arrays).

    Element by element on (N, columns) views: the row form ``destination[k] = source[o]`` took
    0.28 ms for (29,210, 3) floats, this 0.06 ms (one thread; two threads gained nothing).
    """
    n = order.shape[0]
    if n == 0:
        return
    src = source.reshape((n, source.size // n))
    dst = destination.reshape((n, destination.size // n))
    for k in range(n):
        o = order[k]
        for c in range(src.shape[1]):
            dst[k, c] = src[o, c]


@njit(cache=True)
def _gather_candidates(cell, positions, box, offset, cutoff, cells, cell_start, half, bx, by, bz,
                       bj):
    """Copy the particles of the stencil of ``cell`` into (bx, by, bz, bj), already shifted to
    the image nearest the cell; returns (n_plain, n_total): candidates [0, n_plain) need no
    image shift, [n_plain, n_total) do.

    Plain rows use the fixed periodic shift of each stencil cell. Rows across a sheared face
    (y-image n = ±1) search the x-cells covering [x_cell − nΔ − r_c, x_cell+1 − nΔ + r_c),
    widened by 1e−9 L_x against round-off so the stencil relation stays symmetric (4 cells,
    or all if n_x = 3, so Δ need not be a multiple of the cell size), and take each candidate's
    x image nearest the cell centre. Each cell is visited once. With ``half``, cells with a
    lower index are skipped: their pairs with this cell are listed from their side.
    """
    lx, ly, lz = box[0], box[1], box[2]
    nx, ny, nz = cells[0], cells[1], cells[2]
    csx = lx / nx
    cx = cell // (ny * nz)
    cy = (cell // nz) % ny
    cz = cell % nz
    x_centre = (cx + 0.5) * csx
    z_lo, z_n = (cz - 1, 3) if nz > 1 else (0, 1)
    m = 0
    n_plain = 0
    for want_image in (False, True):
        for ry in range(cy - 1, cy + 2):
            n = 0
            if ry < 0:
                n = -1
            elif ry >= ny:
                n = 1
            wy = ry - n * ny
            if n == 0:
                x_lo, x_n = cx - 1, 3
            else:
                shift = n * offset
                pad = cutoff + 1e-9 * lx
                x_lo = int(math.floor((cx * csx - shift - pad) / csx))
                x_hi = int(math.floor(((cx + 1) * csx - shift + pad) / csx))
                x_n = min(x_hi - x_lo + 1, nx)
            for kx in range(x_lo, x_lo + x_n):
                wx = kx % nx
                mx = (kx - wx) // nx
                for kz in range(z_lo, z_lo + z_n):
                    wz = kz % nz
                    mz = (kz - wz) // nz
                    if (n != 0 or mx != 0 or mz != 0) != want_image:
                        continue
                    other = (wx * ny + wy) * nz + wz
                    if half and other < cell:
                        continue
                    for j in range(cell_start[other], cell_start[other + 1]):
                        if n == 0:
                            bx[m] = positions[j, 0] + mx * lx
                        else:
                            x = positions[j, 0] + n * offset
                            bx[m] = x - lx * np.rint((x - x_centre) / lx)
                        by[m] = positions[j, 1] + n * ly
                        bz[m] = positions[j, 2] + mz * lz
                        bj[m] = j
                        m += 1
        if not want_image:
            n_plain = m
    return n_plain, m


@njit(inline="always", cache=True)
def _listed(i, j, half):
    """Whether candidate j of particle i belongs in its list: j > i (half list) or j ≠ i."""
    return (j > i) if half else (j != i)


@njit(cache=True, parallel=True)
def _sweep(positions, box, offset, cutoff, cells, cell_start, start, image_start, neighbours,
           half, group, share_lo, used, buf_x, buf_y, buf_z, buf_j, buf_d):
    """List the pairs of each block of cells into its share [share_lo[b], share_lo[b+1]).

    Each block copies a cell's stencil into a contiguous candidate buffer once and tests it
    against every particle of the cell: the squared distances first, in a loop of its own that
    LLVM vectorises (``buf_d``), then a branch-free compaction that writes every candidate and
    advances past the kept ones (the plain and image candidates in two loops, so that the
    split needs no test per candidate; 11 ms against 19 ms for one fused loop, one thread, the
    32,768-particle benchmark box). Where a particle's candidates might not fit the share, the
    compaction checks each slot. ``used[b]`` counts the block's pairs even beyond its share
    (those are not written). Variables of the prange body are not reused after it: numba
    would treat them as reductions. A particle of a group (``group[i]`` ≥ 0; ``group`` empty:
    no groups) drops the candidates of its own group in a compaction of its own, so that the
    others pay nothing for the test.
    """
    n_cells = cell_start.shape[0] - 1
    n_blocks = used.shape[0]
    rc2 = cutoff * cutoff
    grouped = group.shape[0] > 0
    for b in prange(n_blocks):
        bx, by, bz, bj, bd = buf_x[b], buf_y[b], buf_z[b], buf_j[b], buf_d[b]
        slot = share_lo[b]
        slot_end = share_lo[b + 1]
        for c in range(b * n_cells // n_blocks, (b + 1) * n_cells // n_blocks):
            if cell_start[c + 1] == cell_start[c]:
                continue
            n_plain, n_cand = _gather_candidates(c, positions, box, offset, cutoff, cells,
                                                 cell_start, half, bx, by, bz, bj)
            for i in range(cell_start[c], cell_start[c + 1]):
                xi, yi, zi = positions[i, 0], positions[i, 1], positions[i, 2]
                for k in range(n_cand):
                    dx = xi - bx[k]
                    dy = yi - by[k]
                    dz = zi - bz[k]
                    bd[k] = dx * dx + dy * dy + dz * dz
                start[i] = slot
                g = group[i] if grouped else -1
                if g >= 0 and slot + n_cand <= slot_end:
                    for k in range(n_plain):
                        j = bj[k]
                        neighbours[slot] = j
                        slot += (bd[k] < rc2) & _listed(i, j, half) & (group[j] != g)
                    image_start[i] = slot
                    for k in range(n_plain, n_cand):
                        j = bj[k]
                        neighbours[slot] = j
                        slot += (bd[k] < rc2) & _listed(i, j, half) & (group[j] != g)
                elif slot + n_cand <= slot_end:
                    for k in range(n_plain):
                        j = bj[k]
                        neighbours[slot] = j
                        slot += (bd[k] < rc2) & _listed(i, j, half)
                    image_start[i] = slot
                    for k in range(n_plain, n_cand):
                        j = bj[k]
                        neighbours[slot] = j
                        slot += (bd[k] < rc2) & _listed(i, j, half)
                else:
                    for k in range(n_cand):
                        if k == n_plain:
                            image_start[i] = slot
                        j = bj[k]
                        if slot < slot_end:
                            neighbours[slot] = j
                        slot += (bd[k] < rc2) & _listed(i, j, half) & (g < 0 or group[j] != g)
                    if n_plain == n_cand:
                        image_start[i] = slot
        used[b] = slot - share_lo[b]


#: ``group`` of a list without groups.
_NO_GROUPS = np.empty(0, dtype=np.int64)


def build_neighbour_list(positions, box, offset, cutoff, cells, cell_start, start, image_start,
                         neighbours, half=True, n_blocks=16, group=None):
    """CSR neighbour list of wrapped, cell-sorted positions; returns (code, n_pairs).

    The compiled build (:func:`_build_neighbour_list`) always receives the same argument
    types: numba's cache can give two signatures of one function, compiled in different
    processes, the same symbol, and a later process that loads one of them crashes
    (numba issue 10128; seen here as a segfault in every run after a run that compiled the
    ungrouped build beside a cached grouped one).

    half=True lists each pair once (j > i), half=False both directions. ``group`` (N,) int64,
    optional: pairs of two particles of one group (``group[i] == group[j] ≥ 0``) are not
    listed; the simulation's groups are its rigid bodies, whose inner pairs have no use
    (``density.body_particle_density``). Particle i's neighbours are
    ``neighbours[start[i]:start[i+1]]``: first those whose pair vector needs no image shift,
    from ``image_start[i]`` on those that need the minimum image. That split stays valid until
    the next build because positions are not wrapped in between.

    One parallel sweep over ``n_blocks`` blocks of cells, each writing into a share of
    ``neighbours`` proportional to its particle count; the shares are then compacted. If a
    share overflows while the total fits, a second sweep uses the exact shares. If the total
    does not fit, the code is :data:`PAIR_OVERFLOW` and n_pairs the capacity needed. Scratch
    of 5 × n_blocks × 36 × (max particles per cell) numbers is allocated per build.
    """
    return _build_neighbour_list(positions, np.asarray(box, dtype=np.float64), float(offset),
                                 float(cutoff), cells, cell_start, start, image_start,
                                 neighbours, bool(half), int(n_blocks),
                                 _NO_GROUPS if group is None else group)


@njit(cache=True)
def _build_neighbour_list(positions, box, offset, cutoff, cells, cell_start, start, image_start,
                          neighbours, half, n_blocks, group):
    """:func:`build_neighbour_list` compiled, every argument given."""
    n_particles = positions.shape[0]
    n_cells = cell_start.shape[0] - 1
    capacity = neighbours.shape[0]
    occupancy = 0
    for c in range(n_cells):
        occupancy = max(occupancy, cell_start[c + 1] - cell_start[c])
    n_blocks = max(1, min(n_blocks, n_cells))
    share_lo = np.empty(n_blocks + 1, dtype=np.int64)
    for b in range(n_blocks + 1):
        share_lo[b] = cell_start[b * n_cells // n_blocks] * capacity // max(n_particles, 1)
    used = np.zeros(n_blocks, dtype=np.int64)
    # Buffers per block allocated here: numba hoists an np.empty in a prange body out of the
    # loop, which would share it between threads.
    size = 36 * occupancy
    buf_x = np.empty((n_blocks, size))
    buf_y = np.empty((n_blocks, size))
    buf_z = np.empty((n_blocks, size))
    buf_j = np.empty((n_blocks, size), dtype=np.int32)
    buf_d = np.empty((n_blocks, size))
    for attempt in range(2):
        _sweep(positions, box, offset, cutoff, cells, cell_start, start, image_start, neighbours,
               half, group, share_lo, used, buf_x, buf_y, buf_z, buf_j, buf_d)
        total = used.sum()
        if total > capacity:
            return PAIR_OVERFLOW, total
        fits = True
        for b in range(n_blocks):
            fits &= used[b] <= share_lo[b + 1] - share_lo[b]
        if fits:
            break
        for b in range(n_blocks):
            share_lo[b + 1] = share_lo[b] + used[b]
    dest = 0
    for b in range(n_blocks):
        shift = share_lo[b] - dest
        for k in range(used[b]):
            neighbours[dest + k] = neighbours[share_lo[b] + k]
        for i in range(cell_start[b * n_cells // n_blocks],
                       cell_start[(b + 1) * n_cells // n_blocks]):
            start[i] -= shift
            image_start[i] -= shift
        dest += used[b]
    start[n_particles] = dest
    return OK, dest


@dataclass
class NeighbourList:
    """Buffers of one neighbour list (see the module docstring for the fields' meaning).

    ``n_pairs`` is valid after a build; ``reference`` holds the positions at that build.
    """

    cutoff: float
    skin: float
    cells: np.ndarray
    cell_start: np.ndarray
    cell_of: np.ndarray
    order: np.ndarray
    start: np.ndarray
    image_start: np.ndarray
    neighbours: np.ndarray
    reference: np.ndarray
    half: bool = True
    n_pairs: int = 0


def allocate_neighbour_list(n_particles: int, box, support: float, skin: float, dimension: int,
                            number_density: float, capacity_factor: float = 1.5,
                            half: bool = True) -> NeighbourList:
    """Allocate a list for ``n_particles`` at mean ``number_density`` [length^−d].

    Capacity = capacity_factor × the mean pair count of an ideal gas within r_c = support + skin.
    """
    cutoff = support + skin
    cells = cell_grid(box, cutoff, dimension)
    ball = math.pi * cutoff ** 2 if dimension == 2 else 4.0 / 3.0 * math.pi * cutoff ** 3
    per_particle = number_density * ball * (0.5 if half else 1.0)
    capacity = int(capacity_factor * per_particle * n_particles) + 16
    return NeighbourList(
        cutoff=cutoff, skin=skin, cells=cells,
        cell_start=np.zeros(int(np.prod(cells)) + 1, dtype=np.int64),
        cell_of=np.zeros(n_particles, dtype=np.int64),
        order=np.zeros(n_particles, dtype=np.int64),
        start=np.zeros(n_particles + 1, dtype=np.int64),
        image_start=np.zeros(n_particles, dtype=np.int64),
        neighbours=np.zeros(capacity, dtype=np.int32),
        reference=np.zeros((n_particles, 3)), half=half)


def raise_for_code(code: int, n_pairs: int, capacity: int) -> None:
    """Turn a build's error code into :class:`NeighbourListOverflowError`."""
    if code == PAIR_OVERFLOW:
        raise NeighbourListOverflowError(n_pairs, capacity)
    if code != OK:
        raise SuspsimError(f"neighbour list build returned unknown code {code}")


def rebuild_neighbour_list(nlist: NeighbourList, positions, velocities, box, offset: float,
                           shear_rate: float, particle_arrays=(), group=None) -> None:
    """Wrap, sort and list in place: the Python driver of the life cycle's step 1.

    ``positions``, ``velocities`` (N, 3) and every array in ``particle_arrays`` (first axis N)
    are wrapped/permuted in place into cell order; ``group`` (N,) int64, if given, must be one
    of them (pairs inside a group are not listed, :func:`build_neighbour_list`). Raises
    :class:`NeighbourListOverflowError`.
    """
    box = np.asarray(box, dtype=np.float64)
    wrap_particles(positions, velocities, box, offset, shear_rate)
    sort_by_cell(positions, box, nlist.cells, nlist.cell_of, nlist.order, nlist.cell_start)
    for array in (positions, velocities, *particle_arrays):
        source = array.copy()
        apply_permutation(source, nlist.order, array)
    code, n_pairs = build_neighbour_list(positions, box, offset, nlist.cutoff, nlist.cells,
                                         nlist.cell_start, nlist.start, nlist.image_start,
                                         nlist.neighbours, nlist.half, group=group)
    raise_for_code(code, n_pairs, nlist.neighbours.shape[0])
    nlist.n_pairs = int(n_pairs)
    nlist.reference[:] = positions
