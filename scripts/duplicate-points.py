#!/usr/bin/env python3
"""Repeats points of a text cloud (x y z per line) exactly, as a handheld scanner's repeated
returns do: --fraction of the output lines are copies of random input lines (each picked point
repeated 1-3 times), shuffled with the originals. Seeded, so a figure made with it reproduces.

    python3 scripts/duplicate-points.py IN.xyz OUT.xyz --fraction 0.4 --seed 7
"""
import argparse
import random

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("input")
ap.add_argument("output")
ap.add_argument("--fraction", type=float, default=0.4, help="share of copies in the output")
ap.add_argument("--seed", type=int, default=7)
a = ap.parse_args()
if not 0.0 <= a.fraction < 1.0:
    ap.error("--fraction must be in [0, 1)")
rng = random.Random(a.seed)
with open(a.input) as f:
    lines = [l.rstrip("\n") for l in f if l.strip()]
want = int(a.fraction * len(lines) / (1.0 - a.fraction))
extra = []
while len(extra) < want:
    line = rng.choice(lines)
    extra.extend([line] * rng.randint(1, 3))
out = lines + extra[:want]
rng.shuffle(out)
with open(a.output, "w") as f:
    f.write("\n".join(out) + "\n")
print(f"{len(lines)} points + {want} copies -> {a.output}")
