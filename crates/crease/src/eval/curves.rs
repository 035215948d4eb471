//! Scores of feature polylines against exact curves: how much of each true curve a line passes
//! near (coverage), and how much of the lines' length lies near a true curve (precision), both
//! within a tolerance (the measure: 2 spacings).

use rayon::prelude::*;

use crate::geometry::vec3::{dist, segment_distance};
use crate::geometry::Point3;
use crate::spatial::KdIndex;

/// Coverage and precision of polylines against true curves.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveScores {
    /// Per true curve: the fraction of its samples within the tolerance of a line.
    pub coverage: Vec<f64>,
    /// The fraction of the lines' length within the tolerance of a true curve.
    pub precision: f64,
}

impl CurveScores {
    /// The least coverage of a true curve (1 without curves).
    pub fn coverage_min(&self) -> f64 {
        self.coverage.iter().copied().fold(1.0, f64::min)
    }
}

/// Points along the segments of `lines`, at most `step` apart, with the length each stands for.
fn samples(lines: &[Vec<Point3>], step: f64) -> Vec<(Point3, f64)> {
    let mut out = Vec::new();
    for l in lines {
        for w in l.windows(2) {
            let len = dist(w[0], w[1]);
            let n = ((len / step).ceil() as usize).clamp(1, 1 << 20);
            for i in 0..n {
                let t = (i as f64 + 0.5) / n as f64;
                let p = [0, 1, 2].map(|k| w[0][k] + t * (w[1][k] - w[0][k]));
                out.push((p, len / n as f64));
            }
        }
    }
    out
}

/// Whether `p` lies within `tol` of one of the segments of the polylines whose samples `index`
/// holds (`owner`: the segment of each sample, `step`: their spacing).
fn near(
    p: Point3,
    index: &KdIndex,
    owner: &[(usize, usize)],
    lines: &[Vec<Point3>],
    tol: f64,
    step: f64,
) -> bool {
    // A point within tol of a segment lies within tol + step / 2 of one of its samples.
    index
        .nearest(&p, 16)
        .iter()
        .take_while(|&&(_, d2)| d2.sqrt() <= tol + step)
        .any(|&(s, _)| {
            let (l, i) = owner[s as usize];
            segment_distance(p, lines[l][i], lines[l][i + 1]) <= tol
        })
}

/// Scores `lines` (polylines) against `truth` (polylines densely sampled on the exact curves;
/// a closed curve's last point joins its first) within `tol`.
pub fn score_curves(truth: &[(Vec<Point3>, bool)], lines: &[Vec<Point3>], tol: f64) -> CurveScores {
    let step = tol / 2.0;
    let index_of = |polylines: &[Vec<Point3>]| {
        let mut pts = Vec::new();
        let mut owner = Vec::new();
        for (l, line) in polylines.iter().enumerate() {
            for i in 0..line.len().saturating_sub(1) {
                let len = dist(line[i], line[i + 1]);
                let n = ((len / step).ceil() as usize).clamp(1, 1 << 20);
                for j in 0..=n {
                    let t = j as f64 / n as f64;
                    pts.push([0, 1, 2].map(|k| line[i][k] + t * (line[i + 1][k] - line[i][k])));
                    owner.push((l, i));
                }
            }
        }
        (KdIndex::new(&pts), owner)
    };
    let closed_truth: Vec<Vec<Point3>> = truth
        .iter()
        .map(|(pts, closed)| {
            let mut p = pts.clone();
            if *closed && p.len() > 2 {
                p.push(p[0]);
            }
            p
        })
        .collect();
    let (line_index, line_owner) = index_of(lines);
    let coverage = closed_truth
        .iter()
        .map(|curve| {
            let s = samples(std::slice::from_ref(curve), step);
            let total: f64 = s.iter().map(|(_, w)| w).sum();
            let Some(index) = &line_index else {
                return 0.0;
            };
            let hit: f64 = s
                .par_iter()
                .filter(|(p, _)| near(*p, index, &line_owner, lines, tol, step))
                .map(|(_, w)| w)
                .sum();
            if total > 0.0 {
                hit / total
            } else {
                1.0
            }
        })
        .collect();
    let (truth_index, truth_owner) = index_of(&closed_truth);
    let s = samples(lines, step);
    let total: f64 = s.iter().map(|(_, w)| w).sum();
    let good: f64 = match &truth_index {
        Some(index) => s
            .par_iter()
            .filter(|(p, _)| near(*p, index, &truth_owner, &closed_truth, tol, step))
            .map(|(_, w)| w)
            .sum(),
        None => 0.0,
    };
    CurveScores {
        coverage,
        precision: if total > 0.0 { good / total } else { 1.0 },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_along_half_a_curve_covers_half_and_is_precise() {
        let truth = vec![(vec![[0.0, 0.0, 0.0], [10.0, 0.0, 0.0]], false)];
        let lines = vec![
            vec![[0.0, 0.1, 0.0], [5.0, 0.1, 0.0]],
            vec![[0.0, 5.0, 0.0], [5.0, 5.0, 0.0]],
        ];
        let s = score_curves(&truth, &lines, 0.5);
        // Covered: x in [0, 5.5] (the tolerance reaches past the line's end).
        assert!((s.coverage[0] - 0.55).abs() < 0.02, "{s:?}");
        assert!((s.precision - 0.5).abs() < 0.05, "{s:?}");
    }
}
