//! Smoothing of an edge score along the line the edge lies on (crease's addition to vidal et al.
//! 2011): the last step of the `filtered` angle ([`super::filtered_dihedral`]).
//!
//! A feature line is a chain of mesh edges that continue each other; noise is not. Each edge's
//! score is blended with its mean over its own chain: from each endpoint the walk takes the
//! incident edge that continues the current one most straightly (turning by at most
//! [`LineParams::max_turn_degrees`]) for [`LineParams::steps`] edges, and
//!
//! s'(e) = (1 − β) s(e) + β · mean(s over e and the edges walked), β = [`LineParams::weight`].
//!
//! The walk follows the mesh geometry, never the score, so the along-line neighbours of an edge
//! beside a crease are the edges beside the crease too: a diagonal edge touching a crease has
//! no straight continuation of high score and loses, a crease edge of low noisy angle borrows
//! from its neighbours on the crease.
//!
//! The defaults (2 steps, β = 0.2, at most 45° of turn) scored best among the settings
//! measured with `examples/meshfeat_table2.rs`; choosing the continuation by the score
//! instead of the geometry scored lower, as it rewards the edges beside a crease too
//! (`docs/experiments/mesh-edges-filtered-angle.md`).
//!
//! Parallel over the edges; each value depends only on the mesh and the scores.

use rayon::prelude::*;
use serde::Serialize;

use super::EdgeMesh;
use crate::geometry::vec3;

/// Parameters of [`smooth_along_lines`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LineParams {
    /// Edges walked from each endpoint (0: no smoothing).
    pub steps: usize,
    /// β, the weight of the chain's mean, in [0, 1].
    pub weight: f64,
    /// The largest turn between consecutive edges of a chain, degrees.
    pub max_turn_degrees: f64,
}

impl Default for LineParams {
    fn default() -> Self {
        LineParams {
            steps: 2,
            weight: 0.2,
            max_turn_degrees: 45.0,
        }
    }
}

impl LineParams {
    /// `None` if the parameters are valid, else what is wrong.
    pub fn invalid(&self) -> Option<String> {
        if !(0.0..=1.0).contains(&self.weight) {
            return Some(format!(
                "line smoothing: the weight must be in [0, 1], got {}",
                self.weight
            ));
        }
        if !(self.max_turn_degrees.is_finite() && (0.0..=180.0).contains(&self.max_turn_degrees)) {
            return Some(format!(
                "line smoothing: the largest turn must be in [0, 180] degrees, got {}",
                self.max_turn_degrees
            ));
        }
        None
    }
}

/// The edge leaving vertex `v` that continues edge `e` (which ends at `v`) most straightly,
/// turning by less than the angle of cosine `min_cos`, and its far vertex.
fn continuation(em: &EdgeMesh, e: usize, v: u32, min_cos: f64) -> Option<(usize, u32)> {
    let edges = em.topo.edges();
    let p = em.mesh.positions();
    let other = |e: usize, v: u32| {
        let [a, b] = edges[e];
        if a == v {
            b
        } else {
            a
        }
    };
    let incoming = vec3::normalize(vec3::sub(p[v as usize], p[other(e, v) as usize]))?;
    let mut best: Option<(f64, usize, u32)> = None;
    for &e2 in em.topo.vertex_edges(v as usize) {
        let e2 = e2 as usize;
        if e2 == e {
            continue;
        }
        let w = other(e2, v);
        let Some(out) = vec3::normalize(vec3::sub(p[w as usize], p[v as usize])) else {
            continue;
        };
        let c = vec3::dot(incoming, out);
        if c > min_cos && best.is_none_or(|b| c > b.0) {
            best = Some((c, e2, w));
        }
    }
    best.map(|(_, e2, w)| (e2, w))
}

/// `score` (one value per edge of `em`) smoothed along the lines (see the module
/// documentation).
pub fn smooth_along_lines(em: &EdgeMesh, score: &[f64], params: &LineParams) -> Vec<f64> {
    if params.steps == 0 || params.weight == 0.0 {
        return score.to_vec();
    }
    let min_cos = params.max_turn_degrees.to_radians().cos();
    let edges = em.topo.edges();
    // The continuation of every edge at each of its two ends, once: the walks below only
    // look them up.
    let next: Vec<[Option<(usize, u32)>; 2]> = (0..edges.len())
        .into_par_iter()
        .map(|e| edges[e].map(|v| continuation(em, e, v, min_cos)))
        .collect();
    let beta = params.weight;
    (0..edges.len())
        .into_par_iter()
        .map(|e| {
            let mut sum = score[e];
            let mut n = 1.0;
            for start in next[e] {
                let mut step = start;
                for _ in 0..params.steps {
                    let Some((cur, far)) = step else { break };
                    sum += score[cur];
                    n += 1.0;
                    let [a, _] = edges[cur];
                    step = next[cur][usize::from(a != far)];
                }
            }
            (1.0 - beta) * score[e] + beta * sum / n
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::meshfeat::test_support::cube;

    /// On a cube's mesh, a score of 1 on one edge of each straight line segment and 0 elsewhere
    /// spreads only along the lines it lies on: the edges walked along a cube edge are cube
    /// edges, so an indicator of the cube's edges is unchanged.
    #[test]
    fn smoothing_follows_straight_lines() {
        let m = cube(20.0);
        let em = EdgeMesh::new(&m.mesh).expect("topology");
        let (truth, _) = crate::meshfeat::labels_from_pairs(&em.topo, &m.sharp_edges);
        let indicator: Vec<f64> = truth.iter().map(|&t| f64::from(u8::from(t))).collect();
        let s = smooth_along_lines(&em, &indicator, &LineParams::default());
        // Away from the corners every cube edge continues along its own line.
        let p = m.mesh.positions();
        let near_corner = |e: usize| {
            em.topo.edges()[e].iter().any(|&v| {
                p[v as usize]
                    .iter()
                    .filter(|c| (c.abs() - 0.5).abs() < 0.2)
                    .count()
                    == 3
            })
        };
        let mut checked = 0;
        for e in 0..s.len() {
            if truth[e] && !near_corner(e) {
                assert!((s[e] - 1.0).abs() < 1e-12, "edge {e}: {}", s[e]);
                checked += 1;
            }
            if !truth[e] {
                assert!(s[e] < 0.2 + 1e-12, "edge {e}: {}", s[e]);
            }
        }
        assert!(checked > 50, "{checked} edges checked");
        let unchanged = smooth_along_lines(
            &em,
            &indicator,
            &LineParams {
                steps: 0,
                ..LineParams::default()
            },
        );
        assert_eq!(unchanged, indicator);
        assert!(LineParams::default().invalid().is_none());
        let bad = LineParams {
            weight: -1.0,
            ..LineParams::default()
        };
        assert!(bad.invalid().is_some());
    }
}
