//! Principal curvatures of point clouds from a quadric fitted over the k nearest neighbours in a
//! local frame (demarsin2008 section 2.1: "to compute the mean curvature in p, we fit a quadric
//! through the k nearest neighbors of p, as described in e.g. \[18\]" — Petitjean's survey of
//! quadric fitting), plus the Monge-patch curvature formulas shared with the Bézier fit of
//! [`super::bezier`].
//!
//! Per point `p` with neighbours `N(p)` (the first `k` of its kNN row):
//! 1. The least-squares plane of `{p} ∪ N(p)` (its normal is the eigenvector of the smallest
//!    eigenvalue of the covariance, as in [`crate::geometry::fit_plane`], computed here in closed form) gives
//!    an orthonormal frame `(e1, e2, n)`; the frame's origin is `p` itself.
//! 2. In that frame (coordinates scaled by the neighbourhood radius for conditioning) the height
//!    function `z = a x² + b xy + c y² + d x + e y + f` is fitted by linear least squares
//!    (6 × 6 normal equations, Cholesky on a fixed-size nalgebra matrix). The full form with the
//!    linear and constant terms is used because the plane is the neighbourhood's plane, not the
//!    tangent plane at `p`: the linear terms absorb its tilt (on a curved surface the centroid's
//!    plane is not tangent at an off-centre point) and `f` absorbs the offset of `p` from the
//!    fitted surface (noise). Dropping them biases the curvature wherever `p` is not the
//!    neighbourhood's centre (boundaries, anisotropic sampling).
//! 3. The curvatures are those of the graph surface at `(0, 0)`: first fundamental form
//!    `E = 1 + z_x², F = z_x z_y, G = 1 + z_y²`, second `L, M, N = -(z_xx, z_xy, z_yy) / w` with
//!    `w = √(1 + z_x² + z_y²)`; `H = (EN + GL − 2FM) / 2(EG − F²)`, `K = (LN − M²) / (EG − F²)`,
//!    `k1,2 = H ± √(H² − K)`; the principal directions solve `(II − k I) t = 0`.
//!
//! Sign convention: curvatures are positive where the surface bends away from the normal, so a
//! sphere with outward normals has `k1 = k2 = +1/r`. The normal is the fitted surface's normal
//! at `p` (the refitted normal). With [`quadric_curvature_oriented`] it points to the side of
//! the given normals; [`quadric_curvature`] has no orientation to go by and orients each normal
//! so that `H ≥ 0`: its `mean` is then the unsigned mean curvature `|H|` (what demarsin2008's
//! histogram needs) and `k1 ≥ k2` holds with `k1 ≥ |k2|`.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

use crate::geometry::normal_eq::{add_outer, symmetrize};
use crate::geometry::vec3::{add, cross, dot, normalize, scale, sub};
use crate::geometry::Point3;
use crate::spatial::Neighborhoods;
use crate::{Error, Result};

/// Per-point curvature estimates (all vectors have one entry per input point, input order).
///
/// Points whose fit is impossible (fewer than 5 neighbours, neighbours on a line, non-finite
/// coordinates) get `NaN` curvatures and zero vectors; [`Curvature::num_failed`] counts them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Curvature {
    /// Larger principal curvature.
    pub k1: Vec<f64>,
    /// Smaller principal curvature (`k2 ≤ k1`).
    pub k2: Vec<f64>,
    /// Mean curvature `H = (k1 + k2) / 2`.
    pub mean: Vec<f64>,
    /// Gaussian curvature `K = k1 k2`.
    pub gaussian: Vec<f64>,
    /// Unit principal direction of `k1` (tangent to the fitted surface).
    pub dir1: Vec<Point3>,
    /// Unit principal direction of `k2` (`normal × dir1`).
    pub dir2: Vec<Point3>,
    /// Unit normal of the fitted surface at the point (the sign convention's reference).
    pub normal: Vec<Point3>,
}

impl Curvature {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.k1.len()
    }

    /// True if there are no points.
    pub fn is_empty(&self) -> bool {
        self.k1.is_empty()
    }

    /// The curvatures of the points `picks` (e.g. every input point's distinct copy,
    /// [`crate::spatial::distinct_in_input_order`]).
    pub fn select(&self, picks: &[u32]) -> Curvature {
        fn pick<T: Copy + Send + Sync>(v: &[T], picks: &[u32]) -> Vec<T> {
            picks.par_iter().map(|&i| v[i as usize]).collect()
        }
        Curvature {
            k1: pick(&self.k1, picks),
            k2: pick(&self.k2, picks),
            mean: pick(&self.mean, picks),
            gaussian: pick(&self.gaussian, picks),
            dir1: pick(&self.dir1, picks),
            dir2: pick(&self.dir2, picks),
            normal: pick(&self.normal, picks),
        }
    }

    /// Number of points whose fit failed (`NaN` curvatures).
    pub fn num_failed(&self) -> usize {
        self.k1.iter().filter(|k| k.is_nan()).count()
    }

    /// Per point, the principal curvature of larger absolute value (mizoguchi's `κ_max`).
    pub fn max_abs(&self) -> Vec<f64> {
        self.k1
            .iter()
            .zip(&self.k2)
            .map(|(&a, &b)| if a.abs() >= b.abs() { a } else { b })
            .collect()
    }

    pub(crate) fn from_points(items: Vec<PointCurvature>) -> Curvature {
        let n = items.len();
        let mut c = Curvature {
            k1: Vec::with_capacity(n),
            k2: Vec::with_capacity(n),
            mean: Vec::with_capacity(n),
            gaussian: Vec::with_capacity(n),
            dir1: Vec::with_capacity(n),
            dir2: Vec::with_capacity(n),
            normal: Vec::with_capacity(n),
        };
        for p in items {
            c.push(p);
        }
        c
    }

    pub(crate) fn push(&mut self, p: PointCurvature) {
        self.k1.push(p.k1);
        self.k2.push(p.k2);
        self.mean.push(0.5 * (p.k1 + p.k2));
        self.gaussian.push(p.k1 * p.k2);
        self.dir1.push(p.dir1);
        self.dir2.push(p.dir2);
        self.normal.push(p.normal);
    }
}

/// The curvature of one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PointCurvature {
    pub k1: f64,
    pub k2: f64,
    pub dir1: Point3,
    pub dir2: Point3,
    pub normal: Point3,
}

impl PointCurvature {
    pub(crate) const FAILED: PointCurvature = PointCurvature {
        k1: f64::NAN,
        k2: f64::NAN,
        dir1: [0.0; 3],
        dir2: [0.0; 3],
        normal: [0.0; 3],
    };

    /// The same surface seen from the other side: normal reversed, curvatures negated and
    /// swapped.
    pub(crate) fn flipped(self) -> PointCurvature {
        PointCurvature {
            k1: -self.k2,
            k2: -self.k1,
            dir1: self.dir2,
            dir2: self.dir1,
            normal: scale(self.normal, -1.0),
        }
    }
}

/// Parameters of [`quadric_curvature`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QuadricParams {
    /// Number of nearest neighbours used per point (a prefix of the kNN rows; the whole row if
    /// it is shorter). demarsin2008 leaves k to the user; default 20, the k of the 1-ring and
    /// the PCA normals elsewhere in the pipeline. At least 5 (six points for six coefficients).
    pub k: usize,
}

impl Default for QuadricParams {
    fn default() -> Self {
        QuadricParams { k: 20 }
    }
}

/// [`quadric_curvature`] (or [`quadric_curvature_oriented`] with `normals`) of a point cloud in
/// one call: its `params.k` nearest neighbours, found among its distinct points (exact
/// duplicates are fitted once, and each copy takes its original's estimate).
///
/// Errors: fewer than `params.k + 1` distinct points, non-finite coordinates, `params.k < 5`,
/// `normals` not one per point.
pub fn quadric_curvature_of(
    points: &[Point3],
    normals: Option<&[Point3]>,
    params: &QuadricParams,
) -> Result<Curvature> {
    if normals.is_some_and(|n| n.len() != points.len()) {
        return Err(crate::Error::InvalidInput(format!(
            "{} normals for {} points",
            normals.map_or(0, <[Point3]>::len),
            points.len()
        )));
    }
    let distinct = crate::spatial::distinct_in_input_order(points);
    let pts = distinct.as_ref().map_or(points, |d| d.points.as_slice());
    let nbrs = crate::spatial::knn(pts, params.k)?;
    let c = match (normals, &distinct) {
        (Some(n), Some(d)) => quadric_curvature_oriented(pts, &nbrs, &d.pick(n), params)?,
        (Some(n), None) => quadric_curvature_oriented(pts, &nbrs, n, params)?,
        (None, _) => quadric_curvature(pts, &nbrs, params)?,
    };
    Ok(match &distinct {
        Some(d) => c.select(&d.of),
        None => c,
    })
}

/// Quadric-fit curvature of every point of a cloud (see the module documentation), with
/// unoriented normals: each point's normal is oriented so that its mean curvature is ≥ 0.
///
/// Inputs: `points` (`N`), `nbrs` their kNN lists (`N` rows, nearest first, e.g. from
/// [`crate::spatial::knn()`]), `params`.
/// Output: `N` estimates in input order, identical whatever the thread count.
/// Errors: `nbrs` does not have `N` rows, or `params.k < 5`.
pub fn quadric_curvature(
    points: &[Point3],
    nbrs: &Neighborhoods,
    params: &QuadricParams,
) -> Result<Curvature> {
    run(points, nbrs, None, params)
}

/// Like [`quadric_curvature`], with each point's normal oriented to the side of `normals[i]`
/// (e.g. outward normals given with the scan or oriented by MST propagation); curvatures are
/// then signed (a sphere with outward normals: `+1/r`). A zero normal leaves that point
/// oriented by `H ≥ 0`.
///
/// Errors: as [`quadric_curvature`], or `normals` does not have `N` entries.
pub fn quadric_curvature_oriented(
    points: &[Point3],
    nbrs: &Neighborhoods,
    normals: &[Point3],
    params: &QuadricParams,
) -> Result<Curvature> {
    if normals.len() != points.len() {
        return Err(Error::InvalidArgument(format!(
            "{} normals for {} points",
            normals.len(),
            points.len()
        )));
    }
    run(points, nbrs, Some(normals), params)
}

fn run(
    points: &[Point3],
    nbrs: &Neighborhoods,
    normals: Option<&[Point3]>,
    params: &QuadricParams,
) -> Result<Curvature> {
    if nbrs.len() != points.len() {
        return Err(Error::InvalidArgument(format!(
            "neighbour lists have {} rows for {} points",
            nbrs.len(),
            points.len()
        )));
    }
    if params.k < 5 {
        return Err(Error::InvalidArgument(format!(
            "quadric curvature needs k >= 5 neighbours, got {}",
            params.k
        )));
    }
    if let Some(&bad) = nbrs
        .csr()
        .indices
        .iter()
        .find(|&&j| j as usize >= points.len())
    {
        return Err(Error::InvalidArgument(format!(
            "neighbour index {bad} out of range for {} points",
            points.len()
        )));
    }
    let items: Vec<PointCurvature> = (0..points.len())
        .into_par_iter()
        .with_min_len(256)
        .map(|i| {
            let row = nbrs.prefix(i, params.k);
            let c = fit_point(points, i, row);
            let reference = normals.map(|n| n[i]).unwrap_or([0.0; 3]);
            orient(c, reference)
        })
        .collect();
    Ok(Curvature::from_points(items))
}

/// Orients `c` to the side of `reference`, or by `H ≥ 0` if `reference` is zero or
/// perpendicular.
pub(crate) fn orient(c: PointCurvature, reference: Point3) -> PointCurvature {
    if c.k1.is_nan() {
        return c;
    }
    let s = dot(c.normal, reference);
    let flip = if s != 0.0 && s.is_finite() {
        s < 0.0
    } else {
        c.k1 + c.k2 < 0.0
    };
    if flip {
        c.flipped()
    } else {
        c
    }
}

/// The quadric fit at point `i` over the neighbours `row`.
pub(crate) fn fit_point(points: &[Point3], i: usize, row: &[u32]) -> PointCurvature {
    if row.len() < 5 {
        return PointCurvature::FAILED;
    }
    let p = points[i];
    // Covariance of {p} ∪ N(p), accumulated about p for precision, and the radius h.
    let (mut m1, mut m2, mut h2) = ([0.0; 3], [0.0; 6], 0.0f64);
    for &j in row {
        let d = sub(points[j as usize], p);
        h2 = h2.max(dot(d, d));
        for a in 0..3 {
            m1[a] += d[a];
        }
        m2[0] += d[0] * d[0];
        m2[1] += d[0] * d[1];
        m2[2] += d[0] * d[2];
        m2[3] += d[1] * d[1];
        m2[4] += d[1] * d[2];
        m2[5] += d[2] * d[2];
    }
    let cnt = (row.len() + 1) as f64;
    let c = m1.map(|v| v / cnt);
    let cov = [
        m2[0] / cnt - c[0] * c[0],
        m2[1] / cnt - c[0] * c[1],
        m2[2] / cnt - c[0] * c[2],
        m2[3] / cnt - c[1] * c[1],
        m2[4] / cnt - c[1] * c[2],
        m2[5] / cnt - c[2] * c[2],
    ];
    let Some(n) = smallest_eigenvector(cov) else {
        return PointCurvature::FAILED;
    };
    // The 6-term quadric is invariant under in-plane rotations: any tangent basis will do.
    let Some(e1) = normalize(cross(n, least_axis(n))) else {
        return PointCurvature::FAILED;
    };
    let e2 = cross(n, e1);
    let h = h2.sqrt();
    if h <= 0.0 || !h.is_finite() {
        return PointCurvature::FAILED;
    }
    let inv = 1.0 / h;
    let mut ata = SMatrix::<f64, 6, 6>::zeros();
    let mut atb = SVector::<f64, 6>::zeros();
    let mut add_sample = |d: Point3| {
        let (x, y, z) = (dot(d, e1) * inv, dot(d, e2) * inv, dot(d, n) * inv);
        let m = SVector::<f64, 6>::from([x * x, x * y, y * y, x, y, 1.0]);
        add_outer(&mut ata, &m, 1.0);
        atb += m * z;
    };
    add_sample([0.0; 3]);
    for &j in row {
        add_sample(sub(points[j as usize], p));
    }
    symmetrize(&mut ata);
    let Some(chol) = ata.cholesky() else {
        return PointCurvature::FAILED;
    };
    let c = chol.solve(&atb);
    if c.iter().any(|v| !v.is_finite()) {
        return PointCurvature::FAILED;
    }
    // z(x, y) in original units: h g(x / h, y / h).
    let d = Derivatives {
        fx: c[3],
        fy: c[4],
        fxx: 2.0 * c[0] * inv,
        fxy: c[1] * inv,
        fyy: 2.0 * c[2] * inv,
    };
    monge_curvature(&d, [e1, e2, n])
}

/// The coordinate axis least aligned with `n`.
pub(crate) fn least_axis(n: Point3) -> Point3 {
    let a = [n[0].abs(), n[1].abs(), n[2].abs()];
    if a[0] <= a[1] && a[0] <= a[2] {
        [1.0, 0.0, 0.0]
    } else if a[1] <= a[2] {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    }
}

/// Unit eigenvector of the smallest eigenvalue of the symmetric matrix
/// `[[a0, a1, a2], [a1, a3, a4], [a2, a4, a5]]`, from the closed-form solver the PCA normals use
/// ([`super::normals::smallest_eigen`]); `None` for a zero or non-finite matrix or a degenerate
/// (line- or point-like) neighbourhood, where the smallest eigenvalue is not isolated and the
/// plane normal is undefined.
pub(crate) fn smallest_eigenvector(a: [f64; 6]) -> Option<Point3> {
    let s = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if !(s > 0.0 && s.is_finite()) {
        return None;
    }
    let (normal, [l0, l1, _]) = super::normals::smallest_eigen(a);
    // λ0 ≈ λ1 (relative to the matrix scale): no preferred normal.
    if (l1 - l0) <= 1e-12 * s {
        return None;
    }
    normal.iter().all(|v| v.is_finite()).then_some(normal)
}

/// First and second derivatives of a height function `z = f(x, y)` at the evaluation point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Derivatives {
    pub fx: f64,
    pub fy: f64,
    pub fxx: f64,
    pub fxy: f64,
    pub fyy: f64,
}

/// Principal curvatures, directions and normal of the graph surface `z = f(x, y)` in the
/// orthonormal frame `[e1, e2, n]` (world coordinates), sign convention of the module: positive
/// where the surface bends away from its normal, which is on the side of `n`.
pub(crate) fn monge_curvature(d: &Derivatives, frame: [Point3; 3]) -> PointCurvature {
    let [e1, e2, n] = frame;
    let (ee, ff, gg) = (1.0 + d.fx * d.fx, d.fx * d.fy, 1.0 + d.fy * d.fy);
    let w = (1.0 + d.fx * d.fx + d.fy * d.fy).sqrt();
    let (l, m, nn) = (-d.fxx / w, -d.fxy / w, -d.fyy / w);
    let det = ee * gg - ff * ff;
    let h = (ee * nn + gg * l - 2.0 * ff * m) / (2.0 * det);
    let k = (l * nn - m * m) / det;
    let disc = (h * h - k).max(0.0).sqrt();
    let (k1, k2) = (h + disc, h - disc);
    let xu = add(e1, scale(n, d.fx));
    let xv = add(e2, scale(n, d.fy));
    let Some(normal) = normalize(add(
        scale(n, 1.0),
        scale(add(scale(e1, d.fx), scale(e2, d.fy)), -1.0),
    )) else {
        return PointCurvature::FAILED;
    };
    // (II − k1 I) t = 0: t is perpendicular (in parameter space) to the row of larger norm.
    let r1 = [l - k1 * ee, m - k1 * ff];
    let r2 = [m - k1 * ff, nn - k1 * gg];
    let (n1, n2) = (r1[0].hypot(r1[1]), r2[0].hypot(r2[1]));
    let tol = 1e-12 * (l.abs() + m.abs() + nn.abs() + f64::MIN_POSITIVE);
    let r = if n1 >= n2 { r1 } else { r2 };
    let t = if n1.max(n2) > tol {
        add(scale(xu, -r[1]), scale(xv, r[0]))
    } else {
        xu // umbilic: any tangent direction is principal
    };
    let dir1 = normalize(sub(t, scale(normal, dot(t, normal))))
        .or_else(|| normalize(sub(xu, scale(normal, dot(xu, normal)))))
        .unwrap_or(e1);
    let dir2 = cross(normal, dir1);
    if !(k1.is_finite() && k2.is_finite()) {
        return PointCurvature::FAILED;
    }
    PointCurvature {
        k1,
        k2,
        dir1,
        dir2,
        normal,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_normal_matches_fit_plane() {
        let pts: Vec<Point3> = (0..30)
            .map(|i| {
                let (x, y) = ((i % 6) as f64 * 0.3, (i / 6) as f64 * 0.2 + 0.01 * i as f64);
                [x, y, 0.2 * x - 0.1 * y + 0.01 * x * y]
            })
            .collect();
        let plane = crate::geometry::fit_plane(pts.iter().map(|&p| (p, 1.0))).unwrap();
        let c = pts.iter().fold([0.0; 3], |s, p| add(s, *p));
        let c = scale(c, 1.0 / 30.0);
        let mut m = [0.0; 6];
        for p in &pts {
            let d = sub(*p, c);
            m = [
                m[0] + d[0] * d[0],
                m[1] + d[0] * d[1],
                m[2] + d[0] * d[2],
                m[3] + d[1] * d[1],
                m[4] + d[1] * d[2],
                m[5] + d[2] * d[2],
            ];
        }
        let n = smallest_eigenvector(m).unwrap();
        assert!(dot(n, plane.normal).abs() > 1.0 - 1e-12);
        assert!(smallest_eigenvector([0.0; 6]).is_none());
        assert!(smallest_eigenvector([1.0, 0.0, 0.0, 1.0, 0.0, 1.0]).is_none());
    }

    #[test]
    fn monge_paraboloid() {
        // z = -(x² / 2 r1 + y² / 2 r2): curvatures 1/r1 and 1/r2 about +z at the origin.
        let d = Derivatives {
            fx: 0.0,
            fy: 0.0,
            fxx: -0.5,
            fxy: 0.0,
            fyy: -0.25,
        };
        let c = monge_curvature(&d, [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!((c.k1 - 0.5).abs() < 1e-12 && (c.k2 - 0.25).abs() < 1e-12);
        assert!(c.dir1[0].abs() > 1.0 - 1e-12);
        assert!(c.normal[2] > 1.0 - 1e-12);
        let f = c.flipped();
        assert_eq!((f.k1, f.k2), (-0.25, -0.5));
    }
}
