//! OBJ, OFF, STL and XYZ: round trips, every syntax variant, the shared data files with their
//! known counts, and the bad-input corpus in `tests/bad_input/`.

use crate::common;

use std::path::{Path, PathBuf};

use crease::geometry::{Attribute, PointCloud};
use crease::io::{self, Geometry, ReadOptions, ReadReport, WriteOptions};

fn read(path: &Path) -> (Geometry, ReadReport) {
    io::read(path, &ReadOptions::default())
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

fn write_text(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn roundtrip(dir: &Path, name: &str, g: &Geometry, ascii: bool) -> (Geometry, ReadReport) {
    let p = dir.join(name);
    io::write(&p, g, &WriteOptions { ascii }).unwrap();
    read(&p)
}

/// Awkward coordinates: values without short decimal forms, tiny and huge magnitudes, -0.
fn awkward_positions() -> Vec<[f64; 3]> {
    vec![
        [0.1, 0.2, 0.30000000000000004],
        [std::f64::consts::PI, -std::f64::consts::E, 1e-300],
        [1e300, -0.0, 123456789.12345679],
        [-1.0 / 3.0, 2.0f64.sqrt(), 5e-324],
        [1.0, 2.0, 3.0],
    ]
}

fn mesh_geometry() -> Geometry {
    let mut points = PointCloud::from_positions(awkward_positions());
    points
        .set_normals(vec![
            [0.0, 0.0, 1.0],
            [0.6, 0.8, 0.0],
            [-1.0 / 3.0f64.sqrt(); 3],
            [0.1, 0.2, 0.3],
            [1.0, 0.0, 0.0],
        ])
        .unwrap();
    points
        .set_colors(vec![
            [0, 0, 0],
            [255, 255, 255],
            [1, 128, 254],
            [17, 99, 200],
            [3, 2, 1],
        ])
        .unwrap();
    Geometry {
        points,
        faces: vec![[0, 1, 2], [2, 3, 4], [4, 0, 2]],
        ..Default::default()
    }
}

fn bits(p: &[[f64; 3]]) -> Vec<[u64; 3]> {
    p.iter().map(|v| v.map(f64::to_bits)).collect()
}

// ---------------------------------------------------------------- OBJ

#[test]
fn obj_roundtrip_is_exact() {
    let dir = common::tempdir();
    let mut g = mesh_geometry();
    g.polylines = vec![vec![0, 1, 2, 0], vec![3, 4]];
    let (r, report) = roundtrip(dir.path(), "m.obj", &g, false);
    assert_eq!(bits(&r.points.positions), bits(&g.points.positions));
    assert_eq!(r.points.normals, g.points.normals);
    assert_eq!(r.points.colors, g.points.colors);
    assert_eq!(r.faces, g.faces);
    assert_eq!(r.polylines, g.polylines);
    assert_eq!(report.polygons_triangulated, 0);
}

#[test]
fn obj_edges_are_written_as_two_point_lines() {
    let dir = common::tempdir();
    let mut g = Geometry::from_cloud(PointCloud::from_positions(awkward_positions()));
    g.edges = vec![[0, 1], [3, 4]];
    let (r, _) = roundtrip(dir.path(), "e.obj", &g, false);
    assert_eq!(r.polylines, vec![vec![0, 1], vec![3, 4]]);
    assert!(r.faces.is_empty());
    assert_eq!(r.points.normals, None);
}

#[test]
fn obj_point_cloud_normals_pair_by_order() {
    let dir = common::tempdir();
    let mut pc = PointCloud::from_positions(awkward_positions());
    pc.set_normals(vec![[0.0, 0.0, 1.0]; 5]).unwrap();
    let g = Geometry::from_cloud(pc);
    let (r, report) = roundtrip(dir.path(), "pc.obj", &g, false);
    assert_eq!(r.points.normals, g.points.normals);
    assert!(
        report.notes.iter().any(|n| n.contains("by order")),
        "{report:?}"
    );
}

#[test]
fn obj_all_index_forms_negative_indices_and_polygons() {
    let dir = common::tempdir();
    let text = "# a comment\r\n\
        mtllib parts.mtl\r\n\
        o part\r\n\
        g group1\r\n\
        v 0 0 0\r\n\
        v 1 0 0\r\n\
        v 1 1 0 1.0\r\n\
        v 0 1 0\r\n\
        vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvt 0 1\r\n\
        vn 0 0 1\r\n\
        usemtl steel\r\n\
        s off\r\n\
        f 1 2 3\r\n\
        f 1/1 3/3 4/4\r\n\
        f 1/1/1 2/2/1 3/3/1\r\n\
        f 1//1 3//1 4//1\r\n\
        f -4 -3 -2 -1\r\n\
        f -4//-1 -2//-1 \\\r\n   -1//-1\r\n\
        v 5 5 5\r\n\
        l 1 2 -1\r\n\
        l 3/3 4/4\r\n\
        p 1\r\n\
        g group2\r\n";
    let p = write_text(dir.path(), "forms.obj", text);
    let (g, report) = read(&p);
    assert_eq!(g.points.len(), 5);
    assert_eq!(g.points.positions[2], [1.0, 1.0, 0.0]);
    assert_eq!(
        g.faces,
        vec![
            [0, 1, 2],
            [0, 2, 3],
            [0, 1, 2],
            [0, 2, 3],
            [0, 1, 2],
            [0, 2, 3],
            [0, 2, 3],
        ]
    );
    assert_eq!(report.polygons_triangulated, 1);
    assert_eq!(g.polylines, vec![vec![0, 1, 4], vec![2, 3]]);
    // Vertex 5 (index 4) is used by no face, so no per-vertex normal for every vertex.
    assert_eq!(g.points.normals, None);
    // Groups name the polylines read in them (the curve network's `sharp`, `smooth`, ...).
    assert_eq!(g.polyline_groups, vec!["group1", "group1"]);
    for kind in ["'vt'", "'mtllib'", "'usemtl'", "'o'", "'s'", "'p'"] {
        assert_eq!(
            report.notes.iter().filter(|n| n.contains(kind)).count(),
            1,
            "one note for {kind}: {:?}",
            report.notes
        );
    }
    assert!(!report.notes.iter().any(|n| n.contains("'g'")));
    assert!(report.notes.iter().any(|n| n.contains("ignored 4 'vt'")));
}

#[test]
fn obj_normals_per_vertex_when_consistent_unset_when_conflicting() {
    let dir = common::tempdir();
    // Two vn lines with equal values used for the same vertex: still consistent.
    let ok = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
              vn 0 0 1\nvn 0 0 1\nvn 0.6 0.8 0\n\
              f 1//1 2//1 3//1\nf 2//2 4//3 3//2\n";
    let (g, _) = read(&write_text(dir.path(), "ok.obj", ok));
    assert_eq!(
        g.points.normals,
        Some(vec![
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
            [0.6, 0.8, 0.0]
        ])
    );
    let bad = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
               vn 0 0 1\nvn 1 0 0\n\
               f 1//1 2//1 3//1\nf 2//2 4//2 3//2\n";
    let (g, report) = read(&write_text(dir.path(), "bad.obj", bad));
    assert_eq!(g.points.normals, None);
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("2 vertices have different normals")),
        "{report:?}"
    );
}

#[test]
fn obj_vertex_colours() {
    let dir = common::tempdir();
    let text = "v 0 0 0 1 0 0.5\nv 1 0 0 0 1 0\nv 0 1 0 0.2 0.4 0.6\nf 1 2 3\n";
    let (g, _) = read(&write_text(dir.path(), "c.obj", text));
    assert_eq!(
        g.points.colors,
        Some(vec![[255, 0, 128], [0, 255, 0], [51, 102, 153]])
    );
    let mixed = "v 0 0 0 1 0 0.5\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    let (g, report) = read(&write_text(dir.path(), "m.obj", mixed));
    assert_eq!(g.points.colors, None);
    assert!(report.notes.iter().any(|n| n.contains("only 1 of 3")));
}

#[test]
fn obj_forward_references_are_checked_at_the_end() {
    let dir = common::tempdir();
    let text = "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n";
    let (g, _) = read(&write_text(dir.path(), "fwd.obj", text));
    assert_eq!(g.faces, vec![[0, 1, 2]]);
}

#[test]
fn obj_abc_and_cube_load_with_known_counts() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    let abc = std::fs::read_dir(dir.join("abc"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().ends_with("_trimesh_001.obj"))
        .expect("ABC mesh");
    let (g, report) = read(&abc);
    assert_eq!(g.points.len(), 16332);
    assert_eq!(g.faces.len(), 32664);
    assert_eq!(report.polygons_triangulated, 0);
    // Sharp-edge vertices carry several normals: 970 of them (counted independently with awk).
    assert_eq!(g.points.normals, None);
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("970 vertices have different normals")),
        "{:?}",
        report.notes
    );
    assert!(report
        .notes
        .iter()
        .any(|n| n.contains("ignored 17347 'vc'")));
    // First vertex and first face as written in the file.
    assert_eq!(g.points.positions[0], [-2.38125, 0.0, 1.5875]);
    assert_eq!(g.faces[0], [1015, 1446, 1535]);

    let (g, report) = read(&dir.join("meshes/cube.obj"));
    assert_eq!(g.points.len(), 8);
    assert_eq!(g.faces.len(), 12);
    assert!(report.notes.iter().any(|n| n.contains("'vt'")));
}

// ---------------------------------------------------------------- OFF

#[test]
fn off_roundtrip_is_exact() {
    let dir = common::tempdir();
    let g = mesh_geometry();
    let (r, report) = roundtrip(dir.path(), "m.off", &g, false);
    assert_eq!(bits(&r.points.positions), bits(&g.points.positions));
    assert_eq!(r.faces, g.faces);
    assert_eq!(r.points.normals, None, "plain OFF holds no normals");
    assert_eq!(report.encoding, "ascii OFF");
}

#[test]
fn off_variants_comments_polygons() {
    let dir = common::tempdir();
    let text = "OFF 4 2 0 # counts on the header line\n\
                # a comment\n\n\
                0 0 0\n1 0 0\n1 1 0\n0 1 0\n\
                4 0 1 2 3 255 0 0\n\
                3 0 2 3\n";
    let (g, report) = read(&write_text(dir.path(), "a.off", text));
    assert_eq!(g.faces, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
    assert_eq!(report.polygons_triangulated, 1);
    assert!(report
        .notes
        .iter()
        .any(|n| n.contains("1 per-face colours ignored")));

    let coff = "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0\n0 1 0 1 2 3\n3 0 1 2\n";
    let (g, _) = read(&write_text(dir.path(), "c.off", coff));
    assert_eq!(
        g.points.colors,
        Some(vec![[255, 0, 0], [0, 255, 0], [1, 2, 3]])
    );
    let coff_f = "COFF\n3 1 0\n0 0 0 1.0 0 0 1\n1 0 0 0 0.5 0 1\n0 1 0 0 0 1 1\n3 0 1 2\n";
    let (g, _) = read(&write_text(dir.path(), "cf.off", coff_f));
    assert_eq!(
        g.points.colors,
        Some(vec![[255, 0, 0], [0, 128, 0], [0, 0, 255]])
    );

    let noff = "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0.6 0.8\n0 1 0 1 0 0\n3 0 1 2\n";
    let (g, _) = read(&write_text(dir.path(), "n.off", noff));
    assert_eq!(
        g.points.normals,
        Some(vec![[0.0, 0.0, 1.0], [0.0, 0.6, 0.8], [1.0, 0.0, 0.0]])
    );
    assert_eq!(g.points.positions[1], [1.0, 0.0, 0.0]);

    let cnoff =
        "CNOFF\n3 1 0\n0 0 0 0 0 1 10 20 30\n1 0 0 0 0 1 1 2 3\n0 1 0 0 0 1 4 5 6\n3 0 1 2\n";
    let (g, _) = read(&write_text(dir.path(), "cn.off", cnoff));
    assert_eq!(
        g.points.colors,
        Some(vec![[10, 20, 30], [1, 2, 3], [4, 5, 6]])
    );
    assert_eq!(
        g.points.normals.as_ref().map(|n| n[2]),
        Some([0.0, 0.0, 1.0])
    );

    let stoff = "STOFF\n3 1 0\n0 0 0 0.5 0.5\n1 0 0 0 1\n0 1 0 1 1\n3 0 1 2\n";
    let (g, report) = read(&write_text(dir.path(), "st.off", stoff));
    assert_eq!(g.points.positions[2], [0.0, 1.0, 0.0]);
    assert!(report.notes.iter().any(|n| n.contains("texture")));

    let cloud = "OFF\n2 0 0\n1 2 3\n4 5 6\n";
    let (g, _) = read(&write_text(dir.path(), "pc.off", cloud));
    assert_eq!(g.points.positions, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    assert!(g.faces.is_empty());
}

#[test]
fn off_shared_meshes_load() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    let expected = [
        ("fandisk.off", 7229, 14454),
        ("bar.off", 6084, 12106),
        ("block.off", 2132, 4272),
        ("cup.off", 5668, 11340),
        ("cylinder.off", 4802, 9600),
        ("rocker-arm.off", 10044, 20088),
        ("screwdriver.off", 3395, 6786),
        ("sharp_sphere.off", 10443, 20882),
        ("torus.off", 288, 576),
    ];
    let mut seen = 0;
    for e in std::fs::read_dir(dir.join("meshes")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "off") {
            let (g, report) = read(&p);
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if let Some(&(_, v, f)) = expected.iter().find(|x| x.0 == name) {
                assert_eq!((g.points.len(), g.faces.len()), (v, f), "{name}");
                assert_eq!(report.polygons_triangulated, 0, "{name}");
                seen += 1;
            }
        }
    }
    assert_eq!(seen, expected.len());
}

// ---------------------------------------------------------------- STL

/// A closed tetrahedron with f32-representable coordinates.
fn tetra() -> Geometry {
    Geometry::from_mesh(
        crease::TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.5, 0.0, 0.0],
                [0.0, 2.25, 0.0],
                [0.125, 0.25, -3.0],
            ],
            vec![[0, 1, 2], [0, 3, 1], [1, 3, 2], [2, 3, 0]],
        )
        .unwrap(),
    )
}

#[test]
fn stl_binary_roundtrip_merges_corners() {
    let dir = common::tempdir();
    let g = tetra();
    let p = dir.path().join("t.stl");
    io::write(&p, &g, &WriteOptions::default()).unwrap();
    assert_eq!(std::fs::metadata(&p).unwrap().len(), 84 + 50 * 4);
    let (r, report) = read(&p);
    assert_eq!(report.encoding, "binary");
    assert_eq!(r.points.positions, g.points.positions);
    assert_eq!(r.faces, g.faces);
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("12 corners merged into 4 vertices")),
        "{report:?}"
    );
}

#[test]
fn stl_ascii_roundtrip_is_exact() {
    let dir = common::tempdir();
    let g = mesh_geometry();
    let (r, report) = roundtrip(dir.path(), "a.stl", &g, true);
    assert_eq!(report.encoding, "ascii");
    assert_eq!(bits(&r.points.positions), bits(&g.points.positions));
    assert_eq!(r.faces, g.faces);
}

#[test]
fn stl_binary_rounds_to_f32() {
    let dir = common::tempdir();
    let g = mesh_geometry();
    let mut finite = g.clone();
    // 1e300 and 1e-300 do not fit f32; keep the values f32 can hold.
    finite.points.positions = finite
        .points
        .positions
        .iter()
        .map(|p| {
            p.map(|c| {
                if c.abs() > 1e30 || (c != 0.0 && c.abs() < 1e-30) {
                    7.0
                } else {
                    c
                }
            })
        })
        .collect();
    let (r, _) = roundtrip(dir.path(), "b.stl", &finite, false);
    let want: Vec<[f64; 3]> = finite
        .points
        .positions
        .iter()
        .map(|p| p.map(|c| f64::from(c as f32)))
        .collect();
    assert_eq!(r.points.positions, want);
    assert_eq!(r.faces, g.faces);
}

#[test]
fn stl_binary_whose_header_starts_with_solid() {
    let dir = common::tempdir();
    let p = dir.path().join("s.stl");
    io::write(&p, &tetra(), &WriteOptions::default()).unwrap();
    let mut bytes = std::fs::read(&p).unwrap();
    bytes[..12].copy_from_slice(b"solid tetra ");
    std::fs::write(&p, &bytes).unwrap();
    let (r, report) = read(&p);
    assert_eq!(report.encoding, "binary");
    assert_eq!(r.faces, tetra().faces);
    // With trailing bytes the size rule fails, but the NUL bytes still say binary.
    bytes.extend_from_slice(&[0u8; 7]);
    std::fs::write(&p, &bytes).unwrap();
    let (r, report) = read(&p);
    assert_eq!(r.faces, tetra().faces);
    assert!(report.notes.iter().any(|n| n.contains("7 bytes")));
}

#[test]
fn stl_ascii_variants() {
    let dir = common::tempdir();
    let text = "SOLID Part 1\r\n\
        FACET NORMAL 0 0 1\r\n OUTER LOOP\r\n  VERTEX 0 0 0\r\n  VERTEX 1 0 0\r\n  VERTEX 1 1 0\r\n  VERTEX 0 1 0\r\n ENDLOOP\r\nENDFACET\r\n\
        ENDSOLID Part 1\r\n\
        solid second\nfacet normal 0 0 0\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex -0 1 1\nendloop\nendfacet\nendsolid\n";
    let (g, report) = read(&write_text(dir.path(), "v.stl", text));
    assert_eq!(report.polygons_triangulated, 1);
    assert_eq!(g.faces, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    assert_eq!(g.points.positions[4], [-0.0, 1.0, 1.0]);
}

#[test]
fn stl_write_needs_faces() {
    let dir = common::tempdir();
    let g = Geometry::from_cloud(PointCloud::from_positions(awkward_positions()));
    let e = io::write(dir.path().join("x.stl"), &g, &WriteOptions::default()).unwrap_err();
    assert!(
        e.to_string()
            .contains("STL holds triangles; this geometry has none"),
        "{e}"
    );
}

#[test]
fn stl_nan_faces_are_dropped() {
    let dir = common::tempdir();
    let text = "solid n\n\
        facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n\
        facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex nan 0 0\nvertex 0 1 0\nendloop\nendfacet\n\
        endsolid n\n";
    let (g, report) = read(&write_text(dir.path(), "n.stl", text));
    assert_eq!(g.faces, vec![[0, 1, 2]]);
    assert_eq!(report.dropped_nonfinite, 1);
    assert_eq!(report.dropped_faces, 1);
}

// ---------------------------------------------------------------- XYZ

#[test]
fn xyz_roundtrip_with_and_without_normals() {
    let dir = common::tempdir();
    let g = mesh_geometry();
    let (r, report) = roundtrip(dir.path(), "n.xyz", &g, false);
    assert_eq!(bits(&r.points.positions), bits(&g.points.positions));
    assert_eq!(
        r.points.normals.as_ref().map(|n| bits(n)),
        g.points.normals.as_ref().map(|n| bits(n))
    );
    assert!(r.faces.is_empty(), "xyz holds the vertices only");
    assert_eq!(report.encoding, "ascii, 6 columns");
    let plain = Geometry::from_cloud(PointCloud::from_positions(awkward_positions()));
    let (r, _) = roundtrip(dir.path(), "p.txt", &plain, false);
    assert_eq!(bits(&r.points.positions), bits(&plain.points.positions));
    assert_eq!(r.points.normals, None);
}

#[test]
fn xyz_separators_comments_and_headers() {
    let dir = common::tempdir();
    let csv = "x,y,z,nx,ny,nz,red,green,blue,quality\n\
               1,2,3,0,0,1,255,0,10,0.5\n\
               # comment\n\
               4;5;6;0;1;0;0;128;20;0.25\n\
               7 8\t9, 1 ,0, 0, 1, 2, 3, 1e3\n";
    let (g, report) = read(&write_text(dir.path(), "h.csv", csv));
    assert_eq!(
        g.points.positions,
        vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0], [7.0, 8.0, 9.0]]
    );
    assert_eq!(g.points.normals.as_ref().unwrap()[1], [0.0, 1.0, 0.0]);
    assert_eq!(
        g.points.colors,
        Some(vec![[255, 0, 10], [0, 128, 20], [1, 2, 3]])
    );
    assert_eq!(
        g.points.attribute("quality").map(|a| a.values.clone()),
        Some(vec![0.5, 0.25, 1000.0])
    );
    assert!(report.notes.iter().any(|n| n.contains("from the header")));

    // CloudCompare writes its header as a comment.
    let cc = "//X Y Z R G B\n1 2 3 0.5 0.25 1\n4 5 6 0 1 0\n";
    let (g, _) = read(&write_text(dir.path(), "cc.txt", cc));
    assert_eq!(g.points.colors, Some(vec![[128, 64, 255], [0, 255, 0]]));
    assert_eq!(g.points.normals, None);
}

#[test]
fn xyz_column_rules_without_header() {
    let dir = common::tempdir();
    let (g, _) = read(&write_text(dir.path(), "i.xyz", "1 2 3 40\n4 5 6 50\n"));
    assert_eq!(
        g.points.attribute("intensity").map(|a| a.values.clone()),
        Some(vec![40.0, 50.0])
    );
    // Leica PTS: count line, then x y z intensity r g b.
    let pts = "2\n1 2 3 -120 10 20 30\n4 5 6 300 40 50 60\n";
    let (g, report) = read(&write_text(dir.path(), "s.pts", pts));
    assert_eq!(g.points.len(), 2);
    assert_eq!(g.points.colors, Some(vec![[10, 20, 30], [40, 50, 60]]));
    assert_eq!(
        g.points.attribute("intensity").map(|a| a.values.clone()),
        Some(vec![-120.0, 300.0])
    );
    assert!(report.notes.is_empty() || !report.notes.iter().any(|n| n.contains("point count")));
    let wrong_count = "5\n1 2 3\n";
    let (_, report) = read(&write_text(dir.path(), "w.pts", wrong_count));
    assert!(report.notes.iter().any(|n| n.contains("point count of 5")));
    // Six columns of byte values cannot be unit normals: colours.
    let (g, _) = read(&write_text(dir.path(), "rgb.xyz", "1 2 3 200 100 0\n"));
    assert_eq!(g.points.colors, Some(vec![[200, 100, 0]]));
    assert_eq!(g.points.normals, None);
    // Seven columns that are not PTS colours, and other counts: generic attributes.
    let (g, _) = read(&write_text(dir.path(), "g.xyz", "1 2 3 0.5 0.1 0.2 0.3\n"));
    let names: Vec<&str> = g
        .points
        .attributes
        .iter()
        .map(|a| a.name.as_str())
        .collect();
    assert_eq!(names, ["c3", "c4", "c5", "c6"]);
    let (g, _) = read(&write_text(dir.path(), "g5.xyz", "1 2 3 4 5\n"));
    let names: Vec<&str> = g
        .points
        .attributes
        .iter()
        .map(|a| a.name.as_str())
        .collect();
    assert_eq!(names, ["c3", "c4"]);
}

#[test]
fn xyz_nan_rows_are_dropped() {
    let dir = common::tempdir();
    let (g, report) = read(&write_text(
        dir.path(),
        "n.xyz",
        "1 2 3\nnan 0 0\n4 5 inf\n7 8 9\n",
    ));
    assert_eq!(g.points.positions, vec![[1.0, 2.0, 3.0], [7.0, 8.0, 9.0]]);
    assert_eq!(report.dropped_nonfinite, 2);
}

#[test]
fn xyz_big_file_parses_in_chunks_in_order() {
    let dir = common::tempdir();
    let n = 200_000;
    let mut pc = PointCloud::from_positions(
        (0..n)
            .map(|i| {
                let t = i as f64;
                [t * 0.001, (t * 0.37).sin(), -t / 7.0]
            })
            .collect(),
    );
    pc.set_attribute(Attribute::float("unused", vec![0.0; n]))
        .unwrap();
    let g = Geometry::from_cloud(pc);
    let p = dir.path().join("big.xyz");
    io::write(&p, &g, &WriteOptions::default()).unwrap();
    assert!(
        std::fs::metadata(&p).unwrap().len() > 4 << 20,
        "several chunks"
    );
    let (r, _) = read(&p);
    assert_eq!(bits(&r.points.positions), bits(&g.points.positions));
    // An error deep in the file names the right line.
    let mut text = std::fs::read_to_string(&p).unwrap();
    text.push_str("1 2 3\n1 2 x\n");
    std::fs::write(&p, text).unwrap();
    let e = io::read(&p, &ReadOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains(&format!("line {}", n + 2)), "{e}");
}

#[test]
fn xyz_curvsurf_sample_loads() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    let (g, report) = read(&dir.join("scans/curvsurf/sample.xyz"));
    assert_eq!(g.points.len(), 9664);
    assert_eq!(g.points.positions[0], [-0.429714, 0.325184, -1.1048]);
    assert_eq!(report.dropped_nonfinite, 0);
}

// ---------------------------------------------------------------- bad input

fn bad(name: &str, words: &[&str]) {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/bad_input")
        .join(name);
    assert!(p.is_file(), "{} missing", p.display());
    let e = match io::read(&p, &ReadOptions::default()) {
        Ok((g, _)) => panic!("{name}: expected an error, read {} points", g.points.len()),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains(name),
        "{name}: message does not name the file: {e}"
    );
    for w in words {
        assert!(e.contains(w), "{name}: message lacks {w:?}: {e}");
    }
}

macro_rules! bad_input {
    ($($test:ident: $file:literal => [$($w:literal),*];)*) => {
        $(#[test] fn $test() { bad($file, &[$($w),*]); })*
    };
}

bad_input! {
    bad_obj_index_out_of_range: "obj-index-out-of-range.obj" => ["line 4", "vertex 9", "3 vertices"];
    bad_obj_non_numeric_coordinate: "obj-non-numeric-coordinate.obj" => ["line 2", "expected 3 coordinates after 'v'", "abc"];
    bad_obj_index_zero: "obj-index-zero.obj" => ["line 4", "index 0"];
    bad_obj_relative_index_before_start: "obj-relative-index-before-start.obj" => ["line 4", "relative vertex index -4"];
    bad_obj_face_two_vertices: "obj-face-two-vertices.obj" => ["line 3", "at least 3"];
    bad_obj_normal_out_of_range: "obj-normal-out-of-range.obj" => ["line 5", "normal 2"];
    bad_obj_bad_face_corner: "obj-bad-face-corner.obj" => ["line 4", "1/x"];
    bad_obj_empty: "obj-empty.obj" => ["no vertices"];
    bad_obj_comments_only: "obj-comments-only.obj" => ["no vertices"];
    bad_off_huge_vertex_count: "off-huge-vertex-count.off" => ["line 2", "1000000000 vertices", "truncated"];
    bad_off_missing_counts: "off-missing-counts.off" => ["expected the counts"];
    bad_off_index_out_of_range: "off-index-out-of-range.off" => ["line 6", "vertex 7", "3 vertices"];
    bad_off_non_numeric: "off-non-numeric.off" => ["line 4", "zero"];
    bad_off_truncated: "off-truncated.off" => ["end of file", "2 of 3 vertices"];
    bad_off_bad_keyword: "off-bad-keyword.off" => ["line 1", "expected 'OFF'", "PLY"];
    bad_off_empty: "off-empty.off" => ["empty"];
    bad_xyz_ragged_row: "xyz-ragged-row.xyz" => ["line 3", "expected 3 values", "found 4"];
    bad_xyz_non_numeric: "xyz-non-numeric.xyz" => ["line 2", "column 3", "abc"];
    bad_xyz_empty: "xyz-empty.xyz" => ["no points"];
    bad_xyz_too_few_columns: "xyz-too-few-columns.xyz" => ["line 1", "at least 3"];
    bad_xyz_header_only: "xyz-header-only.xyz" => ["no points"];
    bad_stl_empty: "stl-empty.stl" => ["no triangles", "empty"];
    bad_stl_ascii_non_numeric: "stl-ascii-non-numeric.stl" => ["line 5", "abc"];
    bad_stl_ascii_unterminated: "stl-ascii-unterminated.stl" => ["line 2", "ends inside a facet"];
    bad_stl_not_stl: "stl-not-stl.stl" => ["not an STL file"];
    bad_stl_truncated_binary: "stl-truncated-binary.stl" => ["2 triangles", "truncated"];
    bad_stl_count_larger_than_file: "stl-count-larger-than-file.stl" => ["1000000 triangles", "134 bytes"];
}
