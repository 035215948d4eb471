//! Arbitrary triangle meshes (`crease_fuzz::mesh`; degenerate and non-manifold ones included)
//! into mesh segmentation and the mesh B-rep: `crease segment` and the mesh path of `crease
//! run` (`MeshTopology::new`, `crease::segment::segment_mesh`, then
//! `reconstruct_segmented_mesh`), or by the variant byte `crease reconstruct`
//! (`crease::brep::reconstruct_mesh`); then the STEP text and the tessellation.

#![no_main]

use crease::brep::{LengthUnit, Reconstruction};
use crease::geometry::MeshTopology;
use crease::segment::{segment_mesh, SegmentParams};
use crease_fuzz::Bytes;

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let Some(mesh) = crease_fuzz::mesh(&mut b) else {
        return;
    };
    let params = SegmentParams::default();
    let rec: crease::Result<Reconstruction> = if variant & 1 == 0 {
        let Ok(topo) = MeshTopology::new(&mesh) else {
            return;
        };
        let Ok(seg) = segment_mesh(&mesh, &topo, &params) else {
            return;
        };
        let _ = seg.face_types();
        crease::brep::reconstruct_segmented_mesh(&mesh, seg, &params)
    } else {
        crease::brep::reconstruct_mesh(&mesh, &params)
    };
    let Ok(rec) = rec else {
        return;
    };
    let _ = rec.uncertainty();
    let _ = rec.to_step("fuzz", LengthUnit::Millimetre);
    let _ = rec.tessellate();
}
