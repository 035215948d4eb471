//! The analysis of one point cloud, computed once and shared by every stage.
//!
//! Every detector of crease stands on the same few things: the points in a cache-friendly
//! order, their k nearest neighbours, normals, the measured noise and the segmentation into
//! analytic surfaces. A [`CloudAnalysis`] holds them, each computed lazily on first use and at
//! most once, and the stages read them:
//!
//! | piece | computed by | read by |
//! |---|---|---|
//! | Morton order | [`crate::spatial::morton_order`] | every stage (they run on the sorted points) |
//! | neighbour lists, k = [`AnalysisParams::max_k`] | [`crate::spatial::knn()`] | sharp points (all scales are prefixes), noise, normals, segmentation, 1-rings |
//! | noise ratio | [`crate::estimate::noise::noise_ratio`] | sharp points (Potts switch, surface bands) |
//! | normals (PCA, oriented) | [`crate::segment::estimated_normals`] | segmentation, outputs |
//! | segmentation | [`crate::segment`] (point path) | sharp points' surface stage, outputs |
//!
//! One neighbour query at the largest k serves every smaller k: rows are nearest first with
//! ties broken by index, so a prefix of a row is exactly the smaller query's row. The stages
//! that take an analysis (`sharp::detect`, `lines::extract_lines_from`,
//! `fillets::extract_fillets_from`) give results in the cloud's input order. The line
//! pipelines' first-order structure (Delaunay 1-rings of the first `LinesParams::k`
//! neighbours, region growing) is theirs: `fillets::extract_fillets_from` with the sharp lines
//! builds it once for the whole curve network. [`CloudAnalysis::counts`] tells how often each piece was
//! computed (once at most: a test holds the whole `crease run` to it).
//!
//! Exact duplicate points (a cloud sampled twice over, a scanner's repeated returns: 40 % of a
//! handheld LiDAR scan) are analysed once: the analysis holds the distinct points, and
//! [`CloudAnalysis::to_input_order`] gives every duplicate its first copy's value. Counted as
//! separate samples they would fill neighbourhoods with zero-length edges (a cube sampled
//! twice was segmented into 8 planes).
//!
//! The pieces are computed on first use, one at a time, on the calling thread's rayon pool;
//! an analysis is `Sync`, but a piece asked for by two threads at once may be computed twice
//! (both results are identical; one is kept).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use rayon::prelude::*;

use crate::estimate::noise::{noise_samples, ratio_of_samples, sample_stride};
use crate::geometry::Point3;
use crate::segment::{
    estimated_normals, neighbours_needed, segment_core, PointParams, PointSegmentation,
    SegmentParams,
};
use crate::spatial::{gather, knn, morton_order_unique, Neighborhoods};
use crate::{Error, Result};

/// The default neighbour count of the one query: the largest scale of
/// [`crate::sharp::CLOUD_SCALES`] (tran section 4.2).
pub const DEFAULT_MAX_K: usize = 40;

/// Settings of the shared pieces. The defaults are those of each stage's paper (see
/// [`crate::sharp`], [`crate::segment`]).
#[derive(Debug, Clone, PartialEq)]
pub struct AnalysisParams {
    /// Neighbours per point of the one neighbour query (default [`DEFAULT_MAX_K`]); every
    /// stage's k must be at most this.
    pub max_k: usize,
    /// Segmentation thresholds.
    pub segment: SegmentParams,
    /// Segmentation: the point path's neighbour counts and patch model.
    pub points: PointParams,
}

impl Default for AnalysisParams {
    fn default() -> Self {
        AnalysisParams {
            max_k: DEFAULT_MAX_K,
            segment: SegmentParams::default(),
            points: PointParams::default(),
        }
    }
}

impl AnalysisParams {
    /// Errors (`InvalidArgument`) on invalid segmentation settings or a zero `max_k`. A
    /// `max_k` below what the normals or the segmentation read ([`neighbours_needed`]) is an
    /// error when they are asked for (a stage that reads fewer neighbours need not pay for them).
    pub fn validate(&self) -> Result<()> {
        self.segment.validate()?;
        self.points.validate()?;
        if self.max_k == 0 {
            return Err(Error::InvalidArgument(
                "analysis: max_k must be positive".into(),
            ));
        }
        Ok(())
    }

    /// Errors when the neighbour lists are shorter than the normals (`normals_given` false) or
    /// the segmentation read.
    fn check_needed(&self, normals_given: bool, what: &str) -> Result<()> {
        let need = neighbours_needed(&self.points, normals_given);
        if self.max_k < need {
            return Err(Error::InvalidArgument(format!(
                "analysis: max_k = {} is smaller than the {need} neighbours {what} reads",
                self.max_k
            )));
        }
        Ok(())
    }
}

/// How many times each piece was computed (each is 0 or 1 unless asked for concurrently).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct AnalysisCounts {
    /// Neighbour queries.
    pub neighbours: usize,
    /// Normal estimations.
    pub normals: usize,
    /// Noise measurements.
    pub noise: usize,
    /// Segmentations into analytic surfaces.
    pub segmentations: usize,
}

#[derive(Debug, Default)]
struct Counters {
    neighbours: AtomicUsize,
    normals: AtomicUsize,
    noise: AtomicUsize,
    segmentations: AtomicUsize,
}

/// The shared analysis of one point cloud (see the module documentation). The distinct points
/// are held in Morton order: `points()[r]` is input point `order()[r]` (the first of its
/// duplicates); per-point pieces follow that order, and the stages map their results back to
/// the input order ([`CloudAnalysis::to_input_order`]).
#[derive(Debug)]
pub struct CloudAnalysis {
    params: AnalysisParams,
    order: Vec<u32>,
    /// `rank[i]`: the row of input point i.
    rank: Vec<u32>,
    points: Vec<Point3>,
    neighbours: OnceLock<Neighborhoods>,
    noise: OnceLock<f64>,
    normals: OnceLock<Vec<Point3>>,
    segmentation: OnceLock<PointSegmentation>,
    normals_given: bool,
    counters: Counters,
}

impl CloudAnalysis {
    /// An analysis of `points` (input order) with the given settings; nothing is computed yet
    /// but the spatial order.
    ///
    /// Errors: invalid settings ([`AnalysisParams::validate`]), fewer than `max_k + 1`
    /// distinct points, a non-finite coordinate.
    pub fn new(points: &[Point3], params: AnalysisParams) -> Result<CloudAnalysis> {
        params.validate()?;
        if points.len() <= params.max_k {
            return Err(Error::InvalidInput(format!(
                "{} points: the analysis needs at least {} (its neighbourhoods hold {} points)",
                points.len(),
                params.max_k + 1,
                params.max_k
            )));
        }
        crate::spatial::knn::check_finite(points)?;
        let Some((order, rank)) = morton_order_unique(points) else {
            return Err(Error::InvalidInput("analysis: no points".into()));
        };
        if order.len() <= params.max_k {
            return Err(Error::InvalidInput(format!(
                "{} points, {} of them distinct: the analysis needs at least {} distinct points \
                 (its neighbourhoods hold {} points)",
                points.len(),
                order.len(),
                params.max_k + 1,
                params.max_k
            )));
        }
        let duplicates = points.len() - order.len();
        if duplicates > 0 {
            tracing::info!(
                "{duplicates} of {} points repeat another exactly: analysed once",
                points.len()
            );
        }
        let sorted = order.par_iter().map(|&i| points[i as usize]).collect();
        Ok(CloudAnalysis {
            params,
            order,
            rank,
            points: sorted,
            neighbours: OnceLock::new(),
            noise: OnceLock::new(),
            normals: OnceLock::new(),
            segmentation: OnceLock::new(),
            normals_given: false,
            counters: Counters::default(),
        })
    }

    /// An analysis of `points` whose normals are given (input order, one per point; scaled
    /// to unit length) rather than estimated: a scanner's, or a CAD sampler's.
    ///
    /// Errors: those of [`CloudAnalysis::new`]; a normal count other than the point count; a
    /// zero or non-finite normal (named by its index).
    pub fn with_normals(
        points: &[Point3],
        normals: &[Point3],
        params: AnalysisParams,
    ) -> Result<CloudAnalysis> {
        if normals.len() != points.len() {
            return Err(Error::InvalidInput(format!(
                "{} normals for {} points",
                normals.len(),
                points.len()
            )));
        }
        let mut a = CloudAnalysis::new(points, params)?;
        let sorted: Vec<Option<Point3>> = a
            .order
            .par_iter()
            .map(|&i| crate::geometry::vec3::normalize(normals[i as usize]))
            .collect();
        let mut unit = Vec::with_capacity(sorted.len());
        for (r, n) in sorted.into_iter().enumerate() {
            unit.push(n.ok_or_else(|| {
                Error::InvalidInput(format!(
                    "the normal of point {} is zero or not finite",
                    a.order[r]
                ))
            })?);
        }
        a.normals = OnceLock::from(unit);
        a.normals_given = true;
        Ok(a)
    }

    /// The settings.
    pub fn params(&self) -> &AnalysisParams {
        &self.params
    }

    /// The distinct points in Morton order.
    pub fn points(&self) -> &[Point3] {
        &self.points
    }

    /// `order()[r]` is the input index of sorted point r (the first of its duplicates).
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// `rows()[i]` is the row (in [`CloudAnalysis::points`]) of input point i.
    pub fn rows(&self) -> &[u32] {
        &self.rank
    }

    /// The number of input points (distinct or not).
    pub fn input_len(&self) -> usize {
        self.rank.len()
    }

    /// Input points that repeat an earlier one exactly (analysed as that one).
    pub fn duplicates(&self) -> usize {
        self.input_len() - self.order.len()
    }

    /// Per-point values in the analysis' (sorted) order, put back into the input order; each
    /// duplicate takes its first copy's value.
    pub fn to_input_order<T: Copy + Send + Sync>(&self, sorted: &[T]) -> Vec<T> {
        gather(&self.rank, sorted)
    }

    /// The `max_k` nearest neighbours of every (sorted) point, nearest first.
    pub fn neighbours(&self) -> Result<&Neighborhoods> {
        once(&self.neighbours, &self.counters.neighbours, || {
            knn(&self.points, self.params.max_k)
        })
    }

    /// The noise ratio of [`crate::estimate::noise::noise_ratio`], its sample's stride set by
    /// the number of input points (copies included), as a tiled run sets it
    /// ([`crate::sharp::tiled`]).
    pub fn noise_ratio(&self) -> Result<f64> {
        let nbrs = self.neighbours()?;
        once(&self.noise, &self.counters.noise, || {
            let stride = sample_stride(self.input_len());
            Ok(ratio_of_samples(&mut noise_samples(
                &self.points,
                nbrs,
                stride,
                |_| true,
            )))
        })
        .copied()
    }

    /// The (sorted) points' normals: the given ones ([`CloudAnalysis::with_normals`]), or
    /// consistently oriented PCA normals as the segmentation estimates them
    /// ([`crate::segment::estimated_normals`]).
    pub fn normals(&self) -> Result<&[Point3]> {
        if let Some(n) = self.normals.get() {
            return Ok(n);
        }
        self.params.check_needed(false, "the normal estimation")?;
        let nbrs = self.neighbours()?;
        once(&self.normals, &self.counters.normals, || {
            estimated_normals(&self.points, nbrs, &self.params.points)
        })
        .map(Vec::as_slice)
    }

    /// The segmentation of the (sorted) points into analytic surfaces.
    pub fn segmentation(&self) -> Result<&PointSegmentation> {
        if let Some(s) = self.segmentation.get() {
            return Ok(s);
        }
        self.params
            .check_needed(self.normals_given, "the segmentation")?;
        let nbrs = self.neighbours()?;
        let normals = self.normals()?;
        once(&self.segmentation, &self.counters.segmentations, || {
            segment_core(
                &self.points,
                nbrs,
                normals,
                self.normals_given,
                &self.params.segment,
                &self.params.points,
            )
        })
    }

    /// How many times each piece was computed so far.
    pub fn counts(&self) -> AnalysisCounts {
        let c = &self.counters;
        AnalysisCounts {
            neighbours: c.neighbours.load(Ordering::Relaxed),
            normals: c.normals.load(Ordering::Relaxed),
            noise: c.noise.load(Ordering::Relaxed),
            segmentations: c.segmentations.load(Ordering::Relaxed),
        }
    }
}

/// The cell's value, computing it (and counting the computation) on first use.
fn once<'a, T>(
    cell: &'a OnceLock<T>,
    counter: &AtomicUsize,
    compute: impl FnOnce() -> Result<T>,
) -> Result<&'a T> {
    if let Some(v) = cell.get() {
        return Ok(v);
    }
    let v = compute()?;
    counter.fetch_add(1, Ordering::Relaxed);
    Ok(cell.get_or_init(|| v))
}
