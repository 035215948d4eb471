//! Steps 2 to 6 of demarsin2007 (Algorithm 1): the cluster graph G_all (section 2.3), its
//! extension G_extended (2.4), the pruned minimum spanning tree G_pruned_mst (2.5), branch
//! pruning G_pruned_branches (2.6, Algorithm 2) and closing G_closed (2.7).
//!
//! The graph is small (one vertex per cluster, about one per point along the edges and one per
//! face), so it is a plain adjacency list with sorted rows; every step visits vertices and
//! edges in a fixed order, so results are deterministic.

use crate::geometry::union_find::UnionFind;
use rayon::prelude::*;

use crate::geometry::{vec3, Csr, Point3};
use crate::spatial::KdIndex;

/// An undirected graph over cluster vertices with sorted adjacency rows.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ClusterGraph {
    adj: Vec<Vec<u32>>,
}

impl ClusterGraph {
    /// A graph of `n` vertices and no edges.
    pub fn new(n: usize) -> Self {
        ClusterGraph {
            adj: vec![Vec::new(); n],
        }
    }

    /// Number of vertices (including isolated ones).
    pub fn num_vertices(&self) -> usize {
        self.adj.len()
    }

    /// Neighbours of `v`, sorted.
    pub fn neighbors(&self, v: u32) -> &[u32] {
        &self.adj[v as usize]
    }

    /// Degree of `v`.
    pub fn degree(&self, v: u32) -> usize {
        self.adj[v as usize].len()
    }

    /// True when `a` and `b` are adjacent.
    pub fn has_edge(&self, a: u32, b: u32) -> bool {
        self.adj[a as usize].binary_search(&b).is_ok()
    }

    /// Adds the edge a–b (no effect if present or a == b).
    pub fn add_edge(&mut self, a: u32, b: u32) {
        if a == b {
            return;
        }
        if let Err(p) = self.adj[a as usize].binary_search(&b) {
            self.adj[a as usize].insert(p, b);
            if let Err(q) = self.adj[b as usize].binary_search(&a) {
                self.adj[b as usize].insert(q, a);
            }
        }
    }

    /// Removes the edge a–b (no effect if absent).
    pub fn remove_edge(&mut self, a: u32, b: u32) {
        if let Ok(p) = self.adj[a as usize].binary_search(&b) {
            self.adj[a as usize].remove(p);
        }
        if let Ok(q) = self.adj[b as usize].binary_search(&a) {
            self.adj[b as usize].remove(q);
        }
    }

    /// Edges `[a, b]` with a < b, sorted.
    pub fn edges(&self) -> Vec<[u32; 2]> {
        let mut out = Vec::new();
        for (a, row) in self.adj.iter().enumerate() {
            for &b in row {
                if (a as u32) < b {
                    out.push([a as u32, b]);
                }
            }
        }
        out
    }

    /// Number of edges.
    pub fn num_edges(&self) -> usize {
        self.adj.iter().map(Vec::len).sum::<usize>() / 2
    }

    /// Number of vertices with at least one edge.
    pub fn num_active_vertices(&self) -> usize {
        self.adj.iter().filter(|r| !r.is_empty()).count()
    }

    /// Length in edges of the shortest path from `a` to `b` if it is at most `limit`.
    pub fn path_within(&self, a: u32, b: u32, limit: usize) -> Option<usize> {
        if a == b {
            return Some(0);
        }
        let mut frontier = vec![a];
        let mut seen = vec![a];
        for depth in 1..=limit {
            let mut next = Vec::new();
            for &v in &frontier {
                for &w in self.neighbors(v) {
                    if w == b {
                        return Some(depth);
                    }
                    if !seen.contains(&w) {
                        seen.push(w);
                        next.push(w);
                    }
                }
            }
            if next.is_empty() {
                return None;
            }
            frontier = next;
        }
        None
    }
}

/// The clusters as graph vertices: centre of mass and size (section 2.3).
#[derive(Debug, Clone, PartialEq)]
pub struct Clusters {
    /// Centre of mass of every cluster (its representative point).
    pub centers: Vec<Point3>,
    /// Number of points of every cluster.
    pub sizes: Vec<u32>,
    /// Clusters smaller than the mean cluster size (section 2.3's heuristic).
    pub small: Vec<bool>,
}

/// Step 2: G_all. Two clusters are adjacent when a point of one has a point of the other in its
/// (symmetrised) 1-ring: their points' 1-ring neighbourhoods overlap.
pub fn build_all(
    points: &[Point3],
    labels: &[u32],
    sizes: &[u32],
    adjacency: &Csr,
) -> (Clusters, ClusterGraph) {
    let m = sizes.len();
    let mut sums = vec![[0.0f64; 3]; m];
    for (p, &l) in points.iter().zip(labels) {
        sums[l as usize] = vec3::add(sums[l as usize], *p);
    }
    let centers: Vec<Point3> = sums
        .iter()
        .zip(sizes)
        .map(|(s, &c)| vec3::scale(*s, 1.0 / c.max(1) as f64))
        .collect();
    let mean = sizes.iter().map(|&s| s as f64).sum::<f64>() / m.max(1) as f64;
    let small = sizes.iter().map(|&s| (s as f64) < mean).collect();
    let mut pairs: Vec<[u32; 2]> = Vec::new();
    for (p, &lp) in labels.iter().enumerate() {
        if p >= adjacency.num_rows() {
            break;
        }
        for &q in adjacency.row(p) {
            let lq = labels[q as usize];
            if lp < lq {
                pairs.push([lp, lq]);
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    let mut g = ClusterGraph::new(m);
    for [a, b] in pairs {
        g.add_edge(a, b);
    }
    (
        Clusters {
            centers,
            sizes: sizes.to_vec(),
            small,
        },
        g,
    )
}

/// Step 3: G_extended. Adds an edge between two small clusters that share two large
/// neighbouring clusters, when their representatives are closer than the largest distance
/// between two adjacent small clusters of G_all (section 2.4). Returns the number added.
pub fn extend(clusters: &Clusters, g: &mut ClusterGraph) -> usize {
    let m = clusters.sizes.len();
    let dist =
        |a: u32, b: u32| vec3::dist(clusters.centers[a as usize], clusters.centers[b as usize]);
    let mut bound = 0.0f64;
    for [a, b] in g.edges() {
        if clusters.small[a as usize] && clusters.small[b as usize] {
            bound = bound.max(dist(a, b));
        }
    }
    // Group small clusters by each pair of large neighbours.
    let mut keyed: Vec<([u32; 2], u32)> = Vec::new();
    for s in 0..m as u32 {
        if !clusters.small[s as usize] {
            continue;
        }
        let large: Vec<u32> = g
            .neighbors(s)
            .iter()
            .copied()
            .filter(|&l| !clusters.small[l as usize])
            .collect();
        for i in 0..large.len() {
            for j in i + 1..large.len() {
                keyed.push(([large[i], large[j]], s));
            }
        }
    }
    keyed.sort_unstable();
    let mut new_edges: Vec<[u32; 2]> = Vec::new();
    let mut start = 0;
    while start < keyed.len() {
        let key = keyed[start].0;
        let mut end = start;
        while end < keyed.len() && keyed[end].0 == key {
            end += 1;
        }
        // Sweep along x: only pairs closer than the bound can join.
        let mut group: Vec<u32> = keyed[start..end].iter().map(|k| k.1).collect();
        group.sort_by(|&a, &b| {
            clusters.centers[a as usize][0]
                .total_cmp(&clusters.centers[b as usize][0])
                .then(a.cmp(&b))
        });
        for i in 0..group.len() {
            let xi = clusters.centers[group[i] as usize][0];
            for &t in &group[i + 1..] {
                if clusters.centers[t as usize][0] - xi >= bound {
                    break;
                }
                let s = group[i];
                if dist(s, t) < bound && !g.has_edge(s, t) {
                    new_edges.push([s.min(t), s.max(t)]);
                }
            }
        }
        start = end;
    }
    new_edges.sort_unstable();
    new_edges.dedup();
    for &[a, b] in &new_edges {
        g.add_edge(a, b);
    }
    new_edges.len()
}

/// Step 4: the minimum spanning forest of G_extended with weights = distances between
/// representatives, edges involving a large cluster weighted above every small–small edge
/// (Kruskal; ties by vertex ids), then without the edges involving a large cluster:
/// G_pruned_mst (section 2.5).
pub fn pruned_mst(clusters: &Clusters, g: &ClusterGraph) -> ClusterGraph {
    let m = g.num_vertices();
    let mut edges: Vec<(bool, f64, [u32; 2])> = g
        .edges()
        .into_iter()
        .map(|[a, b]| {
            let large = !clusters.small[a as usize] || !clusters.small[b as usize];
            (
                large,
                vec3::dist(clusters.centers[a as usize], clusters.centers[b as usize]),
                [a, b],
            )
        })
        .collect();
    edges.sort_by(|x, y| x.0.cmp(&y.0).then(x.1.total_cmp(&y.1)).then(x.2.cmp(&y.2)));
    let mut sets = UnionFind::new(m);
    let mut out = ClusterGraph::new(m);
    for (large, _, [a, b]) in edges {
        if sets.union(a, b) && !large {
            out.add_edge(a, b);
        }
    }
    out
}

/// Depth of the branch that starts at `p` through its neighbour `q` (longest path from p into
/// that side, in edges), capped at `cap`. The graph must be a forest.
fn branch_depth(g: &ClusterGraph, p: u32, q: u32, cap: usize) -> usize {
    // Iterative DFS with (vertex, parent, depth).
    let mut best = 1;
    let mut stack = vec![(q, p, 1usize)];
    while let Some((v, parent, d)) = stack.pop() {
        best = best.max(d);
        if best >= cap {
            return cap;
        }
        for &w in g.neighbors(v) {
            if w != parent {
                stack.push((w, v, d + 1));
            }
        }
    }
    best
}

/// Removes the branch from `p` through `q` (every vertex on q's side). Forest only.
fn remove_branch(g: &mut ClusterGraph, p: u32, q: u32) {
    let mut stack = vec![(q, p)];
    let mut cut = Vec::new();
    while let Some((v, parent)) = stack.pop() {
        cut.push([parent, v]);
        for &w in g.neighbors(v) {
            if w != parent {
                stack.push((w, v));
            }
        }
    }
    for [a, b] in cut {
        g.remove_edge(a, b);
    }
}

/// Step 5: Algorithm 2 with maximum branch length `d_max` (section 2.6), repeated until
/// nothing changes. Returns the number of branches removed.
pub fn prune_branches(g: &mut ClusterGraph, d_max: usize) -> usize {
    let mut removed = 0;
    loop {
        let mut changed = false;
        for p in 0..g.num_vertices() as u32 {
            if g.degree(p) <= 2 {
                continue;
            }
            let depths: Vec<(u32, usize)> = g
                .neighbors(p)
                .to_vec()
                .into_iter()
                .map(|q| (q, branch_depth(g, p, q, d_max)))
                .collect();
            let long = depths.iter().filter(|d| d.1 >= d_max).count();
            let short: Vec<(u32, usize)> = depths.iter().copied().filter(|d| d.1 < d_max).collect();
            if long >= 2 && !short.is_empty() {
                for (q, _) in short {
                    remove_branch(g, p, q);
                    removed += 1;
                }
                changed = true;
            } else if long == 1 && short.len() >= 2 {
                // Keep only the deepest short branch (the lowest id on ties).
                let keep = short
                    .iter()
                    .max_by(|a, b| a.1.cmp(&b.1).then(b.0.cmp(&a.0)))
                    .map(|k| k.0);
                for (q, _) in short {
                    if Some(q) != keep {
                        remove_branch(g, p, q);
                        removed += 1;
                    }
                }
                changed = true;
            }
        }
        if !changed {
            return removed;
        }
    }
}

/// What the closing step did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct CloseReport {
    /// Endpoints before closing.
    pub endpoints_before: usize,
    /// Connections to another endpoint (case 1).
    pub endpoint_links: usize,
    /// Connections to an interior vertex (case 2).
    pub interior_links: usize,
    /// Edges removed by pruning the branches that still end.
    pub pruned_edges: usize,
}

/// How far back along a branch the direction of its end is measured (edges).
const DIRECTION_STEPS: usize = 10;

/// Cosine of the widest angle between a branch's direction and a link from its end (60°).
const AHEAD_COS: f64 = 0.5;

/// Branches shorter than this (edges) have no reliable direction: their links may go any way.
const DIRECTION_MIN_STEPS: usize = 3;

/// Direction in which the branch ending at `p` (degree 1) points: from the centre of mass of
/// the [`DIRECTION_STEPS`] vertices behind `p` (fewer where a junction or the other end comes
/// first) to `p`. The centre of mass rather than the farthest vertex, because on a curved line
/// (a circle of about 45 clusters) the chord to the tenth vertex back already turns 40° away
/// from the tangent, while the centre of mass is about five vertices back and still follows
/// hooks (a branch whose last clusters turn back along itself). `None` for a branch shorter
/// than [`DIRECTION_MIN_STEPS`] edges: a fragment of a line, whose two or three clusters may
/// sit side by side across it.
fn end_direction(clusters: &Clusters, g: &ClusterGraph, p: u32) -> Option<Point3> {
    let (mut prev, mut v) = (p, *g.neighbors(p).first()?);
    let mut sum = clusters.centers[v as usize];
    let mut steps = 1;
    while steps < DIRECTION_STEPS && g.degree(v) == 2 {
        let Some(next) = g.neighbors(v).iter().copied().find(|&w| w != prev) else {
            break;
        };
        prev = v;
        v = next;
        sum = vec3::add(sum, clusters.centers[v as usize]);
        steps += 1;
    }
    if steps < DIRECTION_MIN_STEPS {
        return None;
    }
    let centre = vec3::scale(sum, 1.0 / steps as f64);
    let u = vec3::sub(clusters.centers[p as usize], centre);
    let len = vec3::norm(u);
    (len > 0.0).then(|| vec3::scale(u, 1.0 / len))
}

/// Cosine of the narrowest angle between a case-2 link and the line it joins (30°).
const ALONG_COS: f64 = 0.87;

/// True when the link from `p` to `q` runs along the line through `q` (within 30°): the
/// direction of that line is the principal axis of the vertices within 3 edges of `q`. A
/// branch that ends beside a line and parallel to it is a spur grown along the feature, not a
/// line meeting it; a correct case-2 link (a T-junction, a corner) meets the line at an angle.
fn along_line(clusters: &Clusters, g: &ClusterGraph, p: u32, q: u32) -> bool {
    let mut ring = vec![q];
    let mut frontier = vec![q];
    for _ in 0..3 {
        let mut next = Vec::new();
        for &v in &frontier {
            for &w in g.neighbors(v) {
                if w != p && !ring.contains(&w) {
                    ring.push(w);
                    next.push(w);
                }
            }
        }
        frontier = next;
    }
    let pts: Vec<Point3> = ring.iter().map(|&v| clusters.centers[v as usize]).collect();
    let Some(plane) = crate::geometry::plane::fit_plane(pts.iter().map(|&p| (p, 1.0))) else {
        return false;
    };
    let axis = plane.axes[2];
    let u = vec3::sub(clusters.centers[q as usize], clusters.centers[p as usize]);
    vec3::dot(u, axis).abs() > ALONG_COS * vec3::norm(u)
}

/// Step 6: the connect algorithm (section 2.7) for every endpoint, then pruning of the branches
/// that still end.
///
/// The paper's candidate set N is the `n` nearest graph vertices of the endpoint p, and a link
/// is refused when it would close a cycle of at most `d` edges; endpoints are handled one after
/// the other. Taken literally, N is mostly made of p's own branch (every vertex within n steps
/// behind it, all refused by the path test), so a gap longer than about n/2 spacings is never
/// bridged, while vertices beside the branch (a parallel line, the far side of a corner) are
/// accepted: on the synthetic parts (`examples/lines_synth.rs`) that lost edges, cut chamfer
/// lines across and added spurious junctions (`docs/experiments/sharp-lines.md`). crease keeps
/// the two cases and the path test of the paper and changes how N is formed and the order of
/// the links:
/// - N holds the `n` nearest vertices that may be linked: no path of at most `d` edges to p,
///   within `2 n h` of p (h: the median edge length of the graph; the paper's n nearest span
///   about n h along a line, the bound doubles it), and ahead of the branch: within 60° of its
///   direction (`end_direction`; fragments shorter than 3 edges have none and look all
///   ways), unless closer than 2 h (a line that ends on the side of another, as fillet borders
///   end on their region's boundary).
/// - Case 1 for all endpoints together: endpoint pairs that are in each other's N are linked,
///   nearest pairs first; this repeats, since joined fragments gain a direction; then pairs
///   with one end in the other's N.
/// - Case 2 for the endpoints left: the nearest vertex of N that had more than one edge before
///   the closing, unless the link runs along the line through that vertex (`along_line`: a
///   spur beside its own feature) or closes a cycle of at most `2 d` edges (the two ends of a
///   gap linking past each other to the opposite sides).
///
/// On the synthetic parts at 1 to 10 % noise this gives exactly the parts' curve networks,
/// where the literal reading did not.
pub fn close(clusters: &Clusters, g: &mut ClusterGraph, n: usize, d: usize) -> CloseReport {
    let mut report = CloseReport::default();
    let active: Vec<u32> = (0..g.num_vertices() as u32)
        .filter(|&v| g.degree(v) > 0)
        .collect();
    if active.is_empty() {
        return report;
    }
    let pts: Vec<Point3> = active
        .iter()
        .map(|&v| clusters.centers[v as usize])
        .collect();
    let Some(index) = KdIndex::new(&pts) else {
        return report;
    };
    let mut lengths: Vec<f64> = g
        .edges()
        .iter()
        .map(|&[a, b]| vec3::dist(clusters.centers[a as usize], clusters.centers[b as usize]))
        .collect();
    lengths.sort_by(f64::total_cmp);
    let h = lengths.get(lengths.len() / 2).copied().unwrap_or(0.0);
    let reach = 2.0 * n as f64 * h;
    let endpoints: Vec<u32> = active
        .iter()
        .copied()
        .filter(|&v| g.degree(v) == 1)
        .collect();
    report.endpoints_before = endpoints.len();
    let interior: Vec<bool> = (0..g.num_vertices() as u32)
        .map(|v| g.degree(v) > 1)
        .collect();
    // N of an endpoint: up to n vertices ahead of its branch within reach, nearest first.
    let candidates = |g: &ClusterGraph, p: u32| -> Vec<(f64, u32)> {
        let mut near = Vec::with_capacity(n);
        let dir = end_direction(clusters, g, p);
        let cp = clusters.centers[p as usize];
        // The index returns squared distances.
        for (j, dist2) in index.nearest(&cp, 8 * n + 1) {
            if dist2 > reach * reach || near.len() == n {
                break;
            }
            let q = active[j as usize];
            let u = vec3::sub(clusters.centers[q as usize], cp);
            let len = vec3::norm(u);
            let behind =
                len > 2.0 * h && dir.is_some_and(|dir| vec3::dot(u, dir) < AHEAD_COS * len);
            if q != p && !g.has_edge(p, q) && !behind && g.path_within(p, q, d).is_none() {
                near.push((dist2.sqrt(), q));
            }
        }
        near
    };
    // Case 1 in rounds: endpoint pairs that are in each other's N, nearest pairs first; the
    // joined fragments then have longer branches, hence directions, for the next round. When
    // no mutual pair is left, pairs in which one of the two ends lies ahead of the other.
    let mut mutual = true;
    loop {
        let free: Vec<u32> = endpoints
            .iter()
            .copied()
            .filter(|&p| g.degree(p) == 1)
            .collect();
        let sets: Vec<(u32, Vec<(f64, u32)>)> =
            free.par_iter().map(|&p| (p, candidates(g, p))).collect();
        let in_set = |p: u32, q: u32| {
            sets.binary_search_by_key(&p, |s| s.0)
                .is_ok_and(|i| sets[i].1.iter().any(|&(_, w)| w == q))
        };
        let mut pairs: Vec<(f64, u32, u32)> = sets
            .iter()
            .flat_map(|(p, near)| {
                near.iter()
                    .filter(|&&(_, q)| g.degree(q) == 1)
                    .map(move |&(dist, q)| (dist, *p, q))
            })
            .filter(|&(_, p, q)| !mutual || in_set(q, p))
            .map(|(dist, p, q)| (dist, p.min(q), p.max(q)))
            .collect();
        pairs.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        pairs.dedup();
        let mut linked = 0;
        for (_, p, q) in pairs {
            if g.degree(p) == 1 && g.degree(q) == 1 && g.path_within(p, q, d).is_none() {
                g.add_edge(p, q);
                linked += 1;
            }
        }
        report.endpoint_links += linked;
        if linked == 0 {
            if !mutual {
                break;
            }
            mutual = false;
        }
    }
    // Case 2 for the endpoints still free: the nearest vertex of N that had more than one edge
    // before the closing.
    for &p in &endpoints {
        if g.degree(p) != 1 {
            continue;
        }
        let near = candidates(g, p);
        if let Some(&(_, q)) = near.iter().find(|&&(_, q)| {
            interior[q as usize]
                && !along_line(clusters, g, p, q)
                && g.path_within(p, q, 2 * d).is_none()
        }) {
            g.add_edge(p, q);
            report.interior_links += 1;
        }
    }
    // Prune every branch that still ends, back to its junction.
    let mut stack: Vec<u32> = (0..g.num_vertices() as u32)
        .filter(|&v| g.degree(v) == 1)
        .collect();
    stack.reverse();
    while let Some(v) = stack.pop() {
        if g.degree(v) != 1 {
            continue;
        }
        let u = g.neighbors(v)[0];
        g.remove_edge(v, u);
        report.pruned_edges += 1;
        if g.degree(u) == 1 {
            stack.push(u);
        }
    }
    report
}

/// The cloud's boundary as a graph (demarsin2007 Fig. 9: "it has a boundary which we extract
/// and include in the graph", just before the close step). Boundary points are those flagged by
/// the Delaunay 1-ring (the point lies on the hull of its projected neighbours); two boundary
/// points are linked when they are 1-ring neighbours. The minimum spanning forest of those
/// links (weights = distances) with its short branches pruned by Algorithm 2 gives the
/// boundary lines; the connect step later closes their gaps and joins them to the sharp lines.
///
/// Returns the boundary points (indices into `points`) and the graph over them (vertex i of
/// the graph is `ids[i]`).
pub fn boundary_graph(
    points: &[Point3],
    boundary: &[bool],
    adjacency: &Csr,
    d_max: usize,
) -> (Vec<u32>, ClusterGraph) {
    let ids: Vec<u32> = (0..points.len() as u32)
        .filter(|&i| boundary[i as usize])
        .collect();
    let mut local = vec![u32::MAX; points.len()];
    for (k, &i) in ids.iter().enumerate() {
        local[i as usize] = k as u32;
    }
    let mut links: Vec<(f64, [u32; 2])> = Vec::new();
    for (k, &i) in ids.iter().enumerate() {
        if i as usize >= adjacency.num_rows() {
            continue;
        }
        for &j in adjacency.row(i as usize) {
            let l = local[j as usize];
            if l != u32::MAX && (k as u32) < l {
                links.push((
                    vec3::dist(points[i as usize], points[j as usize]),
                    [k as u32, l],
                ));
            }
        }
    }
    links.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut sets = UnionFind::new(ids.len());
    let mut g = ClusterGraph::new(ids.len());
    for (_, [a, b]) in links {
        if sets.union(a, b) {
            g.add_edge(a, b);
        }
    }
    prune_branches(&mut g, d_max);
    (ids, g)
}

impl ClusterGraph {
    /// Appends the vertices and edges of `other`, its vertex i becoming `self.num_vertices() + i`.
    pub fn append(&mut self, other: &ClusterGraph) {
        let base = self.adj.len() as u32;
        self.adj.extend(
            other
                .adj
                .iter()
                .map(|row| row.iter().map(|&v| v + base).collect::<Vec<u32>>()),
        );
    }
}

/// Marks the small clusters that lie between two smooth patches: those from which at least two
/// distinct large clusters are reached within `hops` steps of G_all through small clusters.
///
/// A sharp edge is "the border between two large clusters" (section 2.4). With noise, the
/// 1-ring normals of a flat face scatter beyond α_max here and there and the face's large
/// cluster is sprinkled with islands of small clusters (section 3: "small clusters are created
/// at the noisy parts"); such islands see only their own face's large cluster, and the spanning
/// tree would otherwise wire them into spurious lines across the face.
pub fn between_patches(clusters: &Clusters, g: &ClusterGraph, hops: usize) -> Vec<bool> {
    let m = g.num_vertices();
    let mut out = vec![false; m];
    let mut seen: Vec<u32> = Vec::new();
    for s in 0..m as u32 {
        if !clusters.small[s as usize] {
            continue;
        }
        let mut large: Vec<u32> = Vec::new();
        seen.clear();
        seen.push(s);
        let mut frontier = vec![s];
        'search: for _ in 0..hops {
            let mut next = Vec::new();
            for &v in &frontier {
                for &w in g.neighbors(v) {
                    if !clusters.small[w as usize] {
                        if !large.contains(&w) {
                            large.push(w);
                            if large.len() >= 2 {
                                break 'search;
                            }
                        }
                    } else if !seen.contains(&w) {
                        seen.push(w);
                        next.push(w);
                    }
                }
            }
            frontier = next;
        }
        out[s as usize] = large.len() >= 2;
    }
    out
}
