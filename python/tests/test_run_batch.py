"""crease.run against `crease run`, the in-process command line (crease.command and the `crease`
console command) and crease.batch, on a local process pool and on a dask LocalCluster of two
worker processes: every output equal byte for byte to the CLI binary's on the same file, failed
files reported with the CLI's message, reruns resumed."""

import filecmp
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import crease
from conftest import _find_cli, read_ascii_ply, read_obj


# --- crease.run --------------------------------------------------------------------------------


def test_run_cloud_equal_cli(data, cli, tmp_path):
    cli("run", data / "fcc.ply", "-o", tmp_path / "out", "--ascii", "--no-picture")
    r = crease.run(crease.read(data / "fcc.ply"), name="fcc")
    v = read_ascii_ply(tmp_path / "out" / "labels.ply")["vertex"]
    assert not r.mesh and r.analysis == {"neighbours": 1, "normals": 1, "noise": 1, "segmentations": 1}
    assert np.array_equal(r.sharp, v["sharp"].astype(bool)) and r.sharp.sum() > 50
    assert np.array_equal(r.sharpness.astype(np.float32), v["sharpness"])
    assert np.array_equal(r.labels, v["surface"]) and np.array_equal(r.types, v["surface_type"])
    assert np.array_equal(r.fillet_label, v["fillet_label"])
    assert np.array_equal(r.smooth_edge, v["smooth_edge"].astype(bool))
    verts, lines, groups = read_obj(tmp_path / "out" / "network.obj")
    assert r.polyline_groups == groups and {"sharp", "smooth"} <= set(groups)
    for line, idx, expected in zip(r.polylines, r.polyline_indices, lines):
        assert list(idx) == expected and np.allclose(line, verts[expected], rtol=0, atol=1e-12)
    surfaces = json.loads((tmp_path / "out" / "surfaces.json").read_text())["surfaces"]
    assert r.surfaces == surfaces and len(surfaces) >= 5
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["sharp_points"] == r.sharp.sum() and summary["surfaces"] == len(r.surfaces)
    if r.step is None:
        assert "error" in r.brep and "error" in summary["brep"]
    else:
        assert r.step == (tmp_path / "out" / "part.step").read_text()


def test_run_mesh_equal_cli(data, cli, tmp_path):
    cli("run", data / "cube_mesh.ply", "-o", tmp_path / "out", "--ascii", "--no-picture")
    m = crease.read(data / "cube_mesh.ply")
    r = crease.run(m.points, faces=m.faces, name="cube_mesh")
    ply = read_ascii_ply(tmp_path / "out" / "labels.ply")
    e = ply["edge"]
    assert r.mesh and np.array_equal(r.edges, np.stack([e["vertex1"], e["vertex2"]], axis=1))
    assert np.array_equal(r.sharp, e["sharp"].astype(bool))
    assert np.array_equal(r.labels, ply["face"]["surface"]) and len(r.surfaces) == 6
    assert r.brep["solid"] and r.brep["faces"] == 6
    assert r.step == (tmp_path / "out" / "part.step").read_text()
    assert set(r.polyline_groups) == {"sharp"}


# --- the CLI in-process ------------------------------------------------------------------------


def test_command_writes_what_the_binary_writes(data, cli, tmp_path):
    cli("sharp", data / "cube.ply", "-o", tmp_path / "bin.ply")
    crease.command(["-q", "sharp", str(data / "cube.ply"), "-o", str(tmp_path / "py.ply")])
    assert filecmp.cmp(tmp_path / "bin.ply", tmp_path / "py.ply", shallow=False)


def test_command_errors_carry_the_cli_message_and_code(tmp_path):
    with pytest.raises(crease.CommandError) as e:
        crease.command(["sharp", str(tmp_path / "missing.ply"), "-o", str(tmp_path / "o.ply")])
    assert e.value.code == 1 and "missing.ply" in e.value.message
    with pytest.raises(crease.CommandError) as e:
        crease.command(["sharp", "--no-such-option"])
    assert e.value.code == 2


def test_console_command(data, tmp_path):
    exe = Path(sys.executable).parent / "crease"
    if not exe.exists():
        pytest.skip("the package's console command is not installed beside this interpreter")
    r = subprocess.run([str(exe), "--version"], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.startswith("crease ")
    r = subprocess.run([str(exe), "info", str(tmp_path / "none.ply")], capture_output=True, text=True)
    assert r.returncode == 1 and r.stderr.startswith("error: ") and "none.ply" in r.stderr
    r = subprocess.run([str(exe), "-q", "sharp", str(data / "cube.ply"), "-o", str(tmp_path / "c.ply")])
    assert r.returncode == 0
    subprocess.run([str(_find_cli()), "-q", "sharp", str(data / "cube.ply"), "-o", str(tmp_path / "b.ply")],
                   check=True)
    assert filecmp.cmp(tmp_path / "b.ply", tmp_path / "c.ply", shallow=False)


# --- crease.batch ------------------------------------------------------------------------------


@pytest.fixture()
def inputs(data, tmp_path):
    """Two good clouds and one broken file, in a folder of their own."""
    d = tmp_path / "in"
    d.mkdir()
    for name in ("cube.ply", "rounded.ply"):
        shutil.copy(data / name, d / name)
    (d / "broken.ply").write_text("ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n")
    return [d / "cube.ply", d / "broken.ply", d / "rounded.ply"]


def _check_batch(report, inputs, out, cli, tmp_path, task, ext, *options):
    assert [d[0] for d in report.done] == [str(inputs[0]), str(inputs[2])]
    assert len(report.failed) == 1 and report.failed[0][0] == str(inputs[1])
    assert "broken.ply" in report.failed[0][1]  # the CLI's message names the file
    assert not (out / f"broken{ext}").exists()
    for p in (inputs[0], inputs[2]):
        ref = tmp_path / f"ref-{p.stem}{ext}"
        cli(task, p, "-o", ref, *options)
        assert filecmp.cmp(ref, out / f"{p.stem}{ext}", shallow=False)


def test_batch_local_pool_resumes(inputs, cli, tmp_path):
    out = tmp_path / "out"
    report = crease.batch(inputs, "network", out, workers=2, progress=False, k=16)
    _check_batch(report, inputs, out, cli, tmp_path, "network", ".obj", "-k", "16")
    # A rerun skips what is done and retries what failed.
    again = crease.batch(inputs, "network", out, workers=2, progress=False, k=16)
    assert again.skipped == [str(inputs[0]), str(inputs[2])] and len(again.failed) == 1
    assert not again.done
    # An input newer than its output is redone.
    t = os.stat(out / "cube.obj").st_mtime
    os.utime(inputs[0], (t + 10, t + 10))
    third = crease.batch(inputs, "network", out, workers=1, progress=False, k=16)
    assert [d[0] for d in third.done] == [str(inputs[0])] and third.skipped == [str(inputs[2])]


def test_batch_run_and_segment_outputs(inputs, tmp_path):
    out = tmp_path / "out"
    report = crease.batch(inputs[:1], "run", out, progress=False, no_picture=True)
    assert report.ok and len(report.done) == 1
    summary = json.loads((out / "cube" / "summary.json").read_text())
    assert summary["surfaces"] == 6 and summary["analysis"]["segmentations"] == 1
    seg = crease.batch(inputs[:1], "segment", out, progress=False)
    assert seg.ok and len(json.loads((out / "cube.json").read_text())["surfaces"]) == 6


def test_batch_refuses_clashing_names_and_unknown_tasks(data, tmp_path):
    (tmp_path / "a").mkdir()
    shutil.copy(data / "cube.ply", tmp_path / "a" / "cube.ply")
    with pytest.raises(ValueError, match="both write"):
        crease.batch([data / "cube.ply", tmp_path / "a" / "cube.ply"], "sharp", tmp_path / "o")
    with pytest.raises(ValueError, match="unknown task"):
        crease.batch([data / "cube.ply"], "nope", tmp_path / "o")
    assert crease._batch.cli_options({"k": 8, "region_angle": 4.5, "orient": True, "surfaces": False,
                                      "scales": [12, 16], "x": None}) == [
        "-k", "8", "--region-angle", "4.5", "--orient", "--no-surfaces", "--scales", "12,16"]


def test_batch_on_a_dask_local_cluster(inputs, cli, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        assert len(client.scheduler_info()["workers"]) == 2
        out = tmp_path / "out"
        report = crease.batch(inputs, "sharp", out, client=client, progress=False, surfaces=False)
        _check_batch(report, inputs, out, cli, tmp_path, "sharp", ".ply", "--no-surfaces")
        again = crease.batch(inputs, "sharp", out, client=client, progress=False, surfaces=False)
        assert len(again.skipped) == 2 and not again.done
