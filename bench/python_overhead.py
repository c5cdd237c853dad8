#!/usr/bin/python3
"""Python bindings against C++ on the same work, in one run (the targets: at most 5%
overhead for generation, 10% for distance batches).

    /usr/bin/python3 bench/python_overhead.py [--mesh data/bunny00.off] [--max-spheres 500]
        [--poses 10000] [--rounds 3] [--distance-runs 20]

Generation: inscribe.generate(solid, max_spheres=N) against GenerateSphereSet in
build/bench/python_peer, each on its own prepared solid. Distance: inscribe.distance(h, h,
poses) on an (N, 7) float64 array against PairSeparationDistances on the same poses (core
RigidPose values, prepared before the clock starts). Rounds alternate C++ and Python so that
both see the same machine; the table gives the median over all runs of each (and the minimum).
Run from the source tree after a build; PYTHONPATH defaults to build/python.
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

TOP = pathlib.Path(__file__).resolve().parents[1]
BUILD = pathlib.Path(os.environ.get("INSCRIBE_BUILD_DIR", TOP / "build"))
sys.path.insert(0, str(BUILD / "python"))

import numpy as np  # noqa: E402

import inscribe  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default=str(TOP / "data" / "bunny00.off"))
    parser.add_argument("--max-spheres", type=int, default=500)
    parser.add_argument("--poses", type=int, default=10_000)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--distance-runs", type=int, default=20)
    args = parser.parse_args()

    rng = np.random.default_rng(24)
    q = rng.normal(size=(args.poses, 4))
    solid = inscribe.prepare(inscribe.load_mesh(args.mesh))
    extent = solid.report.bbox_max - solid.report.bbox_min
    poses = np.ascontiguousarray(np.hstack([
        q / np.linalg.norm(q, axis=1, keepdims=True),
        rng.uniform(-0.75, 0.75, size=(args.poses, 3)) * extent]))
    poses_file = tempfile.NamedTemporaryFile(suffix=".bin", delete=False)
    poses_file.write(poses.astype("<f8").tobytes())
    poses_file.close()

    cpp = {"generate": [], "distance": []}
    py = {"generate": [], "distance": []}
    checks = []
    for _ in range(args.rounds):
        peer = subprocess.run(
            [str(BUILD / "bench" / "python_peer"), args.mesh, str(args.max_spheres),
             poses_file.name, "1", str(args.distance_runs)],
            check=True, capture_output=True, text=True)
        figures = json.loads(peer.stdout)
        cpp["generate"] += figures["generate_seconds"]
        cpp["distance"] += figures["distance_seconds"]

        start = time.perf_counter()
        spheres = inscribe.generate(solid, max_spheres=args.max_spheres)
        py["generate"].append(time.perf_counter() - start)
        h = inscribe.Hierarchy(spheres)
        for _ in range(args.distance_runs):
            start = time.perf_counter()
            batch = inscribe.distance(h, h, poses)
            py["distance"].append(time.perf_counter() - start)
        checks.append((figures["spheres"] == len(spheres),
                       figures["distance_sum"] == sum(batch.distance.tolist())))  # in order, as C++ sums
    os.unlink(poses_file.name)
    if not all(all(c) for c in checks):
        sys.exit(f"python_overhead: C++ and Python disagree on the results: {checks}")

    print(f"mesh {pathlib.Path(args.mesh).name}, {len(spheres)} spheres (max {args.max_spheres}),"
          f" {args.poses} poses per batch, {args.rounds} rounds, same results both sides")
    print(f"{'work':<34} {'C++ median':>11} {'Python median':>14} {'overhead':>9}"
          f" {'C++ min':>9} {'Python min':>11} {'overhead':>9}")
    for name, label in [("generate", "generate (budget search + quality)"),
                        ("distance", f"distance batch, {args.poses} poses")]:
        c_med, p_med = statistics.median(cpp[name]), statistics.median(py[name])
        c_min, p_min = min(cpp[name]), min(py[name])
        print(f"{label:<34} {c_med:>10.4f}s {p_med:>13.4f}s {100 * (p_med / c_med - 1):>8.1f}%"
              f" {c_min:>8.4f}s {p_min:>10.4f}s {100 * (p_min / c_min - 1):>8.1f}%")


if __name__ == "__main__":
    main()
