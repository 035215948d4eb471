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
