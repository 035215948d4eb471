//! Mesh feature-edge benchmarks (vidal et al. 2011): the default `fused` method (the learned
//! pipeline, the filtered angle and the surface-intersection term, whose segmentation
//! dominates from 2026-12-04), `filtered` (bilateral and total-variation normal filtering,
//! the mean of their dihedral angles smoothed along the lines), the learned pipeline (the 43 features of
//! section 4, then the shipped SVM's decision values) and the tangent-plane method,
//! on the synthetic fillet-chamfer-cone part meshed with about 10k and 100k edges (and 1M
//! for `filtered`), with Gaussian noise of 0.5 % of the bounding box (section 6.1). The
//! learned and tangent 1M-edge figures are measured with `crease edges` (see the README): one
//! run takes 15 to 25 s.
//!
//! Run with `cargo bench -p crease --bench meshfeat`.

use std::hint::black_box;

use crease::meshfeat::{add_noise, detect_prepared, EdgeMesh, EdgeMethod, EdgeParams};
use crease::synth::{mesh as synth_mesh, MeshParams, Shape};
use criterion::{criterion_group, criterion_main, Criterion};

fn pipelines(c: &mut Criterion) {
    let shape = Shape::from_name("fillet-chamfer-cone").expect("shape");
    let mut g = c.benchmark_group("meshfeat");
    g.sample_size(10);
    // Target edge lengths giving about 10k and 100k edges.
    for (label, edge) in [("10k", 0.035), ("100k", 0.011), ("1M", 0.0035)] {
        let m = synth_mesh(
            &shape,
            &MeshParams {
                target_edge: Some(edge),
                ..Default::default()
            },
        )
        .expect("mesh");
        let noisy = add_noise(&m.mesh, 0.005, 1).expect("noise");
        let em = EdgeMesh::new(&noisy).expect("topology");
        let methods: &[EdgeMethod] = if label == "1M" {
            &[EdgeMethod::Filtered]
        } else {
            &[
                EdgeMethod::Fused,
                EdgeMethod::Filtered,
                EdgeMethod::Learned,
                EdgeMethod::Tangent,
            ]
        };
        for &method in methods {
            let p = EdgeParams {
                method,
                ..EdgeParams::default()
            };
            g.bench_function(format!("{}_{label}", method.name()), |b| {
                b.iter(|| black_box(detect_prepared(&em, &p).expect("detect")))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, pipelines);
criterion_main!(benches);
