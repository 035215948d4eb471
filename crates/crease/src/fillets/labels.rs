//! Point labels of demarsin2008 section 3 and the region growing on them.
//!
//! A threshold τ splits a smooth region into *low* (curvature ≤ τ) and *high* points. The high
//! points are then *inner* (only high points in their 1-ring), *border* (the other high points
//! with at least two inner points in their 1-ring) or *noisy* (the rest, "added to the set of
//! low points"). The 1-ring is the symmetrised Delaunay 1-ring of demarsin2007 (the paper cites
//! Floater and Reimers' meshless 1-ring, which is the same construction).
//!
//! Region growing (section 3): from an inner or low seed, a cluster takes every adjacent point
//! with the same label; a point with another label becomes a one-point cluster. Inner and low
//! patches become large clusters surrounded by one-point clusters of border points, which is
//! what the cluster graph of demarsin2007 turns into closed lines. The paper picks seeds at
//! random; crease takes the lowest unlabelled index, so the result is deterministic.

use std::collections::VecDeque;

use rayon::prelude::*;
use serde::Serialize;

use crate::geometry::Csr;
use crate::lines::ClusterLabels;

/// The neighbours of point `i` (none when the adjacency has no row for it).
fn row_of(adjacency: &Csr, i: usize) -> &[u32] {
    if i < adjacency.num_rows() {
        adjacency.row(i)
    } else {
        &[]
    }
}

/// The label of a point for one threshold (section 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
#[repr(u8)]
pub enum Label {
    /// Curvature ≤ τ.
    Low = 0,
    /// High, with only high points in the 1-ring.
    Inner = 1,
    /// High, not inner, with at least two inner points in the 1-ring.
    Border = 2,
    /// High but neither inner nor border: an isolated noisy point, treated as low.
    Noisy = 3,
}

impl Label {
    /// The label a point grows with (noisy points join the low points).
    fn growth_class(self) -> Label {
        match self {
            Label::Noisy => Label::Low,
            l => l,
        }
    }
}

/// Labels every point of `values` (curvatures) for the threshold `tau` over the symmetric
/// adjacency `adjacency` (points without a row have no neighbours). Non-finite values are low.
pub fn label(values: &[f64], tau: f64, adjacency: &Csr) -> Vec<Label> {
    let high: Vec<bool> = values.iter().map(|&v| v > tau).collect();
    label_high(&high, adjacency)
}

/// Labels from a high / low split (see [`label`]).
pub fn label_high(high: &[bool], adjacency: &Csr) -> Vec<Label> {
    let len = high.len();
    let high = |i: usize| high[i];
    let row = |i: usize| row_of(adjacency, i);
    let inner: Vec<bool> = (0..len)
        .into_par_iter()
        .map(|i| high(i) && row(i).iter().all(|&q| high(q as usize)))
        .collect();
    (0..len)
        .into_par_iter()
        .map(|i| {
            if !high(i) {
                Label::Low
            } else if inner[i] {
                Label::Inner
            } else if row(i).iter().filter(|&&q| inner[q as usize]).count() >= 2 {
                Label::Border
            } else {
                Label::Noisy
            }
        })
        .collect()
}

/// Region growing on `labels` (see the module documentation).
pub fn grow(labels: &[Label], adjacency: &Csr) -> ClusterLabels {
    let n = labels.len();
    let mut out = vec![u32::MAX; n];
    let mut sizes: Vec<u32> = Vec::new();
    let mut queue = VecDeque::new();
    let row = |i: usize| row_of(adjacency, i);
    // Seeds are inner or low points first; border points never seed a cluster.
    for pass in 0..2 {
        for seed in 0..n {
            if out[seed] != u32::MAX {
                continue;
            }
            let class = labels[seed].growth_class();
            if pass == 0 && class == Label::Border {
                continue;
            }
            let id = sizes.len() as u32;
            out[seed] = id;
            sizes.push(1);
            if class == Label::Border {
                continue;
            }
            queue.push_back(seed as u32);
            while let Some(p) = queue.pop_front() {
                for &q in row(p as usize) {
                    let qi = q as usize;
                    if qi >= n || out[qi] != u32::MAX {
                        continue;
                    }
                    if labels[qi].growth_class() == class {
                        out[qi] = id;
                        sizes[id as usize] += 1;
                        queue.push_back(q);
                    } else {
                        // A point of another label: a cluster of its own.
                        out[qi] = sizes.len() as u32;
                        sizes.push(1);
                    }
                }
            }
        }
    }
    ClusterLabels { labels: out, sizes }
}

/// The largest connected set of points whose value lies in the band `(a, b]` together with
/// the values of their whole 1-ring: the interior of the band's patches. A band between two
/// thresholds that only holds the transition points between two patches has (almost) no
/// interior; a curvature patch has one as large as the patch.
pub fn band_interior(values: &[f64], a: f64, b: f64, adjacency: &Csr) -> usize {
    let n = values.len();
    let within = |i: usize| values[i] > a && values[i] <= b;
    let row = |i: usize| row_of(adjacency, i);
    let interior: Vec<bool> = (0..n)
        .into_par_iter()
        .map(|i| within(i) && row(i).iter().all(|&q| within(q as usize)))
        .collect();
    let mut seen = vec![false; n];
    let mut best = 0;
    let mut stack = Vec::new();
    for s in 0..n {
        if seen[s] || !interior[s] {
            continue;
        }
        seen[s] = true;
        stack.push(s);
        let mut size = 0;
        while let Some(p) = stack.pop() {
            size += 1;
            for &q in row(p) {
                let q = q as usize;
                if q < n && !seen[q] && interior[q] {
                    seen[q] = true;
                    stack.push(q);
                }
            }
        }
        best = best.max(size);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 1-D chain 0 - 1 - ... - (n-1).
    fn chain(n: usize) -> Csr {
        let rows: Vec<Vec<u32>> = (0..n as u32)
            .map(|i| {
                let mut r = Vec::new();
                if i > 0 {
                    r.push(i - 1);
                }
                if i + 1 < n as u32 {
                    r.push(i + 1);
                }
                r
            })
            .collect();
        let counts: Vec<u32> = rows.iter().map(|r| r.len() as u32).collect();
        Csr {
            offsets: Csr::offsets_from_counts(&counts),
            indices: rows.concat(),
        }
    }

    #[test]
    fn labels_and_growth_on_a_chain() {
        // A chain's inner points have both neighbours high; "two inner neighbours" cannot hold
        // at a border of a chain, so use a ladder-free check: values low-high-high-high-low.
        let adj = chain(9);
        let v = [0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0];
        let l = label(&v, 0.5, &adj);
        use Label::*;
        // 2 and 6 touch a low point and have one inner neighbour: noisy on a chain; 8 is
        // isolated: noisy.
        assert_eq!(
            l,
            vec![Low, Low, Noisy, Inner, Inner, Inner, Noisy, Low, Noisy]
        );
        let s = grow(&l, &adj);
        // Low + noisy 0..2 grow together; the low growth meets inner 3, which becomes a cluster
        // of its own (there is no border band on a chain); inner 4..5; noisy 6 met by the inner
        // growth is alone; low 7 and noisy 8 together.
        assert_eq!(s.labels, vec![0, 0, 0, 1, 2, 2, 3, 4, 4]);
        assert_eq!(band_interior(&v, 0.5, f64::INFINITY, &adj), 3);
        assert_eq!(band_interior(&v, f64::NEG_INFINITY, 0.5, &adj), 1);
    }

    #[test]
    fn border_points_become_single_clusters() {
        use Label::*;
        let adj = chain(5);
        let l = vec![Low, Border, Inner, Border, Low];
        let s = grow(&l, &adj);
        assert_eq!(s.sizes.len(), 5);
        assert!(s.sizes.iter().all(|&c| c == 1));
    }
}
