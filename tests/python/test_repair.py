"""The repair ladder from Python: the same levels, figures and hashes as the CLI; the wrap
encloses the input (checked here with numpy's own winding number, not core's); bad levels and
conflicting keywords refused."""

import json
import warnings

import numpy as np
import pytest

import inscribe
from conftest import mesh_path, run_cli


def open_cup():
    """A unit cube without its top face."""
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                  [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=np.float64)
    t = np.array([[0, 2, 1], [0, 3, 2], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                  [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]], dtype=np.int32)
    return inscribe.Mesh(v, t)


def winding(mesh, points):
    """Winding numbers of `points` with respect to a closed mesh: solid angles summed
    (Van Oosterom and Strackee), in numpy."""
    v = mesh.vertices[mesh.triangles]  # (T, 3, 3)
    total = np.zeros(len(points))
    for i, p in enumerate(points):
        a, b, c = (v[:, k, :] - p for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=1) for x in (a, b, c))
        det = np.einsum("ij,ij->i", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ij,ij->i", a, b) * lc
               + np.einsum("ij,ij->i", b, c) * la + np.einsum("ij,ij->i", c, a) * lb)
        total[i] = np.sum(2 * np.arctan2(det, den)) / (4 * np.pi)
    return np.rint(total)


def test_levels_refuse_then_repair_an_open_cup():
    cup = open_cup()
    for level in ("none", "safe"):
        report = cup.validate(repair=level)
        assert not report.usable and "--repair" in report.first_error
    with pytest.warns(inscribe.MeshWarning):
        filled = inscribe.prepare(cup, repair="fill")
    assert filled.report.holes_filled == 1 and filled.report.geometry_repaired
    with pytest.warns(inscribe.MeshWarning):
        automatic = inscribe.prepare(cup, repair=inscribe.Repair("auto"))
    assert automatic.sha256 == filled.sha256 and not automatic.report.wrapped
    # fill_holes=True is the older spelling of repair="fill".
    with pytest.warns(inscribe.MeshWarning):
        assert inscribe.prepare(cup, fill_holes=True).sha256 == filled.sha256


def test_the_wrap_encloses_the_input_and_matches_the_cli(tmp_path):
    cup = open_cup()
    wrap = inscribe.Repair("wrap", wrap_alpha=0.1)
    fixed, report = cup.repaired(wrap)
    assert report.usable and report.wrapped and report.closed
    assert report.wrap_alpha == 0.1 and report.wrap_offset == pytest.approx(0.1 / 20)
    assert fixed.num_triangles == report.wrap_triangles
    rng = np.random.default_rng(3)
    tri = cup.vertices[cup.triangles]
    w = rng.uniform(size=(len(tri), 20, 2))
    w = np.where(w.sum(axis=2, keepdims=True) > 1, 1 - w, w)
    samples = (tri[:, None, 0] + w[..., :1] * (tri[:, None, 1] - tri[:, None, 0])
               + w[..., 1:] * (tri[:, None, 2] - tri[:, None, 0])).reshape(-1, 3)
    assert np.all(winding(fixed, samples) == 1)
    # The CLI on the same file gives the same repaired mesh.
    path = tmp_path / "cup.off"
    inscribe.write_mesh(cup, str(path))
    out = tmp_path / "wrapped.off"
    info = json.loads(run_cli("info", "--json", "--repair", "wrap", "--wrap-alpha", "0.1",
                              path, "-o", out).stdout)
    assert info["repair"]["wrapped"] and info["repair"]["wrap"]["reach"] == report.wrap_reach
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", inscribe.MeshWarning)
        assert info["mesh_sha256"] == inscribe.prepare(cup, repair=wrap).sha256
    assert np.array_equal(inscribe.load_mesh(str(out)).vertices, fixed.vertices)


def test_a_wrapped_cover_reports_delta_over_the_input():
    cup = open_cup()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", inscribe.MeshWarning)
        solid = inscribe.prepare(cup, repair=inscribe.Repair("wrap", wrap_alpha=0.1))
    cover = inscribe.generate(solid, max_spheres=40, kind="cover")
    assert cover.certificate.certified
    assert cover.stats["delta_input"] > cover.certificate.delta
    assert cover.stats["delta_input"] == pytest.approx(
        cover.certificate.delta + solid.report.wrap_reach)
    assert cover.params["mesh_wrap_alpha"] == 0.1


def test_bad_levels_and_conflicting_keywords_are_refused():
    with pytest.raises(ValueError, match="unknown mesh repair 'mend'"):
        inscribe.Repair("mend")
    with pytest.raises(ValueError, match="fill_holes=True"):
        inscribe.prepare(open_cup(), repair="wrap", fill_holes=True)
    with pytest.raises(ValueError, match="weld_tolerance"):
        open_cup().validate(repair=inscribe.Repair("safe", weld_tolerance=0.1),
                            weld_tolerance=0.2)


def test_the_client_sends_the_repair(server):
    client = inscribe.Client(server.address)
    cup = open_cup()
    with pytest.raises(inscribe.Error) as refused:
        client.put_mesh(cup, repair="none")
    assert refused.value.code == "FAILED_PRECONDITION"
    result = client.inspect_mesh(cup, repair="auto")
    assert result.report.usable and result.report.holes_filled == 1
    key = client.put_mesh(cup, repair=inscribe.Repair("wrap", wrap_alpha=0.1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", inscribe.MeshWarning)
        assert key == inscribe.prepare(cup, repair=inscribe.Repair("wrap", wrap_alpha=0.1)).sha256


def test_a_robot_whose_link_mesh_is_open_spherizes_every_link_with_a_repair(tmp_path):
    inscribe.write_mesh(open_cup(), str(tmp_path / "cup.off"))
    (tmp_path / "robot.urdf").write_text("""<robot name="r">
  <link name="base"><collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision></link>
  <link name="cup"><collision><geometry><mesh filename="cup.off"/></geometry></collision></link>
  <joint name="j" type="revolute"><parent link="base"/><child link="cup"/>
    <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/><limit lower="-1" upper="1"/></joint>
</robot>""")
    path = str(tmp_path / "robot.urdf")
    default = inscribe.spherize_urdf(path, max_spheres_per_link=8)
    cup = default.links[1]
    assert cup.status == "skipped" and "--repair" in cup.error
    for kwargs in ({"repair": "auto"}, {"link_repair": {"cup": "fill"}},
                   {"repair": inscribe.Repair("wrap", wrap_alpha=0.1)}):
        robot = inscribe.spherize_urdf(path, max_spheres_per_link=8, **kwargs)
        assert [link.status for link in robot.links] == ["spherized", "spherized"], kwargs
        assert any("fixed" in w for w in robot.links[1].warnings), kwargs
    # A budget of 0 leaves a link out, and says so.
    robot = inscribe.spherize_urdf(path, max_spheres_per_link=8, repair="auto",
                                   link_max_spheres={"base": 0})
    assert robot.links[0].status == "skipped" and "left out" in robot.links[0].error
    assert robot.links[1].status == "spherized"
