//! Wall and CPU time of the fused kNN + PCA normals (`pca_normals_direct`, k = 20) and of the
//! plain kNN on the faces of the synthetic cube, in sampling (random) and Morton-sorted order,
//! best of R runs, I/O excluded.
//!
//! `cargo run --release -p crease --example normals_timing -- [N=1000000] [R=5]`
//!
//! With a file instead of N (`normals_timing FILE.ply R`), only the fused normals on that file's
//! points, in its order, best of R in one process: the way `scripts/pcl_normals.cpp` times
//! PCL and the Open3D part of `scripts/compare-normals.sh` times Open3D.

use std::time::Instant;

use crease::estimate::normals::pca_normals_direct;
use crease::estimate::PcaParams;
use crease::geometry::Point3;
use crease::spatial::{knn, morton_order};
use crease::synth::{sample_points, SampleParams, Shape};

/// Process CPU time (user + system) in seconds, from /proc/self/stat (0 where unavailable).
fn cpu() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let f: Vec<&str> = s
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let t = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (t(11) + t(12)) / 100.0
}

fn best_of(reps: usize, mut f: impl FnMut()) -> (f64, f64) {
    let (mut wall, mut cpu_best) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..reps {
        let (t, c) = (Instant::now(), cpu());
        f();
        wall = wall.min(t.elapsed().as_secs_f64());
        cpu_best = cpu_best.min(cpu() - c);
    }
    (wall, cpu_best)
}

fn main() -> Result<(), crease::Error> {
    let args: Vec<String> = std::env::args().collect();
    let reps: usize = args.get(2).and_then(|v| v.parse().ok()).unwrap_or(5);
    if let Some(path) = args.get(1).filter(|a| a.parse::<usize>().is_err()) {
        let (geom, _) = crease::io::read(path, &crease::io::ReadOptions::default())?;
        let pts = &geom.points.positions;
        let (w, c) = best_of(reps, || {
            let r = pca_normals_direct(pts, &PcaParams::default());
            std::hint::black_box(&r);
        });
        println!(
            "pca_normals_direct k=20 {path} ({} points, {} threads): {w:.3} s wall, {c:.2} s CPU (best of {reps})",
            pts.len(),
            rayon::current_num_threads()
        );
        return Ok(());
    }
    let n: usize = args
        .get(1)
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let part = sample_points(
        &Shape::default_cube(),
        &SampleParams {
            n,
            ..Default::default()
        },
    )?;
    let random = part.cloud.positions;
    let order = morton_order(&random);
    let sorted: Vec<Point3> = order.iter().map(|&i| random[i as usize]).collect();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "{n} points, {} threads, load {}",
        rayon::current_num_threads(),
        load.trim()
    );
    // CREASE_ONLY=random|sorted|pca|knn restricts the runs (for profiling).
    let only = std::env::var("CREASE_ONLY").unwrap_or_default();
    for (name, pts) in [("random", &random), ("sorted", &sorted)] {
        if (only == "random" || only == "sorted") && only != name {
            continue;
        }
        let params = PcaParams::default();
        if only != "knn" {
            let (w, c) = best_of(reps, || {
                let r = pca_normals_direct(pts, &params);
                std::hint::black_box(&r);
            });
            println!("pca_normals_direct k=20 {name}: {w:.3} s wall, {c:.2} s CPU");
        }
        if only == "pca" {
            continue;
        }
        let (w, c) = best_of(reps, || {
            let r = knn(pts, 20);
            std::hint::black_box(&r);
        });
        println!("knn k=20 {name}: {w:.3} s wall, {c:.2} s CPU");
    }
    Ok(())
}
