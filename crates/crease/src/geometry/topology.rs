//! Edge topology of a triangle mesh: the unique undirected edges, the face ↔ edge ↔ vertex
//! incidences (CSR), boundary / non-manifold / orientation checks, ordered one-rings (vertex
//! fans), dihedral angles, boundary loops, connected components and the Euler characteristic.
//!
//! Built once per mesh by [`MeshTopology::new`] in O(F) time plus small per-vertex sorts
//! (a counting sort of the half-edges by their lower endpoint, then parallel sorts inside each
//! vertex's bucket), so the results are identical whatever the thread count.
//!
//! Conventions (shared by every accessor):
//! - `V` vertices, `F` faces, `E` unique undirected edges.
//! - Side `i` of face `f = [c0, c1, c2]` joins corner `i` and corner `(i + 1) % 3`, so it goes
//!   `f[i] → f[(i + 1) % 3]` and lies opposite corner `(i + 2) % 3`.
//! - A side whose two corners are the same vertex (a face with a repeated index) is not an edge;
//!   its slot in [`MeshTopology::face_edges`] holds [`NO_EDGE`].
//! - An edge's "faces" are face sides: a face lying on an edge once appears once in its row.

use std::sync::atomic::{AtomicU32, Ordering};

use rayon::prelude::*;

use super::{vec3, Csr, Point3, TriMesh};
use crate::{Error, Result};

/// Marks a face side that is not an edge (both corners are the same vertex).
pub const NO_EDGE: u32 = u32::MAX;

/// What the faces around a vertex look like.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum VertexKind {
    /// No face uses the vertex.
    Isolated,
    /// The faces form one closed fan (a disk around the vertex).
    Interior,
    /// The faces form one open fan (a half-disk: the vertex is on the boundary).
    Boundary,
    /// Anything else: several fans (a "bowtie"), a non-manifold edge at the vertex, or a face
    /// with a repeated vertex index using it.
    NonManifold,
}

/// The ordered one-ring of a manifold vertex `v`.
///
/// `faces[j]` is the face between `neighbors[j]` and `neighbors[j + 1]` (indices modulo
/// `neighbors.len()` when `closed`). The order turns around `v` the way the faces are oriented:
/// in face `(v, a, b)` (up to rotation) `a` comes just before `b`, i.e. counter-clockwise seen
/// from outside for outward-oriented meshes. Closed fans start at the lowest-indexed face;
/// open fans start at the boundary neighbour whose face lists it right after `v`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OneRing<'a> {
    /// Neighbour vertices in fan order: `k` entries for a closed fan of `k` faces, `k + 1` for
    /// an open fan, none for an isolated vertex.
    pub neighbors: &'a [u32],
    /// The faces in fan order, `k` entries.
    pub faces: &'a [u32],
    /// True for a closed fan (interior vertex), false for an open fan (boundary vertex).
    pub closed: bool,
}

/// Edge topology of a triangle mesh. See the module documentation for the conventions.
///
/// Build it with [`MeshTopology::new`]. Every per-edge array is indexed by edge id, edges being
/// sorted lexicographically by `(v0, v1)` with `v0 < v1`; later stages write one row per edge in
/// this order.
#[derive(Debug, Clone, Default)]
pub struct MeshTopology {
    num_vertices: usize,
    faces: Vec<[u32; 3]>,
    edges: Vec<[u32; 2]>,
    /// Row `v`: the edges whose lower endpoint is `v` (a contiguous id range), `V + 1` entries.
    lower_offsets: Vec<u32>,
    face_edges: Vec<[u32; 3]>,
    edge_faces: Csr,
    /// Parallel to `edge_faces.indices`: the side of the face lying on the edge (0, 1, 2).
    edge_face_sides: Vec<u8>,
    /// Parallel to `edge_faces.indices`: true if the face side goes from the upper to the lower
    /// vertex of the edge.
    side_reversed: Vec<bool>,
    vertex_faces: Csr,
    vertex_edges: Csr,
    vertex_kinds: Vec<VertexKind>,
    rings: Csr,
    boundary_edges: Vec<u32>,
    non_manifold_edges: Vec<u32>,
    inconsistent_edges: Vec<u32>,
    non_manifold_vertices: Vec<u32>,
    degenerate_faces: Vec<u32>,
    face_normals: Vec<Point3>,
    dihedral: Vec<f64>,
    signed_dihedral: Vec<f64>,
    face_components: Vec<u32>,
    num_components: usize,
    num_boundary_loops: usize,
    num_referenced_vertices: usize,
}

/// The unit normal of face `f` of `mesh` (right-hand rule on its corner order), or `[0, 0, 0]`
/// for a face of zero (or non-finite) area.
///
/// Inputs: `mesh` with `V` vertices and `F` faces, `f < F` (panics otherwise).
/// Output: a unit 3-vector or zero.
pub fn face_normal(mesh: &TriMesh, f: usize) -> Point3 {
    let [a, b, c] = mesh.triangle(f);
    triangle_normal(a, b, c)
}

/// The area of face `f` of `mesh`.
///
/// Inputs: `mesh` with `V` vertices and `F` faces, `f < F` (panics otherwise).
/// Output: the area (0 for a degenerate face, NaN if a corner is not finite).
pub fn face_area(mesh: &TriMesh, f: usize) -> f64 {
    let [a, b, c] = mesh.triangle(f);
    triangle_area(a, b, c)
}

/// Unit normals of all faces (zero for degenerate faces), computed in parallel.
///
/// Inputs: `mesh` with `F` faces whose indices are in range (panics otherwise).
/// Output: `F` normals, in face order.
pub fn face_normals(mesh: &TriMesh) -> Vec<Point3> {
    let p = mesh.positions();
    mesh.faces
        .par_iter()
        .map(|&[a, b, c]| triangle_normal(p[a as usize], p[b as usize], p[c as usize]))
        .collect()
}

/// Areas of all faces, computed in parallel.
///
/// Inputs: `mesh` with `F` faces whose indices are in range (panics otherwise).
/// Output: `F` areas, in face order.
pub fn face_areas(mesh: &TriMesh) -> Vec<f64> {
    let p = mesh.positions();
    mesh.faces
        .par_iter()
        .map(|&[a, b, c]| triangle_area(p[a as usize], p[b as usize], p[c as usize]))
        .collect()
}

/// The unit normal of triangle `(a, b, c)` or zero if degenerate.
#[inline]
pub(crate) fn triangle_normal(a: Point3, b: Point3, c: Point3) -> Point3 {
    vec3::normalize(vec3::cross(vec3::sub(b, a), vec3::sub(c, a))).unwrap_or([0.0; 3])
}

/// The area of triangle `(a, b, c)`.
#[inline]
pub(crate) fn triangle_area(a: Point3, b: Point3, c: Point3) -> f64 {
    0.5 * vec3::norm(vec3::cross(vec3::sub(b, a), vec3::sub(c, a)))
}

impl MeshTopology {
    /// Builds the topology of `mesh`.
    ///
    /// Inputs: `mesh` with `V` vertices and `F` faces (any faces: soups, repeated indices,
    /// non-manifold or inconsistently oriented configurations are all accepted and reported).
    /// Output: the topology, or `Error::InvalidInput` if a face index is `>= V` or the mesh is
    /// too large for 32-bit incidence lists (`3F + V >= 2^31`).
    ///
    /// Cost: O(V + F) plus per-vertex sorts of the few half-edges and faces around each vertex,
    /// mostly in parallel; randomly ordered vertex ids are the worst case for memory access
    /// (timed in `docs/experiments/mesh-topology.md`).
    pub fn new(mesh: &TriMesh) -> Result<MeshTopology> {
        mesh.check_indices()?;
        let nv = mesh.num_vertices();
        let nf = mesh.num_faces();
        if 3 * nf as u64 + nv as u64 >= 1 << 31 {
            return Err(Error::InvalidInput(format!(
                "mesh too large for edge topology: {nv} vertices and {nf} faces \
                 (3 x faces + vertices must stay below 2^31)"
            )));
        }
        let faces = mesh.faces.clone();

        // 1. Half-edges bucketed by their lower endpoint, packed as
        //    upper << 32 | (3 f + side) << 1 | reversed.
        let mut counts = vec![0u32; nv];
        for f in &faces {
            for i in 0..3 {
                let (a, b) = (f[i], f[(i + 1) % 3]);
                if a != b {
                    counts[a.min(b) as usize] += 1;
                }
            }
        }
        let half_offsets = Csr::offsets_from_counts(&counts);
        drop(counts);
        let mut packed = vec![0u64; half_offsets[nv] as usize];
        {
            let mut cursor: Vec<u32> = half_offsets[..nv].to_vec();
            for (fi, f) in faces.iter().enumerate() {
                for i in 0..3 {
                    let (a, b) = (f[i], f[(i + 1) % 3]);
                    if a != b {
                        let lo = a.min(b) as usize;
                        packed[cursor[lo] as usize] = (u64::from(a.max(b)) << 32)
                            | (((3 * fi + i) as u64) << 1)
                            | u64::from(a > b);
                        cursor[lo] += 1;
                    }
                }
            }
        }
        // Sort each bucket by (upper, half-edge) and count its distinct edges.
        let edge_counts: Vec<u32> = rows_mut(&half_offsets, &mut packed)
            .into_par_iter()
            .map(|row| {
                row.sort_unstable();
                let mut n = 0u32;
                let mut last = u64::MAX;
                for &h in row.iter() {
                    if h >> 32 != last {
                        last = h >> 32;
                        n += 1;
                    }
                }
                n
            })
            .collect();
        let lower_offsets = Csr::offsets_from_counts(&edge_counts);
        drop(edge_counts);
        let ne = lower_offsets[nv] as usize;

        // 2. Edges, edge -> face sides and face -> edges, straight from the sorted buckets.
        let mut edges = vec![[0u32; 2]; ne];
        let mut ef_offsets = vec![0u32; ne + 1];
        ef_offsets[ne] = packed.len() as u32;
        let slots: Vec<AtomicU32> = (0..3 * nf).map(|_| AtomicU32::new(NO_EDGE)).collect();
        rows_mut(&lower_offsets, &mut edges)
            .into_par_iter()
            .zip(rows_mut(&lower_offsets, &mut ef_offsets[..ne]).into_par_iter())
            .enumerate()
            .for_each(|(v, (erow, orow))| {
                let base = half_offsets[v] as usize;
                let bucket = &packed[base..half_offsets[v + 1] as usize];
                let first = lower_offsets[v];
                let mut k = 0;
                let mut last = u64::MAX;
                for (j, &h) in bucket.iter().enumerate() {
                    if h >> 32 != last {
                        last = h >> 32;
                        erow[k] = [v as u32, last as u32];
                        orow[k] = (base + j) as u32;
                        k += 1;
                    }
                    let side = (h as u32 >> 1) as usize;
                    slots[side].store(first + k as u32 - 1, Ordering::Relaxed);
                }
            });
        let face_edges: Vec<[u32; 3]> = slots
            .par_chunks(3)
            .map(|c| [0, 1, 2].map(|i| c[i].load(Ordering::Relaxed)))
            .collect();
        drop(slots);
        let (ef_indices, edge_face_sides): (Vec<u32>, Vec<u8>) = packed
            .par_iter()
            .map(|&h| {
                let h = h as u32 >> 1;
                (h / 3, (h % 3) as u8)
            })
            .unzip();
        let side_reversed: Vec<bool> = packed.par_iter().map(|&h| h & 1 == 1).collect();
        drop(packed);
        let edge_faces = Csr {
            offsets: ef_offsets,
            indices: ef_indices,
        };

        let mut topo = MeshTopology {
            num_vertices: nv,
            faces,
            edges,
            lower_offsets,
            face_edges,
            edge_faces,
            edge_face_sides,
            side_reversed,
            ..Default::default()
        };

        // 3. Per-edge classification.
        topo.boundary_edges = topo.edges_where(|t, e| t.edge_faces.row_len(e) == 1);
        topo.non_manifold_edges = topo.edges_where(|t, e| t.edge_faces.row_len(e) > 2);
        topo.inconsistent_edges = topo.edges_where(|t, e| {
            t.edge_faces.row_len(e) == 2 && {
                let s = t.side_range(e);
                t.side_reversed[s.start] == t.side_reversed[s.start + 1]
            }
        });
        topo.degenerate_faces = (0..nf as u32)
            .into_par_iter()
            .filter(|&f| has_repeated_vertex(topo.faces[f as usize]))
            .collect();

        // 4. Vertex fans: kinds, fan-ordered vertex -> faces, one-rings, boundary loops.
        topo.analyse_fans();
        topo.vertex_edges = vertex_edge_csr(nv, &topo.edges);

        // 5. Geometry: face normals and dihedral angles.
        let p = mesh.positions();
        let geom: Vec<[Point3; 2]> = topo
            .faces
            .par_iter()
            .map(|&[a, b, c]| {
                let (a, b, c) = (p[a as usize], p[b as usize], p[c as usize]);
                let centroid = vec3::scale(vec3::add(vec3::add(a, b), c), 1.0 / 3.0);
                [triangle_normal(a, b, c), centroid]
            })
            .collect();
        topo.face_normals = geom.par_iter().map(|g| g[0]).collect();
        let (dihedral, signed): (Vec<f64>, Vec<f64>) = (0..ne)
            .into_par_iter()
            .map(|e| topo.compute_dihedral(e, &geom))
            .unzip();
        topo.dihedral = dihedral;
        topo.signed_dihedral = signed;

        // 6. Connected components through shared edges.
        topo.label_components();
        Ok(topo)
    }

    /// Number of vertices `V` of the mesh (referenced or not).
    pub fn num_vertices(&self) -> usize {
        self.num_vertices
    }

    /// Number of faces `F`.
    pub fn num_faces(&self) -> usize {
        self.faces.len()
    }

    /// Number of unique undirected edges `E`.
    pub fn num_edges(&self) -> usize {
        self.edges.len()
    }

    /// The faces the topology was built from (`F` vertex triples).
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// The unique undirected edges `[v0, v1]` with `v0 < v1`, sorted lexicographically
    /// (`E` entries). An edge's id is its index here.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// Per face, the ids of its three sides' edges (`F` entries): entry `i` is the edge joining
    /// corner `i` and corner `(i + 1) % 3` (opposite corner `(i + 2) % 3`), or [`NO_EDGE`] if
    /// both corners are the same vertex.
    pub fn face_edges(&self) -> &[[u32; 3]] {
        &self.face_edges
    }

    /// The id of the edge joining vertices `a` and `b` (in either order), if there is one.
    ///
    /// Inputs: two vertex ids (out-of-range ids give `None`). Output: an edge id `< E`.
    /// Cost: a binary search among the edges whose lower endpoint is `min(a, b)`.
    #[inline]
    pub fn edge_index(&self, a: usize, b: usize) -> Option<usize> {
        let (lo, hi) = (a.min(b), a.max(b));
        if lo == hi || hi >= self.num_vertices {
            return None;
        }
        let start = self.lower_offsets[lo] as usize;
        let range = &self.edges[start..self.lower_offsets[lo + 1] as usize];
        range
            .binary_search_by(|e| e[1].cmp(&(hi as u32)))
            .ok()
            .map(|k| start + k)
    }

    /// Edge → incident faces (CSR with `E` rows, ascending face ids). A face with a repeated
    /// vertex may lie twice on the same edge and then appears twice.
    pub fn edge_face_csr(&self) -> &Csr {
        &self.edge_faces
    }

    /// The faces on edge `e`, ascending (1 for a boundary edge, 2 for an interior manifold edge,
    /// more for a non-manifold edge). Panics if `e >= E`.
    #[inline]
    pub fn edge_faces(&self, e: usize) -> &[u32] {
        self.edge_faces.row(e)
    }

    /// Parallel to [`edge_faces`](Self::edge_faces): the side (0, 1 or 2) of each face that lies
    /// on edge `e`. Panics if `e >= E`.
    #[inline]
    pub fn edge_face_sides(&self, e: usize) -> &[u8] {
        &self.edge_face_sides[self.side_range(e)]
    }

    /// Per face on edge `e` (same order as [`edge_faces`](Self::edge_faces)), the face's corner
    /// opposite the edge. Panics if `e >= E`.
    pub fn edge_opposite_vertices(&self, e: usize) -> impl Iterator<Item = u32> + '_ {
        self.edge_faces(e)
            .iter()
            .zip(self.edge_face_sides(e))
            .map(|(&f, &s)| self.faces[f as usize][(s as usize + 2) % 3])
    }

    /// Vertex → incident faces (CSR with `V` rows; each face once). Rows of manifold vertices
    /// are in fan order (the order of [`one_ring`](Self::one_ring)); other rows ascend.
    pub fn vertex_face_csr(&self) -> &Csr {
        &self.vertex_faces
    }

    /// The faces around vertex `v` (see [`vertex_face_csr`](Self::vertex_face_csr) for the
    /// order). Panics if `v >= V`.
    #[inline]
    pub fn vertex_faces(&self, v: usize) -> &[u32] {
        self.vertex_faces.row(v)
    }

    /// Vertex → incident edges (CSR with `V` rows, ascending edge ids, which is also ascending
    /// neighbour ids).
    pub fn vertex_edge_csr(&self) -> &Csr {
        &self.vertex_edges
    }

    /// The edges at vertex `v`, ascending. Panics if `v >= V`.
    #[inline]
    pub fn vertex_edges(&self, v: usize) -> &[u32] {
        self.vertex_edges.row(v)
    }

    /// The vertices sharing an edge with `v`, ascending. Panics if `v >= V`.
    pub fn neighbors(&self, v: usize) -> impl ExactSizeIterator<Item = u32> + '_ {
        self.vertex_edges(v).iter().map(move |&e| {
            let [a, b] = self.edges[e as usize];
            if a as usize == v {
                b
            } else {
                a
            }
        })
    }

    /// The kind of each vertex (`V` entries).
    pub fn vertex_kinds(&self) -> &[VertexKind] {
        &self.vertex_kinds
    }

    /// The kind of vertex `v`. Panics if `v >= V`.
    pub fn vertex_kind(&self, v: usize) -> VertexKind {
        self.vertex_kinds[v]
    }

    /// The ordered one-ring of vertex `v` (see [`OneRing`]); `None` for a non-manifold vertex,
    /// an empty ring for an isolated one. Panics if `v >= V`.
    pub fn one_ring(&self, v: usize) -> Option<OneRing<'_>> {
        let closed = match self.vertex_kinds[v] {
            VertexKind::NonManifold => return None,
            VertexKind::Interior => true,
            VertexKind::Boundary | VertexKind::Isolated => false,
        };
        Some(OneRing {
            neighbors: self.rings.row(v),
            faces: self.vertex_faces.row(v),
            closed,
        })
    }

    /// The one-rings as a CSR list (`V` rows; empty rows for isolated and non-manifold
    /// vertices).
    pub fn one_ring_csr(&self) -> &Csr {
        &self.rings
    }

    /// Edges with exactly one face side, ascending.
    pub fn boundary_edges(&self) -> &[u32] {
        &self.boundary_edges
    }

    /// Edges with more than two face sides, ascending.
    pub fn non_manifold_edges(&self) -> &[u32] {
        &self.non_manifold_edges
    }

    /// Edges with two face sides that both traverse the edge in the same direction (one of the
    /// two faces is flipped), ascending.
    pub fn inconsistent_edges(&self) -> &[u32] {
        &self.inconsistent_edges
    }

    /// Vertices of kind [`VertexKind::NonManifold`], ascending.
    pub fn non_manifold_vertices(&self) -> &[u32] {
        &self.non_manifold_vertices
    }

    /// Faces with a repeated vertex index, ascending.
    pub fn degenerate_faces(&self) -> &[u32] {
        &self.degenerate_faces
    }

    /// True if edge `e` has exactly one face. Panics if `e >= E`.
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_faces.row_len(e) == 1
    }

    /// True if edge `e` has more than two faces. Panics if `e >= E`.
    pub fn is_non_manifold_edge(&self, e: usize) -> bool {
        self.edge_faces.row_len(e) > 2
    }

    /// Unit face normals (`F` entries, `[0, 0, 0]` for faces of zero area).
    pub fn face_normals(&self) -> &[Point3] {
        &self.face_normals
    }

    /// Unsigned dihedral angle per edge (`E` entries, radians in `[0, π]`): the angle between
    /// the normals of the edge's two faces, 0 where they are coplanar, π/2 on a cube's edge.
    ///
    /// NaN for boundary and non-manifold edges and where a face has zero area. On an
    /// inconsistently oriented edge it is the angle between the normals as the faces are
    /// oriented (π minus the geometric bend).
    pub fn dihedral_angles(&self) -> &[f64] {
        &self.dihedral
    }

    /// Signed dihedral angle per edge (`E` entries, radians in `[-π, π]`): the unsigned angle,
    /// positive where the surface is convex (bends away from the side its normals point to),
    /// negative where it is concave. With `n1`, `n2` the normals of the two faces and `d` the
    /// edge's direction as the first face traverses it, the sign is that of `(n1 × n2) · d`
    /// (positive when zero).
    ///
    /// NaN for boundary, non-manifold and inconsistently oriented edges and where a face has
    /// zero area.
    pub fn signed_dihedral_angles(&self) -> &[f64] {
        &self.signed_dihedral
    }

    /// Connected component of each face (`F` entries), faces being connected through shared
    /// edges. Components are numbered `0..num_components()` in order of their lowest face.
    pub fn face_components(&self) -> &[u32] {
        &self.face_components
    }

    /// Number of connected components of faces (connected through shared edges).
    pub fn num_components(&self) -> usize {
        self.num_components
    }

    /// Number of boundary loops: connected sets of boundary edges, two boundary edges at a
    /// vertex being linked when they bound the same fan of faces around it (so two holes that
    /// touch at a vertex count as two loops). Around vertices of faces with a repeated index
    /// the boundary edges are not linked.
    pub fn num_boundary_loops(&self) -> usize {
        self.num_boundary_loops
    }

    /// Number of vertices used by at least one face.
    pub fn num_referenced_vertices(&self) -> usize {
        self.num_referenced_vertices
    }

    /// Euler characteristic `V' - E + F`, where `V'` counts only the vertices used by a face
    /// (so unreferenced vertices do not change it): 2 for a closed sphere-like surface, 1 for a
    /// disk, `2 - 2g` for a closed surface of genus `g`.
    pub fn euler_characteristic(&self) -> i64 {
        self.num_referenced_vertices as i64 - self.edges.len() as i64 + self.faces.len() as i64
    }

    /// True if every edge has exactly two faces and every referenced vertex has a single closed
    /// fan (and there is at least one face). Orientation is not required: see
    /// [`is_oriented`](Self::is_oriented).
    pub fn is_closed_manifold(&self) -> bool {
        !self.faces.is_empty() && self.boundary_edges.is_empty() && self.is_manifold()
    }

    /// True if no edge has more than two faces and every vertex is manifold (its faces form one
    /// closed or open fan).
    pub fn is_manifold(&self) -> bool {
        self.non_manifold_edges.is_empty() && self.non_manifold_vertices.is_empty()
    }

    /// True if no edge is inconsistently oriented.
    pub fn is_oriented(&self) -> bool {
        self.inconsistent_edges.is_empty()
    }

    // ---------------------------------------------------------------- internals

    #[inline]
    fn side_range(&self, e: usize) -> std::ops::Range<usize> {
        self.edge_faces.offsets[e] as usize..self.edge_faces.offsets[e + 1] as usize
    }

    fn edges_where(&self, pred: impl Fn(&Self, usize) -> bool + Sync) -> Vec<u32> {
        (0..self.edges.len() as u32)
            .into_par_iter()
            .filter(|&e| pred(self, e as usize))
            .collect()
    }

    fn compute_dihedral(&self, e: usize, geom: &[[Point3; 2]]) -> (f64, f64) {
        let r = self.side_range(e);
        if r.len() != 2 {
            return (f64::NAN, f64::NAN);
        }
        let [n1, c1] = geom[self.edge_faces.indices[r.start] as usize];
        let [n2, c2] = geom[self.edge_faces.indices[r.start + 1] as usize];
        if n1 == [0.0; 3] || n2 == [0.0; 3] {
            return (f64::NAN, f64::NAN);
        }
        let angle = vec3::norm(vec3::cross(n1, n2)).atan2(vec3::dot(n1, n2));
        if self.side_reversed[r.start] == self.side_reversed[r.start + 1] {
            return (angle, f64::NAN);
        }
        // (n2 - n1) . (c2 - c1) = -3 n1 . (o2 - a) - 3 n2 . (o1 - a) with o the opposite corners
        // and a a vertex of the edge: positive when each face's far corner lies behind the
        // other face's plane, i.e. the edge is convex.
        let s = vec3::dot(vec3::sub(n2, n1), vec3::sub(c2, c1));
        let signed = if s >= 0.0 || angle == 0.0 {
            angle
        } else {
            -angle
        };
        (angle, signed)
    }

    fn analyse_fans(&mut self) {
        let nv = self.num_vertices;
        let (vf_offsets, mut wedges) = vertex_wedges(nv, &self.faces);
        // Ring rows are written with capacity `faces + 1` each, then compacted.
        let cap_offsets: Vec<u32> = vf_offsets
            .iter()
            .enumerate()
            .map(|(v, &o)| o + v as u32)
            .collect();
        let mut ring_buf = vec![0u32; cap_offsets[nv] as usize];
        let mut kinds = vec![VertexKind::Isolated; nv];
        let mut ring_lens = vec![0u32; nv];
        // Triples [v, u1, u2]: boundary edges (v, u1) and (v, u2) bound the same fan at v.
        let pairs: Vec<[u32; 3]> = rows_mut(&vf_offsets, &mut wedges)
            .into_par_iter()
            .zip(rows_mut(&cap_offsets, &mut ring_buf).into_par_iter())
            .zip(kinds.par_iter_mut().zip(ring_lens.par_iter_mut()))
            .enumerate()
            .map_init(FanScratch::default, |s, (v, ((row, ring), (kind, len)))| {
                (*kind, *len) = analyse_fan(v as u32, row, ring, s);
                std::mem::take(&mut s.pairs)
            })
            .flat_map_iter(|p| p.into_iter())
            .collect();
        self.vertex_faces = Csr {
            offsets: vf_offsets,
            indices: wedges.par_iter().map(|w| w[0]).collect(),
        };
        drop(wedges);
        self.num_referenced_vertices = kinds.iter().filter(|&&k| k != VertexKind::Isolated).count();

        let ring_offsets = Csr::offsets_from_counts(&ring_lens);
        let mut ring_indices = vec![0u32; ring_offsets[nv] as usize];
        rows_mut(&ring_offsets, &mut ring_indices)
            .into_par_iter()
            .enumerate()
            .for_each(|(v, dst)| {
                let start = cap_offsets[v] as usize;
                dst.copy_from_slice(&ring_buf[start..start + dst.len()]);
            });
        self.rings = Csr {
            offsets: ring_offsets,
            indices: ring_indices,
        };
        self.non_manifold_vertices = (0..nv as u32)
            .filter(|&v| kinds[v as usize] == VertexKind::NonManifold)
            .collect();
        self.vertex_kinds = kinds;

        // Boundary loops: union boundary edges paired at vertices.
        let nb = self.boundary_edges.len();
        let mut uf = UnionFind::new(nb);
        let bidx = |e: usize| self.boundary_edges.binary_search(&(e as u32)).ok();
        for [v, u1, u2] in pairs {
            let e1 = self.edge_index(v as usize, u1 as usize).and_then(bidx);
            let e2 = self.edge_index(v as usize, u2 as usize).and_then(bidx);
            if let (Some(a), Some(b)) = (e1, e2) {
                uf.union(a, b);
            }
        }
        self.num_boundary_loops = (0..nb).filter(|&i| uf.find(i) == i).count();
    }

    fn label_components(&mut self) {
        let nf = self.faces.len();
        let mut uf = UnionFind::new(nf);
        for e in 0..self.edges.len() {
            let row = self.edge_faces.row(e);
            if let Some((&first, rest)) = row.split_first() {
                for &f in rest {
                    uf.union(first as usize, f as usize);
                }
            }
        }
        let mut label = vec![u32::MAX; nf];
        let mut comps = vec![0u32; nf];
        let mut n = 0u32;
        for (f, c) in comps.iter_mut().enumerate() {
            let r = uf.find(f);
            if label[r] == u32::MAX {
                label[r] = n;
                n += 1;
            }
            *c = label[r];
        }
        self.face_components = comps;
        self.num_components = n as usize;
    }
}

/// True if the face uses a vertex twice.
#[inline]
pub(crate) fn has_repeated_vertex(f: [u32; 3]) -> bool {
    f[0] == f[1] || f[1] == f[2] || f[0] == f[2]
}

/// Splits `data` into its CSR rows (mutable, disjoint) for parallel processing.
fn rows_mut<'a, T>(offsets: &[u32], mut data: &'a mut [T]) -> Vec<&'a mut [T]> {
    let mut rows = Vec::with_capacity(offsets.len().saturating_sub(1));
    for w in offsets.windows(2) {
        let (row, rest) = std::mem::take(&mut data).split_at_mut((w[1] - w[0]) as usize);
        rows.push(row);
        data = rest;
    }
    rows
}

/// Vertex -> wedges: per vertex `v`, one `[f, a, b]` per face `f` using `v` (each face once,
/// ascending `f`), `a` and `b` being the corners after `v` in the face's order.
/// Output: `(offsets, wedges)` with `V + 1` offsets.
fn vertex_wedges(nv: usize, faces: &[[u32; 3]]) -> (Vec<u32>, Vec<[u32; 3]>) {
    let mut counts = vec![0u32; nv];
    let distinct = |f: &[u32; 3], i: usize| (0..i).all(|j| f[j] != f[i]);
    for f in faces {
        for i in 0..3 {
            if distinct(f, i) {
                counts[f[i] as usize] += 1;
            }
        }
    }
    let offsets = Csr::offsets_from_counts(&counts);
    drop(counts);
    let mut wedges = vec![[0u32; 3]; offsets[nv] as usize];
    let mut cursor: Vec<u32> = offsets[..nv].to_vec();
    for (fi, f) in faces.iter().enumerate() {
        for i in 0..3 {
            if distinct(f, i) {
                let c = &mut cursor[f[i] as usize];
                wedges[*c as usize] = [fi as u32, f[(i + 1) % 3], f[(i + 2) % 3]];
                *c += 1;
            }
        }
    }
    (offsets, wedges)
}

fn vertex_edge_csr(nv: usize, edges: &[[u32; 2]]) -> Csr {
    let mut counts = vec![0u32; nv];
    for &[a, b] in edges {
        counts[a as usize] += 1;
        counts[b as usize] += 1;
    }
    let offsets = Csr::offsets_from_counts(&counts);
    let mut indices = vec![0u32; offsets[nv] as usize];
    let mut cursor: Vec<u32> = offsets[..nv].to_vec();
    for (e, &[a, b]) in edges.iter().enumerate() {
        for v in [a, b] {
            let c = &mut cursor[v as usize];
            indices[*c as usize] = e as u32;
            *c += 1;
        }
    }
    Csr { offsets, indices }
}

/// Per-thread buffers for the fan analysis.
#[derive(Default)]
struct FanScratch {
    /// (node << 32 | wedge << 1 | end), sorted by node.
    entries: Vec<u64>,
    parent: Vec<u32>,
    boundary: Vec<(u32, u32)>,
    order: Vec<u32>,
    row_copy: Vec<[u32; 3]>,
    pairs: Vec<[u32; 3]>,
}

/// Classifies vertex `v` from its wedges `row` (`[f, a, b]`, ascending `f`). For a manifold
/// vertex, reorders `row` into fan order and writes the one-ring into `ring` (capacity
/// `row.len() + 1`). Leaves in `s.pairs` the boundary-edge pairs bounding a same fan.
/// Returns the kind and the ring's length.
fn analyse_fan(
    v: u32,
    row: &mut [[u32; 3]],
    ring: &mut [u32],
    s: &mut FanScratch,
) -> (VertexKind, u32) {
    s.pairs.clear();
    let d = row.len();
    if d == 0 {
        return (VertexKind::Isolated, 0);
    }
    // Wedge k joins a (end 0) and b (end 1); degenerate faces take no part.
    s.entries.clear();
    let mut degenerate = false;
    for (k, &[_, a, b]) in row.iter().enumerate() {
        if a == v || b == v || a == b {
            degenerate = true;
            continue;
        }
        s.entries.push((u64::from(a) << 32) | ((k as u64) << 1));
        s.entries.push((u64::from(b) << 32) | ((k as u64) << 1) | 1);
    }
    s.entries.sort_unstable();

    // Components of the wedge graph (wedges linked through shared neighbour nodes).
    s.parent.clear();
    s.parent.extend(0..d as u32);
    s.boundary.clear();
    let mut max_deg = 0;
    let mut i = 0;
    let n = s.entries.len();
    while i < n {
        let node = s.entries[i] >> 32;
        let mut j = i + 1;
        while j < n && s.entries[j] >> 32 == node {
            let a = (s.entries[i] as u32 >> 1) as usize;
            let b = (s.entries[j] as u32 >> 1) as usize;
            local_union(&mut s.parent, a, b);
            j += 1;
        }
        max_deg = max_deg.max(j - i);
        if j - i == 1 {
            s.boundary.push((0, i as u32));
        }
        i = j;
    }
    // Boundary nodes grouped by component root; consecutive ones in a group are paired.
    for b in s.boundary.iter_mut() {
        let wedge = (s.entries[b.1 as usize] as u32 >> 1) as usize;
        b.0 = local_find(&mut s.parent, wedge) as u32;
    }
    s.boundary.sort_unstable();
    for w in s.boundary.windows(2) {
        if w[0].0 == w[1].0 {
            let u1 = (s.entries[w[0].1 as usize] >> 32) as u32;
            let u2 = (s.entries[w[1].1 as usize] >> 32) as u32;
            s.pairs.push([v, u1, u2]);
        }
    }
    if degenerate || max_deg > 2 {
        return (VertexKind::NonManifold, 0);
    }
    let components = (0..d)
        .filter(|&k| local_find(&mut s.parent, k) == k)
        .count();
    if components != 1 {
        return (VertexKind::NonManifold, 0);
    }

    // A single path or cycle of wedges: walk it.
    let closed = s.boundary.is_empty();
    let (mut wedge, mut from_end) = if closed {
        (0usize, 0usize)
    } else {
        // Two boundary nodes; prefer the one listed right after v in its face (end 0), then
        // the lower face.
        let at = |pos: u32| {
            let e = s.entries[pos as usize];
            ((e & 1) as usize, (e as u32 >> 1) as usize)
        };
        let (e1, w1) = at(s.boundary[0].1);
        let (e2, w2) = at(s.boundary[1].1);
        if (e1, w1) <= (e2, w2) {
            (w1, e1)
        } else {
            (w2, e2)
        }
    };
    let len = if closed { d } else { d + 1 };
    ring[0] = row[wedge][1 + from_end];
    s.order.clear();
    for step in 0..d {
        s.order.push(wedge as u32);
        let node = row[wedge][2 - from_end];
        if step + 1 < len {
            ring[step + 1] = node;
        }
        let key = u64::from(node);
        let lo = s.entries.partition_point(|&x| x >> 32 < key);
        let mut next = None;
        for &x in s.entries[lo..].iter().take_while(|&&x| x >> 32 == key) {
            let w = (x as u32 >> 1) as usize;
            if w != wedge {
                next = Some((w, (x & 1) as usize));
            }
        }
        match next {
            Some((w, e)) => {
                wedge = w;
                from_end = e;
            }
            None => break,
        }
    }
    if s.order.len() != d {
        return (VertexKind::NonManifold, 0);
    }
    s.row_copy.clear();
    s.row_copy.extend_from_slice(row);
    for (slot, &k) in row.iter_mut().zip(&s.order) {
        *slot = s.row_copy[k as usize];
    }
    let kind = if closed {
        VertexKind::Interior
    } else {
        VertexKind::Boundary
    };
    (kind, len as u32)
}

fn local_find(parent: &mut [u32], mut x: usize) -> usize {
    while parent[x] as usize != x {
        let p = parent[x] as usize;
        parent[x] = parent[p];
        x = p;
    }
    x
}

fn local_union(parent: &mut [u32], a: usize, b: usize) {
    let (ra, rb) = (local_find(parent, a), local_find(parent, b));
    if ra != rb {
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        parent[hi] = lo as u32;
    }
}

/// Union-find with path halving; roots are the smallest index of their set.
struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }
    fn find(&mut self, x: usize) -> usize {
        local_find(&mut self.parent, x)
    }
    fn union(&mut self, a: usize, b: usize) {
        local_union(&mut self.parent, a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(positions: Vec<Point3>, faces: Vec<[u32; 3]>) -> TriMesh {
        TriMesh::new(positions, faces).unwrap()
    }

    #[test]
    fn single_triangle() {
        let m = tri(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        );
        let t = MeshTopology::new(&m).unwrap();
        assert_eq!(t.edges(), &[[0, 1], [0, 2], [1, 2]]);
        // side 0 = (0,1), side 1 = (1,2), side 2 = (2,0)
        assert_eq!(t.face_edges(), &[[0, 2, 1]]);
        assert_eq!(t.boundary_edges(), &[0, 1, 2]);
        assert_eq!(t.num_boundary_loops(), 1);
        assert_eq!(t.euler_characteristic(), 1);
        let r = t.one_ring(0).unwrap();
        assert!(!r.closed);
        assert_eq!(r.neighbors, &[1, 2]);
        assert_eq!(r.faces, &[0]);
        assert_eq!(t.one_ring(1).unwrap().neighbors, &[2, 0]);
        assert!(t.dihedral_angles().iter().all(|a| a.is_nan()));
        assert_eq!(t.face_normals()[0], [0.0, 0.0, 1.0]);
        assert_eq!(face_area(&m, 0), 0.5);
        assert_eq!(t.edge_opposite_vertices(2).collect::<Vec<_>>(), vec![0]);
    }

    #[test]
    fn repeated_index_face() {
        let m = tri(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 0, 1], [0, 1, 2]],
        );
        let t = MeshTopology::new(&m).unwrap();
        assert_eq!(t.face_edges()[0], [NO_EDGE, 0, 0]);
        assert_eq!(t.edge_faces(0), &[0, 0, 1]);
        assert_eq!(t.degenerate_faces(), &[0]);
        assert_eq!(t.vertex_kind(0), VertexKind::NonManifold);
        assert_eq!(t.vertex_kind(2), VertexKind::Boundary);
        assert_eq!(t.vertex_faces(0), &[0, 1]);
    }

    #[test]
    fn out_of_range_is_an_error() {
        let mut m = tri(vec![[0.0; 3]; 3], vec![[0, 1, 2]]);
        m.faces.push([0, 1, 7]);
        assert!(MeshTopology::new(&m).is_err());
    }

    #[test]
    fn empty_mesh() {
        let t = MeshTopology::new(&TriMesh::default()).unwrap();
        assert_eq!(t.num_edges(), 0);
        assert!(!t.is_closed_manifold());
        assert_eq!(t.euler_characteristic(), 0);
        assert_eq!(t.num_components(), 0);
    }
}
