//! The decoded values of one property of an element: a column per property, or the raw bytes
//! of fixed-size binary rows decoded when the column is used.

use rayon::prelude::*;

use super::binary::read_scalar;
use super::header::PropType;
use crate::geometry::ScalarKind;

/// The decoded values of one property of an element.
#[derive(Debug, Clone)]
pub(super) enum Col<'a> {
    /// Not kept (skipped list, or an element crease does not read).
    Skipped,
    /// One value per row.
    Scalar(Vec<f64>),
    /// A property of fixed-size binary rows, not decoded yet: the value of row `i` is at byte
    /// `i * row_size + off` of `body`. Decoded straight into its final array when it is used.
    Raw(RawCol<'a>),
    /// Row `i` holds `items[offsets[i]..offsets[i + 1]]`.
    List {
        offsets: Vec<usize>,
        items: Vec<f64>,
    },
    /// A list property of binary rows whose lists all have `len` items (so the rows have a fixed
    /// size): item `k` of row `i` is at byte `i * row_size + off + k * kind.size()`.
    RawList { raw: RawCol<'a>, len: usize },
}

/// One property of the fixed-size rows of a binary element (see [`Col::Raw`]).
#[derive(Debug, Clone, Copy)]
pub(super) struct RawCol<'a> {
    pub(super) body: &'a [u8],
    pub(super) row_size: usize,
    pub(super) off: usize,
    pub(super) kind: ScalarKind,
    pub(super) be: bool,
}

impl RawCol<'_> {
    #[inline(always)]
    pub(super) fn get(&self, row: &[u8]) -> f64 {
        read_scalar(row, self.off, self.kind, self.be).unwrap_or(0.0)
    }

    /// Decodes every row with `f` in parallel.
    pub(super) fn decode<T: Send, F: Fn(&[u8]) -> T + Sync + Send>(&self, f: F) -> Vec<T> {
        let mut out = Vec::new();
        if self.row_size > 0 {
            self.body
                .par_chunks_exact(self.row_size)
                .map(f)
                .collect_into_vec(&mut out);
        }
        out
    }
}

impl Col<'_> {
    pub(super) fn new(want: bool, ty: PropType, rows: usize) -> Self {
        match (want, ty) {
            (false, _) => Col::Skipped,
            (true, PropType::Scalar(_)) => Col::Scalar(Vec::with_capacity(rows)),
            (true, PropType::List { .. }) => {
                let mut offsets = Vec::with_capacity(rows + 1);
                offsets.push(0);
                Col::List {
                    offsets,
                    items: Vec::with_capacity(rows.saturating_mul(3)),
                }
            }
        }
    }

    /// Appends `other`'s rows after self's.
    pub(super) fn append(&mut self, other: Self) {
        match (self, other) {
            (Col::Scalar(a), Col::Scalar(b)) => a.extend_from_slice(&b),
            (
                Col::List { offsets, items },
                Col::List {
                    offsets: o2,
                    items: i2,
                },
            ) => {
                let base = items.len();
                offsets.extend(o2.iter().skip(1).map(|o| o + base));
                items.extend_from_slice(&i2);
            }
            _ => {}
        }
    }
}
