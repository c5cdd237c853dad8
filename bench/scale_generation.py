#!/usr/bin/python3
"""Generation at scale: meshes of about a million triangles at 2,000 spheres, and
budgets of 10,000 spheres, with both selections. Each row runs `inscribe generate ... --json` in
its own process and reports its wall time and peak resident memory (os.wait4), next to the
generation's own seconds and the exact nerr from the JSON summary. Prints a Markdown table.

    bench/scale_generation.py [--inscribe build/client/inscribe] [--quick]

Needs scripts/fetch-meshes and scripts/make-big-meshes (run here when data/big/ is missing).
Targets: 1M triangles and 2,000 spheres in at most 20 s and 4 GB.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

TOP = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(command):
    """(exit code, stdout, stderr, wall seconds, peak RSS in GB) of one child process."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        start = time.monotonic()
        process = subprocess.Popen(command, stdout=out, stderr=err)
        # wait4 reaps the child itself, so its rusage is this child's own (ru_maxrss in KiB).
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.monotonic() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        err.seek(0)
        return (process.returncode, out.read().decode(), err.read().decode(), wall,
                usage.ru_maxrss / 1024 / 1024)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--inscribe", default=os.path.join(TOP, "build", "client", "inscribe"))
    parser.add_argument("--quick", action="store_true",
                        help="one small row of each kind (a smoke run)")
    args = parser.parse_args()
    if args.quick:
        big = [os.path.join(TOP, "data", "elephant.off")]
        rows = [(big[0], 300, s) for s in ("paper", "optimised")]
        rows += [(os.path.join(TOP, "data", "eight.off"), 1000, "optimised")]
    else:
        made = subprocess.run([os.path.join(TOP, "scripts", "make-big-meshes")], check=True,
                              capture_output=True, text=True).stdout.split()
        rows = [(mesh, 2000, s) for mesh in made for s in ("paper", "optimised")]
        rows += [(os.path.join(TOP, "data", "bunny00.off"), 10000, s)
                 for s in ("paper", "optimised")]
    print(f"# {time.strftime('%Y-%m-%d')} {os.cpu_count()} cores; `inscribe generate MESH "
          "--max-spheres N --selection S --quality-samples 0 --json`, one process per row\n")
    print("| mesh | triangles | selection | budget | spheres | nerr (exact) | load s | "
          "generation s | wall s | peak RSS GB | <= 20 s and 4 GB |")
    print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|")
    failures = 0
    for mesh, budget, selection in rows:
        command = [args.inscribe, "generate", mesh, "--max-spheres", str(budget), "--selection",
                   selection, "--quality-samples", "0", "--json"]
        code, out, err, wall, rss_gb = run(command)
        name = os.path.basename(mesh)
        if code != 0:
            failures += 1
            print(f"| {name} | | {selection} | {budget} | failed: {err.strip()[:200]} |")
            continue
        summary = json.loads(out)
        triangles = summary["triangles"]
        big = triangles >= 1_000_000 and budget == 2000
        verdict = ("pass" if wall <= 20 and rss_gb <= 4 else "FAIL") if big else "-"
        print(f"| {name} | {triangles:,} | {selection} | {budget:,} | {summary['spheres']} | "
              f"{summary['nerr']:.4f} | {summary['load_seconds']:.2f} | "
              f"{summary['seconds']:.2f} | {wall:.2f} | {rss_gb:.2f} | {verdict} |", flush=True)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
