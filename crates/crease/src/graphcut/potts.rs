//! Binary labellings minimising E(x) = Σ_i D_i(x_i) + Σ_(i,j) V_ij(x_i, x_j) exactly by one
//! minimum cut, for submodular pairwise terms V_ij(0,0) + V_ij(1,1) ≤ V_ij(0,1) + V_ij(1,0)
//! (V. Kolmogorov, R. Zabih, "What energy functions can be minimized via graph cuts?", IEEE
//! PAMI 26(2), 2004, section 4), among them the Potts / Ising model of vidal et al. 2011
//! (equation 1 with a Potts pairwise term): E(x) = Σ_i D_i(x_i) + λ Σ_(i,j) w_ij [x_i ≠ x_j].
//!
//! **Construction.** Label 0 is the source side of the cut, label 1 the sink side. A unary
//! term (D_i(0), D_i(1)) becomes the terminal links source → i of capacity D_i(1) − m and
//! i → sink of capacity D_i(0) − m, m = min(D_i(0), D_i(1)) going to a constant. A pairwise
//! term (A, B, C, D) = (V(0,0), V(0,1), V(1,0), V(1,1)) is
//! A + (C − A) x_i + (D − C) x_j + (B + C − A − D)(1 − x_i) x_j: two unary terms and the arc
//! i → j of capacity B + C − A − D ≥ 0, cut exactly when x_i = 0 and x_j = 1. A Potts term
//! w [x_i ≠ x_j] is the pair of arcs i ⇄ j of capacity w. The minimum energy is the constant
//! plus the maximum flow ([`super::maxflow`]).

use crate::geometry::Csr;
use crate::{Error, Result};

use super::maxflow::Graph;

/// A minimising labelling.
#[derive(Debug, Clone, PartialEq)]
pub struct Labelling {
    /// x_i per node (`true` = label 1).
    pub labels: Vec<bool>,
    /// The minimum energy E(x) (the constant plus the max-flow value; up to rounding).
    pub energy: f64,
}

/// A binary energy with submodular pairwise terms, minimised exactly by
/// [`BinaryEnergy::minimize`].
///
/// ```
/// use crease::graphcut::BinaryEnergy;
/// // Three nodes on a chain; the middle one prefers label 1 weakly, its neighbours 0 strongly.
/// let mut e = BinaryEnergy::new(3);
/// e.add_unary(0, 0.0, 5.0)?;
/// e.add_unary(1, 1.0, 0.0)?;
/// e.add_unary(2, 0.0, 5.0)?;
/// e.add_potts(0, 1, 0.8)?;
/// e.add_potts(1, 2, 0.8)?;
/// let l = e.minimize();
/// assert_eq!(l.labels, vec![false, false, false]); // 1.0 < 0.8 + 0.8
/// assert_eq!(l.energy, 1.0);
/// # Ok::<(), crease::Error>(())
/// ```
#[derive(Debug, Clone)]
pub struct BinaryEnergy {
    graph: Graph,
    constant: f64,
}

fn check_finite(what: &str, i: usize, values: &[f64]) -> Result<()> {
    if let Some(v) = values.iter().find(|v| !v.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "binary energy: {what} of node {i} is not finite ({v})"
        )));
    }
    Ok(())
}

impl BinaryEnergy {
    /// An energy over `num_nodes` binary variables, identically zero.
    pub fn new(num_nodes: usize) -> Self {
        BinaryEnergy::with_capacity(num_nodes, 0)
    }

    /// [`BinaryEnergy::new`] with room for `num_pairs` pairwise terms.
    pub fn with_capacity(num_nodes: usize, num_pairs: usize) -> Self {
        BinaryEnergy {
            graph: Graph::with_capacity(num_nodes, num_pairs),
            constant: 0.0,
        }
    }

    /// Number of variables.
    pub fn num_nodes(&self) -> usize {
        self.graph.num_nodes()
    }

    /// Adds the unary term D_i(0) = `e0`, D_i(1) = `e1` (any finite values). Terms accumulate.
    pub fn add_unary(&mut self, i: usize, e0: f64, e1: f64) -> Result<()> {
        check_finite("unary term", i, &[e0, e1])?;
        let m = e0.min(e1);
        self.graph.add_tweights(i, e1 - m, e0 - m)?;
        self.constant += m;
        Ok(())
    }

    /// Adds the Potts term `w` [x_i ≠ x_j], `w` ≥ 0.
    pub fn add_potts(&mut self, i: usize, j: usize, w: f64) -> Result<()> {
        if i == j {
            return Err(Error::InvalidArgument(format!(
                "binary energy: pairwise term between node {i} and itself"
            )));
        }
        self.graph.add_edge(i, j, w, w)
    }

    /// Adds the pairwise term V(x_i, x_j) with V(0,0) = `e00`, V(0,1) = `e01`, V(1,0) = `e10`,
    /// V(1,1) = `e11`.
    ///
    /// Errors: `i == j`, a value not finite, or a term that is not submodular
    /// (e00 + e11 > e01 + e10 beyond rounding), which one cut cannot minimise.
    pub fn add_pairwise(
        &mut self,
        i: usize,
        j: usize,
        e00: f64,
        e01: f64,
        e10: f64,
        e11: f64,
    ) -> Result<()> {
        check_finite("pairwise term", i, &[e00, e01, e10, e11])?;
        if i == j {
            return Err(Error::InvalidArgument(format!(
                "binary energy: pairwise term between node {i} and itself"
            )));
        }
        let c = e01 + e10 - e00 - e11;
        let scale = e00.abs() + e01.abs() + e10.abs() + e11.abs();
        if c < -1e-12 * scale {
            return Err(Error::InvalidArgument(format!(
                "binary energy: pairwise term ({i}, {j}) is not submodular: \
                 V(0,0) + V(1,1) = {} > V(0,1) + V(1,0) = {}",
                e00 + e11,
                e01 + e10
            )));
        }
        self.add_unary(i, 0.0, e10 - e00)?;
        self.add_unary(j, 0.0, e11 - e10)?;
        self.constant += e00;
        self.graph.add_edge(i, j, c.max(0.0), 0.0)
    }

    /// Minimises the energy exactly (one max-flow).
    pub fn minimize(mut self) -> Labelling {
        let flow = self.graph.maxflow();
        let labels = (0..self.graph.num_nodes())
            .map(|i| !self.graph.is_source_side(i))
            .collect();
        Labelling {
            labels,
            energy: self.constant + flow,
        }
    }
}

fn check_unary(unary: &[[f64; 2]], lambda: f64) -> Result<()> {
    if !(lambda.is_finite() && lambda >= 0.0) {
        return Err(Error::InvalidArgument(format!(
            "Potts labelling: lambda must be finite and >= 0, got {lambda}"
        )));
    }
    if unary.len() > u32::MAX as usize {
        return Err(Error::InvalidArgument(format!(
            "Potts labelling: {} nodes, at most 2^32 − 1",
            unary.len()
        )));
    }
    Ok(())
}

/// The labelling minimising Σ_i D_i(x_i) + λ Σ_(i,j,w) w [x_i ≠ x_j]: `unary[i]` =
/// [D_i(0), D_i(1)], `edges` = (i, j, w) with w ≥ 0 (an edge listed twice counts twice).
///
/// Errors: a node out of range, a value not finite, a negative weight or λ.
pub fn potts(unary: &[[f64; 2]], edges: &[(u32, u32, f64)], lambda: f64) -> Result<Labelling> {
    check_unary(unary, lambda)?;
    let mut e = BinaryEnergy::with_capacity(unary.len(), edges.len());
    for (i, &[d0, d1]) in unary.iter().enumerate() {
        e.add_unary(i, d0, d1)?;
    }
    for &(i, j, w) in edges {
        if i != j {
            e.add_potts(i as usize, j as usize, lambda * w)?;
        }
    }
    Ok(e.minimize())
}

/// [`potts`] over a neighbour graph in CSR form (e.g. kNN lists): every stored entry j of row
/// i is an edge of weight `weights[e]` (`weights` aligned with `graph.indices`; empty for
/// weight 1). The graph is made undirected: when j lists i and i lists j, the two entries
/// are one edge of weight w_ij + w_ji. Entries i → i are ignored.
///
/// Memory: about 40 bytes per undirected edge and 40 per node during the cut.
///
/// Errors: rows ≠ nodes, weights of the wrong length, a neighbour out of range, a value not
/// finite, a negative weight or λ.
pub fn potts_csr(
    unary: &[[f64; 2]],
    graph: &Csr,
    weights: &[f64],
    lambda: f64,
) -> Result<Labelling> {
    check_unary(unary, lambda)?;
    let n = unary.len();
    if graph.num_rows() != n {
        return Err(Error::InvalidArgument(format!(
            "Potts labelling: neighbour graph of {} rows for {n} nodes",
            graph.num_rows()
        )));
    }
    if !weights.is_empty() && weights.len() != graph.indices.len() {
        return Err(Error::InvalidArgument(format!(
            "Potts labelling: {} weights for {} graph entries",
            weights.len(),
            graph.indices.len()
        )));
    }
    if let Some(&j) = graph.indices.iter().find(|&&j| j as usize >= n) {
        return Err(Error::InvalidArgument(format!(
            "Potts labelling: neighbour {j} out of range ({n} nodes)"
        )));
    }
    let w_at = |e: usize| if weights.is_empty() { 1.0 } else { weights[e] };
    let pairs = undirected_pairs(graph);
    let mut e = BinaryEnergy::with_capacity(n, pairs.len());
    for (i, &[d0, d1]) in unary.iter().enumerate() {
        e.add_unary(i, d0, d1)?;
    }
    for (i, j, e1, e2) in pairs {
        let mut w = w_at(e1 as usize);
        if e2 != u32::MAX {
            w += w_at(e2 as usize);
        }
        e.add_potts(i as usize, j as usize, lambda * w)?;
    }
    Ok(e.minimize())
}

/// (i, j, entry of j in row i, entry of i in row j or `u32::MAX`) with i < j, each undirected
/// pair once, in row order.
fn undirected_pairs(graph: &Csr) -> Vec<(u32, u32, u32, u32)> {
    let find = |row: usize, x: u32| -> Option<u32> {
        let s = graph.offsets[row] as usize;
        graph
            .row(row)
            .iter()
            .position(|&y| y == x)
            .map(|p| (s + p) as u32)
    };
    let mut out = Vec::with_capacity(graph.indices.len());
    for i in 0..graph.num_rows() {
        let s = graph.offsets[i] as usize;
        for (p, &j) in graph.row(i).iter().enumerate() {
            let e = (s + p) as u32;
            let ju = j as usize;
            if ju == i || ju >= graph.num_rows() {
                continue;
            }
            if i < ju {
                // Skip a duplicate entry j earlier in row i.
                if graph.row(i)[..p].contains(&j) {
                    continue;
                }
                out.push((i as u32, j, e, find(ju, i as u32).unwrap_or(u32::MAX)));
            } else if find(ju, i as u32).is_none() && !graph.row(i)[..p].contains(&j) {
                out.push((j, i as u32, e, u32::MAX));
            }
        }
    }
    out
}

/// The undirected edges (i, j), i < j, of a neighbour graph in CSR form, each once (i lists j
/// or j lists i), in row order.
pub fn undirected_edges(graph: &Csr) -> Vec<(u32, u32)> {
    undirected_pairs(graph)
        .into_iter()
        .map(|(i, j, _, _)| (i, j))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    type Pair = (usize, usize, [f64; 4]);

    fn energy(unary: &[[f64; 2]], pairs: &[Pair], x: &[bool]) -> f64 {
        let d: f64 = unary.iter().zip(x).map(|(u, &l)| u[l as usize]).sum();
        let p: f64 = pairs
            .iter()
            .map(|&(i, j, v)| v[2 * x[i] as usize + x[j] as usize])
            .sum();
        d + p
    }

    fn brute_force(unary: &[[f64; 2]], pairs: &[Pair]) -> f64 {
        let n = unary.len();
        (0..1u32 << n)
            .map(|m| {
                let x: Vec<bool> = (0..n).map(|i| m >> i & 1 == 1).collect();
                energy(unary, pairs, &x)
            })
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn chains_and_random_graphs_match_brute_force() {
        let mut rng = Pcg64::seed_from_u64(5);
        for case in 0..300 {
            let n = rng.random_range(1..=12usize);
            let unary: Vec<[f64; 2]> = (0..n)
                .map(|_| [rng.random_range(-2.0..2.0), rng.random_range(-2.0..2.0)])
                .collect();
            // Even cases: a chain with Potts terms; odd cases: random submodular terms.
            let mut pairs: Vec<Pair> = Vec::new();
            if case % 2 == 0 {
                for i in 0..n.saturating_sub(1) {
                    let w = rng.random_range(0.0..1.5);
                    pairs.push((i, i + 1, [0.0, w, w, 0.0]));
                }
            } else if n > 1 {
                for _ in 0..2 * n {
                    let (i, j) = (rng.random_range(0..n), rng.random_range(0..n));
                    if i == j {
                        continue;
                    }
                    let (a, d) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                    let b = rng.random_range(-1.0..1.0);
                    let c = a + d - b + rng.random_range(0.0..1.0);
                    pairs.push((i, j, [a, b, c, d]));
                }
            }
            let mut e = BinaryEnergy::new(n);
            for (i, u) in unary.iter().enumerate() {
                e.add_unary(i, u[0], u[1]).unwrap();
            }
            for &(i, j, v) in &pairs {
                if v[0] == 0.0 && v[3] == 0.0 && v[1] == v[2] {
                    e.add_potts(i, j, v[1]).unwrap();
                } else {
                    e.add_pairwise(i, j, v[0], v[1], v[2], v[3]).unwrap();
                }
            }
            let l = e.minimize();
            let best = brute_force(&unary, &pairs);
            let got = energy(&unary, &pairs, &l.labels);
            assert!(
                (got - best).abs() < 1e-9,
                "case {case}: {got} vs optimum {best}"
            );
            assert!(
                (l.energy - best).abs() < 1e-9,
                "case {case}: {} vs {best}",
                l.energy
            );
        }
    }

    #[test]
    fn potts_csr_merges_mutual_entries() {
        // 0 ↔ 1 listed both ways (weights 1 + 2), 1 → 2 one way (weight 4), self entries
        // ignored.
        let graph = Csr {
            offsets: vec![0, 2, 4, 5],
            indices: vec![1, 0, 0, 2, 2],
        };
        let weights = [1.0, 9.0, 2.0, 4.0, 7.0];
        assert_eq!(undirected_edges(&graph), vec![(0, 1), (1, 2)]);
        let unary = [[5.0, 0.0], [0.0, 2.5], [0.0, 9.0]];
        let l = potts_csr(&unary, &graph, &weights, 1.0).unwrap();
        assert_eq!(l.labels, vec![true, false, false]);
        assert_eq!(l.energy, 3.0);
        // λ = 0: each node takes its cheaper label.
        let l = potts_csr(&unary, &graph, &weights, 0.0).unwrap();
        assert_eq!(l.labels, vec![true, false, false]);
        assert_eq!(l.energy, 0.0);
        // Unit weights: the edge list form gives the same.
        let l1 = potts_csr(&unary, &graph, &[], 2.0).unwrap();
        let l2 = potts(&unary, &[(0, 1, 2.0), (1, 2, 1.0)], 2.0).unwrap();
        assert_eq!(l1, l2);
        // Errors.
        assert!(potts_csr(&unary[..2], &graph, &weights, 1.0).is_err());
        assert!(potts_csr(&unary, &graph, &weights[..3], 1.0).is_err());
        assert!(potts_csr(&unary, &graph, &weights, -1.0).is_err());
        assert!(potts(&unary, &[(0, 3, 1.0)], 1.0).is_err());
        assert!(potts(&unary, &[(0, 1, -1.0)], 1.0).is_err());
        assert!(potts(&[[f64::NAN, 0.0]], &[], 1.0).is_err());
        let mut e = BinaryEnergy::new(2);
        assert!(e.add_pairwise(0, 1, 1.0, 0.0, 0.0, 1.0).is_err());
        assert!(e.add_pairwise(0, 0, 0.0, 1.0, 1.0, 0.0).is_err());
    }
}
