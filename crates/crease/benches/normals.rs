//! Normal estimation benchmarks: `pca_normals_direct` (fused kNN search + PCA, the whole
//! estimate), then weighted PCA (tran eq. 1) given the k = 20 neighbourhoods, at
//! 10k, 100k and 1M points on the faces of the synthetic cube in sampling (random) order and in
//! spatially sorted order; the closed-form 3×3 eigen-solver against nalgebra's `SymmetricEigen`;
//! Hoppe orientation. The kNN itself is benchmarked in the spatial benchmarks.
//!
//! Run with `cargo bench -p crease --bench normals` (`CREASE_BENCH_MAX=100000` to skip 1M).

use std::hint::black_box;

use crease::estimate::normals::{pca_normals_direct, smallest_eigen};
use crease::estimate::{orient_normals, pca_normals, PcaParams, PcaWeight};
use crease::geometry::Point3;
use crease::spatial::knn;
use crease::synth::{sample_points, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

/// Cube-face points in sampling order and sorted along a Morton curve.
fn clouds(n: usize) -> (Vec<Point3>, Vec<Point3>) {
    let part = sample_points(
        &Shape::default_cube(),
        &SampleParams {
            n,
            ..Default::default()
        },
    )
    .expect("synthetic cube");
    let random = part.cloud.positions;
    let mut keyed: Vec<(u64, usize)> = random
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let q = |v: f64| (((v + 0.5) * 2047.0) as u64).min(2047);
            let mut code = 0u64;
            for b in 0..11 {
                code |= ((q(p[0]) >> b) & 1) << (3 * b)
                    | ((q(p[1]) >> b) & 1) << (3 * b + 1)
                    | ((q(p[2]) >> b) & 1) << (3 * b + 2);
            }
            (code, i)
        })
        .collect();
    keyed.sort_unstable();
    let sorted = keyed.iter().map(|&(_, i)| random[i]).collect();
    (random, sorted)
}

fn bench_pca(c: &mut Criterion) {
    let max: usize = std::env::var("CREASE_BENCH_MAX")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let mut g = c.benchmark_group("pca_normals_k20");
    g.sample_size(10);
    for n in [10_000usize, 100_000, 1_000_000] {
        if n > max {
            continue;
        }
        let (random, sorted) = clouds(n);
        for (order, pts) in [("random", &random), ("sorted", &sorted)] {
            // The fused path: kNN search and PCA in one pass over the Morton order.
            g.bench_with_input(
                BenchmarkId::new(format!("{order}/direct"), n),
                &n,
                |b, _| {
                    b.iter(|| {
                        black_box(pca_normals_direct(pts, &PcaParams::default()).expect("pca"))
                    })
                },
            );
            let nbrs = knn(pts, 20).expect("knn");
            for (wname, w) in [
                ("gauss", PcaParams::default().weight),
                ("uniform", PcaWeight::Uniform),
            ] {
                let params = PcaParams { k: 20, weight: w };
                g.bench_with_input(
                    BenchmarkId::new(format!("{order}/{wname}"), n),
                    &n,
                    |b, _| b.iter(|| black_box(pca_normals(pts, &nbrs, &params).expect("pca"))),
                );
            }
            if n <= 100_000 {
                let normals = pca_normals(pts, &nbrs, &PcaParams::default())
                    .expect("pca")
                    .normals;
                g.bench_with_input(
                    BenchmarkId::new(format!("{order}/orient"), n),
                    &n,
                    |b, _| {
                        b.iter(|| black_box(orient_normals(pts, &normals, &nbrs).expect("orient")))
                    },
                );
            }
        }
    }
    g.finish();
}

fn bench_eigen(c: &mut Criterion) {
    // 10 000 covariance-like matrices (GᵀG of pseudo-random G).
    let mut s = 1u64;
    let mut rnd = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let mats: Vec<[f64; 6]> = (0..10_000)
        .map(|_| {
            let g: Vec<f64> = (0..9).map(|_| rnd()).collect();
            let e = |r: usize, c: usize| (0..3).map(|k| g[3 * k + r] * g[3 * k + c]).sum::<f64>();
            [e(0, 0), e(0, 1), e(0, 2), e(1, 1), e(1, 2), e(2, 2)]
        })
        .collect();
    let mut g = c.benchmark_group("eigen3x3_10k");
    g.bench_function("closed_form", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for m in &mats {
                acc += smallest_eigen(*m).0[0];
            }
            black_box(acc)
        })
    });
    g.bench_function("nalgebra_symmetric_eigen", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for a in &mats {
                let m =
                    nalgebra::Matrix3::new(a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5]);
                let e = nalgebra::SymmetricEigen::new(m);
                let i = e.eigenvalues.imin();
                acc += e.eigenvectors[(0, i)];
            }
            black_box(acc)
        })
    });
    g.finish();
}

criterion_group!(benches, bench_eigen, bench_pca);
criterion_main!(benches);
