//! # crease
//!
//! Finds the feature lines of scanned man-made objects: sharp edges and fillet edges as closed
//! polylines, per-point / per-edge feature labels, and a segmentation into analytic surfaces.
//!
//! ```text
//! file ──io──▶ PointCloud / TriMesh ──spatial──▶ neighbourhoods ──estimate──▶ normals, curvature
//!                                                      │
//!          sharp · lines · fillets · meshfeat · segment ◀┘ ──▶ eval · io · render
//! use crease::synth::{Shape, SampleParams};
//! let part = crease::synth::sample_points(&Shape::default_cube(), &SampleParams { n: 2000, ..Default::default() }).unwrap();
//! let spacing = crease::geometry::average_spacing(&part.cloud.positions).unwrap();
//! assert!(spacing > 0.0);
