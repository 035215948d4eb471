//! Binary classification scores from a confusion matrix: precision, recall, F1, Matthews
//! correlation coefficient (Matthews 1975; Chicco & Jurman 2020), IoU (Jaccard index) of the
//! positive class, accuracy and specificity.
//!
//! Every ratio whose denominator is 0 is defined as 0 (the convention of scikit-learn's
//! `zero_division=0`): precision with no predicted positive, recall with no true positive, F1 and
//! IoU when there is neither, specificity with no true negative, accuracy of zero items, and MCC
//! whenever a row or column of the matrix is empty (including the "perfect" all-negative case).

use rayon::prelude::*;
use serde::Serialize;

use crate::{Error, Result};

/// Items per parallel task when counting.
const CHUNK: usize = 1 << 16;

/// Counts of a binary classification: true / false positives / negatives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct Confusion {
    /// Predicted positive, truly positive.
    pub tp: u64,
    /// Predicted positive, truly negative.
    pub fp: u64,
    /// Predicted negative, truly negative.
    pub tn: u64,
    /// Predicted negative, truly positive.
    #[serde(rename = "fn")]
    pub fn_: u64,
}

/// The scores of a [`Confusion`], each in [0, 1] (MCC in [-1, 1]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Metrics {
    /// tp / (tp + fp).
    pub precision: f64,
    /// tp / (tp + fn) (sensitivity, true-positive rate).
    pub recall: f64,
    /// 2 tp / (2 tp + fp + fn), the harmonic mean of precision and recall.
    pub f1: f64,
    /// Matthews correlation coefficient (tp tn - fp fn) / sqrt((tp+fp)(tp+fn)(tn+fp)(tn+fn)).
    pub mcc: f64,
    /// Intersection over union of the positive class, tp / (tp + fp + fn).
    pub iou: f64,
    /// (tp + tn) / total.
    pub accuracy: f64,
    /// tn / (tn + fp) (true-negative rate).
    pub specificity: f64,
}

fn ratio(num: u64, den: u64) -> f64 {
    if den == 0 {
        0.0
    } else {
        num as f64 / den as f64
    }
}

impl Confusion {
    /// Counts the matrix of `predicted` against `truth` (same length, item `i` of one matches
    /// item `i` of the other). Counting is parallel; integer sums make it exact whatever the
    /// thread count. Errors if the lengths differ.
    pub fn from_labels(predicted: &[bool], truth: &[bool]) -> Result<Confusion> {
        if predicted.len() != truth.len() {
            return Err(Error::InvalidArgument(format!(
                "confusion matrix: {} predicted labels for {} true labels",
                predicted.len(),
                truth.len()
            )));
        }
        Ok(predicted
            .par_chunks(CHUNK)
            .zip(truth.par_chunks(CHUNK))
            .map(|(p, t)| {
                let mut c = Confusion::default();
                for (&p, &t) in p.iter().zip(t) {
                    match (p, t) {
                        (true, true) => c.tp += 1,
                        (true, false) => c.fp += 1,
                        (false, false) => c.tn += 1,
                        (false, true) => c.fn_ += 1,
                    }
                }
                c
            })
            .reduce(Confusion::default, |a, b| a.merged(&b)))
    }

    /// The sum of two matrices (e.g. of two files scored together).
    pub fn merged(&self, o: &Confusion) -> Confusion {
        Confusion {
            tp: self.tp + o.tp,
            fp: self.fp + o.fp,
            tn: self.tn + o.tn,
            fn_: self.fn_ + o.fn_,
        }
    }

    /// Number of items.
    pub fn total(&self) -> u64 {
        self.tp + self.fp + self.tn + self.fn_
    }

    /// Truly positive items (tp + fn).
    pub fn positives(&self) -> u64 {
        self.tp + self.fn_
    }

    /// Truly negative items (tn + fp).
    pub fn negatives(&self) -> u64 {
        self.tn + self.fp
    }

    /// Items predicted positive (tp + fp).
    pub fn predicted_positives(&self) -> u64 {
        self.tp + self.fp
    }

    /// tp / (tp + fp); 0 when nothing is predicted positive.
    pub fn precision(&self) -> f64 {
        ratio(self.tp, self.tp + self.fp)
    }

    /// tp / (tp + fn); 0 when nothing is truly positive.
    pub fn recall(&self) -> f64 {
        ratio(self.tp, self.tp + self.fn_)
    }

    /// 2 tp / (2 tp + fp + fn); 0 when there is no positive at all (true or predicted).
    pub fn f1(&self) -> f64 {
        ratio(2 * self.tp, 2 * self.tp + self.fp + self.fn_)
    }

    /// tp / (tp + fp + fn); 0 when there is no positive at all.
    pub fn iou(&self) -> f64 {
        ratio(self.tp, self.tp + self.fp + self.fn_)
    }

    /// (tp + tn) / total; 0 for no items.
    pub fn accuracy(&self) -> f64 {
        ratio(self.tp + self.tn, self.total())
    }

    /// tn / (tn + fp); 0 when nothing is truly negative.
    pub fn specificity(&self) -> f64 {
        ratio(self.tn, self.tn + self.fp)
    }

    /// Matthews correlation coefficient, in [-1, 1]; 0 when any of tp+fp, tp+fn, tn+fp, tn+fn
    /// is 0. Computed in f64 (no integer product can overflow): the numerator as a difference
    /// of two products of counts, the denominator as a product of four square roots.
    pub fn mcc(&self) -> f64 {
        let (tp, fp, tn, fn_) = (
            self.tp as f64,
            self.fp as f64,
            self.tn as f64,
            self.fn_ as f64,
        );
        let factors = [tp + fp, tp + fn_, tn + fp, tn + fn_];
        if factors.contains(&0.0) {
            return 0.0;
        }
        let den: f64 = factors.iter().map(|f| f.sqrt()).product();
        ((tp * tn - fp * fn_) / den).clamp(-1.0, 1.0)
    }

    /// All the scores.
    pub fn metrics(&self) -> Metrics {
        Metrics {
            precision: self.precision(),
            recall: self.recall(),
            f1: self.f1(),
            mcc: self.mcc(),
            iou: self.iou(),
            accuracy: self.accuracy(),
            specificity: self.specificity(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(tp: u64, fp: u64, tn: u64, fn_: u64) -> Confusion {
        Confusion { tp, fp, tn, fn_ }
    }

    #[test]
    fn counts_match_a_hand_count() {
        let p = [true, true, false, false, true, false];
        let t = [true, false, false, true, true, false];
        assert_eq!(Confusion::from_labels(&p, &t).unwrap(), c(2, 1, 2, 1));
        assert!(Confusion::from_labels(&p, &t[..5]).is_err());
        // Larger than one chunk: the parallel reduction gives the sequential count.
        let n = 3 * CHUNK + 17;
        let p: Vec<bool> = (0..n).map(|i| i % 3 == 0).collect();
        let t: Vec<bool> = (0..n).map(|i| i % 5 == 0).collect();
        let m = Confusion::from_labels(&p, &t).unwrap();
        let tp = (0..n).filter(|i| i % 15 == 0).count() as u64;
        let pp = (0..n).filter(|i| i % 3 == 0).count() as u64;
        let tt = (0..n).filter(|i| i % 5 == 0).count() as u64;
        assert_eq!(m, c(tp, pp - tp, n as u64 - pp - tt + tp, tt - tp));
    }

    #[test]
    fn hand_computed_scores() {
        // tp 6, fp 2, tn 10, fn 4.
        let m = c(6, 2, 10, 4).metrics();
        assert_eq!(m.precision, 6.0 / 8.0);
        assert_eq!(m.recall, 6.0 / 10.0);
        assert_eq!(m.f1, 12.0 / 18.0);
        assert_eq!(m.iou, 6.0 / 12.0);
        assert_eq!(m.accuracy, 16.0 / 22.0);
        assert_eq!(m.specificity, 10.0 / 12.0);
        let mcc = (60.0 - 8.0) / (8.0f64 * 10.0 * 12.0 * 14.0).sqrt();
        assert!((m.mcc - mcc).abs() < 1e-15, "{} {mcc}", m.mcc);
    }

    #[test]
    fn perfect_inverted_and_empty_cases() {
        let m = c(5, 0, 7, 0).metrics();
        assert_eq!((m.precision, m.recall, m.f1, m.iou), (1.0, 1.0, 1.0, 1.0));
        assert!((m.mcc - 1.0).abs() < 1e-15);
        let m = c(0, 7, 0, 5).metrics();
        assert!((m.mcc + 1.0).abs() < 1e-15);
        assert_eq!(
            (m.precision, m.recall, m.f1, m.accuracy),
            (0.0, 0.0, 0.0, 0.0)
        );
        // Zero denominators are 0, never NaN.
        for m in [
            c(0, 0, 0, 0),
            c(0, 0, 9, 0),
            c(0, 0, 0, 9),
            c(9, 0, 0, 0),
            c(0, 9, 0, 0),
        ] {
            let s = m.metrics();
            for v in [
                s.precision,
                s.recall,
                s.f1,
                s.mcc,
                s.iou,
                s.accuracy,
                s.specificity,
            ] {
                assert!(v.is_finite(), "{m:?} {s:?}");
            }
            assert_eq!(s.mcc, 0.0);
        }
        assert_eq!(c(0, 0, 9, 0).precision(), 0.0);
        assert_eq!(c(0, 0, 9, 0).f1(), 0.0);
    }

    #[test]
    fn mcc_of_huge_counts_does_not_overflow() {
        let big = 3_000_000_000u64;
        let m = c(big, big / 3, 4 * big, big / 7);
        let v = m.mcc();
        assert!(v.is_finite() && v > 0.0 && v < 1.0, "{v}");
        // Scaling all counts leaves MCC unchanged.
        let s = c(21, 7, 84, 3).mcc();
        assert!((c(21 * big, 7 * big, 84 * big, 3 * big).mcc() - s).abs() < 1e-12);
    }
}
