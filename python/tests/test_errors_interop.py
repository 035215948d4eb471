"""Exceptions on bad input (the CLI's messages where the library gives them), the GIL released
while Rust computes, and Open3D / trimesh objects accepted where arrays are."""

import threading
import time

import numpy as np
import pytest

import crease
from conftest import cli_error


def _few_points(tmp_path, n=15):
    rng = np.random.default_rng(3)
    p = rng.random((n, 3))
    crease.write(tmp_path / "few.ply", p)
    return p, tmp_path / "few.ply"


def test_too_few_points_same_message_as_cli(tmp_path, cli):
    p, f = _few_points(tmp_path)
    for cmd, fn in (("sharp", crease.sharp), ("lines", crease.lines), ("network", crease.network)):
        out = tmp_path / ("o.obj" if cmd != "sharp" else "o.ply")
        msg, code = cli_error(cli, cmd, f, "-o", out)
        assert code == 1
        with pytest.raises(ValueError) as e:
            fn(p)
        assert f"{f}: {e.value}" == msg, cmd


def test_coincident_points_same_message_as_cli(tmp_path, cli):
    p = np.ones((50, 3))
    crease.write(tmp_path / "same.ply", p)
    msg, _ = cli_error(cli, "segment", tmp_path / "same.ply", "-o", tmp_path / "s.ply")
    with pytest.raises(ValueError) as e:
        crease.segment(p)
    assert f"{tmp_path / 'same.ply'}: {e.value}" == msg


@pytest.mark.parametrize("fn", [crease.sharp, crease.normals, crease.segment, crease.lines, crease.network])
def test_bad_arrays(fn):
    good = np.random.default_rng(0).random((100, 3))
    bad = good.copy()
    bad[7, 1] = np.nan
    with pytest.raises(ValueError, match="row 7 has a NaN"):
        fn(bad)
    bad[7, 1] = np.inf
    with pytest.raises(ValueError, match="row 7 has a NaN or infinite"):
        fn(bad)
    with pytest.raises(ValueError, match=r"expected an \(n, 3\) array, got shape \(100, 2\)"):
        fn(good[:, :2])
    with pytest.raises(ValueError, match=r"got shape \(300,\)"):
        fn(good.ravel())
    with pytest.raises(ValueError, match="dtype"):
        fn(np.array([["a", "b", "c"]]))


def test_bad_parameters():
    p = np.random.default_rng(0).random((200, 3))
    with pytest.raises(ValueError, match="k must be at least 1"):
        crease.normals(p, k=0)
    with pytest.raises(ValueError, match="method must be one of"):
        crease.sharp(p, method="magic")
    with pytest.raises(ValueError, match=r"manual sharpness threshold must be in \(0, 1\]"):
        crease.sharp(p, threshold=2.0)
    with pytest.raises(ValueError, match="no faces"):
        crease.edges(p)
    with pytest.raises(ValueError, match="refers to vertex 200"):
        crease.edges(p, [[0, 1, 200]])
    with pytest.raises(ValueError, match="STEP"):
        crease.reconstruct(p, out="part.ply")
    with pytest.raises(ValueError, match="thresholds must be"):
        crease.network(p, thresholds="many")


def test_gil_released(data):
    """While sharp() computes in Rust, another Python thread keeps running."""
    g = crease.read(data / "cube.ply")
    p = np.concatenate([g.points + [2.0 * i, 0, 0] for i in range(8)])  # 40k points
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    time.sleep(0.01)
    start = time.perf_counter()
    r = crease.sharp(p)
    end = time.perf_counter()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < end]
    assert r.seconds > 0.05
    assert len(during) >= 10, (len(during), end - start)


def test_open3d_objects(data):
    o3d = pytest.importorskip("open3d")
    g = crease.read(data / "cube.ply")
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(g.points))
    assert np.array_equal(crease.sharp(pcd).sharp, crease.sharp(g.points).sharp)
    pcd.normals = o3d.utility.Vector3dVector(g.normals)
    assert np.array_equal(crease.segment(pcd).labels, crease.segment(g).labels)
    m = crease.read(data / "cube_mesh.ply")
    tm = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(m.points), o3d.utility.Vector3iVector(m.faces))
    assert np.array_equal(crease.edges(tm).sharp, crease.edges(m.points, m.faces).sharp)


def test_trimesh_objects(data):
    trimesh = pytest.importorskip("trimesh")
    m = crease.read(data / "cube_mesh.ply")
    tm = trimesh.Trimesh(vertices=m.points, faces=m.faces, process=False)
    assert np.array_equal(crease.edges(tm).sharp, crease.edges(m.points, m.faces).sharp)
    assert np.array_equal(crease.segment(tm).labels, crease.segment(m.points, faces=m.faces).labels)
    g = crease.read(data / "cube.ply")
    pc = trimesh.PointCloud(g.points)
    assert np.array_equal(crease.sharp(pc).sharpness, crease.sharp(g.points).sharpness)


def test_duck_typed_without_packages(data):
    """The duck typing itself, with stand-ins shaped like Open3D's and trimesh's objects (so that
    it is tested even where neither package is installed)."""
    g = crease.read(data / "cube.ply")
    m = crease.read(data / "cube_mesh.ply")

    class O3dCloud:
        def __init__(self, p, n):
            self.points, self.normals = p, n

        def has_normals(self):
            return self.normals is not None

    class O3dMesh:
        def __init__(self, v, t):
            self.vertices, self.triangles = v, t

    class TriMesh:
        def __init__(self, v, f):
            self.vertices, self.faces = v, f

    ref = crease.segment(g)
    assert np.array_equal(crease.segment(O3dCloud(list(map(tuple, g.points)), g.normals)).labels, ref.labels)
    ref_e = crease.edges(m.points, m.faces)
    assert np.array_equal(crease.edges(O3dMesh(m.points, m.faces.astype(np.int32))).sharp, ref_e.sharp)
    assert np.array_equal(crease.edges(TriMesh(m.points, m.faces)).sharpness, ref_e.sharpness)
