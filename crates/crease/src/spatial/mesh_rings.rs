//! Mesh neighbourhoods: vertex k-rings (tran section 2.2: "a k-ring neighborhood of a vertex
//! p_i is defined as a set of vertices that are connected to p_i by at most k edges") and the
//! ordered one-rings, which live in [`MeshTopology::one_ring`] and are re-exported here as
//! [`OneRing`] rather than duplicated.
//!
//! Also holds [`VertexSet`], the small open-addressing set of vertex ids the per-vertex
//! breadth-first searches (k-rings here, the distance-bounded fit regions of
//! `estimate::bezier`) use as per-thread scratch.

use rayon::prelude::*;

use super::Adjacency;
pub use crate::geometry::OneRing;
use crate::geometry::{Csr, MeshTopology};
use crate::{Error, Result};

/// The vertices within `k` edges of every vertex (the vertex itself excluded), as CSR rows of
/// `V` rows: sorted by ring distance (1-ring first), then by vertex id inside each ring.
///
/// Inputs: the mesh topology with `V` vertices; `k` ≥ 0 (tran uses k = 1..4; `k = 0` gives empty
/// rows). Non-manifold vertices and boundaries need no special care: the rings follow the
/// mesh edges.
/// Output: the CSR lists, identical whatever the thread count; `Error::InvalidInput` if the total
/// number of entries does not fit the 32-bit offsets.
///
/// Cost: per vertex, a breadth-first search over its k-ring with a small hash set; about
/// 3k(k + 1) entries per interior vertex of a regular triangulation.
pub fn vertex_k_rings(topo: &MeshTopology, k: usize) -> Result<Csr> {
    let nv = topo.num_vertices();
    let rows: Vec<Vec<u32>> = (0..nv)
        .into_par_iter()
        .map_init(
            || (VertexSet::default(), Vec::new()),
            |(set, layers), v| {
                k_ring_layers(topo, v as u32, k, set, layers);
                layers.clone()
            },
        )
        .collect();
    let total: usize = rows.iter().map(Vec::len).sum();
    if total >= u32::MAX as usize {
        return Err(Error::InvalidInput(format!(
            "{k}-rings of {nv} vertices hold {total} entries, more than 32-bit offsets allow"
        )));
    }
    let mut offsets = Vec::with_capacity(nv + 1);
    let mut indices = Vec::with_capacity(total);
    offsets.push(0u32);
    for r in rows {
        indices.extend_from_slice(&r);
        offsets.push(indices.len() as u32);
    }
    Ok(Csr { offsets, indices })
}

/// The k-ring of one vertex `v` into `out` (cleared first), sorted by ring distance then id,
/// `v` excluded; `set` is scratch. Panics if `v >= V`.
pub fn k_ring_layers(
    topo: &impl Adjacency,
    v: u32,
    k: usize,
    set: &mut VertexSet,
    out: &mut Vec<u32>,
) {
    k_ring_layers_with(topo, v, k, set, out, |_| {});
}

/// [`k_ring_layers`], calling `layer_end(len)` after each ring s = 1..=k is complete with the
/// number of entries of rings 1..=s (called k times, also when the rings run out early).
pub fn k_ring_layers_with(
    topo: &impl Adjacency,
    v: u32,
    k: usize,
    set: &mut VertexSet,
    out: &mut Vec<u32>,
    mut layer_end: impl FnMut(usize),
) {
    out.clear();
    set.clear();
    set.insert(v);
    if k == 0 {
        return;
    }
    topo.for_each_neighbor(v as usize, |n| {
        if set.insert(n) {
            out.push(n);
        }
    });
    out.sort_unstable();
    layer_end(out.len());
    let mut start = 0usize;
    for _ in 1..k {
        let end = out.len();
        for i in start..end {
            let u = out[i];
            topo.for_each_neighbor(u as usize, |n| {
                if set.insert(n) {
                    out.push(n);
                }
            });
        }
        out[end..].sort_unstable();
        layer_end(out.len());
        start = end;
    }
}

/// The k-rings of every vertex as in [`vertex_k_rings`], plus where each ring ends: entry
/// `ends[v * k + (s - 1)]` is the number of entries of vertex v's row that lie within s edges,
/// so the s-ring of v (s = 1..=k) is the first `ends[v * k + s - 1]` entries of its row.
///
/// Errors as [`vertex_k_rings`]; `k = 0` gives empty rows and no ends.
pub fn vertex_k_rings_layered(topo: &MeshTopology, k: usize) -> Result<(Csr, Vec<u32>)> {
    let nv = topo.num_vertices();
    let rows: Vec<(Vec<u32>, Vec<u32>)> = (0..nv)
        .into_par_iter()
        .map_init(
            || (VertexSet::default(), Vec::new()),
            |(set, layers), v| {
                let mut ends = Vec::with_capacity(k);
                k_ring_layers_with(topo, v as u32, k, set, layers, |e| ends.push(e as u32));
                (layers.clone(), ends)
            },
        )
        .collect();
    let total: usize = rows.iter().map(|r| r.0.len()).sum();
    if total >= u32::MAX as usize {
        return Err(Error::InvalidInput(format!(
            "{k}-rings of {nv} vertices hold {total} entries, more than 32-bit offsets allow"
        )));
    }
    let mut offsets = Vec::with_capacity(nv + 1);
    let mut indices = Vec::with_capacity(total);
    let mut ends = Vec::with_capacity(nv * k);
    offsets.push(0u32);
    for (r, e) in rows {
        indices.extend_from_slice(&r);
        offsets.push(indices.len() as u32);
        ends.extend_from_slice(&e);
    }
    Ok((Csr { offsets, indices }, ends))
}

/// A set of vertex ids (open addressing, linear probing) that clears in time proportional to
/// its size: per-thread scratch for breadth-first searches over a few hundred vertices.
#[derive(Debug, Clone)]
pub struct VertexSet {
    table: Vec<u32>,
    items: Vec<u32>,
}

const EMPTY: u32 = u32::MAX;

impl Default for VertexSet {
    fn default() -> Self {
        VertexSet {
            table: vec![EMPTY; 64],
            items: Vec::new(),
        }
    }
}

impl VertexSet {
    /// Removes every id.
    pub fn clear(&mut self) {
        for &x in &self.items {
            let mask = self.table.len() - 1;
            let mut h = hash(x) & mask;
            while self.table[h] != x {
                h = (h + 1) & mask;
            }
            self.table[h] = EMPTY;
        }
        self.items.clear();
    }

    /// Number of ids.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True if empty.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// True if `x` is in the set.
    pub fn contains(&self, x: u32) -> bool {
        let mask = self.table.len() - 1;
        let mut h = hash(x) & mask;
        loop {
            match self.table[h] {
                EMPTY => return false,
                y if y == x => return true,
                _ => h = (h + 1) & mask,
            }
        }
    }

    /// Inserts `x` (not `u32::MAX`); true if it was not there yet.
    pub fn insert(&mut self, x: u32) -> bool {
        debug_assert_ne!(x, EMPTY);
        if 2 * (self.items.len() + 1) > self.table.len() {
            self.grow();
        }
        let mask = self.table.len() - 1;
        let mut h = hash(x) & mask;
        loop {
            match self.table[h] {
                EMPTY => {
                    self.table[h] = x;
                    self.items.push(x);
                    return true;
                }
                y if y == x => return false,
                _ => h = (h + 1) & mask,
            }
        }
    }

    fn grow(&mut self) {
        let n = self.table.len() * 2;
        self.table = vec![EMPTY; n];
        let mask = n - 1;
        for &x in &self.items {
            let mut h = hash(x) & mask;
            while self.table[h] != EMPTY {
                h = (h + 1) & mask;
            }
            self.table[h] = x;
        }
    }
}

#[inline]
fn hash(x: u32) -> usize {
    (x.wrapping_mul(0x9E37_79B9) >> 8) as usize
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_set_inserts_and_clears() {
        let mut s = VertexSet::default();
        for i in 0..1000u32 {
            assert!(s.insert(i * 7));
            assert!(!s.insert(i * 7));
        }
        assert_eq!(s.len(), 1000);
        assert!(s.contains(7 * 999));
        assert!(!s.contains(3));
        s.clear();
        assert!(s.is_empty());
        assert!(!s.contains(7));
        assert!(s.insert(7));
    }
}
