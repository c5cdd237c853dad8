"""inscribe.generate, evaluate and certify against the CLI on the same input: the same spheres
bit for bit; progress, cancellation and errors."""

import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import inscribe
from conftest import mesh_path, run_cli


@pytest.fixture(scope="module")
def eight():
    return inscribe.prepare(inscribe.load_mesh(mesh_path("eight.off")))


@pytest.mark.parametrize("mesh, cli_args, kwargs", [
    ("bunny00.off", [], {}),
    ("eight.off", ["--max-spheres", "60"], {"max_spheres": 60}),
    ("eight.off", ["--max-spheres", "60", "--selection", "paper"],
     {"max_spheres": 60, "selection": "paper"}),
    ("fandisk.off", ["--voxel-size", "0.08"], {"voxel_size": 0.08}),
    ("eight.off", ["--max-spheres", "60", "--dilate"], {"max_spheres": 60, "kind": "dilated"}),
    ("eight.off", ["--cover", "--max-spheres", "80"], {"max_spheres": 80, "kind": "cover"}),
])
def test_spheres_are_bit_identical_to_the_cli(tmp_path, mesh, cli_args, kwargs):
    out = tmp_path / "cli.json"
    run_cli("generate", mesh_path(mesh), *cli_args, "-o", out)
    cli = inscribe.read_spheres(str(out))
    ours = inscribe.generate(inscribe.load_mesh(mesh_path(mesh)), **kwargs)
    assert ours.spheres.shape == cli.spheres.shape and ours.spheres.dtype == np.float64
    assert np.array_equal(ours.spheres, cli.spheres)  # bit for bit, not approximately
    assert ours.mesh_sha256 == cli.mesh_sha256
    assert ours.kind == kwargs.get("kind", "internal")
    if ours.kind == "internal":
        assert np.array_equal(ours.contact_triangles, cli.contact_triangles)
        assert np.array_equal(ours.contact_barycentrics, cli.contact_barycentrics)
    if ours.kind == "cover":
        assert ours.certificate.certified
        assert ours.certificate.delta == cli.stats["delta"]
    # What a sphere file records of a generation is one rule (core's GenerationSphereFile):
    # the same params, and the same stats but for the timings.
    assert ours.params == cli.params
    assert set(ours.stats) == set(cli.stats)
    untimed = lambda stats: {k: v for k, v in stats.items() if not k.endswith("seconds")}
    assert untimed(ours.stats) == untimed(cli.stats)


def test_a_cover_saved_from_python_is_a_cover_to_the_cli(tmp_path, eight):
    internal = inscribe.generate(eight, max_spheres=40, evaluate=False)
    cover = inscribe.generate(eight, max_spheres=80, kind="cover", evaluate=False)
    internal_file, cover_file = tmp_path / "internal.json", tmp_path / "cover.json"
    inscribe.write_spheres(internal, str(internal_file))
    inscribe.write_spheres(cover, str(cover_file))
    read = inscribe.read_spheres(str(cover_file))
    assert read.kind == "cover" and read.certificate.certified
    assert read.certificate.delta == cover.certificate.delta
    poses = tmp_path / "poses.txt"
    poses.write_text("1 0 0 0 3 0 0\n1 0 0 0 0.5 0 0\n")
    summary = json.loads(run_cli("distance", internal_file, internal_file, "--poses", poses,
                                 "--cover-a", cover_file, "--cover-b", cover_file,
                                 "--json").stdout)
    assert summary["queries"] == 2
    # Edited spheres lose the certificate on reading, as the CLI refuses them.
    edited = np.array(cover.spheres)
    edited[0, 3] *= 0.5
    edited_file = tmp_path / "edited.json"
    forged = inscribe.SphereSet(edited, kind="cover", mesh_sha256=cover.mesh_sha256)
    forged.params, forged.stats = cover.params, cover.stats  # the old certificate's figures
    inscribe.write_spheres(forged, str(edited_file))
    assert inscribe.read_spheres(str(edited_file)).certificate is None


def test_quality_is_the_cli_evaluation(tmp_path, eight):
    out = tmp_path / "s.json"
    run_cli("generate", mesh_path("eight.off"), "--max-spheres", "60", "-o", out)
    report = json.loads(run_cli("evaluate", mesh_path("eight.off"), out, "--json").stdout)
    ours = inscribe.evaluate(eight, inscribe.read_spheres(str(out)))
    assert ours.nerr == report["nerr"]
    assert ours.volume_union == report["volume_union"]
    assert ours.coverage == report["coverage"]


def test_certify_proves_a_cover_and_refuses_an_internal_set(eight):
    cover = inscribe.generate(eight, max_spheres=80, kind="cover", evaluate=False)
    certificate = inscribe.certify(eight, cover)
    assert certificate.certified and certificate.delta > 0
    internal = inscribe.generate(eight, max_spheres=60, evaluate=False)
    refused = inscribe.certify(eight, internal.spheres)
    assert not refused.certified and refused.uncovered_point.shape == (3,)


def test_progress_goes_up_to_one_on_the_calling_thread(eight):
    seen, threads = [], set()

    def progress(fraction):
        seen.append(fraction)
        threads.add(threading.get_ident())

    inscribe.generate(eight, max_spheres=60, evaluate=False, progress=progress)
    assert seen and seen[-1] == 1.0 and seen == sorted(seen)
    assert threads == {threading.get_ident()}


def test_an_exception_in_progress_cancels_and_propagates(eight):
    class Stop(Exception):
        pass

    def progress(fraction):
        raise Stop()

    start = time.monotonic()
    with pytest.raises(Stop):
        inscribe.generate(eight, voxel_size=0.01, evaluate=False, progress=progress)
    assert time.monotonic() - start < 10


def test_ctrl_c_cancels_a_long_run():
    solid = inscribe.prepare(inscribe.load_mesh(mesh_path("bunny00.off")))
    main = threading.get_ident()
    timer = threading.Timer(0.5, lambda: signal.pthread_kill(main, signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        # About a minute of work uncancelled.
        inscribe.generate(solid, voxel_size=0.004, evaluate=False)
    assert time.monotonic() - start < 5


@pytest.mark.parametrize("kwargs, message", [
    ({"max_spheres": 10, "voxel_size": 0.1}, "give a voxel size or a sphere budget, not both"),
    ({"object_angle": 4.0}, "object angle must lie in (0, pi) radians, got 4"),
    ({"kind": "hollow"}, "kind must be 'internal', 'dilated' or 'cover', got 'hollow'"),
    ({"kind": "cover", "voxel_size": 0.1}, "a cover takes a sphere budget or a max_protrusion"),
    ({"selection": "greedy"}, "unknown sphere selection 'greedy': expected paper or optimised"),
])
def test_bad_settings_are_value_errors_with_cores_message(eight, kwargs, message):
    with pytest.raises(ValueError) as raised:
        inscribe.generate(eight, **kwargs)
    assert message in str(raised.value)


def test_the_optimised_selection_beats_the_papers_and_says_so(eight):
    paper = inscribe.generate(eight, max_spheres=80, selection="paper")
    optimised = inscribe.generate(eight, max_spheres=80)
    assert optimised.stats["pool_size"] > 80 and "pool_size" not in paper.stats
    assert optimised.params["selection"] == "optimised" and paper.params["selection"] == "paper"
    assert len(optimised.spheres) <= 80
    assert optimised.quality.nerr < paper.quality.nerr
