//! Geometry: point clouds, triangle meshes with their edge topology, bounding boxes, planes, analytic surfaces.

mod aabb;
mod attribute;
pub mod cleanup;
mod csr;
mod mesh;
pub mod names;
pub(crate) mod normal_eq;
pub mod plane;
mod point_cloud;
pub mod polyline;
pub mod surface;
pub(crate) use point_cloud::retain_by;
pub mod topology;
pub(crate) mod union_find;
pub mod vec3;

pub use aabb::Aabb;
pub use attribute::{Attribute, Attributes, ScalarKind};
pub use cleanup::{clean_mesh, CleanupParams, CleanupReport};
pub use csr::Csr;
pub use mesh::TriMesh;
pub use plane::{fit_plane, Plane};
pub use point_cloud::{Point3, PointCloud};
pub use polyline::{chain_segments, network_counts, NetworkCounts};
pub use surface::{SurfaceParams, SurfaceType};
pub use topology::{
    face_area, face_areas, face_normal, face_normals, MeshTopology, OneRing, VertexKind,
};
