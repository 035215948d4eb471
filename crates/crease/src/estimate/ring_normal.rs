//! The 1-ring normal of demarsin2007 section 2.2: "the normal in p is estimated as the normal of
//! the least squares plane through the 1-ring neighborhood of p" (citing \[15\]), with the 1-ring
//! the Delaunay neighbourhood of [`crate::spatial::delaunay_rings`]. Because the ring holds only
//! the few points around p, the normal changes over a much narrower band at a sharp edge than a
//! k-nearest-neighbour (PCA) normal, which is what the paper's region growing relies on.

use rayon::prelude::*;

use crate::geometry::fit_plane;
use crate::geometry::Point3;
use crate::spatial::ring::{canonical_sign, Rings, COLLINEAR_RATIO};

/// The unit normal of the least-squares plane through each point and its Delaunay 1-ring
/// (unweighted), in the input order; identical whatever the thread count.
///
/// Inputs: `points` (n positions) and their `rings` (from
/// [`crate::spatial::delaunay_rings`] on the same points). Output: n unoriented unit normals.
///
/// Sign convention: the normal points to the same side as the k-nearest-neighbour plane normal
/// stored in `rings.plane_normals` (itself signed by [`canonical_sign`]: its largest-magnitude
/// component is positive); where that is unavailable, or the two are exactly perpendicular,
/// [`canonical_sign`] is applied to the ring normal itself. Consistent orientation is another
/// module's job.
///
/// Fallback: a point whose ring has fewer than 2 members, or whose ring is collinear with it
/// (see [`COLLINEAR_RATIO`]), gets the k-nearest-neighbour plane normal
/// (`rings.plane_normals[i]`, `[NaN; 3]` where not even that plane exists).
///
/// Panics if `rings` does not have one row per point or refers to points out of range (both
/// hold for rings built from `points`).
pub fn ring_normals(points: &[Point3], rings: &Rings) -> Vec<Point3> {
    assert_eq!(
        points.len(),
        rings.len(),
        "ring_normals: rings were built for a different number of points"
    );
    (0..points.len())
        .into_par_iter()
        .map(|i| {
            let fallback = rings.plane_normals[i];
            let ring = rings.ring(i);
            if ring.len() < 2 {
                return fallback;
            }
            let plane = fit_plane(
                std::iter::once(points[i])
                    .chain(ring.iter().map(|&j| points[j as usize]))
                    .map(|q| (q, 1.0)),
            );
            let Some(plane) = plane else {
                return fallback;
            };
            let [_, l1, l2] = plane.eigenvalues;
            if l1.is_nan() || l1 <= COLLINEAR_RATIO * l2 {
                return fallback;
            }
            let n = plane.normal;
            let d = n[0] * fallback[0] + n[1] * fallback[1] + n[2] * fallback[2];
            if d > 0.0 {
                n
            } else if d < 0.0 {
                [-n[0], -n[1], -n[2]]
            } else {
                canonical_sign(n)
            }
        })
        .collect()
}
