//! Globally consistent feature-edge labelling (vidal et al. 2011, section 5): the labels ω
//! (1 = feature edge) minimise
//!
//! E(ω) = Σ_e E_d(ω_e) − μ Σ_{e,e' ∈ N} E_h(ω_e, ω_e')                        (eq. 1)
//!
//! with the pairwise term E_h = 0 if ω_e ≠ ω_e', β if both are 0, and α_ee' if both are 1 (eq. 3),
//!
//! α_ee' = exp(−(λ |cos θ_e − cos θ_e'| / σ + 1 − cos T_ee'))                 (eq. 4)
//!
//! (T_ee' the turning angle between the two edges, 0 when they continue each other in a
//! straight line), and the data term of equation 5 on an edge angle θ:
//! E_d(1) = (2 θ_true − |θ|)², E_d(0) = θ² (equal at |θ| = θ_true).
//!
//! The energy is submodular (V(0,0) + V(1,1) = −μ(β + α) ≤ 0 = V(0,1) + V(1,0)), so one
//! minimum cut ([`crate::graphcut::BinaryEnergy`], Boykov–Kolmogorov max-flow) gives the exact
//! global minimum.
//!
//! **Reading of the paper's text.** The extracted text lost the minus signs; the ones used here
//! are the only ones that make the model submodular and "favour 00 and 11" as section 5 says:
//! the minus before μ in eq. 1, the minus inside the exponential of eq. 4, β = 10⁻³ (not 10³).
//! N is taken as the unordered pairs of edges sharing a vertex (the paper's ordered pairs count
//! each twice, which only rescales μ). The angle θ of the data term is the dihedral angle
//! (`potts-dihedral`) or crease's choice, the tangent-plane angle θ̂ʳ (`potts-tangent`); the
//! similarity term of eq. 4 always uses the same angle as the data term.
//!
//! **Parameters.** With the paper's μ = 2 the pairwise reward of two aligned feature edges
//! (−2 α) outweighs the data cost of labelling noisy flat edges as features, and on crease's
//! meshes every edge ends up a feature. The default μ = 0.05 keeps the labelling close to
//! thresholding the data angle at θ_true (the same AUC and F1 as thresholding; larger μ
//! lowered the F1). So in crease's measurements the global energy does not beat plain
//! thresholding of its own data term, and the same holds for the SVM data term of equation 2
//! with the paper's μ = 0.1, β = 0, λ = 15, σ = 10 (`potts-learned`) against the decision
//! value itself. Figures (`examples/meshfeat_table2.rs`, `examples/meshfeat_learned.rs`):
//! `docs/experiments/mesh-edges-tangent.md`.

use rayon::prelude::*;

use super::EdgeMesh;
use crate::geometry::vec3;
use crate::graphcut::BinaryEnergy;
use crate::{Error, Result};

/// Parameters of the energy of equations 1, 3, 4 and 5.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PottsParams {
    /// μ, weight of the pairwise term.
    pub mu: f64,
    /// β, reward of two neighbouring normal edges.
    pub beta: f64,
    /// λ of equation 4.
    pub lambda: f64,
    /// σ of equation 4.
    pub sigma: f64,
    /// θ_true of equation 5, radians: the angle at which both labels cost the same.
    pub theta_true: f64,
}

impl Default for PottsParams {
    fn default() -> Self {
        PottsParams {
            mu: 0.05,
            beta: 1e-3,
            lambda: 15.0,
            sigma: 10.0,
            theta_true: 65f64.to_radians(),
        }
    }
}

/// The pairs N (edges sharing a vertex, each unordered pair once) with the alignment part
/// 1 − cos T of equation 4, computed once per mesh.
#[derive(Debug, Clone)]
pub struct EdgePairs {
    /// (e, e', 1 − cos T_ee') with e < e'.
    pub pairs: Vec<(u32, u32, f64)>,
}

impl EdgePairs {
    /// The pairs of `em`, in parallel over the vertices (deterministic order).
    pub fn new(em: &EdgeMesh) -> EdgePairs {
        let topo = &em.topo;
        let p = em.mesh.positions();
        let pairs: Vec<Vec<(u32, u32, f64)>> = (0..topo.num_vertices())
            .into_par_iter()
            .map(|v| {
                let es = topo.vertex_edges(v);
                let mut out = Vec::with_capacity(es.len() * es.len().saturating_sub(1) / 2);
                let other = |e: u32| {
                    let [a, b] = topo.edges()[e as usize];
                    if a as usize == v {
                        b
                    } else {
                        a
                    }
                };
                for (i, &e1) in es.iter().enumerate() {
                    // Direction arriving at v along e1, leaving v along e2.
                    let u1 = vec3::sub(p[v], p[other(e1) as usize]);
                    for &e2 in &es[i + 1..] {
                        let u2 = vec3::sub(p[other(e2) as usize], p[v]);
                        let c = vec3::normalize(u1)
                            .zip(vec3::normalize(u2))
                            .map_or(0.0, |(a, b)| vec3::dot(a, b));
                        out.push((e1.min(e2), e1.max(e2), 1.0 - c));
                    }
                }
                out
            })
            .collect();
        EdgePairs {
            pairs: pairs.into_iter().flatten().collect(),
        }
    }
}

/// The exact minimiser of equation 1 with the data term of equation 5 on `angles` (radians,
/// one per edge; NaN counts as π, a feature).
///
/// Errors: `angles` not one per edge, a parameter negative or not finite, σ = 0.
pub fn potts_labels(
    em: &EdgeMesh,
    pairs: &EdgePairs,
    angles: &[f64],
    params: &PottsParams,
) -> Result<Vec<bool>> {
    let ne = em.topo.num_edges();
    if angles.len() != ne {
        return Err(Error::InvalidArgument(format!(
            "Potts labelling: {} angles for {ne} edges",
            angles.len()
        )));
    }
    check_params(params)?;
    let th: Vec<f64> = angles
        .iter()
        .map(|&a| {
            if a.is_nan() {
                std::f64::consts::PI
            } else {
                a.abs()
            }
        })
        .collect();
    let t = params.theta_true;
    let unary: Vec<[f64; 2]> = th
        .iter()
        .map(|&a| [a * a, (2.0 * t - a) * (2.0 * t - a)])
        .collect();
    potts_labels_unary(em, pairs, &th, &unary, params)
}

/// The SVM data term of equation 2: E_d(ω) = exp((−1)^ω d(e)), i.e. (E_d(0), E_d(1)) =
/// (exp d, exp −d), for decision values `d` (positive = feature); `bias` is added to every
/// d (the paper sweeps it over [−2, 1] for the ROC). Values are clamped to |d| ≤ 30.
pub fn svm_unary(decision: &[f64], bias: f64) -> Vec<[f64; 2]> {
    decision
        .iter()
        .map(|&d| {
            let d = if d.is_nan() {
                0.0
            } else {
                (d + bias).clamp(-30.0, 30.0)
            };
            [d.exp(), (-d).exp()]
        })
        .collect()
}

/// The exact minimiser of equation 1 with any data term: `unary[e]` = (E_d(0), E_d(1)); the
/// similarity part of equation 4 reads `angles` (radians, e.g. the dihedral angle; θ_true
/// of `params` is not used).
///
/// Errors: lengths other than one per edge, a parameter negative or not finite, σ = 0, a
/// unary cost not finite.
pub fn potts_labels_unary(
    em: &EdgeMesh,
    pairs: &EdgePairs,
    angles: &[f64],
    unary: &[[f64; 2]],
    params: &PottsParams,
) -> Result<Vec<bool>> {
    let ne = em.topo.num_edges();
    if angles.len() != ne || unary.len() != ne {
        return Err(Error::InvalidArgument(format!(
            "Potts labelling: {} angles and {} data terms for {ne} edges",
            angles.len(),
            unary.len()
        )));
    }
    check_params(params)?;
    let cos: Vec<f64> = angles
        .iter()
        .map(|&a| if a.is_nan() { -1.0 } else { a.cos() })
        .collect();
    let mut energy = BinaryEnergy::with_capacity(ne, pairs.pairs.len());
    for (e, u) in unary.iter().enumerate() {
        energy.add_unary(e, u[0], u[1])?;
    }
    let k = params.lambda / params.sigma;
    for &(e1, e2, align) in &pairs.pairs {
        let (e1, e2) = (e1 as usize, e2 as usize);
        let alpha = (-(k * (cos[e1] - cos[e2]).abs() + align)).exp();
        energy.add_pairwise(
            e1,
            e2,
            -params.mu * params.beta,
            0.0,
            0.0,
            -params.mu * alpha,
        )?;
    }
    Ok(energy.minimize().labels)
}

fn check_params(params: &PottsParams) -> Result<()> {
    let ok = |v: f64| v.is_finite() && v >= 0.0;
    if !(ok(params.mu)
        && ok(params.beta)
        && ok(params.lambda)
        && ok(params.theta_true)
        && ok(params.sigma)
        && params.sigma > 0.0)
    {
        return Err(Error::InvalidArgument(format!(
            "Potts labelling: mu, beta, lambda, theta_true must be finite and >= 0 and sigma > 0, \
             got {params:?}"
        )));
    }
    Ok(())
}
