//! Fillet (smooth-edge) lines of point clouds: Demarsin et al. 2008, "Meshless extraction of
//! closed feature lines using histogram thresholding".
//!
//! 1. **Smooth regions** (section 1.2): the first-order segmentation of demarsin2007
//!    ([`crate::lines::first_order`]: Delaunay 1-ring normals, region growing with α_max = 8°)
//!    splits the cloud along its sharp edges; its large clusters are the parts enclosed by sharp
//!    lines (and the boundary), each treated separately. The small clusters along sharp edges
//!    (those between two or more large clusters) belong to no smooth region; groups of small
//!    clusters that touch only one large cluster are noise islands and join its region
//!    (crease's addition: otherwise each island punches a hole with a boundary into the
//!    region, and at 5 % noise the fillet graph wires dozens of spurious lines to them).
//! 2. **Per region**: optional Laplacian smoothing (section 2.4; crease uses Taubin's λ|μ
//!    variant, which does not shrink the fillets whose curvature is being measured), then the
//!    mean curvature |H| of a quadric fitted over the k nearest neighbours *within the region*
//!    ([`crate::estimate::curvature::quadric_curvature`], section 2.1). Restricting the neighbours to the
//!    region is what section 1.2 buys: the points beside a sharp edge do not see the other
//!    face, so they keep the curvature of their own patch.
//! 3. **Thresholds** ([`histogram`], section 2.2): the highest `trim` fraction of the values is
//!    left out of the histogram (section 2.4), and τ maximises ε = b1 / b2 over the start
//!    histogram of `L_start` = 50 bins. Section 2.3 asks a user whether another threshold below
//!    or above is needed; crease decides (see [`ThresholdCount::Auto`]): a threshold is
//!    accepted when it cuts a valley (ε ≥ [`MIN_RATIO`], and the peak after it stands above
//!    the valley, b3 / b2 ≥ [`MIN_RIGHT_RATIO`]: a continuous curvature ramp such as a cone's has no
//!    such second peak), when the two sides' median curvatures differ by [`MIN_CONTRAST`], and
//!    when both sides are patches, not a noise
//!    tail or the transition between two patches: within the interval it splits, the points
//!    below τ and those above τ each include a connected set of at least [`INTERIOR_FACTOR`] × `k` points whose whole
//!    1-ring lies on the same side ([`labels::band_interior`]; a curvature blob made by noise
//!    spans one quadric neighbourhood, about k points, and has hardly any point whose whole
//!    1-ring is high, and the band of transition values between two patches is one or two
//!    points wide). Accepted thresholds are refined below and
//!    above (the values under τ, then over τ, each with their own histogram) until no split is
//!    accepted or `max` thresholds are found. The user can force a count or give the values.
//! 4. **Labels and lines** (section 3, [`labels`]): per threshold, low / inner / border / noisy
//!    labels, region growing on them, and the cluster graph of demarsin2007
//!    ([`crate::lines::network`]: G_all, G_extended, pruned MST, Algorithm 2, closing), smoothed
//!    along the lines ([`crate::lines::Smoothing::AlongLine`]). As in the paper's Fig. 7(b),
//!    every threshold yields its own closed lines.
//!
//! **Layout.** This file holds the parameters, the results and the pipeline over the regions;
//! step 1 is in `smooth_regions`, steps 2 to 4 of one region in `region`, which calls
//! `curvature` (step 2) and `thresholds` (step 3); [`curve_network`] merges the sharp and the
//! smooth lines (`network`).

mod curvature;
pub mod histogram;
pub mod labels;
mod network;
mod region;
mod smooth_regions;
mod thresholds;

use std::time::Instant;

use serde::Serialize;

pub use histogram::{Search, Split, L_START};
pub use labels::Label;
pub use network::{curve_network, CurveNetwork};

use crate::analysis::CloudAnalysis;
use crate::geometry::{chain_segments, Point3};
use crate::lines::{self, FirstOrder, LineNetwork, LinesParams, Smoothing};
use crate::spatial::distinct_in_input_order;
use crate::{Error, Result};
use region::process_region;
use smooth_regions::{island_owners, Shared};

/// Smallest ε = b1 / b2 of an accepted threshold: the joined valley bin holds at most half the
/// joined peak bin. A histogram without a valley (one mode) has its maximum ratio in the tail,
/// where the inner-patch test rejects it.
pub const MIN_RATIO: f64 = 2.0;

/// Smallest b3 / b2 of an accepted threshold: the peak after the valley is half as high
/// again as the valley. Lower than [`MIN_RATIO`] because the next peak is usually the smaller
/// patch (fillets beside large planes), whose noisy curvature also spreads over more bins; a
/// continuous ramp of curvature (a cone) has b3 ≤ b2.
pub const MIN_RIGHT_RATIO: f64 = 1.5;

/// Smallest relative difference (high − low) / high of the median curvatures on the two
/// sides of an accepted threshold: patches of one analytic surface are not split (a
/// cylinder's curvature varies by round-off only, and along a cone whose radius halves the two
/// halves differ by less, see `docs/experiments/fillets.md`). Fillet borders have far more
/// (plane / fillet 1.0, fillet / spherical corner 0.5).
pub const MIN_CONTRAST: f64 = 0.35;

/// An accepted threshold's bands must each hold a patch interior of at least this many times
/// the quadric's k points: noise makes curvature blobs about one neighbourhood (k points) wide,
/// whose interiors stay below that.
pub const INTERIOR_FACTOR: usize = 3;

/// Noise islands (see `island_owners`) hold at most this many times the quadric's k points.
pub const ISLAND_FACTOR: usize = 2;

/// Valleys of one interval tried, in decreasing ε, before the interval is left unsplit.
pub const MAX_TRIES: usize = 8;

/// How many thresholds per smooth region.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ThresholdCount {
    /// Decided per region (see the module documentation), at most `max`.
    Auto {
        /// Upper bound on the number of thresholds.
        max: usize,
    },
    /// Exactly this many (fewer only when the histograms cannot be split further): the
    /// splits of the largest ε are taken, accepted or not.
    Exactly(usize),
    /// These values, in every region.
    Manual(Vec<f64>),
}

impl Default for ThresholdCount {
    fn default() -> Self {
        ThresholdCount::Auto { max: 4 }
    }
}

/// Parameters of [`extract_fillets`].
#[derive(Debug, Clone, PartialEq)]
pub struct FilletParams {
    /// The sharp-line pipeline's parameters (1-rings, α_max, d_max, n, d, boundary); the
    /// smooth regions are its first-order segmentation's large clusters.
    pub lines: LinesParams,
    /// Neighbours of the quadric fit (section 2.1).
    pub curvature_k: usize,
    /// Taubin smoothing iterations before the curvature (section 2.4; 0 = none).
    pub smoothing_iterations: usize,
    /// Median filter passes over the curvature (median of the point and its `curvature_k`
    /// nearest neighbours in the region) before the histogram; see the module documentation.
    pub median_iterations: usize,
    /// Fraction of the highest curvatures left out of the histogram (section 2.4).
    pub trim: f64,
    /// Start resolution L_start (section 2.2).
    pub bins: usize,
    /// Full search or one run (section 2.2).
    pub search: Search,
    /// Thresholds per region (section 2.3).
    pub thresholds: ThresholdCount,
    /// With automatic thresholds, a region where none is accepted is examined once more with
    /// the curvature at 2 × `curvature_k`, for noisy scans (off by default: it finds fillets
    /// of noisy parts that k alone misses, but on a clean part it turns a 45° chamfer edge into
    /// a curvature band with spurious lines, see `docs/experiments/fillets.md`).
    pub coarse_retry: bool,
    /// Smooth regions with fewer points are skipped.
    pub min_region_points: usize,
}

impl Default for FilletParams {
    fn default() -> Self {
        FilletParams {
            lines: LinesParams::default(),
            curvature_k: 20,
            smoothing_iterations: 0,
            median_iterations: 1,
            trim: 0.005,
            bins: L_START,
            search: Search::Full,
            thresholds: ThresholdCount::default(),
            coarse_retry: false,
            min_region_points: 100,
        }
    }
}

/// One threshold of one region.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThresholdReport {
    /// The threshold and its histogram statistics (ratio 0 for a manual threshold).
    pub split: Split,
    /// The curvature interval it splits (between the neighbouring accepted thresholds; null
    /// for an open end).
    pub interval: [Option<f64>; 2],
    /// (high − low) / high of the median curvatures on either side within the interval.
    pub contrast: f64,
    /// Whether it was used for lines.
    pub accepted: bool,
    /// Points above τ (this and the other label counts are 0 for a rejected split: the labels
    /// are computed for the accepted ones only).
    pub high: usize,
    /// Inner, border and noisy points.
    pub inner: usize,
    /// Border points.
    pub border: usize,
    /// Noisy points.
    pub noisy: usize,
    /// Interiors (largest connected sets of points whose whole 1-ring is in the band) of the
    /// examined interval's bands below and above τ ([`labels::band_interior`]; 0 when a
    /// cheaper test already rejected the split).
    pub band_interiors: [usize; 2],
    /// Polylines and closed loops found with it.
    pub polylines: usize,
    /// Closed loops among them.
    pub closed_loops: usize,
}

/// One smooth region.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegionReport {
    /// Its cluster in the first-order segmentation.
    pub cluster: u32,
    /// Number of points.
    pub points: usize,
    /// Neighbours of the curvature that gave the thresholds.
    pub curvature_k: usize,
    /// Curvature range of the histogram after trimming.
    pub histogram_range: [f64; 2],
    /// Every threshold examined, in the order found.
    pub thresholds: Vec<ThresholdReport>,
}

/// Smooth lines: one network per accepted threshold and region, merged.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CurveSet {
    /// Vertex positions.
    pub vertices: Vec<Point3>,
    /// True for the vertices on the boundary of their smooth region (next to a sharp edge or
    /// on the cloud's boundary), where a smooth line meets the rest of the network.
    pub on_boundary: Vec<bool>,
    /// Edges between vertices.
    pub edges: Vec<[u32; 2]>,
    /// Polylines split at junctions; a closed loop repeats its first vertex.
    pub polylines: Vec<Vec<u32>>,
}

impl CurveSet {
    /// Appends a network's lines except its boundary lines (edges between two boundary
    /// vertices): the feature lines, ending on the boundary where they meet it.
    pub fn append_feature(&mut self, net: &LineNetwork) {
        let kept: Vec<[u32; 2]> = net
            .edges
            .iter()
            .copied()
            .filter(|e| !(net.on_boundary[e[0] as usize] && net.on_boundary[e[1] as usize]))
            .collect();
        let mut index = vec![u32::MAX; net.vertices.len()];
        let base = self.vertices.len() as u32;
        let mut used = 0u32;
        for e in &kept {
            for &v in e {
                if index[v as usize] == u32::MAX {
                    index[v as usize] = used;
                    used += 1;
                    self.vertices.push(net.vertices[v as usize]);
                    self.on_boundary.push(net.on_boundary[v as usize]);
                }
            }
        }
        let local: Vec<[u32; 2]> = kept
            .iter()
            .map(|e| [index[e[0] as usize], index[e[1] as usize]])
            .collect();
        self.polylines.extend(
            chain_segments(used as usize, &local)
                .into_iter()
                .map(|l| l.into_iter().map(|v| v + base).collect::<Vec<u32>>()),
        );
        self.edges
            .extend(local.iter().map(|e| [e[0] + base, e[1] + base]));
    }

    /// Vertices of degree 1.
    pub fn endpoints(&self) -> usize {
        self.counts().endpoints
    }

    /// Vertices of degree 3 or more.
    pub fn junctions(&self) -> usize {
        self.counts().junctions
    }

    /// Polylines that are closed loops.
    pub fn closed_loops(&self) -> usize {
        self.counts().closed_loops
    }

    fn counts(&self) -> crate::geometry::NetworkCounts {
        crate::geometry::network_counts(self.vertices.len(), &self.edges, &self.polylines)
    }
}

/// Per-point output of [`extract_fillets`] (input order).
#[derive(Debug, Clone, PartialEq)]
pub struct Fillets {
    /// The smooth region of every point (`u32::MAX`: on a sharp-edge band or in a skipped
    /// region).
    pub region: Vec<u32>,
    /// Mean curvature |H| used for the histogram (NaN outside the regions).
    pub curvature: Vec<f64>,
    /// The strongest label over the accepted thresholds (border > inner > noisy > low); `None`
    /// outside the regions.
    pub label: Vec<Option<Label>>,
    /// The curvature patch of every point: the number of accepted thresholds of its region
    /// below its curvature (0 = lowest patch; `u8::MAX` outside the regions).
    pub patch: Vec<u8>,
    /// The smooth lines.
    pub lines: CurveSet,
    /// Per-region thresholds and counts.
    pub regions: Vec<RegionReport>,
    /// The sharp lines of the same first-order segmentation (when asked for).
    pub sharp: Option<LineNetwork>,
    /// Seconds: first-order segmentation, sharp lines, curvature, thresholds and lines.
    pub seconds: Timing,
}

/// Time per stage of [`extract_fillets`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Timing {
    /// Delaunay 1-rings, normals and region growing.
    pub first_order: f64,
    /// The sharp-line graph pipeline.
    pub sharp_lines: f64,
    /// Region kNN, smoothing and quadric curvature.
    pub curvature: f64,
    /// Histogram thresholds and labels.
    pub thresholds: f64,
    /// Label growing and the cluster graphs of the smooth lines.
    pub smooth_lines: f64,
}

impl FilletParams {
    /// Errors (`InvalidArgument`) on invalid line settings ([`LinesParams::validate`]), a
    /// trimmed fraction outside [0, 0.5), fewer than 4 bins, a curvature k below 5, or manual
    /// thresholds that are empty or not finite.
    pub fn validate(&self) -> Result<()> {
        check_params(self)
    }
}

fn check_params(params: &FilletParams) -> Result<()> {
    params.lines.validate()?;
    if !(0.0..0.5).contains(&params.trim) {
        return Err(Error::InvalidArgument(format!(
            "the trimmed fraction must be in [0, 0.5), got {}",
            params.trim
        )));
    }
    if params.bins < 4 || params.curvature_k < 5 {
        return Err(Error::InvalidArgument(format!(
            "fillets need at least 4 histogram bins and k >= 5 for the quadric, got {} and {}",
            params.bins, params.curvature_k
        )));
    }
    if let ThresholdCount::Manual(v) = &params.thresholds {
        if v.is_empty() || v.iter().any(|t| !t.is_finite()) {
            return Err(Error::InvalidArgument(
                "manual thresholds must be finite numbers".to_string(),
            ));
        }
    }
    Ok(())
}

/// Runs the pipeline of the module documentation on `points`; with `with_sharp` the sharp lines
/// of the same first-order segmentation are returned too (the whole curve network).
///
/// Exact duplicates are processed once (their copies take the original's labels).
///
/// Errors: too few points, non-finite coordinates, invalid parameters.
pub fn extract_fillets(
    points: &[Point3],
    params: &FilletParams,
    with_sharp: bool,
) -> Result<Fillets> {
    check_params(params)?;
    let Some(distinct) = distinct_in_input_order(points) else {
        let first = lines::first_order(points, &params.lines)?;
        return extract_fillets_with(points, &first, params, with_sharp);
    };
    let first = lines::first_order(&distinct.points, &params.lines)?;
    let f = extract_fillets_with(&distinct.points, &first, params, with_sharp)?;
    Ok(per_input_point(f, &distinct.of))
}

/// `f` computed on some rows of points, its per-point outputs given to every input point
/// (`rows[i]`: input point i's row).
fn per_input_point(mut f: Fillets, rows: &[u32]) -> Fillets {
    use crate::spatial::gather;
    f.region = gather(rows, &f.region);
    f.curvature = gather(rows, &f.curvature);
    f.label = gather(rows, &f.label);
    f.patch = gather(rows, &f.patch);
    if let Some(net) = f.sharp.as_mut() {
        net.segmentation.labels = gather(rows, &net.segmentation.labels);
    }
    f
}

/// [`extract_fillets`] on a shared analysis of the cloud: the first-order structure is built
/// from its neighbour lists (`params.lines.k` must be at most its `max_k`); per-point outputs
/// are in the cloud's input order.
///
/// Errors: as [`extract_fillets`], and the analysis' neighbour errors.
pub fn extract_fillets_from(
    analysis: &CloudAnalysis,
    params: &FilletParams,
    with_sharp: bool,
) -> Result<Fillets> {
    check_params(params)?;
    let points = analysis.points();
    let first = lines::first_order_with(points, analysis.neighbours()?, &params.lines)?;
    let f = extract_fillets_with(points, &first, params, with_sharp)?;
    Ok(per_input_point(f, analysis.rows()))
}

/// [`extract_fillets`] on a first-order structure already computed for `points` with
/// `params.lines` (see [`extract_fillets_from`]).
///
/// Errors: as [`extract_fillets`], and a first-order structure of another number of points.
pub fn extract_fillets_with(
    points: &[Point3],
    first: &FirstOrder,
    params: &FilletParams,
    with_sharp: bool,
) -> Result<Fillets> {
    check_params(params)?;
    if first.segmentation.labels.len() != points.len() {
        return Err(Error::InvalidArgument(format!(
            "fillets: a first-order segmentation of {} points for {} points",
            first.segmentation.labels.len(),
            points.len()
        )));
    }
    let mut seconds = Timing::default();
    seconds.first_order = first.seconds;
    let sharp = if with_sharp {
        let t = Instant::now();
        let boundary = params.lines.boundary.then_some(first.boundary.as_slice());
        let smoothing = if params.lines.smooth {
            Smoothing::PatchIntersection
        } else {
            Smoothing::None
        };
        let net = lines::network(
            points,
            first.segmentation.clone(),
            &first.adjacency,
            boundary,
            &params.lines,
            smoothing,
            first.seconds,
        )?;
        seconds.sharp_lines = t.elapsed().as_secs_f64();
        Some(net)
    } else {
        None
    };

    // Smooth regions: the large clusters (section 2.3's size split) with enough points.
    let seg = &first.segmentation;
    let m = seg.num_clusters().max(1);
    let mean = seg.sizes.iter().map(|&s| s as f64).sum::<f64>() / m as f64;
    let min_points = params
        .min_region_points
        .max(params.curvature_k + 1)
        .max(params.bins);
    let owner = island_owners(
        &seg.labels,
        &seg.sizes,
        mean,
        &first.adjacency,
        ISLAND_FACTOR * params.curvature_k,
    );
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); seg.num_clusters()];
    for (i, &l) in seg.labels.iter().enumerate() {
        members[owner[l as usize] as usize].push(i as u32);
    }
    let n = points.len();
    let mut out = Fillets {
        region: vec![u32::MAX; n],
        curvature: vec![f64::NAN; n],
        label: vec![None; n],
        patch: vec![u8::MAX; n],
        lines: CurveSet::default(),
        regions: Vec::new(),
        sharp,
        seconds,
    };
    let mut owner_of_point = vec![u32::MAX; n];
    let mut local_index = vec![u32::MAX; n];
    for (c, ids) in members.iter().enumerate() {
        for (k, &i) in ids.iter().enumerate() {
            owner_of_point[i as usize] = c as u32;
            local_index[i as usize] = k as u32;
        }
    }
    let shared = Shared {
        adjacency: &first.adjacency,
        owner: &owner_of_point,
        local: &local_index,
        cloud_boundary: params.lines.boundary.then_some(first.boundary.as_slice()),
    };
    for (c, ids) in members.iter().enumerate() {
        let size = ids.len();
        if (seg.sizes[c] as f64) < mean || size < min_points {
            continue;
        }
        let region_id = out.regions.len() as u32;
        let report = process_region(points, ids, c as u32, &shared, params, &mut out, region_id)?;
        out.regions.push(RegionReport {
            cluster: c as u32,
            ..report
        });
    }
    Ok(out)
}
