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
