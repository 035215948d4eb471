//! Curvature benchmarks: the quadric fit (demarsin2008 section 2.1) on synthetic sphere clouds
//! of 10k, 100k and 1M points with the k = 20 neighbourhoods precomputed (the kNN query is
//! benchmarked with the spatial module), and mizoguchi's two-pass Bézier fit on a synthetic
//! sphere mesh of about 100k vertices (topology precomputed).
//!
//! Run with `cargo bench -p crease --bench curvature`.

use std::hint::black_box;

use crease::estimate::bezier::{bezier_curvature, BezierParams};
use crease::estimate::curvature::{quadric_curvature, QuadricParams};
use crease::geometry::MeshTopology;
use crease::spatial::knn;
use crease::synth::{self, MeshParams, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

fn quadric(c: &mut Criterion) {
    let shape = Shape::from_name("sphere").expect("sphere shape");
    let mut g = c.benchmark_group("quadric_curvature_k20");
    g.sample_size(10);
    for n in [10_000usize, 100_000, 1_000_000] {
        let part = synth::sample_points(
            &shape,
            &SampleParams {
                n,
                ..Default::default()
            },
        )
        .expect("synthetic sphere");
        let pts = part.cloud.positions;
        let nbrs = knn(&pts, 20).expect("neighbourhoods");
        g.bench_function(format!("{n}"), |b| {
            b.iter(|| {
                black_box(quadric_curvature(&pts, &nbrs, &QuadricParams::default()).expect("fit"))
            })
        });
    }
    g.finish();
}

fn bezier(c: &mut Criterion) {
    let shape = Shape::from_name("sphere").expect("sphere shape");
    // A sphere of radius 0.5 meshed with edge l has about 3.6 / l² vertices.
    let m = synth::mesh(
        &shape,
        &MeshParams {
            target_edge: Some(0.006),
            ..Default::default()
        },
    )
    .expect("synthetic mesh");
    let topo = MeshTopology::new(&m.mesh).expect("topology");
    let mut g = c.benchmark_group("bezier_two_pass");
    g.sample_size(10);
    g.bench_function(format!("{}", m.mesh.num_vertices()), |b| {
        b.iter(|| {
            black_box(bezier_curvature(&m.mesh, &topo, &BezierParams::default()).expect("fit"))
        })
    });
    g.finish();
}

criterion_group!(benches, quadric, bezier);
criterion_main!(benches);
