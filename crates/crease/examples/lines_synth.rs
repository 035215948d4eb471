//! Demarsin 2007 Table 1 / Table 2 and accuracy of the closed sharp lines on the synthetic parts.
//!
//! `cargo run --release -p crease --example lines_synth [N] [NOISE,NOISE,...] [PART,PART,...]`
//! (defaults: 20000 points; noise 0, 1, 5, 10 and 20 % of the spacing along the normal; every
//! part with sharp curves).
//!
//! Per part and noise: Table 1 (points, average small-cluster size, number of small clusters),
//! Table 2 (vertices / edges of every graph), the topology of the result (polylines, closed
//! loops, junctions, endpoints), the coverage of the exact sharp curves (fraction of each curve's
//! samples within 2 spacings of a network edge; the minimum over the curves), the precision
//! (fraction of network edge length within 2 spacings of a sharp curve) and the farthest
//! network vertex from the curves in spacings. `LINES_DEBUG=1` lists the curves covered less
//! than 95 %; `LINES_RAW=1` scores the vertices before smoothing (step 7).

use std::time::Instant;

use crease::geometry::Point3;
use crease::lines::{extract_lines, LinesParams};
use crease::synth::{self, CurveKind, Noise, NoiseScale, SampleParams, Shape, SyntheticPart};

fn sample(name: &str, n: usize, noise: f64) -> Option<SyntheticPart> {
    synth::sample_points(
        &Shape::from_name(name)?,
        &SampleParams {
            n,
            noise: if noise > 0.0 {
                Noise::AlongNormal(noise)
            } else {
                Noise::None
            },
            noise_scale: NoiseScale::Spacing,
            ..Default::default()
        },
    )
    .ok()
}

fn near_curves(part: &SyntheticPart, p: Point3) -> f64 {
    part.curves
        .iter()
        .filter(|c| c.kind == CurveKind::Sharp)
        .map(|c| c.distance(p))
        .fold(f64::INFINITY, f64::min)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let n: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let noises: Vec<f64> = args
        .get(2)
        .map(|s| s.split(',').filter_map(|v| v.parse().ok()).collect())
        .unwrap_or_else(|| vec![0.0, 0.01, 0.05, 0.1, 0.2]);
    let parts: Vec<String> = args
        .get(3)
        .map(|s| s.split(',').map(str::to_owned).collect())
        .unwrap_or_else(|| {
            ["cube", "box-hole", "two-cylinders", "fillet-chamfer-cone"]
                .iter()
                .map(|s| s.to_string())
                .collect()
        });
    println!(
        "| part | noise | points | small | avg size | G_all | G_ext | G_mst | G_branches | G_closed \
         | polylines | loops | junctions | ends | coverage min | precision | farthest | seconds |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for name in &parts {
        for &noise in &noises {
            let Some(part) = sample(name, n, noise) else {
                eprintln!("unknown part {name}");
                continue;
            };
            let t = Instant::now();
            let net = match extract_lines(&part.cloud.positions, &LinesParams::default()) {
                Ok(net) => net,
                Err(e) => {
                    eprintln!("{name} {noise}: {e}");
                    continue;
                }
            };
            let secs = t.elapsed().as_secs_f64();
            let mut net = net;
            if std::env::var("LINES_RAW").is_ok() {
                net.vertices = net.unsmoothed.clone();
            }
            let tol = 2.0 * part.spacing;
            let coverage = part
                .curves
                .iter()
                .filter(|c| c.kind == CurveKind::Sharp)
                .map(|c| {
                    let hit = c
                        .points
                        .iter()
                        .filter(|&&p| {
                            net.edges.iter().any(|e| {
                                synth::segment_distance(
                                    p,
                                    net.vertices[e[0] as usize],
                                    net.vertices[e[1] as usize],
                                ) <= tol
                            })
                        })
                        .count();
                    let f = hit as f64 / c.points.len().max(1) as f64;
                    if std::env::var("LINES_DEBUG").is_ok() && f < 0.95 {
                        eprintln!(
                            "{name} {noise}: curve {:?} ({} samples, from {:?} to {:?}) covered {f:.3}",
                            c.geometry,
                            c.points.len(),
                            c.points.first(),
                            c.points.last()
                        );
                    }
                    f
                })
                .fold(1.0, f64::min);
            // Precision by length: each edge sampled at 5 points.
            let (mut good, mut total) = (0.0, 0.0);
            for e in &net.edges {
                let (a, b) = (net.vertices[e[0] as usize], net.vertices[e[1] as usize]);
                let len = crease::geometry::vec3::dist(a, b);
                for s in 0..5 {
                    let t = (s as f64 + 0.5) / 5.0;
                    let p = [
                        a[0] + t * (b[0] - a[0]),
                        a[1] + t * (b[1] - a[1]),
                        a[2] + t * (b[2] - a[2]),
                    ];
                    total += len / 5.0;
                    if near_curves(&part, p) <= tol {
                        good += len / 5.0;
                    }
                }
            }
            let precision = if total > 0.0 { good / total } else { 0.0 };
            let far = net
                .vertices
                .iter()
                .map(|&v| near_curves(&part, v))
                .fold(0.0, f64::max)
                / part.spacing;
            let small_sizes: Vec<u32> = net
                .segmentation
                .sizes
                .iter()
                .copied()
                .filter(|&s| (s as f64) < mean(&net.segmentation.sizes))
                .collect();
            let avg_small = small_sizes.iter().map(|&s| s as f64).sum::<f64>()
                / small_sizes.len().max(1) as f64;
            let st = |i: usize| {
                net.stages
                    .get(i)
                    .map(|s| format!("{}/{}", s.vertices, s.edges))
                    .unwrap_or_default()
            };
            let closed = net
                .stages
                .iter()
                .find(|s| s.name == "G_closed")
                .map(|s| format!("{}/{}", s.vertices, s.edges))
                .unwrap_or_default();
            println!(
                "| {name} | {:.0} % | {} | {} | {:.2} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.2} | {:.2} |",
                noise * 100.0,
                part.cloud.positions.len(),
                net.small_clusters,
                avg_small,
                st(0),
                st(1),
                st(2),
                st(3),
                closed,
                net.polylines.len(),
                net.closed_loops(),
                net.junctions(),
                net.endpoints(),
                coverage,
                precision,
                far,
                secs
            );
        }
    }
}

fn mean(v: &[u32]) -> f64 {
    v.iter().map(|&s| s as f64).sum::<f64>() / v.len().max(1) as f64
}
