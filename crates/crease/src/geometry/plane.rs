//! Least-squares planes through point sets: the weighted centroid and the eigen-decomposition of
//! the weighted covariance matrix (the normal is the eigenvector of the smallest eigenvalue).
//! Used by the PCA normal (tran equation 1) and the 1-ring normal (demarsin2007 section 2.2).

use nalgebra::{Matrix3, SymmetricEigen};

use crate::geometry::Point3;

/// A least-squares plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Weighted centroid of the points.
    pub centroid: Point3,
    /// Unit normal (eigenvector of the smallest eigenvalue); its sign is arbitrary.
    pub normal: Point3,
    /// Eigenvalues of the weighted covariance, ascending (λ0 ≤ λ1 ≤ λ2), normalised by the
    /// total weight.
    pub eigenvalues: [f64; 3],
    /// Eigenvectors matching `eigenvalues` (`axes[0] == normal`).
    pub axes: [Point3; 3],
}

impl Plane {
    /// Surface variation λ0 / (λ0 + λ1 + λ2) (Pauly), 0 for a perfect plane.
    pub fn surface_variation(&self) -> f64 {
        let s: f64 = self.eigenvalues.iter().sum();
        if s > 0.0 {
            self.eigenvalues[0] / s
        } else {
            0.0
        }
    }
}

/// The least-squares plane through `(point, weight)` pairs; `None` with fewer than three points,
/// a non-positive total weight or a non-finite result.
pub fn fit_plane(items: impl IntoIterator<Item = (Point3, f64)> + Clone) -> Option<Plane> {
    let mut w_sum = 0.0;
    let mut c = [0.0; 3];
    let mut n = 0usize;
    for (p, w) in items.clone() {
        w_sum += w;
        for k in 0..3 {
            c[k] += w * p[k];
        }
        n += 1;
    }
    if n < 3 || w_sum <= 0.0 || !w_sum.is_finite() {
        return None;
    }
    let c = c.map(|v| v / w_sum);
    let mut m = Matrix3::<f64>::zeros();
    for (p, w) in items {
        let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
        for r in 0..3 {
            for s in r..3 {
                m[(r, s)] += w * d[r] * d[s];
            }
        }
    }
    for r in 0..3 {
        for s in 0..r {
            m[(r, s)] = m[(s, r)];
        }
    }
    m /= w_sum;
    let eig = SymmetricEigen::new(m);
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let axis = |i: usize| {
        let v = eig.eigenvectors.column(order[i]);
        [v[0], v[1], v[2]]
    };
    let plane = Plane {
        centroid: c,
        normal: axis(0),
        eigenvalues: order.map(|i| eig.eigenvalues[i]),
        axes: [axis(0), axis(1), axis(2)],
    };
    plane.normal.iter().all(|v| v.is_finite()).then_some(plane)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tilted_plane_normal_and_zero_variation() {
        let n = crate::geometry::vec3::normalize([1.0, 2.0, 3.0]).unwrap();
        let u = crate::geometry::vec3::normalize(crate::geometry::vec3::cross(n, [0.0, 0.0, 1.0]))
            .unwrap();
        let v = crate::geometry::vec3::cross(n, u);
        let mut pts = Vec::new();
        for i in 0..5 {
            for j in 0..5 {
                let (a, b) = (i as f64 * 0.3, j as f64 * 0.7);
                pts.push((
                    [
                        u[0] * a + v[0] * b,
                        u[1] * a + v[1] * b,
                        u[2] * a + v[2] * b,
                    ],
                    1.0,
                ));
            }
        }
        let p = fit_plane(pts.iter().copied()).unwrap();
        assert!(crate::geometry::vec3::dot(p.normal, n).abs() > 1.0 - 1e-12);
        assert!(p.surface_variation() < 1e-12);
        assert!(fit_plane(pts[..2].iter().copied()).is_none());
    }
}

/// First and second moments of a point set about one of its points p (the origin, which counts
/// as a point at offset zero): taking them about p rather than about the coordinate origin
/// keeps the numbers small, so the covariance Σ(d dᵀ)/m − c cᵀ loses little to cancellation.
/// Used where a uniform PCA runs per point over neighbourhoods (sharp-feature measures, noise
/// estimate, small-scale normals).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Moments {
    s1: [f64; 3],
    /// xx xy xz yy yz zz
    s2: [f64; 6],
    m: usize,
}

impl Moments {
    /// The moments of p alone.
    #[inline]
    pub(crate) fn origin() -> Self {
        Moments {
            s1: [0.0; 3],
            s2: [0.0; 6],
            m: 1,
        }
    }

    /// No point yet: the moments of other points about p, p itself left out.
    #[inline]
    pub(crate) fn without_origin() -> Self {
        Moments {
            s1: [0.0; 3],
            s2: [0.0; 6],
            m: 0,
        }
    }

    /// Adds the point at offset `d` from p.
    #[inline]
    pub(crate) fn add(&mut self, d: Point3) {
        self.s1 = [self.s1[0] + d[0], self.s1[1] + d[1], self.s1[2] + d[2]];
        self.s2[0] += d[0] * d[0];
        self.s2[1] += d[0] * d[1];
        self.s2[2] += d[0] * d[2];
        self.s2[3] += d[1] * d[1];
        self.s2[4] += d[1] * d[2];
        self.s2[5] += d[2] * d[2];
        self.m += 1;
    }

    /// The centroid's offset from p and the covariance `[xx, xy, xz, yy, yz, zz]` (divided by
    /// the number of points, p included).
    #[inline]
    pub(crate) fn centroid_covariance(&self) -> (Point3, [f64; 6]) {
        let inv = 1.0 / self.m as f64;
        let c = [self.s1[0] * inv, self.s1[1] * inv, self.s1[2] * inv];
        let s2 = &self.s2;
        (
            c,
            [
                s2[0] * inv - c[0] * c[0],
                s2[1] * inv - c[0] * c[1],
                s2[2] * inv - c[0] * c[2],
                s2[3] * inv - c[1] * c[1],
                s2[4] * inv - c[1] * c[2],
                s2[5] * inv - c[2] * c[2],
            ],
        )
    }
}
