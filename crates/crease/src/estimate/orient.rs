//! Consistent normal orientation by minimum-spanning-tree propagation (Hoppe et al. 1992,
//! "Surface reconstruction from unorganized points", section 3.3).
//!
//! The Riemannian graph is the symmetrised k-nearest-neighbour graph (an edge i–j when j is
//! among the neighbours of i or i among those of j) with weight 1 − |n_i·n_j|, small between
//! nearly parallel normals, so the tree crosses regions of high curvature last and as few times
//! as possible (an edge longer than ten times the median comes last: a far outlier's). Its
//! minimum spanning forest (Kruskal: edges sorted by (weight, i, j), union–find)
//! is traversed breadth-first from one seed per connected component — the point with the largest
//! z (ties: smallest index), whose normal is turned to point +z (outward on a closed surface) —
//! and each child normal is flipped when its dot product with its parent's is negative.
//! Deterministic: the result does not depend on the thread count.

use rayon::prelude::*;

use crate::geometry::{vec3, Csr, Point3};
use crate::spatial::Neighborhoods;
use crate::{Error, Result};

/// Normals with consistent signs: `normals` flipped where needed (never otherwise changed),
/// in input order. See the module documentation for the algorithm.
///
/// Errors if the lengths of `points`, `normals` and `nbrs` differ or a neighbour index is out of
/// range.
pub fn orient_normals(
    points: &[Point3],
    normals: &[Point3],
    nbrs: &Neighborhoods,
) -> Result<Vec<Point3>> {
    orient_normals_k(points, normals, nbrs, nbrs.k())
}

/// [`orient_normals`] over the first `k` neighbours of each row (the graph of a smaller k from
/// lists computed for a larger one).
///
/// Errors as [`orient_normals`], and when `k` is 0 or exceeds `nbrs.k()`.
pub fn orient_normals_k(
    points: &[Point3],
    normals: &[Point3],
    nbrs: &Neighborhoods,
    k: usize,
) -> Result<Vec<Point3>> {
    if k == 0 || k > nbrs.k() {
        return Err(Error::InvalidArgument(format!(
            "orient normals over k = {k} neighbours from lists of {}",
            nbrs.k()
        )));
    }
    let n = points.len();
    if normals.len() != n || nbrs.len() != n {
        return Err(Error::InvalidArgument(format!(
            "orient normals: {n} points, {} normals, {} neighbourhoods",
            normals.len(),
            nbrs.len()
        )));
    }
    if nbrs.csr().indices.iter().any(|&j| j as usize >= n) {
        return Err(Error::InvalidArgument(format!(
            "orient normals: a neighbour index is out of range for {n} points"
        )));
    }
    let tree = spanning_forest(points, normals, nbrs, k);
    let mut out = normals.to_vec();
    let mut done = vec![false; n];
    let mut queue: Vec<u32> = Vec::with_capacity(n);
    for seed in component_seeds(points, &tree) {
        let s = seed as usize;
        if out[s][2] < 0.0 {
            out[s] = vec3::scale(out[s], -1.0);
        }
        done[s] = true;
        queue.clear();
        queue.push(seed);
        let mut head = 0;
        while let Some(&v) = queue.get(head) {
            head += 1;
            let nv = out[v as usize];
            for &w in tree.row(v as usize) {
                let wu = w as usize;
                if !done[wu] {
                    done[wu] = true;
                    if vec3::dot(nv, out[wu]) < 0.0 {
                        out[wu] = vec3::scale(out[wu], -1.0);
                    }
                    queue.push(w);
                }
            }
        }
    }
    Ok(out)
}

/// The minimum spanning forest of the symmetrised kNN graph weighted by 1 − |n_i·n_j|, as a
/// symmetric adjacency CSR.
fn spanning_forest(points: &[Point3], normals: &[Point3], nbrs: &Neighborhoods, k: usize) -> Csr {
    let n = normals.len();
    let far = far_edge(points, nbrs, k);
    // Each undirected edge once: from i to j > i, and from i to j < i only when i is not in
    // j's row (then j's row did not produce it). Weight as f32 bits (order-preserving for
    // non-negative floats), then the endpoints: a total, deterministic order.
    let mut edges: Vec<[u32; 3]> = (0..n)
        .into_par_iter()
        .flat_map_iter(|i| {
            let row = nbrs.prefix(i, k);
            row.iter().filter_map(move |&j| {
                let ju = j as usize;
                if ju == i || (ju < i && nbrs.prefix(ju, k).contains(&(i as u32))) {
                    return None;
                }
                let (a, b) = if ju < i { (j, i as u32) } else { (i as u32, j) };
                let d = vec3::dot(normals[a as usize], normals[b as usize]).abs();
                let w = if !d.is_finite() {
                    1.0
                } else if vec3::dist(points[a as usize], points[b as usize]) > far {
                    FAR_WEIGHT
                } else {
                    (1.0 - d).max(0.0)
                };
                Some([(w as f32).to_bits(), a, b])
            })
        })
        .collect();
    edges.par_sort_unstable();
    edges.dedup();
    let mut uf = UnionFind::new(n);
    let mut tree: Vec<[u32; 2]> = Vec::with_capacity(n.saturating_sub(1));
    for &[_, a, b] in &edges {
        if uf.union(a, b) {
            tree.push([a, b]);
            if tree.len() + 1 == n {
                break;
            }
        }
    }
    drop(edges);
    let mut offsets = vec![0u32; n + 1];
    for &[a, b] in &tree {
        offsets[a as usize + 1] += 1;
        offsets[b as usize + 1] += 1;
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill: Vec<u32> = offsets[..n].to_vec();
    let mut indices = vec![0u32; 2 * tree.len()];
    for &[a, b] in &tree {
        indices[fill[a as usize] as usize] = b;
        fill[a as usize] += 1;
        indices[fill[b as usize] as usize] = a;
        fill[b as usize] += 1;
    }
    Csr { offsets, indices }
}

/// Edges longer than this many times the median edge of the graph come last in the tree
/// ([`FAR_WEIGHT`]): a far outlier's.
const FAR_EDGE: f64 = 10.0;

/// The weight of an edge longer than [`FAR_EDGE`] times the median: above every other (at most
/// 1). The agreement of two normals that far apart says nothing: a point 1e19 away from a cube
/// has the cube's points for neighbours at distances equal to round-off, on any face, and the
/// tree went through it from the top face to the bottom one, turning the bottom in (492 of a
/// 3000-point cube's normals outward; 2998 without the point). Last, such an edge joins the
/// tree only where nothing else does: the outlier a leaf.
const FAR_WEIGHT: f64 = 2.0;

/// [`FAR_EDGE`] times the median length of the graph's edges (infinite when that is zero or
/// undefined).
fn far_edge(points: &[Point3], nbrs: &Neighborhoods, k: usize) -> f64 {
    let mut lengths: Vec<f64> = (0..points.len())
        .into_par_iter()
        .flat_map_iter(|i| {
            nbrs.prefix(i, k)
                .iter()
                .filter(move |&&j| j as usize != i)
                .map(move |&j| vec3::dist(points[i], points[j as usize]))
        })
        .collect();
    if lengths.is_empty() {
        return f64::INFINITY;
    }
    let mid = lengths.len() / 2;
    let (_, m, _) = lengths.select_nth_unstable_by(mid, f64::total_cmp);
    if *m > 0.0 && m.is_finite() {
        FAR_EDGE * *m
    } else {
        f64::INFINITY
    }
}

/// One seed per connected component of `tree`: its point with the largest z (ties: smallest
/// index; non-finite z counts as −∞), in increasing index order.
fn component_seeds(points: &[Point3], tree: &Csr) -> Vec<u32> {
    let n = points.len();
    let mut comp = vec![u32::MAX; n];
    let mut seeds = Vec::new();
    let mut stack = Vec::new();
    for start in 0..n {
        if comp[start] != u32::MAX {
            continue;
        }
        let id = seeds.len() as u32;
        comp[start] = id;
        stack.push(start as u32);
        let z = |i: usize| {
            let z = points[i][2];
            if z.is_finite() {
                z
            } else {
                f64::NEG_INFINITY
            }
        };
        let mut best = start;
        while let Some(v) = stack.pop() {
            let vu = v as usize;
            if z(vu) > z(best) || (z(vu) == z(best) && vu < best) {
                best = vu;
            }
            for &w in tree.row(vu) {
                if comp[w as usize] == u32::MAX {
                    comp[w as usize] = id;
                    stack.push(w);
                }
            }
        }
        seeds.push(best as u32);
    }
    seeds.sort_unstable();
    seeds
}

/// Disjoint sets with path halving and union by size.
struct UnionFind {
    parent: Vec<u32>,
    size: Vec<u32>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
            size: vec![1; n],
        }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let g = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = g;
            x = g;
        }
        x
    }

    /// Joins the sets of `a` and `b`; false if they were already one.
    fn union(&mut self, a: u32, b: u32) -> bool {
        let (mut ra, mut rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        if self.size[ra as usize] < self.size[rb as usize] {
            std::mem::swap(&mut ra, &mut rb);
        }
        self.parent[rb as usize] = ra;
        self.size[ra as usize] += self.size[rb as usize];
        true
    }
}
