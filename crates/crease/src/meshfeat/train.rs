//! Training data for the learned classifier ([`super::svm`]): labelled meshes (the default
//! model's synthetic parts come from [`crate::synth::training_meshes`]) and the training set of section 6.3 built from
//! clean and noisy versions of labelled meshes.

use rayon::prelude::*;

use super::features::{edge_features, FeatureParams};
use super::svm::TrainingSet;
use super::truth::{add_noise, labels_from_pairs};
use super::EdgeMesh;
use crate::geometry::TriMesh;
use crate::{Error, Result};

/// A mesh with per-edge ground truth (one label per edge of its [`EdgeMesh`], true = feature).
#[derive(Debug, Clone)]
pub struct LabelledMesh {
    /// Name for reports.
    pub name: String,
    /// The clean mesh.
    pub mesh: TriMesh,
    /// Per-edge labels (topology order).
    pub truth: Vec<bool>,
}

impl LabelledMesh {
    /// A mesh labelled by the vertex pairs of its feature edges (e.g. a synthetic part's
    /// `sharp_edges`); boundary edges are feature edges too (section 2).
    pub fn from_pairs(name: String, mesh: TriMesh, pairs: &[[u32; 2]]) -> Result<LabelledMesh> {
        let em = EdgeMesh::new(&mesh)?;
        let (mut truth, _) = labels_from_pairs(&em.topo, pairs);
        for &e in em.topo.boundary_edges() {
            truth[e as usize] = true;
        }
        drop(em);
        Ok(LabelledMesh { name, mesh, truth })
    }
}

/// Settings of [`training_set`].
#[derive(Debug, Clone, PartialEq)]
pub struct SetParams {
    /// Noise levels of the versions of every mesh (0 = the clean mesh; section 6.1: 0.005 of
    /// the bounding box's largest side).
    pub noise: Vec<f64>,
    /// At most this many edges per mesh version (section 6.3: 5000 per mesh model).
    pub max_edges_per_mesh: usize,
    /// Seed of noise and subsampling.
    pub seed: u64,
}

impl Default for SetParams {
    fn default() -> Self {
        SetParams {
            noise: vec![0.0, 0.005],
            max_edges_per_mesh: 400,
            seed: 11,
        }
    }
}

/// The training set of section 6.3 from `meshes`: every mesh in every noise version, its
/// features computed (meshes in sequence, each in parallel), duplicates removed and at most
/// `max_edges_per_mesh` edges kept per version with the class proportions.
pub fn training_set(
    meshes: &[LabelledMesh],
    features: &FeatureParams,
    p: &SetParams,
) -> Result<TrainingSet> {
    let mut set = TrainingSet::default();
    for (i, m) in meshes.iter().enumerate() {
        for (j, &sigma) in p.noise.iter().enumerate() {
            let seed = p.seed.wrapping_add((i * 16 + j) as u64);
            let noisy;
            let mesh = if sigma > 0.0 {
                noisy = add_noise(&m.mesh, sigma, seed)?;
                &noisy
            } else {
                &m.mesh
            };
            let em = EdgeMesh::new(mesh)?;
            if em.num_edges() != m.truth.len() {
                return Err(Error::InvalidInput(format!(
                    "{}: {} labels for {} edges",
                    m.name,
                    m.truth.len(),
                    em.num_edges()
                )));
            }
            let f = edge_features(&em, features)?;
            let name = format!("{} noise {sigma}", m.name);
            set.add_mesh(&name, &f, &m.truth, p.max_edges_per_mesh, seed)?;
            tracing::info!("training set: {name}: {} edges", em.num_edges());
        }
    }
    Ok(set)
}

/// The F-score of every feature (Chen & Lin 2006, the paper's Table 1): between-class
/// variance of the means over the sum of the within-class variances.
pub fn f_scores(set: &TrainingSet) -> Vec<f64> {
    let d = set.dim;
    let n = set.len();
    (0..d)
        .into_par_iter()
        .map(|k| {
            let (mut s, mut sp, mut sn, mut np) = (0.0, 0.0, 0.0, 0usize);
            for i in 0..n {
                let v = f64::from(set.x[i * d + k]);
                s += v;
                if set.y[i] {
                    sp += v;
                    np += 1;
                } else {
                    sn += v;
                }
            }
            let nn = n - np;
            if np < 2 || nn < 2 {
                return 0.0;
            }
            let (m, mp, mn) = (s / n as f64, sp / np as f64, sn / nn as f64);
            let (mut vp, mut vn) = (0.0, 0.0);
            for i in 0..n {
                let v = f64::from(set.x[i * d + k]);
                if set.y[i] {
                    vp += (v - mp) * (v - mp);
                } else {
                    vn += (v - mn) * (v - mn);
                }
            }
            let den = vp / (np - 1) as f64 + vn / (nn - 1) as f64;
            if den > 0.0 {
                ((mp - m).powi(2) + (mn - m).powi(2)) / den
            } else {
                0.0
            }
        })
        .collect()
}
