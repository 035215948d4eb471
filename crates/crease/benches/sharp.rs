//! Sharp-point detection benchmarks: the full multi-scale projected distance (tran et al.: one
//! kNN query at k = 40, eight scales k = 12..40, Otsu per scale, thinning) on the synthetic
//! fillet-chamfer-cone part with 10k, 100k and 1M points, in sampling (random) order.
//!
//! Run with `cargo bench -p crease --bench sharp`.

use std::hint::black_box;

use crease::sharp::{detect_points, SharpParams};
use crease::synth::{self, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

fn multiscale(c: &mut Criterion) {
    let shape = Shape::from_name("fillet-chamfer-cone").expect("shape");
    let mut g = c.benchmark_group("sharp_projected_distance_8_scales");
    g.sample_size(10);
    for n in [10_000usize, 100_000, 1_000_000] {
        let part = synth::sample_points(
            &shape,
            &SampleParams {
                n,
                ..Default::default()
            },
        )
        .expect("synthetic part");
        let pts = part.cloud.positions;
        g.bench_function(format!("{n}"), |b| {
            b.iter(|| black_box(detect_points(&pts, &SharpParams::default()).expect("detect")))
        });
    }
    g.finish();
}

criterion_group!(benches, multiscale);
criterion_main!(benches);
