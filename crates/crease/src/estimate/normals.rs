//! Normals: weighted PCA over k-nearest-neighbour neighbourhoods (tran equation 1) and mesh vertex
//! normals (uniform / Gouraud as tran section 2.2 uses, area- and angle-weighted).
//!
//! **Weighted PCA (tran et al., section 2.1, equation 1).** For point p_i with neighbourhood
//! N(i), p̄_i = (1/|N(i)|) Σ p_j is the plain centroid and
//!
//! ```text
//! CV_i = Σ_{j ∈ N(i)} μ_j (p_j − p̄_i)ᵀ (p_j − p̄_i),   μ_j = exp(−d_j² / σ²),  d_j = ‖p_j − p̄_i‖
//! ```
//!
//! The normal n_i is the eigenvector of the smallest eigenvalue of CV_i. Choices made where the
//! paper is open or scale-dependent:
//!
//! * N(i) is p_i itself plus its k nearest other points (the [`Neighborhoods`] rows exclude the
//!   point itself), i.e. k + 1 points; the paper says "the k points in the neighbourhood around
//!   p_i" without saying whether p_i is one of them.
//! * The paper writes σ = k, the neighbour *count*, which is not scale invariant: for a part a
//!   few units across, exp(−d²/400) ≈ 1 and equation 1 is plain PCA, while in micrometres it
//!   would zero every weight. The default [`PcaWeight::GaussianRelative`]`(2.0)` uses σ = 2 × the
//!   root-mean-square of the d_j of the neighbourhood (scale invariant): on noisy synthetic
//!   spheres, planes and cylinders (tests/it/normals.rs) it costs hardly any accuracy against
//!   plain PCA, where σ = 1 × the mean distance narrows the neighbourhood too much
//!   (`docs/experiments/knn-and-normals.md`).
//!   [`PcaWeight::GaussianFixed`]`(k as f64)` reproduces the paper literally and [`PcaWeight::Uniform`] is classical PCA (Hoppe 1992).
//!
//! The 3×3 symmetric eigenproblem is solved in closed form (trigonometric eigenvalues of the
//! scaled, shifted matrix, then the eigenvector of the smallest eigenvalue from the largest cross
//! product of two rows of CV − λ₀I), which is several times faster than nalgebra's iterative
//! `SymmetricEigen` (see the `normals` benchmark) and agrees with it to ~1e-12 on well-separated
//! eigenvalues (tested). [`pca_normals`] processes given neighbourhoods in input order in
//! parallel; [`pca_normals_direct`] fuses the kNN search and the fit ([`knn_map_set_unzip`] visits
//! the neighbourhoods in Morton order while they are in cache, no n·k lists), with the same
//! result up to rounding (the same neighbours, summed in another order); each is identical
//! whatever the thread count.
//!
//! Timed against PCL and Open3D by `scripts/compare-normals.sh` (figures in
//! `docs/benchmarks.md` and `docs/experiments/knn-and-normals.md`).
//! The covariances are computed in the query loop and parked in the output slots, then solved
//! four at a time ([`smallest_eigen4`]): the scalar solve is a latency-bound chain of square
//! roots and divisions.

use rayon::prelude::*;
use wide::bytemuck::cast;
use wide::{f64x4, u64x4};

use crate::geometry::{vec3, Point3, TriMesh};
use crate::spatial::knn::knn_map_set_unzip;
use crate::spatial::Neighborhoods;
use crate::{Error, Result};

/// The weights μ_j of equation 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PcaWeight {
    /// μ_j = 1: classical PCA (Hoppe 1992).
    Uniform,
    /// μ_j = exp(−d_j²/σ²) with σ = the given factor × the root-mean-square distance of the
    /// neighbourhood's points to their centroid (scale invariant).
    GaussianRelative(f64),
    /// μ_j = exp(−d_j²/σ²) with a fixed σ in model units. `GaussianFixed(k as f64)` is tran's
    /// equation 1 taken literally (σ = the neighbour count).
    GaussianFixed(f64),
}

/// Parameters of [`pca_normals`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PcaParams {
    /// Number of nearest neighbours used (a prefix of each [`Neighborhoods`] row, so one kNN
    /// query at the largest k serves every scale). Default 20.
    pub k: usize,
    /// The weights (default [`PcaWeight::GaussianRelative`]`(2.0)`).
    pub weight: PcaWeight,
}

impl Default for PcaParams {
    fn default() -> Self {
        PcaParams {
            k: 20,
            weight: PcaWeight::GaussianRelative(2.0),
        }
    }
}

/// Normals and covariance eigenvalues of every point.
#[derive(Debug, Clone, PartialEq)]
pub struct PcaResult {
    /// Unit normals (sign arbitrary: see [`crate::estimate::orient_normals`]), in input order.
    /// A neighbourhood of coincident points gets `[0, 0, 1]` with zero eigenvalues; a collinear
    /// one gets a unit vector perpendicular to its line.
    pub normals: Vec<Point3>,
    /// Eigenvalues λ0 ≤ λ1 ≤ λ2 of CV_i / Σ μ_j (the weighted variance along the normal and the
    /// two tangent axes), for the surface variation λ0 / (λ0 + λ1 + λ2) of Pauly et al.
    pub eigenvalues: Vec<[f64; 3]>,
}

impl PcaResult {
    /// Surface variation λ0 / (λ0 + λ1 + λ2) of point `i` (Pauly 2003), 0 for a degenerate
    /// neighbourhood; `None` if `i` is out of range.
    pub fn surface_variation(&self, i: usize) -> Option<f64> {
        let e = self.eigenvalues.get(i)?;
        let s = e[0] + e[1] + e[2];
        Some(if s > 0.0 { e[0] / s } else { 0.0 })
    }
}

/// Weighted-PCA normals (tran equation 1) of every point from precomputed neighbourhoods.
///
/// Errors if `params.k` is 0 or larger than `nbrs.k()`, if `nbrs` was built for another number of points, or if a
/// neighbour index is out of range.
pub fn pca_normals(
    points: &[Point3],
    nbrs: &Neighborhoods,
    params: &PcaParams,
) -> Result<PcaResult> {
    if params.k == 0 {
        return Err(Error::InvalidArgument("PCA normals with k = 0".into()));
    }
    check_weight(params.weight)?;
    if params.k > nbrs.k() {
        return Err(Error::InvalidArgument(format!(
            "PCA normals with k = {} from neighbourhoods of only {} neighbours",
            params.k,
            nbrs.k()
        )));
    }
    if nbrs.len() != points.len() {
        return Err(Error::InvalidArgument(format!(
            "PCA normals: {} neighbourhoods for {} points",
            nbrs.len(),
            points.len()
        )));
    }
    let n = points.len();
    if nbrs.csr().indices.iter().any(|&j| j as usize >= n) {
        return Err(Error::InvalidArgument(format!(
            "PCA normals: a neighbour index is out of range for {n} points"
        )));
    }
    let k = params.k;
    let weight = params.weight;
    let (normals, eigenvalues): (Vec<Point3>, Vec<[f64; 3]>) = (0..n)
        .into_par_iter()
        .map_init(
            || Vec::with_capacity(k),
            |scratch: &mut Vec<Point3>, i| {
                scratch.clear();
                scratch.extend(nbrs.prefix(i, k).iter().map(|&j| points[j as usize]));
                weighted_pca(points[i], scratch, weight)
            },
        )
        .unzip();
    Ok(PcaResult {
        normals,
        eigenvalues,
    })
}

/// Weighted-PCA normals (tran equation 1) of every point over its `params.k` nearest neighbours,
/// searched on the fly: the same result as [`knn`](crate::spatial::knn()) followed by
/// [`pca_normals`] up to rounding, without storing the neighbour lists (the neighbourhoods are
/// visited in spatial order by [`crate::spatial::knn::knn_map_set`], which is also several
/// times more cache friendly than [`pca_normals`]' input-order traversal, and hands over the
/// neighbour set unranked: the fit does not need the order).
///
/// Errors as [`knn`](crate::spatial::knn()) (k = 0, fewer than k + 1 points, a non-finite coordinate) and on a Gaussian
/// sigma that is not positive and finite.
pub fn pca_normals_direct(points: &[Point3], params: &PcaParams) -> Result<PcaResult> {
    check_weight(params.weight)?;
    let k = params.k;
    let weight = params.weight;
    // The covariance of each point first, its six entries parked in the point's normal and
    // eigenvalue slots; then the eigen-decompositions four at a time, in place.
    let (mut normals, mut eigenvalues) = knn_map_set_unzip(
        points,
        k,
        || (),
        |_, q| {
            let [a, b, c, d, e, f] = weighted_covariance(q.point, q.neighbors, weight);
            ([a, b, c], [d, e, f])
        },
    )?;
    normals
        .par_chunks_mut(4)
        .zip(eigenvalues.par_chunks_mut(4))
        .with_min_len(1024)
        .for_each(|(nc, ec)| {
            let mut covs = [[0.0; 6]; 4];
            for (cov, (n, e)) in covs.iter_mut().zip(nc.iter().zip(ec.iter())) {
                *cov = [n[0], n[1], n[2], e[0], e[1], e[2]];
            }
            let solved = smallest_eigen4(covs);
            for ((n, e), (sn, se)) in nc.iter_mut().zip(ec.iter_mut()).zip(solved) {
                (*n, *e) = (sn, se);
            }
        });
    Ok(PcaResult {
        normals,
        eigenvalues,
    })
}

/// Errors on a Gaussian sigma that is not positive and finite.
fn check_weight(weight: PcaWeight) -> Result<()> {
    if let PcaWeight::GaussianFixed(s) | PcaWeight::GaussianRelative(s) = weight {
        if !(s.is_finite() && s > 0.0) {
            return Err(Error::InvalidArgument(format!(
                "PCA normals: Gaussian sigma must be positive and finite, got {s}"
            )));
        }
    }
    Ok(())
}

/// Convenience: PCA normals over the k nearest neighbours with default weights
/// ([`pca_normals_direct`]). Errors as [`knn`](crate::spatial::knn()) (k = 0, fewer than k + 1 points).
pub fn estimate_normals(points: &[Point3], k: usize) -> Result<Vec<Point3>> {
    Ok(pca_normals_direct(
        points,
        &PcaParams {
            k,
            ..Default::default()
        },
    )?
    .normals)
}

/// Equation 1 on one neighbourhood, the point `p` and its neighbours `nbrs`: (unit normal,
/// eigenvalues ascending normalised by Σμ).
///
/// Two passes: the centroid and the mean squared distance to it from sums taken relative to `p`
/// (small numbers, no cancellation to speak of), then the weights and the covariance. Both
/// passes run four points at a time (SIMD lanes over p and its neighbours, the last group
/// padded with zero-weight lanes): about as many instructions as the scalar loop, but short
/// dependency chains, hence faster (`docs/experiments/knn-and-normals.md`).
#[inline]
pub(crate) fn weighted_pca(p: Point3, nbrs: &[Point3], weight: PcaWeight) -> (Point3, [f64; 3]) {
    smallest_eigen(weighted_covariance(p, nbrs, weight))
}

/// The weighted covariance `[xx, xy, xz, yy, yz, zz]` of equation 1 whose eigen-decomposition
/// [`weighted_pca`] returns.
#[inline]
fn weighted_covariance(p: Point3, nbrs: &[Point3], weight: PcaWeight) -> [f64; 6] {
    let m = (nbrs.len() + 1) as f64;
    let groups = (nbrs.len() + 1).div_ceil(4);
    // Lane i of group g is point 4g + i of [p, nbrs...], relative to p; padding lanes repeat p
    // (zero). Group 0 is [p, n0, n1, n2], then whole chunks of four neighbours: no per-lane
    // branches.
    let (px, py, pz) = (f64x4::splat(p[0]), f64x4::splat(p[1]), f64x4::splat(p[2]));
    let four = |a: [&Point3; 4]| -> (f64x4, f64x4, f64x4) {
        (
            f64x4::new([a[0][0], a[1][0], a[2][0], a[3][0]]) - px,
            f64x4::new([a[0][1], a[1][1], a[2][1], a[3][1]]) - py,
            f64x4::new([a[0][2], a[1][2], a[2][2], a[3][2]]) - pz,
        )
    };
    let at = |j: usize| nbrs.get(j).unwrap_or(&p);
    let tail = nbrs.get(3..).unwrap_or(&[]);
    let lanes = |g: usize| -> (f64x4, f64x4, f64x4) {
        if g == 0 {
            return four([&p, at(0), at(1), at(2)]);
        }
        match tail.get(4 * (g - 1)..4 * g) {
            Some([a, b, c, d]) => four([a, b, c, d]),
            _ => {
                let j = 3 + 4 * (g - 1);
                four([at(j), at(j + 1), at(j + 2), at(j + 3)])
            }
        }
    };
    let (mut sx, mut sy, mut sz, mut s2) = (f64x4::ZERO, f64x4::ZERO, f64x4::ZERO, f64x4::ZERO);
    for g in 0..groups {
        let (x, y, z) = lanes(g);
        sx += x;
        sy += y;
        sz += z;
        s2 += x * x + y * y + z * z;
    }
    // Centroid relative to p, and Σ|q − c|² = Σ|q − p|² − m |c − p|².
    let c = [
        sx.reduce_add() / m,
        sy.reduce_add() / m,
        sz.reduce_add() / m,
    ];
    let sum_d2 = (s2.reduce_add() - m * vec3::dot(c, c)).max(0.0);
    let inv_s2 = match weight {
        PcaWeight::Uniform => 0.0,
        PcaWeight::GaussianFixed(s) => 1.0 / (s * s),
        PcaWeight::GaussianRelative(f) => {
            let s2 = f * f * sum_d2 / m;
            if s2 > 0.0 {
                1.0 / s2
            } else {
                0.0
            }
        }
    };
    let (cx, cy, cz) = (f64x4::splat(c[0]), f64x4::splat(c[1]), f64x4::splat(c[2]));
    let neg_inv_s2 = f64x4::splat(-inv_s2);
    let total = nbrs.len() + 1;
    let mut a = [f64x4::ZERO; 6]; // xx xy xz yy yz zz
    let mut wsum = f64x4::ZERO;
    for g in 0..groups {
        let (x, y, z) = lanes(g);
        let (dx, dy, dz) = (x - cx, y - cy, z - cz);
        let w = if inv_s2 > 0.0 {
            exp_neg4((dx * dx + dy * dy + dz * dz) * neg_inv_s2)
        } else {
            f64x4::ONE
        };
        // Padding lanes (past the last point) weigh nothing.
        let w = if 4 * g + 4 > total {
            let mut keep = [0.0; 4];
            for (i, k) in keep.iter_mut().enumerate() {
                *k = if 4 * g + i < total { 1.0 } else { 0.0 };
            }
            w * f64x4::new(keep)
        } else {
            w
        };
        wsum += w;
        let (wx, wy, wz) = (w * dx, w * dy, w * dz);
        a[0] += wx * dx;
        a[1] += wx * dy;
        a[2] += wx * dz;
        a[3] += wy * dy;
        a[4] += wy * dz;
        a[5] += wz * dz;
    }
    let wsum = wsum.reduce_add();
    let mut cov = a.map(f64x4::reduce_add);
    if wsum > 0.0 {
        let inv = 1.0 / wsum;
        for v in &mut cov {
            *v *= inv;
        }
    }
    cov
}

/// e^x for x ≤ 0 on four lanes, to ~6e-9 relative (range reduction by ln 2 and a degree-7
/// Taylor polynomial in Estrin form on |r| ≤ ln2 / 2; rounding to the nearest integer by adding
/// 1.5·2^52); below −708 the result is e^−708 ≈ 3e−308, a weight of nothing. Several times
/// faster than `f64::exp`, and weights need no more precision.
#[inline]
fn exp_neg4(x: f64x4) -> f64x4 {
    const MAGIC: f64 = 6755399441055744.0;
    const LN2_HI: f64 = 6.931_471_803_691_238e-1;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let x = x.max(f64x4::splat(-708.0));
    let magic = f64x4::splat(MAGIC);
    let shifted = x * f64x4::splat(std::f64::consts::LOG2_E) + magic;
    let nf = shifted - magic;
    let r = (x - nf * f64x4::splat(LN2_HI)) - nf * f64x4::splat(LN2_LO);
    let r2 = r * r;
    let r4 = r2 * r2;
    let s = |v: f64| f64x4::splat(v);
    let p = (s(1.0) + r)
        + r2 * (s(0.5) + r * s(1.0 / 6.0))
        + r4 * ((s(1.0 / 24.0) + r * s(1.0 / 120.0)) + r2 * (s(1.0 / 720.0) + r * s(1.0 / 5040.0)));
    // 2^n from the bits of `shifted` = MAGIC + n (n in −1022..=0 sits in the low mantissa
    // bits): (n + 1023) << 52 is the exponent field of 2^n, with integer lanes (a conversion
    // of each lane to i64 took about ten instructions).
    let bits = cast::<f64x4, u64x4>(shifted) + u64x4::splat(1023);
    p * cast::<u64x4, f64x4>(bits << 52)
}

/// Eigen-decomposition of the symmetric 3×3 matrix `[xx, xy, xz, yy, yz, zz]`: the unit
/// eigenvector of the smallest eigenvalue and the eigenvalues ascending.
///
/// Closed form (Smith 1961 trigonometric solution on the matrix scaled by its largest entry and
/// shifted by its mean eigenvalue); the isolated smallest eigenvalue of a near-planar
/// neighbourhood is accurate to rounding. The eigenvector is the largest cross product of two
/// rows of A − λ0·I; when that matrix has rank ≤ 1 (λ0 = λ1) any vector orthogonal to its
/// largest row is an eigenvector, and `[0, 0, 1]` for A = λ·I.
pub fn smallest_eigen(a: [f64; 6]) -> (Point3, [f64; 3]) {
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // (A non-finite entry, from squared coordinates that overflow, has no eigenvectors to
    // speak of either.)
    if scale == 0.0 || !scale.is_finite() || a.iter().any(|v| !v.is_finite()) {
        return ([0.0, 0.0, 1.0], [0.0; 3]);
    }
    let inv = 1.0 / scale;
    let [xx, xy, xz, yy, yz, zz] = a.map(|v| v * inv);
    let q = (xx + yy + zz) / 3.0;
    let (bxx, byy, bzz) = (xx - q, yy - q, zz - q);
    let p2 = bxx * bxx + byy * byy + bzz * bzz + 2.0 * (xy * xy + xz * xz + yz * yz);
    let p = (p2 / 6.0).sqrt();
    if p < 1e-150 {
        return ([0.0, 0.0, 1.0], [q * scale; 3]);
    }
    let ip = 1.0 / p;
    let (cxx, cyy, czz, cxy, cxz, cyz) = (bxx * ip, byy * ip, bzz * ip, xy * ip, xz * ip, yz * ip);
    let det = cxx * (cyy * czz - cyz * cyz) - cxy * (cxy * czz - cyz * cxz)
        + cxz * (cxy * cyz - cyy * cxz);
    let r = (0.5 * det).clamp(-1.0, 1.0);
    let l_min = q + p * smallest_root(r);
    let r0 = [xx - l_min, xy, xz];
    let r1 = [xy, yy - l_min, yz];
    let r2 = [xz, yz, zz - l_min];
    let c01 = vec3::cross(r0, r1);
    let c02 = vec3::cross(r0, r2);
    let c12 = vec3::cross(r1, r2);
    let (d01, d02, d12) = (
        vec3::dot(c01, c01),
        vec3::dot(c02, c02),
        vec3::dot(c12, c12),
    );
    let (best, dbest) = if d01 >= d02 && d01 >= d12 {
        (c01, d01)
    } else if d02 >= d12 {
        (c02, d02)
    } else {
        (c12, d12)
    };
    let normal = if dbest > 1e-26 {
        vec3::scale(best, 1.0 / dbest.sqrt())
    } else {
        // Rows have entries ≤ ~2 after scaling; cross products this small mean rank ≤ 1
        // (λ0 = λ1): any vector orthogonal to the largest row is an eigenvector.
        let rows = [r0, r1, r2];
        let mut big = rows[0];
        for r in &rows[1..] {
            if vec3::dot(*r, *r) > vec3::dot(big, big) {
                big = *r;
            }
        }
        any_orthogonal(big)
    };
    // λ0 as the Rayleigh quotient of the normal (accurate to rounding even when λ0 ≈ λ1, where
    // the closed form loses half the digits); λ1 and λ2 as the roots of the quadratic left once
    // λ0 is known (sum 3q − λ0, product the sum of the principal 2 × 2 minors − λ0 (λ1 + λ2)):
    // accurate unless λ1 ≈ λ2, and then to ~1e-8 relative, like the trigonometric formula.
    let [nx, ny, nz] = normal;
    let l0 = nx * (xx * nx + xy * ny + xz * nz)
        + ny * (xy * nx + yy * ny + yz * nz)
        + nz * (xz * nx + yz * ny + zz * nz);
    let sum = 3.0 * q - l0;
    let minors = xx * yy - xy * xy + xx * zz - xz * xz + yy * zz - yz * yz;
    let product = minors - l0 * sum;
    let l2 = (0.5 * (sum + (sum * sum - 4.0 * product).max(0.0).sqrt())).max(l0);
    let l1 = (sum - l2).max(l0).min(l2);
    (normal, [l0 * scale, l1 * scale, l2 * scale])
}

/// [`smallest_eigen`] of four matrices at once, one per SIMD lane: the same operations in the
/// same order, so the same bits (tested), but four independent chains. The scalar solve is a
/// chain of dependent square roots and divisions (about 300 cycles of latency for 150
/// instructions, the CPU idle most of that time: a large share of the fused kNN + PCA normals
/// under perf, see `docs/experiments/knn-and-normals.md`); lanes make it throughput-bound.
/// Lanes on a special path of the scalar solve (a zero or non-finite matrix, a multiple of the
/// identity, λ0 ≈ λ1, where it branches) are solved by it.
pub fn smallest_eigen4(a: [[f64; 6]; 4]) -> [(Point3, [f64; 3]); 4] {
    let entry = |t: usize| f64x4::new([a[0][t], a[1][t], a[2][t], a[3][t]]);
    let m: [f64x4; 6] = std::array::from_fn(entry);
    let zero = f64x4::ZERO;
    let scale = m.iter().fold(zero, |acc, v| acc.max(v.abs()));
    let inv = f64x4::ONE / scale;
    let [xx, xy, xz, yy, yz, zz] = m.map(|v| v * inv);
    let q = (xx + yy + zz) / f64x4::splat(3.0);
    let (bxx, byy, bzz) = (xx - q, yy - q, zz - q);
    let two = f64x4::splat(2.0);
    let p2 = bxx * bxx + byy * byy + bzz * bzz + two * (xy * xy + xz * xz + yz * yz);
    let p = (p2 / f64x4::splat(6.0)).sqrt();
    let ip = f64x4::ONE / p;
    let (cxx, cyy, czz, cxy, cxz, cyz) = (bxx * ip, byy * ip, bzz * ip, xy * ip, xz * ip, yz * ip);
    let det = cxx * (cyy * czz - cyz * cyz) - cxy * (cxy * czz - cyz * cxz)
        + cxz * (cxy * cyz - cyy * cxz);
    let r = (f64x4::splat(0.5) * det)
        .max(f64x4::splat(-1.0))
        .min(f64x4::ONE);
    let w = (f64x4::splat(0.5) * (f64x4::ONE - r)).max(zero).sqrt();
    let c = |v: f64| f64x4::splat(v);
    let mut b = c(ROOT_POLY[0])
        + w * (c(ROOT_POLY[1])
            + w * (c(ROOT_POLY[2]) + w * (c(ROOT_POLY[3]) + w * c(ROOT_POLY[4]))));
    for _ in 0..3 {
        b -= (b * (b * b - c(3.0)) - two * r) / (c(3.0) * (b * b - f64x4::ONE));
    }
    let l_min = q + p * b;
    let r0 = [xx - l_min, xy, xz];
    let r1 = [xy, yy - l_min, yz];
    let r2 = [xz, yz, zz - l_min];
    let cross = |a: [f64x4; 3], b: [f64x4; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: [f64x4; 3], b: [f64x4; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let (c01, c02, c12) = (cross(r0, r1), cross(r0, r2), cross(r1, r2));
    let (d01, d02, d12) = (dot(c01, c01), dot(c02, c02), dot(c12, c12));
    let first = d01.simd_ge(d02) & d01.simd_ge(d12);
    let second = d02.simd_ge(d12);
    let pick = |v01: f64x4, v02: f64x4, v12: f64x4| first.select(v01, second.select(v02, v12));
    let best = [
        pick(c01[0], c02[0], c12[0]),
        pick(c01[1], c02[1], c12[1]),
        pick(c01[2], c02[2], c12[2]),
    ];
    let dbest = pick(d01, d02, d12);
    let f = f64x4::ONE / dbest.sqrt();
    let (nx, ny, nz) = (best[0] * f, best[1] * f, best[2] * f);
    let l0 = nx * (xx * nx + xy * ny + xz * nz)
        + ny * (xy * nx + yy * ny + yz * nz)
        + nz * (xz * nx + yz * ny + zz * nz);
    let sum = c(3.0) * q - l0;
    let minors = xx * yy - xy * xy + xx * zz - xz * xz + yy * zz - yz * yz;
    let product = minors - l0 * sum;
    let l2 = (c(0.5) * (sum + (sum * sum - c(4.0) * product).max(zero).sqrt())).max(l0);
    let l1 = (sum - l2).max(l0).min(l2);
    // The lanes the scalar solve would branch on.
    let finite = m
        .iter()
        .fold(scale.is_finite(), |acc, v| acc & v.is_finite());
    let fast = finite
        & scale.simd_gt(zero)
        & p.simd_ge(c(1e-150))
        & w.simd_ge(c(ROOT_MIN_W))
        & dbest.simd_gt(c(1e-26));
    let fast = fast.to_bitmask();
    let (nx, ny, nz) = (nx.to_array(), ny.to_array(), nz.to_array());
    let (l0, l1, l2, scale) = (
        l0.to_array(),
        l1.to_array(),
        l2.to_array(),
        scale.to_array(),
    );
    std::array::from_fn(|i| {
        if fast & (1 << i) != 0 {
            (
                [nx[i], ny[i], nz[i]],
                [l0[i] * scale[i], l1[i] * scale[i], l2[i] * scale[i]],
            )
        } else {
            smallest_eigen(a[i])
        }
    })
}

/// The degree-4 start of [`smallest_root`] in w (Chebyshev fit on [0, 1], within 4e-5).
const ROOT_POLY: [f64; 5] = [
    -1.000_038_318_485_340_3,
    -1.153_472_967_059_816_3,
    0.212_707_344_799_025_87,
    -0.076_665_054_090_380_6,
    0.017_497_932_943_738_304,
];

/// Below this w, [`smallest_root`] uses the trigonometric formula.
const ROOT_MIN_W: f64 = 0.02;

/// The smallest root of β³ − 3β − 2r (r in [−1, 1]): the smallest eigenvalue of the matrix
/// C = (A − qI)/p of [`smallest_eigen`], whose characteristic polynomial this is (trace 0,
/// tr C² = 6, det C = 2r), in [−2, −1].
///
/// Smith's formula gives it as 2 cos((acos r + 2π)/3); the acos and the cos were a visible
/// share of the fused kNN + PCA normals under perf (`docs/experiments/knn-and-normals.md`).
/// Instead: as a function of w = √((1 − r)/2) the
/// root is smooth on [0, 1] (the square-root branch point at the double root r = 1 becomes
/// linear), and a degree-4 polynomial (Chebyshev fit) is within 4e-5 of it; three Newton steps
/// then reach rounding (the error squares at each step, times f''/2f' ≤ 1.2 for w ≥ 0.25 and
/// ≤ 45 for w ≥ 0.02). Below w = 0.02 (λ0 and λ1 within about 0.1 % of the spread of the
/// eigenvalues, where the normal is ill-defined anyway and Newton slows) the trigonometric
/// formula is used.
#[inline]
fn smallest_root(r: f64) -> f64 {
    let w = (0.5 * (1.0 - r)).max(0.0).sqrt();
    if w < ROOT_MIN_W {
        return 2.0 * ((r.acos() + 2.0 * std::f64::consts::PI) / 3.0).cos();
    }
    let c = ROOT_POLY;
    let mut b = c[0] + w * (c[1] + w * (c[2] + w * (c[3] + w * c[4])));
    for _ in 0..3 {
        b -= (b * (b * b - 3.0) - 2.0 * r) / (3.0 * (b * b - 1.0));
    }
    b
}

/// A unit vector orthogonal to `v` (`[0, 0, 1]` if `v` is zero).
fn any_orthogonal(v: Point3) -> Point3 {
    let a = v.map(f64::abs);
    let axis = if a[0] <= a[1] && a[0] <= a[2] {
        [1.0, 0.0, 0.0]
    } else if a[1] <= a[2] {
        [0.0, 1.0, 0.0]
    } else {
        [0.0, 0.0, 1.0]
    };
    vec3::normalize(vec3::cross(v, axis)).unwrap_or([0.0, 0.0, 1.0])
}

/// How the face normals around a vertex are combined by [`mesh_vertex_normals`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Weighting {
    /// Mean of the unit normals of the incident faces (Gouraud; tran section 2.2).
    #[default]
    Uniform,
    /// Incident face normals weighted by face area.
    Area,
    /// Incident face normals weighted by the face's interior angle at the vertex (Thürmer &
    /// Wüthrich 1998).
    Angle,
}

/// Unit vertex normals of a triangle mesh, oriented as the faces (right-hand rule on the corner
/// order). Degenerate (zero-area) faces are skipped; a vertex with no valid incident face, or
/// whose incident normals cancel, gets `[0, 0, 0]`.
///
/// Errors if a face refers to a vertex out of range.
pub fn mesh_vertex_normals(mesh: &TriMesh, weighting: Weighting) -> Result<Vec<Point3>> {
    mesh.check_indices()?;
    let p = mesh.positions();
    // Per-face contributions in parallel, accumulated serially (deterministic).
    let contrib: Vec<[Point3; 3]> = mesh
        .faces
        .par_iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| p[v as usize]);
            let cr = vec3::cross(vec3::sub(b, a), vec3::sub(c, a));
            let len = vec3::norm(cr);
            if !(len > 0.0 && len.is_finite()) {
                return [[0.0; 3]; 3];
            }
            let unit = vec3::scale(cr, 1.0 / len);
            match weighting {
                Weighting::Uniform => [unit; 3],
                Weighting::Area => [vec3::scale(cr, 0.5); 3],
                Weighting::Angle => {
                    let ang = |o: Point3, u: Point3, v: Point3| {
                        vec3::angle(vec3::sub(u, o), vec3::sub(v, o))
                    };
                    [
                        vec3::scale(unit, ang(a, b, c)),
                        vec3::scale(unit, ang(b, c, a)),
                        vec3::scale(unit, ang(c, a, b)),
                    ]
                }
            }
        })
        .collect();
    let mut acc = vec![[0.0; 3]; p.len()];
    for (f, c) in mesh.faces.iter().zip(&contrib) {
        for (v, n) in f.iter().zip(c) {
            let s = &mut acc[*v as usize];
            *s = vec3::add(*s, *n);
        }
    }
    Ok(acc
        .into_par_iter()
        .map(|s| vec3::normalize(s).unwrap_or([0.0; 3]))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_matches_nalgebra_on_random_matrices() {
        let mut s = 12345u64;
        let mut rnd = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for _ in 0..2000 {
            let g = [
                [rnd(), rnd(), rnd()],
                [rnd(), rnd(), rnd()],
                [rnd(), rnd(), rnd()],
            ];
            // A = Gᵀ G (positive semi-definite like a covariance).
            let mut a = [0.0; 6];
            let idx = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
            for (t, &(r, c)) in idx.iter().enumerate() {
                a[t] = (0..3).map(|k| g[k][r] * g[k][c]).sum();
            }
            let (n, ev) = smallest_eigen(a);
            assert!((vec3::norm(n) - 1.0).abs() < 1e-12);
            let m = nalgebra::Matrix3::new(a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5]);
            let e = nalgebra::SymmetricEigen::new(m);
            let mut l: Vec<f64> = e.eigenvalues.iter().copied().collect();
            l.sort_by(f64::total_cmp);
            for t in 0..3 {
                assert!((l[t] - ev[t]).abs() < 1e-12, "{l:?} {ev:?}");
            }
            // Residual of the eigenvector.
            let v = nalgebra::Vector3::from(n);
            let res = (m * v - v * ev[0]).norm();
            let gap = (l[1] - l[0]).max(1e-300);
            assert!(res < 1e-10 || gap < 1e-6, "residual {res} gap {gap}");
        }
    }

    #[test]
    fn eigen4_is_bitwise_the_scalar_solve() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(99);
        let mut rnd = || rng.random_range(-0.5..0.5);
        let mut mats: Vec<[f64; 6]> = Vec::new();
        for i in 0..4000 {
            // Covariances of random, flat (plane-like), line-like and degenerate sets.
            let g: [[f64; 3]; 3] = std::array::from_fn(|_| [rnd(), rnd(), rnd()]);
            let squash = match i % 4 {
                1 => [1.0, 1.0, 1e-4],
                2 => [1.0, 1e-5, 1e-5],
                _ => [1.0, 1.0, 1.0],
            };
            let idx = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
            let mut a = [0.0; 6];
            for (t, &(r, c)) in idx.iter().enumerate() {
                a[t] = (0..3)
                    .map(|k| g[k][r] * squash[r] * g[k][c] * squash[c])
                    .sum();
            }
            mats.push(a);
        }
        mats.extend([
            [0.0; 6],
            [2.0, 0.0, 0.0, 2.0, 0.0, 2.0],
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            [f64::NAN, 0.0, 0.0, 1.0, 0.0, 1.0],
            [f64::INFINITY, 0.0, 0.0, 1.0, 0.0, 1.0],
            [1e-300, 0.0, 0.0, 1e-300, 0.0, 0.0],
            [1e300, 1e299, 0.0, 1e300, 0.0, 1e290],
        ]);
        for four in mats.chunks_exact(4) {
            let got = smallest_eigen4([four[0], four[1], four[2], four[3]]);
            for (a, (n, e)) in four.iter().zip(got) {
                let (n0, e0) = smallest_eigen(*a);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!((bits(&n), bits(&e)), (bits(&n0), bits(&e0)), "{a:?}");
            }
        }
    }

    #[test]
    fn smallest_root_matches_smith() {
        for i in 0..=200_000 {
            let r = -1.0 + 2.0 * i as f64 / 200_000.0;
            let smith = 2.0 * ((r.acos() + 2.0 * std::f64::consts::PI) / 3.0).cos();
            let b = smallest_root(r);
            // Within rounding of the root (the formula itself is only that accurate).
            assert!((b - smith).abs() < 1e-13, "r {r}: {b} vs {smith}");
            assert!(
                (b * (b * b - 3.0) - 2.0 * r).abs() < 1e-14,
                "r {r}: residual"
            );
        }
    }

    #[test]
    fn fast_exp_accuracy() {
        let exp_neg = |x: f64| exp_neg4(f64x4::new([x, 0.5 * x, 0.0, x])).to_array();
        for i in 0..=100_000 {
            let x = -(i as f64) * 1e-3;
            let [a, h, one, a2] = exp_neg(x);
            let (b, bh) = (x.exp(), (0.5 * x).exp());
            assert!((a - b).abs() <= 1e-8 * b, "{x}: {a} vs {b}");
            assert!((h - bh).abs() <= 1e-8 * bh, "{x}: {h} vs {bh}");
            assert_eq!((one, a2), (1.0, a));
        }
        assert!(exp_neg(-1000.0)[0] < 1e-300);
        assert_eq!(exp_neg(0.0)[0], 1.0);
    }

    #[test]
    fn eigen_degenerate_cases() {
        // Zero matrix, multiple of identity, rank-1, plane.
        assert_eq!(smallest_eigen([0.0; 6]).0, [0.0, 0.0, 1.0]);
        let (n, ev) = smallest_eigen([2.0, 0.0, 0.0, 2.0, 0.0, 2.0]);
        assert_eq!(n, [0.0, 0.0, 1.0]);
        assert!(ev.iter().all(|&l| (l - 2.0).abs() < 1e-12));
        // Collinear along x: λ = (0, 0, 1); normal ⟂ x.
        let (n, ev) = smallest_eigen([1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert!(n[0].abs() < 1e-12 && (vec3::norm(n) - 1.0).abs() < 1e-12);
        assert!(ev[0].abs() < 1e-12 && ev[1].abs() < 1e-12 && (ev[2] - 1.0).abs() < 1e-12);
        // Plane z = 0, isotropic in the plane (λ1 = λ2: the acos is at its singular end).
        let (n, ev) = smallest_eigen([1.0, 0.0, 0.0, 1.0, 0.0, 0.0]);
        assert!((n[2].abs() - 1.0).abs() < 1e-12, "{n:?}");
        assert!(ev[0].abs() < 1e-12);
    }
}
