//! The topology of a B-rep read off a segmented triangle mesh: faces are the connected
//! regions of triangles that share a surface, edges the chains of mesh edges between two
//! regions (or along the mesh's border), vertices the mesh vertices where three or more
//! regions meet.
//!
//! On a consistently oriented 2-manifold mesh the border of each region, walked with the
//! region on the left, is a set of closed loops; cutting them at the vertices gives the B-rep
//! edges, each walked once forwards by one face and once backwards by the other (once only on
//! the mesh's border: an open shell). Two details a CAD kernel needs:
//! - a loop with no vertex on it (the circle where a hole's cylinder meets a plane) gets one
//!   at its lowest-indexed mesh vertex: a closed edge starts and ends at it;
//! - a region with no border at all (a whole sphere or torus) is cut in two by a plane
//!   through its centre (containing the torus's axis), as CAD kernels represent such solids
//!   with seams; the cut is recorded so that the edge's curve comes from that plane.

use std::collections::HashMap;

use crate::geometry::vec3::{add, dot, scale, sub};
use crate::geometry::{Point3, SurfaceParams, TriMesh};
use crate::{Error, Result};

/// The region on the far side of a mesh border.
pub(crate) const OUTSIDE: u32 = u32::MAX;

/// One B-rep edge as a chain of mesh vertices between two regions.
#[derive(Debug, Clone)]
pub(crate) struct TopoEdge {
    /// Mesh vertices from the start vertex to the end vertex (equal for a closed edge).
    pub chain: Vec<u32>,
    /// The region that walks the chain forwards (the chain has it on its left).
    pub left: u32,
    /// The region on the other side, or [`OUTSIDE`].
    pub right: u32,
    /// B-rep vertex indices of the chain's ends.
    pub start: usize,
    pub end: usize,
}

/// The topology of the segmented mesh.
#[derive(Debug, Clone)]
pub(crate) struct Topology {
    /// Per triangle: its region.
    pub region_of_face: Vec<u32>,
    /// Per region: the surface index (into the segmentation's surfaces).
    pub surface_of_region: Vec<usize>,
    /// Planes that cut a closed region in two: `(region a, region b, plane)`.
    pub cuts: Vec<(u32, u32, SurfaceParams)>,
    /// Per B-rep vertex: its mesh vertex.
    pub vertices: Vec<u32>,
    pub edges: Vec<TopoEdge>,
    /// Per region: its loops, each a cycle of (edge, walked forwards).
    pub loops: Vec<Vec<Vec<(usize, bool)>>>,
}

const NONE: u32 = u32::MAX;

/// Half-edge `h` of triangle `h / 3` runs from corner `h % 3` to the next corner.
struct HalfEdges<'a> {
    faces: &'a [[u32; 3]],
    twin: Vec<u32>,
}

impl HalfEdges<'_> {
    fn origin(&self, h: usize) -> u32 {
        self.faces[h / 3][h % 3]
    }
    fn dest(&self, h: usize) -> u32 {
        self.faces[h / 3][(h + 1) % 3]
    }
    fn next(h: usize) -> usize {
        h - h % 3 + (h + 1) % 3
    }
    fn twin(&self, h: usize) -> Option<usize> {
        let t = self.twin[h];
        (t != NONE).then_some(t as usize)
    }
}

/// Whether the mesh is one the topology can read (an oriented 2-manifold without repeated
/// vertices in a triangle); the error says why not.
pub(crate) fn check(mesh: &TriMesh) -> Result<()> {
    half_edges(mesh).map(|_| ())
}

fn half_edges(mesh: &TriMesh) -> Result<HalfEdges<'_>> {
    use rayon::prelude::*;
    let faces = &mesh.faces[..];
    if let Some((t, f)) = faces
        .iter()
        .enumerate()
        .find(|(_, f)| f[0] == f[1] || f[1] == f[2] || f[0] == f[2])
    {
        return Err(Error::InvalidInput(format!(
            "reconstruct: triangle {t} repeats a vertex ({} {} {}); clean the mesh first \
             (crease convert --clean)",
            f[0], f[1], f[2]
        )));
    }
    // Half-edge 3t + i walks f[i] -> f[i + 1]; sorted by (from, to), its twin is found by
    // binary search (a sort rather than a hash map: parallel, and a third of the time on the
    // million-triangle envelopes of clouds).
    let key = |h: usize| {
        let f = faces[h / 3];
        (u64::from(f[h % 3]) << 32) | u64::from(f[(h % 3 + 1) % 3])
    };
    let mut directed: Vec<(u64, u32)> = (0..faces.len() * 3)
        .into_par_iter()
        .map(|h| (key(h), h as u32))
        .collect();
    directed.par_sort_unstable();
    if let Some(w) = directed.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(Error::InvalidInput(format!(
            "reconstruct: the mesh is not an oriented 2-manifold: the edge {}-{} is walked the \
             same way by two triangles (a non-manifold edge or inconsistently oriented faces)",
            w[0].0 >> 32,
            w[0].0 & 0xffff_ffff
        )));
    }
    let twin: Vec<u32> = (0..faces.len() * 3)
        .into_par_iter()
        .map(|h| {
            let k = key(h);
            let back = k.rotate_right(32);
            directed
                .binary_search_by_key(&back, |&(k, _)| k)
                .map_or(NONE, |i| directed[i].1)
        })
        .collect();
    Ok(HalfEdges { faces, twin })
}

/// A second patch of a surface smaller than this fraction of the surface's largest patch is
/// taken for noise along a border and joins the region around it.
pub(crate) const ISLAND_FRACTION: f64 = 0.05;

/// Connected components of triangles with equal labels: per triangle its component, and the
/// number of components.
fn components(he: &HalfEdges, label: &[i32]) -> (Vec<u32>, usize) {
    let nt = label.len();
    let mut comp = vec![NONE; nt];
    let mut n = 0u32;
    for s in 0..nt {
        if comp[s] != NONE {
            continue;
        }
        comp[s] = n;
        let mut stack = vec![s];
        while let Some(t) = stack.pop() {
            for i in 0..3 {
                if let Some(o) = he.twin(3 * t + i) {
                    let u = o / 3;
                    if comp[u] == NONE && label[u] == label[t] {
                        comp[u] = n;
                        stack.push(u);
                    }
                }
            }
        }
        n += 1;
    }
    (comp, n as usize)
}

/// Relabels the islands (see [`ISLAND_FRACTION`]) with the label of the neighbouring patch they
/// share most mesh edges with; up to three rounds (an island inside an island).
fn absorb_islands(he: &HalfEdges, label: &mut [i32], areas: &[f64]) {
    for _ in 0..3 {
        let (comp, n) = components(he, label);
        let mut area = vec![0.0; n];
        let mut of = vec![0i32; n];
        for (t, &c) in comp.iter().enumerate() {
            area[c as usize] += areas[t];
            of[c as usize] = label[t];
        }
        let mut largest: std::collections::HashMap<i32, f64> = std::collections::HashMap::new();
        for c in 0..n {
            let e = largest.entry(of[c]).or_insert(0.0);
            *e = e.max(area[c]);
        }
        let island: Vec<bool> = (0..n)
            .map(|c| area[c] < ISLAND_FRACTION * largest[&of[c]])
            .collect();
        if !island.contains(&true) {
            return;
        }
        // Shared mesh edges between an island and each neighbouring patch.
        let mut shared: std::collections::BTreeMap<(u32, u32), usize> = Default::default();
        for h in 0..comp.len() * 3 {
            let c = comp[h / 3];
            if !island[c as usize] {
                continue;
            }
            if let Some(o) = he.twin(h) {
                let d = comp[o / 3];
                if d != c {
                    *shared.entry((c, d)).or_insert(0) += 1;
                }
            }
        }
        let mut target: Vec<Option<(usize, i32)>> = vec![None; n];
        for (&(c, d), &count) in &shared {
            let l = of[d as usize];
            let better = match target[c as usize] {
                None => true,
                Some((k, tl)) => count > k || (count == k && l < tl),
            };
            if better {
                target[c as usize] = Some((count, l));
            }
        }
        for (t, &c) in comp.iter().enumerate() {
            if let Some((_, l)) = target[c as usize] {
                label[t] = l;
            }
        }
    }
}

/// Regions: connected components of triangles with the same label (unlabelled triangles first
/// take the label of the nearest labelled ones across edges, breadth first; islands join the
/// region around them, [`absorb_islands`]).
fn regions(he: &HalfEdges, labels: &[i32], areas: &[f64]) -> Result<(Vec<u32>, Vec<usize>)> {
    let nt = he.faces.len();
    let mut label = labels.to_vec();
    let mut frontier: Vec<usize> = (0..nt).filter(|&t| label[t] >= 0).collect();
    if frontier.is_empty() {
        return Err(Error::InvalidInput(
            "reconstruct: no triangle was assigned a surface (the part has no planes, \
             cylinders, cones, spheres or tori that the segmentation could find)"
                .into(),
        ));
    }
    while !frontier.is_empty() {
        let mut next = Vec::new();
        let mut claims: Vec<(usize, i32)> = Vec::new();
        for &t in &frontier {
            for i in 0..3 {
                if let Some(o) = he.twin(3 * t + i) {
                    let u = o / 3;
                    if label[u] < 0 {
                        claims.push((u, label[t]));
                    }
                }
            }
        }
        // Lowest label wins a triangle claimed by two regions in the same round.
        claims.sort_unstable();
        for (u, l) in claims {
            if label[u] < 0 {
                label[u] = l;
                next.push(u);
            }
        }
        frontier = next;
    }
    absorb_islands(he, &mut label, areas);
    let mut region = vec![NONE; nt];
    let mut surface_of_region = Vec::new();
    for s in 0..nt {
        if region[s] != NONE || label[s] < 0 {
            continue;
        }
        let r = surface_of_region.len() as u32;
        surface_of_region.push(label[s] as usize);
        region[s] = r;
        let mut stack = vec![s];
        while let Some(t) = stack.pop() {
            for i in 0..3 {
                if let Some(o) = he.twin(3 * t + i) {
                    let u = o / 3;
                    if region[u] == NONE && label[u] == label[t] {
                        region[u] = r;
                        stack.push(u);
                    }
                }
            }
        }
    }
    if region.contains(&NONE) {
        return Err(Error::InvalidInput(
            "reconstruct: part of the mesh is not connected to any surface the segmentation \
             found"
                .into(),
        ));
    }
    Ok((region, surface_of_region))
}

/// Cuts every region without a border (a closed sphere or torus) in two by a plane through
/// its centre; returns the cuts.
fn cut_closed_regions(
    mesh: &TriMesh,
    he: &HalfEdges,
    region: &mut [u32],
    surface_of_region: &mut Vec<usize>,
    surfaces: &[SurfaceParams],
) -> Result<Vec<(u32, u32, SurfaceParams)>> {
    let nr = surface_of_region.len();
    let mut bordered = vec![false; nr];
    for h in 0..region.len() * 3 {
        match he.twin(h) {
            Some(o) if region[o / 3] == region[h / 3] => {}
            _ => bordered[region[h / 3] as usize] = true,
        }
    }
    let mut cuts = Vec::new();
    for r in 0..nr {
        if bordered[r] {
            continue;
        }
        let s = surfaces[surface_of_region[r]];
        let (centre, normal) = match s {
            SurfaceParams::Sphere { center, .. } => (center, [0.0, 0.0, 1.0]),
            SurfaceParams::Torus {
                center, axis_dir, ..
            } => (center, super::step::perpendicular(axis_dir)),
            other => {
                return Err(Error::InvalidInput(format!(
                    "reconstruct: a closed region of the mesh was fitted by a {}, which cannot \
                     close on itself",
                    other.kind().name()
                )))
            }
        };
        let plane = SurfaceParams::Plane {
            normal,
            offset: dot(normal, centre),
        };
        let new = surface_of_region.len() as u32;
        let mut moved = 0;
        for (t, f) in mesh.faces.iter().enumerate() {
            if region[t] != r as u32 {
                continue;
            }
            let p = |i: usize| mesh.vertices.positions[f[i] as usize];
            let c = scale(add(add(p(0), p(1)), p(2)), 1.0 / 3.0);
            if dot(sub(c, centre), normal) > 0.0 {
                region[t] = new;
                moved += 1;
            }
        }
        if moved == 0 {
            return Err(Error::InvalidInput(
                "reconstruct: a closed sphere or torus region lies on one side of its own \
                 centre"
                    .into(),
            ));
        }
        surface_of_region.push(surface_of_region[r]);
        cuts.push((r as u32, new, plane));
    }
    Ok(cuts)
}

/// The B-rep topology of `mesh` whose triangle `t` lies on surface `labels[t]` (negative:
/// unassigned) of `surfaces`.
pub(crate) fn topology(
    mesh: &TriMesh,
    labels: &[i32],
    surfaces: &[SurfaceParams],
) -> Result<Topology> {
    if labels.len() != mesh.faces.len() {
        return Err(Error::InvalidArgument(format!(
            "reconstruct: {} face labels for {} triangles",
            labels.len(),
            mesh.faces.len()
        )));
    }
    if mesh.faces.is_empty() {
        return Err(Error::InvalidInput(
            "reconstruct: the mesh has no triangles".into(),
        ));
    }
    let he = half_edges(mesh)?;
    let areas = crate::geometry::face_areas(mesh);
    let (mut region, mut surface_of_region) = regions(&he, labels, &areas)?;
    let cuts = cut_closed_regions(mesh, &he, &mut region, &mut surface_of_region, surfaces)?;
    let nr = surface_of_region.len();
    let nh = region.len() * 3;
    let other = |h: usize| -> u32 {
        match he.twin(h) {
            Some(o) => region[o / 3],
            None => OUTSIDE,
        }
    };
    let boundary = |h: usize| other(h) != region[h / 3];

    // B-rep vertices: three or more regions around the mesh vertex (the outside counting as
    // one), or a region whose border passes twice through it.
    let nv = mesh.vertices.positions.len();
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); nv];
    let mut out_of: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for h in 0..nh {
        let v = he.origin(h) as usize;
        around[v].push(region[h / 3]);
        if he.twin(h).is_none() {
            around[v].push(OUTSIDE);
            around[he.dest(h) as usize].push(OUTSIDE);
        }
        if boundary(h) {
            out_of[v].push(region[h / 3]);
        }
    }
    let mut is_vertex: Vec<bool> = (0..nv)
        .map(|v| {
            let a = &mut around[v];
            a.sort_unstable();
            a.dedup();
            let o = &mut out_of[v];
            o.sort_unstable();
            let pinch = o.windows(2).any(|w| w[0] == w[1]);
            a.len() >= 3 || pinch
        })
        .collect();
    drop(around);
    drop(out_of);

    // The next boundary half-edge of the same region after boundary half-edge h, turning
    // about its end through the region's triangles.
    let next_boundary = |h: usize| -> usize {
        let r = region[h / 3];
        let mut g = HalfEdges::next(h);
        for _ in 0..nh {
            match he.twin(g) {
                Some(o) if region[o / 3] == r => g = HalfEdges::next(o),
                _ => return g,
            }
        }
        g
    };

    // Edges: walk each border from a vertex to the next.
    let mut side: Vec<(u32, bool)> = vec![(NONE, false); nh];
    let mut vertex_id: HashMap<u32, usize> = HashMap::new();
    let mut vertices: Vec<u32> = Vec::new();
    let mut edges: Vec<TopoEdge> = Vec::new();
    let mut first: Vec<[usize; 2]> = Vec::new();
    let mut last: Vec<[usize; 2]> = Vec::new();
    let mut id_of = |v: u32, vertices: &mut Vec<u32>| -> usize {
        *vertex_id.entry(v).or_insert_with(|| {
            vertices.push(v);
            vertices.len() - 1
        })
    };
    for pass in 0..2 {
        for h0 in 0..nh {
            if !boundary(h0) || side[h0].0 != NONE {
                continue;
            }
            let o = he.origin(h0);
            if !is_vertex[o as usize] {
                if pass == 0 {
                    continue;
                }
                // A closed border without a vertex: its first mesh vertex becomes one.
                is_vertex[o as usize] = true;
            }
            let e = edges.len() as u32;
            let (left, right) = (region[h0 / 3], other(h0));
            let mut chain = vec![o];
            let mut h = h0;
            let mut halves = Vec::new();
            loop {
                if side[h].0 != NONE || other(h) != right {
                    return Err(Error::InvalidInput(
                        "reconstruct: the borders between the surfaces do not form simple \
                         chains (a mesh vertex where the regions meet in an unexpected way)"
                            .into(),
                    ));
                }
                side[h] = (e, true);
                halves.push(h);
                let d = he.dest(h);
                chain.push(d);
                if is_vertex[d as usize] {
                    break;
                }
                h = next_boundary(h);
            }
            for &g in &halves {
                if let Some(t) = he.twin(g) {
                    side[t] = (e, false);
                }
            }
            let start = id_of(o, &mut vertices);
            let end = id_of(*chain.last().unwrap_or(&o), &mut vertices);
            let hl = *halves.last().unwrap_or(&h0);
            first.push([h0, he.twin(hl).unwrap_or(usize::MAX)]);
            last.push([hl, he.twin(h0).unwrap_or(usize::MAX)]);
            edges.push(TopoEdge {
                chain,
                left,
                right,
                start,
                end,
            });
        }
    }

    // Loops: per region, follow the oriented edges end to start.
    let mut starts: HashMap<usize, (usize, bool)> = HashMap::new();
    for (e, f) in first.iter().enumerate() {
        starts.insert(f[0], (e, true));
        if f[1] != usize::MAX {
            starts.insert(f[1], (e, false));
        }
    }
    let mut used = vec![[false; 2]; edges.len()];
    let mut loops: Vec<Vec<Vec<(usize, bool)>>> = vec![Vec::new(); nr];
    for e0 in 0..edges.len() {
        for dir in [true, false] {
            let d0 = usize::from(!dir);
            if used[e0][d0] || (!dir && edges[e0].right == OUTSIDE) {
                continue;
            }
            let r = if dir { edges[e0].left } else { edges[e0].right };
            let mut cycle = Vec::new();
            let (mut e, mut fwd) = (e0, dir);
            loop {
                let d = usize::from(!fwd);
                if used[e][d] {
                    if (e, fwd) == (e0, dir) {
                        break;
                    }
                    return Err(Error::InvalidInput(
                        "reconstruct: a face's border does not close into loops".into(),
                    ));
                }
                used[e][d] = true;
                cycle.push((e, fwd));
                let h = next_boundary(last[e][d]);
                match starts.get(&h) {
                    Some(&(ne, nf)) => (e, fwd) = (ne, nf),
                    None => {
                        return Err(Error::InvalidInput(
                            "reconstruct: a face's border does not close into loops".into(),
                        ))
                    }
                }
            }
            loops[r as usize].push(cycle);
        }
    }
    Ok(Topology {
        region_of_face: region,
        surface_of_region,
        cuts,
        vertices,
        edges,
        loops,
    })
}

/// The position of mesh vertex `v`.
pub(crate) fn position(mesh: &TriMesh, v: u32) -> Point3 {
    mesh.vertices.positions[v as usize]
}

impl Topology {
    /// Removes the edges flagged in `drop` (edges whose two faces touch in a point only: a
    /// plane tangent to a fillet's corner ball), merging the two ends of each into one vertex.
    /// An edge that is the only edge of a loop is kept.
    pub(crate) fn collapse_edges(&mut self, drop: &[bool]) {
        let alone: Vec<bool> = (0..self.edges.len())
            .map(|e| {
                self.loops
                    .iter()
                    .flatten()
                    .any(|l| l.len() == 1 && l[0].0 == e)
            })
            .collect();
        let nv = self.vertices.len();
        let mut sets = crate::geometry::union_find::UnionFind::new(nv);
        let mut dropped = vec![false; self.edges.len()];
        for (e, edge) in self.edges.iter().enumerate() {
            if !drop[e] || alone[e] {
                continue;
            }
            sets.union(edge.start as u32, edge.end as u32);
            dropped[e] = true;
        }
        if !dropped.contains(&true) {
            return;
        }
        let mut new_vertex = vec![usize::MAX; nv];
        let mut vertices = Vec::new();
        for v in 0..nv {
            let r = sets.find(v as u32) as usize;
            if new_vertex[r] == usize::MAX {
                new_vertex[r] = vertices.len();
                vertices.push(self.vertices[r]);
            }
            new_vertex[v] = new_vertex[r];
        }
        let mut new_edge = vec![usize::MAX; self.edges.len()];
        let mut edges = Vec::new();
        for (e, edge) in self.edges.iter().enumerate() {
            if dropped[e] {
                continue;
            }
            new_edge[e] = edges.len();
            edges.push(TopoEdge {
                start: new_vertex[edge.start],
                end: new_vertex[edge.end],
                ..edge.clone()
            });
        }
        for loops in &mut self.loops {
            for l in loops.iter_mut() {
                l.retain(|&(e, _)| !dropped[e]);
                for (e, _) in l.iter_mut() {
                    *e = new_edge[*e];
                }
            }
            loops.retain(|l| !l.is_empty());
        }
        self.vertices = vertices;
        self.edges = edges;
    }
}
