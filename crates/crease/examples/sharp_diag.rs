//! Diagnostics of the sharp-point detector on the PCEDNet models: confusion colours as PLY,
//! displacement of misses, best single threshold on the sharpness.
//!
//! `cargo run --release -p crease --example sharp_diag -- OUTDIR [set]`

use std::path::PathBuf;

use crease::eval::truth::{class_of_color, PointClass};
use crease::geometry::{vec3, PointCloud};
use crease::io::{read, write, Geometry, ReadOptions, WriteOptions};
use crease::sharp::{detect_points, SharpParams};
use crease::spatial::average_spacing;
use crease::spatial::knn;

fn mcc(pred: &[bool], truth: &[bool]) -> f64 {
    let (mut tp, mut fp, mut tn, mut fnn) = (0f64, 0f64, 0f64, 0f64);
    for (&p, &t) in pred.iter().zip(truth) {
        match (p, t) {
            (true, true) => tp += 1.0,
            (true, false) => fp += 1.0,
            (false, false) => tn += 1.0,
            (false, true) => fnn += 1.0,
        }
    }
    let d = ((tp + fp) * (tp + fnn) * (tn + fp) * (tn + fnn)).sqrt();
    if d > 0.0 {
        (tp * tn - fp * fnn) / d
    } else {
        0.0
    }
}

/// Best MCC over thresholds on a score (higher = sharper).
fn best_mcc(score: &[f64], truth: &[bool]) -> (f64, f64) {
    let mut idx: Vec<usize> = (0..score.len()).collect();
    idx.sort_by(|&a, &b| score[b].total_cmp(&score[a]));
    let pos = truth.iter().filter(|&&t| t).count() as f64;
    let n = truth.len() as f64;
    let (mut tp, mut fp) = (0f64, 0f64);
    let mut best = (0.0, 0.0);
    for (r, &i) in idx.iter().enumerate() {
        if truth[i] {
            tp += 1.0
        } else {
            fp += 1.0
        }
        if r + 1 < idx.len() && score[idx[r + 1]] == score[i] {
            continue;
        }
        let fnn = pos - tp;
        let tn = n - pos - fp;
        let d = ((tp + fp) * (tp + fnn) * (tn + fp) * (tn + fnn)).sqrt();
        if d > 0.0 {
            let m = (tp * tn - fp * fnn) / d;
            if m > best.0 {
                best = (m, score[i]);
            }
        }
    }
    best
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let out = PathBuf::from(args.first().cloned().unwrap_or("/tmp/diag".into()));
    std::fs::create_dir_all(&out)?;
    let sets: Vec<String> = if args.len() > 1 {
        args[1..].to_vec()
    } else {
        vec!["abc".into(), "abc-noisy".into()]
    };
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/points-gt");
    for set in &sets {
        let mut names: Vec<_> = std::fs::read_dir(root.join(set))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        names.sort();
        for path in names {
            let (g, _) = read(&path, &ReadOptions::default())?;
            let cloud = g.points;
            let colors = cloud.colors.clone().ok_or("no colours")?;
            let truth: Vec<bool> = colors
                .iter()
                .map(|c| class_of_color(*c) == Some(PointClass::Sharp))
                .collect();
            let pts = &cloud.positions;
            let h = average_spacing(pts).ok_or("spacing")?;
            let nb = knn(pts, 16)?;
            let r = detect_points(pts, &SharpParams::default())?;
            let m = mcc(&r.sharp, &truth);
            let (bm, bt) = best_mcc(&r.sharpness, &truth);
            // Truth band width: truth neighbours among the 8 nearest of a truth point.
            let tp_nb: f64 = (0..pts.len())
                .filter(|&i| truth[i])
                .map(|i| {
                    nb.prefix(i, 8)
                        .iter()
                        .filter(|&&j| truth[j as usize])
                        .count() as f64
                })
                .sum::<f64>()
                / truth.iter().filter(|&&t| t).count().max(1) as f64;
            // Distance of misses to the nearest prediction, of false detections to the nearest
            // truth (in spacings), from the 16 nearest.
            let near = |i: usize, lab: &[bool]| -> f64 {
                nb.prefix(i, 16)
                    .iter()
                    .filter(|&&j| lab[j as usize])
                    .map(|&j| vec3::dist(pts[i], pts[j as usize]) / h)
                    .fold(f64::INFINITY, f64::min)
            };
            let mut fn_d = [0usize; 4];
            let mut fp_d = [0usize; 4];
            for i in 0..pts.len() {
                let bucket = |d: f64| {
                    if d < 1.5 {
                        0
                    } else if d < 2.5 {
                        1
                    } else if d < 4.0 {
                        2
                    } else {
                        3
                    }
                };
                if truth[i] && !r.sharp[i] {
                    fn_d[bucket(near(i, &r.sharp))] += 1;
                }
                if !truth[i] && r.sharp[i] {
                    fp_d[bucket(near(i, &truth))] += 1;
                }
            }
            println!(
                "{set}/{} n={} h={h:.4} gt={} pred={} mcc={m:.3} best-thr mcc={bm:.3} at {bt:.2} truth-nb8={tp_nb:.2} FN by dist<1.5/2.5/4/inf {:?} FP {:?}",
                path.file_stem().unwrap_or_default().to_string_lossy(),
                pts.len(),
                truth.iter().filter(|&&t| t).count(),
                r.num_sharp(),
                fn_d,
                fp_d
            );
            let cols: Vec<[u8; 3]> = (0..pts.len())
                .map(|i| match (r.sharp[i], truth[i]) {
                    (true, true) => [0, 160, 0],
                    (true, false) => [230, 0, 0],
                    (false, true) => [0, 60, 255],
                    (false, false) => [215, 215, 215],
                })
                .collect();
            let mut c = PointCloud::from_positions(pts.clone());
            c.colors = Some(cols);
            let geom = Geometry {
                points: c,
                ..Default::default()
            };
            let stem = path.file_stem().unwrap_or_default().to_string_lossy();
            write(
                out.join(format!("{set}_{stem}.ply")),
                &geom,
                &WriteOptions::default(),
            )?;
        }
    }
    Ok(())
}
