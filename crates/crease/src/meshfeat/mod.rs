//! Feature edges of triangle meshes that survive noise (V. Vidal, C. Wolf, F. Dupont, "Robust
//! feature line extraction on CAD triangular meshes", GRAPP 2011).
//!
//! * [`tangent`]: the estimator θ̂ʳ_e of the angle between the tangent-plane normals at an edge
//!   at scale r (section 3), multi-scale, parallel over the edges;
//! * [`baseline`]: the baselines of Table 2, thresholding of the dihedral angle and hysteresis
//!   thresholding;
//! * [`potts`]: the global energy of equations 1–5 minimised exactly by one graph cut, with the
//!   dihedral angle (`potts-dihedral`) or the tangent-plane angle (`potts-tangent`) as data;
//! * [`truth`]: per-edge ground truth (synthetic parts, ABC sharp curves, the labelling and
//!   noise protocol of section 6.1) and [`sweep_auc`] for the ROC of a labelling swept over a
//!   parameter (section 6.3).
//!
//! Everything works on an [`EdgeMesh`]: the mesh, its [`MeshTopology`] (edge ids are the
//! topology's: sorted vertex pairs) and consistently oriented face normals. Per-edge outputs
//! have one entry per edge in that order; [`detect_edges`] runs a [`EdgeMethod`] end to end and
//! [`feature_polylines`] chains the feature edges into polylines.
//!
//! * [`features`]: the 43-dimensional feature vector of section 4;
//! * [`svm`]: the RBF SVM trained on it (section 6.3), its model file and the default model
//!   (trained on synthetic parts only, `examples/train_default.rs`); `learned` thresholds its
//!   decision value at 0, `potts-learned` feeds it to equation 1 as the data term of
//!   equation 2;
//! * [`train`]: labelled meshes, the synthetic training parts and the training set;
//! * [`bilateral`] and [`tv`] (crease's additions, not in the paper): bilateral and
//!   total-variation filtering of the face normals; `filtered` thresholds the mean of the two
//!   dihedral angles of the filtered normals ([`filtered_dihedral`]), `potts-filtered` feeds it
//!   to equation 1 with the data term of equation 5. On noisy meshes it ranks edges far better
//!   than the SVM; given to the SVM as more features, it did not help the learned classifier
//!   (figures: `docs/experiments/mesh-edges-fused.md`);
//! * `fused` (the default, crease's addition): the SVM decision value and the filtered angle
//!   combined ([`fused_scores`]), better than either on every noise level measured, plus the
//!   evidence of [`surfaces`]: where the analytic surfaces fitted by the segmentation
//!   (mizoguchi, [`crate::segment`]) intersect.

pub mod baseline;
pub mod bilateral;
pub mod features;
mod grid;
pub mod line;
pub mod potts;
pub mod surfaces;
pub mod svm;
pub mod tangent;
pub mod train;
pub mod truth;
pub mod tv;

/// Shared fixtures of the unit tests of the meshfeat modules.
#[cfg(test)]
pub(crate) mod test_support {
    use crate::synth::{mesh as synth_mesh, MeshParams, Shape, SyntheticMesh};

    /// The unit cube meshed with edges of 1 / `per_side` of its side, with exact sharp edges.
    pub fn cube(per_side: f64) -> SyntheticMesh {
        let shape = Shape::from_name("cube").expect("shape");
        synth_mesh(
            &shape,
            &MeshParams {
                target_edge: Some(shape.aabb().max_side() / per_side),
                ..Default::default()
            },
        )
        .expect("mesh")
    }

    /// The median of `v` (the upper one for an even count).
    pub fn median(mut v: Vec<f64>) -> f64 {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    }

    /// The median, in degrees, of the angles (radians) of the edges where `pick` holds.
    pub fn median_degrees(angles: &[f64], pick: impl Fn(usize) -> bool) -> f64 {
        median(
            (0..angles.len())
                .filter(|&e| pick(e))
                .map(|e| angles[e].to_degrees())
                .collect(),
        )
    }
}

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

pub use baseline::{hysteresis_scores, threshold};
pub use bilateral::BilateralParams;
pub use features::{edge_features, EdgeFeatures, FeatureParams, NUM_FEATURES};
pub use line::LineParams;
pub use potts::{potts_labels, potts_labels_unary, svm_unary, EdgePairs, PottsParams};
pub use surfaces::{intersection_scores, IntersectionParams};
pub use svm::{default_model, SvmModel, TrainParams, TrainingSet};
pub use tangent::{accept_angle, tangent_angles, TangentAngles, TangentParams, PAPER_SCALES};
pub use train::{training_set, LabelledMesh, SetParams};
pub use truth::{
    add_noise, classic_label_degrees, dihedral_labels, labels_from_pairs, read_abc_sharp_edges,
    sliver_edges, CLASSIC_LABELS,
};
pub use tv::TvParams;

use crate::eval::roc::{trapezoid_area, RocPoint};
use crate::geometry::{chain_segments, vec3, Aabb, MeshTopology, Point3, TriMesh};
use crate::{Error, Result};

/// A mesh prepared for edge classification: topology, consistently oriented face normals,
/// areas, barycentres, dihedral angles and the scale reference.
#[derive(Debug, Clone)]
pub struct EdgeMesh<'a> {
    /// The mesh.
    pub mesh: &'a TriMesh,
    /// Its edge topology (edge ids).
    pub topo: MeshTopology,
    /// Unit face normals, flipped where needed so that neighbouring faces agree across every
    /// manifold edge (as far as the surface is orientable); zero for degenerate faces.
    pub normals: Vec<Point3>,
    /// Face areas.
    pub areas: Vec<f64>,
    /// Face barycentres.
    pub centroids: Vec<Point3>,
    /// Dihedral angle θ_e per edge, radians in [0, π]: the angle between the oriented normals
    /// of its two faces; π for boundary and non-manifold edges (section 2) and for edges with
    /// a degenerate face.
    pub dihedral: Vec<f64>,
    /// Length the scales r are relative to: the smallest side of the bounding box (section 4,
    /// "min BB"), but at least a quarter of the largest side, so that a flat part (a plate, a
    /// noisy planar grid) keeps scales of a meaningful size.
    pub reference_length: f64,
    /// Number of faces flipped to orient the normals consistently.
    pub flipped_faces: usize,
    /// Mean length of the edges.
    pub mean_edge_length: f64,
}

impl<'a> EdgeMesh<'a> {
    /// Prepares `mesh`. Errors: face indices out of range, a mesh too large for the topology,
    /// no faces, non-finite coordinates, a span outside [`crate::spatial::check_extent`]'s.
    pub fn new(mesh: &'a TriMesh) -> Result<EdgeMesh<'a>> {
        if mesh.faces.is_empty() {
            return Err(Error::InvalidInput(
                "feature edges need a triangle mesh, but there are no faces".into(),
            ));
        }
        // A vertex 1e308 away: lengths and areas overflow, and the ball searches of every
        // feature hold the whole mesh (a fuzzed 19k-face STL took 98 s).
        crate::spatial::check_extent(mesh.positions())?;
        if let Some(i) = mesh
            .positions()
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(Error::InvalidInput(format!(
                "vertex {i} has a coordinate that is not finite"
            )));
        }
        let topo = MeshTopology::new(mesh)?;
        let p = mesh.positions();
        let (areas, centroids): (Vec<f64>, Vec<Point3>) = mesh
            .faces
            .par_iter()
            .map(|&[a, b, c]| {
                let (a, b, c) = (p[a as usize], p[b as usize], p[c as usize]);
                (
                    0.5 * vec3::norm(vec3::cross(vec3::sub(b, a), vec3::sub(c, a))),
                    vec3::scale(vec3::add(vec3::add(a, b), c), 1.0 / 3.0),
                )
            })
            .unzip();
        let (signs, flipped_faces) = if topo.is_oriented() {
            (None, 0)
        } else {
            let s = orientation_signs(&topo);
            let n = s.iter().filter(|&&x| x).count();
            (Some(s), n)
        };
        let normals: Vec<Point3> = topo
            .face_normals()
            .par_iter()
            .enumerate()
            .map(|(f, &n)| match &signs {
                Some(s) if s[f] => vec3::scale(n, -1.0),
                _ => n,
            })
            .collect();
        let dihedral: Vec<f64> = (0..topo.num_edges())
            .into_par_iter()
            .map(|e| {
                let fs = topo.edge_faces(e);
                if fs.len() != 2 {
                    return std::f64::consts::PI;
                }
                let (a, b) = (fs[0] as usize, fs[1] as usize);
                if areas[a] <= 0.0 || areas[b] <= 0.0 {
                    return std::f64::consts::PI;
                }
                vec3::angle(normals[a], normals[b])
            })
            .collect();
        let reference_length = Aabb::from_points(p)
            .map(|b| b.min_side().max(b.max_side() / 4.0))
            .unwrap_or(0.0);
        let mean_edge_length = if topo.num_edges() > 0 {
            topo.edges()
                .par_iter()
                .map(|&[a, b]| vec3::dist(p[a as usize], p[b as usize]))
                .sum::<f64>()
                / topo.num_edges() as f64
        } else {
            0.0
        };
        Ok(EdgeMesh {
            mesh,
            mean_edge_length,
            topo,
            normals,
            areas,
            centroids,
            dihedral,
            reference_length,
            flipped_faces,
        })
    }

    /// Number of edges.
    pub fn num_edges(&self) -> usize {
        self.topo.num_edges()
    }
}

/// Per face, whether to flip it so that faces sharing a manifold edge traverse it in opposite
/// directions: a breadth-first walk from the lowest face of each component (deterministic).
fn orientation_signs(topo: &MeshTopology) -> Vec<bool> {
    let faces = topo.faces();
    let nf = faces.len();
    // +1: the face goes a -> b along the edge's side.
    let forward = |f: usize, a: u32, b: u32| {
        let t = faces[f];
        (0..3).any(|i| t[i] == a && t[(i + 1) % 3] == b)
    };
    let mut flip = vec![false; nf];
    let mut seen = vec![false; nf];
    let mut queue = VecDeque::new();
    for start in 0..nf {
        if seen[start] {
            continue;
        }
        seen[start] = true;
        queue.push_back(start);
        while let Some(f) = queue.pop_front() {
            for &e in &topo.face_edges()[f] {
                if e == crate::geometry::topology::NO_EDGE {
                    continue;
                }
                let fs = topo.edge_faces(e as usize);
                if fs.len() != 2 {
                    continue;
                }
                let g = if fs[0] as usize == f { fs[1] } else { fs[0] } as usize;
                if seen[g] || g == f {
                    continue;
                }
                let [a, b] = topo.edges()[e as usize];
                // Consistent when the two faces traverse the edge in opposite directions.
                let same_dir = forward(f, a, b) == forward(g, a, b);
                flip[g] = flip[f] ^ same_dir;
                seen[g] = true;
                queue.push_back(g);
            }
        }
    }
    flip
}

/// The methods of [`detect_edges`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum EdgeMethod {
    /// Dihedral angle above a threshold (Table 2, "thres.").
    Dihedral,
    /// Hysteresis thresholding of the dihedral angle (Table 2, "Hys.").
    Hysteresis,
    /// The multi-scale tangent-plane angle θ̂ʳ (section 3) above a threshold.
    Tangent,
    /// Equation 1 with the dihedral data term of equation 5 (Table 2, "dih+G").
    PottsDihedral,
    /// Equation 1 with the data term of equation 5 on the tangent-plane angle.
    PottsTangent,
    /// The SVM decision value d(e) on the features of section 4, above 0 (section 6.3).
    Learned,
    /// Equation 1 with the SVM data term of equation 2 (Table 2, "SVM+G").
    PottsLearned,
    /// crease's addition: the mean dihedral angle of the face normals after bilateral and
    /// total-variation normal filtering ([`bilateral`], [`tv`], [`filtered_dihedral`]) above
    /// [`EdgeParams::filtered_degrees`].
    Filtered,
    /// Equation 1 with the data term of equation 5 on the filtered dihedral angle (its
    /// decision angle θ_true = [`EdgeParams::filtered_degrees`]).
    PottsFiltered,
    /// crease's fusion of the paper's learned classifier, the filtered dihedral angle and the
    /// intersections of fitted surfaces ([`fused_scores`]): w · d(e) + (1 − w) · (θ_f(e) /
    /// θ_t − 1) + β · s(e) above 0.
    Fused,
}

impl EdgeMethod {
    /// The method's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            EdgeMethod::Dihedral => "dihedral",
            EdgeMethod::Hysteresis => "hysteresis",
            EdgeMethod::Tangent => "tangent",
            EdgeMethod::PottsDihedral => "potts-dihedral",
            EdgeMethod::PottsTangent => "potts-tangent",
            EdgeMethod::Learned => "learned",
            EdgeMethod::PottsLearned => "potts-learned",
            EdgeMethod::Filtered => "filtered",
            EdgeMethod::PottsFiltered => "potts-filtered",
            EdgeMethod::Fused => "fused",
        }
    }

    /// All methods.
    pub const ALL: [EdgeMethod; 10] = [
        EdgeMethod::Dihedral,
        EdgeMethod::Hysteresis,
        EdgeMethod::Tangent,
        EdgeMethod::PottsDihedral,
        EdgeMethod::PottsTangent,
        EdgeMethod::Learned,
        EdgeMethod::PottsLearned,
        EdgeMethod::Filtered,
        EdgeMethod::PottsFiltered,
        EdgeMethod::Fused,
    ];

    /// True for the methods that use the tangent-plane angle.
    pub fn uses_tangent(self) -> bool {
        matches!(self, EdgeMethod::Tangent | EdgeMethod::PottsTangent)
    }

    /// True for the methods that read the filtered normals.
    pub fn uses_filter(self) -> bool {
        matches!(
            self,
            EdgeMethod::Filtered | EdgeMethod::PottsFiltered | EdgeMethod::Fused
        )
    }

    /// True for the methods that use the SVM.
    pub fn uses_model(self) -> bool {
        matches!(
            self,
            EdgeMethod::Learned | EdgeMethod::PottsLearned | EdgeMethod::Fused
        )
    }
}

/// Parameters of [`detect_edges`].
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeParams {
    /// The method (default `fused`: the most accurate crease has on the 11 meshes of Table 2,
    /// clean and noisy, measured with `examples/meshfeat_table2.rs` and
    /// `examples/meshfeat_learned.rs`; figures in `docs/experiments/mesh-edges-fused.md`).
    /// `filtered` is about 20 times faster and nearly as accurate.
    pub method: EdgeMethod,
    /// Threshold of `dihedral` / `tangent` and high threshold of `hysteresis`, degrees
    /// (default 65: where θ̂ʳ gives the best F1 on the noisy synthetic parts; on clean meshes
    /// any threshold between the flat and the feature angles works for the dihedral angle).
    pub threshold_degrees: f64,
    /// Low / high threshold ratio of `hysteresis`.
    pub low_ratio: f64,
    /// The tangent-plane estimator; the edge's tangent angle is the mean over these scales.
    pub tangent: TangentParams,
    /// The energy of `potts-dihedral` and `potts-tangent` (its `theta_true` is the decision
    /// angle).
    pub potts: PottsParams,
    /// The energy of `potts-learned` (section 6.3: μ = 0.1, β = 0, λ = 15, σ = 10; the
    /// similarity term reads the dihedral angle).
    pub potts_learned: PottsParams,
    /// The SVM of `learned` and `potts-learned`; `None` = [`default_model`].
    pub model: Option<Arc<SvmModel>>,
    /// Added to the decision value before thresholding at 0 / entering equation 2 (the paper
    /// sweeps it over [−2, 1] for the ROC; default 0).
    pub decision_bias: f64,
    /// Bilateral normal filtering of `filtered` and `potts-filtered`.
    pub bilateral: BilateralParams,
    /// Its number of iterations (default [`FILTER_ITERATIONS`]).
    pub filter_iterations: usize,
    /// Total-variation normal filtering, averaged with the bilateral angle ([`tv`]).
    pub tv: TvParams,
    /// Smoothing of the filtered angle along the lines ([`mod@line`]).
    pub line: LineParams,
    /// Threshold of `filtered`, and the decision angle of `potts-filtered`, degrees (default
    /// [`FILTERED_DEGREES`]).
    pub filtered_degrees: f64,
    /// Weight w of the SVM decision value in `fused` (default [`FUSED_SVM_WEIGHT`]).
    pub fused_svm_weight: f64,
    /// The surface-intersection term of `fused` ([`surfaces`]).
    pub intersection: IntersectionParams,
}

/// Default weight of the SVM in the `fused` score ([`fused_scores`]).
pub const FUSED_SVM_WEIGHT: f64 = 0.1;

/// Default iterations of bilateral normal filtering ([`filtered_dihedral`] averages the
/// dihedral angle over iterations 1 to this): 3 is at or near the best mean AUC of the
/// bilateral angle at both noise levels measured (`examples/meshfeat_table2.rs`,
/// `docs/experiments/mesh-edges-filtered-angle.md`).
pub const FILTER_ITERATIONS: usize = 3;

/// See [`filtered_dihedral`]: the angle between two normals with independent noise has a
/// Rayleigh-like law, which exceeds 4 times its median with probability 2⁻¹⁶.
pub const KEEP_RAW_MEDIANS: f64 = 8.0;

/// Default threshold of the filtered dihedral angle, degrees.
pub const FILTERED_DEGREES: f64 = 25.0;

/// The parameters of equation 1 with the SVM data term, section 6.3.
pub const LEARNED_POTTS: PottsParams = PottsParams {
    mu: 0.1,
    beta: 0.0,
    lambda: 15.0,
    sigma: 10.0,
    theta_true: 0.0,
};

/// Default scales of the `tangent` and `potts-tangent` methods (fractions of the reference
/// length): the three smallest of section 4, as accurate on the noisy meshes of
/// `examples/meshfeat_table2.rs` as the next three at less than half the cost, and better than
/// the smallest alone (`docs/experiments/mesh-edges-tangent.md`).
pub const DEFAULT_TANGENT_SCALES: [f64; 3] = [0.04, 0.07, 0.10];

impl Default for EdgeParams {
    fn default() -> Self {
        EdgeParams {
            method: EdgeMethod::Fused,
            threshold_degrees: 65.0,
            low_ratio: 0.5,
            tangent: TangentParams {
                scales: DEFAULT_TANGENT_SCALES.to_vec(),
                ..TangentParams::default()
            },
            potts: PottsParams::default(),
            potts_learned: LEARNED_POTTS,
            model: None,
            decision_bias: 0.0,
            bilateral: BilateralParams::default(),
            filter_iterations: FILTER_ITERATIONS,
            tv: TvParams::default(),
            line: LineParams::default(),
            filtered_degrees: FILTERED_DEGREES,
            fused_svm_weight: FUSED_SVM_WEIGHT,
            intersection: IntersectionParams::default(),
        }
    }
}

/// Seconds spent in each stage.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct EdgeTimings {
    /// Topology, normals, dihedral angles.
    pub prepare: f64,
    /// Tangent-plane angles, the normal filtering of the filtered methods, or the whole
    /// feature vector for the learned methods (0 if not used).
    pub tangent: f64,
    /// SVM decision values (0 if not used).
    pub classify: f64,
    /// The segmentation and surface-intersection scores of `fused` (0 if not used).
    pub surfaces: f64,
    /// Labelling (threshold, hysteresis or graph cut).
    pub label: f64,
}

/// The result of [`detect_edges`].
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeDetection {
    /// Feature label per edge (topology order).
    pub sharp: Vec<bool>,
    /// Per edge, the angle the method thresholds or feeds to the energy, degrees (the
    /// hysteresis score for `hysteresis`, the SVM decision value d(e) plus the bias for the
    /// learned methods): larger = sharper.
    pub sharpness: Vec<f64>,
    /// Stage times.
    pub timings: EdgeTimings,
}

/// The mean over the scales of the tangent-plane angle of every edge.
pub fn mean_tangent_angle(t: &TangentAngles) -> Vec<f64> {
    let k = t.num_scales().max(1);
    t.angles
        .par_chunks(k)
        .map(|c| c.iter().sum::<f64>() / c.len() as f64)
        .collect()
}

/// Runs `params.method` on a prepared mesh.
pub fn detect_prepared(em: &EdgeMesh, params: &EdgeParams) -> Result<EdgeDetection> {
    if !(params.threshold_degrees.is_finite() && params.threshold_degrees >= 0.0) {
        return Err(Error::InvalidArgument(format!(
            "feature edges: the threshold must be finite and >= 0 degrees, got {}",
            params.threshold_degrees
        )));
    }
    let mut timings = EdgeTimings::default();
    if params.method.uses_filter()
        && !(params.filtered_degrees.is_finite() && params.filtered_degrees >= 0.0)
    {
        return Err(Error::InvalidArgument(format!(
            "feature edges: the filtered threshold must be finite and >= 0 degrees, got {}",
            params.filtered_degrees
        )));
    }
    if params.method.uses_filter() {
        if let Some(why) = params.tv.invalid().or_else(|| params.line.invalid()) {
            return Err(Error::InvalidArgument(format!("feature edges: {why}")));
        }
    }
    if params.method.uses_model() {
        return detect_learned(em, params);
    }
    let t0 = Instant::now();
    let angles = if params.method.uses_tangent() {
        mean_tangent_angle(&tangent_angles(em, &params.tangent)?)
    } else if params.method.uses_filter() {
        filtered_dihedral(
            em,
            params.filter_iterations,
            &params.bilateral,
            &params.tv,
            &params.line,
        )
    } else {
        em.dihedral.clone()
    };
    timings.tangent = if params.method.uses_tangent() || params.method.uses_filter() {
        t0.elapsed().as_secs_f64()
    } else {
        0.0
    };
    let t1 = Instant::now();
    let t = params.threshold_degrees.to_radians();
    let tf = params.filtered_degrees.to_radians();
    let (sharp, score) = match params.method {
        EdgeMethod::Dihedral | EdgeMethod::Tangent => (threshold(&angles, t), angles),
        EdgeMethod::Hysteresis => {
            let h = hysteresis_scores(em, &angles, params.low_ratio)?;
            (threshold(&h, t), h)
        }
        EdgeMethod::PottsDihedral | EdgeMethod::PottsTangent => {
            let pairs = EdgePairs::new(em);
            (potts_labels(em, &pairs, &angles, &params.potts)?, angles)
        }
        EdgeMethod::Filtered => (threshold(&angles, tf), angles),
        EdgeMethod::PottsFiltered => {
            let pairs = EdgePairs::new(em);
            let p = PottsParams {
                theta_true: tf,
                ..params.potts
            };
            (potts_labels(em, &pairs, &angles, &p)?, angles)
        }
        EdgeMethod::Learned | EdgeMethod::PottsLearned | EdgeMethod::Fused => {
            unreachable!("handled above")
        }
    };
    timings.label = t1.elapsed().as_secs_f64();
    Ok(EdgeDetection {
        sharp,
        sharpness: score.iter().map(|a| a.to_degrees()).collect(),
        timings,
    })
}

/// The filtered dihedral angle (radians) of every edge: (1 − w) × the bilateral angle + w ×
/// the total-variation angle, w = `tv.weight`, then smoothed along the lines
/// ([`line::smooth_along_lines`] with `line`).
///
/// The bilateral angle is the mean, over the iterations 1 to `iterations` of bilateral normal
/// filtering ([`bilateral::filter_normals`]), of the dihedral angle of the filtered normals,
/// each never less than the raw dihedral angle minus [`KEEP_RAW_MEDIANS`] times the median
/// raw dihedral angle. The total-variation angle is the dihedral angle of the normals of
/// [`tv::tv_normals`], started from the first bilateral iteration (the raw normals if
/// `iterations` is 0).
///
/// **The raw-angle floor**: what the noise cannot explain is kept. Filtering pulls the normal
/// of a sliver face (a thin chamfer strip of a CAD tessellation, 500 times smaller than its
/// neighbours on block.off) to one of its neighbours and so loses one of its two feature
/// edges; on clean meshes (median near 0) the raw angle keeps them.
///
/// **The mean over the iterations** (crease's choice): one iteration keeps small features and
/// the exact position of a crease, later ones remove more noise; their mean is a multi-scale
/// score, as the paper's multi-scale tangent-plane features (section 4) are. With the range
/// factor 2.5 it ranks edges better at 0.2 % and 0.5 % noise than the last iteration alone did
/// with the earlier factor 1.5.
///
/// **The total-variation half** and **the line smoothing** ([`tv`], [`mod@line`]) each raise
/// the mean AUC at both noise levels. The two filters fail apart: total variation keeps a
/// crease one edge wide on fine meshes, bilateral filtering does not invent creases on coarse
/// curved tessellations; their mean scored above their geometric mean and their minimum.
///
/// The figures of each step, and the variants measured and rejected (non-maximum suppression
/// across the line, other means of the two angles, a per-mesh total-variation weight, the
/// tangent-plane angle of the filtered normals, other range kernels, a second-stage SVM,
/// equation 1 on the fused score): `docs/experiments/mesh-edges-filtered-angle.md`.
pub fn filtered_dihedral(
    em: &EdgeMesh,
    iterations: usize,
    params: &BilateralParams,
    tv: &TvParams,
    line: &LineParams,
) -> Vec<f64> {
    let counts: Vec<usize> = (1..=iterations).collect();
    let normals = bilateral::filter_normals(em, &counts, params);
    let mut out = if normals.is_empty() {
        em.dihedral.clone()
    } else {
        let excess = KEEP_RAW_MEDIANS * tangent::median_dihedral(em).unwrap_or(0.0);
        let mut sum = vec![0.0; em.num_edges()];
        for n in &normals {
            let f = bilateral::dihedral_of(em, n);
            sum.par_iter_mut()
                .zip(f.par_iter().zip(&em.dihedral))
                .for_each(|(s, (&f, &raw))| *s += f.max(raw - excess));
        }
        let k = normals.len() as f64;
        sum.into_par_iter().map(|s| s / k).collect()
    };
    if tv.weight > 0.0 {
        let init = normals.first().unwrap_or(&em.normals);
        let t = bilateral::dihedral_of(em, &tv::tv_normals(em, init, tv));
        let w = tv.weight;
        out.par_iter_mut()
            .zip(t.par_iter())
            .for_each(|(o, &t)| *o = (1.0 - w) * *o + w * t);
    }
    line::smooth_along_lines(em, &out, line)
}

/// The SVM decision values of every edge of `em` under `model` (features of section 4 with the
/// model's feature parameters, then the decision function, both in parallel); also returns the
/// seconds spent on the features and on the classification.
pub fn learned_scores(em: &EdgeMesh, model: &SvmModel) -> Result<(Vec<f64>, [f64; 2])> {
    let t0 = Instant::now();
    let f = edge_features(em, &model.features.params())?;
    let tf = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let d = model.decision_values(&f)?;
    Ok((d, [tf, t1.elapsed().as_secs_f64()]))
}

fn detect_learned(em: &EdgeMesh, params: &EdgeParams) -> Result<EdgeDetection> {
    if !params.decision_bias.is_finite() {
        return Err(Error::InvalidArgument(format!(
            "feature edges: the decision bias must be finite, got {}",
            params.decision_bias
        )));
    }
    let model: &SvmModel = match &params.model {
        Some(m) => m,
        None => default_model(),
    };
    let (d, [tf, tc]) = learned_scores(em, model)?;
    let mut timings = EdgeTimings {
        tangent: tf,
        classify: tc,
        ..EdgeTimings::default()
    };
    if params.method == EdgeMethod::Fused {
        // Finite and >= 0 is checked by `detect_prepared`; `fused` divides by it.
        if params.filtered_degrees == 0.0 {
            return Err(Error::InvalidArgument(
                "feature edges: the filtered threshold of `fused` must be > 0 degrees".into(),
            ));
        }
        if !(0.0..=1.0).contains(&params.fused_svm_weight) {
            return Err(Error::InvalidArgument(format!(
                "feature edges: the SVM weight of `fused` must be in [0, 1], got {}",
                params.fused_svm_weight
            )));
        }
        let ip = &params.intersection;
        let valid = ip.weight.is_finite()
            && ip.weight >= 0.0
            && ip.width.is_finite()
            && ip.width > 0.0
            && ip.noise_floor.is_finite()
            && ip.noise_floor >= 0.0
            && ip.max_points > 0;
        if !valid {
            return Err(Error::InvalidArgument(format!(
                "feature edges: the surface-intersection term of `fused` needs a finite weight \
                 >= 0, a width > 0, a noise floor >= 0 and max_points >= 1, got {ip:?}"
            )));
        }
        let t0 = Instant::now();
        let filtered = filtered_dihedral(
            em,
            params.filter_iterations,
            &params.bilateral,
            &params.tv,
            &params.line,
        );
        timings.tangent += t0.elapsed().as_secs_f64();
        let t2 = Instant::now();
        let intersection = if params.intersection.weight > 0.0 {
            Some(intersection_scores(
                em,
                &params.intersection,
                params.filtered_degrees,
            )?)
        } else {
            None
        };
        timings.surfaces = t2.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let score = fused_scores(&d, &filtered, intersection.as_deref(), params);
        let sharp = threshold(&score, 0.0);
        timings.label = t1.elapsed().as_secs_f64();
        return Ok(EdgeDetection {
            sharp,
            sharpness: score,
            timings,
        });
    }
    let t1 = Instant::now();
    let score: Vec<f64> = d.iter().map(|v| v + params.decision_bias).collect();
    let sharp = if params.method == EdgeMethod::PottsLearned {
        let pairs = EdgePairs::new(em);
        let unary = svm_unary(&d, params.decision_bias);
        potts_labels_unary(em, &pairs, &em.dihedral, &unary, &params.potts_learned)?
    } else {
        threshold(&score, 0.0)
    };
    timings.label = t1.elapsed().as_secs_f64();
    Ok(EdgeDetection {
        sharp,
        sharpness: score,
        timings,
    })
}

/// The `fused` score of every edge (crease's addition): w · (d(e) + bias) + (1 − w) ·
/// (θ_f(e) / θ_t − 1) + β · s(e), with d the SVM decision value of section 6.3 (0 on its
/// decision boundary), θ_f the filtered dihedral angle ([`filtered_dihedral`], radians), θ_t
/// the filtered threshold in degrees (so that both terms are 0 at their own decision point and
/// the edge is a feature edge above 0), s ∈ [0, 1] the surface-intersection score of
/// [`surfaces::intersection_scores`] (`intersection`; `None` = 0) and β its weight
/// ([`IntersectionParams::weight`], default 0.3), all from `params`.
///
/// **Why.** The two estimators fail on different meshes. The SVM, trained on synthetic parts
/// only, reads the 43 multi-scale features of section 4 and handles coarse CAD tessellations
/// with slivers and curved faces (noisy block.off, cup, sharp_sphere); the filtered angle
/// localises creases on fine meshes (fandisk, bar, the ABC model), where the SVM's wide
/// scales blur them. w = 0.1 gave the best mean AUC over the 11 meshes of Table 2 at 0.5 %
/// noise and within 0.01 point of the best at 0.2 % (`examples/meshfeat_learned.rs`); a rank
/// average of the two scores, and the filtered angles as more SVM features, scored lower (the
/// RBF kernel dilutes one strong feature among 43). The intersection term ([`surfaces`])
/// raises the noisy AUCs further. Figures: `docs/experiments/mesh-edges-fused.md`.
pub fn fused_scores(
    decision: &[f64],
    filtered: &[f64],
    intersection: Option<&[f64]>,
    params: &EdgeParams,
) -> Vec<f64> {
    let inv_t = 1.0 / params.filtered_degrees.to_radians();
    let (w, bias) = (params.fused_svm_weight, params.decision_bias);
    let beta = params.intersection.weight;
    decision
        .par_iter()
        .zip(filtered.par_iter())
        .enumerate()
        .map(|(e, (&d, &f))| {
            let s = intersection.map_or(0.0, |s| beta * s[e]);
            w * (d + bias) + (1.0 - w) * (f * inv_t - 1.0) + s
        })
        .collect()
}

/// Prepares `mesh` and runs `params.method` (see [`EdgeMethod`]).
pub fn detect_edges<'a>(
    mesh: &'a TriMesh,
    params: &EdgeParams,
) -> Result<(EdgeMesh<'a>, EdgeDetection)> {
    let t0 = Instant::now();
    let em = EdgeMesh::new(mesh)?;
    let prepare = t0.elapsed().as_secs_f64();
    let mut d = detect_prepared(&em, params)?;
    d.timings.prepare = prepare;
    Ok((em, d))
}

/// The feature edges chained into polylines of mesh vertex indices, split at junctions
/// (vertices with other than two feature edges); a closed loop repeats its first vertex.
pub fn feature_polylines(topo: &MeshTopology, sharp: &[bool]) -> Vec<Vec<u32>> {
    let segs: Vec<[u32; 2]> = topo
        .edges()
        .iter()
        .zip(sharp)
        .filter(|(_, &s)| s)
        .map(|(&e, _)| e)
        .collect();
    chain_segments(topo.num_vertices(), &segs)
}

/// The area under the ROC curve traced by a family of labellings (e.g. a parameter swept over
/// a range, section 6.3): each labelling gives one (false-positive rate, true-positive rate)
/// point; with (0, 0) and (1, 1) added and the points sorted by rate, the trapezoid area.
///
/// Errors: a labelling of the wrong length, no positive or no negative edge in `truth`.
pub fn sweep_auc(labellings: &[Vec<bool>], truth: &[bool]) -> Result<(f64, Vec<RocPoint>)> {
    let pos = truth.iter().filter(|&&t| t).count();
    let neg = truth.len() - pos;
    if pos == 0 || neg == 0 {
        return Err(Error::InvalidArgument(format!(
            "ROC: {pos} positive and {neg} negative edges; both are needed"
        )));
    }
    let mut pts = vec![
        RocPoint {
            threshold: f64::INFINITY,
            fpr: 0.0,
            tpr: 0.0,
        },
        RocPoint {
            threshold: f64::NEG_INFINITY,
            fpr: 1.0,
            tpr: 1.0,
        },
    ];
    for (i, l) in labellings.iter().enumerate() {
        if l.len() != truth.len() {
            return Err(Error::InvalidArgument(format!(
                "ROC: labelling {i} has {} labels for {} edges",
                l.len(),
                truth.len()
            )));
        }
        let (mut tp, mut fp) = (0usize, 0usize);
        for (&p, &t) in l.iter().zip(truth) {
            if p {
                if t {
                    tp += 1;
                } else {
                    fp += 1;
                }
            }
        }
        pts.push(RocPoint {
            threshold: i as f64,
            fpr: fp as f64 / neg as f64,
            tpr: tp as f64 / pos as f64,
        });
    }
    pts.sort_by(|a, b| a.fpr.total_cmp(&b.fpr).then(a.tpr.total_cmp(&b.tpr)));
    Ok((trapezoid_area(&pts), pts))
}
