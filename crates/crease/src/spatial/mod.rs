//! Spatial queries: nearest neighbours over point sets.

mod kdtree;

pub use kdtree::KdIndex;
