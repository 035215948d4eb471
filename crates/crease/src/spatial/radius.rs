//! Radius search for every point of a cloud, and k nearest neighbours capped by a radius.
//!
//! Same machinery as [`super::knn()`]: a Morton sort, a uniform grid whose cell side is a power of
//! two of quantisation units close to the radius, queries in Morton order, rows gathered back to
//! the input order. "Within r" means a squared distance `dx² + dy² + dz² ≤ r·r` evaluated in
//! f64; rows are sorted by distance then input index and exclude the point itself (but keep its
//! coincident duplicates).

use rayon::prelude::*;

use super::grid::{dist2, CellGrid};
use super::knn::{check_finite, knn, kth_distance_subsampled, Neighborhoods};
use super::morton::{morton_sorted, Quantizer, MORTON_BITS};
use crate::geometry::{Csr, Point3};
use crate::{Error, Result};

/// Queries per parallel task (rows of variable length are produced per task, then stitched).
const TASK: usize = 2048;

fn check_radius(r: f64) -> Result<()> {
    if !(r.is_finite() && r >= 0.0) {
        return Err(Error::InvalidArgument(format!(
            "radius search: the radius must be finite and non-negative, got {r}"
        )));
    }
    Ok(())
}

/// All neighbours within distance `r` of every point (itself excluded), nearest first, ties by
/// index, as CSR rows in input order.
///
/// Errors on a negative or non-finite radius, a non-finite coordinate, or more than 2^32 - 1
/// neighbour entries in total.
pub fn radius_neighbors(points: &[Point3], r: f64) -> Result<Csr> {
    check_radius(r)?;
    within(points, r, usize::MAX)
}

/// The k nearest neighbours of every point that lie within distance `r` (itself excluded),
/// nearest first, ties by index: rows have at most k entries (fewer where the ball holds fewer).
///
/// Errors on k = 0, a negative or non-finite radius, or a non-finite coordinate. A cloud of at
/// most k points is allowed (rows are then shorter).
pub fn knn_within(points: &[Point3], k: usize, r: f64) -> Result<Neighborhoods> {
    check_radius(r)?;
    if k == 0 {
        return Err(Error::InvalidArgument(
            "k nearest neighbours with k = 0".into(),
        ));
    }
    check_finite(points)?;
    let n = points.len();
    if n > k {
        // When the ball is larger than the typical k-neighbourhood, the kNN search is cheaper.
        if let Some(quant) = Quantizer::new(points) {
            let rk = kth_distance_subsampled(points, &quant, k);
            if r >= rk {
                let nb = knn(points, k)?;
                let lists = nb.into_csr();
                let r2 = r * r;
                let rows: Vec<u32> = (0..n)
                    .into_par_iter()
                    .flat_map_iter(|i| {
                        let row = lists.row(i);
                        let p = points[i];
                        row.iter()
                            .copied()
                            .filter(move |&j| dist2(&p, &points[j as usize]) <= r2)
                    })
                    .collect();
                let counts: Vec<u32> = (0..n)
                    .into_par_iter()
                    .map(|i| {
                        let p = points[i];
                        lists
                            .row(i)
                            .iter()
                            .filter(|&&j| dist2(&p, &points[j as usize]) <= r2)
                            .count() as u32
                    })
                    .collect();
                let offsets = Csr::offsets_from_counts(&counts);
                return Ok(Neighborhoods::from_csr(
                    k,
                    Csr {
                        offsets,
                        indices: rows,
                    },
                ));
            }
        }
    }
    Ok(Neighborhoods::from_csr(k, within(points, r, k)?))
}

/// Rows of the neighbours within `r`, each cut to its `cap` nearest.
fn within(points: &[Point3], r: f64, cap: usize) -> Result<Csr> {
    check_finite(points)?;
    let n = points.len();
    if n > u32::MAX as usize {
        return Err(Error::InvalidInput(format!(
            "{n} points: more than 2^32 - 1"
        )));
    }
    let Some(quant) = Quantizer::new(points) else {
        return Ok(Csr {
            offsets: vec![0],
            indices: Vec::new(),
        });
    };
    let sorted = morton_sorted(points, &quant);
    let level = if r > 0.0 {
        ((r / quant.unit).log2().round()).clamp(0.0, MORTON_BITS as f64) as u32
    } else {
        0
    };
    let grid = CellGrid::new(points, quant, &sorted, level);
    drop(sorted);
    let shells = ((r / grid.cell_size) * (1.0 + 1e-9) + 1e-12)
        .ceil()
        .max(1.0);
    let shells = if shells > 1e6 {
        i64::MAX
    } else {
        shells as i64
    };
    let r2 = r * r;
    let r2_bits = r2.to_bits();
    // Per task: (counts of its rows, concatenated rows), in Morton order.
    let tasks: Vec<(Vec<u32>, Vec<u32>)> = (0..n.div_ceil(TASK))
        .into_par_iter()
        .map(|t| {
            let mut counts = Vec::with_capacity(TASK);
            let mut rows = Vec::new();
            let mut cands: Vec<(u64, u32)> = Vec::new();
            for rk in t * TASK..((t + 1) * TASK).min(n) {
                let q = grid.points[rk];
                let c = grid.cell_of(&q);
                cands.clear();
                for s in 0..=shells {
                    grid.for_each_shell_cell(c, s, |cell| {
                        if grid.cell_min_dist2(&q, cell) > r2 {
                            return;
                        }
                        let range = grid.cell_range(cell);
                        for j in range {
                            let d = dist2(&q, &grid.points[j]).to_bits();
                            if d <= r2_bits && j != rk {
                                cands.push((d, grid.ids[j]));
                            }
                        }
                    });
                    if grid.covers_all(c, s) {
                        break;
                    }
                }
                if cands.len() > cap {
                    cands.select_nth_unstable(cap - 1);
                    cands.truncate(cap);
                }
                cands.sort_unstable();
                counts.push(cands.len() as u32);
                rows.extend(cands.iter().map(|c| c.1));
            }
            (counts, rows)
        })
        .collect();
    // Offsets of the rows in Morton order, then the rows in input order.
    let mut sorted_offsets = Vec::with_capacity(n + 1);
    sorted_offsets.push(0u64);
    let mut total = 0u64;
    for (counts, _) in &tasks {
        for &c in counts {
            total += c as u64;
            sorted_offsets.push(total);
        }
    }
    if total > u32::MAX as u64 {
        return Err(Error::InvalidInput(format!(
            "radius search with r = {r}: {total} neighbour entries, more than 2^32 - 1"
        )));
    }
    let flat: Vec<u32> = tasks.into_iter().flat_map(|(_, rows)| rows).collect();
    let mut rank = vec![0u32; n];
    for (rk, &i) in grid.ids.iter().enumerate() {
        rank[i as usize] = rk as u32;
    }
    let counts: Vec<u32> = rank
        .par_iter()
        .map(|&rk| (sorted_offsets[rk as usize + 1] - sorted_offsets[rk as usize]) as u32)
        .collect();
    let indices: Vec<u32> = rank
        .par_iter()
        .flat_map_iter(|&rk| {
            let (a, b) = (
                sorted_offsets[rk as usize] as usize,
                sorted_offsets[rk as usize + 1] as usize,
            );
            flat[a..b].iter().copied()
        })
        .collect();
    Ok(Csr {
        offsets: Csr::offsets_from_counts(&counts),
        indices,
    })
}
