//! Symmetric rank-one updates of least-squares normal equations (`AᵀA += w g gᵀ`).
//!
//! nalgebra's `a += g * g.transpose() * w` forms the whole `N × N` outer product and a scaled
//! copy of it before adding; the surface fits and the curvature's local quadrics spend most of
//! their time there (the Kinect scene's profile: a fifth of `crease run` in the cone and torus
//! fits' sums). [`add_outer`] adds the upper triangle only, each entry computed as
//! `(g_i g_j) w`, exactly as the full product does, and [`symmetrize`] copies it to the lower
//! triangle once the sums are done: the matrices are bit for bit those of the full products.

use nalgebra::{SMatrix, SVector};

/// `a += w g gᵀ` on the upper triangle of `a` (`j ≥ i`); call [`symmetrize`] after the last
/// update. `w = 1` gives the unweighted sum exactly (`x · 1 = x` in floating point).
#[inline]
pub fn add_outer<const N: usize>(a: &mut SMatrix<f64, N, N>, g: &SVector<f64, N>, w: f64) {
    for j in 0..N {
        for i in 0..=j {
            a[(i, j)] += (g[i] * g[j]) * w;
        }
    }
}

/// Copies the upper triangle of `a` to its lower triangle.
#[inline]
pub fn symmetrize<const N: usize>(a: &mut SMatrix<f64, N, N>) {
    for j in 0..N {
        for i in 0..j {
            a[(j, i)] = a[(i, j)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_full_outer_product_bit_for_bit() {
        let rows = [
            SVector::<f64, 6>::new(0.3, -1.7, 2.9e-3, 11.0, -0.1, 1.0),
            SVector::<f64, 6>::new(-4.1, 0.25, 7.5, 1e-9, 3.3, 1.0),
            SVector::<f64, 6>::new(0.0, 2.0, -0.5, 0.75, -6.25, 1.0),
        ];
        let (mut full, mut half) = (SMatrix::<f64, 6, 6>::zeros(), SMatrix::<f64, 6, 6>::zeros());
        let (mut full1, mut half1) = (full, half);
        for (k, g) in rows.iter().enumerate() {
            let w = 0.37 + k as f64;
            full += g * g.transpose() * w;
            add_outer(&mut half, g, w);
            full1 += g * g.transpose();
            add_outer(&mut half1, g, 1.0);
        }
        symmetrize(&mut half);
        symmetrize(&mut half1);
        assert_eq!(full, half);
        assert_eq!(full1, half1);
    }
}
