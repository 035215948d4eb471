//! Arbitrary triangle meshes (`crease_fuzz::mesh`; degenerate and non-manifold ones included)
//! into the other mesh paths of the CLI: `crease sharp` on a mesh (`crease::sharp::detect_mesh`,
//! the measure from the variant byte), `crease normals --method mesh`
//! (`mesh_vertex_normals`, all weightings) and `crease info`'s mesh summary (`summarize_mesh`).

#![no_main]

use crease::estimate::{mesh_vertex_normals, Weighting};
use crease::sharp::{detect_mesh, Measure, SharpParams};
use crease_fuzz::Bytes;

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let Some(mesh) = crease_fuzz::mesh(&mut b) else {
        return;
    };
    for w in [Weighting::Uniform, Weighting::Area, Weighting::Angle] {
        let _ = mesh_vertex_normals(&mesh, w);
    }
    let _ = crease::io::summary::summarize_mesh(&mesh);
    let params = SharpParams {
        measure: [
            Measure::ProjectedDistance,
            Measure::NormalVariation,
            Measure::MeanCurvature,
            Measure::SurfaceVariation,
        ][usize::from(variant) % 4],
        ..Default::default()
    };
    let _ = detect_mesh(&mesh, &params);
}
