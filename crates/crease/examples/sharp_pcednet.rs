//! Scores the sharp-point detectors on the PCEDNet benchmark models in `../shared/data/points-gt`
//! (median Matthews correlation coefficient of the sharp class, as the benchmark reports it).
//!
//! `cargo run --release -p crease --example sharp_pcednet -- [MEASURE] [raw] [nothin] [q=0.99]
//! [scales=12,16,..] [reg=K,LAMBDA,ALPHA,SLOPE] [noauto] [auto=RATIO] [sets=abc,abc-noisy,default]`
//!
//! `auto=RATIO`: the noise ratio above which the noisy path (Potts labelling, noise-widened
//! surface bands, rim distance) runs; `auto=-1` forces it (default 0.08).

use std::path::PathBuf;

use crease::eval::truth::{class_of_color, PointClass};
use crease::io::{read, ReadOptions};
use crease::sharp::{Measure, SharpParams};

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

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut params = SharpParams::default();
    let mut sets: Vec<String> = vec!["abc".into(), "abc-noisy".into(), "default".into()];
    for a in &args {
        if let Some(m) = Measure::ALL.iter().find(|m| m.name() == a) {
            params.measure = *m;
        } else if a == "uniform" {
            params.pca_weight = crease::estimate::PcaWeight::Uniform;
        } else if a == "nothin" {
            params.thin = false;
        } else if let Some(t) = a.strip_prefix("auto=") {
            params.auto_regularize = Some(t.parse()?);
        } else if a == "noauto" {
            params.auto_regularize = None;
        } else if a == "raw" {
            params.density_invariant = false;
        } else if let Some(q) = a.strip_prefix("q=") {
            params.otsu.upper_quantile = q.parse()?;
        } else if let Some(r) = a.strip_prefix("reg=") {
            let v: Vec<f64> = r.split(',').map(|x| x.parse()).collect::<Result<_, _>>()?;
            params.regularize = Some(crease::sharp::Regularize {
                k: v[0] as usize,
                lambda: v[1],
                line_reward: v[2],
                slope: v[3],
                ..Default::default()
            });
        } else if let Some(s) = a.strip_prefix("sets=") {
            sets = s.split(',').map(String::from).collect();
        } else if let Some(s) = a.strip_prefix("scales=") {
            params.scales = Some(s.split(',').map(|x| x.parse()).collect::<Result<_, _>>()?);
        }
    }
    let kmax = params
        .scales
        .as_ref()
        .map_or(40, |s| s.iter().copied().max().unwrap_or(40))
        .max(40);
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/points-gt");
    for set in &sets {
        let mut names: Vec<_> = std::fs::read_dir(root.join(set))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        names.sort();
        let mut mccs = Vec::new();
        for path in names {
            let (g, _) = read(&path, &ReadOptions::default())?;
            let cloud = g.points;
            let colors = cloud.colors.clone().ok_or("no colours")?;
            let truth: Vec<bool> = colors
                .iter()
                .map(|c| class_of_color(*c) == Some(PointClass::Sharp))
                .collect();
            let t = std::time::Instant::now();
            let nbrs = crease::spatial::knn(&cloud.positions, kmax)?;
            let r = crease::sharp::detect_points_with(&cloud.positions, &nbrs, &params)?;
            let m = mcc(&r.sharp, &truth);
            let tp = r.sharp.iter().zip(&truth).filter(|(&p, &t)| p && t).count();
            let surf = r.surfaces.as_ref().map_or(String::new(), |s| {
                format!(
                    " surf={} assigned={:.2} explained={:.2} rim={:.2} sigma={:.2}",
                    s.surfaces,
                    s.assigned as f64 / truth.len() as f64,
                    s.explained as f64 / truth.len() as f64,
                    s.rim as f64 / truth.len() as f64,
                    s.sigma
                )
            });
            println!(
                "{set}/{:<22} n={:>6} gt={:>5} pred={:>6} tp={tp:>5} mcc={m:.3} ({:.2}s) noise={:.3}{}{surf} T={:?}",
                path.file_name().unwrap_or_default().to_string_lossy(),
                truth.len(),
                truth.iter().filter(|&&x| x).count(),
                r.num_sharp(),
                t.elapsed().as_secs_f64(),
                r.noise_ratio.unwrap_or(0.0),
                if r.regularized { " potts" } else { "" },
                r.scales
                    .iter()
                    .map(|s| (s.normalized_threshold * 1000.0).round() / 1000.0)
                    .collect::<Vec<_>>()
            );
            mccs.push(m);
        }
        mccs.sort_by(f64::total_cmp);
        let med = if mccs.len() % 2 == 1 {
            mccs[mccs.len() / 2]
        } else {
            0.5 * (mccs[mccs.len() / 2 - 1] + mccs[mccs.len() / 2])
        };
        println!("{set}: median MCC {med:.3}\n");
    }
    Ok(())
}
