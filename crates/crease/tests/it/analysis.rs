//! The shared analysis of a cloud: every stage run from it gives exactly what its one-call form
//! gives, each piece is computed once, and the results do not depend on the thread count.

use crate::common;

use crease::analysis::{AnalysisParams, CloudAnalysis};
use crease::fillets::{extract_fillets, extract_fillets_from, FilletParams};
use crease::geometry::Point3;
use crease::lines::{extract_lines, extract_lines_from, LinesParams};
use crease::segment::{segment_points, PointParams, SegmentParams};
use crease::sharp::{detect, detect_points, SharpParams};

fn cloud(noise: f64) -> Vec<Point3> {
    common::noisy_part("fillet-chamfer-cone", 20_000, noise)
        .cloud
        .positions
}

#[test]
fn sharp_points_and_surfaces_from_the_analysis_equal_the_one_call_forms() {
    for noise in [0.0, 0.5] {
        let pts = cloud(noise);
        let a = CloudAnalysis::new(&pts, AnalysisParams::default()).expect("analysis");
        let shared = detect(&a, &SharpParams::default()).expect("sharp from the analysis");
        let alone = detect_points(&pts, &SharpParams::default()).expect("sharp");
        assert_eq!(shared.sharp, alone.sharp, "noise {noise}");
        assert_eq!(shared.sharpness, alone.sharpness, "noise {noise}");
        assert_eq!(shared.noise_ratio, alone.noise_ratio);
        let surfaces = shared.surfaces.as_ref().expect("surface stage ran");
        assert!(surfaces.surfaces >= 6, "{surfaces:?}");

        // The segmentation the sharp stage read is the analysis' own, and the one-call
        // segmentation of the same points.
        let seg = a.segmentation().expect("segmentation");
        let one = segment_points(
            &pts,
            None,
            &SegmentParams::default(),
            &PointParams::default(),
        )
        .expect("segmentation");
        assert_eq!(a.to_input_order(&seg.point_surface), one.point_surface);
        assert_eq!(seg.surfaces.len(), one.surfaces.len());
        for (s, t) in seg.surfaces.iter().zip(&one.surfaces) {
            assert_eq!(s.params, t.params);
        }
        let c = a.counts();
        assert_eq!(
            (c.neighbours, c.segmentations, c.normals, c.noise),
            (1, 1, 1, 1),
            "{c:?}"
        );
    }
}

#[test]
fn lines_and_fillets_from_the_analysis_equal_the_one_call_forms_on_the_sorted_points() {
    let pts = cloud(0.0);
    let a = CloudAnalysis::new(&pts, AnalysisParams::default()).expect("analysis");
    let lp = LinesParams::default();
    let shared = extract_lines_from(&a, &lp).expect("lines from the analysis");
    let alone = extract_lines(a.points(), &lp).expect("lines");
    assert_eq!(shared.vertices, alone.vertices);
    assert_eq!(shared.polylines, alone.polylines);
    assert_eq!(
        shared.segmentation.labels,
        a.to_input_order(&alone.segmentation.labels)
    );
    // The part has 9 sharp feature curves (the chamfer, the cone's rim, the box's edges away
    // from the fillet): the network closes them with no open end.
    assert!(shared.polylines.len() >= 6, "{}", shared.polylines.len());
    assert_eq!(shared.endpoints(), 0);

    let fp = FilletParams::default();
    let shared = extract_fillets_from(&a, &fp, true).expect("network from the analysis");
    let alone = extract_fillets(a.points(), &fp, true).expect("network");
    assert_eq!(shared.lines.vertices, alone.lines.vertices);
    assert_eq!(shared.lines.polylines, alone.lines.polylines);
    assert_eq!(shared.label, a.to_input_order(&alone.label));
    assert_eq!(shared.region, a.to_input_order(&alone.region));
    assert!(!shared.lines.polylines.is_empty(), "the fillet's borders");
    // Both pipelines read the analysis' one neighbour query.
    assert_eq!(a.counts().neighbours, 1);
    assert_eq!(
        a.counts().segmentations,
        0,
        "nothing asked for a segmentation"
    );
}

#[test]
fn the_analysis_is_identical_whatever_the_thread_count() {
    let pts = cloud(0.5);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool")
            .install(|| {
                let a = CloudAnalysis::new(&pts, AnalysisParams::default()).expect("analysis");
                let s = detect(&a, &SharpParams::default()).expect("sharp");
                let seg = a.segmentation().expect("segmentation");
                let owners = a.to_input_order(&seg.point_surface);
                let f = extract_fillets_from(&a, &FilletParams::default(), true).expect("net");
                (s.sharp, s.sharpness, owners, f.lines.polylines, f.label)
            })
    };
    assert!(run(1) == run(2));
}

#[test]
fn bad_settings_and_too_small_clouds_are_errors() {
    let pts = cloud(0.0);
    // Lists shorter than the segmentation's 20 neighbours serve a stage that reads 10, and the
    // segmentation (or the normals) asked for is an error.
    let small = CloudAnalysis::new(
        &pts,
        AnalysisParams {
            max_k: 10,
            ..Default::default()
        },
    )
    .expect("an analysis for 10 neighbours");
    let e = small
        .segmentation()
        .expect_err("max_k below the segmentation's 20");
    assert!(e.to_string().contains("20 neighbours"), "{e}");
    assert!(small.normals().is_err());
    assert_eq!(small.counts().neighbours, 0, "refused before the query");
    let zero = AnalysisParams {
        max_k: 0,
        ..Default::default()
    };
    assert!(CloudAnalysis::new(&pts, zero).is_err());
    let few = CloudAnalysis::new(&pts[..30], AnalysisParams::default());
    assert!(few.is_err(), "30 points for 40 neighbours");
    let mut nan = pts.clone();
    nan[7] = [f64::NAN, 0.0, 0.0];
    let e = CloudAnalysis::new(&nan, AnalysisParams::default()).expect_err("NaN");
    assert!(e.to_string().contains("point 7"), "{e}");
    // A stage asking for more neighbours than the analysis holds.
    let a = CloudAnalysis::new(
        &pts,
        AnalysisParams {
            max_k: 20,
            ..Default::default()
        },
    )
    .expect("analysis");
    assert!(
        detect(&a, &SharpParams::default()).is_err(),
        "k = 40 from 20"
    );
}

#[test]
fn exact_duplicates_are_analysed_once_and_labelled_like_their_original() {
    let pts = cloud(0.0);
    let n = pts.len();
    // The copy interleaved, and one of its coordinates a negative zero where the original's is
    // zero (equal points).
    let mut twice = Vec::with_capacity(2 * n);
    for p in &pts {
        twice.push(*p);
        twice.push(p.map(|v| if v == 0.0 { -0.0 } else { v }));
    }
    let a = CloudAnalysis::new(&twice, AnalysisParams::default()).expect("analysis");
    assert_eq!(a.points().len(), n);
    assert_eq!((a.input_len(), a.duplicates()), (2 * n, n));
    assert!(
        a.order().iter().all(|&i| i % 2 == 0),
        "the first copies stand"
    );
    let once = detect_points(&pts, &SharpParams::default()).expect("sharp");
    let both = detect(&a, &SharpParams::default()).expect("sharp");
    for i in 0..n {
        assert_eq!(both.sharp[2 * i], once.sharp[i]);
        assert_eq!(both.sharp[2 * i + 1], once.sharp[i]);
        assert_eq!(both.sharpness[2 * i + 1], once.sharpness[i]);
    }
    let seg_once = segment_points(
        &pts,
        None,
        &SegmentParams::default(),
        &PointParams::default(),
    )
    .expect("segmentation");
    let seg_both = segment_points(
        &twice,
        None,
        &SegmentParams::default(),
        &PointParams::default(),
    )
    .expect("segmentation");
    assert_eq!(seg_both.surfaces.len(), seg_once.surfaces.len());
    for i in 0..n {
        assert_eq!(seg_both.point_surface[2 * i], seg_once.point_surface[i]);
        assert_eq!(seg_both.point_surface[2 * i + 1], seg_once.point_surface[i]);
    }
}
