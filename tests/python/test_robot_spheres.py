"""inscribe.read_robot_spheres / write_robot_spheres / SpherizedRobot.write: a robot's spheres in
every planner format, the same as `inscribe urdf --spheres` and `inscribe convert` write."""

import numpy as np
import pytest
import yaml

import inscribe
from conftest import run_cli

ROBOT = """<robot name="two_link">
  <link name="base"><collision><geometry><box size="0.3 0.2 0.1"/></geometry></collision></link>
  <link name="arm"><collision><origin xyz="0 0 0.2" rpy="0.1 0 0"/><geometry><cylinder radius="0.04" length="0.4"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><limit lower="-1" upper="1"/></joint>
</robot>
"""

FORMATS = [("spheres.yml", "curobo"), ("spheres.xrdf", "xrdf"), ("spheres.srdf", "srdf"),
           ("vamp.urdf", "urdf"), ("morphit.urdf", "morphit")]


@pytest.fixture
def robot(tmp_path):
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(ROBOT)
    return urdf, inscribe.spherize_robot(str(urdf), max_spheres_per_link=12)


def test_every_format_reads_back_the_spheres_bit_for_bit(robot, tmp_path):
    urdf, spherized = robot
    matrix = spherized.self_collision(samples=200)
    for name, fmt in FORMATS:
        path = tmp_path / name
        spherized.write(str(path), format=fmt, self_collision=matrix)
        read = inscribe.read_robot_spheres(str(path))
        assert list(read) == ["base", "arm"], fmt
        for link, spheres in spherized.spheres.items():
            assert read[link].shape == spheres.shape and np.array_equal(read[link], spheres), fmt
        info = inscribe.read_robot_sphere_file(str(path))
        assert info["format"] == fmt
        if fmt in ("curobo", "xrdf", "srdf"):
            assert info["self_collision_ignore"][0][:2] == ("arm", "base")
        assert info["self_collision_ignore"] == [] or fmt not in ("urdf", "morphit")
    # The SRDF names the pair's class; cuRobo's YAML holds its pair without one.
    assert inscribe.read_robot_sphere_file(str(tmp_path / "spheres.srdf"))[
        "self_collision_ignore"] == [("arm", "base", "Adjacent")]
    assert yaml.safe_load((tmp_path / "spheres.yml").read_text())["self_collision_ignore"] == {
        "arm": ["base"]}


def test_the_cli_writes_the_same_files(robot, tmp_path):
    urdf, spherized = robot
    run_cli("urdf", urdf, "-o", tmp_path / "out.urdf", "--max-spheres-per-link", "12",
            "--spheres", tmp_path / "cli.xrdf", "--spheres", "morphit:" + str(tmp_path / "cli.urdf"))
    spherized.write(str(tmp_path / "py.xrdf"), self_collision=spherized.self_collision())
    spherized.write(str(tmp_path / "py.urdf"), format="morphit")
    assert (tmp_path / "cli.xrdf").read_text() == (tmp_path / "py.xrdf").read_text()
    assert (inscribe.read_robot_sphere_file(str(tmp_path / "cli.urdf"))["spheres"].keys() ==
            inscribe.read_robot_sphere_file(str(tmp_path / "py.urdf"))["spheres"].keys())
    run_cli("convert", tmp_path / "py.xrdf", "-o", tmp_path / "converted.srdf")
    converted = inscribe.read_robot_spheres(str(tmp_path / "converted.srdf"))
    assert all(np.array_equal(converted[k], v) for k, v in spherized.spheres.items())


def test_write_robot_spheres_and_its_errors(robot, tmp_path):
    urdf, _ = robot
    spheres = {"base": np.array([[0.0, 0.0, 0.0, 0.2]]), "arm": np.array([[0.0, 0, 0.2, 0.05]])}
    path = tmp_path / "hand.yml"
    inscribe.write_robot_spheres(str(path), spheres, self_collision_ignore=[("base", "arm", "")],
                                 collision_buffer={"base": 0.01})
    info = inscribe.read_robot_sphere_file(str(path))
    assert list(info["spheres"]) == ["base", "arm"]
    assert info["collision_buffer"] == {"base": 0.01}
    assert info["self_collision_ignore"] == [("arm", "base", "")]
    with pytest.raises(ValueError, match="robot=URDF_PATH"):
        inscribe.write_robot_spheres(str(tmp_path / "x.urdf"), spheres)
    inscribe.write_robot_spheres(str(tmp_path / "x.urdf"), spheres, robot=str(urdf))
    assert np.array_equal(inscribe.read_robot_spheres(str(tmp_path / "x.urdf"))["arm"],
                          spheres["arm"])
    with pytest.raises(ValueError, match="cannot carry the link name"):
        inscribe.write_robot_spheres(str(tmp_path / "y.xrdf"), {"a b": spheres["arm"]})
    (tmp_path / "bad.srdf").write_text('<robot><link_sphere_approximation link="a">'
                                       '<sphere center="1 2" radius="1"/>'
                                       '</link_sphere_approximation></robot>')
    with pytest.raises(ValueError, match="bad.srdf .srdf.: line 1: <sphere> of link 'a'"):
        inscribe.read_robot_spheres(str(tmp_path / "bad.srdf"))
    with pytest.raises(FileNotFoundError):
        inscribe.read_robot_spheres(str(tmp_path / "none.xrdf"))
    with pytest.raises(ValueError, match="unknown robot sphere format"):
        inscribe.read_robot_spheres(str(path), format="obj")
