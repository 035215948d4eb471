//! A k-d tree over a point set (kiddo's `ImmutableKdTree`), answering nearest-neighbour queries.

use std::num::NonZero;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::geometry::Point3;

/// A static k-d tree over `points`; items are the points' indices.
pub struct KdIndex {
    tree: ImmutableKdTree<f64, 3>,
}

impl KdIndex {
    /// Builds the tree. `points` must be finite and non-empty.
    pub fn new(points: &[Point3]) -> Option<Self> {
        if points.is_empty() {
            return None;
        }
        let tree = ImmutableKdTree::new_from_slice(points).ok()?;
        Some(KdIndex { tree })
    }

    /// The `k` nearest points to `q`, nearest first, as (index, squared distance).
    /// Ties are broken by index so the result does not depend on the tree's internal order.
    pub fn nearest(&self, q: &Point3, k: usize) -> Vec<(u32, f64)> {
        let Some(k) = NonZero::new(k) else {
            return Vec::new();
        };
        let mut r: Vec<(u32, f64)> = self
            .tree
            .query(q)
            .nearest_n::<SquaredEuclidean<f64>>(k)
            .execute()
            .into_iter()
            .map(|it| (it.item, it.distance))
            .collect();
        r.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
        r
    }

    /// The nearest point to `q`, as (index, squared distance): kiddo's single-nearest query,
    /// several times faster than [`KdIndex::nearest`] with `k = 1` (no result list to allocate
    /// and sort). Of points at exactly the same distance it gives the one the tree meets first
    /// (the same for the same points, whatever the thread count), not always the lowest index.
    pub fn nearest_one(&self, q: &Point3) -> (u32, f64) {
        let it = self
            .tree
            .query(q)
            .nearest_one::<SquaredEuclidean<f64>>()
            .execute();
        (it.item, it.distance)
    }
}
