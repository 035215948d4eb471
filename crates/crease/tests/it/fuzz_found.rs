//! Inputs the coverage-guided fuzz targets (`fuzz/`, `scripts/fuzz.sh`) found crashing, decoded
//! to plain files (`fuzz/src/bin/decode.rs`) under `tests/fuzz_found/`, each run the way its
//! target ran it. The tests build with overflow checks (the dev profile), as the targets do;
//! the raw inputs are kept in `fuzz/regressions/<target>/` and replayed by `scripts/fuzz.sh`.

use std::path::PathBuf;

use crease::geometry::MeshTopology;
use crease::segment::{segment_mesh, segment_points, PointParams, SegmentParams};

fn found(name: &str) -> crease::io::Geometry {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_found")
        .join(name);
    crease::io::read(&path, &Default::default()).unwrap().0
}

/// Every label a surface id or -1.
fn assert_labels(labels: &[i32], surfaces: usize) {
    assert!(labels
        .iter()
        .all(|&s| s >= -1 && (s as i64) < surfaces as i64));
}

#[test]
fn a_mesh_of_huge_curvature_segments_without_overflow() {
    // Coordinates up to 1e38 with slivers: κ̃_max · l̄ binned at i64::MAX, and the torus
    // histogram's neighbouring bins overflowed (segment/labels.rs).
    let g = found("mesh_segment-torus-bin-overflow.ply");
    let mesh = crease::TriMesh {
        vertices: g.points,
        faces: g.faces,
        face_attributes: Default::default(),
    };
    let topo = MeshTopology::new(&mesh).unwrap();
    let seg = segment_mesh(&mesh, &topo, &SegmentParams::default()).unwrap();
    assert_labels(&seg.face_surface, seg.surfaces.len());
    assert_eq!(seg.face_surface.len(), mesh.faces.len());
}

#[test]
fn a_cloud_of_huge_curvature_segments_without_overflow() {
    // The same overflow on the point path (k = 8, as the target runs it).
    let g = found("points_segment-torus-bin-overflow.ply");
    let pp = PointParams {
        k: 8,
        ..Default::default()
    };
    match segment_points(&g.points.positions, None, &SegmentParams::default(), &pp) {
        Ok(seg) => {
            assert_labels(&seg.point_surface, seg.surfaces.len());
            assert_eq!(seg.point_surface.len(), g.points.positions.len());
        }
        Err(e) => assert!(matches!(e, crease::Error::InvalidInput(_)), "{e}"),
    }
}
