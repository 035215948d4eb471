//! Per-point sharpness measures at one scale: the projected distance (tran equation 3) and the
//! three measures tran compares it with (section 4.1.1): normal variation (equation 6, Hubeli and
//! Gross), mean curvature (Yang and Lee; quadric fit) and surface variation (equation 7, Pauly
//! et al.).
//!
//! A neighbourhood is the point itself and the entries of its row (`rows(i)`), the k nearest
//! neighbours of a cloud or the vertices of a mesh k-ring. Every measure is computed for all
//! points in parallel (rayon, per-thread scratch) and does not depend on the thread count.

use rayon::prelude::*;

use crate::estimate::curvature::fit_point;
use crate::estimate::normals::{smallest_eigen4, weighted_pca};
use crate::estimate::PcaWeight;
use crate::geometry::plane::Moments;
use crate::geometry::{vec3, Point3};

/// The per-point measure a detector thresholds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Measure {
    /// |(p − p̄)·n|, tran equation 3: the distance from the point to its neighbourhood's
    /// centroid along the normal.
    ProjectedDistance,
    /// The mean angle between the point's normal and its neighbours' normals, tran equation 6.
    NormalVariation,
    /// The absolute mean curvature |H| of a quadric fitted over the neighbourhood.
    MeanCurvature,
    /// λ0 / (λ0 + λ1 + λ2) of the neighbourhood's covariance, tran equation 7 (Pauly 2003).
    SurfaceVariation,
}

impl Measure {
    /// All measures, the default first.
    pub const ALL: [Measure; 4] = [
        Measure::ProjectedDistance,
        Measure::NormalVariation,
        Measure::MeanCurvature,
        Measure::SurfaceVariation,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Measure::ProjectedDistance => "projected-distance",
            Measure::NormalVariation => "normal-variation",
            Measure::MeanCurvature => "mean-curvature",
            Measure::SurfaceVariation => "surface-variation",
        }
    }

    /// True for the measures that are lengths or inverse lengths (they depend on the sampling
    /// density, see [`super::SharpParams::density_invariant`]).
    pub fn has_units(self) -> bool {
        matches!(self, Measure::ProjectedDistance | Measure::MeanCurvature)
    }
}

/// What one neighbourhood's weighted PCA gives: the normal, the eigenvalues, the projected
/// distance of the point and the RMS distance of the neighbourhood to its centroid.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalPca {
    pub normal: Point3,
    pub eigenvalues: [f64; 3],
    /// p − p̄ (the point relative to its neighbourhood's plain centroid).
    pub offset: Point3,
    /// √(mean ‖p_j − p̄‖²) over the neighbourhood (0 when all points coincide).
    pub rms_radius: f64,
}

/// Weighted PCA (tran equation 1) of `{p_i} ∪ rows(i)`; `scratch` (gathered coordinates, work
/// space) is reused between calls.
#[inline]
pub(crate) fn local_pca(
    points: &[Point3],
    i: usize,
    row: &[u32],
    weight: PcaWeight,
    scratch: &mut Scratch,
) -> LocalPca {
    let (coords, work) = scratch;
    coords.clear();
    coords.push(points[i]);
    coords.extend(row.iter().map(|&j| points[j as usize]));
    local_pca_coords(coords, weight, work)
}

/// Per-thread buffers of [`local_pca`]: gathered coordinates and work space.
pub(crate) type Scratch = (Vec<Point3>, Vec<Point3>);

/// Weighted PCA of `coords` (`coords[0]` the point, then its neighbours), with the two-sheet
/// test of [`own_sheet`] (whose tau selects the point's own sheet); `work` is scratch.
#[inline]
pub(crate) fn local_pca_coords(
    coords: &[Point3],
    weight: PcaWeight,
    work: &mut Vec<Point3>,
) -> LocalPca {
    let p = coords[0];
    let (mut normal, mut eigenvalues) = weighted_pca(p, &coords[1..], weight);
    let mut filtered = false;
    if let Some(tau) = own_sheet(coords, normal) {
        // Keep the neighbours within tau of the point's offset along the normal.
        work.clear();
        work.push(p);
        work.extend(
            coords[1..]
                .iter()
                .filter(|q| vec3::dot(vec3::sub(**q, p), normal).abs() <= tau),
        );
        (normal, eigenvalues) = weighted_pca(p, &work[1..], weight);
        filtered = true;
    }
    let used: &[Point3] = if filtered { work } else { coords };
    // Plain centroid and RMS radius, from sums relative to p.
    let m = used.len() as f64;
    let (mut s1, mut s2) = ([0.0f64; 3], 0.0f64);
    for q in used {
        let d = vec3::sub(*q, p);
        s1 = vec3::add(s1, d);
        s2 += vec3::dot(d, d);
    }
    let c = vec3::scale(s1, 1.0 / m);
    let offset = vec3::scale(c, -1.0);
    let rms_radius = (s2 / m - vec3::dot(c, c)).max(0.0).sqrt();
    LocalPca {
        normal,
        eigenvalues,
        offset,
        rms_radius,
    }
}

/// The projected distance or surface variation of one point at every scale at once:
/// `coords[0]` is the point and `coords[1..]` its neighbours nearest first; `out[s]` receives
/// the value over `coords[..ends[s]]` (the point and its neighbours at scale s: the `scales[s]`
/// nearest, or those of them that [`super::face`] keeps). `ends` must not decrease.
#[inline]
pub(crate) fn pca_measure_scales(
    coords: &[Point3],
    ends: &[usize],
    measure: Measure,
    weight: PcaWeight,
    density_invariant: bool,
    work: &mut Vec<Point3>,
    out: &mut [f64],
) {
    if weight != PcaWeight::Uniform {
        for (o, &m) in out.iter_mut().zip(ends) {
            let l = local_pca_coords(&coords[..m.min(coords.len())], weight, work);
            *o = pca_value(&l, None, measure, density_invariant);
        }
        return;
    }
    // Uniform weights: the nested neighbourhoods' moments are prefix sums, so every scale costs
    // one 3 x 3 eigenproblem. Moments are taken about the point itself for precision. The
    // eigenproblems of four scales are solved together ([`smallest_eigen4`], bitwise the scalar
    // solve): one at a time, their latency-bound chains were about a third of the detection.
    let p = coords[0];
    let mut mo = Moments::origin();
    let mut next = 1usize;
    for (outs, ends) in out.chunks_mut(4).zip(ends.chunks(4)) {
        let mut fits = [(0usize, [0.0; 3], [0.0; 6]); 4];
        for (fit, &m) in fits.iter_mut().zip(ends) {
            let m = m.min(coords.len());
            if m < next {
                // Scales given in decreasing order: start the sums again.
                (mo, next) = (Moments::origin(), 1);
            }
            while next < m {
                mo.add(vec3::sub(coords[next], p));
                next += 1;
            }
            let (c, cov) = mo.centroid_covariance();
            *fit = (m, c, cov);
        }
        let solved = smallest_eigen4(fits.map(|f| f.2));
        for ((o, &(m, c, cov)), (normal, eigenvalues)) in outs.iter_mut().zip(&fits).zip(solved) {
            let rms_radius = (cov[0] + cov[3] + cov[5]).max(0.0).sqrt();
            let offset = vec3::scale(c, -1.0);
            let l = if own_sheet(&coords[..m], normal).is_some() {
                local_pca_coords(&coords[..m], weight, work)
            } else {
                LocalPca {
                    normal,
                    eigenvalues,
                    offset,
                    rms_radius,
                }
            };
            *o = pca_value(&l, None, measure, density_invariant);
        }
    }
}

/// The projected distance (with `fixed_normal` instead of the PCA normal if given) or the
/// surface variation of one neighbourhood.
#[inline]
fn pca_value(
    l: &LocalPca,
    fixed_normal: Option<Point3>,
    measure: Measure,
    density_invariant: bool,
) -> f64 {
    match measure {
        Measure::SurfaceVariation => {
            let e = l.eigenvalues;
            let s = e[0] + e[1] + e[2];
            if s > 0.0 {
                e[0].max(0.0) / s
            } else {
                0.0
            }
        }
        _ => {
            let nrm = fixed_normal.unwrap_or(l.normal);
            let d = vec3::dot(l.offset, nrm).abs();
            if density_invariant {
                if l.rms_radius > 0.0 {
                    d / l.rms_radius
                } else {
                    0.0
                }
            } else {
                d
            }
        }
    }
}

/// Detects a neighbourhood made of two parallel sheets (the two faces of a plate thinner than
/// the neighbourhood) and returns tau: the neighbours whose offset |(q − p)·n| along the normal is at most tau lie on
/// the point's own sheet.
///
/// `centred[0]` is the point and `centred[1..]` its neighbours (any common origin: only
/// differences are used);
/// `normal` is their PCA normal. The offsets h_j = (p_j − p)·n split at half their largest
/// magnitude; the far group is another sheet when it lies on one side, is flat and parallel
/// (its offsets span less than half their mean), and the near group is flat too (offsets below a
/// quarter of the far group's). Along a sharp edge the far face's offsets ramp from 0 to their
/// maximum, so it fails the flatness test and the edge keeps its neighbours.
fn own_sheet(centred: &[Point3], normal: Point3) -> Option<f64> {
    let p = *centred.first()?;
    two_sheets(
        centred[1..]
            .iter()
            .map(|q| vec3::dot(vec3::sub(*q, p), normal)),
    )
}

/// The test of [`own_sheet`] on the offsets h_j = (p_j − p)·n of the neighbours.
fn two_sheets(h: impl Iterator<Item = f64> + Clone) -> Option<f64> {
    let max = h.clone().fold(0.0f64, |m, v| m.max(v.abs()));
    if max <= 0.0 {
        return None;
    }
    let tau = 0.5 * max;
    let (mut lo, mut hi, mut sum, mut far, mut pos, mut near_max) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        0.0,
        0usize,
        0usize,
        0.0f64,
    );
    let mut count = 0usize;
    for v in h {
        count += 1;
        if v.abs() > tau {
            lo = lo.min(v);
            hi = hi.max(v);
            sum += v.abs();
            far += 1;
            pos += usize::from(v > 0.0);
        } else {
            near_max = near_max.max(v.abs());
        }
    }
    let near = count - far;
    if far < 3 || near < 4 || (pos != 0 && pos != far) {
        return None;
    }
    let mean = sum / far as f64;
    if hi - lo > 0.5 * mean || near_max > 0.25 * mean {
        return None;
    }
    Some(tau)
}

/// The measure of every point at one scale.
///
/// * `rows(i)`: the neighbours of point i at this scale (the point itself excluded).
/// * `fixed_normals`: normals to use instead of the neighbourhood's PCA normal (meshes: the
///   Gouraud vertex normals of tran section 2.2); `None` for clouds (PCA at this scale).
/// * `density_invariant`: divide lengths by the neighbourhood's RMS radius (projected distance)
///   or multiply inverse lengths by it (mean curvature), see [`super::SharpParams`].
///
/// Points whose measure cannot be computed (a quadric fit over fewer than 5 neighbours or
/// collinear ones) get 0: nothing supports calling them sharp.
pub(crate) fn measure_at_scale<'a, R>(
    points: &'a [Point3],
    rows: R,
    fixed_normals: Option<&[Point3]>,
    measure: Measure,
    weight: PcaWeight,
    density_invariant: bool,
) -> Vec<f64>
where
    R: Fn(usize) -> &'a [u32] + Sync,
{
    let n = points.len();
    match measure {
        Measure::ProjectedDistance | Measure::SurfaceVariation => (0..n)
            .into_par_iter()
            .with_min_len(256)
            .map_init(Scratch::default, |scratch, i| {
                let l = local_pca(points, i, rows(i), weight, scratch);
                pca_value(&l, fixed_normals.map(|f| f[i]), measure, density_invariant)
            })
            .collect(),
        Measure::NormalVariation => {
            let computed;
            let normals: &[Point3] = match fixed_normals {
                Some(f) => f,
                None => {
                    computed = (0..n)
                        .into_par_iter()
                        .with_min_len(256)
                        .map_init(Scratch::default, |scratch, i| {
                            local_pca(points, i, rows(i), weight, scratch).normal
                        })
                        .collect::<Vec<_>>();
                    &computed
                }
            };
            (0..n)
                .into_par_iter()
                .with_min_len(256)
                .map(|i| {
                    let row = rows(i);
                    if row.is_empty() {
                        return 0.0;
                    }
                    let ni = normals[i];
                    let sum: f64 = row
                        .iter()
                        .map(|&j| {
                            // Unoriented normals: the angle between the lines, in [0, π/2].
                            vec3::dot(ni, normals[j as usize]).abs().min(1.0).acos()
                        })
                        .sum();
                    sum / row.len() as f64
                })
                .collect()
        }
        Measure::MeanCurvature => (0..n)
            .into_par_iter()
            .with_min_len(256)
            .map(|i| {
                let row = rows(i);
                let c = fit_point(points, i, row);
                let h = 0.5 * (c.k1 + c.k2);
                if !h.is_finite() {
                    return 0.0;
                }
                let h = h.abs();
                if density_invariant {
                    let p = points[i];
                    let r2 = row
                        .iter()
                        .map(|&j| vec3::dist2(points[j as usize], p))
                        .sum::<f64>()
                        / row.len().max(1) as f64;
                    h * r2.sqrt()
                } else {
                    h
                }
            })
            .collect(),
    }
}
