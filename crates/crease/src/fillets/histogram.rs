//! Multi-resolution histogram thresholding of demarsin2008 section 2.2.
//!
//! The curvature values of a smooth region are put in a start histogram of `L_start` equal bins
//! over `[min, max]` (section 2.1; the last bin also holds `max`). A threshold τ sits after a
//! peak: joining the k bins left of τ (from `start_curv = τ − k |bin|`) represents the peak by
//! one bin of frequency b1, joining the k bins right of τ represents (part of) the following
//! valley by b2, and τ maximises ε(τ, start_curv) = b1 / b2 (b1 when b2 = 0, as in the paper's
//! pseudo-code). [`Search::Full`] tries every start_curv = min + i |bin|, i = 0..L_start − 2, and
//! k = 1..⌊(L_start − i) / 2⌋; [`Search::OneRun`] is the paper's one-run variant
//! (start_curv = min only). Both run in O(L_start²) at most, which for L_start = 50 is nothing.
//!
//! Ties keep the first maximum in the order of the search (per τ the smallest start_curv, then
//! the smallest τ), so the result is deterministic.

use serde::Serialize;

/// Default start resolution (section 2.2: "L_start = 50 is sufficient").
pub const L_START: usize = 50;

/// Which start_curv values the search tries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Search {
    /// Every start_curv (section 2.2, "we consider all possible values").
    #[default]
    Full,
    /// start_curv = min(curv) only (the pseudo-code of section 2.2).
    OneRun,
}

/// A threshold found in a histogram.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Split {
    /// The threshold τ (in the values' units): low ≤ τ < high.
    pub tau: f64,
    /// The ratio ε(τ, start_curv) = b1 / b2 at the maximum.
    pub ratio: f64,
    /// start_curv of the maximum.
    pub start: f64,
    /// Number of joined bins k.
    pub joined: usize,
    /// b1: values in the joined peak bin.
    pub b1: u64,
    /// b2: values in the joined valley bin.
    pub b2: u64,
    /// b3: the most populated run of k bins after the valley (the next peak).
    pub b3: u64,
}

impl Split {
    /// b3 / b2 (b3 when b2 = 0): how far the valley lies below the peak after it.
    pub fn right_ratio(&self) -> f64 {
        if self.b2 != 0 {
            self.b3 as f64 / self.b2 as f64
        } else {
            self.b3 as f64
        }
    }
}

/// The start histogram of `values` (non-finite values are skipped) over `[lo, hi]` with `bins`
/// equal bins; values outside the range are not counted, `hi` falls in the last bin.
pub fn histogram(values: &[f64], lo: f64, hi: f64, bins: usize) -> Vec<u64> {
    let mut h = vec![0u64; bins.max(1)];
    let width = (hi - lo) / bins.max(1) as f64;
    if width.is_nan() || width <= 0.0 || !width.is_finite() {
        // All values equal: one bin holds them.
        h[0] = values
            .iter()
            .filter(|v| v.is_finite() && **v >= lo && **v <= hi)
            .count() as u64;
        return h;
    }
    for &v in values {
        if !v.is_finite() || v < lo || v > hi {
            continue;
        }
        let i = (((v - lo) / width) as usize).min(bins - 1);
        h[i] += 1;
    }
    h
}

/// The threshold of maximal ε over the values in `[lo, hi]` (see the module documentation), or
/// `None` when fewer than two bins are populated (nothing to split).
pub fn select(values: &[f64], lo: f64, hi: f64, bins: usize, search: Search) -> Option<Split> {
    ranked(values, lo, hi, bins, search).into_iter().next()
}

/// The candidate thresholds of `[lo, hi]` in decreasing ε: for every bin edge τ the best
/// ε(τ, start_curv) over the searched start_curv values, keeping the local maxima of ε along τ
/// (a neighbour of a rejected threshold is no better a valley). The first is [`select`]'s
/// answer. Used when the best split is rejected (section 2.3's "shift the threshold to a
/// previous or to a next valley", decided automatically).
pub fn ranked(values: &[f64], lo: f64, hi: f64, bins: usize, search: Search) -> Vec<Split> {
    if bins < 2 || hi.is_nan() || lo.is_nan() || hi <= lo {
        return Vec::new();
    }
    let h = histogram(values, lo, hi, bins);
    if h.iter().filter(|&&c| c > 0).count() < 2 {
        return Vec::new();
    }
    let width = (hi - lo) / bins as f64;
    let starts = match search {
        Search::Full => bins - 1,
        Search::OneRun => 1,
    };
    let mut at: Vec<Option<Split>> = vec![None; bins + 1];
    for s in 0..starts {
        let (mut b1, mut b2) = (0u64, 0u64);
        for k in 1..=(bins - s) / 2 {
            b1 += h[s + k - 1];
            b2 = b2 + h[s + 2 * k - 2] + h[s + 2 * k - 1] - h[s + k - 1];
            let ratio = if b2 != 0 {
                b1 as f64 / b2 as f64
            } else {
                b1 as f64
            };
            let t = s + k;
            if at[t].is_none_or(|b| ratio > b.ratio) {
                at[t] = Some(Split {
                    tau: lo + t as f64 * width,
                    ratio,
                    start: lo + s as f64 * width,
                    joined: k,
                    b1,
                    b2,
                    b3: 0,
                });
            }
        }
    }
    // b3 of every candidate from prefix sums.
    let mut prefix = vec![0u64; bins + 1];
    for i in 0..bins {
        prefix[i + 1] = prefix[i] + h[i];
    }
    for s in at.iter_mut().flatten() {
        let k = s.joined;
        let t = ((s.tau - lo) / width).round() as usize;
        // Windows of k bins after the valley, clipped at the histogram's end (a narrow top
        // mode may sit in the last few bins).
        s.b3 = (t + k..bins)
            .map(|j| prefix[(j + k).min(bins)] - prefix[j])
            .max()
            .unwrap_or(0);
    }
    let r = |t: usize| at.get(t).copied().flatten().map_or(-1.0, |s| s.ratio);
    let mut out: Vec<(usize, Split)> = (1..bins)
        .filter_map(|t| {
            let s = at[t]?;
            (s.ratio >= r(t - 1) && s.ratio >= r(t + 1)).then_some((t, s))
        })
        .collect();
    out.sort_by(|a, b| b.1.ratio.total_cmp(&a.1.ratio).then(a.0.cmp(&b.0)));
    out.into_iter().map(|(_, s)| s).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force of ε for one (s, k).
    fn eps(h: &[u64], s: usize, k: usize) -> (u64, u64) {
        (h[s..s + k].iter().sum(), h[s + k..s + 2 * k].iter().sum())
    }

    #[test]
    fn incremental_sums_match_brute_force() {
        // Values at bin centres of a 50-bin histogram over [0, 50].
        let counts: Vec<u64> = (0..50u64).map(|i| (i * 37 + 11) % 17).collect();
        let values: Vec<f64> = counts
            .iter()
            .enumerate()
            .flat_map(|(i, &c)| std::iter::repeat_n(i as f64 + 0.5, c as usize))
            .chain([0.0, 50.0])
            .collect();
        let h = histogram(&values, 0.0, 50.0, 50);
        let best = select(&values, 0.0, 50.0, 50, Search::Full).unwrap();
        let mut max = -1.0;
        let mut arg = (0, 0);
        for s in 0..49 {
            for k in 1..=(50 - s) / 2 {
                let (b1, b2) = eps(&h, s, k);
                let r = if b2 != 0 {
                    b1 as f64 / b2 as f64
                } else {
                    b1 as f64
                };
                if r > max {
                    max = r;
                    arg = (s, k);
                }
            }
        }
        assert_eq!(best.ratio, max);
        assert_eq!((best.start as usize, best.joined), arg);
        let (b1, b2) = eps(&h, arg.0, arg.1);
        assert_eq!((best.b1, best.b2), (b1, b2));
    }

    #[test]
    fn threshold_falls_in_the_valley_of_a_two_mode_histogram() {
        // A large mode around 1 and a small one around 6: the threshold lies between them.
        let mut v = Vec::new();
        for i in 0..2000 {
            v.push(1.0 + ((i * 7919) % 1000) as f64 / 1000.0 - 0.5);
        }
        for i in 0..300 {
            v.push(6.0 + ((i * 104729) % 1000) as f64 / 1000.0 - 0.5);
        }
        let s = select(&v, 0.5, 6.5, L_START, Search::Full).unwrap();
        assert!(s.tau >= 1.5 && s.tau <= 5.5, "{s:?}");
        let r = ranked(&v, 0.5, 6.5, L_START, Search::Full);
        assert_eq!(r[0], s);
        assert!(r.windows(2).all(|w| w[0].ratio >= w[1].ratio));
        let one = select(&v, 0.5, 6.5, L_START, Search::OneRun).unwrap();
        assert!(one.tau >= 1.5 && one.tau <= 5.5, "{one:?}");
    }

    #[test]
    fn constant_values_have_no_split() {
        assert!(select(&[2.0; 10], 2.0, 2.0, L_START, Search::Full).is_none());
        assert!(select(&[], 0.0, 1.0, L_START, Search::Full).is_none());
    }
}
