//! Morton (Z-order) codes of 3D points: 21 bits per axis, quantised over the bounding box.
//!
//! Sorting points by their code puts points that are close in space close in memory, which is
//! what makes the all-points queries of [`super::knn()`] cache friendly whatever the input order.

use rayon::prelude::*;

use crate::geometry::Point3;

/// Bits per axis of a Morton code.
pub const MORTON_BITS: u32 = 21;

/// Largest quantised coordinate (2^21 - 1).
pub const MORTON_MAX: u32 = (1 << MORTON_BITS) - 1;

/// Spreads the low 21 bits of `v` so that bit i moves to bit 3i.
#[inline]
fn spread(v: u32) -> u64 {
    let mut x = (v & MORTON_MAX) as u64;
    x = (x | (x << 32)) & 0x001f_0000_0000_ffff;
    x = (x | (x << 16)) & 0x001f_0000_ff00_00ff;
    x = (x | (x << 8)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x << 4)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x << 2)) & 0x1249_2492_4924_9249;
    x
}

/// Inverse of [`spread`]: gathers bits 3i into bit i.
#[inline]
fn compact(v: u64) -> u32 {
    let mut x = v & 0x1249_2492_4924_9249;
    x = (x | (x >> 2)) & 0x10c3_0c30_c30c_30c3;
    x = (x | (x >> 4)) & 0x100f_00f0_0f00_f00f;
    x = (x | (x >> 8)) & 0x001f_0000_ff00_00ff;
    x = (x | (x >> 16)) & 0x001f_0000_0000_ffff;
    x = (x | (x >> 32)) & 0x1f_ffff;
    x as u32
}

/// Interleaves three 21-bit coordinates (x in the lowest bit of each triple).
#[inline]
pub fn morton_encode(c: [u32; 3]) -> u64 {
    spread(c[0]) | (spread(c[1]) << 1) | (spread(c[2]) << 2)
}

/// Inverse of [`morton_encode`].
#[inline]
pub fn morton_decode(code: u64) -> [u32; 3] {
    [compact(code), compact(code >> 1), compact(code >> 2)]
}

/// Maps points to 21-bit integer coordinates over a cube containing their bounding box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantizer {
    /// Lower corner of the bounding box.
    pub origin: Point3,
    /// Size of one quantisation step (the cube's side / 2^21), > 0.
    pub unit: f64,
    inv_unit: f64,
}

impl Quantizer {
    /// The quantiser of `points` (finite coordinates); `None` for an empty slice.
    pub fn new(points: &[Point3]) -> Option<Self> {
        let first = *points.first()?;
        let (lo, hi) = points
            .par_iter()
            .fold(
                || (first, first),
                |(mut lo, mut hi), p| {
                    for a in 0..3 {
                        lo[a] = lo[a].min(p[a]);
                        hi[a] = hi[a].max(p[a]);
                    }
                    (lo, hi)
                },
            )
            .reduce(
                || (first, first),
                |(mut lo, mut hi), (l, h)| {
                    for a in 0..3 {
                        lo[a] = lo[a].min(l[a]);
                        hi[a] = hi[a].max(h[a]);
                    }
                    (lo, hi)
                },
            );
        let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f64, f64::max);
        // A degenerate box (one point, or all points equal) still gets a positive unit.
        let extent = if extent > 0.0 && extent.is_finite() {
            extent
        } else {
            1.0
        };
        let unit = extent / (1u64 << MORTON_BITS) as f64;
        Some(Quantizer {
            origin: lo,
            unit,
            inv_unit: 1.0 / unit,
        })
    }

    /// A quantiser with the same origin whose cells of some level `L` have side exactly `cell`
    /// (`unit = cell / 2^L`, the largest `L` ≤ 21 whose cube of 2^21 units still covers this
    /// one), with that level; `None` when no level can (`cell` finer than this quantiser's
    /// unit, or not positive and finite).
    pub fn with_cell(&self, cell: f64) -> Option<(Quantizer, u32)> {
        if !(cell.is_finite() && cell > 0.0) {
            return None;
        }
        let extent = self.extent();
        let mut level = MORTON_BITS;
        // Largest level with 2^(21 - level) * cell >= extent.
        while level > 0 && ((1u64 << (MORTON_BITS - level)) as f64) * cell < extent {
            level -= 1;
        }
        let unit = cell / (1u64 << level) as f64;
        if unit * ((1u64 << MORTON_BITS) as f64) < extent || unit <= 0.0 || unit.is_nan() {
            return None;
        }
        Some((
            Quantizer {
                origin: self.origin,
                unit,
                inv_unit: 1.0 / unit,
            },
            level,
        ))
    }

    /// The side of the quantised cube (2^21 units).
    pub fn extent(&self) -> f64 {
        self.unit * (1u64 << MORTON_BITS) as f64
    }

    /// Integer coordinates of `p`, clamped to `0..=2^21-1`.
    #[inline]
    pub fn quantize(&self, p: &Point3) -> [u32; 3] {
        let q = |a: usize| {
            let v = (p[a] - self.origin[a]) * self.inv_unit;
            // `as` saturates: negative and NaN give 0.
            (v as u32).min(MORTON_MAX)
        };
        [q(0), q(1), q(2)]
    }

    /// The Morton code of `p`.
    #[inline]
    pub fn code(&self, p: &Point3) -> u64 {
        morton_encode(self.quantize(p))
    }
}

/// (Morton code, index) of every point, sorted by code then index (parallel sort).
pub fn morton_sorted(points: &[Point3], quantizer: &Quantizer) -> Vec<(u64, u32)> {
    let mut keys: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (quantizer.code(p), i as u32))
        .collect();
    keys.par_sort_unstable();
    keys
}

/// (Morton code, index) of every point, sorted by the cell of side 2^`level` units (the code
/// shifted right by 3·level), in input order within a cell: all that a [`super::grid::CellGrid`]
/// of that level needs, as the points of each cell are then contiguous and the cells in Morton
/// order.
///
/// A stable least-significant-digit radix sort on the cell key alone, which has far fewer bits
/// than the code at the cell sizes of a neighbour search (8 per axis for 1M points on a cube's
/// faces: two passes of 12 bits), instead of a comparison sort of the whole 63-bit code
/// (faster than [`morton_sorted`], see `docs/experiments/knn-and-normals.md`). Stable, so the
/// result does not depend on how the work is split.
pub(crate) fn cell_sorted(points: &[Point3], quantizer: &Quantizer, level: u32) -> Vec<(u64, u32)> {
    let shift = 3 * level.min(MORTON_BITS);
    let cell = |c: u64| if shift >= 64 { 0 } else { c >> shift };
    let mut keys: Vec<(u64, u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (quantizer.code(p), i as u32))
        .collect();
    let top = keys.par_iter().map(|&(c, _)| cell(c)).max().unwrap_or(0);
    let bits = 64 - top.leading_zeros();
    if bits == 0 {
        return keys;
    }
    let passes = bits.div_ceil(RADIX_BITS);
    let width = bits.div_ceil(passes);
    let buckets = 1usize << width;
    let mask = (buckets - 1) as u64;
    let mut other = vec![(0u64, 0u32); keys.len()];
    for pass in 0..passes {
        let digit_shift = pass * width;
        let digit = |c: u64| ((cell(c) >> digit_shift) & mask) as usize;
        let mut start = vec![0usize; buckets];
        for &(c, _) in &keys {
            start[digit(c)] += 1;
        }
        let mut acc = 0;
        for s in start.iter_mut() {
            (*s, acc) = (acc, acc + *s);
        }
        for &item in &keys {
            let d = digit(item.0);
            other[start[d]] = item;
            start[d] += 1;
        }
        std::mem::swap(&mut keys, &mut other);
    }
    keys
}

/// Largest digit of [`cell_sorted`]'s radix passes, in bits (4096 buckets of counts: a few
/// kilobytes, in the L1 cache).
const RADIX_BITS: u32 = 12;

/// The permutation that sorts `points` along the Morton curve of their bounding box (ties by
/// index): `order[r]` is the input index of the point at rank `r`.
pub fn morton_order(points: &[Point3]) -> Vec<u32> {
    let Some(q) = Quantizer::new(points) else {
        return Vec::new();
    };
    morton_sorted(points, &q)
        .into_iter()
        .map(|(_, i)| i)
        .collect()
}

/// The Morton order of the distinct points of `points`: exact duplicates (equal coordinates;
/// `-0.0` equals `0.0`) collapse into the first of them. `order[r]` is the input index of the
/// first (lowest-index) point at rank `r`, `rank[i]` the rank of input point `i`'s position.
/// Without duplicates `order` is [`morton_order`]'s, unless two distinct points share a code
/// (a cell of 2⁻²¹ of the box): those are ranked by coordinates, not index. `None` for no
/// points; the coordinates must be finite.
///
/// Duplicates share a code, so they are found by sorting each run of equal codes by
/// coordinates (runs are one point long but where the sampling is finer than the cells):
/// a cloud sampled twice over, or a scanner's repeated returns, costs no extra pass.
pub fn morton_order_unique(points: &[Point3]) -> Option<(Vec<u32>, Vec<u32>)> {
    let q = Quantizer::new(points)?;
    let key = |i: u32| points[i as usize].map(|v| (v + 0.0).to_bits());
    let mut keys = morton_sorted(points, &q);
    keys.par_chunk_by_mut(|a, b| a.0 == b.0)
        .filter(|run| run.len() > 1)
        .for_each(|run| run.sort_unstable_by_key(|&(_, i)| (key(i), i)));
    let first: Vec<bool> = (0..keys.len())
        .into_par_iter()
        .map(|r| r == 0 || keys[r - 1].0 != keys[r].0 || key(keys[r - 1].1) != key(keys[r].1))
        .collect();
    let order: Vec<u32> = keys
        .par_iter()
        .zip(&first)
        .filter(|(_, &f)| f)
        .map(|(&(_, i), _)| i)
        .collect();
    let mut rank = vec![0u32; points.len()];
    let mut r = 0u32;
    for (k, (&(_, i), &f)) in keys.iter().zip(&first).enumerate() {
        if f && k > 0 {
            r += 1;
        }
        rank[i as usize] = r;
    }
    Some((order, rank))
}

/// The distinct points of a cloud in input order ([`distinct_in_input_order`]).
#[derive(Debug, Clone)]
pub struct Distinct {
    /// Input index of the first copy of each distinct point, ascending.
    pub first: Vec<u32>,
    /// The distinct points (`points[first[u]]`).
    pub points: Vec<Point3>,
    /// For every input point, the index of its copy among the distinct points.
    pub of: Vec<u32>,
}

impl Distinct {
    /// Per-input values (normals, ...) for the distinct points: their first copies'.
    pub fn pick<T: Copy + Send + Sync>(&self, per_input: &[T]) -> Vec<T> {
        self.first
            .par_iter()
            .map(|&i| per_input[i as usize])
            .collect()
    }

    /// Per-distinct-point results for every input point: each copy takes its original's.
    pub fn expand<T: Copy + Send + Sync>(&self, per_distinct: &[T]) -> Vec<T> {
        gather(&self.of, per_distinct)
    }
}

/// `values[rows[i]]` for every i: per-row results given to the input points (`rows[i]`: the
/// row of input point i, e.g. [`Distinct::of`]).
pub fn gather<T: Copy + Send + Sync>(rows: &[u32], values: &[T]) -> Vec<T> {
    rows.par_iter().map(|&r| values[r as usize]).collect()
}

/// The distinct points of `points` in input order, when some repeat exactly (equal
/// coordinates, found by [`morton_order_unique`]). `None` when no point repeats another, or a
/// coordinate is not finite (the pipelines report that themselves). For the pipelines whose
/// results depend on the point order: a cloud without duplicates is processed as it was.
pub fn distinct_in_input_order(points: &[Point3]) -> Option<Distinct> {
    if !points.par_iter().all(|p| p.iter().all(|v| v.is_finite())) {
        return None;
    }
    let (order, rank) = morton_order_unique(points)?;
    if order.len() == points.len() {
        return None;
    }
    let mut first = order.clone();
    first.par_sort_unstable();
    // Position in `first` of each Morton rank's point.
    let pos: Vec<u32> = order
        .par_iter()
        .map(|i| first.partition_point(|f| f < i) as u32)
        .collect();
    let of = rank.par_iter().map(|&r| pos[r as usize]).collect();
    let points = first.par_iter().map(|&i| points[i as usize]).collect();
    Some(Distinct { first, points, of })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encode_decode_round_trip() {
        for c in [
            [0, 0, 0],
            [1, 2, 3],
            [MORTON_MAX, 0, 12345],
            [MORTON_MAX; 3],
        ] {
            assert_eq!(morton_decode(morton_encode(c)), c);
        }
        assert_eq!(morton_encode([1, 0, 0]), 1);
        assert_eq!(morton_encode([0, 1, 0]), 2);
        assert_eq!(morton_encode([0, 0, 1]), 4);
        assert_eq!(morton_encode([2, 0, 0]), 8);
    }

    #[test]
    fn fitted_quantiser_has_the_asked_cell_side() {
        let pts: Vec<Point3> = vec![[0.0, 0.0, 0.0], [3.7, 1.0, -2.0], [1.0, 9.3, 0.5]];
        let q = Quantizer::new(&pts).unwrap();
        for cell in [0.013, 0.1, 0.77, 5.0, 50.0] {
            let (f, level) = q.with_cell(cell).unwrap();
            let side = f.unit * (1u64 << level) as f64;
            assert!((side - cell).abs() <= 1e-12 * cell, "{cell}: {side}");
            assert!(
                f.extent() >= q.extent(),
                "{cell}: the fitted cube must cover the box"
            );
            // Every point still quantises inside the cube.
            for p in &pts {
                assert!(f.quantize(p).iter().all(|&c| c <= MORTON_MAX));
            }
        }
        // Finer than 2^21 cells over the box, or not a length: no fitted quantiser.
        assert!(q.with_cell(q.extent() * 1e-7).is_none());
        assert!(q.with_cell(0.0).is_none());
        assert!(q.with_cell(f64::NAN).is_none());
    }

    #[test]
    fn order_is_a_permutation_grouping_octants() {
        let pts: Vec<Point3> = (0..64)
            .map(|i| [(i % 4) as f64, ((i / 4) % 4) as f64, (i / 16) as f64])
            .collect();
        let order = morton_order(&pts);
        let mut seen = order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..64).collect::<Vec<u32>>());
        // The first 8 points of the Z-order are the 2x2x2 block at the origin.
        for &i in &order[..8] {
            let p = pts[i as usize];
            assert!(p[0] < 2.0 && p[1] < 2.0 && p[2] < 2.0, "{p:?}");
        }
    }

    #[test]
    fn cell_sort_is_stable_by_cell_key() {
        // Pseudo-random points, many per cell at the coarser levels.
        use rand::{Rng, SeedableRng};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut rnd = || rng.random_range(0.0..1.0);
        let pts: Vec<Point3> = (0..20_000).map(|_| [rnd(), rnd(), rnd()]).collect();
        let q = Quantizer::new(&pts).unwrap();
        for level in [0, 5, 13, 17, 20, 21] {
            let sorted = cell_sorted(&pts, &q, level);
            let full = morton_sorted(&pts, &q);
            let key = |c: u64| c >> (3 * level);
            // The same cells in the same order as the full Morton sort...
            let cells = |v: &[(u64, u32)]| v.iter().map(|&(c, _)| key(c)).collect::<Vec<_>>();
            assert_eq!(cells(&sorted), cells(&full), "level {level}");
            // ...a permutation with the codes of its points, input order within a cell.
            let mut ids: Vec<u32> = sorted.iter().map(|&(_, i)| i).collect();
            for w in sorted.windows(2) {
                assert!(
                    key(w[0].0) < key(w[1].0) || w[0].1 < w[1].1,
                    "level {level}"
                );
            }
            assert!(sorted.iter().all(|&(c, i)| c == q.code(&pts[i as usize])));
            ids.sort_unstable();
            assert_eq!(ids, (0..pts.len() as u32).collect::<Vec<_>>());
        }
    }
}
