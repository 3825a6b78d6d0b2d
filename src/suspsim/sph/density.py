"""Summation density and the step's pair table: the first pair pass, template for the others.

d_p = Σ_q W(r_pq), self term included; ρ_p = m d_p (SPEC §2.2).

The pass also writes the **pair table** of the step, which later passes (shear rate, forces)
read instead of recomputing geometry: for each listed pair with r < h, in particle i's
segment ``[pair_start[i], pair_end[i])`` of the table, first the pairs inside the box, from
``pair_cross[i]`` on those across a face; ``pair_j[k]`` = j, the row ``pair_geometry[k] =
(dx, dy, dz, F)``: r_ij = r_i − r_j at its nearest image and F(r_ij) of the pass's kernel,
and for a pair across a face ``pair_image[k]`` = n, its LE image index (velocity correction
v_ij,x −= n γ̇ L_y; n = 0 inside the box). r² = dx² + dy² + dz². Measured on the
32,768-particle benchmark box (one thread): writing it costs 1.0 ms here (1.9 → 2.9 ms) and
saves 3.1 ms in a shear-rate pass (6.0 → 2.9 ms: no minimum image, no square root, no kernel,
no skin pairs, which are 32 % of the listed pairs at skin 0.2 h); a row per pair was faster
than an array per column, and n out of the row (int8: |n| ≤ 1 between rebuilds; read for the
pairs across a face only) saves 0.28 ms per step (``integrator.accelerations`` 9.76 → 9.48
ms: 32 instead of 40 bytes per pair read by three passes).

The table is **compact**: it holds the pairs within h only, not a row per listed pair. Chunk c
of the pass (particles lo..hi−1) writes its particles' segments one after the other into its
own region of the table, rows ⌊P·start[lo]/L⌋ .. ⌊P·start[hi]/L⌋ − 1 (P table rows, L listed
pairs), so chunks never share rows and the table needs no prefix pass. The pairs within h are
about (h/r_c)^d of the listed ones (58 % at skin 0.2 h in 3D), so a table sized to them with a
margin (:func:`pair_capacity`) has 11.2 rows per particle on the benchmark box, where a row
per list slot took 22.2. A chunk whose region would overflow stops and the pass returns
:data:`TABLE_OVERFLOW`; the caller grows the table and repeats the pass, which gives the same
pairs in the same order, so results do not depend on the table's size. With the float32 rows
(:data:`GEOMETRY_DTYPE`) the table went from 912 to 234 bytes per particle.

Pattern of a pair pass:

- input: cell-sorted positions (N, 3), unwrapped since the list build; the CSR half list
  (start, image_start, neighbours); the box and the current Lees–Edwards offset Δ(t);
- per particle i two inner loops: neighbours[start[i]:image_start[i]] need no image shift,
  neighbours[image_start[i]:start[i+1]] cross a face and take ``minimum_image_3d``
  (6 % of the pairs; skipping three roundings for the rest: 13.3 → 6.2 ns per pair);
- kernels evaluated branch-free for every listed pair (zero beyond h);
- indices without numba's negative-index fix-up: k runs from 0 over per-particle views of the
  list and the table, j is unsigned (``pair_j`` is uint32; this pass casts the list's int32)
  and arrays with a row per particle are indexed ``a[j, c]``; a signed index costs a sign
  test and keeps the array's length live, per access (before: density 2.05 ms, gradient sums
  2.60, dissipation sums 1.47, force sums 2.61; after: 1.59, 2.36, 1.25, 2.24);
- no array view that lives across a branch of a pair loop (index the 2D array instead):
  numba then keeps its reference count, an atomic call per view and pair (force sums with a
  row view ``acc[j]`` used on both sides of the ∇a branch: 3.46 ms);
- kernel choice at build time at no cost in the loop: the pair loop is ``inline="always"``
  and called once per kernel code with that code as a constant, so one specialised loop is
  compiled per kernel (a runtime code inside the loop: 6.3 vs 4.5 ns per pair; function
  objects as arguments are as fast but make the caller uncacheable);
- i's own sum is kept in a register and j's share scattered (half list, each pair once);
- parallel (``chunks``): particles are split into contiguous chunks of equal listed-pair count
  (this pass computes the bounds; the later passes of the step take them as they are);
  chunk 0 scatters into the output, chunk c ≥ 1 into its own buffer row ``scratch[c − 1]``,
  which ``add_chunk_buffers`` adds afterwards. No races, no allocation,
  and the result depends neither on thread scheduling nor on the thread count, only (at
  round-off level) on the chunk count T = scratch.shape[0] + 1 fixed by the caller. Do not
  reuse a variable name of a prange body after the loop: numba treats it as a reduction.

Symbols:

============= ===================================================== ==============
symbol        meaning                                               unit
============= ===================================================== ==============
d_p           number density of particle p (density)                [length]^−d
W, F          kernel and −W'/r (``kernels``), support h            [length]^−d, ^−(d+2)
h             support radius                                        [length]
Δ             Lees–Edwards offset (offset), 0 for periodic          [length]
dx, dy, dz    components of r_ij at the nearest image               [length]
n             LE y-image index of the pair                          1
============= ===================================================== ==============
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit, prange

from suspsim.sph import JIT_OPTIONS
from suspsim.sph.boundaries import minimum_image_3d
from suspsim.sph.kernels import LUCY_2D, LUCY_3D, QUINTIC_2D, QUINTIC_3D, kernel_f, kernel_w
from suspsim.sph.chunks import add_chunk_buffers, chunk_bounds

#: Columns of ``pair_geometry``.
DX, DY, DZ, F = range(4)
#: Storage of ``pair_geometry`` [choice]: float32 halves the table (16 instead of 32 bytes a
#: row). The passes compute in float64 from the rounded r_ij and F (relative error 2⁻²⁴ ≈ 6e-8),
#: each pair's row serving both particles, so pair forces stay antisymmetric and momentum is
#: conserved to float64 round-off. Measured on the benchmark box (fluid-papanastasiou, 350
#: steps): the viscosity changes by 8e-11 of itself and the density error by 2e-11, and a
#: linear velocity field's corrected gradient stays exact to 2.5e-7 on a disordered set
#: (float64: 1e-12); tests hold that to 16 ε of this type.
GEOMETRY_DTYPE = np.float32
#: Return codes of :func:`summation_density`.
TABLE_OK, TABLE_OVERFLOW = 0, 1
#: Table rows per expected pair within h [choice]: the margin over the ideal-gas count. A
#: sheared SPH fluid holds more close pairs than an ideal gas (its first neighbour shell lies
#: inside h): on the benchmark box 1.06 of the ideal count at the start, rising to 1.17 within
#: 300 steps, so 1.3 leaves 11 % for compressed regions and for a chunk holding more than its
#: share; beyond that the table grows (``Simulation``) and keeps its size.
PAIR_MARGIN = 1.3


@dataclass
class PairTable:
    """The step's pairs within h, compact per chunk (see module docstring)."""

    pair_start: np.ndarray
    pair_end: np.ndarray
    pair_j: np.ndarray
    pair_geometry: np.ndarray
    pair_cross: np.ndarray
    pair_image: np.ndarray


def pair_capacity(n_particles: int, number_density: float, support: float, dimension: int,
                  list_capacity: int) -> int:
    """Table rows for ``n_particles`` at ``number_density`` [length^−d]: :data:`PAIR_MARGIN` ×
    the ideal-gas half-list pair count within ``support``, at most ``list_capacity`` (a table
    with a row per listed pair never overflows)."""
    ball = math.pi * support ** 2 if dimension == 2 else 4.0 / 3.0 * math.pi * support ** 3
    rows = int(PAIR_MARGIN * 0.5 * number_density * ball * n_particles) + 64
    return min(rows, int(list_capacity))


def allocate_pair_table(n_particles: int, capacity: int) -> PairTable:
    """Pair table of ``capacity`` rows."""
    return PairTable(pair_start=np.zeros(n_particles, dtype=np.int64),
                     pair_end=np.zeros(n_particles, dtype=np.int64),
                     pair_j=np.zeros(capacity, dtype=np.uint32),
                     pair_geometry=np.zeros((capacity, 4), dtype=GEOMETRY_DTYPE),
                     pair_cross=np.zeros(n_particles, dtype=np.int64),
                     pair_image=np.zeros(capacity, dtype=np.int8))


_KERNEL_ERROR = "pair passes take the 2D and 3D kernel codes only"


@njit(inline="always", **JIT_OPTIONS)
def _pair(j, s, dx, dy, dz, kernel, h, h2, acc, pair_j, pair_geometry):
    """One listed pair (i, j) with r_ij = (dx, dy, dz): acc[j] += W(r) [SPEC §2.2]; writes
    slot s of i's table segment (kept, i.e. the next slot is s + 1, only if r < h); returns
    (W, next slot)."""
    r2 = dx * dx + dy * dy + dz * dz
    r = math.sqrt(r2)
    w = kernel_w(kernel, r, h)
    acc[j] += w
    pair_j[s] = j
    pair_geometry[s, DX] = dx
    pair_geometry[s, DY] = dy
    pair_geometry[s, DZ] = dz
    pair_geometry[s, F] = kernel_f(kernel, r, h)
    return w, s + (r2 < h2)


@njit(inline="always", **JIT_OPTIONS)
def _density_loop(lo, hi, positions, box, offset, start, image_start, neighbours, kernel, h,
                  acc, row_lo, row_hi, pair_start, pair_end, pair_j, pair_geometry, pair_cross,
                  pair_image):
    """acc[p] += Σ_q W(r_pq) over the listed pairs of particles lo..hi−1 (both ends), + W(0);
    their pair table segments one after the other in rows row_lo..row_hi−1. Returns
    :data:`TABLE_OVERFLOW` (and stops, with pair_end[hi − 1] = −1 as the mark that
    :func:`summation_density` reads) when a particle's listed pairs might not fit."""
    lx, ly, lz = box[0], box[1], box[2]
    h2 = h * h
    w0 = kernel_w(kernel, 0.0, h)
    row = row_lo
    for i in range(lo, hi):
        xi, yi, zi = positions[i, 0], positions[i, 1], positions[i, 2]
        own = w0
        first, last = start[i], start[i + 1]
        # _pair writes a row before it knows whether the pair is kept: room for every listed one.
        end = row + (last - first)
        if end > row_hi:
            pair_end[hi - 1] = -1
            return TABLE_OVERFLOW
        listed = neighbours[first:last]
        js, rows, images = pair_j[row:end], pair_geometry[row:end], pair_image[row:end]
        n_plain = image_start[i] - first
        s = 0
        for k in range(n_plain):
            j = np.uint32(listed[k])
            w, s = _pair(j, s, xi - positions[j, 0], yi - positions[j, 1], zi - positions[j, 2],
                         kernel, h, h2, acc, js, rows)
            own += w
        pair_start[i] = row
        pair_cross[i] = row + s
        crossing = listed[n_plain:]
        for k in range(crossing.shape[0]):
            j = np.uint32(crossing[k])
            dx, dy, dz, n = minimum_image_3d(xi - positions[j, 0], yi - positions[j, 1],
                                             zi - positions[j, 2], lx, ly, lz, offset)
            images[s] = n
            w, s = _pair(j, s, dx, dy, dz, kernel, h, h2, acc, js, rows)
            own += w
        row += s
        pair_end[i] = row
        acc[i] += own
    return TABLE_OK


@njit(**JIT_OPTIONS)
def _density_chunk(lo, hi, positions, box, offset, start, image_start, neighbours, kernel, h,
                   acc, row_lo, row_hi, pair_start, pair_end, pair_j, pair_geometry, pair_cross,
                   pair_image):
    """:func:`_density_loop` compiled once per kernel code (the code is a constant in each)."""
    if kernel == LUCY_3D:
        return _density_loop(lo, hi, positions, box, offset, start, image_start, neighbours,
                             LUCY_3D, h, acc, row_lo, row_hi, pair_start, pair_end, pair_j,
                             pair_geometry, pair_cross, pair_image)
    elif kernel == LUCY_2D:
        return _density_loop(lo, hi, positions, box, offset, start, image_start, neighbours,
                             LUCY_2D, h, acc, row_lo, row_hi, pair_start, pair_end, pair_j,
                             pair_geometry, pair_cross, pair_image)
    elif kernel == QUINTIC_3D:
        return _density_loop(lo, hi, positions, box, offset, start, image_start, neighbours,
                             QUINTIC_3D, h, acc, row_lo, row_hi, pair_start, pair_end, pair_j,
                             pair_geometry, pair_cross, pair_image)
    elif kernel == QUINTIC_2D:
        return _density_loop(lo, hi, positions, box, offset, start, image_start, neighbours,
                             QUINTIC_2D, h, acc, row_lo, row_hi, pair_start, pair_end, pair_j,
                             pair_geometry, pair_cross, pair_image)
    else:
        raise ValueError(_KERNEL_ERROR)


@njit(inline="always", **JIT_OPTIONS)
def _chunk_rows(start, lo, hi, n_rows):
    """Table rows of the chunk of particles lo..hi−1: its share of the listed pairs, scaled to
    ``n_rows`` (module docstring)."""
    n_listed = start[start.shape[0] - 1]
    if n_listed == 0:
        return 0, 0
    return start[lo] * n_rows // n_listed, start[hi] * n_rows // n_listed


@njit(parallel=True, **JIT_OPTIONS)
def mass_density(density, mass, volume):
    """ρ = m d in place (``density`` holds d on entry) and the particle volumes V = m/ρ = 1/d."""
    for i in prange(density.shape[0]):
        volume[i] = 1.0 / density[i]
        density[i] *= mass


@njit(**JIT_OPTIONS)
def fluid_mean_density(density, body_of):
    """Mean of ``density`` over the fluid particles (``body_of`` < 0) [m h^−d]; NaN without
    fluid. The pressure reference ``fluid_mean`` takes it every step: serial, so that the sum
    does not depend on the thread count, in eight interleaved partial sums, which do not wait
    on one another."""
    totals = np.zeros(8)
    count = 0
    for i in range(density.shape[0]):
        if body_of[i] < 0:
            totals[i & 7] += density[i]
            count += 1
    return totals.sum() / count if count > 0 else math.nan


@njit(**JIT_OPTIONS)
def summation_density_serial(positions, box, offset, start, image_start, neighbours, kernel, h,
                             density, pair_start, pair_end, pair_j, pair_geometry, pair_cross,
                             pair_image):
    """d_p = Σ_q W(r_pq) incl. self [SPEC §2.2; Martys 2010 Eq. 6] and the pair table, one
    thread; arguments and return code as :func:`summation_density`."""
    density[:] = 0.0
    n = positions.shape[0]
    row_lo, row_hi = _chunk_rows(start, 0, n, pair_j.shape[0])
    return _density_chunk(0, n, positions, box, offset, start, image_start, neighbours, kernel,
                          h, density, row_lo, row_hi, pair_start, pair_end, pair_j,
                          pair_geometry, pair_cross, pair_image)


@njit(parallel=True, **JIT_OPTIONS)
def summation_density(positions, box, offset, start, image_start, neighbours, kernel, h,
                      density, pair_start, pair_end, pair_j, pair_geometry, pair_cross,
                      pair_image, scratch, bounds):
    """d_p = Σ_q W(r_pq) incl. self [SPEC §2.2; Martys 2010 Eq. 6] and the pair table, parallel.

    Parameters
    ----------
    positions : (N, 3) float64, cell-sorted (z ≡ 0 in 2D)
    box : (3,) float64, (L_x, L_y, L_z)
    offset : float, Lees–Edwards offset Δ(t) (0 for a periodic box)
    start, image_start, neighbours : CSR half list from ``build_neighbour_list``
    kernel : int, kernel code (``kernels.LUCY_3D`` ...); h : support radius
    density : (N,) float64, output
    pair_start, pair_end, pair_j, pair_geometry, pair_cross, pair_image : output pair table
        (:func:`allocate_pair_table`)
    scratch : (T − 1, N) float64: the pass runs T chunks (one row per chunk after the
        first); T = ``numba.get_num_threads()`` for full speed, T = 1 (shape (0, N)) serial
    bounds : (T + 1,) int64 scratch for the chunk bounds

    Returns :data:`TABLE_OK`, or :data:`TABLE_OVERFLOW` when the table is too small (density
    and table are then incomplete: grow the table and call again).
    """
    if kernel != LUCY_3D and kernel != LUCY_2D and kernel != QUINTIC_3D and kernel != QUINTIC_2D:
        raise ValueError(_KERNEL_ERROR)  # here: an exception inside prange is a SystemError
    n_chunks = scratch.shape[0] + 1
    n_rows = pair_j.shape[0]
    chunk_bounds(start, n_chunks, bounds)
    for c in prange(n_chunks):
        lo, hi = bounds[c], bounds[c + 1]
        row_lo, row_hi = _chunk_rows(start, lo, hi, n_rows)
        if c == 0:
            density[:] = 0.0
            _density_chunk(lo, hi, positions, box, offset, start, image_start, neighbours,
                           kernel, h, density, row_lo, row_hi, pair_start, pair_end, pair_j,
                           pair_geometry, pair_cross, pair_image)
        else:
            acc = scratch[c - 1]
            acc[lo:] = 0.0
            _density_chunk(lo, hi, positions, box, offset, start, image_start, neighbours,
                           kernel, h, acc, row_lo, row_hi, pair_start, pair_end, pair_j,
                           pair_geometry, pair_cross, pair_image)
    # Chunks report through their last particle's pair_end: no allocation in the step.
    for c in range(n_chunks):
        if bounds[c + 1] > bounds[c] and pair_end[bounds[c + 1] - 1] < 0:
            return TABLE_OVERFLOW
    add_chunk_buffers(density, scratch, bounds, n_chunks, 1)
    return TABLE_OK


@njit(inline="always", **JIT_OPTIONS)
def _shepard_loop(lo, hi, pair_start, pair_end, pair_j, geometry, body_of, kernel, h, rho, rho_eq,
                  c2, viscosity_hat, acc):
    """acc[3 j] += W, acc[3 j + 1] += W P_f, acc[3 j + 2] += W μ̂_f over the fluid–body pairs of
    particles lo..hi−1, for the body particle j of each pair (either end)."""
    for i in range(lo, hi):
        body_i = body_of[i]
        p_i = c2 * (rho[i] - rho_eq)
        mu_i = viscosity_hat[i]
        for k in range(pair_start[i], pair_end[i]):
            j = pair_j[k]
            if (body_i < 0) == (body_of[j] < 0):
                continue
            row = geometry[k]
            w = kernel_w(kernel, math.sqrt(row[DX] * row[DX] + row[DY] * row[DY]
                                           + row[DZ] * row[DZ]), h)
            if body_i >= 0:
                acc[3 * i] += w
                acc[3 * i + 1] += w * c2 * (rho[j] - rho_eq)
                acc[3 * i + 2] += w * viscosity_hat[j]
            else:
                acc[3 * j] += w
                acc[3 * j + 1] += w * p_i
                acc[3 * j + 2] += w * mu_i


@njit(parallel=True, **JIT_OPTIONS)
def body_particle_density(pair_start, pair_end, pair_j, geometry, body_of, kernel, h, rho, rho_eq,
                          c2, mass, viscosity_hat, acc, scratch, bounds, volume):
    """Density and viscosity of rigid-body particles from the fluid around them.

    A body particle j takes the Shepard average of its fluid neighbours' pressures,
    P_j = Σ_f P_f W_jf / Σ_f W_jf with P_f = c² (ρ_f − ρ_eq) (Adami, Hu & Adams 2012, Eq. 27,
    without the acceleration term: Re ≪ 1; SPEC §5.3), and the density of the inverted EOS,
    ρ_j = ρ_eq + P_j/c², V_j = m/ρ_j. Its own summation density would instead reflect how the
    body's lattice meets the fluid's (shell particles sit 5–10 % below ρ_eq after the start's
    relaxation, a tension that pulls fluid onto the surface and kept the relaxation from
    converging). A body particle without fluid neighbours gets ρ_eq.

    Likewise its μ̂_j = Σ_f μ̂_f W_jf / Σ_f W_jf in ``viscosity_hat`` [choice], the normalised
    viscosity of the fluid beside it, which a pair of particles of two different bodies uses
    (a fluid–body pair takes the fluid's μ̂ at both ends, ``force_pass``). μ̂_f is the previous
    step's (this step's is computed later from the volumes set here; the normalisation leaves
    body particles' μ̂ alone); a body particle without fluid neighbours keeps its value. Pairs
    inside one body have no force (the body moves rigidly) and, with density and μ̂ taken from
    the fluid, no other use, so the list leaves them out (``group`` of
    ``neighbours.build_neighbour_list``; a fifth of the pairs within h at φ = 0.4). A body
    particle's own rate and dissipation factor then come from a one-sided neighbourhood, and
    the shell's inner particles have no neighbours at all.

    One sweep of the pair table in the chunks of the density pass (``bounds``; pattern of
    ``chunks``): ``acc`` (3N,) holds (Σ W, Σ W P_f, Σ W μ̂_f) per particle, ``scratch``
    (T − 1, ≥ 3N) the other chunks'.
    """
    n_chunks = scratch.shape[0] + 1
    for c in prange(n_chunks):
        lo, hi = bounds[c], bounds[c + 1]
        if c == 0:
            acc[:] = 0.0
            _shepard_loop(lo, hi, pair_start, pair_end, pair_j, geometry, body_of, kernel, h,
                          rho, rho_eq, c2, viscosity_hat, acc)
        else:
            buffer = scratch[c - 1]
            buffer[3 * lo:] = 0.0
            _shepard_loop(lo, hi, pair_start, pair_end, pair_j, geometry, body_of, kernel, h,
                          rho, rho_eq, c2, viscosity_hat, buffer)
    add_chunk_buffers(acc, scratch, bounds, n_chunks, 3)
    for i in prange(rho.shape[0]):
        if body_of[i] >= 0:
            weight = acc[3 * i]
            p = acc[3 * i + 1] / weight if weight > 0.0 else 0.0
            rho[i] = rho_eq + p / c2
            volume[i] = mass / rho[i]
            if weight > 0.0:
                viscosity_hat[i] = acc[3 * i + 2] / weight
