//! Arbitrary finite point sets (`crease_fuzz::points`) into `crease sharp` on a cloud: Morton
//! order, one kNN query at the largest scale, `detect_points_with`, back to the input order (as
//! the CLI does, without its "too few points" pre-check: the library must refuse those itself),
//! or the shared-analysis path of `crease run` (`crease::sharp::detect`). The variant byte picks
//! the measure, `--no-surfaces`, `--regularize 0.5` and the path.

#![no_main]

use crease::sharp::{self, Measure, Regularize, SharpParams};
use crease_fuzz::Bytes;

libfuzzer_sys::fuzz_target!(|data: &[u8]| crease_fuzz::guarded(|| run(data)));

fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let variant = b.u8();
    let points = crease_fuzz::points(&mut b);
    if variant & 16 != 0 {
        let params = crease::analysis::AnalysisParams::default();
        if let Ok(analysis) = crease::analysis::CloudAnalysis::new(&points, params) {
            let _ = sharp::detect(&analysis, &SharpParams::default());
        }
        return;
    }
    let mut params = SharpParams {
        measure: [
            Measure::ProjectedDistance,
            Measure::NormalVariation,
            Measure::MeanCurvature,
            Measure::SurfaceVariation,
        ][usize::from(variant) % 4],
        ..Default::default()
    };
    if variant & 4 != 0 {
        params.surfaces = None;
    }
    if variant & 8 != 0 {
        params.regularize = Some(Regularize {
            lambda: 0.5,
            ..Default::default()
        });
    }
    if params.validate().is_err() {
        return;
    }
    let kmax = sharp::CLOUD_SCALES[sharp::CLOUD_SCALES.len() - 1];
    let spatial = sharp::spatial_order(&points);
    let pts = spatial.as_ref().map_or(&points, |(_, sorted)| sorted);
    let Ok(nbrs) = crease::spatial::knn(pts, kmax) else {
        return;
    };
    let _ = sharp::detect_points_with(pts, &nbrs, &params).and_then(|r| match &spatial {
        Some((order, _)) => r.to_input_order(order),
        None => Ok(r),
    });
}
