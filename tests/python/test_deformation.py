"""inscribe.Deformer against `inscribe deform` on the same frames, and its refusals."""

import json

import numpy as np
import pytest

import inscribe
from conftest import mesh_path, run_cli


def bend(vertices, amount):
    out = vertices * np.array([1.0 + amount, 1.0, 1.0 - amount / 2])
    out[:, 1] += amount * np.sin(vertices[:, 0] * 3.0)
    return np.ascontiguousarray(out)


@pytest.fixture(scope="module")
def reference():
    solid = inscribe.prepare(inscribe.load_mesh(mesh_path("eight.off")))
    return solid, inscribe.generate(solid, max_spheres=60, evaluate=False)


def test_update_is_the_cli_deform_bit_for_bit(tmp_path, reference):
    solid, spheres = reference
    mesh = solid.mesh
    reference_file, spheres_file = tmp_path / "ref.off", tmp_path / "s.json"
    inscribe.write_mesh(mesh, str(reference_file))
    inscribe.write_spheres(spheres, str(spheres_file))
    deformer = inscribe.Deformer(solid, spheres)
    for frame, amount in enumerate([0.02, 0.05]):
        deformed = bend(mesh.vertices, amount)
        deformed_file, out = tmp_path / f"d{frame}.off", tmp_path / f"o{frame}.json"
        inscribe.write_mesh(inscribe.Mesh(deformed, mesh.triangles), str(deformed_file))
        run_cli("deform", reference_file, spheres_file, deformed_file, "-o", out)
        cli = inscribe.read_spheres(str(out))
        moved = deformer.update(deformed)
        assert np.array_equal(moved.spheres, cli.spheres)
        assert moved.stats["max_protrusion"] < deformer.xi
        bounds = deformer.bounds(moved)
        assert 0 <= bounds.nerr_lower <= bounds.nerr_upper
        assert bounds.nerr_lower == pytest.approx(cli.stats["nerr_lower"], rel=1e-12)


def test_a_rigid_motion_moves_every_sphere_with_it(reference):
    solid, spheres = reference
    moved = inscribe.Deformer(solid, spheres).update(solid.mesh.vertices + np.array([1.0, 2.0, 3.0]))
    assert np.allclose(moved.spheres[:, :3], spheres.spheres[:, :3] + [1.0, 2.0, 3.0], atol=1e-9)
    assert np.allclose(moved.radii, spheres.radii, rtol=1e-9)


def test_bad_frames_are_refused_and_leave_the_deformer_usable(reference):
    solid, spheres = reference
    deformer = inscribe.Deformer(solid, spheres)
    with pytest.raises(ValueError, match="vertices"):
        deformer.update(solid.mesh.vertices[:-1].copy())
    with pytest.raises(TypeError, match="float32"):
        deformer.update(solid.mesh.vertices.astype(np.float32))
    with pytest.raises(ValueError):
        deformer.update(solid.mesh.vertices * np.array([1.0, 1.0, -1.0]))  # inside out
    assert len(deformer.update(np.array(solid.mesh.vertices))) == len(spheres)


def test_threads_sharing_a_deformer_take_turns(reference):
    import concurrent.futures

    solid, spheres = reference
    deformer = inscribe.Deformer(solid, spheres)
    frames = [bend(solid.mesh.vertices, 0.01 * k) for k in range(8)]
    alone = [deformer.update(f).spheres.copy() for f in frames]
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        together = list(pool.map(lambda f: deformer.update(f).spheres.copy(), frames))
    assert all(np.array_equal(a, b) for a, b in zip(alone, together))


def test_a_set_without_contacts_cannot_deform(reference):
    solid, _ = reference
    with pytest.raises(ValueError):
        inscribe.Deformer(solid, inscribe.SphereSet(np.array([[0.0, 0.0, 0.0, 0.1]])))


def coiled_bar(segments=48, turns=1.15, radius=1.0, half=0.18):
    # A square bar along x, of `segments` slices, and the same bar wound around the z axis
    # through `turns` turns: its two ends pass through each other, so the wound frame
    # intersects itself while the straight reference does not.
    length = 2 * np.pi * radius * turns
    xs = np.linspace(0.0, length, segments + 1)
    ring = np.array([[-half, -half], [half, -half], [half, half], [-half, half]])
    vertices = np.array([[x, y, z] for x in xs for (y, z) in ring])
    triangles = []
    for i in range(segments):
        a, b = 4 * i, 4 * (i + 1)
        for k in range(4):
            k1 = (k + 1) % 4
            triangles += [[a + k, b + k, b + k1], [a + k, b + k1, a + k1]]
    triangles += [[0, 2, 1], [0, 3, 2]]
    e = 4 * segments
    triangles += [[e, e + 1, e + 2], [e, e + 2, e + 3]]
    triangles = np.array(triangles, dtype=np.int32)
    straight = inscribe.Mesh(vertices, triangles)
    if inscribe.prepare(straight).mesh.vertices.shape != vertices.shape:
        raise AssertionError("the bar should need no welding")
    theta = vertices[:, 0] / radius
    wound = np.stack([(radius - vertices[:, 1]) * np.cos(theta),
                      (radius - vertices[:, 1]) * np.sin(theta),
                      vertices[:, 2] + 0.05 * theta], axis=1)
    return straight, np.ascontiguousarray(wound)


def test_a_self_intersecting_frame_moves_the_same_from_the_cli_the_service_and_python(tmp_path):
    # The inside-test rule of a deforming boundary is core's alone: the CLI, the service (for
    # a client that asks nothing of it) and Python give one answer bit for bit, also on a frame
    # whose ends pass through each other, where the pseudonormal sign and the winding number
    # disagree near the buried faces.
    from conftest import Server

    straight, wound = coiled_bar()
    solid = inscribe.prepare(straight)
    # The reference (validated as is) needs no exact test; the frame intersects itself.
    assert solid.report.self_intersecting_pairs == 0
    frame = inscribe.prepare(inscribe.Mesh(wound, solid.mesh.triangles))
    assert frame.report.self_intersecting_pairs > 0
    spheres = inscribe.generate(solid, max_spheres=120, evaluate=False)

    ours = inscribe.Deformer(solid, spheres).update(wound)

    reference_file, spheres_file = tmp_path / "bar.off", tmp_path / "bar.json"
    deformed_file, out = tmp_path / "wound.off", tmp_path / "moved.json"
    inscribe.write_mesh(solid.mesh, str(reference_file))
    inscribe.write_spheres(spheres, str(spheres_file))
    inscribe.write_mesh(inscribe.Mesh(wound, solid.mesh.triangles), str(deformed_file))
    run_cli("deform", reference_file, spheres_file, deformed_file, "-o", out)
    cli = inscribe.read_spheres(str(out))

    server = Server("--jobs", "1")
    try:
        with inscribe.Client(server.address) as client:
            mesh_key = client.put_mesh(solid.mesh)
            set_key = client.put_sphere_set(spheres, mesh_sha256=mesh_key)
            served = client.update_deformation(set_key, wound, mesh_sha256=mesh_key).spheres
    finally:
        server.stop()

    assert np.array_equal(ours.spheres, cli.spheres)
    assert np.array_equal(served.spheres, cli.spheres)
    # The frame's buried ends matter: some spheres were shrunk there.
    assert ours.stats["shrunk"] > 0
