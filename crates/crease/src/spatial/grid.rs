//! A uniform grid of cubic cells over Morton-sorted points, for exact all-points neighbour queries.
//!
//! The points are sorted along the Morton curve of their bounding box (21 bits per axis); a cell
//! of side `2^level` quantisation units is then a prefix of the Morton code, so the points of a
//! cell are contiguous in the sorted order and no second sort is needed. Non-empty cells are found
//! through an open-addressing hash table (memory proportional to the number of points, whatever
//! the extent of the cloud). Queries visit shells of cells of growing Chebyshev radius around the
//! query's cell and stop as soon as the shell's outer boundary is farther than the current k-th
//! neighbour, so the results are exact.

use rayon::prelude::*;

use crate::geometry::Point3;

use super::morton::{morton_encode, Quantizer, MORTON_BITS, MORTON_MAX};

/// Empty slot marker (Morton codes use 63 bits, so this is never a key).
const EMPTY: u64 = u64::MAX;

#[derive(Debug, Clone, Copy)]
struct Slot {
    key: u64,
    start: u32,
    end: u32,
}

/// The grid: sorted points, their input indices, and the cell table.
pub(crate) struct CellGrid {
    /// Points in Morton order.
    pub points: Vec<Point3>,
    /// Input index of each sorted point.
    pub ids: Vec<u32>,
    quant: Quantizer,
    level: u32,
    /// Side of a cell.
    pub cell_size: f64,
    max_cell: i64,
    /// Absolute slack on geometric bounds, covering rounding in the quantisation.
    margin: f64,
    table: Vec<Slot>,
    shift: u32,
}

#[inline]
fn hash(key: u64, shift: u32) -> usize {
    (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> shift) as usize
}

impl CellGrid {
    /// Builds the grid from the input points and their Morton-sorted (code, index) list, with
    /// cells of side `2^level` quantisation units (`level` ≤ 21).
    pub fn new(points: &[Point3], quant: Quantizer, sorted: &[(u64, u32)], level: u32) -> Self {
        let level = level.min(MORTON_BITS);
        let shift_code = 3 * level;
        let cell_key = |c: u64| if shift_code >= 64 { 0 } else { c >> shift_code };
        // In parallel: gathering 1M points in sorted order, a read from anywhere in the input
        // each, took 10 to 20 ms on one thread.
        let sorted_points: Vec<Point3> = sorted
            .par_iter()
            .map(|&(_, i)| points[i as usize])
            .collect();
        let ids: Vec<u32> = sorted.par_iter().map(|&(_, i)| i).collect();
        // Runs of equal cell keys.
        let mut cells: Vec<Slot> = Vec::new();
        let mut start = 0usize;
        while start < sorted.len() {
            let key = cell_key(sorted[start].0);
            let mut end = start + 1;
            while end < sorted.len() && cell_key(sorted[end].0) == key {
                end += 1;
            }
            cells.push(Slot {
                key,
                start: start as u32,
                end: end as u32,
            });
            start = end;
        }
        let capacity = (cells.len() * 2).next_power_of_two().max(16);
        let bits = capacity.trailing_zeros();
        let shift = 64 - bits;
        let mut table = vec![
            Slot {
                key: EMPTY,
                start: 0,
                end: 0
            };
            capacity
        ];
        let mask = capacity - 1;
        for c in cells {
            let mut h = hash(c.key, shift);
            while table[h].key != EMPTY {
                h = (h + 1) & mask;
            }
            table[h] = c;
        }
        let cell_size = quant.unit * (1u64 << level) as f64;
        CellGrid {
            points: sorted_points,
            ids,
            quant,
            level,
            cell_size,
            max_cell: (MORTON_MAX >> level) as i64,
            margin: quant.extent() * 1e-12,
            table,
            shift,
        }
    }

    /// The cell coordinates of `p`.
    #[inline]
    pub fn cell_of(&self, p: &Point3) -> [i64; 3] {
        let q = self.quant.quantize(p);
        [
            (q[0] >> self.level) as i64,
            (q[1] >> self.level) as i64,
            (q[2] >> self.level) as i64,
        ]
    }

    /// The range of sorted positions in cell `c` (empty when outside the grid or empty).
    #[inline]
    pub fn cell_range(&self, c: [i64; 3]) -> std::ops::Range<usize> {
        if c.iter().any(|&v| v < 0 || v > self.max_cell) {
            return 0..0;
        }
        let key = morton_encode([c[0] as u32, c[1] as u32, c[2] as u32]);
        let mask = self.table.len() - 1;
        let mut h = hash(key, self.shift);
        loop {
            let s = self.table[h];
            if s.key == key {
                return s.start as usize..s.end as usize;
            }
            if s.key == EMPTY {
                return 0..0;
            }
            h = (h + 1) & mask;
        }
    }

    /// Centre of cell `c`.
    #[inline]
    pub fn cell_centre(&self, c: [i64; 3]) -> Point3 {
        let h = 0.5 * self.cell_size;
        [
            self.lower(c[0], 0) + h,
            self.lower(c[1], 1) + h,
            self.lower(c[2], 2) + h,
        ]
    }

    /// Lower corner of cell `c` along axis `a`.
    #[inline]
    fn lower(&self, c: i64, a: usize) -> f64 {
        self.quant.origin[a] + c as f64 * self.cell_size
    }

    /// A lower bound (rounding slack removed) on the distance from `q` (in cell `c`) to any
    /// point outside the cube of cells within Chebyshev distance `s` of `c`; infinity when that
    /// cube covers the whole grid.
    #[inline]
    pub fn shell_bound(&self, q: &Point3, c: [i64; 3], s: i64) -> f64 {
        let mut b = f64::INFINITY;
        for a in 0..3 {
            if c[a] - s > 0 {
                b = b.min(q[a] - self.lower(c[a] - s, a));
            }
            if c[a] + s < self.max_cell {
                b = b.min(self.lower(c[a] + s + 1, a) - q[a]);
            }
        }
        b - self.margin
    }

    /// A lower bound (rounding slack removed) on the squared distance from `q` to cell `c`.
    #[inline]
    pub fn cell_min_dist2(&self, q: &Point3, c: [i64; 3]) -> f64 {
        let mut d2 = 0.0;
        for a in 0..3 {
            let lo = self.lower(c[a], a);
            let hi = lo + self.cell_size;
            let d = if q[a] < lo {
                lo - q[a]
            } else if q[a] > hi {
                q[a] - hi
            } else {
                0.0
            };
            let d = (d - self.margin).max(0.0);
            d2 += d * d;
        }
        d2
    }

    /// The inclusive range of cells (lowest and highest corner cell) that meet the axis-aligned
    /// box `q ± t`, widened by the rounding slack and clamped to the grid: every point within
    /// distance `t` of `q` lies in one of them.
    #[inline]
    pub fn cell_box(&self, q: &Point3, t: f64) -> ([i64; 3], [i64; 3]) {
        let t = t + self.margin;
        let lo = self.cell_of(&[q[0] - t, q[1] - t, q[2] - t]);
        let hi = self.cell_of(&[q[0] + t, q[1] + t, q[2] + t]);
        (lo, hi)
    }

    /// True when the cube of cells within Chebyshev distance `s` of `c` covers the whole grid.
    #[inline]
    pub fn covers_all(&self, c: [i64; 3], s: i64) -> bool {
        (0..3).all(|a| c[a] - s <= 0 && c[a] + s >= self.max_cell)
    }

    /// Calls `f(cell)` for every cell at Chebyshev distance exactly `s` from `c` that lies in
    /// the grid, in a fixed order.
    #[inline]
    pub fn for_each_shell_cell(&self, c: [i64; 3], s: i64, mut f: impl FnMut([i64; 3])) {
        if s == 0 {
            f(c);
            return;
        }
        let lo = |a: usize| (c[a] - s).max(0);
        let hi = |a: usize| (c[a] + s).min(self.max_cell);
        for z in lo(2)..=hi(2) {
            let zface = (z - c[2]).abs() == s;
            for y in lo(1)..=hi(1) {
                let yface = zface || (y - c[1]).abs() == s;
                if yface {
                    for x in lo(0)..=hi(0) {
                        f([x, y, z]);
                    }
                } else {
                    // Only the two x faces of this row belong to the shell.
                    if c[0] - s >= 0 {
                        f([c[0] - s, y, z]);
                    }
                    if c[0] + s <= self.max_cell {
                        f([c[0] + s, y, z]);
                    }
                }
            }
        }
    }
}

/// Squared Euclidean distance, always evaluated in the same order (exact ties are reproducible).
#[inline]
pub fn dist2(a: &Point3, b: &Point3) -> f64 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    dx * dx + dy * dy + dz * dz
}
