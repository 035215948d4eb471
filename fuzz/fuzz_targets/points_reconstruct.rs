//! Arbitrary finite point sets (`crease_fuzz::points`) into the B-rep of a cloud: `crease
//! reconstruct` (`crease::brep::reconstruct_points`, then the STEP text and the tessellation)
//! or, by the variant byte, the whole cloud path of `crease run` on one shared analysis
//! (segmentation, sharp points, curve network, `reconstruct_cloud`). Stored normals as in
//! `points_segment`.

#![no_main]

use crease::analysis::{AnalysisParams, CloudAnalysis};
use crease::brep::{LengthUnit, Reconstruction};
use crease_fuzz::Bytes;

fn finish(rec: crease::Result<Reconstruction>) {
    let Ok(rec) = rec else {
        return;
    };
    let _ = rec.uncertainty();
    let _ = rec.to_step("fuzz", LengthUnit::Millimetre);
    let _ = rec.tessellate();
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let points = crease_fuzz::points(&mut b);
    let normals = crease_fuzz::stored_normals(variant, &points);
    if variant & 16 == 0 {
        let rec = crease::brep::reconstruct_points(
            &points,
            normals.as_deref(),
            AnalysisParams::default(),
        );
        finish(rec);
        return;
    }
    let analysis = match &normals {
        Some(n) => CloudAnalysis::with_normals(&points, n, AnalysisParams::default()),
        None => CloudAnalysis::new(&points, AnalysisParams::default()),
    };
    let Ok(analysis) = analysis else {
        return;
    };
    if analysis.neighbours().is_err() || analysis.segmentation().is_err() {
        return;
    }
    let _ = crease::sharp::detect(&analysis, &crease::sharp::SharpParams::default());
    let fillets_params = crease::fillets::FilletParams::default();
    if let Ok(f) = crease::fillets::extract_fillets_from(&analysis, &fillets_params, true) {
        let _ = crease::fillets::curve_network(&f);
    }
    finish(crease::brep::reconstruct_cloud(&analysis));
}
