#!/usr/bin/env python3
"""Seeded mutation fuzzer over every input format, as an outside tester runs one.

Seeds: small files of ../shared/data, the hostile samples of crates/crease/tests/bad_input,
and a small mesh and cloud converted by crease itself into every format it writes (PLY
ascii / binary LE / BE, OBJ, OFF, STL ascii / binary, XYZ, CSV, PCD ascii / binary /
binary_compressed, LAS, LAZ, E57). Each run mutates one seed (bit flips, truncation, inserted
or repeated bytes, header counts that lie, numbers replaced by NaN / 1e308 / -1 / huge
integers) and runs one crease command on it under an address-space cap and a time limit.

Outcomes: ok (exit 0), error (exit 1 with an `error:` line), and the defects: panic, timeout,
oom (allocation failure or abort) and other (any other exit). Defects are saved with the
command line under OUT/defects/. Deterministic for a given --seed.

    python3 scripts/mutation-fuzz.py --runs 4800 --jobs 2 --out /tmp/mfuzz
"""

import argparse
import concurrent.futures as cf
import os
import random
import re
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data"
BAD = ROOT / "crates" / "crease" / "tests" / "bad_input"
COMMANDS = ["info", "sharp", "edges", "segment", "normals", "lines", "reconstruct"]
MAX_SEED_BYTES = 400_000
NUMBER = re.compile(rb"-?\d+(\.\d+)?([eE][-+]?\d+)?")
REPLACEMENTS = [b"nan", b"NaN", b"inf", b"-inf", b"1e308", b"-1e308", b"1e19", b"-1",
                b"0", b"4294967295", b"4294967296", b"18446744073709551615", b"99999999999",
                b"1e-320", b"2147483648", b"-2147483649", b""]


def make_seeds(crease, folder, max_bytes):
    """Small real files, the hostile samples, and one mesh and one cloud in every format."""
    seeds = []
    for p in sorted(SHARED.rglob("*")):
        if p.is_file() and p.suffix.lower() in (".ply", ".obj", ".off", ".stl", ".xyz", ".pcd",
                                                ".csv", ".las", ".laz", ".e57"):
            if p.stat().st_size <= max_bytes:
                seeds.append(p)
    seeds += sorted(p for p in BAD.iterdir() if p.is_file())
    mesh = folder / "seed-mesh.obj"
    cloud = folder / "seed-cloud.ply"
    subprocess.run([crease, "synth", "cube", "-o", str(mesh), "-n", "600", "--mesh", "-q"],
                   check=False, capture_output=True)
    subprocess.run([crease, "synth", "cube", "-o", str(cloud), "-n", "600", "-q"],
                   check=False, capture_output=True)
    for src in (mesh, cloud):
        if not src.exists():
            continue
        seeds.append(src)
        for ext, ascii in (("ply", True), ("ply", False), ("off", False), ("stl", True),
                           ("stl", False), ("xyz", False), ("csv", False), ("pcd", True),
                           ("pcd", False), ("las", False), ("laz", False), ("e57", False)):
            out = folder / f"{src.stem}-{'a' if ascii else 'b'}.{ext}"
            cmd = [crease, "convert", str(src), str(out), "-q"] + (["--ascii"] if ascii else [])
            if subprocess.run(cmd, capture_output=True).returncode == 0:
                seeds.append(out)
    return seeds


def mutate(data, rng):
    """One to four mutations of the kinds a broken disk, a bad exporter or an attacker make."""
    data = bytearray(data)
    for _ in range(rng.randint(1, 4)):
        kind = rng.randrange(7)
        n = len(data)
        if n == 0:
            data += bytes(rng.randrange(256) for _ in range(rng.randint(1, 64)))
            continue
        if kind == 0:  # bit flips
            for _ in range(rng.randint(1, 8)):
                i = rng.randrange(n)
                data[i] ^= 1 << rng.randrange(8)
        elif kind == 1:  # truncation
            del data[rng.randrange(n):]
        elif kind == 2:  # inserted bytes
            i = rng.randrange(n + 1)
            data[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 32)))
        elif kind == 3:  # a repeated or removed stretch
            i = rng.randrange(n)
            j = min(n, i + rng.randint(1, 256))
            if rng.random() < 0.5:
                data[i:i] = data[i:j] * rng.randint(1, 50)
            else:
                del data[i:j]
        elif kind in (4, 5):  # a number replaced (header counts that lie, NaN, 1e308, ...)
            head = bytes(data[:4096]) if kind == 4 else bytes(data)
            found = list(NUMBER.finditer(head))
            if found:
                m = found[rng.randrange(len(found))]
                data[m.start():m.end()] = rng.choice(REPLACEMENTS)
        else:  # binary words: a 32-bit count or float overwritten
            i = rng.randrange(n)
            word = rng.choice([b"\xff\xff\xff\xff", b"\x00\x00\xc0\x7f", b"\x00\x00\x80\x7f",
                               b"\xff\xff\xff\x7f", b"\x00\x00\x00\x80", b"\x00\x00\x00\x00"])
            data[i:i + 4] = word
    return bytes(data)


def limit(mem_bytes):
    def f():
        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))
    return f


def classify(rc, err):
    if "panicked" in err:
        return "panic"
    if rc == 0:
        return "ok"
    if rc == 1 and "error:" in err:
        return "error"
    if rc in (-9, 124) or rc is None:
        return "timeout"
    if rc in (134, -6) or "memory allocation" in err or "out of memory" in err.lower():
        return "oom"
    return "other"


def one(args, crease, seeds, work, index):
    rng = random.Random(f"{args.seed}-{index}")
    seed = seeds[rng.randrange(len(seeds))]
    cmd_name = rng.choice(COMMANDS)
    data = mutate(seed.read_bytes(), rng)
    case = Path(tempfile.mkdtemp(dir=work))
    inp = case / f"in{seed.suffix.lower()}"
    inp.write_bytes(data)
    out_ext = {"reconstruct": "step", "lines": "obj"}.get(cmd_name, "ply")
    cmd = [crease, cmd_name, str(inp)]
    if cmd_name != "info":
        cmd += ["-o", str(case / f"out.{out_ext}")]
    try:
        p = subprocess.run(cmd, capture_output=True, timeout=args.timeout,
                           preexec_fn=limit(args.mem_mb << 20))
        rc, err = p.returncode, p.stderr.decode("utf-8", "replace")
    except subprocess.TimeoutExpired:
        rc, err = None, ""
    outcome = classify(rc, err)
    if outcome in ("ok", "error"):
        shutil.rmtree(case, ignore_errors=True)
        return outcome, None
    keep = Path(args.out) / "defects" / f"{index:05d}-{outcome}-{cmd_name}{seed.suffix.lower()}"
    keep.mkdir(parents=True, exist_ok=True)
    shutil.copy(inp, keep / inp.name)
    (keep / "what.txt").write_text(f"seed file: {seed}\ncommand: {' '.join(cmd)}\nexit: {rc}\n"
                                   f"stderr (end):\n{err[-3000:]}\n")
    shutil.rmtree(case, ignore_errors=True)
    return outcome, f"{keep.name}: {err.strip().splitlines()[-1][:150] if err.strip() else rc}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=4800)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--seed", default="1")
    ap.add_argument("--timeout", type=float, default=10.0)
    ap.add_argument("--mem-mb", type=int, default=4096)
    ap.add_argument("--out", default="/tmp/crease-mutation-fuzz")
    ap.add_argument("--max-seed-bytes", type=int, default=MAX_SEED_BYTES,
                    help="real files larger than this are not used as seeds")
    ap.add_argument("--crease", default=str(ROOT / "target" / "release" / "crease"))
    args = ap.parse_args()
    Path(args.out).mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="mfuzz-"))
    seeds = make_seeds(args.crease, work, args.max_seed_bytes)
    print(f"{len(seeds)} seed files, {args.runs} runs", flush=True)
    counts = {}
    with cf.ThreadPoolExecutor(args.jobs) as pool:
        futures = [pool.submit(one, args, args.crease, seeds, work, i) for i in range(args.runs)]
        for f in cf.as_completed(futures):
            outcome, line = f.result()
            counts[outcome] = counts.get(outcome, 0) + 1
            if line:
                print(line, flush=True)
    shutil.rmtree(work, ignore_errors=True)
    print(" ".join(f"{k} {v}" for k, v in sorted(counts.items())))
    defects = sum(v for k, v in counts.items() if k not in ("ok", "error"))
    sys.exit(1 if defects else 0)


if __name__ == "__main__":
    main()
