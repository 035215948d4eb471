//! Sharp-point detection benchmarks: the full multi-scale projected distance (tran et al.: one
//! kNN query at k = 40, eight scales k = 12..40, Otsu per scale, thinning) on the synthetic
//! fillet-chamfer-cone part with 10k, 100k and 1M points, in sampling (random) order; alone
//! (`SharpParams::surfaces` off, group `sharp_projected_distance_8_scales`) and with the default
//! surface stage (group `sharp_default_with_surfaces`); and the default path on the same part
//! with Gaussian noise of half a spacing along the normal, as the noisy PCEDNet models
//! (`crease synth --noise 0.5`), which runs the Potts labelling, the noise-widened surface
//! stage and the rim distance (group `sharp_default_noisy`).
//!
//! Run with `cargo bench -p crease --bench sharp`.

use std::hint::black_box;

use crease::sharp::{detect_points, SharpParams};
use crease::synth::{self, Noise, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

/// The part at 10k, 100k and 1M points with the given noise.
fn parts(noise: Noise) -> Vec<(usize, Vec<crease::geometry::Point3>)> {
    let shape = Shape::from_name("fillet-chamfer-cone").expect("shape");
    [10_000usize, 100_000, 1_000_000]
        .into_iter()
        .map(|n| {
            let part = synth::sample_points(
                &shape,
                &SampleParams {
                    n,
                    noise,
                    ..Default::default()
                },
            )
            .expect("synthetic part");
            (n, part.cloud.positions)
        })
        .collect()
}

fn multiscale(c: &mut Criterion) {
    let clean = parts(Noise::None);
    let noisy = parts(Noise::AlongNormal(0.5));
    for (group, params, parts) in [
        (
            "sharp_projected_distance_8_scales",
            SharpParams {
                surfaces: None,
                ..Default::default()
            },
            &clean,
        ),
        (
            "sharp_default_with_surfaces",
            SharpParams::default(),
            &clean,
        ),
        ("sharp_default_noisy", SharpParams::default(), &noisy),
    ] {
        let mut g = c.benchmark_group(group);
        g.sample_size(10);
        for (n, pts) in parts {
            g.bench_function(format!("{n}"), |b| {
                b.iter(|| black_box(detect_points(pts, &params).expect("detect")))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, multiscale);
criterion_main!(benches);
