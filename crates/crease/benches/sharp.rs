//! Sharp-point detection benchmarks: the full multi-scale projected distance (tran et al.: one
//! kNN query at k = 40, eight scales k = 12..40, Otsu per scale, thinning) on the synthetic
//! fillet-chamfer-cone part with 10k, 100k and 1M points, in sampling (random) order; alone
//! (`SharpParams::surfaces` off, group `sharp_projected_distance_8_scales`) and with the default
//! surface stage (group `sharp_default_with_surfaces`).
//!
//! Run with `cargo bench -p crease --bench sharp`.

use std::hint::black_box;

use crease::sharp::{detect_points, SharpParams};
use crease::synth::{self, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

fn multiscale(c: &mut Criterion) {
    let shape = Shape::from_name("fillet-chamfer-cone").expect("shape");
    let parts: Vec<(usize, Vec<crease::geometry::Point3>)> = [10_000usize, 100_000, 1_000_000]
        .into_iter()
        .map(|n| {
            let part = synth::sample_points(
                &shape,
                &SampleParams {
                    n,
                    ..Default::default()
                },
            )
            .expect("synthetic part");
            (n, part.cloud.positions)
        })
        .collect();
    for (group, params) in [
        (
            "sharp_projected_distance_8_scales",
            SharpParams {
                surfaces: None,
                ..Default::default()
            },
        ),
        ("sharp_default_with_surfaces", SharpParams::default()),
    ] {
        let mut g = c.benchmark_group(group);
        g.sample_size(10);
        for (n, pts) in &parts {
            g.bench_function(format!("{n}"), |b| {
                b.iter(|| black_box(detect_points(pts, &params).expect("detect")))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, multiscale);
criterion_main!(benches);
