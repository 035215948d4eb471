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

use crate::geometry::{vec3, Csr, Point3};

/// Per-point cluster labels (0..num_clusters, numbered by their lowest point) and sizes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Segmentation {
    /// Cluster of every point.
    pub labels: Vec<u32>,
    /// Number of points of every cluster.
    pub sizes: Vec<u32>,
}

impl Segmentation {
    /// Number of clusters.
    pub fn num_clusters(&self) -> usize {
        self.sizes.len()
    }
}

/// Region growing over `adjacency` (symmetric CSR) with unoriented `normals`: adjacent points
/// join the same cluster when their normals differ by at most `alpha_max` radians.
pub fn region_grow(normals: &[Point3], adjacency: &Csr, alpha_max: f64) -> Segmentation {
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
    Segmentation { labels, sizes }
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
}
