"""Hierarchies and distance: one pose, (N, 7) batches, refusals, the CLI's answers, brute force,
certified intervals."""

import numpy as np
import pytest

import inscribe
from conftest import mesh_path, run_cli


@pytest.fixture(scope="module")
def eight():
    return inscribe.generate(inscribe.load_mesh(mesh_path("eight.off")), max_spheres=60,
                             evaluate=False)


def random_poses(n, seed=7, spread=2.0):
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    t = rng.uniform(-spread, spread, size=(n, 3))
    return np.ascontiguousarray(np.hstack([q, t]))


def rotate(q, v):
    w, x, y, z = q
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    return v @ r.T


def test_batch_matches_brute_force_over_all_sphere_pairs(eight):
    poses = random_poses(20)
    h = inscribe.Hierarchy(eight, volume="rss")
    batch = inscribe.distance(h, h, poses)
    s = eight.spheres
    for i, pose in enumerate(poses):
        centers_b = rotate(pose[:4], s[:, :3]) + pose[4:]
        gaps = (np.linalg.norm(s[:, None, :3] - centers_b[None, :, :], axis=2)
                - s[:, None, 3] - s[None, :, 3])
        assert batch.distance[i] == pytest.approx(gaps.min(), abs=1e-12)
        assert gaps[batch.sphere_a[i], batch.sphere_b[i]] == pytest.approx(gaps.min(), abs=1e-12)


def test_one_pose_gives_the_batch_answer(eight):
    poses = random_poses(5)
    batch = inscribe.distance(eight, eight, poses)
    for i in range(5):
        one = inscribe.distance(eight, eight, poses[i])
        assert one.distance == batch.distance[i]
        assert np.array_equal(one.point_a, batch.point_a[i])
    assert batch.point_a.shape == (5, 3) and not batch.distance.flags.writeable


def test_batch_is_the_cli_distance_bit_for_bit(tmp_path, eight):
    spheres = tmp_path / "eight.json"
    inscribe.write_spheres(eight, str(spheres))
    poses = random_poses(50)
    pose_file = tmp_path / "poses.txt"
    pose_file.write_text("".join(" ".join(repr(v) for v in row) + "\n" for row in poses))
    out = tmp_path / "d.csv"
    run_cli("distance", spheres, spheres, "--poses", pose_file, "-o", out)
    cli = np.loadtxt(out, delimiter=",", skiprows=1)
    ours = inscribe.distance(eight, eight, poses)
    assert np.array_equal(cli[:, 1], ours.distance)
    assert np.array_equal(cli[:, 2].astype(np.int32), ours.sphere_a)
    assert np.array_equal(cli[:, 3].astype(np.int32), ours.sphere_b)


def test_closer_than_answers_yes_or_no(eight):
    poses = random_poses(30, spread=4.0)
    exact = inscribe.distance(eight, eight, poses)
    asked = inscribe.distance(eight, eight, poses, closer_than=0.5)
    assert np.array_equal(asked.closer, exact.distance < 0.5)


@pytest.mark.parametrize("poses, error, text", [
    (random_poses(3).astype(np.float32), TypeError, "poses must be a float64 array, got a float32"),
    (random_poses(3)[:, :4].copy(), ValueError, "poses must have shape (7,) or (N, 7), got a float64 array of shape (3, 4)"),
    (np.asfortranarray(random_poses(3)), ValueError, "poses must be C-contiguous"),
    (random_poses(6)[::2], ValueError, "poses must be C-contiguous"),
    (np.array([[2.0, 0, 0, 0, 0, 0, 0]]), ValueError, "poses[0]:"),
    (np.array([[1.0, 0, 0, 0, np.nan, 0, 0]]), ValueError, "poses[0]:"),
])
def test_bad_poses_are_refused_clearly(eight, poses, error, text):
    with pytest.raises(error) as raised:
        inscribe.distance(eight, eight, poses)
    assert text in str(raised.value)


def test_hierarchy_serialises_and_refuses_tampering(eight):
    h = inscribe.Hierarchy(eight)
    data = h.serialize()
    back = inscribe.Hierarchy.deserialize(data)
    assert len(back) == len(eight) and back.volume == "sphere"
    with pytest.raises(ValueError):
        inscribe.Hierarchy.deserialize(data[:-3])
    with pytest.raises(ValueError, match="volume must be 'sphere' or 'rss'"):
        inscribe.Hierarchy(eight, volume="box")


def test_certified_interval_holds_the_internal_distance():
    solid = inscribe.prepare(inscribe.load_mesh(mesh_path("eight.off")))
    internal = inscribe.generate(solid, max_spheres=60, evaluate=False)
    cover = inscribe.generate(solid, max_spheres=80, kind="cover", evaluate=False)
    obj = inscribe.CertifiedObject(internal, cover)  # delta and cores from its certificate
    assert len(cover.certificate.protrusions) == len(cover)
    assert cover.certificate.delta == max(0.0, cover.certificate.protrusions.max())
    without_cores = inscribe.CertifiedObject(internal, cover, cover.certificate.delta,
                                             protrusions=[])
    poses = random_poses(20, spread=4.0)
    result = inscribe.certified_distance(obj, obj, poses, closer_than=0.3)
    plain = inscribe.certified_distance(without_cores, without_cores, poses)
    inner = inscribe.distance(internal, internal, poses).distance
    assert np.all(result.lower <= result.upper)
    assert np.all(plain.upper <= np.maximum(inner, 0) + 1e-9)
    assert np.all(result.upper <= result.lower + 2 * cover.certificate.delta + 1e-9)
    assert np.mean(result.upper - result.lower) < np.mean(plain.upper - plain.lower)
    with pytest.raises(ValueError, match="protrusions"):
        inscribe.CertifiedObject(internal, cover, protrusions=[0.1])
    with pytest.raises(ValueError, match="delta"):
        inscribe.CertifiedObject(internal, cover.spheres)
    # The certificate names the spheres and the mesh it proved; a set naming another mesh
    # does not take it.
    assert cover.certificate.mesh_sha256 == cover.mesh_sha256 == solid.sha256
    assert cover.certificate.spheres_sha256.startswith("sha256:")
    cover.mesh_sha256 = "sha256:" + "0" * 64
    with pytest.raises(inscribe.Error, match="proved against mesh") as raised:
        inscribe.CertifiedObject(internal, cover)
    assert raised.value.code == "FAILED_PRECONDITION"
    cover.mesh_sha256 = solid.sha256
    assert set(result.closer) <= {"yes", "no", "undecided"}
    with pytest.raises(ValueError):
        inscribe.CertifiedObject(internal, cover, -1.0)
