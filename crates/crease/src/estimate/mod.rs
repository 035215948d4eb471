//! Estimators every detector stands on: local planes, normals and curvature.

pub mod bezier;
pub mod curvature;
pub mod plane;
pub mod ring_normal;

pub use plane::{fit_plane, Plane};
pub use ring_normal::ring_normals;
