//! End-to-end tests of `crease fillets` and `crease network`: the fillet lines of the block
//! with a fillet and a chamfer, the tagged curve network, the per-point labels, and usage
//! errors.

use crate::common::{json_of, run, synth};
use crease::io::ReadOptions;

#[test]
fn network_of_the_fillet_block() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(
        dir.path(),
        &["synth", "fillet-chamfer-cone", "-n", "60000"],
        "f.ply",
    );
    let out = dir.path().join("net.obj");
    let labels = dir.path().join("labels.ply");
    let a = run(
        "network",
        &input,
        &out,
        &["--json", "--labels", labels.to_str().unwrap()],
    )
    .success();
    let s = json_of(&a.get_output().stdout);
    // The two fillet borders, each joined at both ends to the sharp lines of the end faces.
    assert_eq!(s["network"]["smooth_polylines"], 2, "{s}");
    assert_eq!(s["network"]["joined_smooth_ends"], 4, "{s}");
    assert_eq!(s["network"]["open_smooth_ends"], 0, "{s}");
    assert!(
        s["network"]["sharp_polylines"].as_u64().unwrap() >= 10,
        "{s}"
    );
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.contains("\ng sharp\n") && text.contains("\ng smooth\n"));
    // One accepted threshold, in the region of the fillet, between |H| = 0 (planes) and
    // |H| = 10 (the fillet of radius 0.1).
    let taus: Vec<f64> = s["regions"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|r| r["thresholds"].as_array().unwrap().iter())
        .filter(|t| t["accepted"] == true)
        .map(|t| t["split"]["tau"].as_f64().unwrap())
        .collect();
    assert_eq!(taus.len(), 1, "{taus:?}");
    assert!(taus[0] > 0.0 && taus[0] < 10.0, "{taus:?}");
    // Labels: every point has one; border points lie on the fillet (|H| between the planes'
    // and the fillet's curvature is where the threshold put them).
    let (g, _) = crease::io::read(&labels, &ReadOptions::default()).unwrap();
    let attr = |name: &str| g.points.attribute(name).unwrap().values.clone();
    let smooth_edge = attr("smooth_edge");
    let gt_dist = attr("gt_smooth_distance");
    // The part's surface area is about 3.5, so the spacing is about sqrt(3.5 / n).
    let spacing = (3.5f64 / 60000.0).sqrt();
    let on_edge: Vec<f64> = smooth_edge
        .iter()
        .zip(&gt_dist)
        .filter(|(s, _)| **s > 0.0)
        .map(|(_, d)| *d)
        .collect();
    assert!(on_edge.len() > 100, "{}", on_edge.len());
    let near = on_edge.iter().filter(|&&d| d <= 2.0 * spacing).count();
    assert!(
        near as f64 >= 0.9 * on_edge.len() as f64,
        "{near} of {}",
        on_edge.len()
    );
}

#[test]
fn fillets_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), &["synth", "sphere", "-n", "2000"], "s.ply");
    let out = dir.path().join("x.obj");
    for bad in [
        &["--thresholds", "many"][..],
        &["--trim", "0.7"][..],
        &["--curvature-k", "2"][..],
        &["--tau=-1"][..],
    ] {
        let a = run("fillets", &input, &out, bad).failure().code(2);
        let err = String::from_utf8_lossy(&a.get_output().stderr).to_string();
        assert!(err.contains("error"), "{bad:?}: {err}");
    }
    // A sphere has no fillet: no line, and the command says so without failing.
    let a = run("fillets", &input, &out, &["--json"]).success();
    assert_eq!(json_of(&a.get_output().stdout)["polylines"], 0);
}
