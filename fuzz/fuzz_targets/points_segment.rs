//! Arbitrary finite point sets (`crease_fuzz::points`) into `crease segment` on a cloud
//! (`crease::segment::segment_points`, k = 8) with the CLI's default tolerances. The variant
//! byte gives the cloud stored normals, as a file may have them (arbitrary vectors made from
//! the coordinates, some zero or NaN: `crease::io::read` checks positions only), or none.

#![no_main]

use crease::segment::{segment_points, PointParams, SegmentParams};
use crease_fuzz::Bytes;

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let points = crease_fuzz::points(&mut b);
    let normals = crease_fuzz::stored_normals(variant, &points);
    let params = SegmentParams::default();
    let pp = PointParams {
        k: 8,
        ..Default::default()
    };
    if let Ok(seg) = segment_points(&points, normals.as_deref(), &params, &pp) {
        let _ = seg.point_types();
    }
}
