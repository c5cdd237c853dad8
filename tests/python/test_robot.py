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
    good = tmp_path / "robot.urdf"
    good.write_text(ROBOT.format(mesh=mesh_path("eight.off")))
    with pytest.raises(ValueError, match="at most one of"):
        inscribe.spherize_urdf(str(good), max_spheres_per_link=3, max_spheres=10)
    with pytest.raises(ValueError, match="covers take no voxel_size"):
        inscribe.spherize_urdf(str(good), voxel_size=0.1)
    with pytest.raises(ValueError, match="kind must be"):
        inscribe.spherize_urdf(str(good), kind="outer")
    with pytest.raises(ValueError, match="'nolink'"):
        inscribe.spherize_urdf(str(good), clip_planes=[("nolink", (0, 0, 1), 0.0)])


def test_covers_budget_padding_and_clip_planes_are_the_clis(tmp_path):
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(ROBOT.format(mesh=mesh_path("eight.off")))
    out = tmp_path / "shared.urdf"
    run_cli("urdf", urdf, "-o", out, "--max-spheres", "20", "--padding", "0.002",
            "--clip", "base=0,0,-1,-0.02", "--link-max-spheres", "arm=12")
    robot = inscribe.spherize_urdf(str(urdf), max_spheres=20, padding=0.002,
                                   clip_planes=[("base", (0, 0, -1), -0.02)],
                                   link_max_spheres={"arm": 12})
    base, arm = robot.links[0], robot.links[1]
    assert base.kind == "cover" and base.certified and arm.certified
    assert arm.budget == 12 and base.budget == 20
    assert base.delta >= 0.002 and arm.delta >= 0.002
    # The base's box starts at z = 0; the part below z = 0.02 is cut off.
    assert np.all(base.spheres[:, 2] - base.spheres[:, 3] >= 0.02 - base.delta - 1e-12)
    assert base.cores.shape[1] == 4 and len(base.cores) > 0
    cli_yaml = inscribe.parse_curobo_yaml((tmp_path / "shared.yml").read_text())
    for link in (base, arm):
        assert np.array_equal(link.spheres, cli_yaml[link.link].spheres)
    assert robot.urdf() == out.read_text()


def test_self_collision_matrix_srdf_and_yaml_are_the_clis(tmp_path):
    urdf = tmp_path / "robot.urdf"
    # One tree: the unattached "world" link would make two roots.
    urdf.write_text(ROBOT.format(mesh=mesh_path("eight.off")).replace('<link name="world"/>', ""))
    out = tmp_path / "matrix.urdf"
    run_cli("urdf", urdf, "-o", out, "--srdf", tmp_path / "matrix.srdf", "--samples", "500",
            "--seed", "3")
    robot = inscribe.spherize_urdf(str(urdf))
    matrix = robot.self_collision(samples=500, seed=3)
    assert matrix.samples == 500 and matrix.seed == 3 and matrix.certified
    assert [(p["link1"], p["link2"]) for p in matrix.pairs] == [("base", "arm")]
    assert matrix.pairs[0]["class"] == "Adjacent" and matrix.pairs[0]["disabled"]
    assert matrix.srdf() == (tmp_path / "matrix.srdf").read_text()
    assert robot.curobo_yaml(matrix) == (tmp_path / "matrix.yml").read_text()
    assert "self_collision_ignore" in yaml.safe_load(robot.curobo_yaml(matrix))
    with pytest.raises(ValueError, match="samples"):
        robot.self_collision(samples=0)

    # Several roots: no matrix, said so.
    two_roots = tmp_path / "two_roots.urdf"
    two_roots.write_text(ROBOT.format(mesh=mesh_path("eight.off")))
    with pytest.raises(ValueError, match="root"):
        inscribe.spherize_urdf(str(two_roots)).self_collision(samples=10)


def test_relative_mesh_paths_resolve_from_the_output_folder(tmp_path):
    import shutil
    (tmp_path / "robot").mkdir()
    (tmp_path / "meshes").mkdir()
    shutil.copy(mesh_path("eight.off"), tmp_path / "meshes" / "eight.off")
    (tmp_path / "meshes" / "open.off").write_text(
        "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n")
    urdf = tmp_path / "robot" / "robot.urdf"
    urdf.write_text("""<?xml version="1.0"?>
<robot name="paths">
  <link name="a">
    <visual><geometry><mesh filename="../meshes/eight.off" scale="0.05 0.05 0.05"/></geometry></visual>
    <collision><geometry><mesh filename="../meshes/eight.off" scale="0.05 0.05 0.05"/></geometry></collision>
  </link>
  <link name="b">
    <collision><geometry><mesh filename="file://../meshes/open.off"/></geometry></collision>
  </link>
  <joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint>
</robot>
""")
    out = tmp_path / "out" / "deeper" / "spherized.urdf"
    out.parent.mkdir(parents=True)
    run = run_cli("urdf", urdf, "-o", out, "--max-spheres-per-link", "8", "--repair", "none",
                  check=False)
    assert run.returncode == 1, run.stderr  # link b is skipped
    text = out.read_text()
    # The visual and the skipped link's kept collision name the same files from the output.
    assert 'filename="../../meshes/eight.off"' in text
    assert 'filename="file://../../meshes/open.off"' in text
    assert (out.parent / "../../meshes/eight.off").resolve() == (
        tmp_path / "meshes" / "eight.off").resolve()
    robot = inscribe.spherize_urdf(str(urdf), max_spheres_per_link=8, repair="none")
    assert robot.urdf(directory=str(out.parent)) == text
    assert 'filename="../meshes/eight.off"' in robot.urdf()  # no folder: as written
    # The output is itself a robot whose meshes are found: its skipped link is skipped for
    # the same reason, not for a missing file.
    again = inscribe.spherize_urdf(str(out), max_spheres_per_link=8, repair="none")
    assert [link.status for link in again.links] == ["spherized", "skipped"]
    assert "does not exist" not in again.links[1].error
