//! Average spacing: the mean distance from a point to its nearest neighbour.
//!
//! Every automatic default in crease (neighbourhood radii, noise levels, tolerances) scales with
//! it. Coincident points (distance 0) are skipped: they say nothing about the sampling density.

use rayon::prelude::*;

use super::KdIndex;
use crate::geometry::Point3;

/// Queries beyond this many points are subsampled (every `n / MAX_QUERIES`-th point): the mean
/// of 200k nearest-neighbour distances is within a fraction of a percent of the full mean, and
/// keeps `crease info` on a 10M-point scan to a few seconds.
const MAX_QUERIES: usize = 200_000;

/// Mean nearest-neighbour distance of `points` (finite coordinates expected), or `None` when
/// fewer than two distinct points exist.
pub fn average_spacing(points: &[Point3]) -> Option<f64> {
    if points.len() < 2 {
        return None;
    }
    let index = KdIndex::new(points)?;
    average_spacing_with(&index, points)
}

/// As [`average_spacing`], with a k-d tree already built over `points`.
pub fn average_spacing_with(index: &KdIndex, points: &[Point3]) -> Option<f64> {
    let stride = points.len().div_ceil(MAX_QUERIES).max(1);
    let (sum, count) = (0..points.len())
        .into_par_iter()
        .step_by(stride)
        .map(|i| {
            // Ask for a few neighbours so that duplicates of `i` (distance 0) can be skipped.
            let nn = index.nearest(&points[i], 4);
            match nn.iter().find(|(_, d2)| *d2 > 0.0) {
                Some((_, d2)) => (d2.sqrt(), 1usize),
                None => (0.0, 0),
            }
        })
        .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
    (count > 0).then(|| sum / count as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_spacing_is_the_grid_step() {
        let mut p = Vec::new();
        for i in 0..30 {
            for j in 0..30 {
                p.push([i as f64 * 0.5, j as f64 * 0.5, 0.0]);
            }
        }
        let s = average_spacing(&p).unwrap();
        assert!((s - 0.5).abs() < 1e-12, "{s}");
    }

    #[test]
    fn duplicates_are_skipped_and_tiny_inputs_give_none() {
        assert_eq!(average_spacing(&[[0.0; 3]]), None);
        assert_eq!(average_spacing(&[[0.0; 3], [0.0; 3]]), None);
        let s = average_spacing(&[[0.0; 3], [0.0; 3], [2.0, 0.0, 0.0]]).unwrap();
        assert!((s - 2.0).abs() < 1e-12);
    }
}
