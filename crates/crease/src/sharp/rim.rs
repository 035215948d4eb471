//! The rim of a thin sheet: how far a point lies from the boundary of the sheet it is sampled
//! on, from the offset of its neighbourhood's centroid *along* the fitted plane.
//!
//! A plate thinner than the neighbourhood (the PCEDNet models 7034 and 7038, plates 1.0–1.3
//! spacings thick) has both faces in every neighbourhood. With noise of about half a spacing the
//! two faces cannot be told apart (the one-face stage of [`super::face`] is off on noisy clouds),
//! the segmentation leaves the plate unassigned, and tran's projected distance (equation 3, an
//! offset *across* the plane) is the noise itself: the sheet is flat at every point, rim or not.
//! What does tell the rim is the offset along the plane: inside the sheet the neighbourhood is a
//! full disc around the point, at the rim a half disc whose centroid lies 4R/(3π) inward.
//! Scanner noise moves points across the sheet, so this offset does not see it.
//!
//! Neither tran nor the PCEDNet benchmark has this measure; it is ours. For a disc of radius R
//! around the point, cut by a straight rim at distance s = uR (0 ≤ u ≤ 1), the ratio of the
//! centroid's offset to the RMS radius about the centroid (both in the plane) is
//! ρ(u) = |M_x| / A / sqrt(M_xx/A − (M_x/A)² + M_yy/A) with the moments of the cut disc
//! (closed forms in [`ratio_at`]): ρ(0) = 0.750, ρ(1) = 0. Inverting ρ gives the distance to
//! the rim, s = ρ⁻¹(measured ratio) · R, with R the distance to the farthest neighbour.
//!
//! The default of [`super::SurfaceRefine::rim_k`] is 80, twice the largest scale of tran
//! section 4.2, since a sheet's neighbourhood holds both faces: the same area of the sheet as
//! 40 neighbours on one face (fewer neighbours scored lower on the noisy PCEDNet plates, see
//! `docs/experiments/sharp-surfaces.md`).

use crate::estimate::normals::smallest_eigen;
use crate::geometry::{vec3, Point3};

/// ρ(u) of the module documentation: a unit disc cut at x ≤ u, the ratio of its centroid's
/// distance from the disc's centre to its RMS radius about the centroid.
pub(crate) fn ratio_at(u: f64) -> f64 {
    let u = u.clamp(-1.0, 1.0);
    let c = (1.0 - u * u).max(0.0).sqrt();
    let a = u.asin() + std::f64::consts::FRAC_PI_2;
    // Area, first moment in x, second moments in x and y of {x² + y² ≤ 1, x ≤ u}.
    let area = u * c + a;
    let mx = -2.0 / 3.0 * c * c * c;
    let mxx = 0.25 * (u * (2.0 * u * u - 1.0) * c + a);
    let myy = (u * (5.0 - 2.0 * u * u) * c + 3.0 * a) / 12.0;
    if area <= 0.0 {
        return 0.0;
    }
    let cx = mx / area;
    let var = mxx / area - cx * cx + myy / area;
    if var > 0.0 {
        cx.abs() / var.sqrt()
    } else {
        0.0
    }
}

/// The u in [0, 1] with ρ(u) = `ratio` (ρ decreases from 0.750 at u = 0 to 0 at u = 1); 0 for
/// a ratio at or above ρ(0) (a corner of the sheet, or beyond its rim), 1 for a ratio of 0.
///
/// The root is bracketed in a table of ρ at [`RATIO_TABLE`] + 1 even steps of u, then found
/// by false position (Illinois variant) to 1e-13 in u: about 5 evaluations of ρ where the
/// bisection it replaced took 40, which made ρ's arcsine 5 % of `crease run` on a noisy
/// million-point cloud.
pub(crate) fn distance_fraction(ratio: f64) -> f64 {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    if ratio.is_nan() {
        return 0.0;
    }
    if ratio >= ratio_at(0.0) {
        return 0.0;
    }
    if ratio <= 0.0 {
        return 1.0;
    }
    let table = TABLE.get_or_init(|| {
        (0..=RATIO_TABLE)
            .map(|i| ratio_at(i as f64 / RATIO_TABLE as f64))
            .collect()
    });
    // table[0] = ρ(0) > ratio > 0 = table[RATIO_TABLE]: the first entry at or below the ratio
    // closes the bracket.
    let i = table.partition_point(|&v| v > ratio).clamp(1, RATIO_TABLE);
    let (mut a, mut b) = (
        (i - 1) as f64 / RATIO_TABLE as f64,
        i as f64 / RATIO_TABLE as f64,
    );
    // f = ρ − ratio: positive at a, at most zero at b.
    let (mut fa, mut fb) = (table[i - 1] - ratio, table[i] - ratio);
    if fb == 0.0 {
        return b;
    }
    let mut side = 0i8;
    for _ in 0..60 {
        if b - a <= 1e-13 {
            break;
        }
        let x = ((a * fb - b * fa) / (fb - fa)).clamp(a, b);
        let fx = ratio_at(x) - ratio;
        if fx == 0.0 {
            return x;
        }
        if fx > 0.0 {
            a = x;
            fa = fx;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        } else {
            b = x;
            fb = fx;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        }
    }
    0.5 * (a + b)
}

/// Steps of the table that brackets ρ's inverse in [`distance_fraction`].
const RATIO_TABLE: usize = 256;

/// The distance from point `p` to the rim of its sheet (length units), from the plane through
/// it and its nearest neighbours `near` (see the module documentation; `radius` is the distance
/// to the farthest of them), and the RMS distance of those points to the plane; `None` when the
/// fit fails.
///
/// The plane's eigenproblem is the closed form of the PCA normals
/// ([`crate::estimate::normals::smallest_eigen`]), not the iterative solver of
/// [`crate::geometry::fit_plane`]: one per point of a noisy cloud, it took 0.25 of this test's
/// 1.3 s on a noisy million-point cloud (the labels there identical).
pub(crate) fn rim_distance(p: Point3, near: &[Point3], radius: f64) -> Option<(f64, f64)> {
    let count = (near.len() + 1) as f64;
    if near.len() < 2 {
        return None;
    }
    let sum = near.iter().fold(p, |s, &q| vec3::add(s, q));
    let centroid = vec3::scale(sum, 1.0 / count);
    let mut a = [0.0; 6];
    for q in std::iter::once(&p).chain(near) {
        let d = vec3::sub(*q, centroid);
        a[0] += d[0] * d[0];
        a[1] += d[0] * d[1];
        a[2] += d[0] * d[2];
        a[3] += d[1] * d[1];
        a[4] += d[1] * d[2];
        a[5] += d[2] * d[2];
    }
    let (normal, eigenvalues) = smallest_eigen(a.map(|v| v / count));
    if !normal.iter().all(|v| v.is_finite()) {
        return None;
    }
    let d = vec3::sub(centroid, p);
    let along = vec3::sub(d, vec3::scale(normal, vec3::dot(d, normal)));
    let rms = (eigenvalues[1] + eigenvalues[2]).sqrt();
    if rms.is_nan() || rms <= 0.0 {
        return None;
    }
    Some((
        distance_fraction(vec3::norm(along) / rms) * radius,
        eigenvalues[0].max(0.0).sqrt(),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed forms against the half disc (centroid 4/(3π), RMS radius sqrt(1/2 − (4/(3π))²))
    /// and a numerical integration of the cut disc; the inverse recovers u.
    #[test]
    fn ratio_matches_the_cut_disc() {
        let cx = 4.0 / (3.0 * std::f64::consts::PI);
        let half = cx / (0.5 - cx * cx).sqrt();
        assert!((ratio_at(0.0) - half).abs() < 1e-12, "{}", ratio_at(0.0));
        assert!(ratio_at(1.0).abs() < 1e-12);
        for &u in &[0.1, 0.3, 0.5, 0.8] {
            let m = 1000;
            let (mut a, mut sx, mut sxx, mut syy) = (0.0, 0.0, 0.0, 0.0);
            for ix in 0..m {
                for iy in 0..m {
                    let x = -1.0 + 2.0 * (ix as f64 + 0.5) / m as f64;
                    let y = -1.0 + 2.0 * (iy as f64 + 0.5) / m as f64;
                    if x * x + y * y <= 1.0 && x <= u {
                        a += 1.0;
                        sx += x;
                        sxx += x * x;
                        syy += y * y;
                    }
                }
            }
            let mx = sx / a;
            let num = mx.abs() / (sxx / a - mx * mx + syy / a).sqrt();
            assert!(
                (ratio_at(u) - num).abs() < 2e-3,
                "u = {u}: {} vs {num}",
                ratio_at(u)
            );
            assert!((distance_fraction(ratio_at(u)) - u).abs() < 1e-9);
        }
        // The inverse everywhere, near both ends too.
        for i in 0..=2000 {
            let u = i as f64 / 2000.0;
            let r = ratio_at(u);
            if r > 0.0 && r < ratio_at(0.0) {
                let got = distance_fraction(r);
                assert!((ratio_at(got) - r).abs() < 1e-12, "u = {u}: {got}");
            }
        }
        assert_eq!(distance_fraction(0.9), 0.0);
        assert_eq!(distance_fraction(0.0), 1.0);
    }

    /// A noisy square sheet: the measured rim distance follows the true distance to the nearest
    /// side (within a spacing where it is under half the neighbourhood radius), and noise across
    /// the sheet does not change it.
    #[test]
    fn rim_distance_of_a_noisy_sheet() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let side = 60usize;
        let mut pts = Vec::new();
        for y in 0..side {
            for x in 0..side {
                for face in [-0.5, 0.5] {
                    let jit: f64 = rng.random_range(-0.5..0.5);
                    pts.push([
                        x as f64 + 0.2 * rng.random_range(-1.0..1.0),
                        y as f64 + 0.2 * rng.random_range(-1.0..1.0),
                        face + jit,
                    ]);
                }
            }
        }
        let index = crate::spatial::KdIndex::new(&pts).expect("index");
        let at = |i: usize| {
            // The point itself is the nearest item: its 80 neighbours follow.
            let near = index.nearest(&pts[i], 81);
            let radius = near.last().expect("neighbours").1.sqrt();
            let others: Vec<Point3> = near[1..].iter().map(|&(j, _)| pts[j as usize]).collect();
            rim_distance(pts[i], &others, radius).expect("fit").0
        };
        let mut worst = 0.0f64;
        for (i, p) in pts.iter().enumerate() {
            let truth = p[0]
                .min(p[1])
                .min(side as f64 - 1.0 - p[0])
                .min(side as f64 - 1.0 - p[1]);
            if !(1.0..=2.0).contains(&truth) || (p[0] - p[1]).abs() < 4.0 {
                continue;
            }
            let s = at(i);
            worst = worst.max((s - truth).abs());
        }
        assert!(worst < 1.0, "worst error {worst}");
        // Deep inside: the distance saturates near the neighbourhood's radius (3.6 spacings here,
        // measured 2.9 with the sampling's jitter).
        let centre = (side / 2) * side * 2 + side;
        let s = at(centre);
        assert!(s > 2.5, "{s}");
    }
}
