//! Seed region creation (mizoguchi section 4): vertex labels from the principal curvatures
//! (Step 1, equation 2), cylinder / cone separation (Step 2, equation 3), torus labels from the
//! histogram of discretised curvatures (Step 3) and seed regions (Step 4, Table 1).
//!
//! **Scale.** The paper's thresholds are absolute (`ε = 0.01` in 1/length units, a curvature
//! step of 0.01) and so depend on the model's units. Here every curvature is made dimensionless
//! before it is compared, `κ̃ = κ · l̄` with `l̄` the mesh's mean edge length, and
//! `ε = min(eps_edge, eps_diagonal · l̄ / D)` in those units (`D` = bounding-box diagonal): the
//! first bound keeps flat parts flat under the curvature-estimation noise (which scales as
//! `1/l̄` for noise proportional to the edge length), the second keeps large radii (up to about
//! `D / eps_diagonal`) apart from planes on finely meshed models, where `κ l̄` of a real
//! cylinder becomes tiny. See [`LabelParams`] for the values.
//!
//! **Equation 3** averages `|(κ_i,max − κ_j,max) / κ_i,max|` over the 2-ring. Over all of the
//! 2-ring, every vertex within two edges of a cylinder's border with a plane (where
//! `κ_j,max = 0`) would score about 1 and turn into a cone, which wipes out narrow cylinders
//! (fillets a few edges wide); so only the 2-ring vertices with the cylinder / cone label take
//! part (the paper does not say which). Vertices with no such neighbour keep label 2.
//!
//! **Step 3** bins `κ̃_max` of the label-0 vertices with the step `torus_step` (dimensionless,
//! 0.01 as the paper) and labels torus every vertex whose bin, together with its two
//! neighbouring bins, holds more than `torus_fraction` of all vertices (a 3-bin window instead
//! of one bin: noise spreads one torus's `1/r` over neighbouring bins).

use rayon::prelude::*;

use crate::spatial::mesh_rings::{k_ring_layers, VertexSet};
use crate::spatial::Adjacency;

/// Vertex labels of equation 2 and Steps 2–3 (the paper's numbers), plus `SHARP` for sharp
/// vertices and vertices without a curvature estimate.
pub mod label {
    /// Label 0: none of the analytic types.
    pub const OTHER: u8 = 0;
    /// Label 1: plane.
    pub const PLANE: u8 = 1;
    /// Label 2: cylinder (cylinder / cone after Step 1).
    pub const CYLINDER: u8 = 2;
    /// Label 3: sphere.
    pub const SPHERE: u8 = 3;
    /// Label 4: cone (Step 2).
    pub const CONE: u8 = 4;
    /// Label 5: torus (Step 3).
    pub const TORUS: u8 = 5;
    /// Sharp vertex (section 3) or no estimate: takes no part in the seeds.
    pub const SHARP: u8 = 255;
}

/// Parameters of the labelling. `Default` = the paper's values in dimensionless form.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabelParams {
    /// ε1 = ε2 = ε3 of equation 2 in units of `1 / l̄` (paper: 0.01 in 1/length).
    pub eps_edge: f64,
    /// Upper bound of ε relative to the bounding-box diagonal `D`: `ε ≤ eps_diagonal / D`
    /// (default 0.5: radii above twice the diagonal count as flat, whatever the resolution).
    pub eps_diagonal: f64,
    /// Absolute ε (1/length) overriding both when set.
    pub eps_absolute: Option<f64>,
    /// `th_cyl_cone` of Step 2 (paper: 0.01 · 0.4).
    pub th_cyl_cone: f64,
    /// Step of the discretised `κ̃_max` histogram (paper: 0.01).
    pub torus_step: f64,
    /// `th_torus` as a fraction of all vertices (paper: 0.1–0.5 %; default 0.2 %).
    pub torus_fraction: f64,
    /// `th_seed` of Table 1 per label 1..=5 (plane 2, cylinder 4, sphere 5, cone 4, torus 7).
    pub th_seed: [usize; 5],
}

impl Default for LabelParams {
    fn default() -> Self {
        LabelParams {
            eps_edge: 0.01,
            eps_diagonal: 0.5,
            eps_absolute: None,
            th_cyl_cone: 0.004,
            torus_step: 0.01,
            torus_fraction: 0.002,
            th_seed: [2, 4, 5, 4, 7],
        }
    }
}

impl LabelParams {
    /// ε (1/length) for a mesh of mean edge `l̄` and bounding-box diagonal `diag`.
    pub fn epsilon(&self, mean_edge: f64, diag: f64) -> f64 {
        self.eps_absolute
            .unwrap_or_else(|| (self.eps_edge / mean_edge).min(self.eps_diagonal / diag))
    }

    /// `th_seed` of a label (usize::MAX for labels without seeds).
    pub fn seed_size(&self, l: u8) -> usize {
        match l {
            1..=5 => self.th_seed[l as usize - 1],
            _ => usize::MAX,
        }
    }
}

/// Step 1 (equation 2) for one vertex; `kmax` is the principal curvature of larger absolute
/// value.
pub fn curvature_label(kmax: f64, kmin: f64, eps: f64) -> u8 {
    if !(kmax.is_finite() && kmin.is_finite()) {
        label::SHARP
    } else if kmax.abs() < eps {
        label::PLANE
    } else if kmin.abs() < eps {
        label::CYLINDER
    } else if (kmax - kmin).abs() < eps && kmax * kmin > 0.0 {
        label::SPHERE
    } else {
        label::OTHER
    }
}

/// Steps 1–3: the label of every vertex.
///
/// Inputs: `kmax`, `kmin` per vertex (1/length), `sharp` flags, `topo` (mesh edges or a
/// cloud's neighbour graph), `eps` (1/length, see
/// [`LabelParams::epsilon`]), `mean_edge`.
/// Output: one label per vertex (module [`label`]), identical whatever the thread count.
pub fn vertex_labels(
    kmax: &[f64],
    kmin: &[f64],
    sharp: &[bool],
    topo: &impl Adjacency,
    eps: f64,
    mean_edge: f64,
    p: &LabelParams,
) -> Vec<u8> {
    let nv = kmax.len();
    let step1: Vec<u8> = (0..nv)
        .into_par_iter()
        .map(|i| {
            if sharp[i] {
                label::SHARP
            } else {
                curvature_label(kmax[i], kmin[i], eps)
            }
        })
        .collect();
    // Step 2: equation 3 over the cylinder-labelled part of the 2-ring.
    let mut labels: Vec<u8> = (0..nv)
        .into_par_iter()
        .map_init(
            || (VertexSet::default(), Vec::new()),
            |(set, ring), i| {
                if step1[i] != label::CYLINDER {
                    return step1[i];
                }
                k_ring_layers(topo, i as u32, 2, set, ring);
                let (mut s, mut n) = (0.0, 0usize);
                for &j in ring.iter() {
                    if step1[j as usize] == label::CYLINDER {
                        s += ((kmax[i] - kmax[j as usize]) / kmax[i]).abs();
                        n += 1;
                    }
                }
                if n > 0 && s / n as f64 > p.th_cyl_cone {
                    label::CONE
                } else {
                    label::CYLINDER
                }
            },
        )
        .collect();
    // Step 3: histogram of the discretised κ̃_max of label-0 vertices.
    let step = p.torus_step;
    let bin = |i: usize| (kmax[i] * mean_edge / step).round() as i64;
    let mut bins: Vec<i64> = (0..nv)
        .filter(|&i| labels[i] == label::OTHER && kmax[i].is_finite())
        .map(bin)
        .collect();
    bins.sort_unstable();
    // Saturating: a huge κ̃_max (a degenerate mesh) bins at i64::MAX.
    let count = |b: i64| -> usize {
        let lo = bins.partition_point(|&x| x < b.saturating_sub(1));
        let hi = bins.partition_point(|&x| x <= b.saturating_add(1));
        hi - lo
    };
    let th = p.torus_fraction * nv as f64;
    let torus: Vec<bool> = (0..nv)
        .into_par_iter()
        .map(|i| labels[i] == label::OTHER && kmax[i].is_finite() && count(bin(i)) as f64 > th)
        .collect();
    for (l, t) in labels.iter_mut().zip(torus) {
        if t {
            *l = label::TORUS;
        }
    }
    labels
}

/// Step 4: seed regions, the connected sets (along mesh edges) of vertices with the same label
/// 1..=5 holding at least `th_seed` of that label's vertices. Each seed lists its vertices in
/// breadth-first order from its smallest vertex id; seeds are ordered by that id.
pub fn seed_regions(labels: &[u8], topo: &impl Adjacency, p: &LabelParams) -> Vec<(u8, Vec<u32>)> {
    let nv = labels.len();
    let mut seen = vec![false; nv];
    let mut seeds = Vec::new();
    for s in 0..nv {
        let l = labels[s];
        if seen[s] || !(1..=5).contains(&l) {
            continue;
        }
        seen[s] = true;
        let mut comp = vec![s as u32];
        let mut head = 0;
        while head < comp.len() {
            let u = comp[head] as usize;
            head += 1;
            topo.for_each_neighbor(u, |w| {
                let wi = w as usize;
                if !seen[wi] && labels[wi] == l {
                    seen[wi] = true;
                    comp.push(w);
                }
            });
        }
        if comp.len() >= p.seed_size(l) {
            seeds.push((l, comp));
        }
    }
    seeds
}

/// Local seeds inside a set of vertices that no one surface explains (not in the paper): a
/// residual set of a noisy cloud can join several surfaces (the twelve fillets and eight
/// corners of a rounded box, all left to the residual seeds, are one connected set), and a fit
/// to all of it explains none of them. Each vertex gets its hop distance to the set's border
/// (a vertex with a neighbour outside the set is at 0); from the deepest vertex not yet in a
/// patch (ties: smaller id), the patch is the vertices of the set within that many hops, so
/// it stays inside the set and spans its width. Patches of fewer than `min_size` vertices are
/// dropped. Returned deepest first; they do not overlap.
pub fn local_patches(set: &[u32], topo: &impl Adjacency, min_size: usize) -> Vec<Vec<u32>> {
    use std::collections::HashMap;
    let index: HashMap<u32, usize> = set.iter().enumerate().map(|(i, &v)| (v, i)).collect();
    let n = set.len();
    // Multi-source breadth-first search from the border inwards.
    let mut depth = vec![u32::MAX; n];
    let mut queue = Vec::new();
    for (i, &v) in set.iter().enumerate() {
        let mut border = false;
        topo.for_each_neighbor(v as usize, |w| border |= !index.contains_key(&w));
        if border {
            depth[i] = 0;
            queue.push(i);
        }
    }
    let mut head = 0;
    while head < queue.len() {
        let i = queue[head];
        head += 1;
        topo.for_each_neighbor(set[i] as usize, |w| {
            if let Some(&j) = index.get(&w) {
                if depth[j] == u32::MAX {
                    depth[j] = depth[i] + 1;
                    queue.push(j);
                }
            }
        });
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&i| (std::cmp::Reverse(depth[i]), set[i]));
    let mut taken = vec![false; n];
    let mut hops = vec![u32::MAX; n];
    let mut patches = Vec::new();
    for &c in &order {
        if taken[c] {
            continue;
        }
        let radius = depth[c].min(n as u32);
        let mut patch = vec![c];
        let mut seen = vec![c];
        hops[c] = 0;
        let mut head = 0;
        while head < patch.len() {
            let i = patch[head];
            head += 1;
            if hops[i] >= radius {
                continue;
            }
            topo.for_each_neighbor(set[i] as usize, |w| {
                if let Some(&j) = index.get(&w) {
                    if hops[j] == u32::MAX {
                        hops[j] = hops[i] + 1;
                        seen.push(j);
                        if !taken[j] {
                            patch.push(j);
                        }
                    }
                }
            });
        }
        for &i in &seen {
            hops[i] = u32::MAX;
        }
        taken[c] = true;
        if patch.len() >= min_size {
            for &i in &patch {
                taken[i] = true;
            }
            patches.push(patch.iter().map(|&i| set[i]).collect());
        }
    }
    patches
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Csr;

    /// A `w × h` grid, each vertex joined to its four neighbours.
    fn grid(w: usize, h: usize) -> Csr {
        let mut rows: Vec<Vec<u32>> = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let mut r = Vec::new();
                if x > 0 {
                    r.push((y * w + x - 1) as u32);
                }
                if x + 1 < w {
                    r.push((y * w + x + 1) as u32);
                }
                if y > 0 {
                    r.push(((y - 1) * w + x) as u32);
                }
                if y + 1 < h {
                    r.push(((y + 1) * w + x) as u32);
                }
                rows.push(r);
            }
        }
        let counts: Vec<u32> = rows.iter().map(|r| r.len() as u32).collect();
        Csr {
            offsets: Csr::offsets_from_counts(&counts),
            indices: rows.concat(),
        }
    }

    #[test]
    fn local_patches_tile_a_strip_from_its_middle_line() {
        // A strip 40 × 9 inside a 48 × 13 grid (the vertices around it are not in the set):
        // the middle row is 4 hops from the set's border, so the patches are discs of radius
        // 4 hops centred on it, disjoint and inside the set.
        let g = grid(48, 13);
        let set: Vec<u32> = (2..11)
            .flat_map(|y| (4..44).map(move |x| (y * 48 + x) as u32))
            .collect();
        let patches = local_patches(&set, &g, 20);
        assert!(patches.len() >= 4, "{} patches", patches.len());
        let mut seen = std::collections::HashSet::new();
        for p in &patches {
            assert!(p.len() >= 20);
            for v in p {
                assert!(set.contains(v));
                assert!(seen.insert(*v), "vertex {v} in two patches");
            }
        }
        // The first patch: the disc of radius 4 around (8, 6), the first vertex of the middle
        // row 4 hops from the strip's left end too.
        let first = &patches[0];
        assert_eq!(first[0], 6 * 48 + 8);
        assert_eq!(first.len(), 41, "a diamond of radius 4 holds 41 vertices");
        // A set that is all border (one row) gives no patch of 20.
        let row: Vec<u32> = (6 * 48 + 4..6 * 48 + 44).map(|v| v as u32).collect();
        assert!(local_patches(&row, &g, 20).is_empty());
    }
}
