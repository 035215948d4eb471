//! Regularised sharp-point labels: a binary labelling of the kNN graph minimising, exactly by
//! one minimum cut ([`crate::graphcut`]), the energy of vidal et al. 2011 (equation 1) with
//! a data term from the per-point sharpness and a pairwise term over neighbouring points:
//!
//! E(x) = Σ_i D_i(x_i) + Σ_(i,j) [ λ w_ij [x_i ≠ x_j] − α a_ij [x_i = x_j = 1] ]
//!
//! * D_i(1) − D_i(0) = −`slope` · ln(sharpness_i): the decision of a lone point is the
//!   detector's (sharp exactly when sharpness ≥ 1);
//! * w_ij = exp(−d_ij² / 2h²) / W, h the mean neighbour distance of i and j, W the mean over
//!   the points of Σ_j exp(…), so λ is the price of a point disagreeing with all its
//!   neighbours, in units of ln(sharpness);
//! * the reward a_ij (vidal's α_ee' of equations 3–4: consistent labelling of *aligned*
//!   neighbours) is w_ij (|d̂_ij · e_i| |d̂_ij · e_j|)² l_i l_j, with e_i the local line direction
//!   (principal axis of the neighbours weighted by their probability of being sharp,
//!   1 / (1 + sharpness^−slope)) and l_i
//!   its linearity 1 − σ₂/σ₁. It fills gaps along lines without a perimeter price across them.
//!
//! Both pairwise terms are submodular (V(0,0) + V(1,1) ≤ V(0,1) + V(1,0)), so the minimum is
//! exact.
//!
//! **Why only on noisy clouds.** Over the settings measured (`docs/experiments/sharp-noise.md`,
//! a table over k, λ, α and the slope on the PCEDNet models), pooling helps the noisy models
//! but always costs on the clean ones (the Potts price erodes lines one or two points wide,
//! which the reward only partly offsets), and its gain stays small: the per-point sharpness
//! of the noisy models is too weak a data term. Hence it is applied only to clouds measured
//! as noisy ([`super::SharpParams::auto_regularize`], setting [`Regularize::noisy`] =
//! (10, 1, 16, 1)), where clean clouds keep the detector alone.

use rayon::prelude::*;

use crate::geometry::fit_plane;
use crate::geometry::{vec3, Point3};
use crate::graphcut::BinaryEnergy;
use crate::spatial::Neighborhoods;
use crate::{Error, Result};

/// Parameters of the Potts regularisation of sharp points ([`super::SharpParams::regularize`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Regularize {
    /// Neighbours per point in the graph (default 10).
    pub k: usize,
    /// λ: Potts price of a point disagreeing with all its neighbours, in units of
    /// ln(sharpness) (see the module documentation).
    pub lambda: f64,
    /// α: reward of two sharp neighbours aligned with the local line direction, same units.
    pub line_reward: f64,
    /// Slope of the data term in ln(sharpness) (default 1).
    pub slope: f64,
    /// Neighbours giving the local line direction (default 16).
    pub k_dir: usize,
}

impl Regularize {
    /// Errors (`InvalidArgument`) on k = 0 or a negative or non-finite weight.
    pub fn validate(&self) -> Result<()> {
        if self.k == 0 {
            return Err(Error::InvalidArgument(
                "sharp regularisation: k must be at least 1".into(),
            ));
        }
        for (name, v) in [
            ("lambda", self.lambda),
            ("line_reward", self.line_reward),
            ("slope", self.slope),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "sharp regularisation: {name} must be finite and >= 0, got {v}"
                )));
            }
        }
        Ok(())
    }

    /// The setting applied automatically to noisy clouds
    /// ([`super::SharpParams::auto_regularize`]): k = 10, λ = 1, α = 16, slope 1, the best noisy
    /// setting of `docs/experiments/sharp-noise.md`, chosen before the noise switch existed
    /// (not re-tuned for it).
    pub fn noisy() -> Self {
        Regularize {
            k: 10,
            lambda: 1.0,
            line_reward: 16.0,
            slope: 1.0,
            k_dir: 16,
        }
    }
}

impl Default for Regularize {
    fn default() -> Self {
        Regularize {
            k: 10,
            lambda: 0.5,
            line_reward: 0.0,
            slope: 1.0,
            k_dir: 16,
        }
    }
}

/// The labelling minimising the energy of the module documentation from the per-point
/// `sharpness` (≥ 1 exactly for the detector's sharp points).
///
/// Errors: parameters out of range, fewer neighbours in `nbrs` than `k` or `k_dir`.
pub fn regularize(
    points: &[Point3],
    nbrs: &Neighborhoods,
    sharpness: &[f64],
    params: &Regularize,
) -> Result<Vec<bool>> {
    regularize_fixed(points, nbrs, sharpness, params, None)
}

/// [`regularize`] with some labels known beforehand (`fixed[i] = Some(label)`, e.g. the points
/// the analytic surfaces decide, see [`super::surfaces`]): the minimum over the other labels,
/// the fixed ones entering their neighbours' terms as constants. The cut's graph holds only the
/// free points, so a cloud the surfaces decide almost everywhere costs little. The fixed
/// points' labels are returned as given.
///
/// Errors: as [`regularize`], and `fixed` of another length.
pub(crate) fn regularize_fixed(
    points: &[Point3],
    nbrs: &Neighborhoods,
    sharpness: &[f64],
    params: &Regularize,
    fixed: Option<&[Option<bool>]>,
) -> Result<Vec<bool>> {
    let n = points.len();
    if sharpness.len() != n || nbrs.len() != n || fixed.is_some_and(|f| f.len() != n) {
        return Err(Error::InvalidArgument(format!(
            "sharp regularisation: {} sharpness values, {} neighbour lists, {} fixed labels \
             for {n} points",
            sharpness.len(),
            nbrs.len(),
            fixed.map_or(n, <[_]>::len)
        )));
    }
    let fixed_at = |i: usize| fixed.and_then(|f| f[i]);
    params.validate()?;
    let k = params.k;
    if k > nbrs.k() || params.k_dir > nbrs.k() {
        return Err(Error::InvalidArgument(format!(
            "sharp regularisation: k = {k} and k_dir = {} need both <= {}",
            params.k_dir,
            nbrs.k()
        )));
    }
    let log_s: Vec<f64> = sharpness
        .par_iter()
        .map(|&s| s.clamp(1e-6, 1e6).ln())
        .collect();
    // Mean neighbour distance per point.
    let h: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|i| {
            let row = nbrs.prefix(i, k);
            let s: f64 = row
                .iter()
                .map(|&j| vec3::dist(points[i], points[j as usize]))
                .sum();
            if row.is_empty() {
                0.0
            } else {
                s / row.len() as f64
            }
        })
        .collect();
    let gauss = |i: usize, j: usize| {
        let hh = 0.5 * (h[i] + h[j]);
        if hh > 0.0 {
            let d2 = vec3::dist2(points[i], points[j]);
            (-d2 / (2.0 * hh * hh)).exp()
        } else {
            1.0
        }
    };
    // Undirected kNN edges, those with a free end only.
    let mut offsets = Vec::with_capacity(n + 1);
    let mut indices = Vec::with_capacity(n * k);
    offsets.push(0u32);
    for i in 0..n {
        indices.extend_from_slice(nbrs.prefix(i, k));
        offsets.push(indices.len() as u32);
    }
    let graph = crate::geometry::Csr { offsets, indices };
    let all_edges = crate::graphcut::undirected_edges(&graph);
    drop(graph);
    let g_all: Vec<f64> = all_edges
        .par_iter()
        .map(|&(i, j)| gauss(i as usize, j as usize))
        .collect();
    // W: the mean over all the points, fixed or not, of Σ_j exp(…) (summed in order: the
    // same whatever the thread count).
    let norm = 2.0 * g_all.iter().sum::<f64>() / n.max(1) as f64;
    let norm = if norm > 0.0 { norm } else { 1.0 };
    let edges: Vec<((u32, u32), f64)> = all_edges
        .into_iter()
        .zip(g_all)
        .filter(|&((i, j), _)| fixed_at(i as usize).is_none() || fixed_at(j as usize).is_none())
        .collect();
    // Line direction and linearity per point at an edge (only needed with a line reward).
    let mut at_edge = vec![fixed.is_none(); n];
    if fixed.is_some() {
        for &((i, j), _) in &edges {
            at_edge[i as usize] = true;
            at_edge[j as usize] = true;
        }
    }
    let dirs: Vec<(Point3, f64)> = if params.line_reward > 0.0 {
        (0..n)
            .into_par_iter()
            .with_min_len(256)
            .map(|i| {
                if !at_edge[i] {
                    return ([0.0; 3], 0.0);
                }
                let prob = |j: usize| 1.0 / (1.0 + (-params.slope * log_s[j]).exp());
                let items = std::iter::once(i as u32)
                    .chain(nbrs.prefix(i, params.k_dir).iter().copied())
                    .map(|j| (points[j as usize], prob(j as usize)));
                match fit_plane(items) {
                    Some(pl) if pl.eigenvalues[2] > 0.0 => {
                        (pl.axes[2], 1.0 - pl.eigenvalues[1] / pl.eigenvalues[2])
                    }
                    _ => ([0.0; 3], 0.0),
                }
            })
            .collect()
    } else {
        Vec::new()
    };
    // The cut's nodes: the free points, numbered in order.
    let node: Vec<u32> = {
        let mut next = 0u32;
        (0..n)
            .map(|i| {
                if fixed_at(i).is_some() {
                    u32::MAX
                } else {
                    next += 1;
                    next - 1
                }
            })
            .collect()
    };
    let free = node.iter().filter(|&&v| v != u32::MAX).count();
    let mut e = BinaryEnergy::with_capacity(free, edges.len());
    for (i, &l) in log_s.iter().enumerate() {
        if node[i] == u32::MAX {
            continue;
        }
        let d = params.slope * l;
        // D(0) − D(1) = slope · ln(sharpness).
        e.add_unary(node[i] as usize, d.max(0.0), (-d).max(0.0))?;
    }
    for &((i, j), g) in &edges {
        let (i, j) = (i as usize, j as usize);
        let w = g / norm;
        let potts = params.lambda * w;
        let reward = if params.line_reward > 0.0 {
            let d = vec3::sub(points[j], points[i]);
            let len = vec3::norm(d);
            if len > 0.0 {
                let (ei, li) = dirs[i];
                let (ej, lj) = dirs[j];
                let a = (vec3::dot(d, ei) / len).abs() * (vec3::dot(d, ej) / len).abs();
                params.line_reward * w * a * a * li * lj
            } else {
                0.0
            }
        } else {
            0.0
        };
        // V(x_i, x_j): 0, potts, potts, −reward.
        let v = |a: bool, b: bool| match (a, b) {
            (false, false) => 0.0,
            (true, true) => -reward,
            _ => potts,
        };
        match (fixed_at(i), fixed_at(j)) {
            (None, None) => {
                let (a, b) = (node[i] as usize, node[j] as usize);
                if reward > 0.0 {
                    e.add_pairwise(a, b, 0.0, potts, potts, -reward)?;
                } else if potts > 0.0 {
                    e.add_potts(a, b, potts)?;
                }
            }
            (None, Some(lj)) => e.add_unary(node[i] as usize, v(false, lj), v(true, lj))?,
            (Some(li), None) => e.add_unary(node[j] as usize, v(li, false), v(li, true))?,
            (Some(_), Some(_)) => {}
        }
    }
    // The cut's graph is the largest allocation of the sharp stage on a noisy cloud: the
    // inputs it was built from go first (a fifth of the peak of `crease run` on a million
    // noisy points).
    drop((edges, dirs, h, log_s, at_edge));
    let cut = e.minimize().labels;
    Ok((0..n)
        .map(|i| fixed_at(i).unwrap_or_else(|| cut[node[i] as usize]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::knn;

    /// A 30 × 30 grid with a sharp line x = 15: isolated false detections are removed, the
    /// line is kept (its gaps stay: the reward is too weak on this grid to pay for them).
    #[test]
    fn removes_isolated_points_and_fills_gaps() {
        let (w, h) = (30usize, 30usize);
        let points: Vec<Point3> = (0..w * h)
            .map(|i| [(i % w) as f64, (i / w) as f64, 0.0])
            .collect();
        let on_line = |i: usize| i % w == 15;
        let false_pos = [3 * w + 4, 10 * w + 25, 20 * w + 7, 26 * w + 22];
        let gaps = [8 * w + 15, 17 * w + 15, 23 * w + 15];
        let sharpness: Vec<f64> = (0..w * h)
            .map(|i| {
                if gaps.contains(&i) {
                    0.6
                } else if on_line(i) || false_pos.contains(&i) {
                    3.0
                } else {
                    0.3
                }
            })
            .collect();
        let nbrs = knn(&points, 16).unwrap();
        let params = Regularize {
            lambda: 1.5,
            line_reward: 8.0,
            ..Default::default()
        };
        let labels = regularize(&points, &nbrs, &sharpness, &params).unwrap();
        for (i, &l) in labels.iter().enumerate() {
            let expected = on_line(i) && !gaps.contains(&i);
            assert_eq!(l, expected, "point {i} ({}, {})", i % w, i / w);
        }
        // Without regularisation the false detections stay.
        assert!(false_pos.iter().all(|&i| sharpness[i] > 1.0));
        // λ = 0 and no reward: the detector's own decisions.
        let plain = Regularize {
            lambda: 0.0,
            ..Default::default()
        };
        let labels = regularize(&points, &nbrs, &sharpness, &plain).unwrap();
        assert!(labels.iter().zip(&sharpness).all(|(&l, &s)| l == (s > 1.0)));
        // Errors.
        let bad = Regularize {
            k: 17,
            ..Default::default()
        };
        assert!(regularize(&points, &nbrs, &sharpness, &bad).is_err());
        assert!(regularize(&points, &nbrs, &sharpness[1..], &params).is_err());
    }

    /// Fixing some labels to those of the whole minimum leaves the others at it (a better
    /// labelling of the free points would lower the whole energy), and the fixed labels are
    /// returned as given, even against their data.
    #[test]
    fn fixed_labels_keep_the_minimum_of_the_others() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let w = 40usize;
        let points: Vec<Point3> = (0..w * w)
            .map(|i| {
                let (x, y) = ((i % w) as f64, (i / w) as f64);
                [
                    x + rng.random_range(-0.2..0.2),
                    y + rng.random_range(-0.2..0.2),
                    0.0,
                ]
            })
            .collect();
        // A noisy line x ≈ 20 in noisy sharpness.
        let sharpness: Vec<f64> = points
            .iter()
            .map(|p| {
                let base: f64 = if (p[0] - 20.0).abs() < 0.7 { 2.0 } else { 0.5 };
                base * rng.random_range(0.4f64..2.5)
            })
            .collect();
        let nbrs = knn(&points, 16).unwrap();
        let params = Regularize::noisy();
        let whole = regularize(&points, &nbrs, &sharpness, &params).unwrap();
        assert_eq!(
            regularize_fixed(&points, &nbrs, &sharpness, &params, None).unwrap(),
            whole
        );
        assert!(whole.iter().any(|&l| l) && whole.iter().any(|&l| !l));
        let fixed: Vec<Option<bool>> = (0..points.len())
            .map(|i| (i % 3 != 0).then_some(whole[i]))
            .collect();
        let part = regularize_fixed(&points, &nbrs, &sharpness, &params, Some(&fixed)).unwrap();
        assert_eq!(part, whole);
        // A fixed label against the data stays.
        let lone = (0..points.len())
            .find(|&i| !whole[i] && i % 3 != 0)
            .unwrap();
        let mut forced = fixed.clone();
        forced[lone] = Some(true);
        let part = regularize_fixed(&points, &nbrs, &sharpness, &params, Some(&forced)).unwrap();
        assert!(part[lone]);
        assert!(regularize_fixed(&points, &nbrs, &sharpness, &params, Some(&fixed[1..])).is_err());
    }
}
