//! Analytic surface fitting (mizoguchi section 5.1) plus a geometric refinement.
//!
//! **Linear fits (the paper's).** Each uses the points `v_i` and the refitted normals `n'_i`
//! (section 3), weighted by `w_i` (crease uses the vertices' areas, so that unevenly dense CAD
//! tessellations do not over-weight their fine parts):
//! - plane: `n` = normalised weighted mean of the normals (signs aligned first), `d` = least
//!   squares offset `Σ w n·v / Σ w`;
//! - cylinder: the normals' end points on the Gaussian sphere lie on a great circle; the axis
//!   is the normal of the least-squares plane through them. The paper does not say whether that
//!   plane passes through the sphere's centre; for a cylinder it must, and forcing it makes
//!   narrow patches (fillets spanning a small arc) well-posed, so the plane through the origin
//!   is used (the smallest eigenvector of `Σ w n nᵀ`). The points projected on the plane
//!   orthogonal to the axis get a least-squares (Kåsa) circle: radius and axis point;
//! - sphere: algebraic least squares `x² + y² + z² + Ax + By + Cz + D = 0`;
//! - cone: the axis as for the cylinder but with a centred plane (the normals of a cone lie on
//!   a small circle of the Gaussian sphere), the apex `a` as the least-squares solution of
//!   `n'_i · (a − v_i) = 0`, the half angle from the mean angle between the axis and the normals;
//! - torus: the axis by Kós et al.'s linear estimate (every normal line of a surface of
//!   revolution meets the axis: with Plücker coordinates `(d, m = d × p)` of the axis,
//!   `d · (n_i × v_i) + n_i · m = 0`, solved as the generalised eigenproblem with `|d| = 1`),
//!   then a circle in the meridian half-plane `(ρ, h)` of the points rotated about the axis:
//!   its radius is `r`, its centre's `ρ` is `R` and its `h` places the centre on the axis.
//!
//! **Refinement.** Users need accurate radii and the linear fits are biased (normals carry
//! estimation errors; algebraic circle fits are biased on short arcs), so each fit is then
//! refined by Levenberg–Marquardt on the orthogonal (geometric) distances, with at most
//! [`LM_MAX_POINTS`] points (an even, deterministic subsample of bigger regions). The plane's
//! geometric least-squares optimum is closed form (the weighted PCA plane). The LM is written
//! here (about 80 lines on nalgebra fixed-size matrices, with each type's analytic Jacobian:
//! one distance evaluation per point and iteration where central differences took 2N + 1)
//! rather than taken from the `levenberg-marquardt` crate, whose API wants a dynamic Jacobian
//! matrix of all residuals (memory of n × p per iteration) and its own nalgebra version.
//!
//! **Units.** Nothing in the fits is absolute: the LM parameters have natural sizes (the
//! patch's extent for lengths, 1 for directions and angles) from which the floor of its
//! damping (`damping_floor`) is taken, it stops at relative decreases of the cost, the restarts of [`refine`] compare relative RMS gains, and
//! the algebraic circle, sphere and quadric fits, whose normal equations mix `x²`, `x` and 1,
//! are solved in units of the data's RMS radius (`unit_scale`). So a fit in other units is
//! the same fit scaled: bit for bit when the factor is a power of two, up to round-off
//! otherwise.

use nalgebra::{Matrix2, Matrix3, SMatrix, SVector, Vector3};
use rayon::prelude::*;

use crate::geometry::normal_eq::{add_outer, symmetrize};
use crate::geometry::surface::{meridian, radial, signed_distance, Prepared};
use crate::geometry::vec3::{add, cross, dist2, dot, norm, normalize, scale, sub};
use crate::geometry::{Point3, SurfaceParams, SurfaceType};

/// Largest number of points an LM refinement iterates on (bigger regions are subsampled
/// evenly, deterministically).
pub const LM_MAX_POINTS: usize = 20_000;

/// Largest number of Levenberg–Marquardt iterations.
pub const LM_MAX_ITERATIONS: usize = 300;

/// The LM stops when one step lowers the cost by less than this fraction of it (MINPACK's
/// `ftol`, whose default is about 1.5e-8).
const LM_COST_TOLERANCE: f64 = 1e-10;

/// The LM stops when the last [`LM_STALL_ITERATIONS`] steps together lowered the cost by less
/// than this fraction (the RMS error by less than half of it): a run creeping along a flat
/// valley, typically a few-point seed fitted with a type it hardly determines (a cone to
/// seven points whose half angle and axis trade off), which otherwise ran to the iteration
/// cap. 0.1 %: the decisions read an RMS to a few per cent; on a Kinect scene a third of the
/// cone runs crept on at 0.06 % per 20 steps to the cap (70 % of the cone work), and
/// stopping them made the segmentation 1 s (30 %) faster with the same surfaces within ±2 on
/// every scan (`docs/experiments/run-profile.md`, 2026-12-07).
const LM_STALL_DECREASE: f64 = 1e-3;

/// The LM stops when the RMS distance falls below this fraction of the patch's size (the
/// diagonal of its bounding box): the fit passes through the points, down to the round-off of
/// their coordinates (exact data, and seeds of no more points than the surface's parameters,
/// whose runs otherwise went on lowering a cost of 1e-38 by relative steps of round-off).
const LM_SETTLED_RMS: f64 = 1e-12;

/// See [`LM_STALL_DECREASE`].
const LM_STALL_ITERATIONS: usize = 20;

/// A fitted surface and its fit quality on the points it was fitted to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fit {
    /// The surface.
    pub params: SurfaceParams,
    /// Weighted RMS of the orthogonal distances.
    pub rms: f64,
}

/// Weighted RMS of the orthogonal distances of `pts` to `s`.
pub fn rms_distance(s: &SurfaceParams, pts: &[Point3], w: &[f64]) -> f64 {
    let parts: Vec<(f64, f64)> = pts
        .par_chunks(4096)
        .zip(w.par_chunks(4096))
        .map(|(p, w)| {
            p.iter().zip(w).fold((0.0, 0.0), |(a, b), (&p, &w)| {
                let d = signed_distance(s, p);
                (a + w * d * d, b + w)
            })
        })
        .collect();
    let (a, b) = parts
        .into_iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    if b > 0.0 {
        (a / b).sqrt()
    } else {
        f64::NAN
    }
}

fn v3(p: Point3) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p[2])
}

fn p3(v: Vector3<f64>) -> Point3 {
    [v[0], v[1], v[2]]
}

/// Weighted centroid.
pub(crate) fn centroid(pts: &[Point3], w: &[f64]) -> Option<Point3> {
    let mut s = [0.0; 3];
    let mut ws = 0.0;
    for (&p, &wi) in pts.iter().zip(w) {
        s = add(s, scale(p, wi));
        ws += wi;
    }
    (ws > 0.0).then(|| scale(s, 1.0 / ws))
}

/// Eigenvectors of a symmetric 3×3 matrix sorted by ascending eigenvalue.
fn sym_eigen(m: Matrix3<f64>) -> ([f64; 3], [Point3; 3]) {
    let e = m.symmetric_eigen();
    let mut idx = [0usize, 1, 2];
    idx.sort_by(|&a, &b| e.eigenvalues[a].total_cmp(&e.eigenvalues[b]));
    let vals = idx.map(|i| e.eigenvalues[i]);
    let vecs = idx.map(|i| p3(e.eigenvectors.column(i).into_owned()));
    (vals, vecs)
}

/// Weighted scatter `Σ w (x − c)(x − c)ᵀ` (c = 0 when `center` is None).
fn scatter(xs: &[Point3], w: &[f64], center: Option<Point3>) -> Matrix3<f64> {
    let c = center.unwrap_or([0.0; 3]);
    let mut m = Matrix3::zeros();
    for (&x, &wi) in xs.iter().zip(w) {
        let d = v3(sub(x, c));
        m += d * d.transpose() * wi;
    }
    m
}

/// Two unit vectors completing `d` to an orthonormal frame.
pub fn frame_of(d: Point3) -> (Point3, Point3) {
    let a = if d[0].abs() < 0.6 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let u = normalize(cross(d, a)).unwrap_or([0.0, 0.0, 1.0]);
    (u, cross(d, u))
}

/// Weighted Kåsa circle fit in 2D: centre and radius.
fn circle_2d(xy: &[[f64; 2]], w: &[f64]) -> Option<([f64; 2], f64)> {
    let ws: f64 = w.iter().sum();
    if ws <= 0.0 || xy.len() < 3 {
        return None;
    }
    // Centred and divided by the RMS radius `k` (see [`unit_scale`]).
    let mx = xy.iter().zip(w).map(|(p, w)| p[0] * w).sum::<f64>() / ws;
    let my = xy.iter().zip(w).map(|(p, w)| p[1] * w).sum::<f64>() / ws;
    let k = unit_scale(
        xy.iter()
            .zip(w)
            .map(|(p, &wi)| ((p[0] - mx).powi(2) + (p[1] - my).powi(2), wi)),
    )?;
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    for (p, &wi) in xy.iter().zip(w) {
        let (x, y) = ((p[0] - mx) / k, (p[1] - my) / k);
        let row = Vector3::new(x, y, 1.0);
        ata += row * row.transpose() * wi;
        atb += row * (-(x * x + y * y)) * wi;
    }
    let s = ata.lu().solve(&atb)?;
    let (cx, cy) = (-s[0] / 2.0, -s[1] / 2.0);
    let r2 = cx * cx + cy * cy - s[2];
    (r2 > 0.0 && r2.is_finite()).then(|| ([cx * k + mx, cy * k + my], r2.sqrt() * k))
}

/// The RMS distance to the centre, `√(Σ w d² / Σ w)` over `(d², w)`, by which the algebraic
/// fits ([`circle_2d`], [`sphere_linear`], [`cylinder_quadric`]) divide their centred
/// coordinates. Their normal equations mix powers of the length (`x²`, `x` and 1), so in raw
/// coordinates both their conditioning and the pivots of the LU solve depend on the units: a
/// cloud scaled by 1024, exact in floating point, changed the last bits of the fits and, through
/// the ill-conditioned fits of very noisy inputs, the labels of 5 of 4000 points (and 61 sharp
/// points of `crease sharp`'s surface stage). In units of this radius the systems are the same
/// whatever the input's units. `None` when the points coincide.
fn unit_scale(d2w: impl Iterator<Item = (f64, f64)>) -> Option<f64> {
    let (s, ws) = d2w.fold((0.0, 0.0), |(s, ws), (d2, w)| (s + w * d2, ws + w));
    let k = (s / ws).sqrt();
    (k > 0.0 && k.is_finite()).then_some(k)
}

/// Plane (paper): normal = mean of the sign-aligned normals, offset by least squares.
pub fn plane_linear(pts: &[Point3], nrm: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    let (_, vecs) = sym_eigen(scatter(nrm, w, None));
    let major = vecs[2];
    let mut s = [0.0; 3];
    for (&n, &wi) in nrm.iter().zip(w) {
        let f = if dot(n, major) < 0.0 { -wi } else { wi };
        s = add(s, scale(n, f));
    }
    // Keep the orientation of the majority of the given normals.
    let normal = normalize(s)?;
    let c = centroid(pts, w)?;
    Some(SurfaceParams::Plane {
        normal,
        offset: dot(normal, c),
    })
}

/// Plane refined: the weighted total least-squares plane (smallest eigenvector of the points'
/// scatter), the exact minimiser of the squared orthogonal distances; oriented like `init`.
pub fn plane_refine(init: &SurfaceParams, pts: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    let c = centroid(pts, w)?;
    let (_, vecs) = sym_eigen(scatter(pts, w, Some(c)));
    let mut n = normalize(vecs[0])?;
    if let SurfaceParams::Plane { normal, .. } = init {
        if dot(n, *normal) < 0.0 {
            n = scale(n, -1.0);
        }
    }
    Some(SurfaceParams::Plane {
        normal: n,
        offset: dot(n, c),
    })
}

/// Axis direction from the normals on the Gaussian sphere: the least-squares plane through
/// their end points, through the origin (`centred = false`, cylinders) or not (cones).
fn gauss_axis(nrm: &[Point3], w: &[f64], centred: bool) -> Option<Point3> {
    let c = if centred { centroid(nrm, w) } else { None };
    let (_, vecs) = sym_eigen(scatter(nrm, w, c));
    normalize(vecs[0])
}

/// Cylinder (paper): Gaussian-sphere axis, circle fit of the projected points.
pub fn cylinder_linear(pts: &[Point3], nrm: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    let d = gauss_axis(nrm, w, false)?;
    cylinder_with_axis(pts, w, d)
}

/// Cylinder from the points alone: the axis is the direction of least curvature of the
/// quadric height function `z = a x² + b xy + c y² + d x + e y + f` over the points' total
/// least-squares plane, then the circle fit of [`cylinder_linear`]. Not in the paper: on a
/// patch of a large-radius cylinder the normals span a few degrees only, and once a scan's
/// noise scatters them by as much the Gaussian-sphere axis of [`cylinder_linear`] is
/// arbitrary (the PCEDNet noisy ABC model 6944: radius-9.5 cylinders 20 spacings wide, the
/// refined fits explained 3 % of their points), while the points' height still bends by a
/// spacing across the patch.
pub fn cylinder_quadric(pts: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    let c = centroid(pts, w)?;
    let (_, vecs) = sym_eigen(scatter(pts, w, Some(c)));
    let n = normalize(vecs[0])?;
    let (u, v) = frame_of(n);
    // In units of the RMS radius `k` (see [`unit_scale`]); the Hessian's eigenvectors, the only
    // output, do not depend on them.
    let k = unit_scale(pts.iter().zip(w).map(|(&p, &wi)| (dist2(p, c), wi)))?;
    let mut ata = SMatrix::<f64, 6, 6>::zeros();
    let mut atb = SVector::<f64, 6>::zeros();
    for (&p, &wi) in pts.iter().zip(w) {
        let q = scale(sub(p, c), 1.0 / k);
        let (x, y, z) = (dot(q, u), dot(q, v), dot(q, n));
        let row = SVector::<f64, 6>::new(x * x, x * y, y * y, x, y, 1.0);
        ata += row * row.transpose() * wi;
        atb += row * (z * wi);
    }
    let s = ata.lu().solve(&atb)?;
    // The Hessian's eigenvector of the eigenvalue of least magnitude.
    let h = Matrix2::new(2.0 * s[0], s[1], s[1], 2.0 * s[2]).symmetric_eigen();
    let i = usize::from(h.eigenvalues[1].abs() < h.eigenvalues[0].abs());
    let e = h.eigenvectors.column(i);
    let d = normalize(add(scale(u, e[0]), scale(v, e[1])))?;
    cylinder_with_axis(pts, w, d)
}

fn cylinder_with_axis(pts: &[Point3], w: &[f64], d: Point3) -> Option<SurfaceParams> {
    let (u, v) = frame_of(d);
    let xy: Vec<[f64; 2]> = pts.iter().map(|&p| [dot(p, u), dot(p, v)]).collect();
    let (c, r) = circle_2d(&xy, w)?;
    let mean_h = centroid(pts, w).map(|m| dot(m, d))?;
    let axis_point = add(add(scale(u, c[0]), scale(v, c[1])), scale(d, mean_h));
    Some(SurfaceParams::Cylinder {
        axis_point,
        axis_dir: d,
        radius: r,
    })
}

/// Sphere (paper): algebraic least squares.
pub fn sphere_linear(pts: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    // Centred and divided by the RMS radius `k` (see [`unit_scale`]).
    let m = centroid(pts, w)?;
    let k = unit_scale(pts.iter().zip(w).map(|(&p, &wi)| (dist2(p, m), wi)))?;
    let mut ata = SMatrix::<f64, 4, 4>::zeros();
    let mut atb = SVector::<f64, 4>::zeros();
    for (&p, &wi) in pts.iter().zip(w) {
        let q = scale(sub(p, m), 1.0 / k);
        let row = SVector::<f64, 4>::new(q[0], q[1], q[2], 1.0);
        ata += row * row.transpose() * wi;
        atb += row * (-dot(q, q)) * wi;
    }
    let s = ata.lu().solve(&atb)?;
    let c = [-s[0] / 2.0, -s[1] / 2.0, -s[2] / 2.0];
    let r2 = dot(c, c) - s[3];
    (r2 > 0.0 && r2.is_finite()).then(|| SurfaceParams::Sphere {
        center: add(scale(c, k), m),
        radius: r2.sqrt() * k,
    })
}

/// Cone (paper): Gaussian-sphere axis (centred plane), apex from `n'·(a − v) = 0`, half angle
/// from the mean angle between the axis and the normals.
pub fn cone_linear(pts: &[Point3], nrm: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    let mut d = gauss_axis(nrm, w, true)?;
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    for ((&p, &n), &wi) in pts.iter().zip(nrm).zip(w) {
        let nv = v3(n);
        ata += nv * nv.transpose() * wi;
        atb += nv * (dot(n, p) * wi);
    }
    let apex = p3(ata.lu().solve(&atb)?);
    let c = centroid(pts, w)?;
    if dot(sub(c, apex), d) < 0.0 {
        d = scale(d, -1.0);
    }
    // Angle between the axis and the normal line: the half angle is its complement.
    let (mut s, mut ws) = (0.0, 0.0);
    for (&n, &wi) in nrm.iter().zip(w) {
        let a = dot(n, d).abs().clamp(0.0, 1.0).acos();
        s += a * wi;
        ws += wi;
    }
    let half_angle = std::f64::consts::FRAC_PI_2 - s / ws;
    (half_angle > 1e-3 && half_angle < std::f64::consts::FRAC_PI_2 - 1e-3 && apex[0].is_finite())
        .then_some(SurfaceParams::Cone {
            apex,
            axis_dir: d,
            half_angle,
        })
}

/// Cone from the axis of revolution (Kós et al.'s estimate, as for the torus) and a line fitted
/// to the points in the meridian half-plane `(ρ, h)`: the generator. Better posed than the
/// paper's Gaussian-sphere axis on narrow patches, whose normals span a short arc.
pub fn cone_revolution(pts: &[Point3], nrm: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    let (mut d, a) = revolution_axis(pts, nrm, w)?;
    let rh: Vec<[f64; 2]> = pts.iter().map(|&p| meridian(p, a, d)).collect();
    // Total least-squares line through the (ρ, h) points.
    let ws: f64 = w.iter().sum();
    let mr = rh.iter().zip(w).map(|(q, w)| q[0] * w).sum::<f64>() / ws;
    let mh = rh.iter().zip(w).map(|(q, w)| q[1] * w).sum::<f64>() / ws;
    let (mut srr, mut srh, mut shh) = (0.0, 0.0, 0.0);
    for (q, &wi) in rh.iter().zip(w) {
        let (x, y) = (q[0] - mr, q[1] - mh);
        srr += wi * x * x;
        srh += wi * x * y;
        shh += wi * y * y;
    }
    // Direction of the line (largest eigenvector of the 2×2 scatter).
    let t = 0.5 * (2.0 * srh).atan2(srr - shh);
    let (mut dr, mut dh) = (t.cos(), t.sin());
    if dh < 0.0 {
        dr = -dr;
        dh = -dh;
    }
    if dr.abs() < 1e-9 {
        return None;
    }
    // Apex: where the line meets ρ = 0.
    let s = -mr / dr;
    let apex_h = mh + s * dh;
    let apex = add(a, scale(d, apex_h));
    // The generator makes the angle atan(|dρ / dh|) with the axis; orient the axis towards
    // the patch.
    let half_angle = (dr.abs()).atan2(dh);
    let half_angle = if half_angle > std::f64::consts::FRAC_PI_2 {
        std::f64::consts::PI - half_angle
    } else {
        half_angle
    };
    if mh - apex_h < 0.0 {
        d = scale(d, -1.0);
    }
    (half_angle > 1e-3 && half_angle < std::f64::consts::FRAC_PI_2 - 1e-3).then_some(
        SurfaceParams::Cone {
            apex,
            axis_dir: d,
            half_angle,
        },
    )
}

/// Axis of a surface of revolution (Kós et al.'s linear estimate, see the module doc):
/// direction and the axis point nearest to the points' centroid.
pub fn revolution_axis(pts: &[Point3], nrm: &[Point3], w: &[f64]) -> Option<(Point3, Point3)> {
    let c = centroid(pts, w)?;
    // Rows [n × (v − c), n] · [d, m] = 0 (coordinates relative to the centroid).
    let mut mm = SMatrix::<f64, 6, 6>::zeros();
    for ((&p, &n), &wi) in pts.iter().zip(nrm).zip(w) {
        let a = cross(n, sub(p, c));
        let row = SVector::<f64, 6>::new(a[0], a[1], a[2], n[0], n[1], n[2]);
        mm += row * row.transpose() * wi;
    }
    let a = mm.fixed_view::<3, 3>(0, 0).into_owned();
    let b = mm.fixed_view::<3, 3>(0, 3).into_owned();
    let cc = mm.fixed_view::<3, 3>(3, 3).into_owned();
    let ci = cc.try_inverse()?;
    let schur = a - b * ci * b.transpose();
    let (_, vecs) = sym_eigen(0.5 * (schur + schur.transpose()));
    let d = normalize(vecs[0])?;
    let m = -ci * b.transpose() * v3(d);
    // The rows' sign convention makes m = d × p for the axis point p ⟂ d, so p = m × d.
    let mut p = p3(m.cross(&v3(d)));
    p = sub(p, scale(d, dot(p, d)));
    Some((d, add(p, c)))
}

/// Torus (paper): Kós axis, then a circle in the meridian half-plane.
pub fn torus_linear(pts: &[Point3], nrm: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    let (d, a) = revolution_axis(pts, nrm, w)?;
    let rh: Vec<[f64; 2]> = pts.iter().map(|&p| meridian(p, a, d)).collect();
    let (c, r) = circle_2d(&rh, w)?;
    (c[0] > 0.0).then(|| SurfaceParams::Torus {
        center: add(a, scale(d, c[1])),
        axis_dir: d,
        major_radius: c[0],
        minor_radius: r,
    })
}

/// Linear fit of the given type (`Other` gives `None`).
pub fn fit_linear(
    kind: SurfaceType,
    pts: &[Point3],
    nrm: &[Point3],
    w: &[f64],
) -> Option<SurfaceParams> {
    match kind {
        SurfaceType::Plane => plane_linear(pts, nrm, w),
        SurfaceType::Cylinder => cylinder_linear(pts, nrm, w),
        SurfaceType::Cone => cone_linear(pts, nrm, w),
        SurfaceType::Sphere => sphere_linear(pts, w),
        SurfaceType::Torus => torus_linear(pts, nrm, w),
        SurfaceType::Other => None,
    }
}

/// Linear fit then geometric refinement; `None` if the linear fit is impossible or the
/// result is not finite.
///
/// Cones are started from both the paper's linear fit and [`cone_revolution`], and the better
/// refined result is kept.
pub fn fit(kind: SurfaceType, pts: &[Point3], nrm: &[Point3], w: &[f64]) -> Option<Fit> {
    let one = |init: Option<SurfaceParams>| -> Option<Fit> {
        let init = init?;
        let params = refine(&init, pts, w).unwrap_or(init);
        if !finite(&params) {
            return None;
        }
        let rms = rms_distance(&params, pts, w);
        rms.is_finite().then_some(Fit { params, rms })
    };
    let a = one(fit_linear(kind, pts, nrm, w));
    let b = match kind {
        SurfaceType::Cone => one(cone_revolution(pts, nrm, w)),
        SurfaceType::Cylinder => one(cylinder_quadric(pts, w)),
        _ => return a,
    };
    match (a, b) {
        (Some(a), Some(b)) => Some(if b.rms < a.rms { b } else { a }),
        (a, b) => a.or(b),
    }
}

fn finite(s: &SurfaceParams) -> bool {
    let ok3 = |p: &Point3| p.iter().all(|x| x.is_finite());
    match s {
        SurfaceParams::Plane { normal, offset } => ok3(normal) && offset.is_finite(),
        SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            radius,
        } => ok3(axis_point) && ok3(axis_dir) && radius.is_finite() && *radius > 0.0,
        SurfaceParams::Sphere { center, radius } => {
            ok3(center) && radius.is_finite() && *radius > 0.0
        }
        SurfaceParams::Cone {
            apex,
            axis_dir,
            half_angle,
        } => {
            ok3(apex)
                && ok3(axis_dir)
                && *half_angle > 0.0
                && *half_angle < std::f64::consts::FRAC_PI_2
        }
        SurfaceParams::Torus {
            center,
            axis_dir,
            major_radius,
            minor_radius,
        } => ok3(center) && ok3(axis_dir) && *major_radius > 0.0 && *minor_radius > 0.0,
    }
}

/// Geometric refinement of a fit (see the module doc). `None` when it fails to improve.
///
/// The Levenberg–Marquardt run is restarted from its result (fresh damping, frame re-centred
/// on the new estimate) while that lowers the RMS error by more than 1 %, at most 5 times:
/// on narrow patches the cost has long flat valleys where one run stalls (measured on the ABC
/// model's chamfer cones: 1–2° axis errors after one run, 0.001° after restarts).
pub fn refine(init: &SurfaceParams, pts: &[Point3], w: &[f64]) -> Option<SurfaceParams> {
    if let SurfaceParams::Plane { .. } = init {
        return plane_refine(init, pts, w);
    }
    let (sp, sw) = subsample(pts, w);
    let mut best = refine_once(init, &sp, &sw)?;
    let mut rms = rms_distance(&best, &sp, &sw);
    for _ in 0..4 {
        let Some(next) = refine_once(&best, &sp, &sw) else {
            break;
        };
        let r = rms_distance(&next, &sp, &sw);
        if r.is_nan() || r >= rms {
            break;
        }
        let gain = (rms - r) / rms.max(1e-300);
        best = next;
        rms = r;
        if gain < 0.01 {
            break;
        }
    }
    Some(best)
}

fn refine_once(init: &SurfaceParams, sp: &[Point3], sw: &[f64]) -> Option<SurfaceParams> {
    let ext = extent(sp)?;
    let out = match *init {
        SurfaceParams::Plane { .. } => return plane_refine(init, sp, sw),
        SurfaceParams::Sphere { center, radius } => {
            let m = SphereModel { center, radius };
            let x = lm(&m, ext, [ext, ext, ext, ext], sp, sw)?;
            m.at(&x).surface()
        }
        SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            radius,
        } => {
            let m = CylinderModel {
                axis_point,
                axis: Axis::new(axis_dir),
                radius,
            };
            let x = lm(&m, ext, [ext, ext, 1.0, 1.0, ext], sp, sw)?;
            m.at(&x).surface()
        }
        SurfaceParams::Cone {
            apex,
            axis_dir,
            half_angle,
        } => {
            // Parametrised by the axis point level with the patch's centroid, the radius there,
            // the axis direction and the half angle: the apex of a patch far from it is nearly
            // undetermined along the axis, and with it as a parameter LM crawls along that
            // valley (measured on the ABC model's chamfer cones: still 16° off after 60
            // iterations).
            let c = centroid(sp, sw)?;
            let hc = dot(sub(c, apex), axis_dir);
            let m = ConeModel {
                axis_point: add(apex, scale(axis_dir, hc)),
                axis: Axis::new(axis_dir),
                radius: hc * half_angle.tan(),
                half_angle,
            };
            let x = lm(&m, ext, [ext, ext, 1.0, 1.0, ext, 1.0], sp, sw)?;
            m.at(&x).surface()
        }
        SurfaceParams::Torus {
            center,
            axis_dir,
            major_radius,
            minor_radius,
        } => {
            let m = TorusModel {
                center,
                axis: Axis::new(axis_dir),
                major_radius,
                minor_radius,
            };
            let x = lm(&m, ext, [ext, ext, ext, 1.0, 1.0, ext, ext], sp, sw)?;
            m.at(&x).surface()
        }
    };
    let out = canonical(out, sp, sw);
    finite(&out).then_some(out)
}

/// A parametrisation of one surface type around its initial estimate, for [`lm`]: `x = 0` is
/// the estimate; [`Model::at`] gives the surface at `x`, whose [`Linearised::row`] is a point's
/// signed distance ([`signed_distance`]) with its gradient in `x` (one row of the Jacobian).
trait Model<const N: usize>: Sync {
    /// The surface at the parameters `x`, with what its Jacobian rows share.
    type At: Linearised<N>;
    /// The surface at `x`.
    fn at(&self, x: &[f64; N]) -> Self::At;
}

/// A surface at given parameters, with its Jacobian rows (see [`Model`]).
trait Linearised<const N: usize>: Sync {
    /// The surface.
    fn surface(&self) -> SurfaceParams;
    /// Signed distance of `p` and its gradient in the parameters.
    fn row(&self, p: Point3) -> (f64, SVector<f64, N>);
}

/// An axis direction parametrised by two tilts along the frame `(u, v)` of its initial
/// direction `d0`: `d(x) = (d0 + x_u u + x_v v) / |…|`. A function of `d` changes with a tilt
/// by `(∂f/∂d)ᵀ (I − d dᵀ) u / |…|` (the derivative of the normalisation).
#[derive(Debug, Clone, Copy)]
struct Axis {
    d0: Point3,
    u: Point3,
    v: Point3,
}

impl Axis {
    fn new(d0: Point3) -> Axis {
        let (u, v) = frame_of(d0);
        Axis { d0, u, v }
    }

    /// The direction at tilts `(a, b)` and `1 / |d0 + a u + b v|`.
    fn at(&self, a: f64, b: f64) -> (Point3, f64) {
        let m = add(add(self.d0, scale(self.u, a)), scale(self.v, b));
        let len = norm(m);
        if len > 0.0 && len.is_finite() {
            (scale(m, 1.0 / len), 1.0 / len)
        } else {
            (self.d0, 1.0)
        }
    }
}

/// Sphere: centre offset (3), radius offset.
struct SphereModel {
    center: Point3,
    radius: f64,
}

struct SphereAt {
    center: Point3,
    radius: f64,
}

impl Model<4> for SphereModel {
    type At = SphereAt;
    fn at(&self, x: &[f64; 4]) -> SphereAt {
        SphereAt {
            center: add(self.center, [x[0], x[1], x[2]]),
            radius: self.radius + x[3],
        }
    }
}

impl Linearised<4> for SphereAt {
    fn surface(&self) -> SurfaceParams {
        SurfaceParams::Sphere {
            center: self.center,
            radius: self.radius,
        }
    }
    /// `d = |p − c| − r`: `∂d/∂c = −n`, `∂d/∂r = −1`.
    fn row(&self, p: Point3) -> (f64, SVector<f64, 4>) {
        let w = sub(p, self.center);
        let len = norm(w);
        let n = if len > 0.0 {
            scale(w, 1.0 / len)
        } else {
            [0.0; 3]
        };
        (
            len - self.radius,
            SVector::<f64, 4>::new(-n[0], -n[1], -n[2], -1.0),
        )
    }
}

/// Cylinder: axis point offset along the frame (2), axis tilts (2), radius offset.
struct CylinderModel {
    axis_point: Point3,
    axis: Axis,
    radius: f64,
}

struct CylinderAt {
    axis_point: Point3,
    dir: Point3,
    inv_len: f64,
    radius: f64,
    u: Point3,
    v: Point3,
}

impl Model<5> for CylinderModel {
    type At = CylinderAt;
    fn at(&self, x: &[f64; 5]) -> CylinderAt {
        let (u, v) = (self.axis.u, self.axis.v);
        let (dir, inv_len) = self.axis.at(x[2], x[3]);
        CylinderAt {
            axis_point: add(add(self.axis_point, scale(u, x[0])), scale(v, x[1])),
            dir,
            inv_len,
            radius: self.radius + x[4],
            u,
            v,
        }
    }
}

impl Linearised<5> for CylinderAt {
    fn surface(&self) -> SurfaceParams {
        SurfaceParams::Cylinder {
            axis_point: self.axis_point,
            axis_dir: self.dir,
            radius: self.radius,
        }
    }
    /// `d = ρ − r` with `w = p − a`, `h = w·d̂`, `ρ = |w − h d̂|` along the unit `ρ̂`:
    /// `∂d/∂a = −ρ̂`, `∂d/∂d̂ = −h ρ̂`, `∂d/∂r = −1`.
    fn row(&self, p: Point3) -> (f64, SVector<f64, 5>) {
        let (rh, rho, h) = radial(sub(p, self.axis_point), self.dir);
        let (ru, rv) = (dot(rh, self.u), dot(rh, self.v));
        let t = -h * self.inv_len;
        (
            rho - self.radius,
            SVector::<f64, 5>::new(-ru, -rv, t * ru, t * rv, -1.0),
        )
    }
}

/// Cone: the axis point level with the patch's centroid offset along the frame (2), axis
/// tilts (2), the radius there and the half angle (offsets); the apex is
/// `q − d̂ r / tan θ`.
struct ConeModel {
    axis_point: Point3,
    axis: Axis,
    radius: f64,
    half_angle: f64,
}

struct ConeAt {
    apex: Point3,
    dir: Point3,
    inv_len: f64,
    half_angle: f64,
    sin: f64,
    cos: f64,
    /// `r / tan θ`: the apex's distance from the axis point.
    back: f64,
    radius: f64,
    u: Point3,
    v: Point3,
}

impl Model<6> for ConeModel {
    type At = ConeAt;
    fn at(&self, x: &[f64; 6]) -> ConeAt {
        let (u, v) = (self.axis.u, self.axis.v);
        let (dir, inv_len) = self.axis.at(x[2], x[3]);
        let q = add(add(self.axis_point, scale(u, x[0])), scale(v, x[1]));
        let half_angle = self.half_angle + x[5];
        let radius = self.radius + x[4];
        let back = radius / half_angle.tan();
        let (sin, cos) = half_angle.sin_cos();
        ConeAt {
            apex: sub(q, scale(dir, back)),
            dir,
            inv_len,
            half_angle,
            sin,
            cos,
            back,
            radius,
            u,
            v,
        }
    }
}

impl Linearised<6> for ConeAt {
    fn surface(&self) -> SurfaceParams {
        SurfaceParams::Cone {
            apex: self.apex,
            axis_dir: self.dir,
            half_angle: self.half_angle,
        }
    }
    /// `d = ρ cos θ − h sin θ` with `w = p − apex`, `h = w·d̂`, `ρ = |w − h d̂|` along `ρ̂`, and
    /// `n = cos θ ρ̂ − sin θ d̂`. Through `apex = q − b d̂` (`b = r / tan θ`):
    /// `∂d/∂q = −n`, `∂d/∂r = −cos θ`, `∂d/∂θ = −ρ sin θ − h cos θ + r / sin θ`, and along a
    /// tilt `(−h cos θ − ρ sin θ + b cos θ) ρ̂`.
    fn row(&self, p: Point3) -> (f64, SVector<f64, 6>) {
        let (s, c) = (self.sin, self.cos);
        let (rh, rho, h) = radial(sub(p, self.apex), self.dir);
        let n = sub(scale(rh, c), scale(self.dir, s));
        let (ru, rv) = (dot(rh, self.u), dot(rh, self.v));
        let t = (-h * c - rho * s + self.back * c) * self.inv_len;
        (
            rho * c - h * s,
            SVector::<f64, 6>::new(
                -dot(n, self.u),
                -dot(n, self.v),
                t * ru,
                t * rv,
                -c,
                -rho * s - h * c + self.radius / s,
            ),
        )
    }
}

/// Torus: centre offset (3), axis tilts (2), major and minor radius offsets.
struct TorusModel {
    center: Point3,
    axis: Axis,
    major_radius: f64,
    minor_radius: f64,
}

struct TorusAt {
    center: Point3,
    dir: Point3,
    inv_len: f64,
    major_radius: f64,
    minor_radius: f64,
    u: Point3,
    v: Point3,
}

impl Model<7> for TorusModel {
    type At = TorusAt;
    fn at(&self, x: &[f64; 7]) -> TorusAt {
        let (dir, inv_len) = self.axis.at(x[3], x[4]);
        TorusAt {
            center: add(self.center, [x[0], x[1], x[2]]),
            dir,
            inv_len,
            major_radius: self.major_radius + x[5],
            minor_radius: self.minor_radius + x[6],
            u: self.axis.u,
            v: self.axis.v,
        }
    }
}

impl Linearised<7> for TorusAt {
    fn surface(&self) -> SurfaceParams {
        SurfaceParams::Torus {
            center: self.center,
            axis_dir: self.dir,
            major_radius: self.major_radius,
            minor_radius: self.minor_radius,
        }
    }
    /// `d = √((ρ − R)² + h²) − r` with `w = p − c`, `h = w·d̂`, `ρ = |w − h d̂|` along `ρ̂`, and
    /// the unit `n = ((ρ − R) ρ̂ + h d̂) / √…`: `∂d/∂c = −n`, `∂d/∂R = −(ρ − R) / √…`,
    /// `∂d/∂r = −1`, and along a tilt `(h R / √…) ρ̂`.
    fn row(&self, p: Point3) -> (f64, SVector<f64, 7>) {
        let (rh, rho, h) = radial(sub(p, self.center), self.dir);
        let e = rho - self.major_radius;
        let len = e.hypot(h);
        let (n, de, t) = if len > 0.0 {
            let k = 1.0 / len;
            (
                add(scale(rh, e * k), scale(self.dir, h * k)),
                e * k,
                h * self.major_radius * k * self.inv_len,
            )
        } else {
            ([0.0; 3], 0.0, 0.0)
        };
        (
            len - self.minor_radius,
            SVector::<f64, 7>::from_column_slice(&[
                -n[0],
                -n[1],
                -n[2],
                t * dot(rh, self.u),
                t * dot(rh, self.v),
                -de,
                -1.0,
            ]),
        )
    }
}

/// Puts a refined surface in its canonical form: cylinder axis point nearest the centroid,
/// cone axis pointing from the apex into the patch, positive half angle.
fn canonical(s: SurfaceParams, pts: &[Point3], w: &[f64]) -> SurfaceParams {
    let c = centroid(pts, w).unwrap_or([0.0; 3]);
    match s {
        SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            radius,
        } => SurfaceParams::Cylinder {
            axis_point: add(
                axis_point,
                scale(axis_dir, dot(sub(c, axis_point), axis_dir)),
            ),
            axis_dir,
            radius: radius.abs(),
        },
        SurfaceParams::Cone {
            apex,
            mut axis_dir,
            half_angle,
        } => {
            if dot(sub(c, apex), axis_dir) < 0.0 {
                axis_dir = scale(axis_dir, -1.0);
            }
            SurfaceParams::Cone {
                apex,
                axis_dir,
                half_angle: half_angle.abs(),
            }
        }
        other => other,
    }
}

/// Diagonal of the points' bounding box: the natural size of the length parameters of the
/// refinement. `None` when the points coincide (the refinement is skipped). No absolute floor: it was 1e-12 model
/// units, which a region a few nanometres across in metres would have reached.
fn extent(pts: &[Point3]) -> Option<f64> {
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for p in pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let e = norm(sub(hi, lo));
    (e > 0.0 && e.is_finite()).then_some(e)
}

fn subsample(pts: &[Point3], w: &[f64]) -> (Vec<Point3>, Vec<f64>) {
    if pts.len() <= LM_MAX_POINTS {
        return (pts.to_vec(), w.to_vec());
    }
    let step = pts.len() as f64 / LM_MAX_POINTS as f64;
    (0..LM_MAX_POINTS)
        .map(|i| {
            let j = ((i as f64 * step) as usize).min(pts.len() - 1);
            (pts[j], w[j])
        })
        .unzip()
}

/// Least value of each diagonal entry of `JᵀJ` in the damping of [`lm`] (Marquardt's
/// `λ · diag(JᵀJ)`, which keeps the damped matrix positive definite where a parameter does not
/// move the residuals): `1e-12` of the largest diagonal entry once every parameter is measured
/// in its natural size (`JᵀJ_jj · scales_j²`), divided back by `scales_j²` — a numerical-rank
/// tolerance. Both sides scale alike with the units: the entries are weights (areas,
/// length²) times squared lever arms (1 for the length parameters, length² for the axis
/// directions and angles), so the damping, the LM path and the fit are the same in any units.
///
/// The floor was an absolute 1e-12, which damped the axes of small seeds thousands of times
/// harder in units 1000 times larger (`docs/experiments/segmentation.md`). Test:
/// `segmentation_is_independent_of_the_mesh_units`.
fn damping_floor<const N: usize>(jtj: &SMatrix<f64, N, N>, scales: &[f64; N]) -> [f64; N] {
    let top = (0..N)
        .map(|j| jtj[(j, j)] * scales[j] * scales[j])
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max);
    let mut out = [f64::MIN_POSITIVE; N];
    for (j, o) in out.iter_mut().enumerate() {
        let f = 1e-12 * top / (scales[j] * scales[j]);
        if f > 0.0 && f.is_finite() {
            *o = f;
        }
    }
    out
}

/// Levenberg–Marquardt on the signed orthogonal distances of `pts` to the surface of `model`,
/// starting at `x = 0` (the initial estimate), with analytic Jacobians ([`Linearised::row`]);
/// `scales` are the parameters' natural sizes (for the floor of the damping). Normal equations
/// accumulated over fixed chunks and summed in order, so the result does not depend on the
/// thread count. `None` if no step improved the initial cost.
fn lm<const N: usize, M: Model<N>>(
    model: &M,
    size: f64,
    scales: [f64; N],
    pts: &[Point3],
    w: &[f64],
) -> Option<[f64; N]> {
    let cost = |x: &[f64; N]| -> f64 {
        let s = Prepared::new(&model.at(x).surface());
        let parts: Vec<f64> = pts
            .par_chunks(2048)
            .zip(w.par_chunks(2048))
            .map(|(p, w)| {
                p.iter()
                    .zip(w)
                    .map(|(&p, &w)| {
                        let d = s.signed_distance(p);
                        w * d * d
                    })
                    .sum::<f64>()
            })
            .collect();
        parts.into_iter().sum()
    };
    let normal_eq = |x: &[f64; N]| -> (SMatrix<f64, N, N>, SVector<f64, N>) {
        let at = model.at(x);
        let parts: Vec<(SMatrix<f64, N, N>, SVector<f64, N>)> = pts
            .par_chunks(2048)
            .zip(w.par_chunks(2048))
            .map(|(p, w)| {
                let mut jtj = SMatrix::<f64, N, N>::zeros();
                let mut jtr = SVector::<f64, N>::zeros();
                for (&p, &wi) in p.iter().zip(w) {
                    let (r, g) = at.row(p);
                    add_outer(&mut jtj, &g, wi);
                    jtr += g * (r * wi);
                }
                (jtj, jtr)
            })
            .collect();
        let mut jtj = SMatrix::<f64, N, N>::zeros();
        let mut jtr = SVector::<f64, N>::zeros();
        for (a, b) in parts {
            jtj += a;
            jtr += b;
        }
        symmetrize(&mut jtj);
        (jtj, jtr)
    };
    let mut x = [0.0; N];
    let mut c = cost(&x);
    if !c.is_finite() {
        return None;
    }
    let c0 = c;
    let settled = (LM_SETTLED_RMS * size).powi(2) * w.iter().sum::<f64>();
    let mut lambda = 1e-3;
    // The cost at the start of every iteration, for the stall test.
    let mut history: Vec<f64> = Vec::new();
    for it in 0..LM_MAX_ITERATIONS {
        if c <= settled {
            break;
        }
        history.push(c);
        if it >= LM_STALL_ITERATIONS {
            let before = history[it - LM_STALL_ITERATIONS];
            if before - c < LM_STALL_DECREASE * before {
                break;
            }
        }
        let (jtj, jtr) = normal_eq(&x);
        let floor = damping_floor(&jtj, &scales);
        let mut improved = false;
        for _ in 0..12 {
            let mut a = jtj;
            for j in 0..N {
                a[(j, j)] += lambda * jtj[(j, j)].max(floor[j]);
            }
            let Some(delta) = a.cholesky().map(|ch| ch.solve(&-jtr)) else {
                lambda *= 10.0;
                continue;
            };
            let mut xn = x;
            for j in 0..N {
                xn[j] += delta[j];
            }
            let cn = cost(&xn);
            if cn.is_finite() && cn < c {
                let rel = (c - cn) / c.max(1e-300);
                x = xn;
                c = cn;
                lambda = (lambda * 0.3).max(1e-12);
                improved = true;
                if rel < LM_COST_TOLERANCE {
                    return Some(x);
                }
                break;
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    (c <= c0).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::surface::surface_normal;
    use rand::{Rng, SeedableRng};
    use rand_distr::StandardNormal;
    use rand_pcg::Pcg64;

    fn angle_deg(a: Point3, b: Point3) -> f64 {
        dot(a, b).abs().clamp(-1.0, 1.0).acos().to_degrees()
    }

    /// Samples `n` points of a patch with exact normals, noise `sigma` along the normal.
    fn sample(
        s: &SurfaceParams,
        n: usize,
        sigma: f64,
        gen: impl Fn(&mut Pcg64) -> Point3,
    ) -> (Vec<Point3>, Vec<Point3>, Vec<f64>) {
        let mut rng = Pcg64::seed_from_u64(7);
        let mut pts = Vec::new();
        let mut nrm = Vec::new();
        for _ in 0..n {
            let p = gen(&mut rng);
            let nn = surface_normal(s, p);
            let e: f64 = rng.sample::<f64, _>(StandardNormal) * sigma;
            pts.push(add(p, scale(nn, e)));
            // Normals perturbed a little (estimated normals are never exact).
            let jitter = [
                rng.sample::<f64, _>(StandardNormal) * 0.01 * (sigma > 0.0) as u8 as f64,
                rng.sample::<f64, _>(StandardNormal) * 0.01 * (sigma > 0.0) as u8 as f64,
                rng.sample::<f64, _>(StandardNormal) * 0.01 * (sigma > 0.0) as u8 as f64,
            ];
            nrm.push(normalize(add(nn, jitter)).unwrap());
        }
        let w = vec![1.0; n];
        (pts, nrm, w)
    }

    #[test]
    fn cylinder_fits_radius_and_axis() {
        let d = normalize([0.3, -0.2, 1.0]).unwrap();
        let (u, v) = frame_of(d);
        let truth = SurfaceParams::Cylinder {
            axis_point: [0.1, 0.2, 0.3],
            axis_dir: d,
            radius: 0.4,
        };
        for sigma in [0.0, 0.002] {
            // A 120° arc, height 1.
            let (pts, nrm, w) = sample(&truth, 3000, sigma, |rng| {
                let t: f64 = rng.random_range(0.0..2.1);
                let h: f64 = rng.random_range(-0.5..0.5);
                add(
                    add([0.1, 0.2, 0.3], scale(d, h)),
                    add(scale(u, 0.4 * t.cos()), scale(v, 0.4 * t.sin())),
                )
            });
            let f = fit(SurfaceType::Cylinder, &pts, &nrm, &w).unwrap();
            let SurfaceParams::Cylinder {
                axis_point,
                axis_dir,
                radius,
            } = f.params
            else {
                panic!("type")
            };
            let rel = (radius - 0.4).abs() / 0.4;
            let ang = angle_deg(axis_dir, d);
            let off = norm(cross(sub(axis_point, [0.1, 0.2, 0.3]), d));
            eprintln!("cylinder sigma {sigma}: radius err {rel:.2e}, axis {ang:.3}°, axis offset {off:.2e}, rms {:.2e}", f.rms);
            let tol = if sigma > 0.0 { 0.01 } else { 0.005 };
            assert!(rel < tol * 0.2 && ang < 1.0 && off < 0.004);
        }
    }

    #[test]
    fn cone_sphere_torus_fit() {
        let d = normalize([0.0, 0.6, 0.8]).unwrap();
        let (u, v) = frame_of(d);
        let apex = [0.2, -0.1, 0.05];
        let ha: f64 = 0.5;
        let cone = SurfaceParams::Cone {
            apex,
            axis_dir: d,
            half_angle: ha,
        };
        let sphere = SurfaceParams::Sphere {
            center: [1.0, 2.0, -0.5],
            radius: 0.7,
        };
        let torus = SurfaceParams::Torus {
            center: [-0.3, 0.4, 0.2],
            axis_dir: d,
            major_radius: 0.5,
            minor_radius: 0.15,
        };
        for sigma in [0.0, 0.002] {
            let (pts, nrm, w) = sample(&cone, 3000, sigma, |rng| {
                let t: f64 = rng.random_range(0.0..4.0);
                let s: f64 = rng.random_range(0.3..1.0);
                let dir = add(
                    scale(d, ha.cos()),
                    scale(add(scale(u, t.cos()), scale(v, t.sin())), ha.sin()),
                );
                add(apex, scale(dir, s))
            });
            let f = fit(SurfaceType::Cone, &pts, &nrm, &w).unwrap();
            let SurfaceParams::Cone {
                apex: a,
                axis_dir,
                half_angle,
            } = f.params
            else {
                panic!("type")
            };
            let ang = angle_deg(axis_dir, d);
            let ea = (half_angle - ha).abs().to_degrees();
            let eapex = norm(sub(a, apex));
            eprintln!("cone sigma {sigma}: axis {ang:.3}°, half angle err {ea:.3}°, apex err {eapex:.2e}, rms {:.2e}", f.rms);
            assert!(ang < 1.0 && ea < 0.2 && eapex < 0.01);
            assert!(dot(axis_dir, d) > 0.0);

            let (pts, nrm, w) = sample(&sphere, 3000, sigma, |rng| {
                let z: f64 = rng.random_range(0.2..1.0);
                let t: f64 = rng.random_range(0.0..3.0);
                let q = [
                    (1.0 - z * z).sqrt() * t.cos(),
                    (1.0 - z * z).sqrt() * t.sin(),
                    z,
                ];
                add([1.0, 2.0, -0.5], scale(q, 0.7))
            });
            let f = fit(SurfaceType::Sphere, &pts, &nrm, &w).unwrap();
            let SurfaceParams::Sphere { center, radius } = f.params else {
                panic!("type")
            };
            let rel = (radius - 0.7).abs() / 0.7;
            eprintln!(
                "sphere sigma {sigma}: radius err {rel:.2e}, centre err {:.2e}",
                norm(sub(center, [1.0, 2.0, -0.5]))
            );
            assert!(rel < 0.002);

            let (pts, nrm, w) = sample(&torus, 4000, sigma, |rng| {
                let t: f64 = rng.random_range(0.0..3.5);
                let p: f64 = rng.random_range(-1.5..2.5);
                let radial = add(scale(u, t.cos()), scale(v, t.sin()));
                add(
                    [-0.3, 0.4, 0.2],
                    add(
                        scale(radial, 0.5 + 0.15 * p.cos()),
                        scale(d, 0.15 * p.sin()),
                    ),
                )
            });
            let f = fit(SurfaceType::Torus, &pts, &nrm, &w).unwrap();
            let SurfaceParams::Torus {
                center,
                axis_dir,
                major_radius,
                minor_radius,
            } = f.params
            else {
                panic!("type")
            };
            let (er, em) = (
                (major_radius - 0.5).abs() / 0.5,
                (minor_radius - 0.15).abs() / 0.15,
            );
            let ang = angle_deg(axis_dir, d);
            eprintln!("torus sigma {sigma}: R err {er:.2e}, r err {em:.2e}, axis {ang:.3}°, centre {:.2e}", norm(sub(center, [-0.3, 0.4, 0.2])));
            assert!(er < 0.005 && em < 0.005 && ang < 1.0);
        }
    }

    #[test]
    fn plane_fit_and_distances() {
        let n = normalize([1.0, 2.0, 2.0]).unwrap();
        let s = SurfaceParams::Plane {
            normal: n,
            offset: 0.3,
        };
        let (u, v) = frame_of(n);
        let (pts, nrm, w) = sample(&s, 500, 0.001, |rng| {
            add(
                scale(n, 0.3),
                add(
                    scale(u, rng.random_range(-1.0..1.0)),
                    scale(v, rng.random_range(-1.0..1.0)),
                ),
            )
        });
        let f = fit(SurfaceType::Plane, &pts, &nrm, &w).unwrap();
        let SurfaceParams::Plane { normal, offset } = f.params else {
            panic!()
        };
        assert!(angle_deg(normal, n) < 0.1 && (offset - 0.3).abs() < 1e-3);
        assert!((f.rms - 0.001).abs() < 2e-4);
        // Signed distances and normals agree with the synth module's unsigned distance.
        let torus = SurfaceParams::Torus {
            center: [0.0; 3],
            axis_dir: [0.0, 0.0, 1.0],
            major_radius: 1.0,
            minor_radius: 0.25,
        };
        let p = [1.5, 0.0, 0.1];
        assert!((signed_distance(&torus, p).abs() - torus.distance(p)).abs() < 1e-12);
        let nn = surface_normal(&torus, [1.25, 0.0, 0.0]);
        assert!(norm(sub(nn, [1.0, 0.0, 0.0])) < 1e-12);
    }

    /// Every model's Jacobian row against central differences of its surface's signed
    /// distance, at parameters away from the initial estimate and at points around it.
    #[test]
    fn analytic_jacobians_match_finite_differences() {
        fn check<const N: usize, M: Model<N>>(m: &M, x: [f64; N], pts: &[Point3]) {
            let at = m.at(&x);
            for &p in pts {
                let (r, g) = at.row(p);
                let d0 = signed_distance(&at.surface(), p);
                assert!((r - d0).abs() < 1e-12, "residual {r} vs {d0}");
                for j in 0..N {
                    let h = 1e-6;
                    let (mut xp, mut xm) = (x, x);
                    xp[j] += h;
                    xm[j] -= h;
                    let fd = (signed_distance(&m.at(&xp).surface(), p)
                        - signed_distance(&m.at(&xm).surface(), p))
                        / (2.0 * h);
                    assert!(
                        (g[j] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                        "parameter {j}: analytic {} vs central difference {fd} at {p:?}",
                        g[j]
                    );
                }
            }
        }
        let mut rng = Pcg64::seed_from_u64(3);
        let pts: Vec<Point3> = (0..50)
            .map(|_| {
                [
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-3.0..3.0),
                    rng.random_range(-3.0..3.0),
                ]
            })
            .collect();
        let dir = normalize([0.3, -0.5, 0.8]).unwrap();
        check(
            &SphereModel {
                center: [0.1, 0.2, -0.3],
                radius: 1.5,
            },
            [0.05, -0.02, 0.1, 0.2],
            &pts,
        );
        check(
            &CylinderModel {
                axis_point: [0.1, 0.2, -0.3],
                axis: Axis::new(dir),
                radius: 1.2,
            },
            [0.05, -0.02, 0.1, -0.15, 0.2],
            &pts,
        );
        check(
            &ConeModel {
                axis_point: [0.1, 0.2, -0.3],
                axis: Axis::new(dir),
                radius: 1.2,
                half_angle: 0.5,
            },
            [0.05, -0.02, 0.1, -0.15, 0.2, 0.1],
            &pts,
        );
        check(
            &TorusModel {
                center: [0.1, 0.2, -0.3],
                axis: Axis::new(dir),
                major_radius: 2.0,
                minor_radius: 0.5,
            },
            [0.05, -0.02, 0.1, -0.15, 0.12, 0.2, -0.1],
            &pts,
        );
    }
}
