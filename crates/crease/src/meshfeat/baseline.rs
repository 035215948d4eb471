//! The baselines of vidal et al. 2011, Table 2: thresholding of an edge angle (the dihedral
//! angle, as CGAL `detect_sharp_edges`, libigl `sharp_edges` and MeshLab do) and hysteresis
//! thresholding.
//!
//! **Hysteresis as a score.** With a high threshold t and a low one k·t (0 < k ≤ 1), an edge is
//! a feature if its angle exceeds k·t and a chain of edges above k·t, consecutive ones sharing a
//! vertex, links it to an edge above t (Canny's rule on the edge graph). For a fixed ratio k
//! an edge is selected at threshold t exactly when t < h_e, with
//! h_e = max over edges e' reachable from e of min(θ_e', min over the chain of θ / k), so h_e is
//! a score whose ROC is the sweep of t. It is computed exactly by a widest-path propagation
//! (Dijkstra with max-min instead of plus-min) from every edge at once. The paper gives no
//! ratio; crease uses k = 0.5 by default (Canny's usual 1:2).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::EdgeMesh;
use crate::{Error, Result};

/// Labels `score > threshold`.
pub fn threshold(scores: &[f64], threshold: f64) -> Vec<bool> {
    scores.iter().map(|&s| s > threshold).collect()
}

#[derive(PartialEq)]
struct Item(f64, u32);
impl Eq for Item {}
impl PartialOrd for Item {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Item {
    fn cmp(&self, o: &Self) -> Ordering {
        self.0.total_cmp(&o.0).then(o.1.cmp(&self.1))
    }
}

/// The hysteresis score h_e of every edge (see the module documentation) for the edge angles
/// `angles` (radians; NaN counts as 0) and the ratio `low_ratio` = low / high threshold.
/// Labelling `h_e > t` is hysteresis thresholding with thresholds t and `low_ratio`·t.
///
/// Errors: `angles` not one per edge, `low_ratio` outside (0, 1].
pub fn hysteresis_scores(em: &EdgeMesh, angles: &[f64], low_ratio: f64) -> Result<Vec<f64>> {
    let topo = &em.topo;
    let ne = topo.num_edges();
    if angles.len() != ne {
        return Err(Error::InvalidArgument(format!(
            "hysteresis: {} angles for {ne} edges",
            angles.len()
        )));
    }
    if !(low_ratio > 0.0 && low_ratio <= 1.0) {
        return Err(Error::InvalidArgument(format!(
            "hysteresis: the low / high ratio must be in (0, 1], got {low_ratio}"
        )));
    }
    let a = |e: usize| if angles[e].is_nan() { 0.0 } else { angles[e] };
    let mut h: Vec<f64> = (0..ne).map(a).collect();
    let mut done = vec![false; ne];
    let mut heap: BinaryHeap<Item> = (0..ne).map(|e| Item(h[e], e as u32)).collect();
    while let Some(Item(val, e)) = heap.pop() {
        let e = e as usize;
        if done[e] || val < h[e] {
            continue;
        }
        done[e] = true;
        for &v in &topo.edges()[e] {
            for &f in topo.vertex_edges(v as usize) {
                let f = f as usize;
                if done[f] {
                    continue;
                }
                let cand = val.min(a(f) / low_ratio);
                if cand > h[f] {
                    h[f] = cand;
                    heap.push(Item(cand, f as u32));
                }
            }
        }
    }
    Ok(h)
}
