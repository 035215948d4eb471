//! The noise level of a cloud, measured from the data, which decides whether the sharp-point
//! detector's per-point decisions are regularised (see
//! [`crate::sharp::SharpParams::auto_regularize`]).
//!
//! Tran et al. note that their method "depends on the level of noise of the captured data"
//! (section 4.5) and that 4–5 % noise already contaminates the result (section 4.4), but give no
//! way to tell how noisy a cloud is. The measure here: for every point the RMS distance √λ0 of
//! the point and its 6 nearest neighbours to their least-squares plane (tran equation 1 with
//! uniform weights over a very small neighbourhood), divided by the average spacing, and the
//! **lower decile** of that value over the cloud.
//!
//! Why these choices (measured on the PCEDNet ABC models, 8 clean and 8 noisy, and the synthetic
//! parts; figures in `docs/experiments/sharp-noise.md`):
//! * seven points span about one spacing, where a CAD surface is flat to far below the spacing
//!   (curvature radii of many spacings), so on a clean cloud the residual comes from the few
//!   neighbourhoods on edges and on the two faces of thin plates;
//! * the median is not robust enough: on the clean models made of thin plates it is as large
//!   as on the noisy clouds, because most neighbourhoods hold points of both faces;
//! * the lower decile at 6 neighbours separates the clean models from the noisy ones by more
//!   than two orders of magnitude, so [`NOISY_RATIO`] is set between the noisiest synthetic
//!   parts the tests use and the least noisy PCEDNet cloud, not tuned on the scores.
//!
//! At most about [`SAMPLES`] points (one in n/SAMPLES, chosen by a hash of the coordinates) are
//! measured, so the cost is bounded; the result depends neither on the thread count nor on the
//! order of the points, and a cloud cut into tiles gives the same (`crate::sharp::tiled`).

use rayon::prelude::*;

use crate::estimate::normals::smallest_eigen;
use crate::geometry::plane::Moments;
use crate::geometry::{vec3, Point3};
use crate::spatial::Neighborhoods;

/// Neighbours per local plane of the noise measure.
pub const NOISE_K: usize = 6;
/// The quantile of the per-point residuals that is reported.
pub const NOISE_QUANTILE: f64 = 0.1;
/// Most points measured (evenly strided over the input order).
pub const SAMPLES: usize = 100_000;
/// The default noise ratio above which a cloud is treated as noisy: 0.08 sits at half the
/// least noisy PCEDNet cloud and twice the synthetic parts at 5 % noise (the most the tests and
/// tran section 4.4 use); the ratios measured are in `docs/experiments/sharp-noise.md`.
pub const NOISY_RATIO: f64 = 0.08;

/// The lower decile over the points of √λ0 / spacing, with λ0 the smallest eigenvalue of the
/// covariance of the point and its [`NOISE_K`] nearest neighbours and the spacing the mean
/// distance of the points to their nearest neighbour (see the module documentation).
///
/// `nbrs` must hold at least 3 neighbours per point (fewer of them are used when it holds fewer
/// than [`NOISE_K`]). Returns 0 for an empty cloud or one whose points all coincide.
pub fn noise_ratio(points: &[Point3], nbrs: &Neighborhoods) -> f64 {
    let mut samples = noise_samples(points, nbrs, sample_stride(points.len()), |_| true);
    ratio_of_samples(&mut samples)
}

/// The stride of the sample measured in a cloud of `n` points: at most about [`SAMPLES`] points.
pub fn sample_stride(n: usize) -> usize {
    n.div_ceil(SAMPLES).max(1)
}

/// Whether the point at `p` is one of the measured ones at `stride`: about one in `stride`
/// points, chosen by a hash of its coordinates, so that the sample does not depend on the order
/// of the points nor on how the cloud is cut into tiles ([`crate::sharp::tiled`]).
fn sampled(p: Point3, stride: usize) -> bool {
    if stride <= 1 {
        return true;
    }
    // SplitMix64's finaliser over the three coordinates' bits.
    let mut h = 0x9E37_79B9_7F4A_7C15u64;
    for c in p {
        h ^= c.to_bits();
        h = (h ^ (h >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        h ^= h >> 31;
    }
    h.is_multiple_of(stride as u64)
}

/// The measured pairs (√λ0, distance to the nearest neighbour) of the sampled points among those
/// for which `keep(i)` holds (a tile's core points); [`ratio_of_samples`] turns the samples of a
/// whole cloud, in any order, into its ratio.
pub fn noise_samples(
    points: &[Point3],
    nbrs: &Neighborhoods,
    stride: usize,
    keep: impl Fn(usize) -> bool + Sync,
) -> Vec<(f64, f64)> {
    let n = points.len().min(nbrs.len());
    let k = nbrs.k().min(NOISE_K);
    if n == 0 || k < 3 {
        return Vec::new();
    }
    (0..n)
        .into_par_iter()
        .with_min_len(256)
        .filter(|&i| keep(i) && sampled(points[i], stride))
        .map(|i| {
            let p = points[i];
            let row = nbrs.prefix(i, k);
            let nn = row
                .first()
                .map_or(0.0, |&j| vec3::dist(p, points[j as usize]));
            // The point itself is the origin of the moments (one of the row.len() + 1 points).
            let mut mo = Moments::origin();
            for &j in row {
                mo.add(vec3::sub(points[j as usize], p));
            }
            let (_, cov) = mo.centroid_covariance();
            let (_, eig) = smallest_eigen(cov);
            let r = eig[0].max(0.0).sqrt();
            (if r.is_finite() { r } else { 0.0 }, nn)
        })
        .collect()
}

/// The noise ratio of a cloud from its samples ([`noise_samples`]), whatever their order (they
/// are sorted here, so the sum of the spacings is the same for any order).
pub fn ratio_of_samples(samples: &mut [(f64, f64)]) -> f64 {
    if samples.is_empty() {
        return 0.0;
    }
    samples.sort_unstable_by(|a, b| a.1.total_cmp(&b.1).then(a.0.total_cmp(&b.0)));
    let spacing = samples.iter().map(|s| s.1).sum::<f64>() / samples.len() as f64;
    if !(spacing > 0.0 && spacing.is_finite()) {
        return 0.0;
    }
    let mut res: Vec<f64> = samples.iter().map(|s| s.0).collect();
    let q = ((res.len() - 1) as f64 * NOISE_QUANTILE).round() as usize;
    let (_, v, _) = res.select_nth_unstable_by(q, f64::total_cmp);
    *v / spacing
}

/// Neighbours of the local surface of [`noise_sigma`]: with 16, a plane's estimate of noise of a
/// whole spacing came out 35 % low (the nearest neighbours in 3D favour points on the point's
/// own side of the surface); with 64, 10 % low.
pub const SIGMA_K: usize = 64;
/// Most points measured by [`noise_sigma`] (chosen by a hash of their coordinates).
pub const SIGMA_SAMPLES: usize = 20_000;

/// The noise of a cloud as a length: the standard deviation of the points across the surface,
/// what `crease synth --noise` adds (along the normal; of isotropic noise, its component along
/// the normal). For about [`SIGMA_SAMPLES`] points, the height of the point above the quadric
/// `h = a x² + b xy + c y² + d x + e y + f` fitted by least squares to its [`SIGMA_K`]
/// nearest neighbours (itself left out) in the frame of their plane, divided by
/// √(1 + ℓ) with ℓ the fit's leverage at the point (its own error); the median of those
/// heights over 0.6745 (the median of |x| for a unit Gaussian) is σ. The quadric takes the
/// surface's curvature out (a plane read 0.07 spacings of noise on the clean two cylinders);
/// the median leaves out the neighbourhoods across edges. Measured on the synthetic parts (test
/// `noise::the_noise_of_synthetic_parts_is_measured`, 100k points): 0 on clean parts, 6–7 %
/// high at half a spacing of noise, 12–13 % high at a whole spacing. `None` for fewer than 7
/// distinct points.
pub fn noise_sigma(points: &[Point3]) -> Option<f64> {
    let index = crate::spatial::KdIndex::new(points)?;
    let stride = points.len().div_ceil(SIGMA_SAMPLES).max(1);
    let mut r: Vec<f64> = (0..points.len())
        .into_par_iter()
        .with_min_len(64)
        .filter(|&i| sampled(points[i], stride))
        .filter_map(|i| {
            let p = points[i];
            // Leave the point itself (and its exact copies) out of its surface.
            let near: Vec<Point3> = index
                .nearest(&p, SIGMA_K + 1)
                .into_iter()
                .filter(|&(_, d2)| d2 > 0.0)
                .map(|(j, _)| vec3::sub(points[j as usize], p))
                .collect();
            quadric_height(&near)
        })
        .collect();
    if r.is_empty() {
        return None;
    }
    let mid = r.len() / 2;
    let (_, median, _) = r.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*median / 0.6745)
}

/// |f| / √(1 + ℓ) of the quadric fitted to `near` (offsets from the point) in the frame of
/// their plane (see [`noise_sigma`]); `None` where the fit is singular.
fn quadric_height(near: &[Point3]) -> Option<f64> {
    use nalgebra::{Matrix6, Vector6};
    if near.len() < 7 {
        return None;
    }
    let mut mo = Moments::without_origin();
    for &d in near {
        mo.add(d);
    }
    let (_, cov) = mo.centroid_covariance();
    let (n, _) = smallest_eigen(cov);
    let u = vec3::normalize(vec3::cross(
        n,
        if n[0].abs() < 0.9 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 1.0, 0.0]
        },
    ))?;
    let v = vec3::cross(n, u);
    // Scale the frame by the neighbourhood's radius so the normal equations are well scaled.
    let radius = near.iter().map(|&d| vec3::norm(d)).fold(0.0, f64::max);
    if !(radius > 0.0 && radius.is_finite()) {
        return None;
    }
    let (mut ata, mut atb) = (Matrix6::<f64>::zeros(), Vector6::<f64>::zeros());
    for &d in near {
        let (x, y, h) = (
            vec3::dot(d, u) / radius,
            vec3::dot(d, v) / radius,
            vec3::dot(d, n),
        );
        let row = Vector6::new(x * x, x * y, y * y, x, y, 1.0);
        ata += row * row.transpose();
        atb += row * h;
    }
    let chol = ata.cholesky()?;
    let coef = chol.solve(&atb);
    let leverage = chol.inverse()[(5, 5)];
    let h = coef[5].abs() / (1.0 + leverage).sqrt();
    h.is_finite().then_some(h)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spatial::knn;

    /// A jittered grid on a plane: 0 without noise, about the noise's σ with it.
    #[test]
    fn flat_grid_with_and_without_noise() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let grid = |sigma: f64, rng: &mut rand_pcg::Pcg64| -> Vec<Point3> {
            (0..2500)
                .map(|i| {
                    let z: f64 = (0..12).map(|_| rng.random::<f64>()).sum::<f64>() - 6.0;
                    [(i % 50) as f64, (i / 50) as f64, sigma * z]
                })
                .collect()
        };
        let clean = grid(0.0, &mut rng);
        let nb = knn(&clean, 8).unwrap();
        assert_eq!(noise_ratio(&clean, &nb), 0.0);
        let noisy = grid(0.5, &mut rng);
        let nb = knn(&noisy, 8).unwrap();
        let r = noise_ratio(&noisy, &nb);
        assert!(r > NOISY_RATIO && r < 0.5, "{r}");
    }
}
