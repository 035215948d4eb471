//! End-to-end tests of `crease lines`: polylines written as OBJ / PLY, the per-stage JSON
//! summary (the paper's Table 2), the segmentation output, and usage errors.

use crate::common::{crease, run, synth};
use crease::io::ReadOptions;

#[test]
fn two_cylinders_give_six_closed_loops() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(
        dir.path(),
        &["synth", "two-cylinders", "-n", "30000"],
        "c.ply",
    );
    let out = dir.path().join("lines.obj");
    let seg = dir.path().join("seg.ply");
    let a = crease()
        .arg("lines")
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .arg("--segmentation")
        .arg(&seg)
        .arg("--json")
        .assert()
        .success();
    let s: serde_json::Value = serde_json::from_slice(&a.get_output().stdout).unwrap();
    assert_eq!(s["closed_loops"], 6);
    assert_eq!(s["polylines"], 6);
    assert_eq!(s["endpoints"], 0);
    assert_eq!(s["junctions"], 0);
    let names: Vec<&str> = s["stages"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["name"].as_str().unwrap())
        // Isolated boundary flags (pruned away on a closed solid) still run the boundary stage.
        .filter(|&n| n != "boundary")
        .collect();
    assert_eq!(
        names,
        [
            "segmentation+G_all",
            "G_extended",
            "G_pruned_mst",
            "G_pruned_branches",
            "G_closed",
            "G_smooth"
        ]
    );
    let (lines, _) = crease::io::read(&out, &ReadOptions::default()).unwrap();
    assert_eq!(lines.polylines.len(), 6);
    assert!(lines.polylines.iter().all(|l| l.first() == l.last()));
    let (seg, _) = crease::io::read(&seg, &ReadOptions::default()).unwrap();
    let labels = &seg.points.attribute("cluster").unwrap().values;
    assert_eq!(labels.len(), 30000);
    let max = labels.iter().fold(0.0f64, |m, &v| m.max(v));
    assert_eq!(max as u64 + 1, s["clusters"].as_u64().unwrap());
}

/// Heavy noise (20 % of the spacing along the normal): the 1-ring normals are denoised first and
/// the cube comes out as its 12 edges and 8 corners; `--no-denoise` (the paper as written)
/// shatters its faces (measured: 203 polylines).
#[test]
fn noisy_cube_needs_the_normal_denoising() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(
        dir.path(),
        &["synth", "cube", "-n", "20000", "--noise", "0.2"],
        "c.ply",
    );
    let out = dir.path().join("lines.obj");
    let run = |extra: &[&str]| -> serde_json::Value {
        let a = crease()
            .arg("lines")
            .arg(&input)
            .arg("-o")
            .arg(&out)
            .arg("--json")
            .args(extra)
            .assert()
            .success();
        serde_json::from_slice(&a.get_output().stdout).unwrap()
    };
    let s = run(&[]);
    assert_eq!(s["polylines"], 12, "{s}");
    assert_eq!(s["junctions"], 8);
    assert_eq!(s["endpoints"], 0);
    let raw = run(&["--no-denoise"]);
    assert!(raw["polylines"].as_u64().unwrap() > 50, "{raw}");
}

#[test]
fn usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), &["synth", "cube", "-n", "15"], "tiny.ply");
    let out = dir.path().join("o.obj");
    let a = run("lines", &input, &out, &[]).failure().code(1);
    let err = String::from_utf8_lossy(&a.get_output().stderr).to_string();
    assert!(
        err.contains("tiny.ply") && err.contains("15 points"),
        "{err}"
    );
    // Plain option names, and the paper's symbols as aliases.
    for bad in [
        vec!["--alpha-max", "0"],
        vec!["--region-angle", "95"],
        vec!["-k", "2"],
        vec!["--neighbours", "2"],
        vec!["--spur-length", "0"],
        vec!["--close-candidates", "0"],
        vec!["--n", "0"],
    ] {
        let a = run("lines", &input, &out, &bad).failure().code(2);
        let err = String::from_utf8_lossy(&a.get_output().stderr).to_string();
        assert!(err.contains("invalid argument"), "{bad:?}: {err}");
    }
    run("lines", &input, &input, &[]).failure().code(2);
}
