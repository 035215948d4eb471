//! `TriMesh`: a triangle mesh whose vertices are a `PointCloud` (so per-vertex data travels
//! with them) plus faces with optional per-face attributes.

use super::{Attribute, Attributes, PointCloud};
use crate::{Error, Result};

/// A triangle mesh. Faces index `vertices.positions`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertices with their normals, colours and attributes.
    pub vertices: PointCloud,
    /// Triangles as vertex indices, counter-clockwise seen from outside when oriented.
    pub faces: Vec<[u32; 3]>,
    /// Named per-face attributes (`surface`, `surface_type`, ...).
    pub face_attributes: Attributes,
}

impl TriMesh {
    /// A mesh from bare positions and faces; fails if a face index is out of range.
    pub fn new(positions: Vec<[f64; 3]>, faces: Vec<[u32; 3]>) -> Result<Self> {
        let m = TriMesh {
            vertices: PointCloud::from_positions(positions),
            faces,
            face_attributes: Attributes::new(),
        };
        m.check_indices()?;
        Ok(m)
    }

    /// Vertex positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.vertices.positions
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.vertices.len()
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }

    /// Adds (or replaces) a per-face attribute.
    pub fn set_face_attribute(&mut self, attr: Attribute) -> Result<()> {
        let n = self.faces.len();
        self.face_attributes.insert(n, attr)
    }

    /// The three corner positions of face `f`.
    pub fn triangle(&self, f: usize) -> [[f64; 3]; 3] {
        let [a, b, c] = self.faces[f];
        let p = &self.vertices.positions;
        [p[a as usize], p[b as usize], p[c as usize]]
    }

    /// Fails with a message naming the first face whose index is out of range.
    pub fn check_indices(&self) -> Result<()> {
        let n = self.vertices.len();
        for (i, f) in self.faces.iter().enumerate() {
            if let Some(&v) = f.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidInput(format!(
                    "face {i} refers to vertex {v}, but the mesh has {n} vertices"
                )));
            }
        }
        Ok(())
    }
}
