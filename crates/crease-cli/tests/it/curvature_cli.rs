//! End-to-end tests of `crease curvature`: PLY properties in input order, analytic values on a
//! synthetic sphere, the Bézier method's sharp flags on a cube mesh, and clear usage errors.

use crate::common::{crease, synth};
use crease::io::ReadOptions;

fn attr(geom: &crease::io::Geometry, name: &str) -> Vec<f64> {
    geom.points
        .attribute(name)
        .unwrap_or_else(|| panic!("attribute {name} missing"))
        .values
        .clone()
}

#[test]
fn quadric_on_sphere_cloud_writes_properties_in_order() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), &["synth", "sphere", "-n", "4000"], "s.ply");
    let out = dir.path().join("c.ply");
    let assert = crease()
        .args(["curvature"])
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["-k", "20", "--use-normals", "--json"])
        .assert()
        .success();
    let summary: serde_json::Value = serde_json::from_slice(&assert.get_output().stdout).unwrap();
    assert_eq!(summary["method"], "quadric");
    assert_eq!(summary["points"], 4000);
    assert_eq!(summary["failed"], 0);
    let (a, _) = crease::io::read(&input, &ReadOptions::default()).unwrap();
    let (b, _) = crease::io::read(&out, &ReadOptions::default()).unwrap();
    // Same points, same order.
    assert_eq!(a.points.positions, b.points.positions);
    // Sphere of radius 0.5 with outward normals: k1 = k2 = H = 2, K = 4.
    for (name, want) in [
        ("k1", 2.0),
        ("k2", 2.0),
        ("mean_curvature", 2.0),
        ("gaussian_curvature", 4.0),
    ] {
        let v = attr(&b, name);
        assert_eq!(v.len(), 4000);
        let bad = v
            .iter()
            .filter(|x| ((**x - want) / want).abs() > 0.02)
            .count();
        assert!(bad < 40, "{name}: {bad} values off by more than 2 %");
    }
    let k1 = attr(&b, "k1");
    let k2 = attr(&b, "k2");
    assert!(k1.iter().zip(&k2).all(|(a, b)| a >= b));
}

#[test]
fn bezier_on_cube_mesh_flags_edges() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(
        dir.path(),
        &["synth", "cube", "--mesh", "--edge", "0.05"],
        "cube.ply",
    );
    let out = dir.path().join("c.ply");
    let assert = crease()
        .args(["curvature"])
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["--method", "bezier", "--json"])
        .assert()
        .success();
    let summary: serde_json::Value = serde_json::from_slice(&assert.get_output().stdout).unwrap();
    assert_eq!(summary["method"], "bezier");
    let (b, _) = crease::io::read(&out, &ReadOptions::default()).unwrap();
    let sharp = attr(&b, "sharp");
    let p = &b.points.positions;
    // Vertices on two faces' planes (|x|, |y| or |z| = 0.5 twice) are on cube edges: flagged.
    // Vertices 3 edge lengths or more from every edge: not flagged.
    let mut on = 0;
    for (q, s) in p.iter().zip(&sharp) {
        let mut g: Vec<f64> = q.iter().map(|c| 0.5 - c.abs()).collect();
        g.sort_by(f64::total_cmp);
        if g[1] < 1e-9 {
            on += 1;
            assert_eq!(*s, 1.0, "edge vertex {q:?} not sharp");
        } else if g[1] > 0.15 {
            assert_eq!(*s, 0.0, "interior vertex {q:?} sharp");
        }
    }
    assert!(on > 100);
    assert_eq!(
        summary["sharp_vertices"].as_u64().unwrap() as f64,
        sharp.iter().sum::<f64>()
    );
    // The flat faces have zero curvature away from the sharp band.
    let k1 = attr(&b, "k1");
    assert!(k1
        .iter()
        .zip(&sharp)
        .filter(|(_, s)| **s == 0.0)
        .all(|(k, _)| k.abs() < 1e-6));
}

#[test]
fn usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), &["synth", "plane", "-n", "500"], "p.ply");
    let out = dir.path().join("o.ply");
    // Bézier needs a mesh.
    crease()
        .arg("curvature")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["--method", "bezier"])
        .assert()
        .code(2)
        .stderr(predicates::str::contains("needs a triangle mesh"));
    // k too small.
    crease()
        .arg("curvature")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(["-k", "3"])
        .assert()
        .code(2);
    // Never overwrite the input.
    crease()
        .arg("curvature")
        .arg(&input)
        .arg("-o")
        .arg(&input)
        .assert()
        .failure();
    // --use-normals without normals in the file.
    let bare = dir.path().join("bare.xyz");
    std::fs::write(
        &bare,
        (0..100)
            .map(|i| format!("{} {} 0\n", i % 10, i / 10))
            .collect::<String>(),
    )
    .unwrap();
    crease()
        .arg("curvature")
        .arg(&bare)
        .arg("-o")
        .arg(&out)
        .arg("--use-normals")
        .assert()
        .code(2)
        .stderr(predicates::str::contains("no normals"));
}
