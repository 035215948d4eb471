"""crease.read / crease.write against the CLI's files and its own reading of them."""

import numpy as np
import pytest

import crease
from conftest import BAD_INPUT, cli_error, read_ascii_ply, read_xyz


def test_read_cloud_matches_cli_text(data, cli, tmp_path):
    g = crease.read(data / "cube.ply")
    # The CLI's conversion to text (shortest round-trip decimals), parsed by Python.
    cli("convert", data / "cube.ply", tmp_path / "cube.xyz")
    xyz = read_xyz(tmp_path / "cube.xyz")
    assert g.points.dtype == np.float64 and g.points.shape == (5000, 3)
    assert np.array_equal(g.points, xyz[:, :3])
    assert np.array_equal(g.normals, xyz[:, 3:6])
    assert g.faces is None and g.colors is None
    # Every attribute, in its storage type, against the CLI's ascii PLY.
    cli("convert", data / "cube.ply", tmp_path / "cube_ascii.ply", "--ascii")
    ply = read_ascii_ply(tmp_path / "cube_ascii.ply")["vertex"]
    assert list(g.attributes) == [k for k in ply if k not in ("x", "y", "z", "nx", "ny", "nz")]
    for name, values in g.attributes.items():
        assert values.dtype == ply[name].dtype or values.dtype.kind in "iu", name
        assert np.array_equal(values, ply[name]), name
    assert g.attributes["gt_sharp"].dtype == np.uint8
    assert g.attributes["gt_edge_distance"].dtype == np.float32
    assert g.report["dropped_nonfinite"] == 0


def test_read_mesh_faces(data, cli, tmp_path):
    g = crease.read(data / "cube_mesh.ply")
    info = cli("info", data / "cube_mesh.ply", json_out=True)
    cli("convert", data / "cube_mesh.ply", tmp_path / "m.ply", "--ascii")
    ply = read_ascii_ply(tmp_path / "m.ply")
    assert g.faces.dtype == np.int64 and g.faces.shape == (len(ply["face"]["vertex_indices"]), 3)
    assert np.array_equal(g.faces, np.array(ply["face"]["vertex_indices"]))
    assert len(g.points) == info["points"] and len(g.faces) == info["faces"]
    assert np.array_equal(g.face_attributes["gt_surface"], ply["face"]["gt_surface"])
    # A closed cube: Euler characteristic 2.
    e = {tuple(sorted(p)) for f in g.faces for p in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0]))}
    assert len(g.points) - len(e) + len(g.faces) == 2


@pytest.mark.parametrize("ascii", [False, True])
def test_write_round_trip(tmp_path, cli, ascii):
    rng = np.random.default_rng(1)
    p = rng.normal(size=(500, 3))
    n = p / np.linalg.norm(p, axis=1)[:, None]
    attrs = {
        "flag": rng.random(500) > 0.5,
        "label": rng.integers(-5, 100, 500).astype(np.int32),
        "value": rng.random(500),
        "single": rng.random(500).astype(np.float32),
    }
    crease.write(tmp_path / "w.ply", p, normals=n, attributes=attrs, ascii=ascii)
    g = crease.read(tmp_path / "w.ply")
    assert np.array_equal(g.points, p)  # positions are written as double
    assert np.array_equal(g.normals, n.astype(np.float32).astype(np.float64))  # normals as float
    assert g.attributes["flag"].dtype == np.uint8
    assert np.array_equal(g.attributes["flag"], attrs["flag"])
    assert g.attributes["label"].dtype == np.int32 and np.array_equal(g.attributes["label"], attrs["label"])
    assert g.attributes["value"].dtype == np.float64 and np.array_equal(g.attributes["value"], attrs["value"])
    assert np.array_equal(g.attributes["single"], attrs["single"])
    # The CLI reads what the module wrote.
    info = cli("info", tmp_path / "w.ply", json_out=True)
    assert info["points"] == 500
    cli("convert", tmp_path / "w.ply", tmp_path / "w.xyz")
    assert np.array_equal(read_xyz(tmp_path / "w.xyz")[:, :3], p)


def test_write_mesh_and_geometry(data, tmp_path):
    g = crease.read(data / "cube_mesh.ply")
    crease.write(tmp_path / "copy.off", g)  # a Geometry as a whole
    h = crease.read(tmp_path / "copy.off")
    assert np.array_equal(h.faces, g.faces)
    assert np.array_equal(h.points, g.points)  # OFF text: shortest round-trip decimals
    crease.write(tmp_path / "copy.ply", g)
    assert crease.read(tmp_path / "copy.ply").attributes.keys() == g.attributes.keys()


def test_file_errors(tmp_path, cli):
    missing = tmp_path / "missing.ply"
    with pytest.raises(FileNotFoundError) as e:
        crease.read(missing)
    msg, _ = cli_error(cli, "info", missing)
    assert str(e.value) == msg and e.value.errno == 2
    with pytest.raises(crease.FileFormatError) as e:
        crease.read(tmp_path / "points.unknown")
    assert isinstance(e.value, ValueError) and isinstance(e.value, OSError)
    with pytest.raises(OSError):
        crease.write(tmp_path / "no-such-folder" / "x.ply", np.zeros((3, 3)))
    with pytest.raises(crease.FileFormatError):
        crease.write(tmp_path / "x.unknown", np.zeros((3, 3)))


def test_bad_input_corpus_same_as_cli(cli):
    """Every file of the bad-input corpus: where `crease info` fails, read raises an OSError or
    ValueError with the CLI's message; where it reads the file, read gives the same counts."""
    files = sorted(p for p in BAD_INPUT.iterdir() if p.is_file() and not p.name.startswith("README"))
    assert len(files) > 40
    failures = 0
    for f in files:
        r = cli("info", "--json", f, check=False)
        if r.returncode != 0:
            failures += 1
            msg = r.stderr.strip().splitlines()[-1][len("error: ") :]
            with pytest.raises((OSError, ValueError)) as e:
                crease.read(f)
            assert str(e.value) == msg, f.name
        else:
            import json

            info = json.loads(r.stdout)
            g = crease.read(f)
            assert len(g.points) == info["points"], f.name
            assert (0 if g.faces is None else len(g.faces)) == info["faces"], f.name
    assert failures > 30


def test_write_refuses_bad_arrays(tmp_path):
    with pytest.raises(ValueError, match=r"\(n, 3\)"):
        crease.write(tmp_path / "x.ply", np.zeros((4, 2)))
    with pytest.raises(ValueError, match="NaN"):
        crease.write(tmp_path / "x.ply", np.array([[0, 0, 0], [np.nan, 0, 0.0]]))
    with pytest.raises(ValueError, match="refers to vertex 5"):
        crease.write(tmp_path / "x.ply", np.zeros((3, 3)), faces=[[0, 1, 5]])
    with pytest.raises(ValueError, match="1-D array of 3 values"):
        crease.write(tmp_path / "x.ply", np.eye(3), attributes={"a": np.zeros(4)})
