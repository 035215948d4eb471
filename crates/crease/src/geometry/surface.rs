//! Analytic surfaces: the five types crease fits and writes (plane, cylinder, cone, sphere,
//! torus), their parameters, and the orthogonal distance and normal of a point against them.
//! Shared by the detectors (segmentation, surface-anchored sharp points and edges) and the
//! synthetic parts' ground truth.

use serde::Serialize;

use crate::geometry::vec3::{add, dot, norm, normalize, scale, sub};
use crate::geometry::Point3;

/// Type of an analytic surface. The discriminants are the `surface_type` (PLY `uchar`) codes
/// crease writes everywhere (`gt_surface_type`, `surface_type`): plane 0, cylinder 1, cone 2,
/// sphere 3, torus 4, and 255 for "none / other" (outliers, unsegmented points).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[repr(u8)]
pub enum SurfaceType {
    /// A plane.
    Plane = 0,
    /// A circular cylinder.
    Cylinder = 1,
    /// A circular cone.
    Cone = 2,
    /// A sphere.
    Sphere = 3,
    /// A torus.
    Torus = 4,
    /// No analytic surface (outliers, unknown). Code 255.
    Other = 255,
}

impl SurfaceType {
    /// The `surface_type` code (see the type's documentation).
    pub fn code(self) -> u8 {
        self as u8
    }

    /// The type of a code, `None` for an unknown code.
    pub fn from_code(code: u8) -> Option<SurfaceType> {
        Some(match code {
            0 => SurfaceType::Plane,
            1 => SurfaceType::Cylinder,
            2 => SurfaceType::Cone,
            3 => SurfaceType::Sphere,
            4 => SurfaceType::Torus,
            255 => SurfaceType::Other,
            _ => return None,
        })
    }

    /// Lower-case name (`plane`, `cylinder`, ...).
    pub fn name(self) -> &'static str {
        match self {
            SurfaceType::Plane => "plane",
            SurfaceType::Cylinder => "cylinder",
            SurfaceType::Cone => "cone",
            SurfaceType::Sphere => "sphere",
            SurfaceType::Torus => "torus",
            SurfaceType::Other => "other",
        }
    }
}

/// Parameters of an analytic surface (untrimmed). Directions are unit vectors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum SurfaceParams {
    /// The plane `normal · x = offset`; `normal` is the outward normal of the patch.
    Plane {
        /// Unit normal (outward).
        normal: Point3,
        /// Signed offset `d` in `n · x = d`.
        offset: f64,
    },
    /// Points at distance `radius` from the axis line.
    Cylinder {
        /// A point on the axis.
        axis_point: Point3,
        /// Unit axis direction.
        axis_dir: Point3,
        /// Radius.
        radius: f64,
    },
    /// Points whose direction from `apex` makes the angle `half_angle` with `axis_dir`
    /// (`axis_dir` points from the apex into the nappe that holds the patch).
    Cone {
        /// The apex.
        apex: Point3,
        /// Unit axis direction, from the apex towards the patch.
        axis_dir: Point3,
        /// Half opening angle in radians, in (0, π/2).
        half_angle: f64,
    },
    /// A sphere.
    Sphere {
        /// Centre.
        center: Point3,
        /// Radius.
        radius: f64,
    },
    /// A ring torus: the circle of radius `minor_radius` swept around the axis at distance
    /// `major_radius`.
    Torus {
        /// Centre.
        center: Point3,
        /// Unit axis direction.
        axis_dir: Point3,
        /// Distance from the axis to the centre of the tube.
        major_radius: f64,
        /// Radius of the tube.
        minor_radius: f64,
    },
}

impl SurfaceParams {
    /// The axis of a cylinder, cone or torus: a point on it (the axis point, the apex, the
    /// centre) and its unit direction; none for a plane or a sphere.
    pub fn axis(&self) -> Option<(Point3, Point3)> {
        match *self {
            SurfaceParams::Cylinder {
                axis_point,
                axis_dir,
                ..
            } => Some((axis_point, axis_dir)),
            SurfaceParams::Cone { apex, axis_dir, .. } => Some((apex, axis_dir)),
            SurfaceParams::Torus {
                center, axis_dir, ..
            } => Some((center, axis_dir)),
            _ => None,
        }
    }

    /// The surface type of these parameters.
    pub fn kind(&self) -> SurfaceType {
        match self {
            SurfaceParams::Plane { .. } => SurfaceType::Plane,
            SurfaceParams::Cylinder { .. } => SurfaceType::Cylinder,
            SurfaceParams::Cone { .. } => SurfaceType::Cone,
            SurfaceParams::Sphere { .. } => SurfaceType::Sphere,
            SurfaceParams::Torus { .. } => SurfaceType::Torus,
        }
    }

    /// Unsigned Euclidean distance from `p` to the (untrimmed) surface. Exact for every type
    /// (the cone is treated as the single nappe `axis_dir` points into, for points not behind
    /// the apex).
    pub fn distance(&self, p: Point3) -> f64 {
        match *self {
            SurfaceParams::Plane { normal, offset } => (dot(normal, p) - offset).abs(),
            SurfaceParams::Cylinder {
                axis_point,
                axis_dir,
                radius,
            } => {
                let v = sub(p, axis_point);
                let along = dot(v, axis_dir);
                let radial = sub(v, scale(axis_dir, along));
                (dot(radial, radial).sqrt() - radius).abs()
            }
            SurfaceParams::Cone {
                apex,
                axis_dir,
                half_angle,
            } => {
                let v = sub(p, apex);
                let h = dot(v, axis_dir);
                let rho = dot(v, v) - h * h;
                let rho = rho.max(0.0).sqrt();
                // Rotate into the (rho, h) half-plane: the generator is the ray at angle
                // half_angle from the h axis.
                let (s, c) = half_angle.sin_cos();
                let along = rho * s + h * c;
                if along >= 0.0 {
                    (rho * c - h * s).abs()
                } else {
                    (rho * rho + h * h).sqrt()
                }
            }
            SurfaceParams::Sphere { center, radius } => {
                (crate::geometry::vec3::dist(p, center) - radius).abs()
            }
            SurfaceParams::Torus {
                center,
                axis_dir,
                major_radius,
                minor_radius,
            } => {
                let v = sub(p, center);
                let h = dot(v, axis_dir);
                let rho = (dot(v, v) - h * h).max(0.0).sqrt();
                ((rho - major_radius).hypot(h) - minor_radius).abs()
            }
        }
    }
}

/// Coordinates `[ρ, h]` of `p` in the meridian half-plane of the axis through `origin` along
/// the unit `dir`: distance from the axis and height along it.
pub fn meridian(p: Point3, origin: Point3, dir: Point3) -> [f64; 2] {
    let v = sub(p, origin);
    let h = dot(v, dir);
    [(dot(v, v) - h * h).max(0.0).sqrt(), h]
}

/// Signed orthogonal distance from `p` to the surface (positive on the side the surface's
/// normal of [`surface_normal`] points to). For the cone, the distance to the double cone's
/// generator line in the meridian half-plane (exact near the patch).
pub fn signed_distance(s: &SurfaceParams, p: Point3) -> f64 {
    match *s {
        SurfaceParams::Plane { normal, offset } => dot(normal, p) - offset,
        SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            radius,
        } => meridian(p, axis_point, axis_dir)[0] - radius,
        SurfaceParams::Sphere { center, radius } => norm(sub(p, center)) - radius,
        SurfaceParams::Cone {
            apex,
            axis_dir,
            half_angle,
        } => cone_distance(p, apex, axis_dir, half_angle.sin_cos()),
        SurfaceParams::Torus {
            center,
            axis_dir,
            major_radius,
            minor_radius,
        } => {
            let [rho, h] = meridian(p, center, axis_dir);
            (rho - major_radius).hypot(h) - minor_radius
        }
    }
}

/// Unit normal of the surface at the point nearest to `p` (outward for the closed types and
/// the cylinder, away from the axis for the cone). Zero where undefined (on the axis).
pub fn surface_normal(s: &SurfaceParams, p: Point3) -> Point3 {
    match *s {
        SurfaceParams::Plane { normal, .. } => normal,
        SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            ..
        } => radial(sub(p, axis_point), axis_dir).0,
        SurfaceParams::Sphere { center, .. } => normalize(sub(p, center)).unwrap_or([0.0; 3]),
        SurfaceParams::Cone {
            apex,
            axis_dir,
            half_angle,
        } => cone_normal(p, apex, axis_dir, half_angle.sin_cos()),
        SurfaceParams::Torus {
            center,
            axis_dir,
            major_radius,
            ..
        } => {
            let (u, rho, h) = radial(sub(p, center), axis_dir);
            normalize(add(scale(u, rho - major_radius), scale(axis_dir, h))).unwrap_or([0.0; 3])
        }
    }
}

/// Unit direction of `v` away from the axis along the unit `d`, its distance from the axis
/// and its height along it.
pub(crate) fn radial(v: Point3, d: Point3) -> (Point3, f64, f64) {
    let h = dot(v, d);
    let r = sub(v, scale(d, h));
    let rho = norm(r);
    (
        if rho > 0.0 {
            scale(r, 1.0 / rho)
        } else {
            [0.0; 3]
        },
        rho,
        h,
    )
}

/// The cone's signed distance with `(sin, cos)` of its half angle given.
#[inline]
fn cone_distance(p: Point3, apex: Point3, axis_dir: Point3, (s, c): (f64, f64)) -> f64 {
    let [rho, h] = meridian(p, apex, axis_dir);
    rho * c - h * s
}

/// The cone's normal with `(sin, cos)` of its half angle given.
#[inline]
fn cone_normal(p: Point3, apex: Point3, axis_dir: Point3, (s, c): (f64, f64)) -> Point3 {
    let (u, _, _) = radial(sub(p, apex), axis_dir);
    sub(scale(u, c), scale(axis_dir, s))
}

/// A surface with its per-surface constants computed once (the cone's sine and cosine of its
/// half angle), for loops over many points: [`Prepared::signed_distance`] equals
/// [`signed_distance`] and [`Prepared::normal`] [`surface_normal`] bit for bit. The per-point
/// `sin_cos` of the cone's distance was half the segmentation's time on a scan, in the
/// Levenberg–Marquardt refinements, which then evaluated every residual 2N + 1 times an
/// iteration (`docs/experiments/segmentation.md`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prepared {
    surface: SurfaceParams,
    sin: f64,
    cos: f64,
}

impl Prepared {
    /// Prepares `surface`.
    pub fn new(surface: &SurfaceParams) -> Prepared {
        let (sin, cos) = match *surface {
            SurfaceParams::Cone { half_angle, .. } => half_angle.sin_cos(),
            _ => (0.0, 1.0),
        };
        Prepared {
            surface: *surface,
            sin,
            cos,
        }
    }

    /// The surface.
    pub fn surface(&self) -> &SurfaceParams {
        &self.surface
    }

    /// [`signed_distance`] from `p`.
    #[inline]
    pub fn signed_distance(&self, p: Point3) -> f64 {
        match self.surface {
            SurfaceParams::Cone { apex, axis_dir, .. } => {
                cone_distance(p, apex, axis_dir, (self.sin, self.cos))
            }
            ref s => signed_distance(s, p),
        }
    }

    /// [`surface_normal`] at the point nearest to `p`.
    #[inline]
    pub fn normal(&self, p: Point3) -> Point3 {
        match self.surface {
            SurfaceParams::Cone { apex, axis_dir, .. } => {
                cone_normal(p, apex, axis_dir, (self.sin, self.cos))
            }
            ref s => surface_normal(s, p),
        }
    }
}
