//! Closed sharp lines (Demarsin 2007) benchmarks: the whole pipeline (kNN, Delaunay 1-rings,
//! ring normals, region growing, cluster graphs, closing, smoothing) on the synthetic
//! two-cylinders part with 100k and 1M points. Per-stage times are in `crease lines --json`.
//!
//! Run with `cargo bench -p crease --bench lines`.

use std::hint::black_box;

use crease::lines::{extract_lines, LinesParams};
use crease::synth::{self, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

fn pipeline(c: &mut Criterion) {
    let shape = Shape::from_name("two-cylinders").expect("shape");
    let mut g = c.benchmark_group("sharp_lines_pipeline");
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
            b.iter(|| black_box(extract_lines(&pts, &LinesParams::default()).expect("lines")))
        });
    }
    g.finish();
}

criterion_group!(benches, pipeline);
criterion_main!(benches);
