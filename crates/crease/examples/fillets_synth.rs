//! Fillet lines (demarsin2008) on a synthetic part, against its exact smooth curves.
//!
//! `cargo run --release -p crease --example fillets_synth -- SHAPE N NOISE [SMOOTH_ITERS]`
//! (noise in spacings along the normal), e.g. `rounded-cube 100000 0.05`.

use crease::fillets::{extract_fillets, FilletParams};
use crease::synth::{self, CurveKind, Noise, NoiseScale, SampleParams, Shape};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let shape =
        Shape::from_name(args.get(1).map_or("rounded-cube", |s| s.as_str())).expect("shape");
    let n: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let noise: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(0.0);
    let iters: usize = args.get(4).and_then(|s| s.parse().ok()).unwrap_or(0);
    let part = synth::sample_points(
        &shape,
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
    .expect("sample");
    let params = FilletParams {
        smoothing_iterations: iters,
        coarse_retry: std::env::var("FILLET_RETRY").is_ok(),
        median_iterations: std::env::var("FILLET_MED")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1),
        curvature_k: std::env::var("FILLET_K")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(20),
        ..Default::default()
    };
    let t = std::time::Instant::now();
    let f = extract_fillets(&part.cloud.positions, &params, true).expect("fillets");
    let secs = t.elapsed().as_secs_f64();
    println!(
        "{} points, spacing {:.4}, {:.2} s {:?}",
        n, part.spacing, secs, f.seconds
    );
    for r in &f.regions {
        println!(
            "region {} ({} points) range {:.3?}",
            r.cluster, r.points, r.histogram_range
        );
        for t in &r.thresholds {
            println!(
                "  {:.3?} tau {:.3} ratio {:.2} b {} {} {} k {} contrast {:.2} acc {} high {} inner {} border {} noisy {} bands {} {} lines {} loops {}",
                t.interval, t.split.tau, t.split.ratio, t.split.b1, t.split.b2, t.split.b3, t.split.joined, t.contrast, t.accepted, t.high, t.inner, t.border, t.noisy,
                t.band_interiors[0], t.band_interiors[1], t.polylines, t.closed_loops
            );
        }
    }
    if std::env::var("FILLET_DEBUG").is_ok() {
        // Rounded cube classes by position: plane (no coordinate beyond 0.4), fillet (one),
        // corner (two or more).
        let mut by: [Vec<f64>; 3] = Default::default();
        for (p, &c) in part.cloud.positions.iter().zip(&f.curvature) {
            if c.is_finite() {
                let k = p
                    .iter()
                    .filter(|x| x.abs() > 0.4)
                    .count()
                    .saturating_sub(1)
                    .min(2);
                by[k].push(c);
            }
        }
        for (name, v) in ["plane", "fillet", "corner"].iter().zip(by.iter_mut()) {
            v.sort_by(f64::total_cmp);
            let q = |f: f64| {
                v.get(((v.len() as f64 - 1.0) * f) as usize)
                    .copied()
                    .unwrap_or(f64::NAN)
            };
            println!(
                "{name}: {} points, q05 {:.2} q25 {:.2} q50 {:.2} q75 {:.2} q95 {:.2}",
                v.len(),
                q(0.05),
                q(0.25),
                q(0.5),
                q(0.75),
                q(0.95)
            );
        }
    }
    let l = &f.lines;
    println!(
        "smooth lines: {} polylines, {} closed, {} junctions, {} endpoints, {} vertices",
        l.polylines.len(),
        l.closed_loops(),
        l.junctions(),
        l.endpoints(),
        l.vertices.len()
    );
    if let Some(s) = &f.sharp {
        println!(
            "sharp lines: {} polylines, {} closed",
            s.polylines.len(),
            s.closed_loops()
        );
    }
    let tol = 2.0 * part.spacing;
    let smooth: Vec<_> = part
        .curves
        .iter()
        .filter(|c| c.kind == CurveKind::Smooth)
        .collect();
    let mut covered = 0;
    for c in &smooth {
        let near = c
            .points
            .iter()
            .filter(|&&p| {
                l.edges.iter().any(|e| {
                    synth::segment_distance(p, l.vertices[e[0] as usize], l.vertices[e[1] as usize])
                        <= tol
                })
            })
            .count();
        let frac = near as f64 / c.points.len().max(1) as f64;
        if frac >= 0.9 {
            covered += 1;
        }
        print!("{frac:.2} ");
    }
    println!();
    let dists: Vec<f64> = l
        .vertices
        .iter()
        .map(|&v| {
            smooth
                .iter()
                .map(|c| c.distance(v))
                .fold(f64::INFINITY, f64::min)
                / part.spacing
        })
        .collect();
    let far = dists.iter().filter(|&&d| d > 2.0).count();
    let mut sorted = dists.clone();
    sorted.sort_by(f64::total_cmp);
    println!(
        "smooth curves covered (>=90% within 2 spacings): {covered}/{}; vertices > 2 spacings from a smooth curve: {far}/{}; median {:.2} p95 {:.2} spacings",
        smooth.len(),
        dists.len(),
        sorted.get(sorted.len() / 2).copied().unwrap_or(0.0),
        sorted.get(sorted.len() * 95 / 100).copied().unwrap_or(0.0)
    );
}

#[allow(dead_code)]
fn unused() {}
