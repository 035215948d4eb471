//! # crease
//!
//! Finds the feature lines of scanned man-made objects: sharp edges and fillet edges as closed
//! polylines, per-point / per-edge feature labels, and a segmentation into analytic surfaces.
//!
//! ```text
//! file ──io──▶ PointCloud / TriMesh ──spatial──▶ neighbourhoods ──estimate──▶ normals, curvature
//!                                                      │
//!          sharp · lines · fillets · meshfeat · segment ◀┘ ──▶ eval · io · render
//! ```
//!
//! Each stage is a plain function: inputs and a `Params` struct in, a result struct out.

pub mod analysis;
pub mod brep;
pub mod error;
pub mod estimate;
pub mod eval;
pub mod fillets;
pub mod geometry;
pub mod graphcut;
pub mod io;
pub mod lines;
pub mod meshfeat;
pub mod network;
pub mod pipeline;
pub mod render;
pub mod segment;
pub mod sharp;
pub mod spatial;
pub mod synth;
pub mod threshold;

pub use error::{Error, Result};
pub use geometry::{Aabb, Attribute, PointCloud, TriMesh};
pub use io::Geometry;

/// The README's Rust examples, compiled as doc tests so they stay true.
#[doc = include_str!("../../../README.md")]
#[cfg(doctest)]
pub struct ReadmeDoctests;
