//! Receiver operating characteristic of a continuous score (Fawcett 2006, "An introduction to
//! ROC analysis", algorithm 2 for the curve, algorithm 3 / trapezoids for the area).
//!
//! Items are sorted by score, largest first; every distinct score value is one threshold, and
//! all the items sharing it enter the positive side together (one diagonal step), so the curve
//! and the AUC do not depend on the order of tied items. The AUC is the trapezoid area under
//! that curve, which equals the Mann-Whitney statistic P(s+ > s-) + P(s+ = s-) / 2. It is
//! accumulated in exact integer arithmetic and divided once, so it is exactly reproducible.

use rayon::prelude::*;
use serde::Serialize;

use crate::{Error, Result};

/// One point of a ROC curve: predicting "positive" for every item whose score is at least
/// `threshold` gives the false-positive rate `fpr` and true-positive rate `tpr`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RocPoint {
    /// Score threshold (`score >= threshold` is positive). The first point, (0, 0), has
    /// `+inf` (written as `null` in JSON).
    pub threshold: f64,
    /// False-positive rate fp / negatives.
    pub fpr: f64,
    /// True-positive rate tp / positives.
    pub tpr: f64,
}

/// A ROC curve with its area.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Roc {
    /// From (0, 0) at threshold +inf to (1, 1) at the smallest score, one point per distinct
    /// score, fpr and tpr non-decreasing.
    pub points: Vec<RocPoint>,
    /// Area under the curve (trapezoid rule), in [0, 1].
    pub auc: f64,
    /// Number of truly positive items.
    pub positives: u64,
    /// Number of truly negative items.
    pub negatives: u64,
}

/// The ROC curve of `scores` (larger = more positive) against `truth`, item by item.
///
/// Errors if the lengths differ, if a score is NaN (naming the first such item), or if `truth`
/// holds no positive or no negative item (the rates are then undefined). Infinite scores are
/// allowed; -0.0 and 0.0 are the same score.
pub fn roc(scores: &[f64], truth: &[bool]) -> Result<Roc> {
    if scores.len() != truth.len() {
        return Err(Error::InvalidArgument(format!(
            "ROC: {} scores for {} true labels",
            scores.len(),
            truth.len()
        )));
    }
    if let Some(i) = scores.par_iter().position_first(|s| s.is_nan()) {
        return Err(Error::InvalidInput(format!(
            "ROC: the score of item {i} is NaN; every score must be a number"
        )));
    }
    let positives = truth.par_iter().filter(|&&t| t).count() as u64;
    let negatives = truth.len() as u64 - positives;
    if positives == 0 || negatives == 0 {
        return Err(Error::InvalidInput(format!(
            "ROC: needs both positive and negative items, got {positives} positive and {negatives} negative"
        )));
    }
    // Adding 0.0 turns -0.0 into +0.0, so that total_cmp orders equal scores together.
    let mut items: Vec<(f64, bool)> = scores
        .par_iter()
        .zip(truth.par_iter())
        .map(|(&s, &t)| (s + 0.0, t))
        .collect();
    items.par_sort_unstable_by(|a, b| b.0.total_cmp(&a.0));

    let mut points = vec![RocPoint {
        threshold: f64::INFINITY,
        fpr: 0.0,
        tpr: 0.0,
    }];
    let (mut tp, mut fp) = (0u64, 0u64);
    // Twice the area in units of one (positive, negative) pair.
    let mut area2: u128 = 0;
    let mut i = 0;
    while i < items.len() {
        let s = items[i].0;
        let (mut dtp, mut dfp) = (0u64, 0u64);
        while i < items.len() && items[i].0 == s {
            if items[i].1 {
                dtp += 1;
            } else {
                dfp += 1;
            }
            i += 1;
        }
        area2 += dfp as u128 * (2 * tp as u128 + dtp as u128);
        tp += dtp;
        fp += dfp;
        points.push(RocPoint {
            threshold: s,
            fpr: fp as f64 / negatives as f64,
            tpr: tp as f64 / positives as f64,
        });
    }
    let auc = area2 as f64 / (2.0 * positives as f64 * negatives as f64);
    Ok(Roc {
        points,
        auc,
        positives,
        negatives,
    })
}

impl Roc {
    /// At most `max_points` points of the curve (at least 2: the first and the last are always
    /// kept), for plots and reports: the curve is cut into `max_points - 1` equal lengths of
    /// its monotone path (measured as fpr + tpr, which grows from 0 to 2 along it) and the first
    /// point reaching each cut is kept. Steep and flat parts thus keep detail in proportion to
    /// their length, not to their number of thresholds.
    pub fn thinned(&self, max_points: usize) -> Vec<RocPoint> {
        let max_points = max_points.max(2);
        let n = self.points.len();
        if n <= max_points {
            return self.points.clone();
        }
        let mut out = Vec::with_capacity(max_points);
        let mut j = 0;
        for k in 0..max_points {
            let target = 2.0 * k as f64 / (max_points - 1) as f64;
            while j + 1 < n && self.points[j].fpr + self.points[j].tpr < target {
                j += 1;
            }
            if k + 1 == max_points {
                j = n - 1;
            }
            if out.last() != Some(&self.points[j]) {
                out.push(self.points[j]);
            }
        }
        out
    }
}

/// Area under the piecewise-linear curve through `points` (trapezoid rule), e.g. of a
/// [`Roc::thinned`] curve.
pub fn trapezoid_area(points: &[RocPoint]) -> f64 {
    points
        .windows(2)
        .map(|w| (w[1].fpr - w[0].fpr) * (w[1].tpr + w[0].tpr) / 2.0)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    fn rates(r: &Roc) -> Vec<(f64, f64)> {
        r.points.iter().map(|p| (p.fpr, p.tpr)).collect()
    }

    #[test]
    fn hand_computed_curve() {
        // Scores descending: 0.9 P, 0.8 N, 0.7 P, 0.6 P, 0.5 N. 3 positives, 2 negatives.
        let s = [0.5, 0.9, 0.6, 0.8, 0.7];
        let t = [false, true, true, false, true];
        let r = roc(&s, &t).unwrap();
        assert_eq!((r.positives, r.negatives), (3, 2));
        assert_eq!(
            rates(&r),
            vec![
                (0.0, 0.0),
                (0.0, 1.0 / 3.0),
                (0.5, 1.0 / 3.0),
                (0.5, 2.0 / 3.0),
                (0.5, 1.0),
                (1.0, 1.0)
            ]
        );
        let th: Vec<f64> = r.points.iter().map(|p| p.threshold).collect();
        assert_eq!(th, vec![f64::INFINITY, 0.9, 0.8, 0.7, 0.6, 0.5]);
        // Pairs ranked right: (0.9 > both N) 2 + (0.7, 0.6 > 0.5) 2 = 4 of 6.
        assert_eq!(r.auc, 4.0 / 6.0);
        assert!((trapezoid_area(&r.points) - r.auc).abs() < 1e-15);
    }

    #[test]
    fn ties_form_one_diagonal_step_whatever_the_order() {
        let t = [true, false, true, false];
        let a = roc(&[1.0, 1.0, 0.0, 0.0], &t).unwrap();
        let b = roc(&[1.0, 1.0, 0.0, -0.0], &[false, true, false, true]).unwrap();
        assert_eq!(rates(&a), vec![(0.0, 0.0), (0.5, 0.5), (1.0, 1.0)]);
        assert_eq!(rates(&a), rates(&b));
        assert_eq!(a.auc, 0.5);
        // All equal: the chance diagonal.
        assert_eq!(
            roc(&[3.0; 5], &[true, false, false, true, false])
                .unwrap()
                .auc,
            0.5
        );
    }

    #[test]
    fn perfect_inverted_and_errors() {
        let t = [true, true, false, false, false];
        assert_eq!(roc(&[5.0, 4.0, 3.0, 2.0, 1.0], &t).unwrap().auc, 1.0);
        assert_eq!(roc(&[1.0, 2.0, 3.0, 4.0, 5.0], &t).unwrap().auc, 0.0);
        let inf = roc(&[f64::INFINITY, 2.5, 3.0, 2.0, f64::NEG_INFINITY], &t).unwrap();
        assert_eq!(inf.auc, 5.0 / 6.0);
        let e = roc(&[1.0, f64::NAN, 0.0, 0.0, 0.0], &t).unwrap_err();
        assert!(e.to_string().contains("item 1 is NaN"), "{e}");
        assert!(roc(&[1.0, 2.0], &[true, true]).is_err());
        assert!(roc(&[1.0, 2.0], &[false, false]).is_err());
        assert!(roc(&[1.0], &[true, false]).is_err());
    }

    #[test]
    fn auc_is_the_mann_whitney_statistic() {
        let mut rng = Pcg64::seed_from_u64(7);
        for round in 0..5 {
            let n = 300 + 50 * round;
            // Few score levels so that ties are frequent; positives shifted up.
            let t: Vec<bool> = (0..n).map(|_| rng.random_bool(0.3)).collect();
            let s: Vec<f64> = t
                .iter()
                .map(|&p| (rng.random_range(0..20) + if p { 4 } else { 0 }) as f64 * 0.25)
                .collect();
            let r = roc(&s, &t).unwrap();
            let (mut wins, mut pairs) = (0.0, 0.0);
            for i in 0..n {
                for j in 0..n {
                    if t[i] && !t[j] {
                        pairs += 1.0;
                        if s[i] > s[j] {
                            wins += 1.0;
                        } else if s[i] == s[j] {
                            wins += 0.5;
                        }
                    }
                }
            }
            assert!(
                (r.auc - wins / pairs).abs() < 1e-12,
                "{} {}",
                r.auc,
                wins / pairs
            );
            assert!(r.auc > 0.6 && r.auc < 0.95, "{}", r.auc);
            // Shuffling the items changes nothing.
            let mut idx: Vec<usize> = (0..n).collect();
            idx.reverse();
            let s2: Vec<f64> = idx.iter().map(|&i| s[i]).collect();
            let t2: Vec<bool> = idx.iter().map(|&i| t[i]).collect();
            assert_eq!(roc(&s2, &t2).unwrap(), r);
        }
    }

    #[test]
    fn random_scores_give_about_one_half() {
        let mut rng = Pcg64::seed_from_u64(3);
        let n = 20_000;
        let t: Vec<bool> = (0..n).map(|_| rng.random_bool(0.2)).collect();
        let s: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let a = roc(&s, &t).unwrap().auc;
        assert!((a - 0.5).abs() < 0.02, "{a}");
    }

    #[test]
    fn thinning_keeps_the_ends_and_the_area() {
        let mut rng = Pcg64::seed_from_u64(11);
        let n = 5000;
        let t: Vec<bool> = (0..n).map(|_| rng.random_bool(0.4)).collect();
        let s: Vec<f64> = t
            .iter()
            .map(|&p| rng.random::<f64>() + if p { 0.5 } else { 0.0 })
            .collect();
        let r = roc(&s, &t).unwrap();
        assert_eq!(r.points.len(), n + 1);
        for m in [2, 3, 10, 101] {
            let th = r.thinned(m);
            assert!(th.len() <= m && th.len() >= 2, "{m}: {}", th.len());
            assert_eq!(th[0], r.points[0]);
            assert_eq!(th.last(), r.points.last());
            assert!(th
                .windows(2)
                .all(|w| w[0].fpr <= w[1].fpr && w[0].tpr <= w[1].tpr));
            if m >= 101 {
                assert!((trapezoid_area(&th) - r.auc).abs() < 0.01);
            }
        }
        assert_eq!(r.thinned(10_000), r.points);
    }
}
