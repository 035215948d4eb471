#!/usr/bin/env python3
"""The cost of calling crease from Python against the CLI's own compute time (issue 32's goal:
under 5 %), at 100k and 1M points.

For `sharp` and `run` on clouds made by `crease synth`: the CLI's compute time (its --json
`seconds`, reading and writing excluded) and the Python call's wall time on the array already
in memory (checks and copies in, the computation, arrays and dicts out). Each is the median of
--repeat runs, in one process per measurement so both pay the same warm-up.

    python/target/py-venv/bin/python scripts/python-overhead.py --cli target/release/crease
"""

import argparse
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import crease


def cli_seconds(cli, task, src, out):
    args = [cli, "--json", "-q", task, str(src), "-o", str(out)]
    if task == "run":
        args.append("--no-picture")
    r = subprocess.run(args, capture_output=True, text=True, check=True)
    d = json.loads(r.stdout)
    if task == "run":
        # The stages' sum: reading, writing the files and the picture excluded.
        return sum(d["timings"].values())
    return d["seconds"]


def py_seconds(task, points):
    t = time.perf_counter()
    if task == "run":
        crease.run(points)
    else:
        crease.sharp(points)
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cli", required=True, help="the crease binary (a release build)")
    ap.add_argument("--sizes", default="100000,1000000")
    ap.add_argument("--tasks", default="sharp,run")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        print("| task | points | CLI compute (s) | Python call (s) | overhead |")
        print("|---|---|---|---|---|")
        for n in [int(x) for x in a.sizes.split(",")]:
            src = d / f"part-{n}.ply"
            subprocess.run([a.cli, "-q", "synth", "fillet-chamfer-cone", "-n", str(n), "-o", str(src)],
                           check=True)
            points = crease.read(src).points
            for task in a.tasks.split(","):
                out = d / ("out" if task == "run" else "out.ply")
                c = statistics.median(cli_seconds(a.cli, task, src, out) for _ in range(a.repeat))
                p = statistics.median(py_seconds(task, points) for _ in range(a.repeat))
                print(f"| {task} | {n:,} | {c:.3f} | {p:.3f} | {100 * (p - c) / c:+.1f} % |")
                sys.stdout.flush()


if __name__ == "__main__":
    main()
