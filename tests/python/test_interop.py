"""numpy-first interop: meshes from any float/integer dtype, (V, F) pairs, trimesh-like objects
and paths wherever a mesh is taken; SphereSet as an array; spheres as a mesh for viewing;
mistyped keywords named; progress bars; __version__."""

import pathlib
import re

import numpy as np
import pytest

import inscribe
from conftest import SOURCE_DIR, mesh_path


class TrimeshLike:
    """What inscribe reads of a trimesh.Trimesh: .vertices (float64) and .faces (int64)."""

    def __init__(self, vertices, faces):
        self.vertices = np.array(vertices, dtype=np.float64)
        self.faces = np.array(faces, dtype=np.int64)


@pytest.fixture(scope="module")
def eight():
    return inscribe.load_mesh(mesh_path("eight.off"))


def int32_rows(triangles):
    """The triangles as int32 through Python ints: no numpy cast involved."""
    return np.array([[int(i) for i in row] for row in triangles.tolist()], dtype=np.int32)


@pytest.mark.parametrize("dtype", [np.int8, np.int16, np.int32, np.int64, np.uint8, np.uint16,
                                   np.uint32, np.uint64, np.intp])
def test_any_integer_dtype_of_faces_gives_the_same_mesh(dtype):
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    t = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    mesh = inscribe.Mesh(v, t.astype(dtype))
    assert mesh.triangles.dtype == np.int32
    assert np.array_equal(mesh.triangles, int32_rows(t))
    assert mesh.sha256 == inscribe.Mesh(v, int32_rows(t)).sha256


@pytest.mark.parametrize("layout", ["float32", "float16", "fortran", "strided", "float32-fortran"])
def test_float_vertices_of_any_width_and_layout_are_converted_once(eight, layout):
    v, t = np.array(eight.vertices), np.array(eight.triangles)
    given = {"float32": v.astype(np.float32), "float16": v.astype(np.float16),
             "fortran": np.asfortranarray(v), "strided": np.hstack([v, v])[:, :3],
             "float32-fortran": np.asfortranarray(v.astype(np.float32))}[layout]
    assert given.flags.c_contiguous == (layout in ("float32", "float16"))
    mesh = inscribe.Mesh(given, t)
    # Widening a float is exact: each vertex is the given one, as Python's float() reads it.
    expected = [[float(x) for x in row] for row in given.tolist()]
    assert mesh.vertices.tolist() == expected


def test_float_faces_and_integer_vertices_are_refused_naming_the_argument():
    with pytest.raises(TypeError, match=r"vertices must be a float array .* got a int64"):
        inscribe.Mesh(np.zeros((3, 3), dtype=np.int64), np.zeros((1, 3), dtype=np.int32))
    with pytest.raises(TypeError, match=r"triangles must be an integer array .* got a float32"):
        inscribe.Mesh(np.zeros((3, 3)), np.zeros((1, 3), dtype=np.float32))
    with pytest.raises(ValueError, match=r"triangles must have shape \(N, 3\), got a int64 array "
                                         r"of shape \(4,\)"):
        inscribe.prepare((np.zeros((3, 3)), np.zeros(4, dtype=np.int64)))


def test_every_mesh_form_gives_the_same_spheres(eight, tmp_path):
    expected = inscribe.generate(eight, max_spheres=40, evaluate=False)
    v, t = np.array(eight.vertices), np.array(eight.triangles)
    path = tmp_path / "eight.off"
    inscribe.write_mesh((v, t.astype(np.int64)), path)  # a pair in, a pathlib.Path out
    forms = {"tuple": (v, t.astype(np.int64)), "list": [v, t.astype(np.uint32)],
             "trimesh": TrimeshLike(v, t), "pathlib": path, "str": str(path),
             "inscribe.Mesh.faces": TrimeshLike(eight.vertices, eight.faces)}
    for name, mesh in forms.items():
        got = inscribe.generate(mesh, max_spheres=40, evaluate=False)
        assert np.array_equal(got.spheres, expected.spheres), name
    assert inscribe.prepare(TrimeshLike(v, t)).sha256 == inscribe.prepare(eight).sha256
    assert inscribe.load_mesh(path).sha256 == eight.sha256


def test_what_is_not_a_mesh_is_refused_naming_the_forms():
    with pytest.raises(TypeError, match=r"a mesh must be an inscribe.Mesh, a path, a \(vertices, "
                                        r"faces\) pair or an object with .vertices and .faces "
                                        r"\(trimesh\), got int"):
        inscribe.generate(42)
    with pytest.raises(TypeError, match="path must be a str or os.PathLike, got int"):
        inscribe.load_mesh(3)


def test_a_sphere_set_is_its_n_by_4_array(eight):
    s = inscribe.generate(eight, max_spheres=40, evaluate=False)
    array = np.asarray(s)
    assert array.shape == (len(s), 4) == s.shape and array.dtype == np.float64
    assert np.shares_memory(array, s.spheres) and not array.flags.writeable
    assert np.array_equal(array[:, :3], s.centers) and np.array_equal(array[:, 3], s.radii)
    assert np.array_equal(s[:, 3], s.radii) and np.array_equal(s[2], s.spheres[2])
    assert [row.tolist() for row in s] == s.spheres.tolist()
    assert np.asarray(s, dtype=np.float32).dtype == np.float32
    copied = np.array(s, copy=True)
    assert not np.shares_memory(copied, s.spheres) and np.array_equal(copied, s.spheres)


@pytest.mark.parametrize("subdivision", [0, 1, 2])
def test_to_mesh_puts_every_vertex_on_its_sphere(eight, subdivision):
    s = inscribe.generate(eight, max_spheres=20, evaluate=False)
    mesh = s.to_mesh(subdivision)
    per_sphere = 10 * 4 ** subdivision + 2
    assert mesh.num_vertices == len(s) * per_sphere
    assert mesh.num_triangles == len(s) * 20 * 4 ** subdivision
    # Each sphere's block of vertices, measured from its centre by plain Python arithmetic.
    vertices = mesh.vertices.tolist()
    for i, (x, y, z, r) in enumerate(s.spheres.tolist()):
        for vx, vy, vz in vertices[i * per_sphere:(i + 1) * per_sphere]:
            d = ((vx - x) ** 2 + (vy - y) ** 2 + (vz - z) ** 2) ** 0.5
            assert abs(d - r) <= 1e-12 * max(1.0, r) + 1e-15
    faces = np.asarray(mesh.faces)
    assert faces.min() == 0 and faces.max() == mesh.num_vertices - 1
    assert (faces // per_sphere == faces[:, :1] // per_sphere).all()  # no face spans spheres


@pytest.mark.parametrize("call, text", [
    (lambda m: inscribe.generate(m, max_sphere=10),
     "generate() got an unexpected keyword argument 'max_sphere'; did you mean 'max_spheres'?"),
    (lambda m: m.validate(repiar="fill"),
     "Mesh.validate() got an unexpected keyword argument 'repiar'; did you mean 'repair'?"),
    (lambda m: inscribe.Mesh(m.vertices, trianglez=m.triangles),
     "Mesh() got an unexpected keyword argument 'trianglez'; did you mean 'triangles'?"),
    (lambda m: inscribe.prepare(m, colour="red"),
     "prepare() got an unexpected keyword argument 'colour' (it takes "),
])
def test_a_mistyped_keyword_is_named(eight, call, text):
    with pytest.raises(TypeError) as raised:
        call(eight)
    assert text in str(raised.value)
    assert "incompatible function arguments" not in str(raised.value)


def test_a_wrong_type_still_gets_pybinds_signature(eight):
    with pytest.raises(TypeError, match="incompatible function arguments"):
        inscribe.generate(eight, max_spheres="many")


class Bar:
    """What inscribe uses of a tqdm.tqdm bar."""

    def __init__(self, total=None):
        self.total, self.n, self.updates = total, 0.0, []

    def update(self, n):
        self.updates.append(n)
        self.n += n


@pytest.mark.parametrize("total", [100, None])
def test_a_progress_bar_is_driven_to_its_total(eight, total):
    bar = Bar(total)
    inscribe.generate(eight, max_spheres=60, evaluate=False, progress=bar)
    assert bar.updates and all(n > 0 for n in bar.updates)
    assert bar.n == pytest.approx(total or 1.0)


def test_progress_that_is_neither_callable_nor_a_bar_is_refused(eight):
    with pytest.raises(TypeError, match=r"progress must be None, a callable\(fraction\) or a "
                                        r"progress bar .* got int"):
        inscribe.generate(eight, max_spheres=10, evaluate=False, progress=3)


def test_version_is_the_projects():
    version = re.search(r"project\(inscribe VERSION ([0-9.]+)",
                        pathlib.Path(SOURCE_DIR / "CMakeLists.txt").read_text()).group(1)
    assert inscribe.__version__ == version


def test_every_path_argument_takes_a_pathlib_path(eight, tmp_path):
    s = inscribe.generate(eight, max_spheres=20, evaluate=False)
    inscribe.write_spheres(s, tmp_path / "eight.json")
    assert np.array_equal(inscribe.read_spheres(tmp_path / "eight.json").spheres, s.spheres)
    urdf = tmp_path / "box.urdf"
    urdf.write_text('<robot name="r"><link name="base"><collision><geometry>'
                    '<box size="0.3 0.2 0.1"/></geometry></collision></link></robot>')
    robot = inscribe.spherize_robot(urdf, max_spheres_per_link=8)
    robot.write(tmp_path / "box.yml")
    back = inscribe.read_robot_spheres(tmp_path / "box.yml")
    assert np.array_equal(back["base"], robot.spheres["base"])
    assert inscribe.read_robot_sphere_file(tmp_path / "box.yml")["format"] == "curobo"
    inscribe.write_robot_spheres(tmp_path / "again.yml", back)
    assert np.array_equal(inscribe.read_robot_spheres(str(tmp_path / "again.yml"))["base"],
                          back["base"])
    with pytest.raises(TypeError, match="path must be a str or os.PathLike, got float"):
        inscribe.read_spheres(1.5)
