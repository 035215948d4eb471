//! Compressed sparse row (CSR) lists: the one layout crease uses for every variable-length
//! per-element list (mesh incidences, neighbour lists, rings), as `../shared/DESIGN.md` asks.

use rayon::prelude::*;

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

    /// The undirected graph of a directed adjacency list (`rows` rows whose entries are row
    /// indices): row i holds every j with j in row(i) or i in row(j), sorted, without
    /// repetitions. Deterministic (rows are sorted in parallel, then compacted in order).
    pub fn symmetrized(&self) -> Csr {
        let n = self.num_rows();
        let mut counts = vec![0u32; n];
        for (p, row) in self.rows().enumerate() {
            counts[p] += row.len() as u32;
            for &q in row {
                counts[q as usize] += 1;
            }
        }
        let offsets = Csr::offsets_from_counts(&counts);
        let mut fill: Vec<u32> = offsets[..n].to_vec();
        let mut indices = vec![0u32; offsets[n] as usize];
        for (p, row) in self.rows().enumerate() {
            for &q in row {
                indices[fill[p] as usize] = q;
                fill[p] += 1;
                indices[fill[q as usize] as usize] = p as u32;
                fill[q as usize] += 1;
            }
        }
        // Sort and deduplicate every row in parallel, then compact.
        let mut slices: Vec<&mut [u32]> = Vec::with_capacity(n);
        let mut rest: &mut [u32] = &mut indices;
        for &c in &counts {
            let (head, tail) = rest.split_at_mut(c as usize);
            slices.push(head);
            rest = tail;
        }
        let lens: Vec<u32> = slices
            .par_iter_mut()
            .map(|row| {
                row.sort_unstable();
                let mut w = 0;
                for r in 0..row.len() {
                    if w == 0 || row[r] != row[w - 1] {
                        row[w] = row[r];
                        w += 1;
                    }
                }
                w as u32
            })
            .collect();
        let mut out = Vec::with_capacity(lens.iter().map(|&l| l as usize).sum());
        for (p, &l) in lens.iter().enumerate() {
            let start = offsets[p] as usize;
            out.extend_from_slice(&indices[start..start + l as usize]);
        }
        Csr {
            offsets: Csr::offsets_from_counts(&lens),
            indices: out,
        }
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
