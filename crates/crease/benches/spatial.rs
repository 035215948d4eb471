//! Neighbour-search benchmarks on points sampled on surfaces (a cube's faces, jittered along the
//! normal): index builds, all-points kNN at k = 20 (10k, 100k, 1M points, random and
//! Morton-sorted input order) and radius search at 100k.
//!
//! Run with `cargo bench -p crease --bench spatial`. Set `CREASE_BENCH_KIDDO=1` to also time the
//! kiddo baselines (`KnnMethod::KdTree`, `KnnMethod::KdTreeMorton`) at 1M points (slow).

use std::hint::black_box;

use crease::geometry::Point3;
use crease::spatial::{knn_with, morton_order, radius_neighbors, KdIndex, KnnMethod};
use crease::synth::{sample_points, Noise, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

/// `n` points on the faces of the default cube (random order) and the same points Morton-sorted.
fn clouds(n: usize) -> (Vec<Point3>, Vec<Point3>) {
    let part = sample_points(
        &Shape::default_cube(),
        &SampleParams {
            n,
            noise: Noise::AlongNormal(0.1),
            ..Default::default()
        },
    )
    .expect("synthetic cube");
    let random = part.cloud.positions;
    let sorted = morton_order(&random)
        .into_iter()
        .map(|i| random[i as usize])
        .collect();
    (random, sorted)
}

fn bench(c: &mut Criterion) {
    let kiddo = std::env::var("CREASE_BENCH_KIDDO").is_ok_and(|v| v == "1");
    let mut g = c.benchmark_group("spatial");
    g.sample_size(10);
    for n in [10_000usize, 100_000, 1_000_000] {
        let (random, sorted) = clouds(n);
        g.bench_with_input(BenchmarkId::new("kdtree_build", n), &random, |b, p| {
            b.iter(|| black_box(KdIndex::new(p)))
        });
        g.bench_with_input(BenchmarkId::new("morton_order", n), &random, |b, p| {
            b.iter(|| black_box(morton_order(p)))
        });
        for (order, p) in [("random", &random), ("sorted", &sorted)] {
            let mut methods = vec![("grid", KnnMethod::Grid)];
            if kiddo || n <= 100_000 {
                methods.push(("kiddo", KnnMethod::KdTree));
                methods.push(("kiddo_morton", KnnMethod::KdTreeMorton));
            }
            for (name, m) in methods {
                g.bench_with_input(
                    BenchmarkId::new(format!("knn20_{name}_{order}"), n),
                    p,
                    |b, p| b.iter(|| black_box(knn_with(p, 20, m).expect("knn"))),
                );
            }
        }
        if n == 100_000 {
            // About 20 neighbours per point: r = 2.5 x the expected spacing.
            let spacing = (6.0 / n as f64).sqrt();
            for (order, p) in [("random", &random), ("sorted", &sorted)] {
                g.bench_with_input(BenchmarkId::new(format!("radius_{order}"), n), p, |b, p| {
                    b.iter(|| black_box(radius_neighbors(p, 2.5 * spacing).expect("radius")))
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
