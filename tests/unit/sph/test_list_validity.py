"""The rebuild criterion of the neighbour list (``list_validity``) against brute force: the
bound on the two largest displacements, and the outliers checked pair by pair, scanned against
every particle in a small box and searched in the build's cells in a wide one."""
import math

import numpy as np
import pytest

from neighbour_helpers import brute_force_pairs, build, listed, scene
from suspsim.sph import list_validity as lv

SKIN = 0.3


def moved_scene(rng):
    box, positions = scene("random", (4.0, 5.3, 4.0), 3, rng, density=4.0)
    offset = 1.1
    nlist, _ = build(positions, box, 3, offset, skin=SKIN)
    return box, positions, offset, nlist


def missed_pairs(positions, box, offset, nlist):
    within_h = brute_force_pairs(positions, box, offset, nlist.cutoff - nlist.skin, 3)
    return within_h - set(listed(nlist))


def test_no_pair_missed_below_half_skin():
    rng = np.random.default_rng(5)
    box, positions, offset, nlist = moved_scene(rng)
    step = rng.normal(size=positions.shape)
    step *= ((0.499 * SKIN) * rng.uniform(0.5, 1, (len(step), 1))
             / np.linalg.norm(step, axis=1)[:, None])
    moved = positions + step  # unwrapped: positions may leave the box
    assert not lv.needs_rebuild(moved, nlist.reference, 0.0, nlist.cutoff, SKIN)
    assert not missed_pairs(moved, box, offset, nlist)


def test_no_pair_missed_under_affine_shear():
    # particles carried by v_x = γ̇ y for strain A while the image offset moves by A L_y: only
    # the non-affine part counts, so no rebuild although particles moved up to A L_y = 2.1
    rng = np.random.default_rng(6)
    box, positions, offset, nlist = moved_scene(rng)
    strain = 0.4
    moved = positions.copy()
    moved[:, 0] += strain * positions[:, 1]
    moved += rng.uniform(-0.01, 0.01, moved.shape)
    new_offset = (offset + strain * box[1]) % box[0]
    assert not lv.needs_rebuild(moved, nlist.reference, strain, nlist.cutoff, SKIN)
    assert not missed_pairs(moved, box, new_offset, nlist)


def test_rebuild_triggered():
    rng = np.random.default_rng(7)
    box, positions, offset, nlist = moved_scene(rng)
    reference = nlist.reference
    moved = positions.copy()
    moved[3, 0] += 0.16
    assert not lv.needs_rebuild(moved, reference, 0.0, nlist.cutoff, SKIN)
    moved[8, 1] -= 0.16  # two particles approaching by 0.32 > skin
    assert lv.needs_rebuild(moved, reference, 0.0, nlist.cutoff, SKIN)
    # at rest while the offset slides: the images of particles near the faces approach
    assert not lv.needs_rebuild(positions, reference, 0.001, nlist.cutoff, SKIN)
    assert lv.needs_rebuild(positions, reference, 0.1, nlist.cutoff, SKIN)
    # affine motion: the strain alone triggers once the sheared cutoff sphere dips below h
    sheared = positions.copy()
    sheared[:, 0] += 0.6 * positions[:, 1]
    assert lv.needs_rebuild(sheared, reference, 0.6, nlist.cutoff, SKIN)
    wrapped = positions.copy()
    wrapped[0, 1] -= box[1]  # a wrap between builds shows as a jump and forces a rebuild
    assert lv.needs_rebuild(wrapped, reference, 0.0, nlist.cutoff, SKIN)
    wrapped[0, 1] = np.nan
    assert lv.needs_rebuild(wrapped, reference, 0.0, nlist.cutoff, SKIN)


def test_a_pair_missed_when_the_criterion_fires():
    # two particles 1.35 apart (outside r_c = 1.3) approach by 0.4: the list misses them
    box = np.array([4.0, 4.0, 4.0])
    positions = np.array([[1.0, 2.0, 2.0], [2.35, 2.0, 2.0]])
    nlist, _ = build(positions.copy(), box, 3, 0.0, skin=SKIN)
    moved = nlist.reference.copy()
    moved[:, 0] += np.where(moved[:, 0] < 2, 0.2, -0.2)
    assert missed_pairs(moved, box, 0.0, nlist)
    assert lv.needs_rebuild(moved, nlist.reference, 0.0, nlist.cutoff, SKIN)


def outdated(moved, nlist, box, offset, strain=0.0, group=None,
             max_checked=lv.MAX_CHECKED_OUTLIERS):
    group = np.empty(0, dtype=np.int64) if group is None else group
    return lv.list_outdated(moved, nlist.reference, strain, nlist.cutoff, nlist.skin, 0.0, box,
                            offset, nlist.cells, nlist.cell_start, nlist.start,
                            nlist.neighbours, group, max_checked)


def test_outliers_checked_pair_by_pair():
    """A particle moved by more than the skin into open space needs no rebuild; moved next to
    a particle it is not listed with, it does; the bound alone asks for both."""
    box = np.array([5.0, 5.0, 5.0])
    positions = np.array([[1.0, 1.0, 1.0], [1.0, 2.6, 1.0], [3.5, 3.5, 3.5], [3.5, 3.5, 1.5]])
    nlist, _ = build(positions.copy(), box, 3, 0.0, skin=SKIN)
    assert nlist.n_pairs == 0
    away = nlist.reference.copy()
    away[0] += (-0.45, -0.45, 0.0)  # 0.64 > skin, away from every other particle
    assert lv.needs_rebuild(away, nlist.reference, 0.0, nlist.cutoff, SKIN)
    assert not missed_pairs(away, box, 0.0, nlist)
    assert not outdated(away, nlist, box, 0.0)
    assert outdated(away, nlist, box, 0.0, max_checked=0)  # too many outliers to check
    towards = nlist.reference.copy()
    towards[0, 1] += 0.65  # 0.95 from particle 1, which it is not listed with
    assert missed_pairs(towards, box, 0.0, nlist)
    assert outdated(towards, nlist, box, 0.0)
    # one group: the pair is never listed and never needed
    assert not outdated(towards, nlist, box, 0.0, group=np.array([0, 0, -1, -1]))
    towards[2, 0] = np.nan
    assert outdated(towards, nlist, box, 0.0)


def wide_scene(rng):
    """A box of 5 × 6 × 5 cells of r_c = 1.3, so outliers are searched in the build's cells."""
    box, positions = scene("random", (7.0, 8.3, 7.5), 3, rng, density=1.5)
    offset = 2.3
    nlist, _ = build(positions, box, 3, offset, skin=SKIN)
    return box, offset, nlist


def displaced(nlist, box, rng, strain, outliers, spread):
    """The reference sheared by ``strain`` about y = 0, jiggled, ``outliers`` moved by
    ``spread``; with the LE offset that strain gives and every |d̃| (module docstring)."""
    moved = nlist.reference.copy()
    moved[:, 0] += strain * nlist.reference[:, 1]
    moved += rng.normal(0.0, 0.02, moved.shape)
    chosen = rng.choice(len(moved), size=outliers, replace=False)
    moved[chosen] += rng.normal(0.0, spread, (outliers, 3))
    d = moved - nlist.reference
    d[:, 0] -= strain * nlist.reference[:, 1]
    return moved, np.sqrt((d ** 2).sum(axis=1))


@pytest.mark.parametrize("strain", [0.0, 0.1, 0.2])
def test_the_cell_search_finds_every_partner_of_a_moved_particle(strain):
    """Partners within h now, searched in the build's cells within (h + |d̃_i| + |d̃|max)/σ_min
    of i's reference position, are those of a search over every particle, for every particle
    (some reaching two cell layers), across the Lees–Edwards faces."""
    rng = np.random.default_rng(3)
    box, offset, nlist = wide_scene(rng)
    moved, d = displaced(nlist, box, rng, strain, outliers=12, spread=0.2)
    new_offset = (offset + strain * box[1]) % box[0]
    sigma = math.sqrt(1.0 + 0.25 * strain ** 2) - 0.5 * strain
    h, group = nlist.cutoff - nlist.skin, np.empty(0, dtype=np.int64)
    near, anywhere = [], []
    reaches = (h + d + d.max()) / sigma + 1e-9 * box[0]
    assert reaches.max() > (box / nlist.cells).min()
    for i, reach in enumerate(reaches):
        near.append(lv._missed_near(i, moved, nlist.reference, reach, box, new_offset, offset,
                                    nlist.cells, nlist.cell_start, h, nlist.start,
                                    nlist.neighbours, group))
        anywhere.append(lv._missed_anywhere(i, moved, box, new_offset, h, nlist.start,
                                            nlist.neighbours, group))
    assert min(near) >= 0
    assert near == anywhere
    assert sum(anywhere) > 0


@pytest.mark.parametrize("wide, strain", [(False, 0.0), (False, 0.05), (True, 0.05)])
def test_list_outdated_never_misses_a_pair(wide, strain):
    """Random moves of a few outliers over a bulk that stays within the bound, under shear
    across the Lees–Edwards faces: the list is kept exactly when brute force finds no pair
    within h missing from it, in trials where the bound alone would rebuild too. In the small
    box (3 cells across) each outlier is compared with every particle, in the wide one only
    with those of the build's cells around it."""
    rng = np.random.default_rng(4 if wide else 12)
    if wide:
        box, offset, nlist = wide_scene(rng)
    else:
        box, _, offset, nlist = moved_scene(rng)
    new_offset = (offset + strain * box[1]) % box[0]
    trials = 12 if wide else 40
    kept_beyond_bound = 0
    for trial in range(trials):
        moved, _ = displaced(nlist, box, rng, strain, outliers=int(rng.integers(1, 5)),
                             spread=0.25)
        keep = not outdated(moved, nlist, box, new_offset, strain)
        assert keep == (not missed_pairs(moved, box, new_offset, nlist))
        if keep:
            kept_beyond_bound += lv.needs_rebuild(moved, nlist.reference, strain,
                                                  nlist.cutoff, SKIN)
    assert trials // 8 <= kept_beyond_bound <= trials - trials // 8
