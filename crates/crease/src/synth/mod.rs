//! Synthetic CAD parts with exact ground truth: the test bed of every detector in crease.
//!
//! A [`Shape`] (cube, box with a hole, two intersecting cylinders, rounded cube, block with
//! fillet / chamfer / cone, and the single primitives plane, cylinder, cone, sphere, torus) is
//! described exactly as trimmed analytic surface patches ([`Surface`]) and feature curves
//! ([`FeatureCurve`]: sharp creases, smooth tangent-continuous borders, open boundaries).
//! [`sample_points`] draws a point cloud uniformly over the area with optional Gaussian noise and
//! uniform outliers; [`mesh`] tessellates the shape with vertices on the feature curves. Both
//! write per-point ground truth as attributes with fixed names:
//!
//! | attribute            | kind | meaning                                                         |
//! |----------------------|------|-----------------------------------------------------------------|
//! | `gt_edge_distance`   | F32  | exact distance from the true (noise-free) position to the nearest sharp curve (`f32::MAX` if the shape has none) |
//! | `gt_sharp`           | U8   | `gt_edge_distance <= sharp_tolerance` (0 for outliers)          |
//! | `gt_smooth_distance` | F32  | same for the nearest smooth curve                               |
//! | `gt_smooth`          | U8   | `gt_smooth_distance <= sharp_tolerance` (0 for outliers)        |
//! | `gt_sharp_curve`     | I32  | index in `curves` of the nearest sharp curve, -1 if none        |
//! | `gt_smooth_curve`    | I32  | index in `curves` of the nearest smooth curve, -1 if none       |
//! | `gt_surface`         | I32  | surface id (index in `surfaces`), -1 for outliers               |
//! | `gt_surface_type`    | U8   | [`SurfaceType`](crate::geometry::SurfaceType) code, 255 for outliers                          |
//! | `gt_outlier`         | U8   | 1 for outliers                                                  |
//!
//! For outliers the distances are measured from the outlier's own position. Normals are the
//! exact outward unit normals of the analytic surface at the true position (noise does not
//! change them); outliers get the zero vector.

mod mesh;
mod sample;
mod shapes;
mod surfaces;
mod trimmed;
mod truth;

use serde::Serialize;

pub use mesh::{mesh, training_meshes, MeshParams, SyntheticMesh};
pub use sample::{sample_points, SampleParams, SyntheticPart};
pub use shapes::{two_cylinders_curve_length, Shape};
pub use surfaces::Surface;
pub use truth::{arc_distance, segment_distance, CurveGeometry, CurveKind, FeatureCurve};

/// Gaussian noise added to the positions; the value is the standard deviation sigma, relative
/// to the [`NoiseScale`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "type", content = "sigma", rename_all = "snake_case")]
pub enum Noise {
    /// No noise.
    None,
    /// Displacement along the exact normal, N(0, sigma²).
    AlongNormal(f64),
    /// Isotropic displacement, N(0, sigma²) on each coordinate.
    Isotropic(f64),
}

impl Noise {
    /// The relative sigma (0 for `None`).
    pub fn sigma(&self) -> f64 {
        match *self {
            Noise::None => 0.0,
            Noise::AlongNormal(s) | Noise::Isotropic(s) => s,
        }
    }
}

/// What a noise sigma is relative to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseScale {
    /// The expected point spacing (points) or the mean edge length (meshes), as in Tran et
    /// al. (noise of 1–5 % of the average distance between points).
    Spacing,
    /// The diagonal of the shape's bounding box.
    BoundingBox,
}

/// The per-element ground-truth attribute names (see the module documentation).
pub use crate::geometry::names::gt as attr;
