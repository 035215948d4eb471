"""Shared fixtures: the `crease` CLI built from this repository (or $CREASE_BIN), small inputs it
synthesises, and parsers of its text outputs that do not go through crease's own readers (ascii
PLY, OBJ, XYZ), so that the CLI's answers and the module's are compared independently."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
BAD_INPUT = REPO / "crates" / "crease" / "tests" / "bad_input"


def _find_cli() -> Path:
    env = os.environ.get("CREASE_BIN")
    if env:
        return Path(env)
    for p in (REPO / "target" / "release" / "crease", shutil.which("crease")):
        if p and Path(p).is_file():
            return Path(p)
    raise RuntimeError(
        "the crease CLI is needed to compare against: `cargo build --release -p crease-cli` "
        "or set CREASE_BIN"
    )


@pytest.fixture(scope="session")
def cli():
    """Runs the CLI: cli(args..., json=True) -> parsed --json summary; check=False returns the
    CompletedProcess."""
    exe = _find_cli()

    def run(*args, json_out=False, check=True):
        cmd = [str(exe), "-q"] + (["--json"] if json_out else []) + [str(a) for a in args]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if not check:
            return r
        if r.returncode != 0:
            raise AssertionError(f"{' '.join(cmd)} failed ({r.returncode}): {r.stderr}")
        return json.loads(r.stdout) if json_out else r

    return run


@pytest.fixture(scope="session")
def data(tmp_path_factory, cli):
    """Small inputs made by `crease synth` (exact ground truth), shared by every test."""
    d = tmp_path_factory.mktemp("data")
    cli("synth", "cube", "-n", 5000, "-o", d / "cube.ply")
    cli("synth", "rounded-cube", "-n", 5000, "-o", d / "rounded.ply")
    cli("synth", "fillet-chamfer-cone", "-n", 5000, "-o", d / "fcc.ply")
    cli("synth", "cube", "--mesh", "-n", 3000, "-o", d / "cube_mesh.ply")
    cli("synth", "fillet-chamfer-cone", "--mesh", "-n", 3000, "-o", d / "fcc_mesh.ply")
    return d


def read_ascii_ply(path):
    """{element: {property: np.array}} of an ascii PLY (scalar properties; a list property is
    returned as a list of lists), parsed here without crease."""
    lines = Path(path).read_text().splitlines()
    assert lines[0] == "ply" and lines[1].startswith("format ascii"), lines[:2]
    elements = []
    i = 2
    while lines[i] != "end_header":
        t = lines[i].split()
        if t[0] == "element":
            elements.append((t[1], int(t[2]), []))
        elif t[0] == "property":
            if t[1] == "list":
                elements[-1][2].append((t[4], "list", t[3]))
            else:
                elements[-1][2].append((t[2], "scalar", t[1]))
        i += 1
    i += 1
    out = {}
    for name, count, props in elements:
        cols = {p[0]: [] for p in props}
        for row in lines[i : i + count]:
            tok = row.split()
            j = 0
            for pname, kind, typ in props:
                if kind == "list":
                    m = int(tok[j])
                    cols[pname].append([int(x) for x in tok[j + 1 : j + 1 + m]])
                    j += 1 + m
                else:
                    cols[pname].append(tok[j])
                    j += 1
        i += count
        res = {}
        for pname, kind, typ in props:
            if kind == "list":
                res[pname] = cols[pname]
            elif typ in ("float", "float32"):
                res[pname] = np.array([np.float32(x) for x in cols[pname]], dtype=np.float32)
            elif typ in ("double", "float64"):
                res[pname] = np.array([float(x) for x in cols[pname]], dtype=np.float64)
            else:
                res[pname] = np.array([int(x) for x in cols[pname]], dtype=np.int64)
        out[name] = res
    return out


def read_obj(path):
    """(vertices (v, 3) float64, polylines as lists of 0-based indices, group per polyline)."""
    verts, lines, groups = [], [], []
    group = ""
    for row in Path(path).read_text().splitlines():
        t = row.split()
        if not t:
            continue
        if t[0] == "v":
            verts.append([float(x) for x in t[1:4]])
        elif t[0] == "g":
            group = t[1] if len(t) > 1 else ""
        elif t[0] == "l":
            lines.append([int(x) - 1 for x in t[1:]])
            groups.append(group)
    return np.array(verts, dtype=np.float64).reshape(-1, 3), lines, groups


def read_xyz(path):
    """The rows of a text point file as float64 (Python's float parsing, not crease's)."""
    rows = [[float(x) for x in r.split()] for r in Path(path).read_text().splitlines() if r.strip()]
    return np.array(rows, dtype=np.float64)


def cli_error(cli, *args):
    """The message the CLI prints after `error: ` (and its exit code) for a failing command."""
    r = cli(*args, check=False)
    assert r.returncode != 0, f"expected {args} to fail"
    msg = r.stderr.strip().splitlines()[-1]
    assert msg.startswith("error: "), r.stderr
    return msg[len("error: ") :], r.returncode


def no_times(obj):
    """`obj` (a JSON-like summary) without its timings, which differ between two runs."""
    if isinstance(obj, dict):
        return {
            k: no_times(v)
            for k, v in obj.items()
            if not any(w in k for w in ("second", "timing", "time"))
        }
    if isinstance(obj, list):
        return [no_times(v) for v in obj]
    return obj
