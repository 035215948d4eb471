//! Arbitrary triangle meshes (`crease_fuzz::mesh`: raw vertices and faces, or synthetic parts
//! with edits; degenerate and non-manifold ones included) into `crease edges`
//! (`crease::meshfeat::detect_edges`, then `feature_polylines` as `--lines` does). The variant
//! byte picks the method (0: `fused`, the default).

#![no_main]

use crease::meshfeat::{detect_edges, feature_polylines, EdgeMethod, EdgeParams};
use crease_fuzz::Bytes;

const METHODS: [EdgeMethod; 10] = [
    EdgeMethod::Fused,
    EdgeMethod::Dihedral,
    EdgeMethod::Hysteresis,
    EdgeMethod::Tangent,
    EdgeMethod::PottsDihedral,
    EdgeMethod::PottsTangent,
    EdgeMethod::Learned,
    EdgeMethod::PottsLearned,
    EdgeMethod::Filtered,
    EdgeMethod::PottsFiltered,
];

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let Some(mesh) = crease_fuzz::mesh(&mut b) else {
        return;
    };
    let params = EdgeParams {
        method: METHODS[usize::from(variant) % METHODS.len()],
        ..EdgeParams::default()
    };
    if let Ok((em, det)) = detect_edges(&mesh, &params) {
        let _ = feature_polylines(&em.topo, &det.sharp);
        let _ = em.topo.boundary_edges();
    }
}
