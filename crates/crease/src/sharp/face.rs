//! One-face neighbourhoods: the k nearest neighbours of a point less those that lie on another
//! sheet of the surface parallel to the point's own, such as the opposite face of a plate
//! thinner than the neighbourhood or the facing wall of a narrow slot.
//!
//! Tran et al. take N(i) as the k nearest points (section 2.1) and the projected distance of
//! equation 3 assumes they sample one surface around p_i. On a plate a few spacings thick the
//! k = 12..40 nearest points include the opposite face (on most points of the thin-plate
//! PCEDNet models, see `docs/experiments/sharp-points.md`), the neighbourhood's centroid lies
//! between the faces and every point of the plate looks sharp. This module drops those
//! neighbours before the measure is taken.
//!
//! **The test.** Every point gets a small-scale normal m_i (`face_normals`): the PCA normal of
//! the point and its [`FACE_K`] nearest neighbours (few enough that the opposite face is rarely
//! among them), refitted [`FACE_REFITS`] times over those of its [`FACE_K_REFIT`] nearest whose
//! chord q − p makes at most [`CHORD_DEG`] with the current plane (which drops the opposite face
//! and the far side of an edge from the fit). Neighbour j of point i is on another sheet
//! (`SheetTest::other_sheet`) when
//! * the two normals are parallel, |m_i·m_j| ≥ cos [`PARALLEL_DEG`], and
//! * the chord leaves both tangent planes by more than [`CHORD_DEG`]:
//!   |d·m_i| > sin(β)‖d‖ and |d·m_j| > sin(β)‖d‖, d = p_j − p_i.
//!
//! Two points of one smooth sheet have chords that make half the angle between their normals
//! with the tangent planes (exactly so on a circle), so with β = 15° > 20°/2 no neighbour on a
//! smooth surface is dropped, whatever its curvature; across a sharp edge the normals are not
//! parallel and the neighbour is kept, so edges keep the neighbourhoods that make them sharp;
//! a parallel sheet at offset t is dropped up to a distance t / tan β ≈ 3.7 t, which covers the
//! 40 nearest neighbours on plates down to about one spacing thick. The test is symmetric and
//! needs no length scale, so it is invariant to the cloud's scale and density.
//!
//! Scale s then uses the neighbours that pass the test among the s nearest (the neighbourhood
//! keeps the radius of the s-nearest ball), so one kNN query still serves every scale.
//!
//! **Cost**: three 3 × 3 eigenproblems per point for the small-scale normals and one test per
//! neighbour, and 24 B a point for the normals (timed in `docs/experiments/sharp-points.md`).
//!
//! The small-scale PCA normals score nearly as well as exact ones on the clean PCEDNet models;
//! other normals (fewer neighbours, no refit, a refit over the one-face neighbourhood, a
//! RANSAC plane) and taking the first s survivors of a larger query scored lower or cost more
//! (`docs/experiments/sharp-points.md`).

use rayon::prelude::*;

use crate::estimate::normals::smallest_eigen4;
use crate::geometry::plane::Moments;
use crate::geometry::{vec3, Point3};
use crate::spatial::Neighborhoods;

/// Neighbours of the first small-scale fit of `face_normals`.
pub const FACE_K: usize = 6;
/// Neighbours among which the refits of `face_normals` choose.
pub const FACE_K_REFIT: usize = 12;
/// Number of refits of `face_normals`.
pub const FACE_REFITS: usize = 2;
/// Normals at most this far apart (degrees) are parallel in `SheetTest::other_sheet`.
pub const PARALLEL_DEG: f64 = 20.0;
/// A chord further than this (degrees) from a tangent plane leaves it (`SheetTest::other_sheet`, refits).
pub const CHORD_DEG: f64 = 15.0;

/// Uniform covariance of `p` and the points of `q` (moments about `p`), whose smallest
/// eigenvector is their PCA normal (`[0, 0, 1]` when degenerate).
fn plane_covariance(p: Point3, q: impl Iterator<Item = Point3>) -> [f64; 6] {
    let mut mo = Moments::origin();
    for x in q {
        mo.add(vec3::sub(x, p));
    }
    mo.centroid_covariance().1
}

/// The small-scale normals m_i of the one-face test (see the module documentation), in input
/// order; `nbrs` must hold at least [`FACE_K_REFIT`] neighbours per point (fewer are used when
/// it holds fewer). Does not depend on the thread count.
///
/// Four points at a time: each fit's eigenproblem is solved for the four together
/// ([`smallest_eigen4`], bitwise the scalar solve), since one at a time the three dependent
/// solves per point were a latency-bound chain (a quarter of the samples of `crease sharp` on
/// 1M points).
pub(crate) fn face_normals(points: &[Point3], nbrs: &Neighborhoods) -> Vec<Point3> {
    let sin_chord = CHORD_DEG.to_radians().sin();
    let mut out = vec![[0.0; 3]; points.len()];
    out.par_chunks_mut(4)
        .enumerate()
        .with_min_len(64)
        .for_each(|(c, chunk)| {
            let all: [usize; 4] = std::array::from_fn(|l| 4 * c + l);
            let ids = &all[..chunk.len()];
            let mut covs = [[0.0; 6]; 4];
            for (cov, &i) in covs.iter_mut().zip(ids) {
                let first = nbrs.prefix(i, FACE_K).iter();
                *cov = plane_covariance(points[i], first.map(|&j| points[j as usize]));
            }
            let mut normals = smallest_eigen4(covs).map(|s| s.0);
            // A lane stops refitting at its first round with fewer than 3 neighbours on the
            // plane, as the scalar loop breaks.
            let mut done = [false; 4];
            for _ in 0..FACE_REFITS {
                let mut refit = [false; 4];
                for (l, &i) in ids.iter().enumerate() {
                    covs[l] = [0.0; 6];
                    if done[l] {
                        continue;
                    }
                    let (p, n) = (points[i], normals[l]);
                    // One pass: the neighbours on the plane are counted and summed together
                    // (the same sums, in the same order, as `plane_covariance`).
                    let mut mo = Moments::origin();
                    let mut on = 0usize;
                    for &j in nbrs.prefix(i, FACE_K_REFIT) {
                        let d = vec3::sub(points[j as usize], p);
                        if vec3::dot(d, n).abs() <= sin_chord * vec3::norm(d) {
                            mo.add(d);
                            on += 1;
                        }
                    }
                    if on < 3 {
                        done[l] = true;
                        continue;
                    }
                    covs[l] = mo.centroid_covariance().1;
                    refit[l] = true;
                }
                if !refit.contains(&true) {
                    break;
                }
                let solved = smallest_eigen4(covs);
                for ((n, s), &r) in normals.iter_mut().zip(solved).zip(&refit) {
                    if r {
                        *n = s.0;
                    }
                }
            }
            chunk.copy_from_slice(&normals[..chunk.len()]);
        });
    out
}

/// Cosine of [`PARALLEL_DEG`] and sine of [`CHORD_DEG`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct SheetTest {
    cos_parallel: f64,
    sin_chord: f64,
}

impl Default for SheetTest {
    fn default() -> Self {
        SheetTest {
            cos_parallel: PARALLEL_DEG.to_radians().cos(),
            sin_chord: CHORD_DEG.to_radians().sin(),
        }
    }
}

impl SheetTest {
    /// True when `q` (small-scale normal `mq`) lies on another sheet parallel to the one of
    /// `p` (normal `mp`), see the module documentation.
    #[inline]
    pub(crate) fn other_sheet(&self, p: Point3, mp: Point3, q: Point3, mq: Point3) -> bool {
        if vec3::dot(mp, mq).abs() < self.cos_parallel {
            return false;
        }
        let d = vec3::sub(q, p);
        let lim = self.sin_chord * vec3::norm(d);
        vec3::dot(d, mp).abs() > lim && vec3::dot(d, mq).abs() > lim
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::knn;

    /// A plate 1.3 spacings thick: every neighbour of a point inside a face that is dropped is
    /// on the other face, and most of the other face is dropped; a 90° edge keeps both faces.
    #[test]
    fn plate_faces_are_separated_and_edges_kept() {
        let mut pts = Vec::new();
        for z in [0.0, 1.3] {
            for y in 0..30 {
                for x in 0..30 {
                    pts.push([x as f64 + 0.25 * (y % 2) as f64, y as f64, z]);
                }
            }
        }
        let nb = knn(&pts, 40).unwrap();
        let m = face_normals(&pts, &nb);
        let t = SheetTest::default();
        let i = 15 * 30 + 15;
        let (mut other, mut dropped_other, mut dropped_same) = (0, 0, 0);
        for &j in nb.of(i) {
            let j = j as usize;
            let drop = t.other_sheet(pts[i], m[i], pts[j], m[j]);
            let is_other = pts[j][2] != pts[i][2];
            other += usize::from(is_other);
            dropped_other += usize::from(drop && is_other);
            dropped_same += usize::from(drop && !is_other);
        }
        assert_eq!(dropped_same, 0);
        assert!(
            other > 10 && dropped_other == other,
            "{dropped_other} of {other}"
        );
        // A 90° edge: the faces z = 0 (x < 0) and x = 0 (z < 0) share the line x = z = 0.
        let mut edge = Vec::new();
        for y in 0..30 {
            for a in 0..15 {
                edge.push([-(a as f64), y as f64, 0.0]);
                if a > 0 {
                    edge.push([0.0, y as f64, -(a as f64)]);
                }
            }
        }
        let nb = knn(&edge, 40).unwrap();
        let m = face_normals(&edge, &nb);
        for i in 0..edge.len() {
            if edge[i][1] < 5.0 || edge[i][1] > 24.0 {
                continue;
            }
            for &j in nb.of(i) {
                let j = j as usize;
                assert!(
                    !t.other_sheet(edge[i], m[i], edge[j], m[j]),
                    "{:?} {:?}",
                    edge[i],
                    edge[j]
                );
            }
        }
    }
}
