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
//!
//! **Own side** (clouds, `same_side`). Two edges of a rim thinner than the comparison
//! neighbourhood (the edges of a plate 1.3–1.8 spacings thick on the PCEDNet models 7038 and
//! 7010, where the ground truth labels both) are two parallel lines one or two spacings apart,
//! and the plain comparison keeps only the sharper of them. What tells them apart is the side
//! the point sticks out to: the unit displacement u_i = (p_i − p̄_i)/‖p_i − p̄_i‖ from the
//! centroid of its `k_dir` nearest points (the direction in which tran's projected distance,
//! equation 3, is measured) points along the bisector of the edge's two faces. On both sides
//! of one edge the bisector is the same; on the two edges of a rim the bisectors differ by the
//! angle between the rim face and the plate faces (90° on a square rim). A neighbour is
//! compared only when u_i·u_j ≥ cos [`SIDE_DEG`] (60°), so each edge of a rim is thinned on
//! its own. Tran et al. do not thin; this is a choice of ours. It keeps both edges of the
//! propeller blades of PCEDNet model 7038 (60° scored best among 30° to 90°; the one-face
//! test of [`super::face`] as the criterion did not: the small-scale normals of the two edges
//! of a rim are rarely parallel); figures in `docs/experiments/sharp-points.md`. Meshes keep
//! the plain comparison (not measured there).

use rayon::prelude::*;

use crate::geometry::fit_plane;
use crate::geometry::{vec3, Point3};

/// Two detected points are compared only when their displacement directions are at most this
/// far apart (degrees), see the module documentation.
pub const SIDE_DEG: f64 = 60.0;

/// Suppresses detected points that are not the sharpest across their line (see the module doc).
///
/// `rows(i)`: neighbours of point i, nearest first. `k_dir` / `k_cmp`: how many of them give the
/// line direction and the displacement direction / are compared. `same_side`: compare only
/// neighbours displaced to the same side. Returns the thinned labels.
pub(crate) fn thin<'a, R>(
    points: &'a [Point3],
    sharp: &[bool],
    sharpness: &[f64],
    rows: R,
    k_dir: usize,
    k_cmp: usize,
    same_side: bool,
) -> Vec<bool>
where
    R: Fn(usize) -> &'a [u32] + Sync,
{
    let side = same_side.then(|| displacements(points, sharp, &rows, k_dir));
    let cos_side = SIDE_DEG.to_radians().cos();
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
                if let Some(u) = &side {
                    // A zero displacement (a point at its centroid) is compared.
                    let c = vec3::dot(u[i], u[j]);
                    if c < cos_side && u[i] != [0.0; 3] && u[j] != [0.0; 3] {
                        return false;
                    }
                }
                let sj = sharpness[j];
                sj > si || (sj == si && j < i)
            })
        })
        .collect()
}

/// The unit displacement p_i − p̄_i from the centroid of the point's `k` nearest (and itself)
/// for the detected points; zero for the others and where the point is at its centroid.
fn displacements<'a, R>(points: &'a [Point3], sharp: &[bool], rows: &R, k: usize) -> Vec<Point3>
where
    R: Fn(usize) -> &'a [u32] + Sync,
{
    (0..points.len())
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            if !sharp[i] {
                return [0.0; 3];
            }
            let p = points[i];
            let (s, m) = rows(i)
                .iter()
                .take(k)
                .fold(([0.0f64; 3], 1usize), |(s, m), &j| {
                    (vec3::add(s, vec3::sub(points[j as usize], p)), m + 1)
                });
            let d = vec3::scale(s, -1.0 / m as f64);
            let len = vec3::norm(d);
            if len > 0.0 {
                vec3::scale(d, 1.0 / len)
            } else {
                [0.0; 3]
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::knn;

    /// The two edges of a square rim 1.5 spacings wide are both kept with `same_side` (their
    /// displacements differ by 90°), while the plain comparison keeps only one line.
    #[test]
    fn both_edges_of_a_thin_rim_are_kept() {
        // A plate 1.5 thick: top z = 1.5 and bottom z = 0 for x <= 0, rim face x = 0.
        let mut pts = Vec::new();
        for y in 0..40 {
            for a in 0..10 {
                let (x, y) = (-(a as f64), y as f64);
                pts.push([x, y, 0.0]);
                pts.push([x - 0.5, y + 0.5, 1.5]);
            }
            pts.push([0.0, y as f64 + 0.5, 0.75]);
        }
        let nb = knn(&pts, 16).unwrap();
        // The detections: both rim edges (top row x = -0.5 and bottom row x = 0), the top one
        // sharper.
        let sharp: Vec<bool> = pts
            .iter()
            .map(|p| (p[0] == 0.0 && p[2] == 0.0) || (p[0] == -0.5 && p[2] == 1.5))
            .collect();
        let sharpness: Vec<f64> = pts
            .iter()
            .map(|p| if p[2] > 1.0 { 2.0 } else { 1.5 })
            .collect();
        let run = |same| thin(&pts, &sharp, &sharpness, |i| nb.prefix(i, 16), 16, 8, same);
        let inner = |l: &[bool], z: f64| {
            (0..pts.len())
                .filter(|&i| l[i] && pts[i][2] == z && (5.0..35.0).contains(&pts[i][1]))
                .count()
        };
        let plain = run(false);
        let own = run(true);
        assert_eq!(inner(&plain, 0.0), 0);
        assert_eq!(inner(&own, 0.0), 30);
        assert_eq!(inner(&own, 1.5), 30);
        // Deterministic.
        assert_eq!(own, run(true));
    }
}
