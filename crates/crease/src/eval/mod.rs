//! Evaluation against ground truth: precision / recall / F1 / MCC / IoU of binary labels
//! ([`metrics`]), ROC curve and AUC of a continuous score ([`mod@roc`]), distance-tolerant precision
//! and recall ([`tolerant`]), and ground-truth readers ([`truth`]).
//!
//! The inputs are per-item: a predicted and a true boolean label per item, optionally a score
//! (larger = more positive) and a position. Items are points here; feature-line vertices or mesh
//! edges (with their midpoints as positions) are scored the same way. [`evaluate`] computes
//! everything into one [`EvalReport`] (serde `Serialize`, the `crease eval --json` output);
//! [`check_same_points`] checks that a prediction and its ground truth list the same points in
//! the same order before their labels are compared item by item.

pub mod curves;
pub mod metrics;
pub mod roc;
pub mod tolerant;
pub mod truth;

use std::path::Path;

use rayon::prelude::*;
use serde::Serialize;

use crate::geometry::{Aabb, Point3};
use crate::spatial::KdIndex;
use crate::{Error, Result};

pub use curves::{score_curves, CurveScores};
pub use metrics::{Confusion, Metrics};
pub use roc::{roc, Roc, RocPoint};
pub use tolerant::{
    default_tolerance, tolerant_scores, TolerantScores, DEFAULT_TOLERANCE_SPACINGS,
};
pub use truth::{
    class_of_color, labels_from_property, read_truth, scores_from_property, truth_from_colors,
    truth_from_property, ClassCounts, GroundTruth, PointClass, TruthSource, DEFAULT_PROPERTIES,
};

/// Relative coordinate tolerance of [`check_same_points`]: 1e-6 × the bounding-box diagonal,
/// above the rounding of coordinates stored as f32 (relative 6e-8) and far below any spacing.
pub const SAME_POINT_TOLERANCE: f64 = 1e-6;

/// Parameters of [`evaluate`].
#[derive(Debug, Clone, PartialEq)]
pub struct EvalParams {
    /// Distance of the tolerant scores; `None` = [`default_tolerance`] of the positions
    /// ([`DEFAULT_TOLERANCE_SPACINGS`] × the average spacing).
    pub tolerance: Option<f64>,
    /// At most this many points of the ROC curve in the report (default 101; the full curve
    /// stays available in [`RocReport::full`]).
    pub roc_points: usize,
}

impl Default for EvalParams {
    fn default() -> Self {
        EvalParams {
            tolerance: None,
            roc_points: 101,
        }
    }
}

/// What is evaluated: one entry per item in every slice given.
#[derive(Debug, Clone, Copy)]
pub struct Labels<'a> {
    /// Predicted positive (e.g. the detector's `sharp`).
    pub predicted: &'a [bool],
    /// Truly positive.
    pub truth: &'a [bool],
    /// A continuous score, larger = more positive (e.g. `sharpness`), for the ROC curve.
    pub scores: Option<&'a [f64]>,
    /// Positions, for the distance-tolerant scores.
    pub positions: Option<&'a [Point3]>,
    /// True classes, for the per-class breakdown.
    pub classes: Option<&'a [PointClass]>,
}

/// The ROC part of a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RocReport {
    /// Area under the full curve.
    pub auc: f64,
    /// Truly positive items.
    pub positives: u64,
    /// Truly negative items.
    pub negatives: u64,
    /// Points of the full curve (distinct scores + 1).
    pub full_points: usize,
    /// The curve thinned to at most [`EvalParams::roc_points`] points ([`Roc::thinned`]).
    pub curve: Vec<RocPoint>,
    /// The full curve (not serialised).
    #[serde(skip)]
    pub full: Roc,
}

/// How the items of one true class were predicted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ClassRow {
    /// The class.
    pub class: PointClass,
    /// Items of that class.
    pub count: u64,
    /// Of which predicted positive.
    pub predicted_positive: u64,
}

/// Everything [`evaluate`] measures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EvalReport {
    /// Number of items.
    pub items: u64,
    /// The confusion matrix of the binary labels.
    pub confusion: Confusion,
    /// Threshold-free scores of the binary labels.
    pub metrics: Metrics,
    /// Distance-tolerant scores (when positions were given and a tolerance could be set).
    pub tolerant: Option<TolerantScores>,
    /// ROC curve and AUC (when scores were given and both classes occur).
    pub roc: Option<RocReport>,
    /// Per true class (when classes were given).
    pub classes: Option<Vec<ClassRow>>,
    /// Why a part was left out, in words.
    pub notes: Vec<String>,
}

/// Scores `labels`. Errors when the slices' lengths differ, a score is NaN, or a position is
/// not finite; a part that cannot be computed for a reason of the data (no positive or no
/// negative item for the ROC, fewer than two distinct points for the default tolerance) is
/// left out with a note.
pub fn evaluate(labels: &Labels, params: &EvalParams) -> Result<EvalReport> {
    let n = labels.truth.len();
    let check = |what: &str, len: usize| {
        if len != n {
            return Err(Error::InvalidArgument(format!(
                "evaluate: {len} {what} for {n} true labels"
            )));
        }
        Ok(())
    };
    check("predicted labels", labels.predicted.len())?;
    if let Some(s) = labels.scores {
        check("scores", s.len())?;
    }
    if let Some(p) = labels.positions {
        check("positions", p.len())?;
    }
    if let Some(c) = labels.classes {
        check("classes", c.len())?;
    }
    let confusion = Confusion::from_labels(labels.predicted, labels.truth)?;
    let mut notes = Vec::new();

    let tolerant = match labels.positions {
        Some(p) => match params.tolerance.or_else(|| default_tolerance(p)) {
            Some(tol) => Some(tolerant_scores(p, labels.predicted, labels.truth, tol)?),
            None => {
                notes.push(
                    "tolerant scores left out: fewer than two distinct points, so no spacing to set the tolerance from".into(),
                );
                None
            }
        },
        None => None,
    };

    let roc = match labels.scores {
        Some(s) => {
            if confusion.positives() == 0 || confusion.negatives() == 0 {
                notes.push(format!(
                    "ROC left out: it needs both positive and negative items, the truth has {} positive and {} negative",
                    confusion.positives(),
                    confusion.negatives()
                ));
                None
            } else {
                let full = roc::roc(s, labels.truth)?;
                Some(RocReport {
                    auc: full.auc,
                    positives: full.positives,
                    negatives: full.negatives,
                    full_points: full.points.len(),
                    curve: full.thinned(params.roc_points),
                    full,
                })
            }
        }
        None => None,
    };

    let classes = labels.classes.map(|cls| {
        PointClass::ALL
            .iter()
            .map(|&k| {
                let (count, predicted_positive) = cls
                    .par_iter()
                    .zip(labels.predicted.par_iter())
                    .filter(|(c, _)| **c == k)
                    .map(|(_, &p)| (1u64, p as u64))
                    .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
                ClassRow {
                    class: k,
                    count,
                    predicted_positive,
                }
            })
            .filter(|r| r.count > 0)
            .collect()
    });

    Ok(EvalReport {
        items: n as u64,
        confusion,
        metrics: confusion.metrics(),
        tolerant,
        roc,
        classes,
        notes,
    })
}

/// Checks that `pred` (from `pred_path`) lists the same points as `truth` (from `truth_path`)
/// in the same order: the same count, and every point within [`SAME_POINT_TOLERANCE`] × the
/// bounding-box diagonal of `truth` of its counterpart. The error names both files, the first
/// differing point with both positions, how many differ, and whether the two hold the same
/// points in another order (they are never reordered silently).
pub fn check_same_points(
    pred: &[Point3],
    pred_path: &Path,
    truth: &[Point3],
    truth_path: &Path,
) -> Result<()> {
    let (pp, tp) = (pred_path.display(), truth_path.display());
    if pred.len() != truth.len() {
        return Err(Error::InvalidInput(format!(
            "{pp} has {} points, {tp} has {}: the prediction must list the ground truth's points, in the same order",
            pred.len(),
            truth.len()
        )));
    }
    let diag = Aabb::from_points(truth).map_or(0.0, |b| b.diagonal());
    let tol = SAME_POINT_TOLERANCE * diag;
    let tol2 = tol * tol;
    let differs = |a: &Point3, b: &Point3| {
        let d2: f64 = (0..3).map(|k| (a[k] - b[k]) * (a[k] - b[k])).sum();
        // NaN (a non-finite coordinate) counts as a difference.
        d2.is_nan() || d2 > tol2
    };
    let Some(first) = pred
        .par_iter()
        .zip(truth.par_iter())
        .position_first(|(a, b)| differs(a, b))
    else {
        return Ok(());
    };
    let count = pred
        .par_iter()
        .zip(truth.par_iter())
        .filter(|(a, b)| differs(a, b))
        .count();
    let (a, b) = (pred[first], truth[first]);
    let reordered = pred
        .iter()
        .chain(truth)
        .all(|p| p.iter().all(|c| c.is_finite()))
        && KdIndex::new(truth)
            .is_some_and(|index| pred.par_iter().all(|q| index.nearest_one(q).1 <= tol2));
    let hint = if reordered {
        "; the two files hold the same points in a different order: write the prediction in the ground truth's point order"
    } else {
        "; the prediction must be computed on the ground truth's own points"
    };
    Err(Error::InvalidInput(format!(
        "point {first} differs: {pp} has ({}, {}, {}), {tp} has ({}, {}, {}); {count} of {} points differ by more than {tol:.3e} (1e-6 of the bounding-box diagonal){hint}",
        a[0], a[1], a[2], b[0], b[1], b[2], pred.len()
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_of_a_small_case() {
        let pos: Vec<Point3> = (0..8).map(|i| [i as f64, 0.0, 0.0]).collect();
        let truth = [false, false, true, true, false, false, false, false];
        let pred = [false, false, false, true, true, false, false, false];
        let scores = [0.0, 0.1, 0.6, 0.9, 0.8, 0.2, 0.0, 0.1];
        let classes = [
            PointClass::Flat,
            PointClass::Smooth,
            PointClass::Sharp,
            PointClass::Sharp,
            PointClass::Flat,
            PointClass::Flat,
            PointClass::Smooth,
            PointClass::Flat,
        ];
        let r = evaluate(
            &Labels {
                predicted: &pred,
                truth: &truth,
                scores: Some(&scores),
                positions: Some(&pos),
                classes: Some(&classes),
            },
            &EvalParams::default(),
        )
        .unwrap();
        assert_eq!(
            r.confusion,
            Confusion {
                tp: 1,
                fp: 1,
                tn: 5,
                fn_: 1
            }
        );
        // Default tolerance: 2 × spacing 1 = 2: every predicted and true point is matched.
        let t = r.tolerant.unwrap();
        assert_eq!(t.tolerance, 2.0);
        assert_eq!((t.precision, t.recall), (1.0, 1.0));
        // 0.9 P, 0.8 N, 0.6 P, then the 6 negatives: 11 of 12 pairs right.
        let roc = r.roc.as_ref().unwrap();
        assert_eq!(roc.auc, 11.0 / 12.0);
        let rows = r.classes.unwrap();
        assert_eq!(rows.len(), 3);
        assert_eq!((rows[0].count, rows[0].predicted_positive), (4, 1));
        assert_eq!((rows[1].count, rows[1].predicted_positive), (2, 1));
        assert_eq!((rows[2].count, rows[2].predicted_positive), (2, 0));
        let json = serde_json::to_value(&r.roc).unwrap();
        assert!(json["curve"][0]["threshold"].is_null());
        assert!(json.get("full").is_none());
    }

    #[test]
    fn degenerate_parts_become_notes() {
        let r = evaluate(
            &Labels {
                predicted: &[true, false],
                truth: &[false, false],
                scores: Some(&[1.0, 0.0]),
                positions: Some(&[[0.0; 3], [0.0; 3]]),
                classes: None,
            },
            &EvalParams::default(),
        )
        .unwrap();
        assert!(r.roc.is_none() && r.tolerant.is_none());
        assert_eq!(r.notes.len(), 2, "{:?}", r.notes);
        assert!(evaluate(
            &Labels {
                predicted: &[true],
                truth: &[false, false],
                scores: None,
                positions: None,
                classes: None,
            },
            &EvalParams::default(),
        )
        .is_err());
    }

    #[test]
    fn point_lists_must_agree_in_count_and_order() {
        let a: Vec<Point3> = (0..5).map(|i| [i as f64, 1.0, 0.0]).collect();
        let (pa, pb) = (Path::new("pred.ply"), Path::new("gt.ply"));
        check_same_points(&a, pa, &a, pb).unwrap();
        // f32 rounding is accepted.
        let r: Vec<Point3> = a
            .iter()
            .map(|p| p.map(|c| (c + 1e-3) as f32 as f64 - 1e-3))
            .collect();
        check_same_points(&r, pa, &a, pb).unwrap();
        let e = check_same_points(&a[..4], pa, &a, pb)
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "pred.ply has 4 points, gt.ply has 5: the prediction must list the ground truth's points, in the same order"
        );
        let mut rev = a.clone();
        rev.reverse();
        let e = check_same_points(&rev, pa, &a, pb).unwrap_err().to_string();
        assert!(
            e.starts_with(
                "point 0 differs: pred.ply has (4, 1, 0), gt.ply has (0, 1, 0); 4 of 5 points"
            ),
            "{e}"
        );
        assert!(e.contains("different order"), "{e}");
        let mut moved = a.clone();
        moved[3][2] = 0.5;
        let e = check_same_points(&moved, pa, &a, pb)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("point 3 differs")
                && e.contains("1 of 5")
                && !e.contains("different order"),
            "{e}"
        );
    }
}
