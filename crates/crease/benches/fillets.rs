//! Fillet lines (Demarsin 2008) benchmarks: the whole pipeline (first-order segmentation,
//! per-region kNN and quadric curvature, median filter, histogram thresholds, labels, cluster
//! graphs) on the synthetic rounded cube with 100k and 1M points. Per-stage times are in
//! `crease fillets --json` (`timing`).
//!
//! Run with `cargo bench -p crease --bench fillets`.

use std::hint::black_box;

use crease::fillets::{extract_fillets, FilletParams};
use crease::synth::{self, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

fn pipeline(c: &mut Criterion) {
    let shape = Shape::from_name("rounded-cube").expect("shape");
    let mut g = c.benchmark_group("fillet_lines_pipeline");
    g.sample_size(10);
    for n in [100_000usize, 1_000_000] {
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
            b.iter(|| {
                black_box(extract_fillets(&pts, &FilletParams::default(), false).expect("fillets"))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
