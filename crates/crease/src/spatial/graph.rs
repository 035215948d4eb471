//! Vertex adjacency shared by meshes and point clouds: the mesh edges of a
//! [`crate::geometry::MeshTopology`], or an undirected neighbour graph stored as
//! [`Csr`] rows (e.g. the symmetrised k-nearest-neighbour graph of a cloud,
//! [`Csr::symmetrized`]). Algorithms written over [`Adjacency`] (k-rings, the Bézier / quadric
//! fit regions of `estimate::bezier`, the seeds and region growing of `segment`) run unchanged
//! on both.

use crate::geometry::{Csr, MeshTopology};

/// An undirected graph over `num_nodes()` vertices.
pub trait Adjacency: Sync {
    /// Number of vertices.
    fn num_nodes(&self) -> usize;
    /// Calls `f` with every neighbour of `v` (in a fixed order; panics if `v` is out of range).
    fn for_each_neighbor<F: FnMut(u32)>(&self, v: usize, f: F);
}

impl Adjacency for MeshTopology {
    fn num_nodes(&self) -> usize {
        self.num_vertices()
    }

    #[inline]
    fn for_each_neighbor<F: FnMut(u32)>(&self, v: usize, f: F) {
        self.neighbors(v).for_each(f)
    }
}

impl Adjacency for Csr {
    fn num_nodes(&self) -> usize {
        self.num_rows()
    }

    #[inline]
    fn for_each_neighbor<F: FnMut(u32)>(&self, v: usize, f: F) {
        self.row(v).iter().copied().for_each(f)
    }
}
