//! The learned edge classifier of vidal et al. 2011 (sections 4 and 6.3): an RBF support
//! vector machine on the feature vector of [`super::features`], trained with the feature
//! class weighted 9 times the normal class, its hyper-parameters chosen by grid search with
//! cross-validation maximising the AUC; the signed decision value d(e) is the data term of
//! equation 2.
//!
//! **Why crease has its own solver.** linfa-svm (the Rust SVM crate) has the RBF kernel and
//! per-class weights (`pos_neg_weights`), but its fitted `Svm` (docs.rs, 0.7) exposes only
//! `alpha`, `rho`, `nsupport` and `weighted_sum`: the support vectors stay in a private field,
//! and it brings the ndarray / linfa stack in for a few hundred lines of solver. crease needs
//! the support vectors themselves, to save a compact versioned model and to evaluate the
//! decision function over millions of edges in parallel with its own vectorised kernel loop. The
//! solver here is the SMO of LIBSVM (the library the paper used): C-SVC dual with per-class
//! bounds C₊ = 9 C, C₋ = C, working-set selection by second-order information (Fan, Chen &
//! Lin, JMLR 2005), the full kernel matrix in memory (training sets are capped at a few
//! thousand edges, as the paper's 5000 per mesh).
//!
//! **Normalisation.** Each feature is mapped affinely to [−1, 1] (section 4) from its 0.5 % and
//! 99.5 % quantiles over the training set and clipped there (crease's choice: plain min / max,
//! as `svm-scale`, lets a few noisy-mesh curvature outliers squeeze all other values to a
//! point). The same map, stored in the model, is applied to every mesh the model is used on.
//!
//! **Training set (section 6.3).** Per mesh, duplicate feature vectors are removed and at most
//! a fixed number of edges is drawn at random keeping the class proportions.

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_pcg::Pcg64;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::features::{EdgeFeatures, FeatureParams};
use crate::eval::roc::roc;
use crate::{Error, Result};

/// Version of the model file format (2: the features record the tangent-plane estimator's
/// noise-adapted acceptance angle, `tangent_noise_accept`; version-1 files read as the paper's
/// fixed angle).
pub const MODEL_VERSION: u32 = 2;
/// The `format` tag of a model file.
pub const MODEL_FORMAT: &str = "crease-edge-svm";
/// Support vector coordinates are stored as integers of this many units per 1 (they are in
/// [−1, 1] after normalisation).
const QUANT: f32 = 30000.0;
/// Lanes of the vectorised kernel loop.
const LANES: usize = 8;

/// The affine map of each feature to [−1, 1].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Normalizer {
    /// Value mapped to −1, per feature.
    pub lo: Vec<f32>,
    /// Value mapped to +1, per feature.
    pub hi: Vec<f32>,
}

impl Normalizer {
    /// Quantiles 0.5 % and 99.5 % of every feature over `x` (row-major, `dim` per row).
    pub fn fit(x: &[f32], dim: usize) -> Normalizer {
        let n = x.len() / dim.max(1);
        let (lo, hi): (Vec<f32>, Vec<f32>) = (0..dim)
            .into_par_iter()
            .map(|k| {
                let mut col: Vec<f32> = (0..n).map(|i| x[i * dim + k]).collect();
                col.sort_by(f32::total_cmp);
                if col.is_empty() {
                    return (-1.0, 1.0);
                }
                let q = |f: f64| col[((f * (n - 1) as f64).round() as usize).min(n - 1)];
                let (a, b) = (q(0.005), q(0.995));
                if b > a {
                    (a, b)
                } else {
                    (a - 1.0, a + 1.0)
                }
            })
            .unzip();
        Normalizer { lo, hi }
    }

    /// Number of features.
    pub fn dim(&self) -> usize {
        self.lo.len()
    }

    /// `row` normalised into `out` (same length), clipped to [−1, 1]; NaN becomes 0.
    pub fn apply(&self, row: &[f32], out: &mut [f32]) {
        for k in 0..self.lo.len() {
            let v = 2.0 * (row[k] - self.lo[k]) / (self.hi[k] - self.lo[k]) - 1.0;
            out[k] = if v.is_nan() { 0.0 } else { v.clamp(-1.0, 1.0) };
        }
    }

    /// All rows of `x` normalised.
    pub fn apply_all(&self, x: &[f32]) -> Vec<f32> {
        let d = self.dim();
        let mut out = vec![0f32; x.len()];
        out.par_chunks_mut(d.max(1))
            .zip(x.par_chunks(d.max(1)))
            .for_each(|(o, r)| self.apply(r, o));
        out
    }
}

/// The feature parameters a model was trained with (prediction must use the same).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FeatureSpec {
    /// Tangent-plane scales.
    pub tangent_scales: Vec<f64>,
    /// Tangent-plane face budget.
    pub tangent_max_faces: Option<usize>,
    /// The noise factor of the tangent-plane acceptance angle
    /// ([`crate::meshfeat::TangentParams::noise_accept`]); absent in version-1 models, which
    /// were trained with the paper's fixed 23°.
    #[serde(default)]
    pub tangent_noise_accept: Option<f64>,
    /// Curvature scales.
    pub curvature_scales: Vec<f64>,
    /// Curvature ball budget.
    pub max_items: Option<usize>,
}

impl FeatureSpec {
    /// The spec of `p`.
    pub fn of(p: &FeatureParams) -> FeatureSpec {
        FeatureSpec {
            tangent_scales: p.tangent.scales.clone(),
            tangent_max_faces: p.tangent.max_faces,
            tangent_noise_accept: p.tangent.noise_accept,
            curvature_scales: p.curvature_scales.clone(),
            max_items: p.max_items,
        }
    }

    /// The feature parameters (the rest at their defaults).
    pub fn params(&self) -> FeatureParams {
        let mut p = FeatureParams::default();
        p.tangent.scales = self.tangent_scales.clone();
        p.tangent.max_faces = self.tangent_max_faces;
        p.tangent.noise_accept = self.tangent_noise_accept;
        p.curvature_scales = self.curvature_scales.clone();
        p.max_items = self.max_items;
        p
    }
}

/// A trained RBF SVM: d(x) = Σ_i coef_i exp(−γ |s_i − x̂|²) + bias, x̂ the normalised features.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SvmModel {
    /// Always [`MODEL_FORMAT`].
    pub format: String,
    /// [`MODEL_VERSION`] when written.
    pub version: u32,
    /// What it was trained on.
    pub description: String,
    /// Feature parameters.
    pub features: FeatureSpec,
    /// Normalisation.
    pub normalizer: Normalizer,
    /// RBF γ.
    pub gamma: f64,
    /// C of the normal class (the feature class has `positive_weight` × C).
    pub c: f64,
    /// Weight of the feature class (section 6.3: 9).
    pub positive_weight: f64,
    /// Mean cross-validation AUC of the chosen (C, γ).
    pub cv_auc: f64,
    /// Number of training edges (feature, normal).
    pub training_edges: [usize; 2],
    /// The bias (−ρ).
    pub bias: f64,
    /// α_i y_i per support vector.
    pub coef: Vec<f32>,
    /// Support vectors, normalised, row-major, quantised: value × 30000 rounded.
    pub support: Vec<i16>,
}

impl SvmModel {
    /// Number of support vectors.
    pub fn num_support(&self) -> usize {
        self.coef.len()
    }

    /// Parses a model file's text. Errors: not JSON, not a crease model, a newer version,
    /// inconsistent sizes.
    pub fn from_json(text: &str) -> std::result::Result<SvmModel, String> {
        let m: SvmModel = serde_json::from_str(text).map_err(|e| format!("not a model: {e}"))?;
        if m.format != MODEL_FORMAT {
            return Err(format!("format `{}` is not `{MODEL_FORMAT}`", m.format));
        }
        if m.version > MODEL_VERSION {
            return Err(format!(
                "model version {} is newer than this crease's ({MODEL_VERSION})",
                m.version
            ));
        }
        let d = m.normalizer.dim();
        if d == 0 || m.normalizer.hi.len() != d || m.support.len() != d * m.coef.len() {
            return Err(format!(
                "inconsistent sizes: {} features, {} support values for {} coefficients",
                d,
                m.support.len(),
                m.coef.len()
            ));
        }
        let nf = 4 + m.features.tangent_scales.len() + 6 * m.features.curvature_scales.len();
        if nf != d {
            return Err(format!(
                "the feature parameters give {nf} features but the normaliser has {d}"
            ));
        }
        if !(m.gamma.is_finite() && m.gamma > 0.0 && m.bias.is_finite()) {
            return Err("gamma must be positive and the bias finite".into());
        }
        Ok(m)
    }

    /// Reads a model file. Errors name the file.
    pub fn read(path: &std::path::Path) -> Result<SvmModel> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
        SvmModel::from_json(&text).map_err(|m| Error::format(path, m))
    }

    /// The model as JSON.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Writes the model file.
    pub fn write(&self, path: &std::path::Path) -> Result<()> {
        crate::io::atomic::replace(path, |tmp| {
            std::fs::write(tmp, self.to_json()).map_err(|e| Error::io(tmp, e))
        })
    }

    /// The decision value d(e) of every edge (positive = feature edge), in parallel.
    ///
    /// Errors: features of another dimension than the model's.
    pub fn decision_values(&self, f: &EdgeFeatures) -> Result<Vec<f64>> {
        let d = self.normalizer.dim();
        if f.dim != d {
            return Err(Error::InvalidArgument(format!(
                "SVM: the model has {d} features, the mesh's vectors {}",
                f.dim
            )));
        }
        let pd = d.div_ceil(LANES) * LANES;
        let nsv = self.num_support();
        let mut sv = vec![0f32; nsv * pd];
        let mut sv2 = vec![0f32; nsv];
        for i in 0..nsv {
            for k in 0..d {
                sv[i * pd + k] = f32::from(self.support[i * d + k]) / QUANT;
            }
            sv2[i] = sv[i * pd..(i + 1) * pd].iter().map(|v| v * v).sum();
        }
        let gamma = self.gamma as f32;
        let mut out = vec![0f64; f.len()];
        out.par_chunks_mut(64).enumerate().for_each(|(ci, chunk)| {
            let mut x = vec![0f32; pd];
            for (j, o) in chunk.iter_mut().enumerate() {
                let e = ci * 64 + j;
                self.normalizer.apply(f.row(e), &mut x[..d]);
                let x2: f32 = x.iter().map(|v| v * v).sum();
                let mut acc = 0f64;
                for i in 0..nsv {
                    let s = &sv[i * pd..(i + 1) * pd];
                    let mut lanes = [0f32; LANES];
                    for (xs, ss) in x.chunks_exact(LANES).zip(s.chunks_exact(LANES)) {
                        for l in 0..LANES {
                            lanes[l] += xs[l] * ss[l];
                        }
                    }
                    let dot: f32 = lanes.iter().sum();
                    let d2 = (x2 + sv2[i] - 2.0 * dot).max(0.0);
                    acc += f64::from(self.coef[i] * (-gamma * d2).exp());
                }
                *o = acc + self.bias;
            }
        });
        Ok(out)
    }
}

/// The model shipped with crease, trained on synthetic parts only (see
/// `examples/train_default.rs`).
pub fn default_model() -> &'static SvmModel {
    static MODEL: std::sync::OnceLock<SvmModel> = std::sync::OnceLock::new();
    MODEL.get_or_init(|| {
        SvmModel::from_json(include_str!("default_model.json"))
            .expect("the shipped default model parses")
    })
}

/// Training samples: raw feature rows and labels.
#[derive(Debug, Clone, Default)]
pub struct TrainingSet {
    /// Features per row.
    pub dim: usize,
    /// Row-major raw features.
    pub x: Vec<f32>,
    /// Label per row (true = feature edge).
    pub y: Vec<bool>,
    /// Names of the meshes added.
    pub sources: Vec<String>,
}

impl TrainingSet {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.y.len()
    }

    /// True if empty.
    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }

    /// Adds the edges of one mesh (section 6.3): duplicates removed, then at most `max_edges`
    /// drawn at random (seeded) keeping the class proportions (at least one of each class
    /// present). Errors: a truth of the wrong length, another dimension than earlier meshes.
    pub fn add_mesh(
        &mut self,
        name: &str,
        f: &EdgeFeatures,
        truth: &[bool],
        max_edges: usize,
        seed: u64,
    ) -> Result<()> {
        if truth.len() != f.len() {
            return Err(Error::InvalidArgument(format!(
                "training set: {name}: {} labels for {} edges",
                truth.len(),
                f.len()
            )));
        }
        if self.dim == 0 {
            self.dim = f.dim;
        } else if self.dim != f.dim {
            return Err(Error::InvalidArgument(format!(
                "training set: {name} has {} features, earlier meshes {}",
                f.dim, self.dim
            )));
        }
        let mut seen = std::collections::HashSet::new();
        let mut pos = Vec::new();
        let mut neg = Vec::new();
        for (e, &t) in truth.iter().enumerate() {
            let key: Vec<u32> = f.row(e).iter().map(|v| v.to_bits()).collect();
            if seen.insert((key, t)) {
                if t {
                    pos.push(e);
                } else {
                    neg.push(e);
                }
            }
        }
        let total = pos.len() + neg.len();
        let mut rng = Pcg64::seed_from_u64(seed);
        let (mut np, mut nn) = (pos.len(), neg.len());
        if total > max_edges {
            np = ((max_edges as f64 * pos.len() as f64 / total as f64).round() as usize)
                .max(usize::from(!pos.is_empty()))
                .min(pos.len());
            nn = (max_edges - np).min(neg.len());
        }
        pos.shuffle(&mut rng);
        neg.shuffle(&mut rng);
        let mut take: Vec<(usize, bool)> = pos[..np]
            .iter()
            .map(|&e| (e, true))
            .chain(neg[..nn].iter().map(|&e| (e, false)))
            .collect();
        take.sort_unstable();
        for (e, t) in take {
            self.x.extend_from_slice(f.row(e));
            self.y.push(t);
        }
        self.sources.push(name.to_string());
        Ok(())
    }
}

/// Settings of [`train`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrainParams {
    /// Candidate C (normal class).
    pub c_grid: Vec<f64>,
    /// Candidate γ.
    pub gamma_grid: Vec<f64>,
    /// Cross-validation folds (≥ 2; 0 or 1 = no search, the first C and γ).
    pub folds: usize,
    /// Weight of the feature class (section 6.3: 9).
    pub positive_weight: f64,
    /// SMO stopping tolerance (LIBSVM's default 1e-3).
    pub eps: f64,
    /// Iteration cap of one SMO run.
    pub max_iterations: usize,
    /// Seed of the fold assignment.
    pub seed: u64,
    /// Free text stored in the model.
    pub description: String,
}

impl Default for TrainParams {
    fn default() -> Self {
        TrainParams {
            c_grid: vec![0.5, 2.0, 8.0, 32.0],
            gamma_grid: vec![0.01, 0.03, 0.1, 0.3],
            folds: 3,
            positive_weight: 9.0,
            eps: 1e-3,
            max_iterations: 200_000,
            seed: 1,
            description: String::new(),
        }
    }
}

/// Result of one SMO run on a sub-problem.
struct Solution {
    /// α_i y_i per training row of the sub-problem.
    coef: Vec<f64>,
    /// −ρ.
    bias: f64,
}

/// Squared distances between all normalised rows (n × n, f32).
fn squared_distances(x: &[f32], dim: usize) -> Vec<f32> {
    let n = x.len() / dim;
    let mut d = vec![0f32; n * n];
    d.par_chunks_mut(n).enumerate().for_each(|(i, row)| {
        let a = &x[i * dim..(i + 1) * dim];
        for (j, o) in row.iter_mut().enumerate() {
            let b = &x[j * dim..(j + 1) * dim];
            *o = a.iter().zip(b).map(|(p, q)| (p - q) * (p - q)).sum();
        }
    });
    d
}

/// SMO (LIBSVM's C-SVC solver, second-order working-set selection) on the rows `idx` of the
/// kernel matrix `k` (n × n over all rows).
#[allow(clippy::too_many_arguments)]
fn smo(
    k: &[f32],
    n: usize,
    idx: &[usize],
    y: &[bool],
    c_pos: f64,
    c_neg: f64,
    eps: f64,
    max_iter: usize,
) -> Solution {
    let m = idx.len();
    let ys: Vec<f64> = idx.iter().map(|&i| if y[i] { 1.0 } else { -1.0 }).collect();
    let cb: Vec<f64> = idx
        .iter()
        .map(|&i| if y[i] { c_pos } else { c_neg })
        .collect();
    let kk = |a: usize, b: usize| f64::from(k[idx[a] * n + idx[b]]);
    let mut alpha = vec![0.0f64; m];
    let mut grad = vec![-1.0f64; m];
    let up = |t: usize, alpha: &[f64]| {
        if ys[t] > 0.0 {
            alpha[t] < cb[t]
        } else {
            alpha[t] > 0.0
        }
    };
    let low = |t: usize, alpha: &[f64]| {
        if ys[t] > 0.0 {
            alpha[t] > 0.0
        } else {
            alpha[t] < cb[t]
        }
    };
    let tau = 1e-12;
    for _ in 0..max_iter {
        // Working set: i maximal violator, j by second-order gain.
        let mut gmax = f64::NEG_INFINITY;
        let mut i = usize::MAX;
        for t in 0..m {
            if up(t, &alpha) {
                let v = -ys[t] * grad[t];
                if v > gmax {
                    gmax = v;
                    i = t;
                }
            }
        }
        if i == usize::MAX {
            break;
        }
        let kii = kk(i, i);
        let mut gmin = f64::INFINITY;
        let mut j = usize::MAX;
        let mut best = f64::INFINITY;
        for t in 0..m {
            if low(t, &alpha) {
                let v = -ys[t] * grad[t];
                gmin = gmin.min(v);
                let b = gmax - v;
                if b > 0.0 {
                    let a = (kii + kk(t, t) - 2.0 * kk(i, t)).max(tau);
                    let obj = -(b * b) / a;
                    if obj <= best {
                        best = obj;
                        j = t;
                    }
                }
            }
        }
        if gmax - gmin < eps || j == usize::MAX {
            break;
        }
        let (ai, aj) = (alpha[i], alpha[j]);
        let (ci, cj) = (cb[i], cb[j]);
        let kij = kk(i, j);
        let quad = (kii + kk(j, j) - 2.0 * kij).max(tau);
        if ys[i] != ys[j] {
            let delta = (-grad[i] - grad[j]) / quad;
            let diff = alpha[i] - alpha[j];
            alpha[i] += delta;
            alpha[j] += delta;
            if diff > 0.0 {
                if alpha[j] < 0.0 {
                    alpha[j] = 0.0;
                    alpha[i] = diff;
                }
            } else if alpha[i] < 0.0 {
                alpha[i] = 0.0;
                alpha[j] = -diff;
            }
            if diff > ci - cj {
                if alpha[i] > ci {
                    alpha[i] = ci;
                    alpha[j] = ci - diff;
                }
            } else if alpha[j] > cj {
                alpha[j] = cj;
                alpha[i] = cj + diff;
            }
        } else {
            let delta = (grad[i] - grad[j]) / quad;
            let sum = alpha[i] + alpha[j];
            alpha[i] -= delta;
            alpha[j] += delta;
            if sum > ci {
                if alpha[i] > ci {
                    alpha[i] = ci;
                    alpha[j] = sum - ci;
                }
            } else if alpha[j] < 0.0 {
                alpha[j] = 0.0;
                alpha[i] = sum;
            }
            if sum > cj {
                if alpha[j] > cj {
                    alpha[j] = cj;
                    alpha[i] = sum - cj;
                }
            } else if alpha[i] < 0.0 {
                alpha[i] = 0.0;
                alpha[j] = sum;
            }
        }
        let (dai, daj) = (alpha[i] - ai, alpha[j] - aj);
        let (yi, yj) = (ys[i], ys[j]);
        let ri = &k[idx[i] * n..(idx[i] + 1) * n];
        let rj = &k[idx[j] * n..(idx[j] + 1) * n];
        for t in 0..m {
            let it = idx[t];
            grad[t] += ys[t] * (yi * dai * f64::from(ri[it]) + yj * daj * f64::from(rj[it]));
        }
    }
    // ρ: mean of y G over free variables, else the middle of the feasible interval.
    let (mut sum, mut nfree) = (0.0, 0usize);
    let (mut ub, mut lb) = (f64::INFINITY, f64::NEG_INFINITY);
    for t in 0..m {
        let yg = ys[t] * grad[t];
        if alpha[t] > 0.0 && alpha[t] < cb[t] {
            sum += yg;
            nfree += 1;
        } else if (alpha[t] >= cb[t] && ys[t] < 0.0) || (alpha[t] <= 0.0 && ys[t] > 0.0) {
            ub = ub.min(yg);
        } else {
            lb = lb.max(yg);
        }
    }
    let rho = if nfree > 0 {
        sum / nfree as f64
    } else if ub.is_finite() && lb.is_finite() {
        0.5 * (ub + lb)
    } else if ub.is_finite() {
        ub
    } else if lb.is_finite() {
        lb
    } else {
        0.0
    };
    Solution {
        coef: alpha.iter().zip(&ys).map(|(a, y)| a * y).collect(),
        bias: -rho,
    }
}

/// One cell of the grid search: (C, γ, mean cross-validation AUC).
pub type GridCell = (f64, f64, f64);

/// Trains the classifier on `set` (section 6.3): normalisation, grid search over C × γ with
/// stratified `folds`-fold cross-validation maximising the mean per-fold AUC, then the final
/// model on all rows with the best pair. Returns the model and the grid's AUCs.
///
/// Errors: an empty set or one class missing, a bad grid.
pub fn train(
    set: &TrainingSet,
    features: &FeatureParams,
    params: &TrainParams,
) -> Result<(SvmModel, Vec<GridCell>)> {
    let n = set.len();
    let npos = set.y.iter().filter(|&&t| t).count();
    if npos == 0 || npos == n {
        return Err(Error::InvalidInput(format!(
            "training: {npos} feature and {} normal edges; both classes are needed",
            n - npos
        )));
    }
    let ok = |v: &f64| v.is_finite() && *v > 0.0;
    if params.c_grid.is_empty()
        || params.gamma_grid.is_empty()
        || !params.c_grid.iter().all(ok)
        || !params.gamma_grid.iter().all(ok)
        || !ok(&params.positive_weight)
    {
        return Err(Error::InvalidArgument(
            "training: C, gamma and the class weight must be positive".into(),
        ));
    }
    let dim = set.dim;
    let normalizer = Normalizer::fit(&set.x, dim);
    let xn = normalizer.apply_all(&set.x);
    let d2 = squared_distances(&xn, dim);
    // Stratified folds.
    let mut rng = Pcg64::seed_from_u64(params.seed);
    let mut pos: Vec<usize> = (0..n).filter(|&i| set.y[i]).collect();
    let mut neg: Vec<usize> = (0..n).filter(|&i| !set.y[i]).collect();
    pos.shuffle(&mut rng);
    neg.shuffle(&mut rng);
    let nf = params.folds.max(1);
    let mut fold = vec![0usize; n];
    for (r, &i) in pos.iter().chain(neg.iter()).enumerate() {
        fold[i] = r % nf;
    }
    let mut grid = Vec::new();
    let mut best = (params.c_grid[0], params.gamma_grid[0], f64::NEG_INFINITY);
    for &g in &params.gamma_grid {
        let k: Vec<f32> = d2.par_iter().map(|&v| (-(g as f32) * v).exp()).collect();
        if nf < 2 {
            break;
        }
        for &c in &params.c_grid {
            // Folds in parallel (each SMO run is sequential).
            let aucs: Vec<f64> = (0..nf)
                .into_par_iter()
                .map(|f| {
                    let tr: Vec<usize> = (0..n).filter(|&i| fold[i] != f).collect();
                    let te: Vec<usize> = (0..n).filter(|&i| fold[i] == f).collect();
                    let s = smo(
                        &k,
                        n,
                        &tr,
                        &set.y,
                        c * params.positive_weight,
                        c,
                        params.eps,
                        params.max_iterations,
                    );
                    let scores: Vec<f64> = te
                        .iter()
                        .map(|&t| {
                            s.bias
                                + tr.iter()
                                    .zip(&s.coef)
                                    .filter(|(_, &a)| a != 0.0)
                                    .map(|(&i, &a)| a * f64::from(k[t * n + i]))
                                    .sum::<f64>()
                        })
                        .collect();
                    let truth: Vec<bool> = te.iter().map(|&t| set.y[t]).collect();
                    roc(&scores, &truth).map(|r| r.auc).unwrap_or(0.5)
                })
                .collect();
            let auc = aucs.iter().sum::<f64>() / aucs.len() as f64;
            tracing::debug!("grid C {c} gamma {g}: AUC {auc:.5}");
            grid.push((c, g, auc));
            if auc > best.2 {
                best = (c, g, auc);
            }
        }
    }
    let (c, g, cv_auc) = best;
    let k: Vec<f32> = d2.par_iter().map(|&v| (-(g as f32) * v).exp()).collect();
    let all: Vec<usize> = (0..n).collect();
    let s = smo(
        &k,
        n,
        &all,
        &set.y,
        c * params.positive_weight,
        c,
        params.eps,
        params.max_iterations,
    );
    let mut coef = Vec::new();
    let mut support = Vec::new();
    for (i, &a) in s.coef.iter().enumerate() {
        if a != 0.0 {
            coef.push(a as f32);
            support.extend(
                xn[i * dim..(i + 1) * dim]
                    .iter()
                    .map(|v| (v * QUANT).round() as i16),
            );
        }
    }
    Ok((
        SvmModel {
            format: MODEL_FORMAT.into(),
            version: MODEL_VERSION,
            description: params.description.clone(),
            features: FeatureSpec::of(features),
            normalizer,
            gamma: g,
            c,
            positive_weight: params.positive_weight,
            cv_auc: if cv_auc.is_finite() { cv_auc } else { 0.0 },
            training_edges: [npos, n - npos],
            bias: s.bias,
            coef,
            support,
        },
        grid,
    ))
}
