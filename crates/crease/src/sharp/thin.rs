//! Thinning of detected sharp points to lines one or two points wide: non-maximum suppression of
//! the sharpness across the feature line (as Canny's edge detector thins image edges).
//!
//! Tran et al. find "in most cases, the detected features are one-point wide" (section 1); with
//! the density-invariant measure and irregular sampling the detections are bands two to four
//! points wide, wider than the feature-line ground truth of the PCEDNet benchmark (where a
//! ground-truth sharp point lies about one spacing from a non-sharp one). A detected point p is
//! kept when no detected neighbour *across* the line is sharper: the line's direction e at p is
//! the principal axis of the detected points among p's `k_dir` nearest neighbours, and a
//! neighbour q among the `k_cmp` nearest is across the line when the angle between q − p and e
//! exceeds 60°. Points along the line are never compared, so the line stays connected. Ties are
//! broken by the smaller index, so the result does not depend on the thread count.

use rayon::prelude::*;

use crate::estimate::fit_plane;
use crate::geometry::{vec3, Point3};

/// Suppresses detected points that are not the sharpest across their line (see the module doc).
///
/// `rows(i)`: neighbours of point i, nearest first. `k_dir` / `k_cmp`: how many of them give the
/// line direction / are compared. Returns the thinned labels.
pub(crate) fn thin<'a, R>(
    points: &'a [Point3],
    sharp: &[bool],
    sharpness: &[f64],
    rows: R,
    k_dir: usize,
    k_cmp: usize,
) -> Vec<bool>
where
    R: Fn(usize) -> &'a [u32] + Sync,
{
    (0..points.len())
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            if !sharp[i] {
                return false;
            }
            let row = rows(i);
            let p = points[i];
            let dir_pts = std::iter::once(i as u32)
                .chain(row.iter().take(k_dir).copied())
                .filter(|&j| sharp[j as usize])
                .map(|j| (points[j as usize], 1.0));
            let Some(e) = fit_plane(dir_pts).and_then(|pl| {
                // A line: one eigenvalue dominates.
                (pl.eigenvalues[2] > 2.0 * pl.eigenvalues[1]).then_some(pl.axes[2])
            }) else {
                return true;
            };
            let si = sharpness[i];
            !row.iter().take(k_cmp).any(|&j| {
                let j = j as usize;
                if !sharp[j] {
                    return false;
                }
                let d = vec3::sub(points[j], p);
                let len = vec3::norm(d);
                if len == 0.0 || vec3::dot(d, e).abs() > 0.5 * len {
                    return false;
                }
                let sj = sharpness[j];
                sj > si || (sj == si && j < i)
            })
        })
        .collect()
}
