"""crease.tiled_sharp: a 2M-point cloud cut into tiles gives the sharp labels of one run over the
whole cloud (the halo rule of crease::sharp::tiled: exact for tran's detector on a clean cloud),
on a local process pool; a LAS file (streamed when cut) on a dask LocalCluster with the surface
stage, which is solved per tile and measured."""

import numpy as np
import pytest

import crease


def box_cloud(n, seed):
    """n points on the surface of a 3 x 2 x 1 box (uniform by area) with a 0.4-radius
    cylindrical boss on top: sharp edges along the box and the boss' rims."""
    rng = np.random.default_rng(seed)
    dims = np.array([3.0, 2.0, 1.0])
    faces = []
    for axis in range(3):
        u, v = [a for a in range(3) if a != axis]
        for side in (0.0, 1.0):
            faces.append((axis, u, v, side, dims[u] * dims[v]))
    boss_side = 2 * np.pi * 0.4 * 0.5
    areas = np.array([f[4] for f in faces] + [boss_side, np.pi * 0.4**2])
    counts = rng.multinomial(n, areas / areas.sum())
    parts = []
    for (axis, u, v, side, _), m in zip(faces, counts):
        p = np.empty((m, 3))
        p[:, axis] = side * dims[axis]
        p[:, u] = rng.random(m) * dims[u]
        p[:, v] = rng.random(m) * dims[v]
        if axis == 2 and side == 1.0:
            # The top face minus the boss' footprint (those points go to its top instead).
            inside = (p[:, 0] - 1.5) ** 2 + (p[:, 1] - 1.0) ** 2 < 0.16
            p[inside, 2] += 0.5
        parts.append(p)
    m = counts[-2]
    t = rng.random(m) * 2 * np.pi
    parts.append(np.stack([1.5 + 0.4 * np.cos(t), 1.0 + 0.4 * np.sin(t), 1.0 + 0.5 * rng.random(m)], axis=1))
    m = counts[-1]
    r = 0.4 * np.sqrt(rng.random(m))
    t = rng.random(m) * 2 * np.pi
    parts.append(np.stack([1.5 + r * np.cos(t), 1.0 + r * np.sin(t), np.full(m, 1.5)], axis=1))
    p = np.concatenate(parts)
    return p[rng.permutation(len(p))]


def test_two_million_points_in_tiles_equal_the_whole_run(tmp_path):
    src = tmp_path / "box.ply"
    crease.write(src, box_cloud(2_000_000, 1))
    g = crease.read(src)
    whole = crease.sharp(g.points, surfaces=False)
    out = tmp_path / "tiled.ply"
    rep = crease.tiled_sharp(src, out, tile_size=0.8, surfaces=False, workers=2, progress=False)
    assert rep["tiles"] >= 12 and rep["points"] == 2_000_000
    r = crease.read(out)
    assert np.array_equal(r.points, g.points)  # input order
    assert rep["noise_ratio"] == whole.noise_ratio
    assert [t for t in rep["thresholds"]] == [s["threshold"] for s in whole.scales]
    assert whole.sharp.sum() > 5000
    assert np.array_equal(r.attributes["sharp"].astype(bool), whole.sharp)
    assert np.array_equal(r.attributes["sharpness"], whole.sharpness.astype(np.float32))
    # Nothing is left beside the output.
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.ply", "tiled.ply"]


def test_a_las_file_in_tiles_on_a_dask_cluster(tmp_path):
    distributed = pytest.importorskip("distributed")
    src = tmp_path / "box.las"
    crease.write(src, box_cloud(300_000, 2))
    g = crease.read(src)  # the LAS file's quantised coordinates
    whole = crease.sharp(g.points)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        rep = crease.tiled_sharp(src, tmp_path / "tiled.ply", tile_size=1.0, client=client, progress=False,
                                 work_dir=tmp_path / "tiles", keep_tiles=True)
    assert rep["tiles"] >= 6 and len(list((tmp_path / "tiles").glob("tile-*-*-*.ply"))) >= 12
    r = crease.read(tmp_path / "tiled.ply")
    assert np.array_equal(r.points, g.points)
    sharp = r.attributes["sharp"].astype(bool)
    differ = int((sharp != whole.sharp).sum())
    # The surface stage segments each tile: measured 0 differences here; a surface cut by a tile
    # may be fitted a little differently from the whole cloud's.
    assert differ <= 0.01 * whole.sharp.sum(), (differ, int(whole.sharp.sum()))


def test_bad_tiling_arguments(tmp_path):
    src = tmp_path / "box.ply"
    crease.write(src, box_cloud(20_000, 3))
    with pytest.raises(ValueError, match="larger tiles"):
        crease.tiled_sharp(src, tmp_path / "o.ply", tile_size=0.01, progress=False)
    with pytest.raises(ValueError, match="tile size"):
        crease.tiled_sharp(src, tmp_path / "o.ply", tile_size=-1.0, progress=False)
    with pytest.raises(FileNotFoundError):
        crease.tiled_sharp(tmp_path / "none.ply", tmp_path / "o.ply", tile_size=1.0, progress=False)
    assert not (tmp_path / "o.ply").exists()
