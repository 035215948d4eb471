//! Estimators every detector stands on: normals and curvature.

pub mod bezier;
pub mod curvature;
pub mod noise;
pub mod normals;
pub mod orient;
pub mod ring_normal;

pub use normals::{
    estimate_normals, mesh_vertex_normals, pca_normals, pca_normals_direct, PcaParams, PcaResult,
    PcaWeight, Weighting,
};
pub use orient::orient_normals;
pub use ring_normal::ring_normals;
