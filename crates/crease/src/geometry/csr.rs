//! Compressed sparse row (CSR) lists: the one layout crease uses for every variable-length
//! per-element list (mesh incidences, neighbour lists, rings), as `../shared/DESIGN.md` asks.

/// A compressed sparse row list: row `i` is `indices[offsets[i]..offsets[i + 1]]`.
///
/// `offsets` has `rows + 1` entries, starts at 0 and never decreases; `indices` has
/// `offsets[rows]` entries.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Csr {
    /// Row starts, `rows + 1` entries.
    pub offsets: Vec<u32>,
    /// Concatenated rows.
    pub indices: Vec<u32>,
}

impl Csr {
    /// Number of rows.
    pub fn num_rows(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Row `i` (panics if `i >= num_rows()`).
    #[inline]
    pub fn row(&self, i: usize) -> &[u32] {
        &self.indices[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Length of row `i` (panics if `i >= num_rows()`).
    #[inline]
    pub fn row_len(&self, i: usize) -> usize {
        (self.offsets[i + 1] - self.offsets[i]) as usize
    }

    /// The rows in order.
    pub fn rows(&self) -> impl ExactSizeIterator<Item = &[u32]> + '_ {
        self.offsets
            .windows(2)
            .map(move |w| &self.indices[w[0] as usize..w[1] as usize])
    }

    /// Offsets from per-row counts (prefix sum); the last entry is the total.
    pub fn offsets_from_counts(counts: &[u32]) -> Vec<u32> {
        let mut offsets = Vec::with_capacity(counts.len() + 1);
        let mut acc = 0u32;
        offsets.push(0);
        for &c in counts {
            acc += c;
            offsets.push(acc);
        }
        offsets
    }

    /// A CSR list of `rows` rows of exactly `width` entries each, from their concatenation.
    pub fn from_fixed_width(rows: usize, width: usize, indices: Vec<u32>) -> Csr {
        debug_assert_eq!(indices.len(), rows * width);
        Csr {
            offsets: (0..=rows).map(|i| (i * width) as u32).collect(),
            indices,
        }
    }
}
