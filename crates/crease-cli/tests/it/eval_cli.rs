//! End-to-end tests of `crease eval`: a prediction copied from the ground truth scores F1 = 1
//! and AUC = 1, perturbed labels give the exact counts, the ROC CSV is written, and mismatched
//! inputs fail with a message naming the file.

use std::path::{Path, PathBuf};

use crate::common::{crease, json_of};
use crease::geometry::Attribute;
use crease::io::{Geometry, ReadOptions, WriteOptions};

fn synth(dir: &Path, name: &str, n: usize) -> PathBuf {
    let out = dir.join(name);
    crease()
        .args(["synth", "cube", "-q", "-n", &n.to_string(), "-o"])
        .arg(&out)
        .assert()
        .success();
    out
}

/// Writes `gt`'s points with `sharp` = gt_sharp (every `flip`-th point flipped when `flip` > 0)
/// and `sharpness` = minus the distance to the edges.
fn predict(gt: &Path, out: &Path, flip: usize) -> Geometry {
    let (mut geom, _) = crease::io::read(gt, &ReadOptions::default()).unwrap();
    let pts = &mut geom.points;
    let sharp: Vec<bool> = pts
        .attribute("gt_sharp")
        .unwrap()
        .values
        .iter()
        .enumerate()
        .map(|(i, &v)| (v > 0.0) != (flip > 0 && i % flip == 0))
        .collect();
    let dist = pts.attribute("gt_edge_distance").unwrap().values.clone();
    pts.set_attribute(Attribute::flag("sharp", sharp)).unwrap();
    pts.set_attribute(Attribute::float(
        "sharpness",
        dist.iter().map(|d| -d).collect(),
    ))
    .unwrap();
    crease::io::write(out, &geom, &WriteOptions::default()).unwrap();
    geom
}

#[test]
fn a_copy_of_the_truth_scores_one_and_the_roc_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let gt = synth(dir.path(), "cube.ply", 5000);
    let pred = dir.path().join("pred.ply");
    predict(&gt, &pred, 0);
    let roc = dir.path().join("roc.csv");
    let out = crease()
        .args(["eval", "--json"])
        .arg(&pred)
        .arg("--gt")
        .arg(&gt)
        .arg("--roc")
        .arg(&roc)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json_of(&out.stdout);
    assert_eq!(v["items"], 5000);
    for k in ["precision", "recall", "f1", "mcc", "iou", "accuracy"] {
        assert_eq!(v["metrics"][k], 1.0, "{k}: {v}");
    }
    assert_eq!(v["tolerant"]["f1"], 1.0);
    assert_eq!(v["roc"]["auc"], 1.0);
    assert_eq!(v["confusion"]["fp"], 0);
    assert_eq!(v["confusion"]["fn"], 0);
    assert_eq!(v["ground_truth"]["source"], "property gt_sharp");
    assert_eq!(v["prediction"]["score"], "sharpness");
    assert!(v["roc"]["curve"].as_array().unwrap().len() <= 101);
    let csv = std::fs::read_to_string(&roc).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("threshold,fpr,tpr"));
    assert_eq!(lines.next(), Some("inf,0,0"));
    assert_eq!(csv.lines().last().map(|l| l.ends_with(",1,1")), Some(true));
    // The CSV has one row per distinct score, plus the header and the (0, 0) start.
    assert_eq!(
        csv.lines().count() as u64,
        v["roc"]["full_points"].as_u64().unwrap() + 1
    );

    // The text report: an aligned table.
    let out = crease()
        .arg("eval")
        .arg(&pred)
        .arg("--gt")
        .arg(&gt)
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("F1             1.0000"), "{text}");
    assert!(text.contains("AUC            1.0000"), "{text}");
}

#[test]
fn flipped_labels_give_the_exact_confusion_matrix() {
    let dir = tempfile::tempdir().unwrap();
    let gt = synth(dir.path(), "cube.ply", 4000);
    let pred = dir.path().join("pred.ply");
    let geom = predict(&gt, &pred, 10);
    let truth: Vec<bool> = geom
        .points
        .attribute("gt_sharp")
        .unwrap()
        .values
        .iter()
        .map(|&v| v > 0.0)
        .collect();
    let (mut tp, mut fp, mut fn_) = (0u64, 0u64, 0u64);
    for (i, &t) in truth.iter().enumerate() {
        let p = t != (i % 10 == 0);
        tp += (p && t) as u64;
        fp += (p && !t) as u64;
        fn_ += (!p && t) as u64;
    }
    let out = crease()
        .args(["eval", "--json", "--tolerance", "0"])
        .arg(&pred)
        .arg("--gt")
        .arg(&gt)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json_of(&out.stdout);
    assert_eq!(v["confusion"]["tp"], tp);
    assert_eq!(v["confusion"]["fp"], fp);
    assert_eq!(v["confusion"]["fn"], fn_);
    assert_eq!(
        v["metrics"]["f1"],
        (2 * tp) as f64 / (2 * tp + fp + fn_) as f64
    );
    // Tolerance 0 is the exact overlap.
    assert_eq!(v["tolerant"]["tolerance"], 0.0);
    assert_eq!(v["tolerant"]["precision"], v["metrics"]["precision"]);
    assert_eq!(v["tolerant"]["recall"], v["metrics"]["recall"]);
}

#[test]
fn mismatched_inputs_fail_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let gt = synth(dir.path(), "cube.ply", 3000);
    let other = synth(dir.path(), "other.ply", 3001);
    let pred = dir.path().join("pred.ply");
    predict(&other, &pred, 0);
    let out = crease()
        .arg("eval")
        .arg(&pred)
        .arg("--gt")
        .arg(&gt)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("pred.ply has 3001 points") && err.contains("cube.ply has 3000"),
        "{err}"
    );

    // Same count, other order.
    let (mut geom, _) = crease::io::read(&gt, &ReadOptions::default()).unwrap();
    let n = geom.points.len();
    let rev: Vec<usize> = (0..n).rev().collect();
    geom.points = geom.points.select(&rev);
    geom.points
        .set_attribute(Attribute::flag("sharp", vec![false; n]))
        .unwrap();
    let shuffled = dir.path().join("shuffled.ply");
    crease::io::write(&shuffled, &geom, &WriteOptions::default()).unwrap();
    let out = crease()
        .arg("eval")
        .arg(&shuffled)
        .arg("--gt")
        .arg(&gt)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("point 0 differs: ")
            && err.contains("shuffled.ply")
            && err.contains("different order"),
        "{err}"
    );

    // No label property in PRED.
    let out = crease()
        .arg("eval")
        .arg(&gt)
        .arg("--gt")
        .arg(&gt)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cube.ply: no per-point property \"sharp\""),
        "{err}"
    );

    // Usage errors: exit code 2; the ROC CSV may not overwrite an input.
    let out = crease()
        .arg("eval")
        .arg(&gt)
        .arg("--gt")
        .arg(&gt)
        .arg("--gt-colors")
        .arg("--gt-label")
        .arg("x")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let out = crease()
        .arg("eval")
        .arg(&pred)
        .arg("--gt")
        .arg(&gt)
        .arg("--roc")
        .arg(&gt)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(std::fs::metadata(&gt).unwrap().len() > 0);
}

#[test]
fn pcednet_colour_classes_as_ground_truth() {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data/points-gt/default/TwoPlane90.ply");
    if !d.is_file() {
        assert!(
            std::env::var("CI").map(|v| v != "true").unwrap_or(true),
            "CI=true but {} is missing",
            d.display()
        );
        return;
    }
    // A prediction marking the sharp-coloured points: F1 = 1, the smooth class all negative.
    let dir = tempfile::tempdir().unwrap();
    let (mut geom, _) = crease::io::read(&d, &ReadOptions::default()).unwrap();
    let sharp: Vec<bool> = geom
        .points
        .colors
        .as_ref()
        .unwrap()
        .iter()
        .map(|c| c[1] == 0 && c[2] == 0 && c[0] > 0)
        .collect();
    geom.points
        .set_attribute(Attribute::flag("sharp", sharp))
        .unwrap();
    let pred = dir.path().join("pred.ply");
    crease::io::write(&pred, &geom, &WriteOptions::default()).unwrap();
    let out = crease()
        .args(["eval", "--json", "--gt-colors"])
        .arg(&pred)
        .arg("--gt")
        .arg(&d)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = json_of(&out.stdout);
    assert_eq!(v["metrics"]["f1"], 1.0);
    assert_eq!(v["ground_truth"]["source"], "colour classes");
    let rows = v["classes"].as_array().unwrap();
    let row = |k: &str| rows.iter().find(|r| r["class"] == k).unwrap().clone();
    assert_eq!(
        (
            row("flat")["count"].as_u64(),
            row("flat")["predicted_positive"].as_u64()
        ),
        (Some(5871), Some(0))
    );
    assert_eq!(
        (
            row("sharp")["count"].as_u64(),
            row("sharp")["predicted_positive"].as_u64()
        ),
        (Some(36), Some(36))
    );
    assert_eq!(
        (
            row("smooth")["count"].as_u64(),
            row("smooth")["predicted_positive"].as_u64()
        ),
        (Some(95), Some(0))
    );
    assert!(v["roc"].is_null());
}
