//! Sharp points of a cloud cut into tiles, each with a halo of its neighbours' points: for
//! clouds whose analysis outgrows one machine's memory (the Python package's
//! `crease.tiled_sharp` runs the passes below as tasks on a process pool or a dask cluster).
//!
//! Every quantity of the detector is local (a point's neighbourhoods) except three global ones:
//! the noise ratio (a quantile over a sample chosen by a hash of the coordinates,
//! [`crate::estimate::noise`]) and, per scale, the range and the histogram that give Otsu's
//! threshold. The tiles contribute to them in passes, and the merged values are exactly those of
//! one run over the whole cloud (the histograms are integer counts over the same bins):
//! 1. [`tile_noise_samples`]: the noise samples of the tile's core points; [`ratio_of_samples`]
//!    of all tiles' samples is the cloud's noise ratio.
//! 2. [`tile_measures`]: the measure of every tile point at every scale (kept by the caller until
//!    pass 4) and the range of its core points' values; [`merge_ranges`].
//! 3. [`tile_histograms`]: the core points' histograms over the merged ranges; [`thresholds`]
//!    adds them up and applies Otsu's method ([`otsu_of_histogram`]).
//! 4. [`label_tile`]: the labels from those thresholds, then the thinning (and, on noisy clouds,
//!    the Potts labelling; with [`SharpParams::surfaces`], the surface stage) on the tile.
//!
//! **Halo rule.** A core point's label equals the one of a run over the whole cloud when the
//! neighbourhoods it reads lie in its tile: its largest-scale neighbourhood, its neighbours'
//! (one-face normals, thinning) and theirs: [`HALO_HOPS`] hops of the largest scale's radius
//! ([`halo_width`] sizes the halo from the spacing so). Two stages are not local and are
//! solved per tile, so their labels may differ from the whole run's near a tile's border and
//! along a surface cut by one: the Potts labelling (a minimum cut, only on clouds measured
//! noisy) and the surface stage (the tile's own segmentation); the Python tests measure the
//! agreement. Otsu's top as a quantile ([`crate::threshold::OtsuParams::upper_quantile`] < 1)
//! is refused: a quantile does not merge from tiles.

use std::borrow::Cow;

use crate::analysis::{AnalysisParams, CloudAnalysis};
pub use crate::estimate::noise::ratio_of_samples;
use crate::estimate::noise::{noise_samples, sample_stride, NOISE_K};
use crate::geometry::Point3;
use crate::threshold::{histogram, otsu_of_histogram};
use crate::{Error, Result};

use super::{
    analysis_params, apply_thresholds, check_scales, finish, measure_values, SharpParams,
    SharpResult, ThresholdRule, CLOUD_SCALES,
};

/// Hops of the largest scale's neighbourhood that a core point's label reads (its neighbours'
/// neighbourhoods for the one-face normals and the thinning, and theirs).
pub const HALO_HOPS: f64 = 3.0;

/// A tile: its points (core and halo) and which of them are in its core (the points whose
/// labels it gives).
#[derive(Debug, Clone, Copy)]
pub struct Tile<'a> {
    /// The points of the tile, core and halo.
    pub points: &'a [Point3],
    /// Per point: in the core.
    pub core: &'a [bool],
}

impl Tile<'_> {
    fn check(&self) -> Result<()> {
        if self.points.len() != self.core.len() {
            return Err(Error::InvalidArgument(format!(
                "tile: {} core flags for {} points",
                self.core.len(),
                self.points.len()
            )));
        }
        Ok(())
    }
}

/// The tile's analysis with neighbour lists of `k`, with an error that says to use larger tiles.
fn analysis(tile: &Tile<'_>, params: AnalysisParams) -> Result<CloudAnalysis> {
    tile.check()?;
    let need = params.max_k + 1;
    if tile.points.len() < need {
        return Err(Error::InvalidInput(format!(
            "a tile of {} points: its neighbourhoods need at least {need}; use larger tiles",
            tile.points.len()
        )));
    }
    CloudAnalysis::new(tile.points, params)
}

/// The width of the halo for a cloud of spacing `spacing` (mean distance to the nearest
/// neighbour) and the detector's settings: [`HALO_HOPS`] × the radius of the largest scale's
/// neighbourhood on a surface sampled at that spacing (√(k / π) spacings), doubled for uneven
/// sampling.
pub fn halo_width(spacing: f64, params: &SharpParams) -> f64 {
    let k = analysis_params(params).map_or(CLOUD_SCALES[CLOUD_SCALES.len() - 1], |a| a.max_k);
    2.0 * HALO_HOPS * spacing * (k as f64 / std::f64::consts::PI).sqrt()
}

/// Pass 1: the noise samples of the tile's core points, for a cloud of `total` input points.
pub fn tile_noise_samples(tile: &Tile<'_>, total: usize) -> Result<Vec<(f64, f64)>> {
    let a = analysis(
        tile,
        AnalysisParams {
            max_k: NOISE_K,
            ..Default::default()
        },
    )?;
    let order = a.order();
    Ok(noise_samples(
        a.points(),
        a.neighbours()?,
        sample_stride(total),
        |r| tile.core[order[r] as usize],
    ))
}

/// The result of pass 2 on one tile.
#[derive(Debug, Clone, PartialEq)]
pub struct TileMeasures {
    /// Per scale, the measure of every tile point (input order of the tile); NaN for the later
    /// copies of a repeated point, which a run over the whole cloud counts once.
    pub values: Vec<Vec<f64>>,
    /// Per scale, the smallest and largest value over the core points ((∞, −∞) without any).
    pub ranges: Vec<(f64, f64)>,
}

/// The scales of `params` (checked), and a refusal of what does not merge across tiles.
fn scales_of(params: &SharpParams) -> Result<Vec<usize>> {
    params.validate()?;
    if params.threshold == ThresholdRule::Otsu && params.otsu.upper_quantile < 1.0 {
        return Err(Error::InvalidArgument(
            "tiled sharp points: Otsu's histogram top as a quantile does not merge across tiles \
             (use an upper quantile of 1)"
                .into(),
        ));
    }
    if params.measure != super::Measure::ProjectedDistance
        && params.measure != super::Measure::SurfaceVariation
    {
        return Err(Error::InvalidArgument(format!(
            "tiled sharp points: the {} measure is not supported (projected distance and \
             surface variation are)",
            params.measure.name()
        )));
    }
    let scales = params
        .scales
        .clone()
        .unwrap_or_else(|| CLOUD_SCALES.to_vec());
    check_scales(&scales, "neighbourhood sizes")?;
    Ok(scales)
}

/// Pass 2: every scale's measure of the tile's points, given the cloud's noise ratio.
pub fn tile_measures(tile: &Tile<'_>, ratio: f64, params: &SharpParams) -> Result<TileMeasures> {
    let scales = scales_of(params)?;
    let a = analysis(tile, analysis_params(params)?)?;
    let rows = measure_values(a.points(), a.neighbours()?, ratio, params, &scales);
    let order = a.order();
    let first: Vec<bool> = a
        .rows()
        .iter()
        .enumerate()
        .map(|(i, &r)| order[r as usize] as usize == i)
        .collect();
    let values: Vec<Vec<f64>> = rows
        .iter()
        .map(|v| {
            let mut v = a.to_input_order(v);
            v.iter_mut()
                .zip(&first)
                .filter(|(_, &f)| !f)
                .for_each(|(x, _)| *x = f64::NAN);
            v
        })
        .collect();
    let ranges = values
        .iter()
        .map(|v| {
            v.iter()
                .zip(tile.core)
                .filter(|(x, &c)| c && !x.is_nan())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (&x, _)| {
                    (lo.min(x), hi.max(x))
                })
        })
        .collect();
    Ok(TileMeasures { values, ranges })
}

/// The ranges of all tiles merged (per scale, the smallest low and the largest high).
pub fn merge_ranges<'r>(ranges: impl IntoIterator<Item = &'r [(f64, f64)]>) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    for r in ranges {
        if out.is_empty() {
            out = vec![(f64::INFINITY, f64::NEG_INFINITY); r.len()];
        }
        for (o, x) in out.iter_mut().zip(r) {
            *o = (o.0.min(x.0), o.1.max(x.1));
        }
    }
    out
}

/// Pass 3: per scale, the histogram of the tile's core values over the merged `ranges`.
pub fn tile_histograms(
    tile: &Tile<'_>,
    values: &[Vec<f64>],
    ranges: &[(f64, f64)],
    params: &SharpParams,
) -> Result<Vec<Vec<u64>>> {
    tile.check()?;
    if values.len() != ranges.len() {
        return Err(Error::InvalidArgument(format!(
            "tile histograms: {} scales of values, {} ranges",
            values.len(),
            ranges.len()
        )));
    }
    Ok(values
        .iter()
        .zip(ranges)
        .map(|(v, &(lo, hi))| {
            let core: Vec<f64> = v
                .iter()
                .zip(tile.core)
                .filter(|(x, &c)| c && !x.is_nan())
                .map(|(&x, _)| x)
                .collect();
            histogram(&core, lo, hi, params.otsu.bins)
        })
        .collect())
}

/// Each scale's threshold (T_s, T_s normalised) from all tiles' histograms (each tile's list
/// per scale) and the merged ranges: Otsu's method on the summed histogram, or the manual
/// threshold times the largest value.
pub fn thresholds(
    histograms: &[Vec<Vec<u64>>],
    ranges: &[(f64, f64)],
    params: &SharpParams,
) -> Result<Vec<(f64, f64)>> {
    ranges
        .iter()
        .enumerate()
        .map(|(s, &(lo, hi))| {
            if !(lo.is_finite() && hi.is_finite()) {
                return Err(Error::InvalidInput(
                    "tiled sharp points: no tile has a core point".into(),
                ));
            }
            Ok(match params.threshold {
                ThresholdRule::Manual(tn) => (tn * hi.max(0.0), tn),
                ThresholdRule::Otsu => {
                    let mut sum = vec![0u64; params.otsu.bins];
                    for h in histograms {
                        let h = h.get(s).ok_or_else(|| {
                            Error::InvalidArgument("tile histograms: a scale is missing".into())
                        })?;
                        sum.iter_mut().zip(h).for_each(|(a, b)| *a += b);
                    }
                    let o = otsu_of_histogram(sum, lo, hi, hi);
                    (o.threshold, o.normalized)
                }
            })
        })
        .collect()
}

/// Pass 4: the labels of the tile's points (input order of the tile; the caller keeps the core
/// points') from its measures (pass 2), the cloud's thresholds (pass 3) and noise ratio (pass 1).
pub fn label_tile(
    tile: &Tile<'_>,
    values: &[Vec<f64>],
    thresholds: &[(f64, f64)],
    ratio: f64,
    params: &SharpParams,
) -> Result<SharpResult> {
    let scales = scales_of(params)?;
    if values.len() != scales.len() || thresholds.len() != scales.len() {
        return Err(Error::InvalidArgument(format!(
            "tile labels: {} scales, {} of values, {} thresholds",
            scales.len(),
            values.len(),
            thresholds.len()
        )));
    }
    if values.iter().any(|v| v.len() != tile.points.len()) {
        return Err(Error::InvalidArgument(
            "tile labels: values of another tile".into(),
        ));
    }
    let a = analysis(tile, analysis_params(params)?)?;
    // The values of the analysis' rows (the first copy of each point).
    let order = a.order();
    let rows: Vec<Vec<f64>> = values
        .iter()
        .map(|v| order.iter().map(|&i| v[i as usize]).collect())
        .collect();
    let r = apply_thresholds(&scales, &rows, thresholds);
    let mut r = finish(a.points(), a.neighbours()?, ratio, r, params, || {
        a.segmentation().map(Cow::Borrowed)
    })?;
    r.sharp = a.to_input_order(&r.sharp);
    r.sharpness = a.to_input_order(&r.sharpness);
    Ok(r)
}
