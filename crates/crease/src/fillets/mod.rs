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

pub mod histogram;
pub mod labels;

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

pub use histogram::{Search, Split, L_START};
pub use labels::Label;

use crate::analysis::CloudAnalysis;
use crate::estimate::curvature::{quadric_curvature, QuadricParams};
use crate::geometry::{chain_segments, Csr, Point3};
use crate::lines::{self, FirstOrder, LineNetwork, LinesParams, Smoothing};
use crate::spatial::knn;
use crate::{Error, Result};

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
/// Errors: too few points, non-finite coordinates, invalid parameters.
pub fn extract_fillets(
    points: &[Point3],
    params: &FilletParams,
    with_sharp: bool,
) -> Result<Fillets> {
    check_params(params)?;
    let first = lines::first_order(points, &params.lines)?;
    extract_fillets_with(points, &first, params, with_sharp)
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
    let mut f = extract_fillets_with(points, &first, params, with_sharp)?;
    f.region = analysis.to_input_order(&f.region);
    f.curvature = analysis.to_input_order(&f.curvature);
    f.label = analysis.to_input_order(&f.label);
    f.patch = analysis.to_input_order(&f.patch);
    if let Some(net) = f.sharp.as_mut() {
        net.segmentation.labels = analysis.to_input_order(&net.segmentation.labels);
    }
    Ok(f)
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

/// The smooth region every first-order cluster belongs to: a large cluster to itself; a group
/// of adjacent small clusters that touches exactly one large cluster (a noise island inside a
/// smooth patch, section 3 of demarsin2007: "small clusters are created at the noisy parts")
/// to that large cluster; the others (the bands along sharp edges, between two or more large
/// clusters) to themselves, which leaves them out of every region. Without this, every noise
/// island punches a hole with a boundary into its region, and the fillet graph wires lines
/// to those holes. Groups larger than `max_island` points stay out: they are the bands of
/// sharp edges that the region growing went around (two faces joined elsewhere into one large
/// cluster), not noise.
fn island_owners(
    labels: &[u32],
    sizes: &[u32],
    mean: f64,
    adjacency: &Csr,
    max_island: usize,
) -> Vec<u32> {
    let m = sizes.len();
    let large = |c: u32| sizes[c as usize] as f64 >= mean;
    let mut parent: Vec<u32> = (0..m as u32).collect();
    fn find(parent: &mut [u32], mut a: u32) -> u32 {
        while parent[a as usize] != a {
            parent[a as usize] = parent[parent[a as usize] as usize];
            a = parent[a as usize];
        }
        a
    }
    let mut touches: Vec<(u32, u32)> = Vec::new();
    for (p, &lp) in labels.iter().enumerate() {
        if large(lp) || p >= adjacency.num_rows() {
            continue;
        }
        for &q in adjacency.row(p) {
            let lq = labels[q as usize];
            if lq == lp {
                continue;
            }
            if large(lq) {
                touches.push((lp, lq));
            } else {
                let (a, b) = (find(&mut parent, lp), find(&mut parent, lq));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
    }
    // Large clusters touched by each group of small clusters.
    let mut seen: Vec<(u32, u32)> = touches
        .into_iter()
        .map(|(s, l)| (find(&mut parent, s), l))
        .collect();
    seen.sort_unstable();
    seen.dedup();
    let mut only = vec![u32::MAX; m];
    let mut count = vec![0u32; m];
    for &(g, l) in &seen {
        count[g as usize] += 1;
        only[g as usize] = l;
    }
    let mut group_size = vec![0usize; m];
    for c in 0..m as u32 {
        if !large(c) {
            group_size[find(&mut parent, c) as usize] += sizes[c as usize] as usize;
        }
    }
    (0..m as u32)
        .map(|c| {
            if large(c) {
                return c;
            }
            let g = find(&mut parent, c) as usize;
            if count[g] == 1 && group_size[g] <= max_island {
                only[g]
            } else {
                c
            }
        })
        .collect()
}

/// What every region reads of the whole cloud: the 1-ring adjacency, the smooth region
/// (first-order cluster) each point belongs to and its index within that region, and the cloud's
/// boundary flags.
struct Shared<'a> {
    adjacency: &'a Csr,
    owner: &'a [u32],
    local: &'a [u32],
    cloud_boundary: Option<&'a [bool]>,
}

/// The adjacency of region `cluster` (points `ids`) in local indices: neighbours outside the
/// region dropped.
fn local_adjacency(ids: &[u32], cluster: u32, shared: &Shared) -> Csr {
    let adjacency = shared.adjacency;
    let rows: Vec<Vec<u32>> = ids
        .par_iter()
        .map(|&i| {
            if (i as usize) >= adjacency.num_rows() {
                return Vec::new();
            }
            adjacency
                .row(i as usize)
                .iter()
                .filter(|&&q| shared.owner[q as usize] == cluster)
                .map(|&q| shared.local[q as usize])
                .collect()
        })
        .collect();
    let counts: Vec<u32> = rows.iter().map(|r| r.len() as u32).collect();
    Csr {
        offsets: Csr::offsets_from_counts(&counts),
        indices: rows.concat(),
    }
}

/// Taubin λ|μ smoothing over the 1-ring (umbrella operator), `iterations` pairs of steps.
fn taubin(points: &[Point3], adjacency: &Csr, iterations: usize) -> Vec<Point3> {
    const LAMBDA: f64 = 0.5;
    const MU: f64 = -0.53;
    let mut cur = points.to_vec();
    for _ in 0..iterations {
        for f in [LAMBDA, MU] {
            cur = (0..cur.len())
                .into_par_iter()
                .map(|i| {
                    let row = adjacency.row(i);
                    if row.is_empty() {
                        return cur[i];
                    }
                    let mut s = [0.0; 3];
                    for &q in row {
                        for k in 0..3 {
                            s[k] += cur[q as usize][k];
                        }
                    }
                    let inv = 1.0 / row.len() as f64;
                    let p = cur[i];
                    [
                        p[0] + f * (s[0] * inv - p[0]),
                        p[1] + f * (s[1] * inv - p[1]),
                        p[2] + f * (s[2] * inv - p[2]),
                    ]
                })
                .collect();
        }
    }
    cur
}

/// Every signed mean curvature replaced by the median over the point and its kNN row (NaN
/// values skipped), each neighbour's value taken relative to the point's normal (negated when
/// the two fitted normals point to opposite sides). On a flat patch the noise makes H scatter
/// on both sides of 0 and the median brings it back to 0, which a filter of |H| cannot do; at
/// the border of two patches the median keeps the step where it is (a median filter preserves
/// monotone steps), unlike a mean.
fn median_filter(
    values: &[f64],
    normals: &[Point3],
    nbrs: &crate::spatial::Neighborhoods,
) -> Vec<f64> {
    (0..values.len())
        .into_par_iter()
        .map_init(Vec::new, |buf: &mut Vec<f64>, i| {
            buf.clear();
            buf.extend(
                std::iter::once(values[i])
                    .chain(nbrs.of(i).iter().map(|&q| {
                        let q = q as usize;
                        if crate::geometry::vec3::dot(normals[i], normals[q]) < 0.0 {
                            -values[q]
                        } else {
                            values[q]
                        }
                    }))
                    .filter(|v| v.is_finite()),
            );
            if buf.is_empty() {
                return f64::NAN;
            }
            let mid = buf.len() / 2;
            let (_, m, _) = buf.select_nth_unstable_by(mid, f64::total_cmp);
            *m
        })
        .collect()
}

/// Median of the finite values in `(a, b]` (NaN when there is none).
fn band_median(values: &[f64], a: f64, b: f64) -> f64 {
    let mut v: Vec<f64> = values
        .iter()
        .copied()
        .filter(|&x| x.is_finite() && x > a && x <= b)
        .collect();
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The value below which a fraction `1 - trim` of the finite values lie.
fn upper_quantile(values: &[f64], trim: f64) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_unstable_by(f64::total_cmp);
    let lo = v[0];
    let k = (((v.len() - 1) as f64) * (1.0 - trim)).round() as usize;
    Some((lo, v[k.min(v.len() - 1)]))
}

struct Candidate {
    split: Split,
    labels: Vec<Label>,
    /// Interiors of the interval's bands below and above τ.
    interiors: [usize; 2],
    contrast: f64,
    accepted: bool,
    /// The interval split (-∞ / +∞ at the ends of the value range).
    range: [f64; 2],
}

fn examine(
    values: &[f64],
    hist_range: (f64, f64),
    range: [f64; 2],
    adjacency: &Csr,
    params: &FilletParams,
) -> Option<Candidate> {
    let (lo, hi) = hist_range;
    let splits = histogram::ranked(
        values,
        range[0].max(lo),
        range[1].min(hi),
        params.bins,
        params.search,
    );
    let mut first = None;
    for split in splits.into_iter().take(MAX_TRIES) {
        if split.ratio < MIN_RATIO && first.is_some() {
            break;
        }
        let c = candidate(values, split, range, adjacency, params);
        if c.accepted {
            return Some(c);
        }
        first.get_or_insert(c);
    }
    first
}

/// Examines the split `split` of the interval `range`: the histogram tests first, then the
/// contrast of the medians, then the band interiors (each only when the cheaper ones pass), and
/// the labels only for an accepted split. Labels of a split taken anyway (a count or values
/// forced by the user) come from [`with_labels`].
fn candidate(
    values: &[f64],
    split: Split,
    range: [f64; 2],
    adjacency: &Csr,
    params: &FilletParams,
) -> Candidate {
    let min_patch = INTERIOR_FACTOR * params.curvature_k;
    let mut c = Candidate {
        split,
        labels: Vec::new(),
        interiors: [0, 0],
        contrast: 0.0,
        accepted: false,
        range,
    };
    if !(split.ratio >= MIN_RATIO
        && split.right_ratio() >= MIN_RIGHT_RATIO
        && split.b1.min(split.b3) >= min_patch as u64)
    {
        return c;
    }
    let medians = [
        band_median(values, range[0], split.tau),
        band_median(values, split.tau, range[1]),
    ];
    c.contrast = (medians[1] - medians[0]) / medians[1].abs().max(f64::MIN_POSITIVE);
    if c.contrast.is_nan() || c.contrast < MIN_CONTRAST {
        return c;
    }
    c.interiors = [
        labels::band_interior(values, range[0], split.tau, adjacency),
        labels::band_interior(values, split.tau, range[1], adjacency),
    ];
    c.accepted = c.interiors.iter().all(|&s| s >= min_patch);
    if c.accepted {
        c.labels = labels::label(values, split.tau, adjacency);
    }
    c
}

/// `c` accepted, with its labels.
fn with_labels(mut c: Candidate, values: &[f64], adjacency: &Csr) -> Candidate {
    if c.labels.is_empty() {
        c.labels = labels::label(values, c.split.tau, adjacency);
    }
    c.accepted = true;
    c
}

/// |H| of every point of a region: quadric fit over its `k` nearest neighbours in the region,
/// then `median_iterations` passes of the signed median filter.
fn region_curvature(points: &[Point3], k: usize, median_iterations: usize) -> Result<Vec<f64>> {
    let nbrs = knn(points, k)?;
    let curv = quadric_curvature(points, &nbrs, &QuadricParams { k })?;
    // Signed mean curvature, each relative to its own point's fitted normal.
    let mut values = curv.mean.clone();
    for _ in 0..median_iterations {
        values = median_filter(&values, &curv.normal, &nbrs);
    }
    Ok(values.iter().map(|h| h.abs()).collect())
}

type Selection = (f64, f64, Vec<Candidate>, Vec<Candidate>);

/// The thresholds of one region's curvature values (see [`ThresholdCount`]): the histogram
/// range after trimming, the chosen candidates in increasing τ and the rejected ones.
fn select_thresholds(values: &[f64], adj: &Csr, params: &FilletParams) -> Selection {
    let (lo, hi) = upper_quantile(values, params.trim).unwrap_or((0.0, 0.0));
    let mut chosen: Vec<Candidate> = Vec::new();
    let mut rejected: Vec<Candidate> = Vec::new();
    match &params.thresholds {
        ThresholdCount::Manual(taus) => {
            for &tau in taus {
                let split = Split {
                    tau,
                    ratio: 0.0,
                    start: lo,
                    joined: 0,
                    b1: 0,
                    b2: 0,
                    b3: 0,
                };
                let c = candidate(
                    values,
                    split,
                    [f64::NEG_INFINITY, f64::INFINITY],
                    adj,
                    params,
                );
                chosen.push(with_labels(c, values, adj));
            }
        }
        ThresholdCount::Auto { max } => {
            // Breadth-first refinement: the whole range, then below and above each accepted τ.
            let mut queue = std::collections::VecDeque::from([[f64::NEG_INFINITY, f64::INFINITY]]);
            while let Some(range) = queue.pop_front() {
                if chosen.len() >= *max {
                    break;
                }
                let Some(c) = examine(values, (lo, hi), range, adj, params) else {
                    continue;
                };
                if c.accepted {
                    queue.push_back([range[0], c.split.tau]);
                    queue.push_back([c.split.tau, range[1]]);
                    chosen.push(c);
                } else {
                    rejected.push(c);
                }
            }
        }
        ThresholdCount::Exactly(count) => {
            // Greedy: split the interval whose best split has the largest ratio.
            let mut open: Vec<Candidate> = examine(
                values,
                (lo, hi),
                [f64::NEG_INFINITY, f64::INFINITY],
                adj,
                params,
            )
            .into_iter()
            .collect();
            while chosen.len() < *count && !open.is_empty() {
                let best = (0..open.len())
                    .max_by(|&a, &b| {
                        open[a]
                            .split
                            .ratio
                            .total_cmp(&open[b].split.ratio)
                            .then(b.cmp(&a))
                    })
                    .unwrap_or(0);
                let c = with_labels(open.swap_remove(best), values, adj);
                for r in [[c.range[0], c.split.tau], [c.split.tau, c.range[1]]] {
                    if let Some(next) = examine(values, (lo, hi), r, adj, params) {
                        open.push(next);
                    }
                }
                chosen.push(c);
            }
        }
    }
    chosen.sort_by(|a, b| a.split.tau.total_cmp(&b.split.tau));
    (lo, hi, chosen, rejected)
}

fn process_region(
    points: &[Point3],
    ids: &[u32],
    cluster: u32,
    shared: &Shared,
    params: &FilletParams,
    out: &mut Fillets,
    region_id: u32,
) -> Result<RegionReport> {
    let t = Instant::now();
    let adj = local_adjacency(ids, cluster, shared);
    let original: Vec<Point3> = ids.iter().map(|&i| points[i as usize]).collect();
    let smoothed = taubin(&original, &adj, params.smoothing_iterations);
    let mut values = region_curvature(&smoothed, params.curvature_k, params.median_iterations)?;
    out.seconds.curvature += t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (mut lo, mut hi, mut chosen, mut rejected) = select_thresholds(&values, &adj, params);
    out.seconds.thresholds += t.elapsed().as_secs_f64();
    let mut curvature_k = params.curvature_k;
    // Nothing found in a noisy region may be the quadric's curvature noise at k hiding the
    // valley: once more with 2k (curvature noise falls about as k^-1.5), accepted only with the
    // tests at 2k (patch interiors of 6k points).
    if chosen.is_empty()
        && params.coarse_retry
        && matches!(params.thresholds, ThresholdCount::Auto { .. })
        && ids.len() > 2 * params.curvature_k
    {
        let t = Instant::now();
        let coarse = FilletParams {
            curvature_k: 2 * params.curvature_k,
            ..params.clone()
        };
        let coarse_values =
            region_curvature(&smoothed, coarse.curvature_k, params.median_iterations)?;
        out.seconds.curvature += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let (clo, chi, cchosen, crejected) = select_thresholds(&coarse_values, &adj, &coarse);
        out.seconds.thresholds += t.elapsed().as_secs_f64();
        if !cchosen.is_empty() {
            (lo, hi, chosen) = (clo, chi, cchosen);
            rejected.extend(crejected);
            values = coarse_values;
            curvature_k = coarse.curvature_k;
        }
    }

    // Per-point outputs.
    let t = Instant::now();
    for (k, &i) in ids.iter().enumerate() {
        let i = i as usize;
        out.region[i] = region_id;
        out.curvature[i] = values[k];
        out.patch[i] = chosen.iter().filter(|c| values[k] > c.split.tau).count() as u8;
        let rank = |l: Label| match l {
            Label::Low => 0,
            Label::Noisy => 1,
            Label::Inner => 2,
            Label::Border => 3,
        };
        out.label[i] = chosen
            .iter()
            .map(|c| c.labels[k])
            .max_by_key(|&l| rank(l))
            .or(Some(Label::Low));
    }
    // The region's own boundary (points with a 1-ring neighbour outside the region, i.e. next
    // to a sharp-edge band, plus the cloud's boundary) joins each graph as the cloud boundary
    // does in demarsin2007 (Fig. 8 of demarsin2008): a fillet line that ends at a sharp edge
    // is closed through it instead of being pruned as a dangling branch.
    // A point with a neighbour outside the region has a shorter local row.
    let region_boundary: Vec<bool> = ids
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            let i = i as usize;
            shared.cloud_boundary.is_some_and(|b| b[i])
                || (i < shared.adjacency.num_rows() && adj.row_len(k) < shared.adjacency.row_len(i))
        })
        .collect();
    let mut thresholds = Vec::new();
    for c in &chosen {
        let seg = labels::grow(&c.labels, &adj);
        let net = lines::network(
            &original,
            seg,
            &adj,
            Some(&region_boundary),
            &params.lines,
            if params.lines.smooth {
                Smoothing::AlongLine
            } else {
                Smoothing::None
            },
            0.0,
        )?;
        out.lines.append_feature(&net);
        thresholds.push(report(c, Some(&net)));
    }
    thresholds.extend(rejected.iter().map(|c| report(c, None)));
    out.seconds.smooth_lines += t.elapsed().as_secs_f64();
    Ok(RegionReport {
        cluster: 0,
        points: ids.len(),
        curvature_k,
        histogram_range: [lo, hi],
        thresholds,
    })
}

fn report(c: &Candidate, net: Option<&LineNetwork>) -> ThresholdReport {
    let count = |l: Label| c.labels.iter().filter(|&&x| x == l).count();
    ThresholdReport {
        split: c.split,
        interval: c.range.map(|x| x.is_finite().then_some(x)),
        contrast: c.contrast,
        accepted: c.accepted,
        high: c.labels.len() - count(Label::Low),
        inner: count(Label::Inner),
        border: count(Label::Border),
        noisy: count(Label::Noisy),
        band_interiors: c.interiors,
        polylines: net.map_or(0, |n| n.polylines.len()),
        closed_loops: net.map_or(0, |n| n.closed_loops()),
    }
}

/// The whole curve network: sharp and smooth lines in one vertex set, each polyline tagged.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CurveNetwork {
    /// Vertex positions (the sharp network's first).
    pub vertices: Vec<Point3>,
    /// Polylines; a closed loop repeats its first vertex.
    pub polylines: Vec<Vec<u32>>,
    /// Per polyline: true for a smooth (fillet) line, false for a sharp one.
    pub smooth: Vec<bool>,
    /// Smooth-line ends joined to the sharp line they meet.
    pub joined_ends: usize,
    /// Smooth-line ends left open.
    pub open_ends: usize,
}

/// Merges the sharp and the smooth lines of `f` into one network. A smooth line that ends on
/// its region's boundary (next to a sharp edge) is extended to the nearest sharp-line vertex
/// when that lies within `3 ×` the median edge length of the smooth lines (the band between a
/// region's border points and the sharp line is one or two spacings wide), so that the
/// network a CAD user receives is connected as the paper's figures show it.
pub fn curve_network(f: &Fillets) -> CurveNetwork {
    let mut net = CurveNetwork::default();
    if let Some(sharp) = &f.sharp {
        net.vertices.extend_from_slice(&sharp.vertices);
        net.polylines.extend(sharp.polylines.iter().cloned());
        net.smooth
            .extend(std::iter::repeat_n(false, sharp.polylines.len()));
    }
    let base = net.vertices.len() as u32;
    let l = &f.lines;
    net.vertices.extend_from_slice(&l.vertices);
    let mut lengths: Vec<f64> = l
        .edges
        .iter()
        .map(|e| crate::geometry::vec3::dist(l.vertices[e[0] as usize], l.vertices[e[1] as usize]))
        .collect();
    lengths.sort_by(f64::total_cmp);
    let reach = 3.0 * lengths.get(lengths.len() / 2).copied().unwrap_or(0.0);
    let sharp_index = f
        .sharp
        .as_ref()
        .and_then(|s| crate::spatial::KdIndex::new(&s.vertices));
    let mut degree = vec![0u32; l.vertices.len()];
    for e in &l.edges {
        degree[e[0] as usize] += 1;
        degree[e[1] as usize] += 1;
    }
    for line in &l.polylines {
        let mut out: Vec<u32> = line.iter().map(|&v| v + base).collect();
        let closed = line.len() > 2 && line.first() == line.last();
        if !closed {
            for at_end in [false, true] {
                let v = if at_end {
                    line[line.len() - 1]
                } else {
                    line[0]
                } as usize;
                if degree[v] != 1 {
                    continue;
                }
                let near = sharp_index
                    .as_ref()
                    .filter(|_| l.on_boundary[v])
                    .and_then(|idx| idx.nearest(&l.vertices[v], 1).first().copied())
                    .filter(|&(_, d2)| d2.sqrt() <= reach);
                match near {
                    Some((s, _)) => {
                        net.joined_ends += 1;
                        if at_end {
                            out.push(s);
                        } else {
                            out.insert(0, s);
                        }
                    }
                    None => net.open_ends += 1,
                }
            }
        }
        net.polylines.push(out);
        net.smooth.push(true);
    }
    net
}
