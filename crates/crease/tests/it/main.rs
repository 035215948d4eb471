//! The library's integration tests, linked into one binary: one module per area (they were one
//! binary each, and each linked the whole crate). `common` holds the shared helpers.
//!
//! Run one module with a filter, e.g. `cargo test -p crease --test it sharp::`.

mod common;

mod analysis;
mod architecture;
mod brep;
mod curvature;
mod eval;
mod fillets;
mod fuzz_found;
mod io_pcd_las_e57;
mod io_ply;
mod io_text_formats;
mod lines;
mod mesh_topology;
mod meshfeat;
mod meshfeat_filtered;
mod meshfeat_learned;
mod network;
mod noise;
mod normals;
mod render;
mod ring;
mod segment;
mod segment_points;
mod sharp;
mod sharp_tiled;
mod spatial_knn;
mod synth;
