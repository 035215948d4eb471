"""Each function against the CLI command it mirrors, on the same file: the same answers bit for
bit (where the CLI's file stores a value as float32, the module's float64 value rounded to
float32 equals it, and its --json summaries give the full float64 values)."""

import json

import numpy as np
import pytest

import crease
from conftest import no_times, read_ascii_ply, read_obj, read_xyz


@pytest.fixture(scope="module")
def cube(data):
    return crease.read(data / "cube.ply")


@pytest.fixture(scope="module")
def fcc(data):
    return crease.read(data / "fcc.ply")


@pytest.fixture(scope="module")
def cube_mesh(data):
    return crease.read(data / "cube_mesh.ply")


# --- normals -----------------------------------------------------------------------------------


@pytest.mark.parametrize("extra", [[], ["-k", "12"], ["--orient"], ["--method", "ring"]])
def test_normals_equal_cli(data, cube, cli, tmp_path, extra):
    cli("normals", data / "cube.ply", "-o", tmp_path / "n.xyz", *extra)
    expected = read_xyz(tmp_path / "n.xyz")[:, 3:6]  # full float64 text
    kw = {}
    if "-k" in extra:
        kw["k"] = 12
    if "--orient" in extra:
        kw["orient"] = True
    if "--method" in extra:
        kw["method"] = "ring"
    n = crease.normals(cube.points, **kw)
    assert n.dtype == np.float64 and n.shape == (5000, 3)
    assert np.array_equal(n, expected)


def test_normals_mesh_and_analytic(data, cube_mesh, cli, tmp_path):
    cli("normals", data / "cube_mesh.ply", "-o", tmp_path / "m.xyz", "--method", "mesh")
    n = crease.normals(cube_mesh.points, method="mesh", faces=cube_mesh.faces)
    assert np.array_equal(n, read_xyz(tmp_path / "m.xyz")[:, 3:6])
    # Analytic: PCA normals of a sampled plane are +-z exactly up to round-off.
    rng = np.random.default_rng(0)
    plane = np.column_stack([rng.random(2000), rng.random(2000), np.zeros(2000)])
    pn = crease.normals(plane)
    assert np.allclose(np.abs(pn[:, 2]), 1.0, atol=1e-12)


# --- sharp -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "extra,kw",
    [
        ([], {}),
        (["--no-surfaces"], {"surfaces": False}),
        (["--method", "surface-variation", "--scales", "10,20"], {"method": "surface-variation", "scales": [10, 20]}),
    ],
)
def test_sharp_equal_cli(data, cube, cli, tmp_path, extra, kw):
    summary = cli("sharp", data / "cube.ply", "-o", tmp_path / "s.ply", "--ascii", *extra, json_out=True)
    ply = read_ascii_ply(tmp_path / "s.ply")["vertex"]
    r = crease.sharp(cube.points, **kw)
    assert r.sharp.dtype == np.bool_ and r.sharpness.dtype == np.float64
    assert np.array_equal(r.sharp, ply["sharp"].astype(bool))
    assert r.sharp.sum() == summary["sharp"] > 0
    # The file stores sharpness as float32: the module's value rounds to exactly it.
    assert np.array_equal(r.sharpness.astype(np.float32), ply["sharpness"])
    # The per-scale thresholds, full float64 in the CLI's JSON.
    assert r.scales == summary["scales"]
    assert r.noise_ratio == summary["noise_ratio"]
    assert no_times(r.surfaces) == no_times(summary["surfaces"])
    assert r.regularized == summary["regularized"]
    if not kw:
        # sharpness >= 1 for every sharp point (thinning may leave some >= 1 unmarked).
        assert np.all(r.sharpness[r.sharp] >= 1.0)


def test_sharp_on_cube_edges(cube):
    """Analytic: the sharp points of the unit cube lie on its 12 edges (two coordinates at
    +-0.5), within a few spacings."""
    r = crease.sharp(cube.points)
    p = cube.points[r.sharp]
    near = np.sort(0.5 - np.abs(p), axis=1)[:, 1]  # the second-smallest distance to a face
    assert len(p) > 100
    assert np.all(near < 0.06)
    # Against the synthetic ground truth: most ground-truth sharp points are found.
    gt = cube.attributes["gt_sharp"].astype(bool)
    assert (r.sharp & gt).sum() > 0.6 * r.sharp.sum()


def test_sharp_mesh_equal_cli(data, cube_mesh, cli, tmp_path):
    cli("sharp", data / "cube_mesh.ply", "-o", tmp_path / "s.ply", "--ascii")
    ply = read_ascii_ply(tmp_path / "s.ply")["vertex"]
    r = crease.sharp(cube_mesh)  # a Geometry with faces: the mesh path, as the CLI on the file
    assert r.mesh
    assert np.array_equal(r.sharp, ply["sharp"].astype(bool))
    assert np.array_equal(r.sharpness.astype(np.float32), ply["sharpness"])


# --- segment -----------------------------------------------------------------------------------


def test_segment_cloud_equal_cli(data, cube, cli, tmp_path):
    cli("segment", data / "cube.ply", "-o", tmp_path / "seg.ply", "--ascii", "--primitives", tmp_path / "p.json")
    ply = read_ascii_ply(tmp_path / "seg.ply")["vertex"]
    prims = json.loads((tmp_path / "p.json").read_text())
    r = crease.segment(cube)  # the file's normals are used, as the CLI uses them
    assert r.normals_source == "given"
    assert r.labels.dtype == np.int32 and np.array_equal(r.labels, ply["surface"])
    assert np.array_equal(r.types, ply["surface_type"])
    assert r.surfaces == prims["surfaces"]  # every parameter, full float64
    assert r.groups == prims["groups"]
    assert r.mean_edge == prims["mean_edge"] and r.epsilon == prims["epsilon"]
    # Analytic: the cube is 6 planes with offsets +-0.5 and axis-aligned normals.
    assert [s["type"] for s in r.surfaces] == ["plane"] * 6
    for s in r.surfaces:
        nrm = np.abs(s["params"]["normal"])
        assert np.isclose(nrm.max(), 1.0, atol=1e-9) and np.isclose(abs(s["params"]["offset"]), 0.5, atol=1e-6)
    assert sum(s["vertices"] for s in r.surfaces) == (r.labels >= 0).sum()


def test_segment_estimated_normals_equal_cli(data, cube, cli, tmp_path):
    cli("segment", data / "cube.ply", "-o", tmp_path / "seg.ply", "--ascii", "--estimate-normals",
        "--primitives", tmp_path / "p.json")
    ply = read_ascii_ply(tmp_path / "seg.ply")["vertex"]
    r = crease.segment(cube.points)  # bare points: normals estimated
    assert r.normals_source == "estimated"
    assert np.array_equal(r.labels, ply["surface"])
    assert r.surfaces == json.loads((tmp_path / "p.json").read_text())["surfaces"]


def test_segment_mesh_equal_cli(data, cli, tmp_path):
    cli("segment", data / "fcc_mesh.ply", "-o", tmp_path / "seg.ply", "--ascii", "--primitives", tmp_path / "p.json")
    ply = read_ascii_ply(tmp_path / "seg.ply")
    g = crease.read(data / "fcc_mesh.ply")
    r = crease.segment(g.points, faces=g.faces)
    assert r.mesh and len(r.labels) == len(g.faces)
    assert np.array_equal(r.labels, ply["face"]["surface"])
    assert np.array_equal(r.types, ply["face"]["surface_type"])
    assert r.surfaces == json.loads((tmp_path / "p.json").read_text())["surfaces"]
    assert {"plane", "cylinder", "cone"} <= {s["type"] for s in r.surfaces}


# --- lines, fillets, network -------------------------------------------------------------------


def _same_polylines(curves, obj_path):
    verts, lines, groups = read_obj(obj_path)
    assert len(curves.polylines) == len(lines) > 0
    assert np.array_equal(curves.vertices, verts)
    for poly, idx, l in zip(curves.polylines, curves.indices, lines):
        assert poly.dtype == np.float64 and poly.shape == (len(l), 3)
        assert list(idx) == l
        assert np.array_equal(poly, verts[l])
    return groups


def test_lines_equal_cli(data, cube, cli, tmp_path):
    summary = cli("lines", data / "cube.ply", "-o", tmp_path / "l.obj", json_out=True)
    r = crease.lines(cube.points)
    _same_polylines(r, tmp_path / "l.obj")
    assert r.groups == ["sharp"] * len(r.polylines)
    for key in ("clusters", "closed_loops", "junctions", "endpoints", "polylines", "close", "n", "d"):
        assert no_times(r.summary[key]) == no_times(summary[key]), key
    # Analytic: the cube's network: 12 edges closed into loops meeting at 8 corners.
    assert summary["junctions"] == 8 and summary["endpoints"] == 0


def test_network_equal_cli(data, fcc, cli, tmp_path):
    summary = cli("network", data / "fcc.ply", "-o", tmp_path / "n.obj", "--labels", tmp_path / "lab.ply",
                  "--ascii", json_out=True)
    r = crease.network(fcc.points)
    groups = _same_polylines(r, tmp_path / "n.obj")
    assert r.groups == groups and {"sharp", "smooth"} <= set(groups)
    assert r.summary["network"] == summary["network"]
    lab = read_ascii_ply(tmp_path / "lab.ply")["vertex"]
    assert np.array_equal(r.fillet_label, lab["fillet_label"])
    assert np.array_equal(r.smooth_edge, lab["smooth_edge"].astype(bool))
    assert np.array_equal(r.region, lab["region"])
    # NaN outside the smooth regions, in both.
    assert np.array_equal(r.mean_curvature.astype(np.float32), lab["mean_curvature"], equal_nan=True)
    assert np.isfinite(r.mean_curvature[r.region >= 0]).all()


def test_fillets_equal_cli(data, fcc, cli, tmp_path):
    cli("fillets", data / "fcc.ply", "-o", tmp_path / "f.obj")
    r = crease.fillets(fcc.points)
    _same_polylines(r, tmp_path / "f.obj")
    assert set(r.groups) == {"smooth"}


# --- edges -------------------------------------------------------------------------------------


@pytest.mark.parametrize("method", ["fused", "dihedral"])
def test_edges_equal_cli(data, cube_mesh, cli, tmp_path, method):
    summary = cli("edges", data / "cube_mesh.ply", "-o", tmp_path / "e.ply", "--ascii", "--method", method,
                  "--lines", tmp_path / "e.obj", json_out=True)
    e = read_ascii_ply(tmp_path / "e.ply")["edge"]
    r = crease.edges(cube_mesh.points, cube_mesh.faces, method=method)
    assert r.edges.dtype == np.int64 and r.edges.shape == (summary["edges"], 2)
    assert np.array_equal(r.edges[:, 0], e["vertex1"]) and np.array_equal(r.edges[:, 1], e["vertex2"])
    assert np.array_equal(r.sharp, e["sharp"].astype(bool))
    assert np.array_equal(r.sharpness.astype(np.float32), e["sharpness"])
    _, lines, _ = read_obj(tmp_path / "e.obj")
    assert [list(l) for l in r.lines] == lines
    # Analytic: the cube's 12 edges, each edge of the mesh on two faces at 90 degrees.
    ends = cube_mesh.points[r.edges[r.sharp]]
    on_two_faces = (np.abs(np.abs(ends) - 0.5) < 1e-9).sum(axis=2) >= 2
    assert on_two_faces.all() and r.sharp.sum() == summary["sharp_edges"] > 0


# --- reconstruct -------------------------------------------------------------------------------


def test_reconstruct_mesh_equal_cli(data, cube_mesh, cli, tmp_path):
    summary = cli("reconstruct", data / "cube_mesh.ply", "-o", tmp_path / "cube_mesh.step", json_out=True)
    out = tmp_path / "py.step"
    r = crease.reconstruct(cube_mesh.points, faces=cube_mesh.faces, out=out, name="cube_mesh")
    assert r.step == (tmp_path / "cube_mesh.step").read_text() == out.read_text()
    assert r.solid and summary["solid"] and r.faces == 6 == summary["faces"] and r.edges == summary["edges"] == 12
    assert no_times(r.report) == no_times(summary["report"]) and r.uncertainty == summary["uncertainty"]


def test_reconstruct_cloud_equal_cli(data, cube, cli, tmp_path):
    summary = cli("reconstruct", data / "cube.ply", "-o", tmp_path / "c.step", json_out=True)
    r = crease.reconstruct(cube, out=tmp_path / "cube.step")  # name from out's stem: "cube"
    assert r.step == (tmp_path / "c.step").read_text()
    assert r.solid == summary["solid"] and r.faces == summary["faces"]


# --- curvature ---------------------------------------------------------------------------------


def _same_as_ply(values, column):
    """The module's float64 values rounded as the CLI's PLY column stores them."""
    return np.array_equal(values.astype(column.dtype), column, equal_nan=True)


@pytest.mark.parametrize("extra", [[], ["-k", "12"], ["--use-normals"]])
def test_curvature_equal_cli(data, cube, cli, tmp_path, extra):
    cli("curvature", data / "cube.ply", "-o", tmp_path / "c.ply", "--ascii", *extra)
    v = read_ascii_ply(tmp_path / "c.ply")["vertex"]
    kw = {}
    if "-k" in extra:
        kw["k"] = 12
    if "--use-normals" in extra:
        kw["use_normals"] = True
    c = crease.curvature(cube, **kw)
    assert c.k1.dtype == np.float64 and c.k1.shape == (5000,) and c.sharp is None
    for name in ("k1", "k2", "mean_curvature", "gaussian_curvature"):
        assert _same_as_ply(c[name], v[name]), name


def test_curvature_bezier_equal_cli(data, cube_mesh, cli, tmp_path):
    cli("curvature", data / "cube_mesh.ply", "-o", tmp_path / "b.ply", "--ascii", "--method", "bezier")
    v = read_ascii_ply(tmp_path / "b.ply")["vertex"]
    c = crease.curvature(cube_mesh.points, method="bezier", faces=cube_mesh.faces)
    assert _same_as_ply(c.mean_curvature, v["mean_curvature"])
    assert np.array_equal(c.sharp, v["sharp"].astype(bool))
    assert c.sharp.any()  # the cube's edges


def test_curvature_of_a_sphere_and_of_repeated_points():
    """Analytic: points on a sphere of radius 2 have principal curvatures 1/2; a cloud whose
    points each appear twice gets the same answer on both copies."""
    rng = np.random.default_rng(5)
    v = rng.normal(size=(4000, 3))
    p = 2.0 * v / np.linalg.norm(v, axis=1, keepdims=True)
    c = crease.curvature(p)
    assert c.failed == 0
    assert np.allclose(c.k1, 0.5, atol=0.01) and np.allclose(c.k2, 0.5, atol=0.01)
    signed = crease.curvature(p, use_normals=True, normals=p / 2.0)  # outward normals
    assert np.allclose(signed.mean_curvature, 0.5, atol=0.01)
    twice = crease.curvature(np.concatenate([p, p[::-1]]))
    assert np.array_equal(twice.k1[:4000], c.k1) and np.array_equal(twice.k1[4000:], c.k1[::-1])
    with pytest.raises(ValueError, match="no normals"):
        crease.curvature(p, use_normals=True)
    with pytest.raises(ValueError, match="at least 5"):
        crease.curvature(p, k=3)
