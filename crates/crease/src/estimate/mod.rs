//! Estimators every detector stands on: local planes, normals and curvature.

pub mod bezier;
pub mod curvature;
pub mod plane;

pub use plane::{fit_plane, Plane};
