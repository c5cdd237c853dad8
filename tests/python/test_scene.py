"""Scenes: close pairs of many posed objects against inscribe.distance on every pair, certified
intervals against certified_distance, groups, masks, ignore lists, refusals."""

import math

import numpy as np
import pytest

import inscribe
from conftest import mesh_path


@pytest.fixture(scope="module")
def shapes():
    out = []
    for name in ("eight.off", "knot1.off"):
        mesh = inscribe.load_mesh(mesh_path(name))
        spheres = inscribe.generate(mesh, max_spheres=60, evaluate=False)
        out.append(inscribe.Hierarchy(spheres))
    return out


def random_poses(rng, n, spread):
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    t = rng.uniform(0.0, spread, size=(n, 3))
    return np.ascontiguousarray(np.hstack([q, t]))


def expected_pairs(hierarchies, poses, threshold, skip=lambda a, b: False):
    out = {}
    for a in range(len(poses)):
        for b in range(a + 1, len(poses)):
            if skip(a, b):
                continue
            r = inscribe.distance(hierarchies[a], hierarchies[b], poses[b], pose_a=poses[a])
            if r.distance < threshold:
                out[(a, b)] = r.distance
    return out


def test_frames_equal_distance_on_every_pair(shapes):
    rng = np.random.default_rng(3)
    n = 24
    objects = [shapes[i % 2] for i in range(n)]
    poses = random_poses(rng, n, 8.0)
    scene = inscribe.Scene()
    for i in range(n):
        scene.add(i, objects[i], poses[i])
    assert len(scene) == n and 5 in scene and 99 not in scene
    for frame in range(6):
        moved = rng.choice(n, size=8, replace=False)
        poses[moved] = random_poses(rng, 8, 8.0)
        scene.set_poses(moved.tolist(), poses[moved])
        threshold = [0.0, 0.5, 2.0][frame % 3]
        got = scene.close_pairs(threshold)
        want = expected_pairs(objects, poses, threshold)
        assert list(zip(got.a.tolist(), got.b.tolist())) == sorted(want)
        np.testing.assert_allclose(got.distance, [want[k] for k in sorted(want)], atol=1e-9)
        assert got.close_pairs == len(want) and not got.truncated
        gaps = np.linalg.norm(got.point_a - got.point_b, axis=1)
        np.testing.assert_allclose(gaps, np.abs(got.distance), atol=1e-9)
        assert got.a.dtype == np.uint64 and got.point_a.shape == (len(got), 3)


def test_groups_masks_and_ignored_pairs(shapes):
    rng = np.random.default_rng(5)
    n = 12
    poses = random_poses(rng, n, 3.0)
    groups = [1 << (i % 3) for i in range(n)]
    masks = [0b011 if i % 4 == 0 else 0xFFFFFFFF for i in range(n)]
    scene = inscribe.Scene()
    for i in range(n):
        scene.add(i, shapes[0], poses[i], group=groups[i], mask=masks[i])
    scene.ignore(0, 1)
    scene.ignore(5, 3)

    def skip(a, b):
        if (a, b) in ((0, 1), (3, 5)):
            return True
        return not (groups[a] & masks[b]) or not (groups[b] & masks[a])

    got = scene.close_pairs(math.inf)
    want = expected_pairs([shapes[0]] * n, poses, math.inf, skip)
    assert list(zip(got.a.tolist(), got.b.tolist())) == sorted(want)
    scene.remove(1)
    assert 1 not in scene
    assert all(1 not in pair for pair in zip(scene.close_pairs(math.inf).a.tolist(),
                                             scene.close_pairs(math.inf).b.tolist()))


def test_certified_pairs_match_certified_distance():
    mesh = inscribe.load_mesh(mesh_path("eight.off"))
    internal = inscribe.generate(mesh, max_spheres=60, evaluate=False)
    cover = inscribe.generate(mesh, kind="cover", max_spheres=60, evaluate=False)
    solid = inscribe.CertifiedObject(internal, cover)
    spheres = inscribe.Hierarchy(internal)
    rng = np.random.default_rng(7)
    n = 10
    poses = random_poses(rng, n, 2.5)
    scene = inscribe.Scene()
    for i in range(n):
        scene.add(i, spheres, poses[i], certified=solid)
    threshold = 0.3
    got = scene.close_pairs(threshold)
    assert len(got) > 0 and got.certified.all()
    for a, b, lower, upper in zip(got.a.tolist(), got.b.tolist(), got.lower, got.upper):
        want = inscribe.certified_distance(solid, solid, poses[b], pose_a=poses[a])
        assert lower == pytest.approx(want.lower[0], abs=1e-12)
        assert upper == pytest.approx(want.upper[0], abs=1e-12)
        assert lower < threshold
    # Every pair left out is certainly no closer than the threshold.
    reported = set(zip(got.a.tolist(), got.b.tolist()))
    for a in range(n):
        for b in range(a + 1, n):
            if (a, b) not in reported:
                want = inscribe.certified_distance(solid, solid, poses[b], pose_a=poses[a])
                assert want.lower[0] >= threshold - 1e-9


def test_refusals(shapes):
    scene = inscribe.Scene()
    scene.add(1, shapes[0])
    with pytest.raises(ValueError, match="already"):
        scene.add(1, shapes[0])
    with pytest.raises(KeyError, match="no object 7"):
        scene.set_poses([7], np.array([[1.0, 0, 0, 0, 0, 0, 0]]))
    with pytest.raises(ValueError, match="poses"):
        scene.set_poses([1], np.array([[float("nan"), 0, 0, 0, 0, 0, 0]]))
    with pytest.raises(ValueError, match="entries"):
        scene.set_poses([1, 1], np.array([[1.0, 0, 0, 0, 0, 0, 0]]))
    with pytest.raises(KeyError):
        scene.remove(2)
    with pytest.raises(ValueError, match="itself"):
        scene.ignore(1, 1)
    with pytest.raises(ValueError, match="threshold"):
        scene.close_pairs(float("nan"))
    with pytest.raises(ValueError, match="max_pairs"):
        scene.close_pairs(1.0, max_pairs=0)
    with pytest.raises(TypeError):
        scene.add(-1, shapes[0])
