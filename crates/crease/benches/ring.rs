//! Delaunay 1-ring benchmarks (demarsin2007 section 2.2): `delaunay_rings` at k = 20 and the
//! 1-ring normals, on 10k / 100k / 1M points sampled on the faces of the unit cube, given
//! precomputed k = 20 neighbourhoods (the kNN time is not included; it is printed once per size
//! for reference).
//!
//! Run with `cargo bench -p crease --bench ring`.

use std::hint::black_box;
use std::time::Instant;

use crease::estimate::ring_normals;
use crease::spatial::{delaunay_rings, knn, RingParams};
use crease::synth::{self, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("ring");
    group.sample_size(10);
    for n in [10_000usize, 100_000, 1_000_000] {
        let part = synth::sample_points(
            &Shape::default_cube(),
            &SampleParams {
                n,
                ..Default::default()
            },
        )
        .expect("cube sample");
        let pts = part.cloud.positions;
        let t = Instant::now();
        let nbrs = knn(&pts, 20).expect("kNN");
        eprintln!(
            "{n} points: kNN k = 20 in {:.3} s",
            t.elapsed().as_secs_f64()
        );
        let params = RingParams::default();
        group.bench_function(format!("delaunay_rings_k20_{n}"), |b| {
            b.iter(|| black_box(delaunay_rings(&pts, &nbrs, &params).expect("rings")))
        });
        let rings = delaunay_rings(&pts, &nbrs, &params).expect("rings");
        group.bench_function(format!("ring_normals_{n}"), |b| {
            b.iter(|| black_box(ring_normals(&pts, &rings)))
        });
        group.bench_function(format!("symmetrized_{n}"), |b| {
            b.iter(|| black_box(rings.symmetrized()))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
