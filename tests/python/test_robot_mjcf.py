"""inscribe.spherize_robot on MuJoCo models (MJCF): spheres per body as numpy arrays, the
collision geoms by MuJoCo's contact rule or by class or group, and the same results as
spherize_urdf on a URDF."""

import numpy as np
import pytest
import yaml

import inscribe
from test_robot import ROBOT
from conftest import mesh_path

MODEL = """<mujoco model="arm">
  <compiler angle="degree" autolimits="true"/>
  <default>
    <default class="visual"><geom contype="0" conaffinity="0" group="2"/></default>
    <default class="collision"><geom group="3"/></default>
  </default>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <body name="base" pos="0 0 0.1">
      <geom class="collision" type="box" size="0.1 0.08 0.05" euler="0 0 30"/>
      <geom class="visual" type="sphere" size="0.2"/>
      <body name="arm" pos="0 0 0.1" quat="0.9 0 0.3 0">
        <joint name="shoulder" type="ball"/>
        <joint name="slide" type="slide" axis="0 0 1" range="0 0.1"/>
        <geom class="collision" type="capsule" fromto="0 0 0 0 0 0.3" size="0.03"/>
        <body name="camera" pos="0 0 0.3">
          <geom class="visual" type="ellipsoid" size="0.02 0.03 0.01"/>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


def box_points(half, yaw_degrees, centre, count=2000, seed=0):
    """Points of a box with half sizes `half` turned by yaw about z, in its body's frame."""
    rng = np.random.default_rng(seed)
    local = rng.uniform(-1, 1, size=(count, 3)) * np.asarray(half)
    c, s = np.cos(np.radians(yaw_degrees)), np.sin(np.radians(yaw_degrees))
    turn = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    return local @ turn.T + np.asarray(centre)


def covered(points, spheres):
    """Whether every point lies in some sphere (N, 4) [x, y, z, r]."""
    d = np.linalg.norm(points[:, None, :] - spheres[None, :, :3], axis=2)
    return bool(np.all(np.any(d <= spheres[None, :, 3] + 1e-12, axis=1)))


def test_bodies_spherized_from_their_collision_geoms(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(MODEL)
    robot = inscribe.spherize_robot(str(path), max_spheres_per_link=12)
    assert robot.format == "mjcf" and robot.name == "arm"
    # The ball and the slide add two links of their own, without geometry.
    statuses = {link.link: link.status for link in robot.links}
    assert statuses["world"] == "no_geometry"
    assert statuses["arm/shoulder/x"] == "no_geometry"
    assert set(robot.spheres) == {"base", "arm", "camera"}
    for name, spheres in robot.spheres.items():
        assert spheres.dtype == np.float64 and spheres.shape[1] == 4
        assert 0 < len(spheres) <= 12
    # The base's spheres hold its collision box (its visual sphere is not the solid).
    assert covered(box_points((0.1, 0.08, 0.05), 30, (0, 0, 0)), robot.spheres["base"])
    base = next(link for link in robot.links if link.link == "base")
    assert base.certified and not base.from_visual and base.delta > 0
    assert np.all(np.linalg.norm(robot.spheres["base"][:, :3], axis=1) < 0.2)
    # The camera has visual geoms only: they stand in, with a warning.
    camera = next(link for link in robot.links if link.link == "camera")
    assert camera.from_visual
    assert any("'camera'" in w for w in robot.warnings)
    assert any("'floor'" in w for w in robot.warnings)
    matrix = robot.self_collision(samples=200)
    pairs = {frozenset((p["link1"], p["link2"])): p["class"] for p in matrix.pairs}
    assert set(pairs) == {frozenset(("base", "arm")), frozenset(("base", "camera")),
                          frozenset(("arm", "camera"))}
    # Joined through the ball's and the slide's links of their own, which have no geometry.
    assert pairs[frozenset(("base", "arm"))] == "Adjacent"
    assert pairs[frozenset(("arm", "camera"))] == "Adjacent"
    assert set(yaml.safe_load(robot.curobo_yaml())["collision_spheres"]) == {"base", "arm",
                                                                             "camera"}
    with pytest.raises(ValueError, match="MJCF model"):
        robot.urdf()
    text = robot.mjcf(str(tmp_path))
    total = sum(len(spheres) for spheres in robot.spheres.values())
    assert text.count('group="3" mass="0"') == total  # one massless sphere geom per sphere
    assert text.count('contype="0" conaffinity="0"') >= 3  # the solids no longer collide


def test_solid_chosen_by_group_or_class(tmp_path):
    path = tmp_path / "arm.xml"
    path.write_text(MODEL)
    by_group = inscribe.spherize_robot(str(path), max_spheres_per_link=8, solid_groups=[2])
    # Group 2 is the visual class: the base's sphere of radius 0.2 is now its solid.
    assert np.max(np.linalg.norm(by_group.spheres["base"][:, :3], axis=1)
                  + by_group.spheres["base"][:, 3]) > 0.19
    by_class = inscribe.spherize_robot(str(path), max_spheres_per_link=8,
                                       solid_classes=["visual"])
    assert np.array_equal(by_class.spheres["base"], by_group.spheres["base"])
    # The arm has no visual geom: its collision capsule stands in, with a warning.
    assert any("'arm'" in w for w in by_class.warnings)


def test_urdf_through_spherize_robot_is_spherize_urdf(tmp_path):
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(ROBOT.format(mesh=mesh_path("eight.off")))
    a = inscribe.spherize_robot(str(urdf), max_spheres_per_link=10)
    b = inscribe.spherize_urdf(str(urdf), max_spheres_per_link=10)
    assert a.format == "urdf" and a.warnings == []
    assert a.spheres.keys() == b.spheres.keys()
    for name in a.spheres:
        assert np.array_equal(a.spheres[name], b.spheres[name])
    assert a.urdf() == b.urdf()


def test_bad_models_name_the_line(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text("<mujoco>\n<worldbody>\n<geom type=\"cone\"/>\n</worldbody>\n</mujoco>\n")
    with pytest.raises(ValueError, match=r"bad.xml line 3: <geom type=\"cone\">"):
        inscribe.spherize_robot(str(bad))
    escape = tmp_path / "escape.xml"
    escape.write_text('<mujoco><include file="../outside.xml"/></mujoco>')
    with pytest.raises(ValueError, match="outside the model's folder"):
        inscribe.spherize_robot(str(escape))
    with pytest.raises(FileNotFoundError):
        inscribe.spherize_robot(str(tmp_path / "none.xml"))
