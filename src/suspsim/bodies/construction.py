"""Rigid bodies built from SPH particles at the fluid's number density (SPEC §3.1).

Each body of a :class:`~suspsim.bodies.packing.Packing` becomes a rigid assembly of particles:

1. **Lattice.** The points x = ℓ k of a simple-cubic (2D: square) lattice in the body frame,
   k ∈ ℤ^d, ℓ = n^(−1/d) the fluid's spacing, that lie strictly inside the body: |x| < a for a
   sphere (analytic), |x| < r(x/|x|) for a grain (exact harmonic radius, as
   :func:`~suspsim.bodies.shapes.contains`). [choice: integer multiples of ℓ, so the lattice
   has the body's origin as a site — every body, however small, has at least that particle —
   and a sphere is symmetric under the cube group about its centre, which puts its centre of
   mass exactly on the centre and makes its inertia tensor isotropic.]
2. **Shell and core.** Only particles within one kernel support h (= ``support``) of the surface
   can see fluid; the others (the core) are dropped. Sphere: core ⇔ |x| ≤ a − h, the ball
   B(x, h) fits exactly. Grain [choice, stricter than the radial test r(u) − |x| ≥ h]: the
   radial depth over-estimates the distance to the surface by 1/cos α, α the angle between the
   radius and the normal (up to 47° on a 2.6:1 ellipsoid, so particles 0.68 h deep would be
   dropped), so a particle is core only if the whole ball B(x, h) is inside: r − |x| ≥ h and
   the ``BALL_DIRECTIONS`` points x + h u_k (Fibonacci directions, angular spacing ≈ 0.25 rad)
   are inside by the cube-map radius table minus its interpolation error
   (:mod:`~suspsim.bodies.radius_table`; ≈ 20 ms per grain of degree 20).
3. **Mass.** Every lattice particle of the full body has the fluid particle's mass m
   (``particle_mass``), so ρ = n m in both: M = N_full m [choice: the lattice count, not
   n m V — the body then displaces exactly the mass of the fluid particles its lattice
   replaces; the two differ by the lattice-counting error, a surface effect, −6 % for a/ℓ = 4].
4. **Centre of mass and inertia** of the full lattice (core included) [choice: from the same
   particles as the mass, each particle a uniform cube (2D: square) of side ℓ, so that the body
   is the union of its voxels]:

       X = (1/N) Σ x_c,   J = Σ m [(|y_c|² I − y_c y_cᵀ)] + N m ℓ²/6 I   (y_c = x_c − X),

   in 2D the voxel term is N m ℓ² diag(1/12, 1/12, 1/6). The lattice centre of mass X of a grain
   is not its centroid (the packing's body origin) — it differs by the counting error, ≲ 0.1 ℓ.
   [choice: the body's reference point is X, not the packing centre: offsets are x − X, and
   :attr:`BodyParticles.centre_shift` reports X so that R = centre + Q X
   (:meth:`BodyParticles.centres_of_mass`).] Principal moments and the rotation P to the
   principal frame (y_principal = P y_body, rows the principal axes, det +1) diagonalise J;
   spheres and discs keep P = I (J is diagonal by symmetry), grains have I_1 ≤ I_2 ≤ I_3.
The fluid lattice is cleared with :func:`fluid_outside_bodies` (periodic, minimum image, the
box at zero Lees–Edwards offset). Particles move with their body through
:mod:`~suspsim.bodies.coupling`.

Symbols:

======== ============================================================ =================
symbol   meaning                                                      unit
======== ============================================================ =================
n        number density of the fluid (= ``number_density``)           [length]^−d
ℓ        lattice spacing n^(−1/d)                                     [length]
h        kernel support radius (= ``support``)                        [length]
m        particle mass (= ``particle_mass``)                          [mass]
a, r(u)  sphere radius, grain radius function in the body frame       [length]
x_c      body-frame lattice point (origin: packing centre/centroid)   [length]
X        lattice centre of mass in the body frame                     [length]
y        offset from X, body frame                                    [length]
M, J     body mass and inertia tensor about X                         [mass], [mass length²]
P        body frame → principal frame rotation                        1
R, Q     centre of mass (box) and rotation (frame → box) of a body    [length], 1
V, Ω     body velocity and angular velocity (box frame)               [length/time], [1/time]
======== ============================================================ =================

References: Martys et al. (2010), Rheol. Acta 49, 1059 (seed 000), rigid inclusions as
particle assemblies.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from . import harmonics as sh
from .overlap import fibonacci_directions
from .packing import Packing
from .pairs import bin_by_cell
from .radius_table import build_table, table_error, table_radius
from .rotations import rotation_matrices

__all__ = ["BALL_DIRECTIONS", "BodyParticles", "build_body_particles", "fluid_outside_bodies"]

#: Directions of the ball test of a grain's core (module docstring, step 2) [choice: 200, an
#: angular spacing √(4π/200) ≈ 0.25 rad, i.e. 0.25 h on the sphere of radius h; an exterior
#: bump narrower than that is far below the resolution of degree-20 grains of a few h].
BALL_DIRECTIONS = 200
_PRINCIPAL_TOLERANCE = 1e-12


@dataclass(frozen=True)
class BodyParticles:
    """The particles of B rigid bodies, grouped by body (module docstring).

    Attributes
    ----------
    offsets : (M, 3) particle positions in each body's packing frame, relative to its centre
        of mass [length]; x_i = R_b + Q_b offsets_i with Q_b the packing orientation.
    principal_offsets : (M, 3) the same in the principal frame, P_b offsets_i [length]; use
        with principal-frame quaternions (:func:`~suspsim.bodies.rigid.principal_orientations`).
    body_index : (M,) int64 body of each particle; particles of body b are
        ``first[b]:first[b + 1]``.
    first : (B + 1,) int64 CSR starts.
    mass : (B,) N_full m [mass].
    inertia : (B, 3, 3) inertia tensor about the centre of mass, packing frame [mass length²].
    principal_moments : (B, 3) eigenvalues of ``inertia`` [mass length²].
    body_to_principal : (B, 3, 3) P_b, y_principal = P_b y_body (rows: principal axes).
    centre_shift : (B, 3) lattice centre of mass X_b in the packing frame [length]; zero for
        spheres.
    particle_count_full, particle_count_shell : (B,) int64 lattice particles of the full body
        and kept (shell) particles.
    number_density : n [length]^−d.  spacing : ℓ [length].  support : h [length].
    particle_mass : m [mass].
    dimension : 2 or 3.
    """

    offsets: np.ndarray
    principal_offsets: np.ndarray
    body_index: np.ndarray
    first: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    principal_moments: np.ndarray
    body_to_principal: np.ndarray
    centre_shift: np.ndarray
    particle_count_full: np.ndarray
    particle_count_shell: np.ndarray
    number_density: float
    spacing: float
    support: float
    particle_mass: float
    dimension: int

    @property
    def count(self) -> int:
        """Number of body particles M (shell particles of all bodies)."""
        return len(self.body_index)

    @property
    def body_count(self) -> int:
        """Number of bodies B."""
        return len(self.mass)

    def centres_of_mass(self, centres: np.ndarray, orientations: np.ndarray) -> np.ndarray:
        """R_b = centre_b + Q_b X_b (B, 3) from packing centres and orientations (w, x, y, z)."""
        rot = rotation_matrices(orientations)
        return np.asarray(centres, dtype=np.float64) + np.einsum("bij,bj->bi", rot,
                                                                 self.centre_shift)


def build_body_particles(packing: Packing, number_density: float, support: float = 1.0,
                         dimension: int = 3,
                         particle_mass: float = 1.0) -> BodyParticles:
    """Shell particles, core densities, mass and inertia of every body of ``packing``.

    Parameters
    ----------
    packing : spheres or grains; lengths in [length].
    number_density : fluid number density n [length]^−d; spacing ℓ = n^(−1/d).
    support : kernel support radius h [length]: the shell depth.
    dimension : 3, or 2 for discs (spheres only; the packing's z coordinates are ignored and
        the lattice is square in the xy plane).
    particle_mass : m [mass], the fluid particle's mass (ρ = n m).

    Raises
    ------
    ValueError : non-positive n or h, or 2D with grains.
    """
    if not number_density > 0.0 or not support > 0.0 or not particle_mass > 0.0:
        raise ValueError(f"number_density, support and particle_mass must be > 0, got "
                         f"{number_density}, {support}, {particle_mass}")
    if dimension not in (2, 3):
        raise ValueError(f"dimension must be 2 or 3, got {dimension}")
    if dimension == 2 and packing.coefficients is not None:
        raise ValueError("2D bodies are discs: build them from a sphere packing")
    spacing = float(number_density) ** (-1.0 / dimension)
    parts = []
    for b in range(packing.count):
        if packing.coefficients is None:
            inside, core, grid = _sphere_lattice(packing.radii[b], spacing, support, dimension)
        else:
            inside, core, grid = _grain_lattice(packing.coefficients[b],
                                                packing.support_radii[b], spacing, support)
        parts.append(_body_from_lattice(inside, core, grid, spacing, dimension, particle_mass,
                                        symmetric=packing.coefficients is None))
    counts_shell = np.array([len(p["offsets"]) for p in parts], dtype=np.int64)
    first = np.zeros(packing.count + 1, dtype=np.int64)
    first[1:] = np.cumsum(counts_shell)
    offsets = _stack([p["offsets"] for p in parts], (0, 3))
    rotations = np.array([p["to_principal"] for p in parts]).reshape(-1, 3, 3)
    principal = np.concatenate([p["offsets"] @ p["to_principal"].T for p in parts]) \
        if parts else np.zeros((0, 3))
    return BodyParticles(
        offsets=offsets, principal_offsets=np.ascontiguousarray(principal),
        body_index=np.repeat(np.arange(packing.count, dtype=np.int64), counts_shell),
        first=first,
        mass=np.array([p["mass"] for p in parts], dtype=np.float64),
        inertia=np.array([p["inertia"] for p in parts]).reshape(-1, 3, 3),
        principal_moments=np.array([p["moments"] for p in parts]).reshape(-1, 3),
        body_to_principal=rotations,
        centre_shift=np.array([p["shift"] for p in parts]).reshape(-1, 3),
        particle_count_full=np.array([p["full"] for p in parts], dtype=np.int64),
        particle_count_shell=counts_shell, number_density=float(number_density),
        spacing=spacing, support=float(support), particle_mass=float(particle_mass),
        dimension=int(dimension))


def _stack(arrays, empty_shape):
    return np.ascontiguousarray(np.concatenate(arrays)) if arrays else np.zeros(empty_shape)


def _lattice_grid(reach: float, spacing: float, dimension: int) -> np.ndarray:
    """Body-frame lattice points ℓ k, |k_a| ≤ ⌈reach/ℓ⌉, as an array (2K+1, …, 3) (z ≡ 0 in 2D)."""
    k = int(math.ceil(reach / spacing))
    axis = np.arange(-k, k + 1) * spacing
    axes = [axis] * dimension + [np.zeros(1)] * (3 - dimension)
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
    return grid.reshape(grid.shape[:dimension] + (3,))


def _sphere_lattice(radius: float, spacing: float, support: float, dimension: int):
    """Inside (|x| < a) and core (|x| ≤ a − h: the ball B(x, h) is inside) masks on the grid."""
    grid = _lattice_grid(radius, spacing, dimension)
    rho = np.linalg.norm(grid, axis=-1)
    inside = rho < radius
    return inside, inside & (rho <= radius - support), grid


def _grain_lattice(coefficients: np.ndarray, support_radius: float, spacing: float,
                   support: float):
    """Inside and core masks of a grain (module docstring, step 2)."""
    grid = _lattice_grid(support_radius, spacing, 3)
    flat = grid.reshape(-1, 3)
    rho = np.linalg.norm(flat, axis=1)
    near = rho < support_radius
    u = np.where(rho[:, None] > 0.0, flat / np.where(rho > 0.0, rho, 1.0)[:, None],
                 np.array([0.0, 0.0, 1.0]))
    radius = np.full(len(flat), -np.inf)
    radius[near] = sh.evaluate(coefficients, u[near])
    inside = rho < radius
    core = np.zeros(len(flat), dtype=np.bool_)
    ambiguous = np.flatnonzero(inside & (radius - rho >= support))
    if len(ambiguous):
        table = build_table(coefficients)
        slack = table_error(coefficients, table)
        passed = np.empty(len(ambiguous), dtype=np.bool_)
        _ball_inside(table, slack, flat[ambiguous], fibonacci_directions(BALL_DIRECTIONS),
                     support, passed)
        core[ambiguous] = passed
    shape = grid.shape[:-1]
    return inside.reshape(shape), core.reshape(shape), grid


@njit(cache=True)
def _ball_inside(table, slack, points, directions, radius, out):
    """out_i: every x_i + radius u_k satisfies |p| < r_table(p/|p|) − slack (surely inside)."""
    for i in range(points.shape[0]):
        ok = True
        for k in range(directions.shape[0]):
            px = points[i, 0] + radius * directions[k, 0]
            py = points[i, 1] + radius * directions[k, 1]
            pz = points[i, 2] + radius * directions[k, 2]
            rho = math.sqrt(px * px + py * py + pz * pz)
            if rho == 0.0:
                continue
            if rho >= table_radius(table, px / rho, py / rho, pz / rho) - slack:
                ok = False
                break
        out[i] = ok


def _body_from_lattice(inside, core, grid, spacing, dimension, mass, symmetric):
    """Shell offsets, mass, inertia and principal frame of one lattice body."""
    shell = inside & ~core
    points = grid[inside]
    full = len(points)
    centre = points.mean(axis=0)
    if symmetric:
        centre = np.zeros(3)  # exact by the cube symmetry of the centred lattice
    y = points - centre
    inertia = mass * (np.sum(y * y) * np.eye(3) - y.T @ y)
    voxel = np.array([1.0, 1.0, 1.0]) / 6.0 if dimension == 3 else np.array([1.0, 1.0, 2.0]) / 12.0
    inertia += full * mass * spacing ** 2 * np.diag(voxel)
    moments, to_principal = _principal_frame(inertia)
    return {"offsets": grid[shell] - centre,
            "mass": full * mass, "inertia": inertia, "moments": moments,
            "to_principal": to_principal, "shift": centre, "full": full}


def _principal_frame(inertia: np.ndarray):
    """(moments, P): P J Pᵀ = diag(moments), det P = +1; P = I if J is already diagonal."""
    off = inertia - np.diag(np.diag(inertia))
    if np.abs(off).max() <= _PRINCIPAL_TOLERANCE * np.trace(inertia):
        return np.diag(inertia).copy(), np.eye(3)
    moments, axes = np.linalg.eigh(inertia)
    if np.linalg.det(axes) < 0.0:
        axes[:, 2] *= -1.0
    return moments, np.ascontiguousarray(axes.T)


# ---------------------------------------------------------------------------------------------
# Clearing the fluid lattice

def fluid_outside_bodies(positions: np.ndarray, packing: Packing, box=None,
                         margin: float = 0.0, dimension: int = 3) -> np.ndarray:
    """(N,) True for the fluid points outside every body enlarged radially by ``margin``.

    A point p is removed when, with d the periodic minimum image of p − centre_b and
    y = Q_bᵀ d, |y| < a_b + margin (sphere) or |y| < r_b(y/|y|) + margin (grain, exact radius;
    the same test as :func:`~suspsim.bodies.shapes.contains`). Bodies are binned by a cell list
    of the points, so the cost is O(N + Σ_b points near b). ``box`` defaults to
    ``packing.box``; the minimum image needs 2 (support radius + margin) ≤ min L. With
    ``dimension`` 2 (discs) z is ignored: points, centres and the box's z length.
    """
    x = np.array(positions, dtype=np.float64)
    box = np.array(packing.box if box is None else box, dtype=np.float64)
    centres = np.array(packing.centres, dtype=np.float64)
    reach = np.asarray(packing.support_radii, dtype=np.float64) + margin
    if dimension == 2:
        x[:, 2] = 0.0
        centres[:, 2] = 0.0
        box[2] = 4.0 * float(reach.max(initial=0.0)) + 1.0  # one z image, never a neighbour
    if len(reach) and 2.0 * reach.max() > box.min():
        raise ValueError(f"a body's reach {reach.max():.4g} exceeds half the box "
                         f"{box.min():.4g}: the minimum image is ambiguous")
    keep = np.ones(len(x), dtype=np.bool_)
    if packing.count == 0 or len(x) == 0:
        return keep
    to_body = np.ascontiguousarray(np.transpose(rotation_matrices(packing.orientations),
                                                (0, 2, 1)))
    if packing.coefficients is None:
        coefficients = np.zeros((packing.count, 1))
        alpha = beta = np.zeros((1, 1))
        grains = False
    else:
        coefficients = np.ascontiguousarray(packing.coefficients, dtype=np.float64)
        alpha, beta = sh.recurrence_tables(sh.degree_of(coefficients[0]))
        grains = True
    cells = np.maximum(1, np.minimum((box / max(0.5 * float(reach.mean()), 1e-9)).astype(np.int64),
                                     256))
    _clear_bodies(x, box, cells, centres,
                  to_body, reach, np.asarray(packing.radii, dtype=np.float64),
                  coefficients, alpha, beta, grains, float(margin), keep)
    return keep


@njit(cache=True)
def _clear_bodies(x, box, cells, centres, to_body, reach, radii, coefficients, alpha,
                  beta, grains, margin, keep):
    """Set keep[i] = False for points inside a body (see :func:`fluid_outside_bodies`)."""
    _, start, members = bin_by_cell(x, box, cells)
    degree = alpha.shape[0] - 1
    low = np.empty(3, np.int64)
    span = np.empty(3, np.int64)
    for b in range(centres.shape[0]):
        for d in range(3):
            width = box[d] / cells[d]
            lo = int(math.floor((centres[b, d] - reach[b]) / width))
            hi = int(math.floor((centres[b, d] + reach[b]) / width))
            if hi - lo + 1 >= cells[d]:
                low[d], span[d] = 0, cells[d]
            else:
                low[d], span[d] = lo, hi - lo + 1
        reach2 = reach[b] * reach[b]
        for ox in range(span[0]):
            cx = (low[0] + ox) % cells[0]
            for oy in range(span[1]):
                cy = (low[1] + oy) % cells[1]
                for oz in range(span[2]):
                    c = (cx * cells[1] + cy) * cells[2] + (low[2] + oz) % cells[2]
                    for k in range(start[c], start[c + 1]):
                        i = members[k]
                        if not keep[i]:
                            continue
                        dx = x[i, 0] - centres[b, 0]
                        dy = x[i, 1] - centres[b, 1]
                        dz = x[i, 2] - centres[b, 2]
                        dx -= box[0] * np.rint(dx / box[0])
                        dy -= box[1] * np.rint(dy / box[1])
                        dz -= box[2] * np.rint(dz / box[2])
                        d2 = dx * dx + dy * dy + dz * dz
                        if d2 >= reach2:
                            continue
                        rho = math.sqrt(d2)
                        if not grains:
                            if rho < radii[b] + margin:
                                keep[i] = False
                            continue
                        if rho == 0.0:
                            keep[i] = False  # the origin is inside (star-shaped, r > 0)
                            continue
                        r = to_body[b]
                        yx = r[0, 0] * dx + r[0, 1] * dy + r[0, 2] * dz
                        yy = r[1, 0] * dx + r[1, 1] * dy + r[1, 2] * dz
                        yz = r[2, 0] * dx + r[2, 1] * dy + r[2, 2] * dz
                        radius = sh.evaluate_one(coefficients[b], degree, alpha, beta,
                                                 yx / rho, yy / rho, yz / rho)
                        if rho < radius + margin:
                            keep[i] = False
