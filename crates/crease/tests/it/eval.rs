//! Evaluation against ground truth: every PCEDNet benchmark file's colour classes read and
//! counted, and a synthetic cube scored against its own (perturbed) labels with exact values.

use crate::common;

use std::path::Path;

use crease::eval::{
    check_same_points, evaluate, read_truth, truth_from_colors, ClassCounts, Confusion, EvalParams,
    Labels, PointClass, TruthSource,
};
use crease::io::{read_cloud, ReadOptions};
use crease::synth::{attr, sample_points, SampleParams, Shape};

fn ply_files(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .expect("readable directory")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ply"))
        .collect();
    v.sort();
    v
}

fn counts_of(path: &Path) -> (ClassCounts, usize) {
    let (cloud, _) = read_cloud(path, &ReadOptions::default()).expect("readable PLY");
    let t = truth_from_colors(&cloud, path).expect("PCEDNet colours");
    // The automatic choice finds the colours too (these files carry no label property).
    let auto = read_truth(&cloud, &TruthSource::Auto, path).expect("automatic truth");
    assert_eq!(auto, t, "{}", path.display());
    assert_eq!(t.len(), cloud.len());
    (t.class_counts(), cloud.len())
}

#[test]
fn every_pcednet_file_has_plausible_class_counts() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    let dir = dir.join("points-gt");
    let mut seen = 0;
    for sub in ["abc", "abc-noisy"] {
        let files = ply_files(&dir.join(sub));
        assert_eq!(files.len(), 8, "{sub}");
        for f in files {
            let (c, n) = counts_of(&f);
            let frac = c.sharp as f64 / n as f64;
            eprintln!(
                "{sub}/{}: {n} points, {c:?}, sharp {:.2} %",
                f.file_name().unwrap().to_string_lossy(),
                100.0 * frac
            );
            assert!(
                (0.005..=0.15).contains(&frac),
                "{}: sharp fraction {frac}",
                f.display()
            );
            assert_eq!(c.smooth, 0, "{}", f.display());
            assert!((6_000..=90_000).contains(&n), "{}: {n}", f.display());
            if sub == "abc" {
                // The noisy twin has the same points (moved) with the same classes.
                let noisy = dir.join("abc-noisy").join(f.file_name().unwrap());
                let (cn, nn) = counts_of(&noisy);
                assert_eq!((cn, nn), (c, n), "{}", noisy.display());
            }
            seen += 1;
        }
    }
    // Exact anchors, counted once by hand from the colours.
    assert_eq!(
        counts_of(&dir.join("abc/7031.ply")).0,
        ClassCounts {
            flat: 10612,
            sharp: 64,
            smooth: 0
        }
    );
    assert_eq!(
        counts_of(&dir.join("default/TwoPlane90.ply")).0,
        ClassCounts {
            flat: 5871,
            sharp: 36,
            smooth: 95
        }
    );
    let files = ply_files(&dir.join("default"));
    assert_eq!(files.len(), 7);
    for f in files {
        let (c, n) = counts_of(&f);
        eprintln!(
            "default/{}: {n} points, {c:?}",
            f.file_name().unwrap().to_string_lossy()
        );
        assert_eq!(c.total(), n as u64);
        assert!(c.sharp > 0 && c.flat > c.sharp, "{}: {c:?}", f.display());
        seen += 1;
    }
    assert_eq!(seen, 23);
}

fn cube(n: usize) -> crease::PointCloud {
    sample_points(
        &Shape::default_cube(),
        &SampleParams {
            n,
            seed: 5,
            ..Default::default()
        },
    )
    .expect("synthetic cube")
    .cloud
}

#[test]
fn synthetic_cube_scored_against_its_own_perturbed_labels() {
    let cloud = cube(20_000);
    let path = Path::new("cube.ply");
    let truth = read_truth(&cloud, &TruthSource::Auto, path).unwrap();
    assert_eq!(truth.source, "property gt_sharp");
    // The cube has only sharp edges: classes flat and sharp.
    let counts = truth.class_counts();
    assert_eq!(counts.smooth, 0);
    assert!(counts.sharp > 500, "{counts:?}");
    let (p, n) = (counts.sharp, counts.flat);

    // Perfect prediction.
    let perfect = evaluate(
        &Labels {
            predicted: &truth.sharp,
            truth: &truth.sharp,
            scores: None,
            positions: Some(&cloud.positions),
            classes: truth.classes.as_deref(),
        },
        &EvalParams::default(),
    )
    .unwrap();
    assert_eq!(
        perfect.confusion,
        Confusion {
            tp: p,
            fp: 0,
            tn: n,
            fn_: 0
        }
    );
    let m = perfect.metrics;
    assert_eq!(
        (m.precision, m.recall, m.f1, m.iou, m.accuracy),
        (1.0, 1.0, 1.0, 1.0, 1.0)
    );
    assert!((m.mcc - 1.0).abs() < 1e-15);
    let t = perfect.tolerant.unwrap();
    assert_eq!((t.precision, t.recall, t.f1), (1.0, 1.0, 1.0));

    // Deterministic perturbation: every 4th sharp point missed, every 50th flat point far from
    // the edges (>= 5 spacings) wrongly marked.
    let dist = &cloud.attribute(attr::EDGE_DISTANCE).unwrap().values;
    let spacing = crease::spatial::average_spacing(&cloud.positions).unwrap();
    let (mut k_sharp, mut k_flat) = (0usize, 0usize);
    let mut pred = truth.sharp.clone();
    let (mut missed, mut wrong) = (0u64, 0u64);
    for i in 0..pred.len() {
        if truth.sharp[i] {
            if k_sharp % 4 == 0 {
                pred[i] = false;
                missed += 1;
            }
            k_sharp += 1;
        } else if dist[i] >= 5.0 * spacing {
            if k_flat % 50 == 0 {
                pred[i] = true;
                wrong += 1;
            }
            k_flat += 1;
        }
    }
    assert_eq!(missed, p.div_ceil(4));
    // A continuous score: minus the distance to the edge, exact for the ROC.
    let score: Vec<f64> = dist.iter().map(|d| -d).collect();
    let r = evaluate(
        &Labels {
            predicted: &pred,
            truth: &truth.sharp,
            scores: Some(&score),
            positions: Some(&cloud.positions),
            classes: truth.classes.as_deref(),
        },
        &EvalParams::default(),
    )
    .unwrap();
    let (tp, fp, tn, fn_) = (p - missed, wrong, n - wrong, missed);
    assert_eq!(r.confusion, Confusion { tp, fp, tn, fn_ });
    let m = r.metrics;
    let f = |x: u64| x as f64;
    assert_eq!(m.precision, f(tp) / f(tp + fp));
    assert_eq!(m.recall, f(tp) / f(tp + fn_));
    assert_eq!(m.f1, f(2 * tp) / f(2 * tp + fp + fn_));
    assert_eq!(m.iou, f(tp) / f(tp + fp + fn_));
    let mcc = (f(tp) * f(tn) - f(fp) * f(fn_))
        / (f(tp + fp) * f(tp + fn_) * f(tn + fp) * f(tn + fn_)).sqrt();
    assert!((m.mcc - mcc).abs() < 1e-12, "{} {mcc}", m.mcc);
    // Tolerant: checked against a brute-force count. The wrong flat points are at least 5
    // spacings (more than the 2-spacing tolerance) from every sharp point.
    let t = r.tolerant.unwrap();
    assert!((t.tolerance - 2.0 * spacing).abs() < 1e-12);
    let near = |i: usize, set: &[bool]| {
        let q = cloud.positions[i];
        (0..set.len()).any(|j| {
            set[j] && {
                let o = cloud.positions[j];
                (0..3).map(|k| (q[k] - o[k]).powi(2)).sum::<f64>() <= t.tolerance * t.tolerance
            }
        })
    };
    let truth_matched = (0..pred.len())
        .filter(|&i| truth.sharp[i] && near(i, &pred))
        .count() as u64;
    assert_eq!((t.truth, t.truth_matched), (p, truth_matched));
    assert_eq!((t.predicted, t.predicted_matched), (tp + fp, tp));
    assert_eq!(t.precision, f(tp) / f(tp + fp));
    assert_eq!(t.recall, f(truth_matched) / f(p));
    // Most missed points have a found neighbour: tolerant recall well above the exact 3/4.
    assert!(t.recall > 0.93, "{t:?}");
    // The truth is "distance <= tolerance", so minus the distance separates it perfectly.
    let roc = r.roc.unwrap();
    assert_eq!(roc.auc, 1.0);
    assert_eq!((roc.positives, roc.negatives), (p, n));
    assert!(roc.curve.len() <= 101);
    let rows = r.classes.unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(
        (rows[0].class, rows[0].count, rows[0].predicted_positive),
        (PointClass::Flat, n, wrong)
    );
    assert_eq!(
        (rows[1].class, rows[1].count, rows[1].predicted_positive),
        (PointClass::Sharp, p, tp)
    );
}

#[test]
fn a_thin_detection_is_scored_fairly_by_the_tolerant_variant() {
    // Truth: the band within one expected spacing of the edges (about 2 average spacings, so
    // the band is some 4 points wide); detection: the band within half of that (a line about
    // one point wide).
    let part = sample_points(
        &Shape::default_cube(),
        &SampleParams {
            n: 20_000,
            seed: 9,
            ..Default::default()
        },
    )
    .unwrap();
    let cloud = &part.cloud;
    let truth = read_truth(cloud, &TruthSource::Auto, Path::new("cube.ply")).unwrap();
    let dist = &cloud.attribute(attr::EDGE_DISTANCE).unwrap().values;
    let pred: Vec<bool> = dist.iter().map(|&d| d <= 0.5 * part.spacing).collect();
    let labels = Labels {
        predicted: &pred,
        truth: &truth.sharp,
        scores: None,
        positions: Some(&cloud.positions),
        classes: None,
    };
    let r = evaluate(&labels, &EvalParams::default()).unwrap();
    let sp = crease::spatial::average_spacing(&cloud.positions).unwrap();
    let wide = evaluate(
        &labels,
        &EvalParams {
            tolerance: Some(4.0 * sp),
            ..Default::default()
        },
    )
    .unwrap();
    let (t, w) = (r.tolerant.unwrap(), wide.tolerant.unwrap());
    eprintln!(
        "thin detection: exact recall {:.3}, tolerant recall {:.3} at 2 spacings, {:.3} at 4",
        r.metrics.recall, t.recall, w.recall
    );
    // Measured: 0.526, 0.863, 0.990.
    assert_eq!(r.metrics.precision, 1.0);
    assert!((0.45..0.55).contains(&r.metrics.recall), "{:?}", r.metrics);
    assert_eq!((t.precision, w.precision), (1.0, 1.0));
    assert!(t.recall > 0.84, "{t:?}");
    assert!(w.recall > 0.98, "{w:?}");
}

#[test]
fn pred_and_truth_must_list_the_same_points() {
    let a = cube(2000);
    let b = cube(2001);
    let e = check_same_points(
        &b.positions,
        Path::new("p.ply"),
        &a.positions,
        Path::new("g.ply"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("p.ply has 2001 points, g.ply has 2000"),
        "{e}"
    );
    let mut idx: Vec<usize> = (0..a.len()).collect();
    idx.swap(10, 20);
    let swapped = a.select(&idx);
    let e = check_same_points(
        &swapped.positions,
        Path::new("p.ply"),
        &a.positions,
        Path::new("g.ply"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("point 10 differs")
            && e.contains("2 of 2000")
            && e.contains("different order"),
        "{e}"
    );
}
