//! Where the faces meet: points on several surfaces at once (the B-rep's vertices, and the
//! samples of curves without a closed form), and the intersection curve of two adjacent faces,
//! exact where it is a line, a circle or an ellipse.
//!
//! Points: Levenberg–Marquardt on the signed distances, started from the mesh vertex. With as
//! many surfaces as unknowns it converges to their common point in Gauss–Newton steps; with
//! fewer (two faces and a closed edge, a face and the mesh border) the tiny damping keeps the
//! step near the minimum-norm one, so the point stays near its start; with tangent faces (a
//! fillet meeting a plane) the system is rank deficient, and a step that would overshoot along
//! the tangent (faces that nearly touch but not quite) is refused and damped instead.
//!
//! Curves, in the order tried:
//! - two planes: their line;
//! - a plane across the axis of a cylinder, cone, sphere or torus, or two such surfaces on one
//!   axis (a sphere's centre on the other's axis): the circle about that axis through the
//!   edge's start vertex;
//! - a plane parallel to a cylinder's axis: the line along the axis through the start vertex;
//!   a plane through a torus's axis: the tube circle through the start vertex;
//! - a plane oblique to a cylinder's axis, or across a cone steeper than its generators:
//!   their ellipse;
//! - anything else (a plane's parabola or hyperbola on a cone, two crossing cylinders): the cubic
//!   B-spline interpolating the mesh chain's vertices moved onto both surfaces (`interpolate`);
//! - the mesh border (one surface): the surface's curve in the border's plane when the border
//!   is planar, a line where it is straight on a plane, else the degree-1 B-spline through the
//!   chain's vertices moved onto the surface (a border may have corners).

use crate::geometry::surface::{signed_distance, surface_normal};
use crate::geometry::vec3::{add, cross, dist, dot, line_distance, norm, normalize, scale, sub};
use crate::geometry::{Point3, SurfaceParams};

use super::Curve;

/// Axes closer to parallel than this (1 − |cos|) are taken as parallel, and points closer
/// than this fraction of the part's size as on an axis.
const PARALLEL: f64 = 1e-9;

/// The point nearest `start` (approximately, see the module documentation) on every surface
/// of `surfaces`.
pub(crate) fn on_surfaces(surfaces: &[SurfaceParams], start: Point3) -> Point3 {
    let mut x = start;
    if surfaces.is_empty() {
        return x;
    }
    // Normal equations JᵀJ and −Jᵀr at `x`, and the cost Σ r².
    let system = |x: Point3| {
        let mut a = [[0.0f64; 3]; 3];
        let mut b = [0.0f64; 3];
        let mut cost = 0.0;
        for s in surfaces {
            let r = signed_distance(s, x);
            let g = surface_normal(s, x);
            cost += r * r;
            for i in 0..3 {
                b[i] -= g[i] * r;
                for j in 0..3 {
                    a[i][j] += g[i] * g[j];
                }
            }
        }
        (a, b, cost)
    };
    let (mut a, mut b, mut cost) = system(x);
    // Levenberg–Marquardt: the damping starts at a tiny fraction of the trace (a Gauss–Newton
    // step) and grows tenfold whenever a step would raise the cost (the overshoot of nearly
    // tangent surfaces that do not quite meet), shrinking again after a step that lowers it.
    let trace = (a[0][0] + a[1][1] + a[2][2]).max(1e-300);
    let mut mu = 1e-16 * trace;
    for _ in 0..200 {
        if cost == 0.0 || mu > 1e8 * trace {
            break;
        }
        let mut damped = a;
        for (i, row) in damped.iter_mut().enumerate() {
            row[i] += mu;
        }
        let Some(d) = solve3(damped, b) else { break };
        let next = add(x, d);
        let (na, nb, ncost) = system(next);
        if ncost <= cost {
            (x, a, b, cost) = (next, na, nb, ncost);
            mu = (mu / 10.0).max(1e-16 * trace);
            if norm(d) <= 1e-15 * (1.0 + norm(x)) {
                break;
            }
        } else {
            mu *= 10.0;
        }
    }
    x
}

/// Points along the intersection curve of `a` and `b` from `start` to `end` (equal for a
/// closed curve), about `step` apart: each step goes along the curve's tangent (the cross
/// product of the two normals) and is pulled back onto both surfaces ([`on_surfaces`]); the
/// direction is the one the mesh chain `guide` (from start to end) sets off in. Marching gives
/// evenly spaced points exactly on the curve where the chain of a noisy or coarse mesh
/// zigzags about it. None when the march does not reach the end within twice the guide's
/// length (the surfaces turn tangent or part, or the march took another branch).
pub(crate) fn march(
    a: &SurfaceParams,
    b: &SurfaceParams,
    start: Point3,
    end: Point3,
    guide: &[Point3],
    step: f64,
) -> Option<Vec<Point3>> {
    let both = [*a, *b];
    let tangent = |x: Point3| normalize(cross(surface_normal(a, x), surface_normal(b, x)));
    let length: f64 = guide.windows(2).map(|w| dist(w[0], w[1])).sum();
    if step.is_nan() || step <= 0.0 || length <= 2.0 * step {
        return None;
    }
    // The way the chain sets off: towards its first point two steps away.
    let ahead = guide.iter().find(|&&g| dist(g, start) > 2.0 * step)?;
    let mut t = tangent(start)?;
    if dot(t, sub(*ahead, start)) < 0.0 {
        t = scale(t, -1.0);
    }
    let mut points = vec![start];
    let mut x = start;
    let mut travelled = 0.0;
    while travelled <= 2.0 * length {
        let next = on_surfaces(&both, add(x, scale(t, step)));
        let moved = dist(next, x);
        if !(moved > 0.3 * step && moved < 3.0 * step) {
            return None;
        }
        // The end within this step (not the start of a closed curve as it sets off).
        if travelled > 1.5 * step && dist(end, next) <= step {
            let past = dot(sub(end, x), sub(next, x)) < dot(sub(next, x), sub(next, x));
            if !past && dist(end, next) > 0.5 * step {
                points.push(next);
            }
            points.push(end);
            return Some(points);
        }
        travelled += moved;
        let mut nt = tangent(next)?;
        if dot(nt, t) < 0.0 {
            nt = scale(nt, -1.0);
        }
        points.push(next);
        (x, t) = (next, nt);
    }
    None
}

/// Where a plane and a ball among `surfaces` touch, if they do (to round-off, as snapping
/// leaves a ball tangent to its faces): the vertex where a corner ball meets a face and its
/// fillets. All the surfaces there share one normal, so their distances alone leave the point
/// free to slide (to the square root of the round-off); the contact point does not.
pub(crate) fn contact_point(surfaces: &[SurfaceParams]) -> Option<Point3> {
    surfaces.iter().find_map(|p| {
        let SurfaceParams::Plane { normal, offset } = *p else {
            return None;
        };
        surfaces.iter().find_map(|s| {
            let SurfaceParams::Sphere { center, radius } = *s else {
                return None;
            };
            let h = dot(normal, center) - offset;
            ((h.abs() - radius).abs() <= 1e-9 * radius).then(|| sub(center, scale(normal, h)))
        })
    })
}

fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<Point3> {
    let m = nalgebra::Matrix3::from_fn(|i, j| a[i][j]);
    let v = nalgebra::Vector3::new(b[0], b[1], b[2]);
    let x = m.lu().solve(&v)?;
    let x = [x[0], x[1], x[2]];
    x.iter().all(|c| c.is_finite()).then_some(x)
}

/// An axis of symmetry of a surface: a point on it and its unit direction (none for a plane;
/// a sphere's is any line through its centre, returned as `None` direction).
fn axis(s: &SurfaceParams) -> Option<(Point3, Option<Point3>)> {
    match *s {
        SurfaceParams::Sphere { center, .. } => Some((center, None)),
        _ => s.axis().map(|(p, d)| (p, Some(d))),
    }
}

fn parallel(a: Point3, b: Point3) -> bool {
    1.0 - dot(a, b).abs() <= PARALLEL
}

/// The line through `start` along `±d`, pointing towards `end`.
fn line_from(start: Point3, end: Point3, d: Point3) -> Curve {
    let dir = if dot(d, sub(end, start)) < 0.0 {
        scale(d, -1.0)
    } else {
        d
    };
    Curve::Line { origin: start, dir }
}

/// The circle about the line (`o`, `d`) through `p`.
fn circle_through(o: Point3, d: Point3, p: Point3) -> Option<Curve> {
    let centre = add(o, scale(d, dot(sub(p, o), d)));
    let radius = dist(p, centre);
    let ref_dir = normalize(sub(p, centre))?;
    (radius > 0.0).then_some(Curve::Circle {
        center: centre,
        axis: d,
        ref_dir,
        radius,
    })
}

/// The ellipse in which the plane of normal `n` through `start` (a point of the cylinder: the
/// edge's start vertex, as for circles) cuts the cylinder of axis (`o`, unit `d`) and `radius`
/// obliquely: centred where the axis crosses the plane, semi-minor axis the radius across the
/// axis, semi-major axis `radius / |cos φ|` along the plane's steepest line (φ the angle
/// between the axis and the normal). None when that semi-major axis is longer than `size`
/// (the part's): the axis then nearly lies in the plane, the edge is a barely curved stretch
/// of an ellipse centred far off the part, whose arc the edge's chain cannot tell (the
/// B-spline marched along the intersection serves there).
fn oblique_cut(
    (o, d, radius): (Point3, Point3, f64),
    n: &Point3,
    start: Point3,
    size: f64,
) -> Option<Curve> {
    let cos = dot(d, *n);
    if !(radius > 0.0 && radius < size * cos.abs()) {
        return None;
    }
    let center = add(o, scale(d, dot(*n, sub(start, o)) / cos));
    let minor = normalize(cross(d, *n))?;
    Some(Curve::Ellipse {
        center,
        axis: *n,
        ref_dir: cross(*n, minor),
        semi_major: radius / cos.abs(),
        semi_minor: radius,
    })
}

/// The ellipse in which the plane of normal `n` through `start` (a point of the cone) cuts
/// the nappe of the cone (`apex`, unit `d`, `half_angle`) that `d` points into, when the plane
/// crosses every generator of it (steeper than the cone: a closed section): the two
/// generators in the plane of the axis and `n` meet the plane at the ends of the major axis;
/// the semi-minor axis is the half chord across that plane through their midpoint, `√(ρ² −
/// δ²)`, ρ the cone's radius at the midpoint's height and δ the midpoint's distance from the
/// axis. None for a parabola or a hyperbola, or a major axis longer than `size` (see
/// [`oblique_cut`]).
fn conic_section(
    (apex, d, half_angle): (Point3, Point3, f64),
    n: &Point3,
    start: Point3,
    size: f64,
) -> Option<Curve> {
    let offset = dot(*n, start);
    // The unit direction across the axis in the plane of the axis and the normal.
    let e = normalize(sub(*n, scale(d, dot(*n, d))))?;
    let (sin, cos) = half_angle.sin_cos();
    let mut ends = [[0.0; 3]; 2];
    for (end, side) in ends.iter_mut().zip([1.0, -1.0]) {
        let g = add(scale(d, cos), scale(e, side * sin));
        let along = dot(*n, g);
        let t = (offset - dot(*n, apex)) / along;
        if !(t > 0.0 && t.is_finite()) {
            return None;
        }
        *end = add(apex, scale(g, t));
    }
    let center = scale(add(ends[0], ends[1]), 0.5);
    let semi_major = 0.5 * dist(ends[0], ends[1]);
    let v = sub(center, apex);
    let h = dot(v, d);
    let rho = h * sin / cos;
    let delta = norm(sub(v, scale(d, h)));
    let semi_minor = (rho * rho - delta * delta).max(0.0).sqrt();
    if !(semi_minor > 0.0 && semi_major < size) {
        return None;
    }
    let ref_dir = normalize(sub(ends[0], ends[1]))?;
    Some(Curve::Ellipse {
        center,
        axis: *n,
        ref_dir,
        semi_major: semi_major.max(semi_minor),
        semi_minor: semi_minor.min(semi_major),
    })
}

/// The closed-form intersection curve of `a` and `b` through the vertex `start`, if the pair
/// has one (see the module documentation); `size` (the part's) scales the "on the axis" test
/// and bounds an ellipse's axes.
pub(crate) fn analytic_curve(
    a: &SurfaceParams,
    b: &SurfaceParams,
    start: Point3,
    end: Point3,
    size: f64,
) -> Option<Curve> {
    let on_axis = PARALLEL.sqrt() * size;
    match (a, b) {
        (SurfaceParams::Plane { normal: n1, .. }, SurfaceParams::Plane { normal: n2, .. }) => {
            // Parallel planes (a sheet and the plane of its own border) have no line.
            (!parallel(*n1, *n2)).then_some(())?;
            Some(line_from(start, end, normalize(cross(*n1, *n2))?))
        }
        (SurfaceParams::Plane { normal, .. }, s) | (s, SurfaceParams::Plane { normal, .. }) => {
            let (o, dir) = axis(s)?;
            match dir {
                None => circle_through(o, *normal, start),
                Some(d) if parallel(d, *normal) => circle_through(o, d, start),
                Some(d) if dot(d, *normal).abs() <= PARALLEL => match *s {
                    SurfaceParams::Torus {
                        center,
                        major_radius,
                        minor_radius,
                        ..
                    } if dot(sub(center, start), *normal).abs() <= on_axis => {
                        // A plane through the torus's axis: the two tube circles; the one
                        // through the start vertex.
                        let u = normalize(cross(d, *normal))?;
                        let side = if dot(sub(start, center), u) < 0.0 {
                            -1.0
                        } else {
                            1.0
                        };
                        let c = add(center, scale(u, side * major_radius));
                        let ref_dir = normalize(sub(start, c))?;
                        Some(Curve::Circle {
                            center: c,
                            axis: *normal,
                            ref_dir,
                            radius: minor_radius,
                        })
                    }
                    SurfaceParams::Cylinder { .. } => Some(line_from(start, end, d)),
                    _ => None,
                },
                Some(d) => match *s {
                    SurfaceParams::Cylinder {
                        axis_point, radius, ..
                    } => oblique_cut((axis_point, d, radius), normal, start, size),
                    SurfaceParams::Cone {
                        apex, half_angle, ..
                    } => conic_section((apex, d, half_angle), normal, start, size),
                    _ => None,
                },
            }
        }
        _ => {
            let (oa, da) = axis(a)?;
            let (ob, db) = axis(b)?;
            match (da, db) {
                (Some(da), Some(db))
                    if parallel(da, db) && line_distance(ob, oa, da) <= on_axis =>
                {
                    circle_through(oa, da, start)
                }
                (Some(d), None) if line_distance(ob, oa, d) <= on_axis => {
                    circle_through(oa, d, start)
                }
                (None, Some(d)) if line_distance(oa, ob, d) <= on_axis => {
                    circle_through(ob, d, start)
                }
                _ => None,
            }
        }
    }
}

/// Points kept of a chain for the interpolating B-spline: enough for a smooth intersection
/// curve, few enough for the dense solve.
const MAX_SPLINE_POINTS: usize = 256;

/// The cubic B-spline through `points` (Piegl & Tiller, "The NURBS Book", algorithm A9.1:
/// chord-length parameters, knots by averaging), after evenly thinning them to at most
/// [`MAX_SPLINE_POINTS`] (the ends kept). Fewer than four points give a lower degree.
pub(crate) fn interpolate(points: &[Point3]) -> Curve {
    let n0 = points.len();
    let q: Vec<Point3> = if n0 > MAX_SPLINE_POINTS {
        (0..MAX_SPLINE_POINTS)
            .map(|i| points[i * (n0 - 1) / (MAX_SPLINE_POINTS - 1)])
            .collect()
    } else {
        points.to_vec()
    };
    let n = q.len();
    if n < 3 {
        return Curve::polyline(q);
    }
    let p = 3.min(n - 1);
    // Chord-length parameters.
    let mut u = vec![0.0; n];
    for k in 1..n {
        u[k] = u[k - 1] + dist(q[k], q[k - 1]);
    }
    let total = u[n - 1];
    if total <= 0.0 {
        return Curve::polyline(q);
    }
    for x in &mut u {
        *x /= total;
    }
    u[n - 1] = 1.0;
    // Knots: p + 1 zeros, averages, p + 1 ones.
    let mut knots = vec![0.0; p + 1];
    for j in 1..n - p {
        knots.push(u[j..j + p].iter().sum::<f64>() / p as f64);
    }
    knots.extend(std::iter::repeat_n(1.0, p + 1));
    // Each row holds the p + 1 basis functions that are nonzero at u[k].
    let mut a = nalgebra::DMatrix::zeros(n, n);
    for (k, &t) in u.iter().enumerate() {
        let s = span(&knots, p, n, t);
        let nz = basis_funs(&knots, p, s, t);
        for (j, &b) in nz[..=p].iter().enumerate() {
            a[(k, s - p + j)] = b;
        }
    }
    let Some(lu) = Some(a.lu()) else {
        return Curve::polyline(q);
    };
    let mut control = vec![[0.0; 3]; n];
    for c in 0..3 {
        let b = nalgebra::DVector::from_fn(n, |k, _| q[k][c]);
        let Some(x) = lu.solve(&b) else {
            return Curve::polyline(q);
        };
        for k in 0..n {
            control[k][c] = x[k];
        }
    }
    if control.iter().flatten().any(|v| !v.is_finite()) {
        return Curve::polyline(q);
    }
    // Distinct knots with multiplicities.
    let mut distinct: Vec<f64> = Vec::new();
    let mut mult: Vec<usize> = Vec::new();
    for &k in &knots {
        match distinct.last() {
            Some(&l) if l == k => *mult.last_mut().unwrap_or(&mut 0) += 1,
            _ => {
                distinct.push(k);
                mult.push(1);
            }
        }
    }
    Curve::BSpline {
        degree: p,
        control_points: control,
        knots: distinct,
        multiplicities: mult,
    }
}

/// Largest degree of the splines built here (cubic).
const MAX_DEGREE: usize = 3;

/// The knot span of `t` on a clamped knot vector `full` of `n` control points and degree `p`:
/// the s in p..n with full[s] ≤ t < full[s + 1]; the last span at the end of the domain.
fn span(full: &[f64], p: usize, n: usize, t: f64) -> usize {
    if t >= full[n] {
        return n - 1;
    }
    let s = full[..=n].partition_point(|&k| k <= t);
    s.saturating_sub(1).clamp(p, n - 1)
}

/// The p + 1 basis functions N_{s-p..=s, p}(t) that are nonzero on span `s` (The NURBS Book,
/// algorithm A2.2: O(p²), no allocation; 0/0 taken as 0 on repeated knots). Evaluating every
/// basis function by Cox–de Boor made a long border's spline cost 16 s.
fn basis_funs(full: &[f64], p: usize, s: usize, t: f64) -> [f64; MAX_DEGREE + 1] {
    let mut n = [0.0; MAX_DEGREE + 1];
    let (mut left, mut right) = ([0.0; MAX_DEGREE + 1], [0.0; MAX_DEGREE + 1]);
    n[0] = 1.0;
    for j in 1..=p {
        left[j] = t - full[s + 1 - j];
        right[j] = full[s + j] - t;
        let mut saved = 0.0;
        for r in 0..j {
            let den = right[r + 1] + left[j - r];
            let temp = if den != 0.0 { n[r] / den } else { 0.0 };
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
    }
    n
}

/// Points of a clamped B-spline (distinct `knots` with their `multiplicities`) at the
/// parameters `ts`.
pub(crate) fn bspline_points(
    degree: usize,
    control: &[Point3],
    knots: &[f64],
    multiplicities: &[usize],
    ts: impl IntoIterator<Item = f64>,
) -> Vec<Point3> {
    let full: Vec<f64> = knots
        .iter()
        .zip(multiplicities)
        .flat_map(|(&k, &m)| std::iter::repeat_n(k, m))
        .collect();
    let (p, n) = (degree.min(MAX_DEGREE), control.len());
    if n == 0 || full.len() < n + p + 1 {
        return Vec::new();
    }
    ts.into_iter()
        .map(|t| {
            let s = span(&full, p, n, t);
            let b = basis_funs(&full, p, s, t);
            let mut q = [0.0; 3];
            for (j, &w) in b[..=p].iter().enumerate() {
                let c = control[s - p + j];
                for k in 0..3 {
                    q[k] += w * c[k];
                }
            }
            q
        })
        .collect()
}

/// The point of a clamped B-spline at parameter `t` ([`bspline_points`]).
#[cfg(test)]
fn bspline_point(
    degree: usize,
    control: &[Point3],
    knots: &[f64],
    multiplicities: &[usize],
    t: f64,
) -> Point3 {
    bspline_points(degree, control, knots, multiplicities, [t])
        .first()
        .copied()
        .unwrap_or([f64::NAN; 3])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_interpolating_spline_passes_through_its_points_and_follows_a_circle() {
        let pts: Vec<Point3> = (0..40)
            .map(|i| {
                let a = 2.0 * i as f64 / 39.0;
                [a.cos(), a.sin(), 0.3]
            })
            .collect();
        let Curve::BSpline {
            degree,
            control_points,
            knots,
            multiplicities,
        } = interpolate(&pts)
        else {
            panic!("a spline expected");
        };
        assert_eq!(degree, 3);
        assert_eq!(
            multiplicities.iter().sum::<usize>(),
            control_points.len() + 4
        );
        // Ends exact, and every point of the curve within 1e-6 of the unit circle.
        let start = bspline_point(degree, &control_points, &knots, &multiplicities, 0.0);
        let end = bspline_point(degree, &control_points, &knots, &multiplicities, 1.0);
        assert!(dist(start, pts[0]) < 1e-12 && dist(end, pts[39]) < 1e-12);
        for i in 0..=200 {
            let p = bspline_point(
                degree,
                &control_points,
                &knots,
                &multiplicities,
                i as f64 / 200.0,
            );
            assert!(((p[0].hypot(p[1])) - 1.0).abs() < 1e-6, "{p:?}");
            assert!((p[2] - 0.3).abs() < 1e-12);
        }
    }

    #[test]
    fn the_common_point_of_three_surfaces_is_solved_exactly() {
        let planes = [
            SurfaceParams::Plane {
                normal: [1.0, 0.0, 0.0],
                offset: 0.5,
            },
            SurfaceParams::Plane {
                normal: [0.0, 1.0, 0.0],
                offset: -0.25,
            },
        ];
        let cyl = SurfaceParams::Cylinder {
            axis_point: [0.0; 3],
            axis_dir: [1.0, 0.0, 0.0],
            radius: 1.0,
        };
        let p = on_surfaces(&[planes[0], planes[1], cyl], [0.4, -0.2, 0.9]);
        // x = 0.5, y = -0.25, y² + z² = 1 with z > 0.
        assert!(
            dist(p, [0.5, -0.25, (1.0f64 - 0.0625).sqrt()]) < 1e-14,
            "{p:?}"
        );
    }

    #[test]
    fn a_plane_across_an_axis_meets_it_in_a_circle() {
        let plane = SurfaceParams::Plane {
            normal: [0.0, 0.0, 1.0],
            offset: 2.0,
        };
        let cone = SurfaceParams::Cone {
            apex: [1.0, 1.0, 0.0],
            axis_dir: [0.0, 0.0, 1.0],
            half_angle: std::f64::consts::FRAC_PI_4,
        };
        let start = [3.0, 1.0, 2.0];
        let Some(Curve::Circle {
            center,
            radius,
            axis,
            ..
        }) = analytic_curve(&plane, &cone, start, start, 10.0)
        else {
            panic!("a circle expected");
        };
        assert!(dist(center, [1.0, 1.0, 2.0]) < 1e-15 && (radius - 2.0).abs() < 1e-15);
        assert!(parallel(axis, [0.0, 0.0, 1.0]));
    }

    #[test]
    fn a_plane_steeper_than_a_cone_cuts_it_in_an_ellipse_on_both() {
        // A cone of half angle 30° about an oblique axis, cut 25° off square to its axis at
        // height 2 (an ellipse), then 70° off (steeper than the generators' 60°: a
        // hyperbola, no closed form here).
        let d = normalize([0.3, -0.2, 1.0]).expect("axis");
        let apex = [0.1, 0.2, -0.3];
        let cone = SurfaceParams::Cone {
            apex,
            axis_dir: d,
            half_angle: 30f64.to_radians(),
        };
        let across = normalize(cross(d, [1.0, 0.0, 0.0])).expect("across");
        let at = add(apex, scale(d, 2.0));
        for (tilt, ellipse) in [(25.0f64, true), (70.0, false)] {
            let t = tilt.to_radians();
            let normal = add(scale(d, t.cos()), scale(across, t.sin()));
            let plane = SurfaceParams::Plane {
                normal,
                offset: dot(normal, at),
            };
            // A point of both: along a generator from the apex, where it crosses the plane.
            let g = add(
                scale(d, 30f64.to_radians().cos()),
                scale(cross(d, across), 30f64.to_radians().sin()),
            );
            let start = add(apex, scale(g, dot(normal, sub(at, apex)) / dot(normal, g)));
            let curve = analytic_curve(&plane, &cone, start, start, 100.0);
            if !ellipse {
                assert!(curve.is_none(), "{curve:?}");
                continue;
            }
            let curve = curve.expect("a curve");
            assert_eq!(curve.name(), "ellipse", "{curve:?}");
            let conic = curve.conic().expect("conic");
            assert!(conic.3 >= conic.4, "{conic:?}");
            for i in 0..32 {
                let p = super::super::conic_point(conic, i as f64 * 0.2);
                assert!(signed_distance(&plane, p).abs() < 1e-13, "{p:?}");
                assert!(signed_distance(&cone, p).abs() < 1e-13, "{tilt}: {p:?}");
            }
            assert!(curve.distance(start) < 1e-13);
        }
    }

    #[test]
    fn an_oblique_plane_cuts_a_cylinder_in_an_ellipse_on_both() {
        // The plane z = 1 + tan 40° (x − 0.2) across the cylinder of radius 0.5 about the
        // vertical line through (0.2, −0.1).
        let tilt = 40f64.to_radians();
        let normal = [-tilt.sin(), 0.0, tilt.cos()];
        let plane = SurfaceParams::Plane {
            normal,
            offset: dot(normal, [0.2, -0.1, 1.0]),
        };
        let cylinder = SurfaceParams::Cylinder {
            axis_point: [0.2, -0.1, -3.0],
            axis_dir: [0.0, 0.0, 1.0],
            radius: 0.5,
        };
        let start = [0.7, -0.1, 1.0 + 0.5 * tilt.tan()];
        let curve = analytic_curve(&cylinder, &plane, start, start, 10.0).expect("a curve");
        let Some((center, _, _, a, b)) = curve.conic() else {
            panic!("an ellipse expected, got {curve:?}");
        };
        assert_eq!(curve.name(), "ellipse");
        assert!(dist(center, [0.2, -0.1, 1.0]) < 1e-15);
        assert!((a - 0.5 / tilt.cos()).abs() < 1e-15 && (b - 0.5).abs() < 1e-15);
        // Every point of it on both surfaces, and at distance 0 from it.
        for i in 0..32 {
            let p = super::super::conic_point(curve.conic().expect("conic"), i as f64 * 0.2);
            assert!(signed_distance(&plane, p).abs() < 1e-14, "{p:?}");
            assert!(signed_distance(&cylinder, p).abs() < 1e-14, "{p:?}");
            assert!(curve.distance(p) < 1e-12, "{p:?}");
        }
        // The distance from points off it: the nearest of a fine sampling.
        for q in [
            [0.2, -0.1, 1.0],
            [1.3, 0.4, 2.0],
            [0.25, 0.45, 0.9],
            [-0.5, -0.1, 0.2],
        ] {
            let near = (0..200_000)
                .map(|i| {
                    let t = i as f64 * std::f64::consts::TAU / 200_000.0;
                    dist(
                        q,
                        super::super::conic_point(curve.conic().expect("conic"), t),
                    )
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                (curve.distance(q) - near).abs() < 1e-9,
                "{q:?}: {} against {near}",
                curve.distance(q)
            );
        }
    }
}
