//! Analytic surfaces and trimmed surface patches of the synthetic parts.
//!
//! A synthetic part is a set of *patches*: a piece of one analytic surface (plane, cylinder,
//! cone, sphere, torus) given by an area-correct parametric domain (a rectangle in the plane, an
//! angle × height strip on a cylinder, an angle × slant strip on a cone, a whole sphere or one
//! octant of it, a whole torus) and an optional trim (a planar region made of a polygon and
//! disks, or "outside another cylinder"). Uniform sampling of a patch draws a uniform point of
//! the domain and rejects it when the trim removes it, so the accepted points are uniform over
//! the trimmed patch. Every patch carries its exact (trimmed) area, computed in closed form or by
//! exponentially convergent quadrature where no closed form exists (cylinder–cylinder trims).

use rand::Rng;
use rand_distr::StandardNormal;
use serde::Serialize;

use crate::geometry::vec3::{add, cross, dot, normalize, scale, sub};
use crate::geometry::{Point3, SurfaceParams, SurfaceType};

/// One analytic surface patch of a synthetic part (a B-rep face).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Surface {
    /// Surface id: the index of the patch in the part's surface list (`gt_surface` values).
    pub id: u32,
    /// Type of the surface (`gt_surface_type` code).
    pub kind: SurfaceType,
    /// Parameters of the underlying analytic surface.
    pub params: SurfaceParams,
    /// Exact area of the trimmed patch.
    pub area: f64,
}

/// A planar region in a plane patch's 2D coordinates: `(polygon ∪ disks) \ holes`. With no
/// polygon and no disks the whole domain rectangle is inside (minus the holes).
#[derive(Debug, Clone, Default)]
pub(crate) struct Region2 {
    pub polygon: Option<Vec<[f64; 2]>>,
    pub disks: Vec<([f64; 2], f64)>,
    pub holes: Vec<([f64; 2], f64)>,
}

impl Region2 {
    pub fn contains(&self, q: [f64; 2]) -> bool {
        let in_disk = |&(c, r): &([f64; 2], f64)| {
            let (dx, dy) = (q[0] - c[0], q[1] - c[1]);
            dx * dx + dy * dy < r * r
        };
        if self.holes.iter().any(in_disk) {
            return false;
        }
        if self.polygon.is_none() && self.disks.is_empty() {
            return true;
        }
        self.polygon
            .as_ref()
            .is_some_and(|poly| point_in_polygon(poly, q))
            || self.disks.iter().any(in_disk)
    }
}

/// Even-odd point-in-polygon test.
pub(crate) fn point_in_polygon(poly: &[[f64; 2]], q: [f64; 2]) -> bool {
    let mut inside = false;
    let n = poly.len();
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > q[1]) != (b[1] > q[1]) {
            let x = a[0] + (q[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if q[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// The untrimmed, area-parametrised domain of a patch.
#[derive(Debug, Clone)]
pub(crate) enum Domain {
    /// `origin + s u + t v`, s in [s0, s1], t in [t0, t1]; `normal` is the outward normal.
    Plane {
        origin: Point3,
        u: Point3,
        v: Point3,
        s: [f64; 2],
        t: [f64; 2],
        normal: Point3,
    },
    /// `center + h axis + radius (cos θ e1 + sin θ e2)`, θ in [theta0, theta0 + sweep],
    /// h in [h0, h1]. Normal points away from the axis, or towards it if `inward`.
    Cylinder {
        center: Point3,
        axis: Point3,
        e1: Point3,
        e2: Point3,
        radius: f64,
        theta0: f64,
        sweep: f64,
        h: [f64; 2],
        inward: bool,
    },
    /// `apex + l (cos α axis + sin α (cos θ e1 + sin θ e2))`, slant distance l in [l0, l1].
    Cone {
        apex: Point3,
        axis: Point3,
        e1: Point3,
        e2: Point3,
        half_angle: f64,
        theta0: f64,
        sweep: f64,
        l: [f64; 2],
    },
    /// A whole sphere, or the octant whose coordinate signs are `octant`.
    Sphere {
        center: Point3,
        radius: f64,
        octant: Option<[f64; 3]>,
    },
    /// A whole torus.
    Torus {
        center: Point3,
        axis: Point3,
        e1: Point3,
        e2: Point3,
        major: f64,
        minor: f64,
    },
}

/// What removes parts of a patch's domain.
#[derive(Debug, Clone)]
pub(crate) enum Trim {
    None,
    /// Plane patches: keep the 2D coordinates inside the region.
    Region(Region2),
    /// Keep the points strictly outside the solid cylinder.
    OutsideCylinder {
        axis_point: Point3,
        axis_dir: Point3,
        radius: f64,
    },
}

/// A trimmed patch: surface description, domain and trim.
#[derive(Debug, Clone)]
pub(crate) struct Patch {
    pub surface: Surface,
    pub domain: Domain,
    pub trim: Trim,
}

impl Domain {
    /// Area of the untrimmed domain.
    pub fn area(&self) -> f64 {
        match *self {
            Domain::Plane { s, t, .. } => (s[1] - s[0]) * (t[1] - t[0]),
            Domain::Cylinder {
                radius, sweep, h, ..
            } => radius * sweep * (h[1] - h[0]),
            Domain::Cone {
                half_angle,
                sweep,
                l,
                ..
            } => 0.5 * sweep * half_angle.sin() * (l[1] * l[1] - l[0] * l[0]),
            Domain::Sphere { radius, octant, .. } => {
                let full = 4.0 * std::f64::consts::PI * radius * radius;
                if octant.is_some() {
                    full / 8.0
                } else {
                    full
                }
            }
            Domain::Torus { major, minor, .. } => {
                4.0 * std::f64::consts::PI * std::f64::consts::PI * major * minor
            }
        }
    }

    /// A uniform random point of the domain with its outward unit normal and, for planes, its
    /// 2D coordinates.
    pub fn sample<R: Rng>(&self, rng: &mut R) -> (Point3, Point3, [f64; 2]) {
        match *self {
            Domain::Plane {
                origin,
                u,
                v,
                s,
                t,
                normal,
            } => {
                let a = s[0] + rng.random::<f64>() * (s[1] - s[0]);
                let b = t[0] + rng.random::<f64>() * (t[1] - t[0]);
                (plane_point(origin, u, v, a, b), normal, [a, b])
            }
            Domain::Cylinder {
                center,
                axis,
                e1,
                e2,
                radius,
                theta0,
                sweep,
                h,
                inward,
            } => {
                let th = theta0 + rng.random::<f64>() * sweep;
                let hh = h[0] + rng.random::<f64>() * (h[1] - h[0]);
                cylinder_point(center, axis, e1, e2, radius, th, hh, inward)
            }
            Domain::Cone {
                apex,
                axis,
                e1,
                e2,
                half_angle,
                theta0,
                sweep,
                l,
            } => {
                let th = theta0 + rng.random::<f64>() * sweep;
                let ll = (l[0] * l[0] + rng.random::<f64>() * (l[1] * l[1] - l[0] * l[0])).sqrt();
                cone_point(apex, axis, e1, e2, half_angle, th, ll)
            }
            Domain::Sphere {
                center,
                radius,
                octant,
            } => {
                let d = loop {
                    let g: Point3 = [
                        rng.sample(StandardNormal),
                        rng.sample(StandardNormal),
                        rng.sample(StandardNormal),
                    ];
                    if let Some(d) = normalize(g) {
                        break d;
                    }
                };
                let d = match octant {
                    Some(sg) => [d[0].abs() * sg[0], d[1].abs() * sg[1], d[2].abs() * sg[2]],
                    None => d,
                };
                (add(center, scale(d, radius)), d, [0.0; 2])
            }
            Domain::Torus {
                center,
                axis,
                e1,
                e2,
                major,
                minor,
            } => {
                let th = rng.random::<f64>() * std::f64::consts::TAU;
                // Area element (R + r cos φ) dθ dφ: rejection on φ.
                let ph = loop {
                    let ph = rng.random::<f64>() * std::f64::consts::TAU;
                    if rng.random::<f64>() * (major + minor) <= major + minor * ph.cos() {
                        break ph;
                    }
                };
                torus_point(center, axis, e1, e2, major, minor, th, ph)
            }
        }
    }
}

impl Trim {
    /// True if the trim keeps the domain point (`q` = 2D plane coordinates).
    pub fn keeps(&self, p: Point3, q: [f64; 2]) -> bool {
        match self {
            Trim::None => true,
            Trim::Region(r) => r.contains(q),
            Trim::OutsideCylinder {
                axis_point,
                axis_dir,
                radius,
            } => {
                let v = sub(p, *axis_point);
                let a = dot(v, *axis_dir);
                dot(v, v) - a * a >= radius * radius
            }
        }
    }
}

/// `origin + a u + b v`.
#[inline]
pub(crate) fn plane_point(origin: Point3, u: Point3, v: Point3, a: f64, b: f64) -> Point3 {
    add(origin, add(scale(u, a), scale(v, b)))
}

/// Point and normal of a cylinder at angle `th`, height `h`.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn cylinder_point(
    center: Point3,
    axis: Point3,
    e1: Point3,
    e2: Point3,
    radius: f64,
    th: f64,
    h: f64,
    inward: bool,
) -> (Point3, Point3, [f64; 2]) {
    let (s, c) = th.sin_cos();
    let radial = add(scale(e1, c), scale(e2, s));
    let p = add(center, add(scale(axis, h), scale(radial, radius)));
    let n = if inward { scale(radial, -1.0) } else { radial };
    (p, n, [th, h])
}

/// Point and outward normal of a cone at angle `th`, slant distance `l` from the apex.
#[inline]
pub(crate) fn cone_point(
    apex: Point3,
    axis: Point3,
    e1: Point3,
    e2: Point3,
    half_angle: f64,
    th: f64,
    l: f64,
) -> (Point3, Point3, [f64; 2]) {
    let (s, c) = th.sin_cos();
    let radial = add(scale(e1, c), scale(e2, s));
    let (sa, ca) = half_angle.sin_cos();
    let gen = add(scale(axis, ca), scale(radial, sa));
    let n = sub(scale(radial, ca), scale(axis, sa));
    (add(apex, scale(gen, l)), n, [th, l])
}

/// Point and outward normal of a torus at angles `th` (around the axis) and `ph` (around the
/// tube).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(crate) fn torus_point(
    center: Point3,
    axis: Point3,
    e1: Point3,
    e2: Point3,
    major: f64,
    minor: f64,
    th: f64,
    ph: f64,
) -> (Point3, Point3, [f64; 2]) {
    let (s, c) = th.sin_cos();
    let radial = add(scale(e1, c), scale(e2, s));
    let (sp, cp) = ph.sin_cos();
    let n = add(scale(radial, cp), scale(axis, sp));
    let p = add(center, add(scale(radial, major), scale(n, minor)));
    (p, n, [th, ph])
}

/// Two unit vectors completing `axis` to an orthonormal right-handed frame (e1, e2, axis).
pub(crate) fn frame(axis: Point3) -> (Point3, Point3) {
    let helper = if axis[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let e1 = normalize(cross(helper, axis)).unwrap_or([1.0, 0.0, 0.0]);
    let e2 = cross(axis, e1);
    (e1, e2)
}
