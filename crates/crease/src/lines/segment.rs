//! Step 1 of demarsin2007 (section 2.2, "Region growing"): first-order segmentation of the cloud
//! by region growing with a single angle threshold α_max between the normals of adjacent points
//! (a modification of Vanco et al.'s method: one threshold, no seed-normal comparison).
//!
//! Adjacent points are Delaunay 1-ring neighbours (symmetrised: p and q are adjacent when either
//! is in the other's ring). A cluster grows from the lowest unlabelled point by breadth-first
//! search: a neighbour q of a cluster point p joins when the angle between their (unoriented)
//! normals is at most α_max. Along a sharp edge the 1-ring normals vary strongly, so the edge
//! is covered by many small clusters between the large clusters of the smooth faces.
//!
//! The growth is sequential (each cluster is one breadth-first search; the whole pass is
//! O(number of ring entries)), so the labels do not depend on the thread count.

use std::collections::VecDeque;

use rayon::prelude::*;

use crate::geometry::{vec3, Csr, Point3};

/// Per-point cluster labels (0..num_clusters, numbered by their lowest point) and sizes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ClusterLabels {
    /// Cluster of every point.
    pub labels: Vec<u32>,
    /// Number of points of every cluster.
    pub sizes: Vec<u32>,
}

impl ClusterLabels {
    /// Number of clusters.
    pub fn num_clusters(&self) -> usize {
        self.sizes.len()
    }
}

/// Region growing over `adjacency` (symmetric CSR) with unoriented `normals`: adjacent points
/// join the same cluster when their normals differ by at most `alpha_max` radians.
pub fn region_grow(normals: &[Point3], adjacency: &Csr, alpha_max: f64) -> ClusterLabels {
    let n = normals.len();
    let cos_max = alpha_max.cos();
    let mut labels = vec![u32::MAX; n];
    let mut sizes = Vec::new();
    let mut queue = VecDeque::new();
    for seed in 0..n {
        if labels[seed] != u32::MAX {
            continue;
        }
        let id = sizes.len() as u32;
        labels[seed] = id;
        let mut size = 1u32;
        queue.push_back(seed as u32);
        while let Some(p) = queue.pop_front() {
            let np = normals[p as usize];
            let row = if (p as usize) < adjacency.num_rows() {
                adjacency.row(p as usize)
            } else {
                &[]
            };
            for &q in row {
                let qi = q as usize;
                if qi >= n || labels[qi] != u32::MAX {
                    continue;
                }
                if vec3::dot(np, normals[qi]).abs() >= cos_max {
                    labels[qi] = id;
                    size += 1;
                    queue.push_back(q);
                }
            }
        }
        sizes.push(size);
    }
    ClusterLabels { labels, sizes }
}

/// Median angle (radians) between the normals of adjacent points: the normal noise of a
/// cloud whose points mostly lie on smooth patches (sharp edges are a small minority of the
/// adjacent pairs).
pub fn median_adjacent_angle(normals: &[Point3], adjacency: &Csr) -> f64 {
    let n = normals.len().min(adjacency.num_rows());
    let mut angles: Vec<f64> = (0..n)
        .into_par_iter()
        .flat_map_iter(|p| {
            adjacency
                .row(p)
                .iter()
                .filter(move |&&q| (q as usize) > p && (q as usize) < n)
                .map(move |&q| {
                    vec3::dot(normals[p], normals[q as usize])
                        .abs()
                        .min(1.0)
                        .acos()
                })
        })
        .collect();
    if angles.is_empty() {
        return 0.0;
    }
    let mid = angles.len() / 2;
    let (_, m, _) = angles.select_nth_unstable_by(mid, f64::total_cmp);
    *m
}

/// Bilateral (feature-preserving) smoothing of unoriented normals over `adjacency`: each pass
/// replaces every normal by the normalised sum of its own and its neighbours' normals (signs
/// aligned to it), a neighbour weighted by `exp(-(θ / sigma)²)`, θ being the angle between the
/// two normals. Normals across a sharp edge differ by far more than `sigma` and hardly count,
/// so the edges stay sharp while the noise on the patches averages out. Every pass reads the
/// previous pass only, so the result does not depend on the thread count.
pub fn smooth_normals(
    normals: &[Point3],
    adjacency: &Csr,
    sigma: f64,
    passes: usize,
) -> Vec<Point3> {
    let mut cur = normals.to_vec();
    if sigma <= 0.0 {
        return cur;
    }
    for _ in 0..passes {
        let prev = &cur;
        cur = (0..prev.len())
            .into_par_iter()
            .map(|p| {
                let np = prev[p];
                let row: &[u32] = if p < adjacency.num_rows() {
                    adjacency.row(p)
                } else {
                    &[]
                };
                let mut sum = np;
                for &q in row {
                    let Some(&nq) = prev.get(q as usize) else {
                        continue;
                    };
                    let c = vec3::dot(np, nq);
                    let theta = c.abs().min(1.0).acos() / sigma;
                    let w = (-theta * theta).exp() * c.signum();
                    sum = vec3::add(sum, vec3::scale(nq, w));
                }
                vec3::normalize(sum).unwrap_or(np)
            })
            .collect();
    }
    cur
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_planes_give_two_clusters() {
        // A chain of 6 points: normals z, z, z, x, x, x.
        let normals = vec![
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
        ];
        let rows: Vec<Vec<u32>> = (0..6u32)
            .map(|i| {
                let mut r = Vec::new();
                if i > 0 {
                    r.push(i - 1);
                }
                if i < 5 {
                    r.push(i + 1);
                }
                r
            })
            .collect();
        let counts: Vec<u32> = rows.iter().map(|r| r.len() as u32).collect();
        let adj = Csr {
            offsets: Csr::offsets_from_counts(&counts),
            indices: rows.concat(),
        };
        let s = region_grow(&normals, &adj, 8f64.to_radians());
        assert_eq!(s.labels, vec![0, 0, 0, 1, 1, 1]);
        assert_eq!(s.sizes, vec![3, 3]);
    }

    /// A chain of 40 points, 20 on each side of a 90° crease, normals tilted by ±10° noise:
    /// the bilateral smoothing brings each side's normals to within 3° of the exact ones and
    /// keeps the crease (the two sides still 90° apart).
    #[test]
    fn smoothing_keeps_the_crease_and_removes_noise() {
        let n = 40;
        let tilt = |i: usize| if i.is_multiple_of(2) { 0.17 } else { -0.17 };
        let normals: Vec<Point3> = (0..n)
            .map(|i| {
                let t: f64 = tilt(i);
                if i < n / 2 {
                    [t.sin(), 0.0, t.cos()]
                } else {
                    [t.cos(), t.sin(), 0.0]
                }
            })
            .collect();
        let rows: Vec<Vec<u32>> = (0..n as u32)
            .map(|i| {
                (i.saturating_sub(2)..=(i + 2).min(n as u32 - 1))
                    .filter(|&j| j != i)
                    .collect()
            })
            .collect();
        let counts: Vec<u32> = rows.iter().map(|r| r.len() as u32).collect();
        let adj = Csr {
            offsets: Csr::offsets_from_counts(&counts),
            indices: rows.concat(),
        };
        let noise = median_adjacent_angle(&normals, &adj);
        assert!((noise - 0.34).abs() < 0.01, "{noise}");
        let s = smooth_normals(&normals, &adj, 1.5 * noise, 3);
        let angle = |a: Point3, b: Point3| vec3::dot(a, b).abs().min(1.0).acos().to_degrees();
        for (i, &v) in s.iter().enumerate() {
            let exact = if i < n / 2 {
                [0.0, 0.0, 1.0]
            } else {
                [1.0, 0.0, 0.0]
            };
            // The two points next to the crease keep some of the other side.
            let tol = if i + 2 >= n / 2 && i < n / 2 + 2 {
                20.0
            } else {
                3.0
            };
            assert!(angle(v, exact) < tol, "point {i}: {}", angle(v, exact));
        }
        assert!(angle(s[0], s[n - 1]) > 85.0);
    }
}
