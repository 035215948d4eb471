//! Analytic-surface segmentation (Mizoguchi) benchmarks: the whole pipeline (curvature, labels,
//! seeds, fits, region growing, recognition) on the synthetic fillet-chamfer-cone part, as a
//! mesh of about 100k and 1M triangles and as a cloud of 100k and 1M points (normals estimated
//! inside, as `crease segment --estimate-normals` does). Per-stage times are in
//! `crease segment --json`.
//!
//! Run with `cargo bench -p crease --bench segment`.

use std::hint::black_box;

use crease::geometry::MeshTopology;
use crease::segment::{segment_mesh, segment_points, PointParams, SegmentParams};
use crease::synth::{self, MeshParams, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

/// Surface area of the part (about 3.5), to size the meshes.
const AREA: f64 = 3.5;

fn mesh(c: &mut Criterion) {
    let shape = Shape::from_name("fillet-chamfer-cone").expect("shape");
    let mut g = c.benchmark_group("segment_mesh");
    g.sample_size(10);
    for faces in [100_000usize, 1_000_000] {
        // Equilateral triangles of edge e cover sqrt(3)/4 e² each.
        let edge = (AREA / (faces as f64 * 3f64.sqrt() / 4.0)).sqrt();
        let m = synth::mesh(
            &shape,
            &MeshParams {
                target_edge: Some(edge),
                ..Default::default()
            },
        )
        .expect("synthetic mesh");
        let topo = MeshTopology::new(&m.mesh).expect("topology");
        g.bench_function(format!("{}", m.mesh.num_faces()), |b| {
            b.iter(|| {
                black_box(segment_mesh(&m.mesh, &topo, &SegmentParams::default()).expect("segment"))
            })
        });
    }
    g.finish();
}

fn points(c: &mut Criterion) {
    let shape = Shape::from_name("fillet-chamfer-cone").expect("shape");
    let mut g = c.benchmark_group("segment_points");
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
                black_box(
                    segment_points(
                        &pts,
                        None,
                        &SegmentParams::default(),
                        &PointParams::default(),
                    )
                    .expect("segment"),
                )
            })
        });
    }
    g.finish();
}

criterion_group!(benches, mesh, points);
criterion_main!(benches);
