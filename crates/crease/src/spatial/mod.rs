//! Spatial queries: nearest neighbours over point sets, local Delaunay 1-rings, mesh k-rings.

mod kdtree;
pub mod knn;
pub mod mesh_rings;
pub mod ring;

pub use kdtree::KdIndex;
pub use knn::{knn, Neighborhoods};
pub use ring::{delaunay_rings, RingParams, Rings};
