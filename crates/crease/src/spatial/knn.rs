//! k nearest neighbours of every point of a cloud, as CSR lists.
//!
//! Multi-scale users query the largest k once and take prefixes ([`Neighborhoods::prefix`]):
//! rows are sorted nearest first (ties by index), so the first k' entries of a row are exactly
//! the k' nearest neighbours.

use rayon::prelude::*;

use super::KdIndex;
use crate::geometry::{Csr, Point3};
use crate::{Error, Result};

/// The k nearest neighbours of every point (the point itself excluded), nearest first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Neighborhoods {
    k: usize,
    lists: Csr,
}

impl Neighborhoods {
    /// Wraps CSR lists whose rows hold at most `k` neighbours, nearest first.
    pub fn from_csr(k: usize, lists: Csr) -> Self {
        Neighborhoods { k, lists }
    }

    /// The k the lists were built for (rows are shorter only when the cloud has ≤ k points).
    pub fn k(&self) -> usize {
        self.k
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.lists.num_rows()
    }

    /// True for an empty cloud.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The neighbours of point `i`, nearest first.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        self.lists.row(i)
    }

    /// The `k` nearest neighbours of point `i` (all of them if the row is shorter).
    #[inline]
    pub fn prefix(&self, i: usize, k: usize) -> &[u32] {
        let row = self.lists.row(i);
        &row[..k.min(row.len())]
    }

    /// The underlying CSR lists.
    pub fn csr(&self) -> &Csr {
        &self.lists
    }
}

/// The `k` nearest neighbours of every point of `points` (finite coordinates), in parallel.
///
/// Errors when the cloud has fewer than `k + 1` points (a neighbourhood of k other points is
/// impossible) or `k` is 0.
pub fn knn(points: &[Point3], k: usize) -> Result<Neighborhoods> {
    if k == 0 {
        return Err(Error::InvalidArgument(
            "k nearest neighbours with k = 0".into(),
        ));
    }
    if points.len() < k + 1 {
        return Err(Error::InvalidInput(format!(
            "{} points: k-nearest-neighbour neighbourhoods with k = {k} need at least {} points",
            points.len(),
            k + 1
        )));
    }
    let index = KdIndex::new(points)
        .ok_or_else(|| Error::InvalidInput("cannot build a k-d tree over the points".into()))?;
    let rows: Vec<Vec<u32>> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| {
            let mut nn = index.nearest(p, k + 1);
            // Drop the point itself (wherever a coincident duplicate put it), keep k others.
            if let Some(pos) = nn.iter().position(|(j, _)| *j as usize == i) {
                nn.remove(pos);
            }
            nn.truncate(k);
            nn.into_iter().map(|(j, _)| j).collect()
        })
        .collect();
    let mut indices = Vec::with_capacity(points.len() * k);
    let mut offsets = Vec::with_capacity(points.len() + 1);
    offsets.push(0u32);
    for r in rows {
        indices.extend_from_slice(&r);
        offsets.push(indices.len() as u32);
    }
    Ok(Neighborhoods::from_csr(k, Csr { offsets, indices }))
}
