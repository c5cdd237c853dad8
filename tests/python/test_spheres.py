"""SphereSet, sphere files in every format, and a cuRobo YAML round trip through PyYAML."""

import numpy as np
import pytest
import yaml

import inscribe
from conftest import mesh_path


@pytest.fixture(scope="module")
def generated():
    return inscribe.generate(inscribe.load_mesh(mesh_path("eight.off")), max_spheres=60)


def test_spheres_is_a_read_only_view_without_copies(generated):
    a, b = generated.spheres, generated.spheres
    assert a.shape == (len(generated), 4) and a.dtype == np.float64
    assert np.shares_memory(a, b) and not a.flags.writeable
    assert np.shares_memory(generated.radii, a) and np.array_equal(generated.radii, a[:, 3])


@pytest.mark.parametrize("extension", ["json", "csv", "sph", "yaml"])
def test_every_readable_format_round_trips_the_spheres_exactly(tmp_path, generated, extension):
    path = str(tmp_path / f"s.{extension}")
    inscribe.write_spheres(generated, path)
    back = inscribe.read_spheres(path)
    assert np.array_equal(back.spheres, generated.spheres)


def test_json_keeps_contacts_hash_params_and_stats(tmp_path, generated):
    path = str(tmp_path / "s.json")
    inscribe.write_spheres(generated, path)
    back = inscribe.read_spheres(path)
    assert back.mesh_sha256 == generated.mesh_sha256
    assert np.array_equal(back.contact_triangles, generated.contact_triangles)
    assert np.array_equal(back.contact_barycentrics, generated.contact_barycentrics)
    assert back.params == generated.params and back.stats == generated.stats


def test_obj_is_written_for_viewers(tmp_path, generated):
    path = tmp_path / "s.obj"
    inscribe.write_spheres(generated, str(path), obj_subdivision=0)
    assert sum(line.startswith("v ") for line in path.read_text().splitlines()) == 12 * len(generated)


def test_curobo_yaml_round_trip_through_pyyaml(tmp_path, generated):
    path = tmp_path / "robot.yml"
    inscribe.write_spheres(generated, str(path), yaml_link_name="gripper")
    document = yaml.safe_load(path.read_text())
    spheres = document["collision_spheres"]["gripper"]
    assert len(spheres) == len(generated)
    for sphere, row in zip(spheres, generated.spheres):
        assert sphere["center"] == list(row[:3]) and sphere["radius"] == row[3]
    # Edited in Python as cuRobo users do: a second link, and a placeholder sphere.
    document["collision_spheres"]["finger"] = [{"center": [0.0, 0.0, 0.1], "radius": 0.02},
                                               {"center": [0.0, 0.0, 0.0], "radius": -10.0}]
    edited = tmp_path / "edited.yml"
    edited.write_text(yaml.safe_dump(document, sort_keys=False))
    links = inscribe.parse_curobo_yaml(edited.read_text())
    assert list(links) == ["gripper", "finger"]
    assert np.array_equal(links["gripper"].spheres, generated.spheres)
    assert links["finger"].spheres.tolist() == [[0.0, 0.0, 0.1, 0.02]]
    finger = inscribe.read_spheres(str(edited), yaml_link="finger")
    assert finger.spheres.tolist() == [[0.0, 0.0, 0.1, 0.02]]
    with pytest.raises(ValueError, match="gripper"):
        inscribe.read_spheres(str(edited))  # two links: which one?
    text = inscribe.format_curobo_yaml([("gripper", generated), ("finger", links["finger"])])
    assert yaml.safe_load(text)["collision_spheres"] == {
        "gripper": spheres, "finger": document["collision_spheres"]["finger"][:1]}


def test_sphere_set_from_numpy_checks_every_sphere():
    ok = inscribe.SphereSet(np.array([[0.0, 0.0, 0.0, 1.0]]))
    assert len(ok) == 1 and ok.contact_triangles is None
    with pytest.raises(ValueError, match="sphere 1: radius -1 is not positive"):
        inscribe.SphereSet(np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, -1.0]]))
    with pytest.raises(TypeError, match="float32"):
        inscribe.SphereSet(np.zeros((2, 4), dtype=np.float32))
    with pytest.raises(ValueError, match=r"\(N, 4\)"):
        inscribe.SphereSet(np.ones((2, 3)))


def test_malformed_files_name_the_line(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("x,y,z,r\n1,2,3,0.5\n1,2,3\n")
    with pytest.raises(ValueError, match="line 3"):
        inscribe.read_spheres(str(path))
    with pytest.raises(FileNotFoundError):
        inscribe.read_spheres(str(tmp_path / "missing.json"))
    with pytest.raises(ValueError, match="format"):
        inscribe.read_spheres(str(path), format="stl")
