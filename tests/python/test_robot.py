"""inscribe.spherize_urdf against `inscribe urdf` on the same robot."""

import numpy as np
import pytest
import yaml

import inscribe
from conftest import mesh_path, run_cli

ROBOT = """<?xml version="1.0"?>
<robot name="two_link">
  <link name="base">
    <collision><origin xyz="0 0 0.05" rpy="0 0 0"/><geometry><box size="0.3 0.2 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <collision><origin xyz="0 0 0.2" rpy="0.1 0 0"/><geometry><cylinder radius="0.04" length="0.4"/></geometry></collision>
    <collision><geometry><mesh filename="{mesh}" scale="0.05 0.05 0.05"/></geometry></collision>
  </link>
  <link name="world"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/></joint>
</robot>
"""


def test_spheres_urdf_and_yaml_are_the_clis(tmp_path):
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(ROBOT.format(mesh=mesh_path("eight.off")))
    out = tmp_path / "spherized.urdf"
    run_cli("urdf", urdf, "-o", out, "--max-spheres-per-link", "24")
    robot = inscribe.spherize_urdf(str(urdf), max_spheres_per_link=24)
    assert [link.status for link in robot.links] == ["spherized", "spherized", "no_geometry"]
    cli_yaml = inscribe.parse_curobo_yaml((tmp_path / "spherized.yml").read_text())
    for link in robot.links[:2]:
        assert np.array_equal(link.spheres, cli_yaml[link.link].spheres)
        assert 0 < len(link.spheres) <= 24
    assert robot.urdf() == out.read_text()
    assert yaml.safe_load(robot.curobo_yaml()) == yaml.safe_load(
        (tmp_path / "spherized.yml").read_text())


def test_default_budget_is_the_clis(tmp_path):
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(ROBOT.format(mesh=mesh_path("eight.off")))
    robot = inscribe.spherize_urdf(str(urdf))
    assert all(len(link.spheres) <= inscribe.DEFAULT_MAX_SPHERES_PER_LINK for link in robot.links)
    assert inscribe.DEFAULT_MAX_SPHERES_PER_LINK == 32


def test_a_missing_mesh_skips_its_link_with_the_reason(tmp_path):
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(ROBOT.format(mesh="missing.stl"))
    robot = inscribe.spherize_urdf(str(urdf))
    arm = robot.links[1]
    assert arm.status == "skipped" and "missing.stl" in arm.error and len(arm.spheres) == 0


def test_bad_urdf_and_missing_file(tmp_path):
    with pytest.raises(FileNotFoundError):
        inscribe.spherize_urdf(str(tmp_path / "none.urdf"))
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot><link></robot>")
    with pytest.raises(ValueError, match="bad.urdf"):
        inscribe.spherize_urdf(str(bad))
    with pytest.raises(ValueError, match="not both"):
        inscribe.spherize_urdf(str(bad), max_spheres_per_link=3, voxel_size=0.1)
