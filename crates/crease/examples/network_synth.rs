//! The curve network of the synthetic parts under noise, anchored on surfaces
//! (`crease::network`, what `crease network` does) and from the points alone (Demarsin's graph,
//! `crease network --lines-from points`), scored against the exact curves.
//!
//! `cargo run --release -p crease --example network_synth [N] [SIGMA,...] [MODE,...] [PART,...]`
//! (defaults: 100000 points; σ = 0.5 and 1 spacing; noise along the normal and isotropic; cube,
//! box-hole, two-cylinders, fillet-chamfer-cone, rounded-cube).
//!
//! Per part, noise and method: polylines (sharp / smooth / boundary), junctions, free ends, the
//! true network's curves, the least coverage of a true curve (the fraction of it within 2
//! spacings of a line), the precision (the fraction of the lines' length within 2 spacings of a
//! true curve), and the seconds (analysis included).

use std::time::Instant;

use crease::analysis::{AnalysisParams, CloudAnalysis};
use crease::eval::score_curves;
use crease::fillets::{curve_network, extract_fillets, CurveNetwork, FilletParams};
use crease::network::{cloud_network, NetworkSummary};
use crease::synth::{self, CurveKind, Noise, NoiseScale, SampleParams, Shape};

fn polylines(net: &CurveNetwork, boundary: bool) -> Vec<Vec<[f64; 3]>> {
    net.polylines
        .iter()
        .zip(&net.boundary)
        .filter(|(_, &b)| b == boundary)
        .map(|(l, _)| l.iter().map(|&v| net.vertices[v as usize]).collect())
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let sigmas: Vec<f64> = args
        .get(2)
        .map(|s| s.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![0.5, 1.0]);
    let list = |i: usize, default: &[&str]| -> Vec<String> {
        args.get(i)
            .map(|s| s.split(',').map(str::to_owned).collect())
            .unwrap_or_else(|| default.iter().map(|s| s.to_string()).collect())
    };
    let modes = list(3, &["normal", "isotropic"]);
    let parts = list(
        4,
        &[
            "cube",
            "box-hole",
            "two-cylinders",
            "fillet-chamfer-cone",
            "rounded-cube",
        ],
    );
    println!(
        "| part | noise | method | sharp / smooth / boundary | junctions | free ends | true curves | coverage min | precision | seconds |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for name in &parts {
        let Some(shape) = Shape::from_name(name) else {
            eprintln!("unknown part {name}");
            continue;
        };
        for mode in &modes {
            for &sigma in &sigmas {
                let noise = match mode.as_str() {
                    "isotropic" => Noise::Isotropic(sigma),
                    _ => Noise::AlongNormal(sigma),
                };
                let part = match synth::sample_points(
                    &shape,
                    &SampleParams {
                        n,
                        noise,
                        noise_scale: NoiseScale::Spacing,
                        ..Default::default()
                    },
                ) {
                    Ok(p) => p,
                    Err(e) => {
                        eprintln!("{name}: {e}");
                        continue;
                    }
                };
                let truth: Vec<(Vec<[f64; 3]>, bool)> = part
                    .curves
                    .iter()
                    .filter(|c| c.kind != CurveKind::Boundary)
                    .map(|c| (c.points.clone(), c.closed))
                    .collect();
                let points = &part.cloud.positions;
                for method in ["surfaces", "points"] {
                    let t = Instant::now();
                    let (net, summary) = if method == "surfaces" {
                        let analysis = match CloudAnalysis::new(points, AnalysisParams::default()) {
                            Ok(a) => a,
                            Err(e) => {
                                eprintln!("{name}: {e}");
                                continue;
                            }
                        };
                        match cloud_network(&analysis, &FilletParams::default(), false) {
                            Ok(r) => (r.network, r.summary),
                            Err(e) => {
                                eprintln!("{name}: {e}");
                                continue;
                            }
                        }
                    } else {
                        match extract_fillets(points, &FilletParams::default(), true) {
                            Ok(f) => {
                                let net = curve_network(&f);
                                let s = NetworkSummary::new(&net, 0, None);
                                (net, s)
                            }
                            Err(e) => {
                                eprintln!("{name}: {e}");
                                continue;
                            }
                        }
                    };
                    let secs = t.elapsed().as_secs_f64();
                    let scores = score_curves(&truth, &polylines(&net, false), 2.0 * part.spacing);
                    if std::env::var("NETWORK_DEBUG").is_ok() {
                        for (c, f) in part
                            .curves
                            .iter()
                            .filter(|c| c.kind != CurveKind::Boundary)
                            .zip(&scores.coverage)
                            .filter(|(_, &f)| f < 0.95)
                        {
                            eprintln!(
                                "{name} {mode} {sigma} {method}: {:?} curve {:?} covered {f:.3}",
                                c.kind, c.geometry
                            );
                        }
                    }
                    println!(
                        "| {name} | {mode} {sigma} | {method} | {} / {} / {} | {} | {} | {} | {:.3} | {:.3} | {:.2} |{}",
                        summary.sharp_polylines,
                        summary.smooth_polylines,
                        summary.boundary_polylines,
                        summary.junctions,
                        summary.endpoints,
                        truth.len(),
                        scores.coverage_min(),
                        scores.precision,
                        secs,
                        summary.not_anchored.map(|w| format!(" {w}")).unwrap_or_default()
                    );
                }
            }
        }
    }
}
