//! Spatial queries: nearest neighbours over point sets, local Delaunay 1-rings, mesh k-rings.

pub mod graph;
mod grid;
mod kdtree;
pub mod knn;
pub mod mesh_rings;
pub mod morton;
pub mod radius;
pub mod ring;
pub mod spacing;

pub use graph::Adjacency;
pub use kdtree::KdIndex;
pub use knn::{
    check_extent, check_shape, knn, knn_map, knn_map_set, knn_map_set_unzip, knn_with, KnnMethod,
    KnnQuery, Neighborhoods,
};
pub use morton::{distinct_in_input_order, gather, morton_order, morton_order_unique, Distinct};
pub use radius::{knn_within, radius_neighbors};
pub use ring::{delaunay_rings, RingParams, Rings};
pub use spacing::{average_spacing, average_spacing_with};
