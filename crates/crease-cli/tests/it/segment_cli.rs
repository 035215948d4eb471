//! End-to-end tests of `crease segment`: per-face `surface` / `surface_type` in the input's
//! face order, the primitives JSON, the render, and usage errors.

use crate::common::{crease, json_of, run, synth};
use crease::io::ReadOptions;

#[test]
fn box_with_hole_gives_six_planes_and_a_cylinder() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), &["synth", "box-hole", "--mesh"], "b.ply");
    let out = dir.path().join("seg.ply");
    let prims = dir.path().join("primitives.json");
    let png = dir.path().join("seg.png");
    let a = run(
        "segment",
        &input,
        &out,
        &[
            "--primitives",
            prims.to_str().unwrap(),
            "--render",
            png.to_str().unwrap(),
            "--json",
        ],
    )
    .success();
    let s = json_of(&a.get_output().stdout);
    assert_eq!(s["by_type"]["plane"], 6);
    assert_eq!(s["by_type"]["cylinder"], 1);
    let (geom, _) = crease::io::read(&out, &ReadOptions::default()).unwrap();
    let (orig, _) = crease::io::read(&input, &ReadOptions::default()).unwrap();
    assert_eq!(geom.faces, orig.faces, "faces keep the input order");
    let surf = geom.face_attributes.get("surface").unwrap();
    let types = geom.face_attributes.get("surface_type").unwrap();
    let gt = orig.face_attributes.get("gt_surface_type").unwrap();
    // Every face typed as the ground truth says.
    let right = types
        .values
        .iter()
        .zip(&gt.values)
        .filter(|(a, b)| a == b)
        .count();
    assert_eq!(right, geom.faces.len());
    assert!(surf.values.iter().all(|&v| v >= 0.0));
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&prims).unwrap()).unwrap();
    let list = doc["surfaces"].as_array().unwrap();
    assert_eq!(list.len(), 7);
    let cyl = list.iter().find(|x| x["type"] == "cylinder").unwrap();
    let r = cyl["params"]["radius"].as_f64().unwrap();
    assert!((r - 0.2).abs() < 1e-6, "hole radius {r}");
    // The hole touches the top and bottom planes.
    assert_eq!(cyl["neighbours"].as_array().unwrap().len(), 2);
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

#[test]
fn point_cloud_gets_per_point_surfaces() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = synth(dir.path(), &["synth", "box-hole", "-n", "20000"], "c.ply");
    let out = dir.path().join("o.ply");
    let prims = dir.path().join("p.json");
    let png = dir.path().join("c.png");
    let a = run(
        "segment",
        &cloud,
        &out,
        &[
            "--estimate-normals",
            "--primitives",
            prims.to_str().unwrap(),
            "--render",
            png.to_str().unwrap(),
            "--json",
        ],
    )
    .success();
    let s = json_of(&a.get_output().stdout);
    assert_eq!(s["by_type"]["plane"], 6);
    assert_eq!(s["by_type"]["cylinder"], 1);
    assert_eq!(s["normals"], "estimated");
    let (geom, _) = crease::io::read(&out, &ReadOptions::default()).unwrap();
    let (orig, _) = crease::io::read(&cloud, &ReadOptions::default()).unwrap();
    assert_eq!(
        geom.points.positions, orig.points.positions,
        "input point order"
    );
    let types = geom.points.attributes.get("surface_type").unwrap();
    let gt = orig.points.attributes.get("gt_surface_type").unwrap();
    let right = types
        .values
        .iter()
        .zip(&gt.values)
        .filter(|(a, b)| a == b)
        .count();
    assert!(right as f64 > 0.99 * gt.values.len() as f64, "{right}");
    assert!(geom.points.attributes.get("surface").is_some());
    let doc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&prims).unwrap()).unwrap();
    let cyl = doc["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["type"] == "cylinder")
        .unwrap();
    let r = cyl["params"]["radius"].as_f64().unwrap();
    assert!((r - 0.2).abs() < 1e-3, "hole radius {r}");
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

#[test]
fn bad_thresholds_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o.ply");
    let cloud = synth(dir.path(), &["synth", "cube", "-n", "2000"], "c.ply");
    run("segment", &cloud, &out, &["--k", "2"]).code(2);
    let mesh = synth(dir.path(), &["synth", "cube", "--mesh"], "m.ply");
    run("segment", &mesh, &out, &["--th-norm", "95"]).code(2);
    crease()
        .args(["segment", "/nonexistent/mesh.ply", "-o"])
        .arg(&out)
        .assert()
        .code(1);
}
