//! Scan-to-CAD benchmarks: `brep::reconstruct_mesh` (segmentation, topology, snapping, vertices,
//! curves) on the synthetic two-cylinders part as a mesh of about 10k, 100k and 1M triangles,
//! clean and with noise of half the mesh spacing along the normals (segmented through its
//! vertices); and `brep::reconstruct_points` on the same part as a cloud of 10k, 100k and 1M
//! points, clean and with noise of half a spacing along the normals (shared analysis, envelope, B-rep). STEP
//! writing excluded (`crease reconstruct` times the whole process).
//!
//! Run with `cargo bench -p crease --bench brep`.

use std::hint::black_box;

use crease::analysis::AnalysisParams;
use crease::brep::{reconstruct_mesh, reconstruct_points};
use crease::segment::SegmentParams;
use crease::synth::{self, MeshParams, Noise, SampleParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

/// Surface area of the part (about 8.3), to size the meshes.
const AREA: f64 = 8.3;

fn reconstruct(c: &mut Criterion) {
    let shape = Shape::from_name("two-cylinders").expect("shape");
    for (name, noise) in [
        ("brep_clean", Noise::None),
        ("brep_noisy", Noise::AlongNormal(0.5)),
    ] {
        let mut g = c.benchmark_group(name);
        g.sample_size(10);
        for faces in [10_000usize, 100_000, 1_000_000] {
            // Equilateral triangles of edge e cover sqrt(3)/4 e² each.
            let edge = (AREA / (faces as f64 * 3f64.sqrt() / 4.0)).sqrt();
            let m = synth::mesh(
                &shape,
                &MeshParams {
                    target_edge: Some(edge),
                    noise,
                    ..Default::default()
                },
            )
            .expect("synthetic mesh");
            g.bench_function(format!("{}", m.mesh.num_faces()), |b| {
                b.iter(|| {
                    black_box(reconstruct_mesh(&m.mesh, &SegmentParams::default()).expect("B-rep"))
                })
            });
        }
        g.finish();
    }
}

fn reconstruct_cloud(c: &mut Criterion) {
    let shape = Shape::from_name("two-cylinders").expect("shape");
    for (name, noise) in [("brep_cloud_clean", 0.0), ("brep_cloud_noisy", 0.5)] {
        let mut g = c.benchmark_group(name);
        g.sample_size(10);
        for n in [10_000usize, 100_000, 1_000_000] {
            let cloud = synth::sample_points(
                &shape,
                &SampleParams {
                    n,
                    noise: if noise > 0.0 {
                        Noise::AlongNormal(noise)
                    } else {
                        Noise::None
                    },
                    ..Default::default()
                },
            )
            .expect("synthetic cloud");
            let normals = cloud.cloud.normals.clone();
            g.bench_function(format!("{n}"), |b| {
                b.iter(|| {
                    black_box(
                        reconstruct_points(
                            &cloud.cloud.positions,
                            normals.as_deref(),
                            AnalysisParams::default(),
                        )
                        .expect("B-rep"),
                    )
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, reconstruct, reconstruct_cloud);
criterion_main!(benches);
