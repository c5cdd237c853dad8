"""inscribe.Mesh, load_mesh, validation and prepare: arrays in and out, refusals, errors."""

import numpy as np
import pytest

import inscribe
from conftest import mesh_path, run_cli


def cube():
    v = np.array([[x, y, z] for x in (0.0, 1.0) for y in (0.0, 1.0) for z in (0.0, 1.0)])
    t = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
                  [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]],
                 dtype=np.int32)
    return v, t


def test_mesh_from_arrays_round_trips_without_changing_a_bit():
    v, t = cube()
    mesh = inscribe.Mesh(v, t)
    assert mesh.num_vertices == 8 and mesh.num_triangles == 12
    assert np.array_equal(mesh.vertices, v) and np.array_equal(mesh.triangles, t)
    assert mesh.vertices.dtype == np.float64 and mesh.triangles.dtype == np.int32
    assert not mesh.vertices.flags.writeable


def test_views_share_the_mesh_memory():
    mesh = inscribe.load_mesh(mesh_path("eight.off"))
    first = mesh.vertices
    assert first.base is not None
    assert np.shares_memory(first, mesh.vertices)


@pytest.mark.parametrize("vertices, error, text", [
    (lambda v: v.astype(np.int64), TypeError,
     "vertices must be a float array (float64, float32, ...), got a int64 array of shape (8, 3)"),
    (lambda v: v[:, :2].copy(), ValueError, "vertices must have shape (N, 3), got a float64 array of shape (8, 2)"),
    (lambda v: v.ravel(), ValueError, "vertices must have shape (N, 3)"),
    (lambda v: v.astype(np.float32)[:, :2], ValueError, "vertices must have shape (N, 3), got a float32"),
])
def test_wrong_vertex_arrays_are_refused_by_name(vertices, error, text):
    v, t = cube()
    with pytest.raises(error) as raised:
        inscribe.Mesh(vertices(v), t)
    assert text in str(raised.value)


@pytest.mark.parametrize("triangles, error, text", [
    (lambda t: t.astype(np.float64), TypeError,
     "triangles must be an integer array (int32, int64, ...), got a float64 array of shape (12, 3)"),
    (lambda t: t[:, :2].astype(np.int64), ValueError,
     "triangles must have shape (N, 3), got a int64 array of shape (12, 2)"),
    (lambda t: np.where(t == 7, 2**31, t).astype(np.int64), ValueError,
     "triangles holds 2147483648, which int32 cannot hold"),
    (lambda t: np.where(t == 7, -2**40, t).astype(np.int64), ValueError,
     "triangles holds -1099511627776, which int32 cannot hold"),
])
def test_wrong_triangle_arrays_are_refused_by_name(triangles, error, text):
    v, t = cube()
    with pytest.raises(error) as raised:
        inscribe.Mesh(v, triangles(t))
    assert text in str(raised.value)


def test_load_mesh_missing_file_is_file_not_found():
    with pytest.raises(FileNotFoundError, match="nope.off"):
        inscribe.load_mesh("/nonexistent/nope.off")


def test_load_mesh_unknown_extension_is_value_error(tmp_path):
    path = tmp_path / "mesh.xyz"
    path.write_text("1 2 3\n")
    with pytest.raises(ValueError, match="mesh.xyz"):
        inscribe.load_mesh(str(path))


def test_validate_reports_an_open_mesh_and_prepare_refuses_it_with_the_cli_message():
    mesh = inscribe.load_mesh(mesh_path("ChineseDragon-10kv.off"))
    report = mesh.validate()
    assert not report.usable and not report.closed and report.border_edges > 0
    assert any(issue.code == "not_closed" for issue in report.issues)
    with pytest.raises(inscribe.Error) as raised:
        inscribe.prepare(mesh)
    assert raised.value.code == "FAILED_PRECONDITION"
    assert str(raised.value) == report.first_error
    cli = run_cli("info", mesh_path("ChineseDragon-10kv.off"), check=False)
    assert report.first_error.split(":")[0] in cli.stdout + cli.stderr


def test_validate_welds_vertices_repeated_per_face_and_within_a_tolerance():
    v, t = cube()
    per_face = np.ascontiguousarray(v[t.ravel()])  # each triangle with its own 3 vertices
    faces = np.arange(len(per_face), dtype=np.int32).reshape(-1, 3)
    report = inscribe.Mesh(per_face, faces).validate()
    assert report.usable and report.welded_vertices == 36 - 8
    assert report.weld_collapsed_triangles == 0
    assert any(i.code == "welded_vertices" and i.severity == inscribe.Severity.FIXED
               for i in report.issues)
    apart = per_face + 1e-9 * np.arange(len(per_face))[:, None]
    assert not inscribe.Mesh(apart, faces).validate(repair="none").usable
    cracks = inscribe.Mesh(apart, faces).validate()  # the default repair welds them as cracks
    assert cracks.usable and cracks.crack_vertices_welded == 36 - 8
    welded = inscribe.Mesh(apart, faces).validate(weld_tolerance=1e-6)
    assert welded.usable and welded.welded_vertices == 36 - 8


def test_sha256_of_the_solid_is_the_cli_mesh_hash():
    import json
    solid = inscribe.prepare(inscribe.load_mesh(mesh_path("eight.off")))
    info = json.loads(run_cli("info", mesh_path("eight.off"), "--json").stdout)
    assert solid.sha256 == info["mesh_sha256"]
    assert solid.report.usable and solid.report.volume > 0


@pytest.mark.parametrize("extension", ["off", "obj", "ply", "stl"])
def test_write_mesh_round_trips_the_doubles(tmp_path, extension):
    mesh = inscribe.load_mesh(mesh_path("eight.off"))
    path = str(tmp_path / f"eight.{extension}")
    inscribe.write_mesh(mesh, path)
    back = inscribe.load_mesh(path)
    if extension != "stl":  # STL repeats vertices per triangle
        assert np.array_equal(back.vertices, mesh.vertices)
        assert np.array_equal(back.triangles, mesh.triangles)
    assert back.num_triangles == mesh.num_triangles
    with pytest.raises(ValueError):
        inscribe.write_mesh(mesh, str(tmp_path / "eight.xyz"))
