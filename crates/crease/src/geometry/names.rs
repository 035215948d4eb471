//! The names of the per-element attributes crease writes and reads, typed once. Other tools
//! read these PLY properties (see the design's conventions); every writer and reader in the
//! library and the command line uses these constants.

/// Sharp feature flag (U8 0 / 1), per point, vertex or edge.
pub const SHARP: &str = "sharp";
/// Continuous sharpness score (F32): sharp exactly when ≥ 1 for points; per-edge score for edges.
pub const SHARPNESS: &str = "sharpness";
/// Analytic surface id (I32, -1 when unassigned), per point or face.
pub const SURFACE: &str = "surface";
/// Analytic surface type code (U8: plane 0, cylinder 1, cone 2, sphere 3, torus 4, 255 none).
pub const SURFACE_TYPE: &str = "surface_type";
/// First-order cluster of the sharp-line pipeline (I32).
pub const CLUSTER: &str = "cluster";
/// Fillet label (U8: 0 low, 1 inner, 2 border, 3 noisy, 255 outside the smooth regions).
pub const FILLET_LABEL: &str = "fillet_label";
/// On a fillet border (U8 0 / 1).
pub const SMOOTH_EDGE: &str = "smooth_edge";
/// Curvature patch of the fillet pipeline (U8, 255 outside).
pub const PATCH: &str = "patch";
/// Smooth region of the fillet pipeline (I32, -1 outside).
pub const REGION: &str = "region";
/// Signed mean curvature (F32).
pub const MEAN_CURVATURE: &str = "mean_curvature";
/// Principal curvatures (F32).
pub const K1: &str = "k1";
/// Principal curvatures (F32).
pub const K2: &str = "k2";
/// Gaussian curvature (F32).
pub const GAUSSIAN_CURVATURE: &str = "gaussian_curvature";
/// On a smooth (fillet) line rather than a sharp one (U8 0 / 1), per network vertex.
pub const SMOOTH: &str = "smooth";
/// The polyline groups of a curve network (OBJ `g`): sharp lines ([`SHARP`]), smooth (fillet)
/// lines ([`SMOOTH`]) and the cloud's open border.
pub const BOUNDARY: &str = "boundary";

/// Ground truth, as the synthetic parts ([`crate::synth`]) write it.
pub mod gt {
    /// Exact distance to the nearest sharp curve (F32).
    pub const EDGE_DISTANCE: &str = "gt_edge_distance";
    /// Sharp label (U8).
    pub const SHARP: &str = "gt_sharp";
    /// Exact distance to the nearest smooth curve (F32).
    pub const SMOOTH_DISTANCE: &str = "gt_smooth_distance";
    /// Smooth label (U8).
    pub const SMOOTH: &str = "gt_smooth";
    /// Index of the nearest sharp curve (I32, -1 if none).
    pub const SHARP_CURVE: &str = "gt_sharp_curve";
    /// Index of the nearest smooth curve (I32, -1 if none).
    pub const SMOOTH_CURVE: &str = "gt_smooth_curve";
    /// Surface id (I32, -1 for outliers).
    pub const SURFACE: &str = "gt_surface";
    /// Surface type code (U8, 255 for outliers).
    pub const SURFACE_TYPE: &str = "gt_surface_type";
    /// Outlier flag (U8).
    pub const OUTLIER: &str = "gt_outlier";
}
