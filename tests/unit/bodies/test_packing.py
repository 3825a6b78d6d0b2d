"""Packings: exact φ, no overlaps (brute force, independent of the packer's own check),
reproducibility, structure, speed, errors.

The polydisperse sand packing is ``slow``; ``SUSPSIM_REDUCED=1`` runs it smaller.
"""
import itertools
import math
import os

import numpy as np
import pytest

from suspsim.bodies import packing as packing_module
from suspsim.bodies import harmonics as sh
from suspsim.bodies import shapes
from suspsim.bodies.overlap import fibonacci_directions
from suspsim.bodies.packing import PackingError, pack, pack_sand, pack_spheres
from suspsim.bodies.rotations import rotation_matrices
from suspsim.errors import InputError

REDUCED = os.environ.get("SUSPSIM_REDUCED") == "1"
IMAGES = np.array(list(itertools.product((-1, 0, 1), repeat=3)), dtype=float)


def sphere_gaps_brute_force(centres, radii, box):
    """(N, N) surface gaps over all 27 images (no minimum-image assumption), +inf diagonal."""
    d = centres[:, None, :] - centres[None, :, :]
    distance = np.full(d.shape[:2], np.inf)
    for image in IMAGES * box:
        distance = np.minimum(distance, np.sqrt(((d + image) ** 2).sum(-1)))
    gaps = distance - radii[:, None] - radii[None, :]
    np.fill_diagonal(gaps, np.inf)
    return gaps


def assert_grains_do_not_overlap(result, points=3000):
    """Dense exact surface points of every grain are outside every other grain + min_gap."""
    rotations = rotation_matrices(result.orientations)
    directions = fibonacci_directions(points)
    surfaces = [shapes.surface_points(a, directions) @ r.T
                for a, r in zip(result.coefficients, rotations)]
    smallest = np.inf
    for i, j in itertools.permutations(range(result.count), 2):
        for image in IMAGES * result.box:
            offset = result.centres[i] - result.centres[j] + image
            if np.linalg.norm(offset) > result.support_radii[i] + result.support_radii[j]:
                continue
            p = (surfaces[i] + offset) @ rotations[j]  # in j's body frame
            near = np.linalg.norm(p, axis=1) < result.support_radii[j] + result.min_gap
            if near.any():
                u = p[near] / np.linalg.norm(p[near], axis=1)[:, None]
                radial = np.linalg.norm(p[near], axis=1) - sh.evaluate(result.coefficients[j], u)
                smallest = min(smallest, radial.min())
                assert not shapes.contains(result.coefficients[j], p[near],
                                           margin=result.min_gap).any(), (i, j)
    return smallest


@pytest.fixture(scope="session", autouse=True)
def compiled():
    """Compile (or load from cache) the kernels before anything is timed."""
    pack_spheres([10, 10, 10], 0.2, 1.0, seed=0)


def test_monodisperse_spheres_at_055_fast_exact_no_overlap():
    result = pack_spheres([20, 20, 20], 0.55, 1.9, seed=1)
    assert 100 <= result.count <= 200
    assert result.details["wall_time_s"] < 5.0
    assert result.volume_fraction == pytest.approx(0.55, rel=1e-12)
    assert np.all(result.radii == result.radii[0])
    gaps = sphere_gaps_brute_force(result.centres, result.radii, result.box)
    assert gaps.min() >= result.min_gap == pytest.approx(1.9e-3)
    assert gaps.min() == pytest.approx(result.details["smallest_gap"], rel=1e-9)
    assert np.all((result.centres >= 0) & (result.centres < result.box))
    np.testing.assert_allclose(np.linalg.norm(result.orientations, axis=1), 1.0, rtol=1e-14)


def test_polydisperse_spheres():
    result = pack_spheres([24, 20, 28], 0.55, 1.5, polydispersity=0.3, size_ratio=4.0, seed=2)
    assert result.volume_fraction == pytest.approx(0.55, rel=1e-12)
    assert result.radii.max() / result.radii.min() <= 4.0
    assert result.radii.std() / result.radii.mean() == pytest.approx(0.3, abs=0.06)
    assert sphere_gaps_brute_force(result.centres, result.radii, result.box).min() >= \
        result.min_gap


def test_sphere_structure_is_amorphous():
    result = pack_spheres([20, 20, 20], 0.55, 1.9, seed=3)
    a = result.radii[0]
    gaps = sphere_gaps_brute_force(result.centres, result.radii, result.box)
    contacts = (gaps < 0.1 * a).sum(1).mean()
    assert 3.0 < contacts < 9.0  # measured 6.1; a jammed packing has 6, a crystal 12
    # Global bond-orientational order Q6 (Steinhardt et al. 1983): 0.575 for fcc, ~0 random.
    d = result.centres[:, None] - result.centres[None]
    d -= result.box * np.rint(d / result.box)
    i, j = np.nonzero(np.triu(gaps < 0.4 * a, 1))
    bonds = d[i, j] / np.linalg.norm(d[i, j], axis=1)[:, None]
    y6 = np.stack([sh.evaluate(np.eye(sh.coefficient_count(6))[k], bonds)
                   for k in range(36, 49)])
    q6 = math.sqrt(4 * math.pi / 13 * (y6.mean(1) ** 2).sum())
    assert q6 < 0.2


def test_reproducible_from_seed():
    first = pack_spheres([12, 12, 12], 0.45, 1.2, polydispersity=0.2, seed=7)
    again = pack_spheres([12, 12, 12], 0.45, 1.2, polydispersity=0.2, seed=7)
    other = pack_spheres([12, 12, 12], 0.45, 1.2, polydispersity=0.2, seed=8)
    for name in ("centres", "orientations", "radii", "volumes"):
        assert np.array_equal(getattr(first, name), getattr(again, name))
    assert not np.array_equal(first.centres, other.centres)
    sand = [pack_sand([7, 7, 7], 0.3, 1.0, seed=4, degree=8) for _ in range(2)]
    assert np.array_equal(sand[0].coefficients, sand[1].coefficients)
    assert np.array_equal(sand[0].centres, sand[1].centres)


def test_sand_at_050():
    result = pack("sand", [7, 7, 7], 0.50, 1.0, seed=1)
    assert result.count == 41
    assert result.volume_fraction == pytest.approx(0.50, rel=1e-12)
    volumes = np.array([shapes.volume(a) for a in result.coefficients])
    np.testing.assert_allclose(result.volumes, volumes, rtol=1e-14)
    smallest = assert_grains_do_not_overlap(result)
    assert smallest >= result.min_gap
    assert result.details["smallest_gap"] <= smallest + 1e-3
    # Grains are in their principal frame with the centroid at the origin.
    props = shapes.mass_properties(result.coefficients[0])
    np.testing.assert_allclose(props.centroid, 0.0, atol=1e-12)


@pytest.mark.slow
def test_polydisperse_sand_at_050():
    side, ratio = (11.0, 3.0) if REDUCED else (14.0, 5.0)
    result = pack_sand([side] * 3, 0.50, 1.0, polydispersity=0.3, size_ratio=ratio, seed=5)
    assert result.volume_fraction == pytest.approx(0.50, rel=1e-12)
    assert result.radii.max() / result.radii.min() <= ratio
    assert assert_grains_do_not_overlap(result, points=2000) >= result.min_gap


def test_unreachable_volume_fraction_raises_with_advice():
    with pytest.raises(PackingError, match="lower the volume fraction") as info:
        pack_spheres([12, 12, 12], 0.63, 1.0, seed=1, max_steps=50)
    assert "50 relaxation steps" in str(info.value)


@pytest.mark.parametrize("kwargs, source", [
    (dict(volume_fraction=0.7), "volume_fraction"),
    (dict(volume_fraction=0.0), "volume_fraction"),
    (dict(radius=-1.0), "radius"),
    (dict(box=[10, 10]), "box"),
    (dict(radius=3.0), "box"),
    (dict(size_ratio=6.0), "size_ratio"),
    (dict(polydispersity=-0.1), "polydispersity"),
    (dict(seed=-3), "seed"),
])
def test_bad_arguments(kwargs, source):
    arguments = dict(box=[10, 10, 10], volume_fraction=0.3, radius=1.0) | kwargs
    box, phi, radius = arguments.pop("box"), arguments.pop("volume_fraction"), \
        arguments.pop("radius")
    with pytest.raises(InputError) as info:
        pack_spheres(box, phi, radius, **arguments)
    assert info.value.source == source


def test_bad_sand_arguments():
    with pytest.raises(InputError, match="roughness"):
        pack_sand([10, 10, 10], 0.3, 1.0, roughness=0.5)
    with pytest.raises(InputError, match="unknown shape"):
        pack("cube", [10, 10, 10], 0.3, 1.0)
    assert packing_module.MAX_VOLUME_FRACTION == 0.64
