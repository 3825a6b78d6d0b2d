"""Shared set-up of the neighbour-list tests: random and lattice scenes, builds, and brute-force
pairs and distances over the Lees–Edwards images."""
import itertools

import numpy as np

from suspsim.sph import neighbours as nb

CUTOFF = 1.0
BOXES = {3: [(3.3, 4.2, 3.0), (4.5, 3.1, 4.0)], 2: [(3.3, 4.2, 1.0), (4.5, 3.1, 1.0)]}


def image_shifts(box, offset, dim):
    zs = (-1, 0, 1) if dim == 3 else (0,)
    return np.array([(mx * box[0] + n * offset, n * box[1], mz * box[2])
                     for n, mx, mz in itertools.product((-1, 0, 1), (-2, -1, 0, 1, 2), zs)])


def brute_force_distances(positions, box, offset, dim):
    """(N, N) distance to the nearest image, by enumerating images."""
    d = positions[:, None, :] - positions[None, :, :]
    best = np.full(d.shape[:2], np.inf)
    for s in image_shifts(box, offset, dim):
        best = np.minimum(best, np.sqrt(((d - s) ** 2).sum(-1)))
    return best


def brute_force_pairs(positions, box, offset, cutoff, dim):
    r = brute_force_distances(positions, box, offset, dim)
    i, j = np.nonzero(np.triu(r < cutoff, 1))
    return set(zip(i.tolist(), j.tolist()))


def listed_arrays(nlist):
    """(i, j, k) of every listed pair, k its slot in ``neighbours``."""
    counts = np.diff(nlist.start)
    i = np.repeat(np.arange(len(counts)), counts)
    k = np.arange(nlist.start[-1])
    return i, nlist.neighbours[k].astype(np.int64), k


def listed(nlist):
    i, j, _ = listed_arrays(nlist)
    return list(zip(i.tolist(), j.tolist()))


def scene(kind, box, dim, rng, density=5.0):
    box = np.array(box, dtype=float)
    if kind == "random":
        n = int(density * np.prod(box[:dim]))
        positions = rng.uniform(0, 1, (n, 3)) * box
    else:  # a lattice that does not fit the box, so rows meet the faces unevenly
        axes = [np.arange(0.05, box[a], 0.53) for a in range(dim)] + [np.zeros(1)] * (3 - dim)
        positions = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    if dim == 2:
        positions[:, 2] = 0.0
    return box, positions


def build(positions, box, dim, offset, shear_rate=0.0, skin=0.0, half=True, support=CUTOFF):
    nlist = nb.allocate_neighbour_list(len(positions), box, support, skin, dim,
                                       len(positions) / np.prod(box[:dim]), half=half)
    velocities = np.zeros_like(positions)
    nb.rebuild_neighbour_list(nlist, positions, velocities, box, offset, shear_rate)
    return nlist, velocities
