//! Step 2: the curvature of one region (demarsin2008 sections 2.1 and 2.4): Taubin smoothing,
//! the quadric fit over the region's own k nearest neighbours and the signed median filter.

use rayon::prelude::*;

use crate::estimate::curvature::{quadric_curvature, QuadricParams};
use crate::geometry::{Csr, Point3};
use crate::spatial::knn;
use crate::Result;

/// Taubin λ|μ smoothing over the 1-ring (umbrella operator), `iterations` pairs of steps.
pub(super) fn taubin(points: &[Point3], adjacency: &Csr, iterations: usize) -> Vec<Point3> {
    const LAMBDA: f64 = 0.5;
    const MU: f64 = -0.53;
    let mut cur = points.to_vec();
    for _ in 0..iterations {
        for f in [LAMBDA, MU] {
            cur = (0..cur.len())
                .into_par_iter()
                .map(|i| {
                    let row = adjacency.row(i);
                    if row.is_empty() {
                        return cur[i];
                    }
                    let mut s = [0.0; 3];
                    for &q in row {
                        for k in 0..3 {
                            s[k] += cur[q as usize][k];
                        }
                    }
                    let inv = 1.0 / row.len() as f64;
                    let p = cur[i];
                    [
                        p[0] + f * (s[0] * inv - p[0]),
                        p[1] + f * (s[1] * inv - p[1]),
                        p[2] + f * (s[2] * inv - p[2]),
                    ]
                })
                .collect();
        }
    }
    cur
}

/// Every signed mean curvature replaced by the median over the point and its kNN row (NaN
/// values skipped), each neighbour's value taken relative to the point's normal (negated when
/// the two fitted normals point to opposite sides). On a flat patch the noise makes H scatter
/// on both sides of 0 and the median brings it back to 0, which a filter of |H| cannot do; at
/// the border of two patches the median keeps the step where it is (a median filter preserves
/// monotone steps), unlike a mean.
fn median_filter(
    values: &[f64],
    normals: &[Point3],
    nbrs: &crate::spatial::Neighborhoods,
) -> Vec<f64> {
    (0..values.len())
        .into_par_iter()
        .map_init(Vec::new, |buf: &mut Vec<f64>, i| {
            buf.clear();
            buf.extend(
                std::iter::once(values[i])
                    .chain(nbrs.of(i).iter().map(|&q| {
                        let q = q as usize;
                        if crate::geometry::vec3::dot(normals[i], normals[q]) < 0.0 {
                            -values[q]
                        } else {
                            values[q]
                        }
                    }))
                    .filter(|v| v.is_finite()),
            );
            if buf.is_empty() {
                return f64::NAN;
            }
            let mid = buf.len() / 2;
            let (_, m, _) = buf.select_nth_unstable_by(mid, f64::total_cmp);
            *m
        })
        .collect()
}

/// |H| of every point of a region: quadric fit over its `k` nearest neighbours in the region,
/// then `median_iterations` passes of the signed median filter.
pub(super) fn region_curvature(
    points: &[Point3],
    k: usize,
    median_iterations: usize,
) -> Result<Vec<f64>> {
    let nbrs = knn(points, k)?;
    let curv = quadric_curvature(points, &nbrs, &QuadricParams { k })?;
    // Signed mean curvature, each relative to its own point's fitted normal.
    let mut values = curv.mean.clone();
    for _ in 0..median_iterations {
        values = median_filter(&values, &curv.normal, &nbrs);
    }
    Ok(values.iter().map(|h| h.abs()).collect())
}
