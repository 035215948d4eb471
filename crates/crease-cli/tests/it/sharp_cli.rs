//! End-to-end tests of `crease sharp` and `crease eval`: properties in input order, the
//! detection scored against the synthetic labels, meshes, the JSON summary, and usage errors.

use crate::common::{crease, run, synth};
use crease::io::ReadOptions;

#[test]
fn cloud_detection_scored_by_eval() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), &["synth", "cube", "-n", "12000"], "cube.ply");
    let out = dir.path().join("sharp.ply");
    let a = crease()
        .arg("sharp")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .arg("--json")
        .assert()
        .success();
    let summary: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
    assert_eq!(summary["method"], "projected-distance");
    assert_eq!(summary["points"], 12000);
    assert_eq!(summary["scales"].as_array().unwrap().len(), 8);
    assert_eq!(summary["scales"][0]["scale"], 12);
    assert!(summary["timings"]["knn"].as_f64().unwrap() >= 0.0);
    assert!(summary["timings"]["detection"].as_f64().unwrap() >= 0.0);
    let (src, _) = crease::io::read(&input, &ReadOptions::default()).unwrap();
    let (res, _) = crease::io::read(&out, &ReadOptions::default()).unwrap();
    assert_eq!(
        src.points.positions, res.points.positions,
        "input order kept"
    );
    let sharp = res.points.attribute("sharp").unwrap();
    let score = res.points.attribute("sharpness").unwrap();
    let n_sharp = sharp.values.iter().filter(|&&v| v > 0.0).count();
    assert_eq!(summary["sharp"], n_sharp);
    for (s, v) in sharp.values.iter().zip(&score.values) {
        if *s > 0.0 {
            assert!(*v >= 1.0 - 1e-6);
        }
    }
    // The output still carries gt_sharp: score it against itself with crease eval.
    let e = crease()
        .arg("eval")
        .arg(&out)
        .arg("--gt")
        .arg(&out)
        .arg("--json")
        .assert()
        .success();
    let report: serde_json::Value = serde_json::from_slice(&e.get_output().stdout).unwrap();
    let tol_f1 = report["tolerant"]["f1"].as_f64().unwrap();
    let auc = report["roc"]["auc"].as_f64().unwrap();
    assert!(tol_f1 > 0.9, "tolerant F1 {tol_f1}");
    assert!(auc > 0.9, "AUC {auc}");
}

#[test]
fn mesh_detection_uses_rings() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), &["synth", "cube", "--mesh"], "cube.ply");
    let out = dir.path().join("sharp.ply");
    let a = crease()
        .arg("sharp")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .arg("--json")
        .assert()
        .success();
    let summary: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
    assert_eq!(summary["mesh"], true);
    assert_eq!(summary["scales"].as_array().unwrap().len(), 4);
    let (res, _) = crease::io::read(&out, &ReadOptions::default()).unwrap();
    assert!(!res.faces.is_empty(), "faces are written back");
    // Every vertex on a cube edge is sharp, and only those (F1 = 1 measured).
    let sharp = &res.points.attribute("sharp").unwrap().values;
    // Vertices on an edge are those at distance 0 from it (gt_sharp is a band).
    let truth = &res.points.attribute("gt_edge_distance").unwrap().values;
    let wrong = sharp
        .iter()
        .zip(truth)
        .filter(|(s, d)| (**s > 0.0) != (**d < 1e-6))
        .count();
    assert!(wrong * 50 < truth.len(), "{wrong} wrong of {}", truth.len());
}

#[test]
fn usage_errors_and_too_few_points() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), &["synth", "cube", "-n", "30"], "tiny.ply");
    let out = dir.path().join("o.ply");
    let a = run("sharp", &input, &out, &[]).failure().code(1);
    let err = String::from_utf8_lossy(&a.get_output().stderr).to_string();
    assert!(
        err.contains("tiny.ply") && err.contains("30 points"),
        "{err}"
    );
    for bad in [
        vec!["--threshold", "0"],
        vec!["--threshold", "1.5"],
        vec!["--scales", "0,12"],
        vec!["--upper-quantile", "0"],
    ] {
        run("sharp", &input, &out, &bad).failure().code(2);
    }
    // Never overwrite the input.
    run("sharp", &input, &input, &[]).failure().code(2);
}
