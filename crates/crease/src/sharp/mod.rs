//! Sharp feature points: the projected distance of tran et al. with automatic multi-scale Otsu
//! thresholds, and the classical measures it is compared with (tran section 4.1).
//!
//! **Algorithm (tran sections 3.1–3.3).** For every scale s (clouds: k = 12, 16, ..., 40 nearest
//! neighbours, section 4.2; meshes: the 1- to 4-rings, section 2.2):
//! 1. the measure of every point over its neighbourhood at that scale ([`Measure`]; the default
//!    is the projected distance |(p_i − p̄_i)·n_i| of equation 3, with n_i the weighted-PCA normal
//!    of equation 1 at the same scale for clouds and the Gouraud vertex normal (equation 2,
//!    ω_j = 1) for meshes);
//! 2. the values normalised to [0, 1], their histogram, and Otsu's threshold T_s (section 3.2);
//!    f_s(i) = 1 when the value is ≥ T_s (equation 4);
//! 3. a point is a sharp feature when f_s(i) = 1 at every scale (equation 5).
//!
//! One kNN query at the largest k serves every scale (rows are nearest first, each scale is a
//! prefix); one breadth-first search to the largest ring serves every ring.
//!
//! The continuous score written as `sharpness` is min_s (value_s / T_s): a point is sharp
//! exactly when its sharpness is ≥ 1, and ranking points by it gives ROC curves.
//!
//! **Choices where the paper is open** (each measured on the synthetic parts and the PCEDNet
//! benchmark, see `tests/it/sharp.rs`; the figures and the variants tried are in
//! `docs/experiments/sharp-points.md`, `sharp-noise.md` and `sharp-surfaces.md`):
//! * N(i) is the point and its k nearest other points (as the PCA normals of
//!   [`crate::estimate::normals`]). Equation 1's Gaussian weights are available
//!   ([`SharpParams::pca_weight`], σ = 2 × the neighbourhood's RMS radius instead of σ = k, see
//!   [`PcaWeight`]) but off by default: they do not change the accuracy and cost three times
//!   the time.
//! * Thin plates: when a neighbourhood holds both faces of a plate thinner than itself, its
//!   centroid lies between the faces and every point of the plate gets a large projected
//!   distance (Otsu then flags most of a thin plate). Two stages keep the neighbourhoods on the
//!   point's own face:
//!   1. [`SharpParams::one_face`] (clouds measured noise-free): every neighbour on another sheet
//!      parallel to the point's own (the opposite face of a plate, the facing wall of a slot) is
//!      dropped by a test on small-scale normals and chord angles ([`face`]); scale k keeps the
//!      neighbours that pass among its k nearest. This departs from tran's N(i) = the k
//!      nearest (section 2.1), which assumes one surface around the point.
//!   2. what remains is tested for two flat parallel groups along the normal, and only the
//!      point's own group is used (catches the plates whose small-scale normals were wrong).
//!
//!   Both stages are kept: stage 1 alone has the higher median MCC on the clean PCEDNet
//!   models but loses on four of the eight, and stage 2 is what keeps the propeller blades of
//!   model 7038. On noisy clouds the chord test of stage 1 drops neighbours at random, hence
//!   it is off where the cloud is measured noisy ([`noise::NOISY_RATIO`]).
//! * [`SharpParams::thin`]: detections are thinned across the line to one or two points,
//!   comparing (clouds) only neighbours displaced to the same side, see the module `thin`.
//! * [`SharpParams::density_invariant`]: the projected distance is a length, so on an unevenly
//!   sampled scan a single threshold flags the sparse regions first (tran section 4.5 names
//!   this limitation). Dividing it by the RMS radius of the neighbourhood makes it a
//!   dimensionless measure of how far the point sits off its neighbourhood's plane relative to
//!   the neighbourhood's size, identical for any sampling density. Mean curvature is likewise
//!   multiplied by the radius. On by default.
//! * [`SharpParams::otsu`]: the histogram's top can be a high quantile instead of the maximum
//!   (see [`crate::threshold::otsu()`]); a few outliers otherwise squeeze all points into the
//!   first bins.
//! * [`SharpParams::auto_regularize`] (clouds): tran's method "depends on the level of noise"
//!   (section 4.5) and degrades from 4–5 % noise on (section 4.4). The noise is measured from the
//!   data ([`noise::noise_ratio`]: lower decile of the 7-point plane residual over the spacing);
//!   above [`noise::NOISY_RATIO`] the per-point decisions are replaced by the Potts labelling of
//!   [`potts`] (vidal2011 equation 1) with [`Regularize::noisy`]. The ratio separates the
//!   clean PCEDNet clouds from the noisy ones by two orders of magnitude, and the synthetic
//!   parts with 0–5 % noise stay below half the switch value; the labelling raises the noisy
//!   clouds' MCC but would lower the clean ones'.
//!
//! * [`SharpParams::surfaces`] (clouds, projected distance; on by default): after the labelling
//!   above, the points whose neighbourhood the cloud's segmentation into analytic surfaces
//!   explains are decided by their distance to the intersection of two surfaces meeting at more
//!   than 30° ([`surfaces`]): a fitted surface averages the noise over many points, and a
//!   tangent junction (fillet) has no such intersection. It raises the median MCC on the clean
//!   and the noisy PCEDNet models; the thin plates, where the segmentation fails, keep the
//!   detector's labels. On noisy clouds the points of thin sheets are then decided by their
//!   distance to the sheet's rim (module `rim`, from the in-plane offset of the centroid of 80
//!   neighbours, see [`surfaces`] step 6). The surfaces decide first: the Potts labelling then
//!   labels only the points they leave undecided, the decided ones entering its energy as fixed
//!   labels with their surfaces' sharpness (vidal's labelling of the whole graph, whose labels
//!   were then replaced on 99 % of a segmented noisy part, cost 2 of the 5 s of a noisy
//!   million-point cloud's sharp points; the noisy PCEDNet models' MCC: median 0.468 → 0.467,
//!   mean 0.451 → 0.454).
//!
//! **Tried and not kept** (`docs/experiments/sharp-points.md`): larger fixed scales than the
//! paper's (worse on clean and noisy clouds), a denoised projected distance (the centroid of
//! the m nearest points instead of the point) and the distance to the intersection of two
//! planes fitted per neighbourhood (both below the projected distance).

pub mod face;
mod measures;
pub mod potts;
mod rim;
pub mod surfaces;
mod thin;
pub mod tiled;

pub use crate::estimate::noise;
pub use measures::Measure;
pub use potts::Regularize;
pub use surfaces::{SurfaceRefine, SurfaceReport};

use std::borrow::Cow;

use rayon::prelude::*;

use crate::analysis::{AnalysisParams, CloudAnalysis};
use crate::estimate::normals::{mesh_vertex_normals, PcaWeight, Weighting};
use crate::geometry::{MeshTopology, Point3, TriMesh};
use crate::segment::{
    neighbours_needed, segment_points, PointParams, PointSegmentation, SegmentParams,
};
use crate::spatial::mesh_rings::vertex_k_rings_layered;
use crate::spatial::{morton_order, Neighborhoods};
use crate::threshold::{otsu, OtsuParams};
use crate::{Error, Result};

/// The kNN scales of tran section 4.2 for point clouds: k = 12, 16, ..., 40.
pub const CLOUD_SCALES: [usize; 8] = [12, 16, 20, 24, 28, 32, 36, 40];
/// The ring scales of tran section 4.2 for meshes: the 1-, 2-, 3- and 4-rings.
pub const MESH_SCALES: [usize; 4] = [1, 2, 3, 4];

/// How each scale's threshold is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ThresholdRule {
    /// Otsu's threshold on the histogram of the normalised values (tran section 3.2).
    Otsu,
    /// A fixed threshold on the values normalised to [0, 1] by their maximum at each scale
    /// (the manual thresholds tran sets for Pauly's measure in Fig. 7).
    Manual(f64),
}

/// Parameters of [`detect_points`] and [`detect_mesh`].
#[derive(Debug, Clone, PartialEq)]
pub struct SharpParams {
    /// The measure (default: projected distance).
    pub measure: Measure,
    /// Scales: neighbour counts k for clouds, ring sizes for meshes. `None`: [`CLOUD_SCALES`] or
    /// [`MESH_SCALES`].
    pub scales: Option<Vec<usize>>,
    /// Threshold rule (default Otsu).
    pub threshold: ThresholdRule,
    /// Histogram parameters of Otsu's method.
    pub otsu: OtsuParams,
    /// Weights of the PCA of equation 1. Default [`PcaWeight::Uniform`]: the Gaussian weights
    /// (σ = 2 × the RMS radius, see [`PcaWeight`]) hardly change the accuracy, while uniform
    /// weights let all scales share prefix sums of one neighbourhood's moments (one
    /// eigenproblem per scale instead of a weighted pass over the points), about 3 times
    /// faster (see `docs/experiments/sharp-points.md`).
    pub pca_weight: PcaWeight,
    /// Make the length-valued measures independent of the sampling density (see the module
    /// documentation). Default true.
    pub density_invariant: bool,
    /// Clouds: drop from every neighbourhood the neighbours on another sheet parallel to the
    /// point's own (the opposite face of a thin plate, the facing wall of a slot), see
    /// [`face`]. Default true. Only for the projected distance and the surface variation.
    pub one_face: bool,
    /// Thin the detections to lines one or two points wide (see the module `thin`); default true.
    pub thin: bool,
    /// Replace the per-point decisions by the Potts labelling of the kNN graph of
    /// [`potts`] (before thinning; point clouds only). Default `None`: it raises the MCC of
    /// noisy clouds but lowers that of clean ones (`docs/experiments/sharp-noise.md`); hence
    /// applied only to clouds measured as noisy ([`SharpParams::auto_regularize`]).
    pub regularize: Option<Regularize>,
    /// Clouds: when [`SharpParams::regularize`] is `None` and the measured noise ratio
    /// ([`noise::noise_ratio`]) exceeds this value, the decisions are regularised with
    /// [`Regularize::noisy`]. Default `Some(`[`noise::NOISY_RATIO`]`)`; `None` never regularises
    /// automatically. Clean clouds keep the plain detector (see the module documentation and
    /// `docs/experiments/sharp-noise.md`).
    pub auto_regularize: Option<f64>,
    /// Clouds, projected distance: let the analytic surfaces of the cloud's segmentation
    /// decide the points whose neighbourhood they explain ([`surfaces`]); the regularisation
    /// and thinning label the others. Default `Some(SurfaceRefine::default())`; `None` keeps
    /// tran's method (and the multi-scale detection's speed).
    pub surfaces: Option<SurfaceRefine>,
}

impl Default for SharpParams {
    fn default() -> Self {
        SharpParams {
            measure: Measure::ProjectedDistance,
            scales: None,
            threshold: ThresholdRule::Otsu,
            otsu: OtsuParams::default(),
            pca_weight: PcaWeight::Uniform,
            density_invariant: true,
            one_face: true,
            thin: true,
            regularize: None,
            auto_regularize: Some(noise::NOISY_RATIO),
            surfaces: Some(SurfaceRefine::default()),
        }
    }
}

impl SharpParams {
    /// Errors (`InvalidArgument`) on an empty or zero scale, a manual threshold outside
    /// (0, 1], and invalid Otsu, regularisation or surface-stage settings. (Scale limits that
    /// depend on the input, such as the largest ring of a mesh or k >= 5 for the mean
    /// curvature of a cloud, are checked by the detectors.)
    pub fn validate(&self) -> Result<()> {
        if let Some(s) = &self.scales {
            check_scales(s, "scales")?;
        }
        if let ThresholdRule::Manual(t) = self.threshold {
            if !(t > 0.0 && t <= 1.0) {
                return Err(Error::InvalidArgument(format!(
                    "manual sharpness threshold must be in (0, 1], got {t}"
                )));
            }
        }
        self.otsu.validate()?;
        if let Some(r) = &self.regularize {
            r.validate()?;
        }
        if let Some(s) = &self.surfaces {
            s.validate()?;
        }
        if let Some(t) = self.auto_regularize {
            if !t.is_finite() {
                return Err(Error::InvalidArgument(format!(
                    "auto_regularize must be finite, got {t}"
                )));
            }
        }
        Ok(())
    }
}

/// Per-thread buffers of the measure pass: gathered coordinates, work space, the end of each
/// scale's neighbourhood in the coordinates, the running count of kept neighbours.
type Gather = (Vec<Point3>, Vec<Point3>, Vec<usize>, Vec<usize>);

/// What happened at one scale.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ScaleReport {
    /// The scale (k, or ring size for meshes).
    pub scale: usize,
    /// Threshold T_s in the measure's units (after the density normalisation if on).
    pub threshold: f64,
    /// T_s normalised over the histogram's range, as tran's Fig. 4b plots it.
    pub normalized_threshold: f64,
    /// Points with f_s(i) = 1 (equation 4).
    pub detected: usize,
}

/// Result of a detection.
#[derive(Debug, Clone, PartialEq)]
pub struct SharpResult {
    /// F(i) of equation 5, in input order.
    pub sharp: Vec<bool>,
    /// min_s value_s(i) / T_s: ≥ 1 exactly for sharp points.
    pub sharpness: Vec<f64>,
    /// One report per scale, in the order of the scales.
    pub scales: Vec<ScaleReport>,
    /// Clouds: the measured noise ratio of [`noise::noise_ratio`] (`None` for meshes).
    pub noise_ratio: Option<f64>,
    /// True when the decisions were regularised (given or automatic).
    pub regularized: bool,
    /// What the surface stage did, when it ran ([`SharpParams::surfaces`]).
    pub surfaces: Option<SurfaceReport>,
}

impl SharpResult {
    /// Number of sharp points.
    pub fn num_sharp(&self) -> usize {
        self.sharp.iter().filter(|&&s| s).count()
    }

    /// The result of a detection run on `points` permuted by `order` (point r of the run is
    /// input point `order[r]`, see [`spatial_order`]), back in input order.
    pub fn to_input_order(mut self, order: &[u32]) -> Result<SharpResult> {
        if order.len() != self.sharp.len() {
            return Err(Error::InvalidArgument(format!(
                "sharp features: a permutation of {} points for {} results",
                order.len(),
                self.sharp.len()
            )));
        }
        let mut sharp = vec![false; order.len()];
        let mut sharpness = vec![0.0; order.len()];
        for (r, &i) in order.iter().enumerate() {
            sharp[i as usize] = self.sharp[r];
            sharpness[i as usize] = self.sharpness[r];
        }
        self.sharp = sharp;
        self.sharpness = sharpness;
        Ok(self)
    }
}

/// The points along the Morton curve, with `order[r]` = the input index of sorted point r
/// (`None` when there is no order, e.g. a non-finite coordinate, which the kNN then reports).
///
/// Every per-point pass of the cloud detector reads the coordinates of 12 to 40 neighbours;
/// with the points in input order a scan in sampling (random) order misses the cache on
/// almost every one of them (perf: `docs/experiments/sharp-points.md`).
/// Run on Morton-sorted points, neighbours are mostly in cache; [`detect_points`] does this and
/// maps the result back ([`SharpResult::to_input_order`]). Ties between equidistant neighbours
/// are then broken by Morton rank instead of input index.
pub fn spatial_order(points: &[Point3]) -> Option<(Vec<u32>, Vec<Point3>)> {
    let order = morton_order(points);
    if order.len() != points.len() {
        return None;
    }
    let sorted = order.par_iter().map(|&i| points[i as usize]).collect();
    Some((order, sorted))
}

fn check_scales(scales: &[usize], what: &str) -> Result<()> {
    if scales.is_empty() {
        return Err(Error::InvalidArgument(format!("sharp features: no {what}")));
    }
    if scales.contains(&0) {
        return Err(Error::InvalidArgument(format!(
            "sharp features: {what} must be positive, got {scales:?}"
        )));
    }
    Ok(())
}

/// Sharp feature points of a point cloud (see the module documentation): [`detect`] on a new
/// analysis of the cloud (Morton order, exact duplicates once, one kNN query at the largest
/// scale, or at the segmentation's when the surface stage reads more).
///
/// Errors: fewer distinct points than the largest k + 1, non-finite coordinates, invalid
/// parameters.
pub fn detect_points(points: &[Point3], params: &SharpParams) -> Result<SharpResult> {
    let analysis = CloudAnalysis::new(points, analysis_params(params)?)?;
    detect(&analysis, params)
}

/// The settings of the analysis [`detect_points`] builds: neighbour lists as long as the
/// largest scale, or as the segmentation reads when the surface stage runs.
pub fn analysis_params(params: &SharpParams) -> Result<AnalysisParams> {
    let scales = params
        .scales
        .clone()
        .unwrap_or_else(|| CLOUD_SCALES.to_vec());
    check_scales(&scales, "neighbourhood sizes")?;
    let mut ap = AnalysisParams::default();
    let kmax = scales.iter().copied().max().unwrap_or(1);
    ap.max_k = if params.surfaces.is_some() {
        kmax.max(neighbours_needed(&ap.points, false))
    } else {
        kmax
    };
    Ok(ap)
}

/// [`detect_points`] from precomputed k-nearest-neighbour lists (at least the largest scale).
/// The surface stage ([`SharpParams::surfaces`]) segments `points` with the default settings.
pub fn detect_points_with(
    points: &[Point3],
    nbrs: &Neighborhoods,
    params: &SharpParams,
) -> Result<SharpResult> {
    detect_core(points, nbrs, None, params, || {
        segment_points(
            points,
            None,
            &SegmentParams::default(),
            &PointParams::default(),
        )
        .map(Cow::Owned)
    })
}

/// Sharp feature points from a shared analysis of the cloud: its neighbour lists, measured noise
/// and segmentation into analytic surfaces are read, never recomputed. The result is in the
/// input order of the cloud.
///
/// Errors: the analysis' neighbour lists shorter than the largest scale (build the analysis
/// with [`crate::analysis::AnalysisParams::max_k`] at least that), invalid parameters, and the
/// segmentation's errors when the surface stage runs.
pub fn detect(analysis: &CloudAnalysis, params: &SharpParams) -> Result<SharpResult> {
    let nbrs = analysis.neighbours()?;
    let ratio = analysis.noise_ratio()?;
    let mut r = detect_core(analysis.points(), nbrs, Some(ratio), params, || {
        analysis.segmentation().map(Cow::Borrowed)
    })?;
    r.sharp = analysis.to_input_order(&r.sharp);
    r.sharpness = analysis.to_input_order(&r.sharpness);
    Ok(r)
}

/// The cloud detector on `points` with their neighbour lists; `ratio` the measured noise ratio
/// (measured here when `None`); `segmentation` gives the cloud's segmentation, in the order of
/// `points`, when the surface stage needs it.
fn detect_core<'s>(
    points: &[Point3],
    nbrs: &Neighborhoods,
    ratio: Option<f64>,
    params: &SharpParams,
    segmentation: impl FnOnce() -> Result<Cow<'s, PointSegmentation>>,
) -> Result<SharpResult> {
    params.validate()?;
    let scales = params
        .scales
        .clone()
        .unwrap_or_else(|| CLOUD_SCALES.to_vec());
    check_scales(&scales, "neighbourhood sizes")?;
    if nbrs.len() != points.len() {
        return Err(Error::InvalidArgument(format!(
            "sharp features: {} neighbour lists for {} points",
            nbrs.len(),
            points.len()
        )));
    }
    let kmax = scales.iter().copied().max().unwrap_or(1);
    if kmax > nbrs.k() {
        return Err(Error::InvalidArgument(format!(
            "sharp features at k = {kmax} from neighbour lists of k = {}",
            nbrs.k()
        )));
    }
    if params.measure == Measure::MeanCurvature && scales.iter().any(|&k| k < 5) {
        return Err(Error::InvalidArgument(format!(
            "mean curvature needs k >= 5 (a quadric has 6 coefficients), got scales {scales:?}"
        )));
    }
    let ratio = ratio.unwrap_or_else(|| noise::noise_ratio(points, nbrs));
    let per_scale = measure_values(points, nbrs, ratio, params, &scales);
    let r = combine(&scales, per_scale, params)?;
    finish(points, nbrs, ratio, r, params, segmentation)
}

/// The labelling stages after the thresholds (the Potts labelling on noisy clouds, the
/// thinning, the surface stage) on the detector's result `r`.
pub(crate) fn finish<'s>(
    points: &[Point3],
    nbrs: &Neighborhoods,
    ratio: f64,
    mut r: SharpResult,
    params: &SharpParams,
    segmentation: impl FnOnce() -> Result<Cow<'s, PointSegmentation>>,
) -> Result<SharpResult> {
    r.noise_ratio = Some(ratio);
    let auto = Regularize::noisy();
    let params = match (&params.regularize, params.auto_regularize) {
        (None, Some(t)) if ratio > t && nbrs.k() >= auto.k.max(auto.k_dir) => &SharpParams {
            regularize: Some(auto),
            ..params.clone()
        },
        _ => params,
    };
    r.regularized = params.regularize.is_some();
    // The surfaces' decisions first: the Potts labelling then labels only the points they
    // leave undecided, the decided ones entering as fixed labels (their own labels would be
    // replaced anyway).
    let decided = match params
        .surfaces
        .as_ref()
        .filter(|_| params.measure == Measure::ProjectedDistance)
    {
        Some(sp) => {
            let noisy = ratio > params.auto_regularize.unwrap_or(noise::NOISY_RATIO);
            let sp = SurfaceRefine {
                k: sp.k.min(nbrs.k()),
                ..sp.clone()
            };
            let start = std::time::Instant::now();
            let seg = segmentation()?;
            let (decided, mut report) = surfaces::decide(points, nbrs, &seg, noisy, &sp)?;
            report.seconds = start.elapsed().as_secs_f64();
            r.surfaces = Some(report);
            Some(decided)
        }
        None => None,
    };
    if params.regularize.is_some() || params.thin {
        let fixed: Option<Vec<Option<bool>>> = decided
            .as_ref()
            .map(|d| d.iter().map(|x| x.map(|(label, _)| label)).collect());
        let merged: Option<Vec<f64>> = decided
            .as_ref()
            .filter(|_| params.regularize.is_some())
            .map(|d| {
                d.iter()
                    .zip(&r.sharpness)
                    .map(|(x, &s)| x.map_or(s, |(_, t)| t))
                    .collect()
            });
        r.sharp = relabel_fixed(
            points,
            nbrs,
            &r.sharp,
            merged.as_deref().unwrap_or(&r.sharpness),
            params,
            fixed.as_deref(),
        )?;
    }
    if let Some(d) = &decided {
        surfaces::apply(d, &mut r.sharp, &mut r.sharpness);
    }
    Ok(r)
}

/// Per scale, the measure of every point over its neighbourhood (steps 1 of the module
/// documentation): the expensive pass, one gathering of the largest neighbourhood per point.
/// `ratio` the measured noise ratio (the one-face test is off on noisy clouds).
pub(crate) fn measure_values(
    points: &[Point3],
    nbrs: &Neighborhoods,
    ratio: f64,
    params: &SharpParams,
    scales: &[usize],
) -> Vec<Vec<f64>> {
    let kmax = scales.iter().copied().max().unwrap_or(1);
    if matches!(
        params.measure,
        Measure::ProjectedDistance | Measure::SurfaceVariation
    ) {
        // Every scale from one gathering of the largest neighbourhood per point.
        let ns = scales.len();
        // The one-face test compares chord angles of 15°: on clouds whose noise is a sizeable
        // fraction of the spacing (the regularised ones) it drops neighbours at random.
        let face_normals = (params.one_face && ratio <= noise::NOISY_RATIO)
            .then(|| face::face_normals(points, nbrs));
        let test = face::SheetTest::default();
        let mut flat = vec![0.0f64; points.len() * ns];
        flat.par_chunks_mut(ns)
            .enumerate()
            .with_min_len(256)
            .for_each_init(
                || (Vec::new(), Vec::new(), vec![0usize; ns], Vec::new()),
                |(coords, work, ends, cum): &mut Gather, (i, out)| {
                    let p = points[i];
                    coords.clear();
                    coords.push(p);
                    let row = nbrs.prefix(i, kmax);
                    match &face_normals {
                        Some(m) => {
                            // The neighbours on the point's own sheet; scale s keeps those among
                            // its scales[s] nearest.
                            let mp = m[i];
                            cum.clear();
                            cum.push(1);
                            for &j in row {
                                let q = points[j as usize];
                                if !test.other_sheet(p, mp, q, m[j as usize]) {
                                    coords.push(q);
                                }
                                cum.push(coords.len());
                            }
                            for (e, &k) in ends.iter_mut().zip(scales) {
                                *e = cum[k.min(row.len())];
                            }
                        }
                        None => {
                            coords.extend(row.iter().map(|&j| points[j as usize]));
                            for (e, &k) in ends.iter_mut().zip(scales) {
                                *e = k + 1;
                            }
                        }
                    }
                    measures::pca_measure_scales(
                        coords,
                        ends,
                        params.measure,
                        params.pca_weight,
                        params.density_invariant,
                        work,
                        out,
                    );
                },
            );
        (0..ns)
            .map(|s| flat.par_chunks(ns).map(|row| row[s]).collect())
            .collect()
    } else {
        scales
            .iter()
            .map(|&k| {
                measures::measure_at_scale(
                    points,
                    |i| nbrs.prefix(i, k),
                    None,
                    params.measure,
                    params.pca_weight,
                    params.density_invariant,
                )
            })
            .collect()
    }
}

/// The labelling stages of [`detect_points_with`] after the thresholds: from the per-point
/// decisions `sharp` (F(i) of equation 5) and `sharpness`, the Potts labelling of
/// [`SharpParams::regularize`] when set, then the thinning of [`SharpParams::thin`] when on.
/// Lets a caller try labelling variants without recomputing the measures.
///
/// Errors: lengths that differ from the number of points, neighbour lists shorter than 16
/// (thinning) or than the regularisation's k, invalid regularisation parameters.
pub fn relabel_points(
    points: &[Point3],
    nbrs: &Neighborhoods,
    sharp: &[bool],
    sharpness: &[f64],
    params: &SharpParams,
) -> Result<Vec<bool>> {
    relabel_fixed(points, nbrs, sharp, sharpness, params, None)
}

/// [`relabel_points`] with the labels of some points known (`fixed`, see
/// [`potts::regularize_fixed`]; with the regularisation the thinning sees them so labelled).
fn relabel_fixed(
    points: &[Point3],
    nbrs: &Neighborhoods,
    sharp: &[bool],
    sharpness: &[f64],
    params: &SharpParams,
    fixed: Option<&[Option<bool>]>,
) -> Result<Vec<bool>> {
    let n = points.len();
    if sharp.len() != n || sharpness.len() != n || nbrs.len() != n {
        return Err(Error::InvalidArgument(format!(
            "sharp relabelling: {} labels, {} sharpness values, {} neighbour lists for {n} points",
            sharp.len(),
            sharpness.len(),
            nbrs.len()
        )));
    }
    let mut labels = match &params.regularize {
        Some(reg) => potts::regularize_fixed(points, nbrs, sharpness, reg, fixed)?,
        None => sharp.to_vec(),
    };
    if params.thin {
        let k = nbrs.k().min(16);
        labels = thin::thin(
            points,
            &labels,
            sharpness,
            |i| nbrs.prefix(i, k),
            k,
            k.min(8),
            true,
        );
    }
    Ok(labels)
}

/// Sharp feature vertices of a triangle mesh: the measures over the vertex k-rings (tran
/// section 2.2) for every ring size in the scales, with the Gouraud vertex normals (equation 2,
/// ω_j = 1) for the projected distance and the normal variation.
///
/// Errors: invalid parameters or a mesh whose topology cannot be built.
pub fn detect_mesh(mesh: &TriMesh, params: &SharpParams) -> Result<SharpResult> {
    params.validate()?;
    let scales = params
        .scales
        .clone()
        .unwrap_or_else(|| MESH_SCALES.to_vec());
    check_scales(&scales, "ring sizes")?;
    let kmax = scales.iter().copied().max().unwrap_or(1);
    if kmax > 16 {
        return Err(Error::InvalidArgument(format!(
            "sharp features on meshes: ring size {kmax} is too large (at most 16)"
        )));
    }
    let topo = MeshTopology::new(mesh)?;
    let (rings, ends) = vertex_k_rings_layered(&topo, kmax)?;
    let normals = mesh_vertex_normals(mesh, Weighting::Uniform)?;
    let points = &mesh.vertices.positions;
    let per_scale: Vec<Vec<f64>> = scales
        .iter()
        .map(|&s| {
            measures::measure_at_scale(
                points,
                |i| {
                    let row = rings.row(i);
                    let end = ends[i * kmax + s - 1] as usize;
                    &row[..end.min(row.len())]
                },
                Some(&normals),
                params.measure,
                params.pca_weight,
                params.density_invariant,
            )
        })
        .collect();
    let mut r = combine(&scales, per_scale, params)?;
    if params.thin {
        r.sharp = thin::thin(
            points,
            &r.sharp,
            &r.sharpness,
            |i| {
                let row = rings.row(i);
                &row[..(ends[i * kmax + kmax.min(2) - 1] as usize).min(row.len())]
            },
            usize::MAX,
            usize::MAX,
            false,
        );
    }
    Ok(r)
}

/// Equations 4 and 5: a threshold per scale, a point is sharp when it passes every scale.
fn combine(
    scales: &[usize],
    per_scale: Vec<Vec<f64>>,
    params: &SharpParams,
) -> Result<SharpResult> {
    let mut thresholds = Vec::with_capacity(scales.len());
    for values in &per_scale {
        thresholds.push(match params.threshold {
            ThresholdRule::Otsu => {
                let o = otsu(values, &params.otsu)?;
                (o.threshold, o.normalized)
            }
            ThresholdRule::Manual(tn) => {
                if !(tn.is_finite() && tn > 0.0) {
                    return Err(Error::InvalidArgument(format!(
                        "manual sharpness threshold must be positive, got {tn}"
                    )));
                }
                let max = values.par_iter().copied().reduce(|| 0.0, f64::max);
                (tn * max, tn)
            }
        });
    }
    Ok(apply_thresholds(scales, &per_scale, &thresholds))
}

/// Equations 4 and 5 and the sharpness min_s value_s / T_s from each scale's threshold
/// (T_s, T_s normalised).
pub(crate) fn apply_thresholds(
    scales: &[usize],
    per_scale: &[Vec<f64>],
    thresholds: &[(f64, f64)],
) -> SharpResult {
    let n = per_scale.first().map_or(0, Vec::len);
    let reports = scales
        .iter()
        .zip(per_scale)
        .zip(thresholds)
        .map(
            |((&scale, values), &(threshold, normalized_threshold))| ScaleReport {
                scale,
                threshold,
                normalized_threshold,
                detected: values.par_iter().filter(|&&v| v >= threshold).count(),
            },
        )
        .collect();
    let thresholds: Vec<f64> = thresholds.iter().map(|t| t.0).collect();
    let sharpness: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|i| {
            per_scale
                .iter()
                .zip(&thresholds)
                .map(|(v, &t)| {
                    if t > 0.0 {
                        v[i] / t
                    } else if v[i] > 0.0 {
                        f64::INFINITY
                    } else {
                        0.0
                    }
                })
                .fold(f64::INFINITY, f64::min)
        })
        .map(|s| if s.is_finite() { s } else { f64::MAX })
        .collect();
    let sharp = per_scale
        .iter()
        .zip(&thresholds)
        .fold(vec![true; n], |mut acc, (v, &t)| {
            acc.par_iter_mut()
                .zip(v.par_iter())
                .for_each(|(a, &x)| *a = *a && x >= t);
            acc
        });
    SharpResult {
        sharp,
        sharpness,
        scales: reports,
        noise_ratio: None,
        regularized: false,
        surfaces: None,
    }
}
