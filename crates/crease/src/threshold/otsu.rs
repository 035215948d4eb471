//! Otsu's threshold (Otsu 1979) on the histogram of a score, as tran et al. use it to select the
//! projected-distance threshold automatically (section 3.2, equation 4).
//!
//! The scores are normalised to [0, 1] (tran section 3.2: "every projected distance is
//! normalized between \[0,1\]"), binned into a histogram, and the bin boundary that maximises the
//! between-class variance ω₀ω₁(μ₀ − μ₁)² is the threshold T; a value is in the upper class when
//! it is ≥ T (equation 4). The paper does not give the number of bins: 256, the usual grey-level
//! count of Otsu's method, is the default.
//!
//! **Range of the normalisation (a choice the paper leaves open).** Normalising by the minimum
//! and maximum lets one outlier squeeze every other value into the first few bins, where Otsu's
//! split degenerates (on a real scan with one stray point, all of the part falls into one bin).
//! [`OtsuParams::upper_quantile`] sets the top of the histogram at a high quantile of the values
//! instead (values above it fall into the last bin); the default 1.0 is the paper's min-max
//! normalisation. The threshold is returned in the units of the input values, so it applies to
//! the un-normalised scores directly.
//!
//! The histogram is counted in parallel with integer counts, so the result does not depend on
//! the thread count.

use rayon::prelude::*;

use crate::{Error, Result};

/// Parameters of [`otsu`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OtsuParams {
    /// Number of histogram bins (default 256).
    pub bins: usize,
    /// The top of the histogram as a quantile of the values in (0, 1] (default 1.0: the
    /// maximum, the paper's min-max normalisation).
    pub upper_quantile: f64,
}

impl OtsuParams {
    /// Errors (`InvalidArgument`) on fewer than 2 bins or an upper quantile outside (0, 1].
    pub fn validate(&self) -> Result<()> {
        if self.bins < 2 {
            return Err(Error::InvalidArgument(format!(
                "Otsu threshold with {} histogram bins (at least 2)",
                self.bins
            )));
        }
        let q = self.upper_quantile;
        if !(q > 0.0 && q <= 1.0) {
            return Err(Error::InvalidArgument(format!(
                "Otsu threshold: upper quantile must be in (0, 1], got {q}"
            )));
        }
        Ok(())
    }
}

impl Default for OtsuParams {
    fn default() -> Self {
        OtsuParams {
            bins: 256,
            upper_quantile: 1.0,
        }
    }
}

/// The result of [`otsu`].
#[derive(Debug, Clone, PartialEq)]
pub struct Otsu {
    /// The threshold T in the units of the input values: a value is in the upper class when it
    /// is ≥ T.
    pub threshold: f64,
    /// T normalised to [0, 1] over the histogram range (the figure tran plots in Fig. 4b).
    pub normalized: f64,
    /// The histogram range (lowest value, top of the last bin).
    pub range: (f64, f64),
    /// The between-class variance at T, in normalised units (0 when all values are equal).
    pub between_variance: f64,
    /// Number of values ≥ T.
    pub upper_count: usize,
    /// The histogram counts.
    pub histogram: Vec<u64>,
}

/// Otsu's threshold of `values` (see the module documentation).
///
/// Errors when `values` is empty, holds a non-finite value, or the parameters are invalid. When
/// all values are equal there is no split: the threshold is just above them (no value in the
/// upper class) and `between_variance` is 0.
pub fn otsu(values: &[f64], params: &OtsuParams) -> Result<Otsu> {
    params.validate()?;
    let q = params.upper_quantile;
    if values.is_empty() {
        return Err(Error::InvalidArgument(
            "Otsu threshold of an empty set of values".into(),
        ));
    }
    if let Some(i) = values.par_iter().position_first(|v| !v.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "Otsu threshold: value {i} is not finite ({})",
            values[i]
        )));
    }
    let (lo, max) = values
        .par_iter()
        .fold(
            || (f64::INFINITY, f64::NEG_INFINITY),
            |(a, b), &v| (a.min(v), b.max(v)),
        )
        .reduce(
            || (f64::INFINITY, f64::NEG_INFINITY),
            |(a, b), (c, d)| (a.min(c), b.max(d)),
        );
    let hi = if q < 1.0 {
        quantile(values, q).max(lo)
    } else {
        max
    };
    let histogram = histogram(values, lo, hi, params.bins);
    Ok(otsu_of_histogram(histogram, lo, hi, max))
}

/// The histogram of `values` in `bins` equal bins over [`lo`, `hi`] (values above `hi` in the
/// last bin; all in the first when `hi` ≤ `lo`), as [`otsu`] counts it. Histograms of parts of
/// a set of values over the same range add up to the set's: a cloud cut into tiles
/// ([`crate::sharp::tiled`]) gets the same threshold as the whole.
pub fn histogram(values: &[f64], lo: f64, hi: f64, bins: usize) -> Vec<u64> {
    let bins = bins.max(1);
    if hi <= lo {
        let mut h = vec![0u64; bins];
        h[0] = values.len() as u64;
        return h;
    }
    let width = (hi - lo) / bins as f64;
    let bin_of = |v: f64| (((v - lo) / width) as usize).min(bins - 1);
    values
        .par_chunks(1 << 14)
        .map(|chunk| {
            let mut h = vec![0u64; bins];
            for &v in chunk {
                h[bin_of(v)] += 1;
            }
            h
        })
        .reduce(
            || vec![0u64; bins],
            |mut a, b| {
                a.iter_mut().zip(&b).for_each(|(x, y)| *x += y);
                a
            },
        )
}

/// Otsu's threshold from the [`histogram`] over [`lo`, `hi`] of values whose largest is `max`
/// (what [`otsu`] does once it has counted; `upper_count` is read from the bins).
pub fn otsu_of_histogram(histogram: Vec<u64>, lo: f64, hi: f64, max: f64) -> Otsu {
    let bins = histogram.len();
    if hi <= lo || bins < 2 {
        return Otsu {
            threshold: next_up(max),
            normalized: 1.0,
            range: (lo, hi),
            between_variance: 0.0,
            upper_count: 0,
            histogram,
        };
    }
    let width = (hi - lo) / bins as f64;
    let bin_of = |v: f64| (((v - lo) / width) as usize).min(bins - 1);
    let (t, between_variance) = otsu_bin(&histogram);
    // Class 1 starts at bin t + 1; its lower edge in value units.
    let normalized = (t + 1) as f64 / bins as f64;
    let threshold = lo + (t + 1) as f64 * width;
    // The count of values ≥ threshold must agree with the bins (rounding at the edge).
    let threshold = if bin_of(threshold) == t + 1 || t + 1 >= bins {
        threshold
    } else {
        next_up(threshold)
    };
    let upper_count = histogram[(t + 1).min(bins)..].iter().sum::<u64>() as usize;
    Otsu {
        threshold,
        normalized,
        range: (lo, hi),
        between_variance,
        upper_count,
        histogram,
    }
}

/// The bin t maximising the between-class variance when class 0 is bins 0..=t (first maximum on
/// ties), and that variance in units of bins normalised to [0, 1].
pub fn otsu_bin(histogram: &[u64]) -> (usize, f64) {
    let bins = histogram.len();
    let total: u64 = histogram.iter().sum();
    if total == 0 || bins < 2 {
        return (0, 0.0);
    }
    let total = total as f64;
    let centre = |b: usize| (b as f64 + 0.5) / bins as f64;
    let sum_all: f64 = histogram
        .iter()
        .enumerate()
        .map(|(b, &c)| c as f64 * centre(b))
        .sum();
    let mut w0 = 0.0;
    let mut sum0 = 0.0;
    let mut best = (0usize, -1.0f64);
    for (t, &c) in histogram.iter().enumerate().take(bins - 1) {
        w0 += c as f64;
        sum0 += c as f64 * centre(t);
        let w1 = total - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let m0 = sum0 / w0;
        let m1 = (sum_all - sum0) / w1;
        let var = (w0 / total) * (w1 / total) * (m0 - m1) * (m0 - m1);
        if var > best.1 {
            best = (t, var);
        }
    }
    if best.1 < 0.0 {
        // A single occupied bin: no split.
        let last = histogram.iter().rposition(|&c| c > 0).unwrap_or(0);
        return (last.min(bins - 2), 0.0);
    }
    best
}

/// The q-quantile of `values` (nearest rank), by selection on a copy.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    let r = ((q.clamp(0.0, 1.0) * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
    let (_, x, _) = v.select_nth_unstable_by(r, f64::total_cmp);
    *x
}

/// The smallest f64 larger than `x` (finite x).
fn next_up(x: f64) -> f64 {
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let b = x.to_bits();
    f64::from_bits(if x > 0.0 { b + 1 } else { b - 1 })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bimodal_split_between_modes() {
        let mut v: Vec<f64> = (0..1000).map(|i| (i % 10) as f64 * 0.01).collect();
        v.extend((0..100).map(|i| 0.9 + (i % 10) as f64 * 0.01));
        let r = otsu(&v, &OtsuParams::default()).unwrap();
        assert!(r.threshold > 0.09 && r.threshold <= 0.9, "{}", r.threshold);
        assert_eq!(r.upper_count, 100);
        assert!(r.between_variance > 0.05, "{}", r.between_variance);
    }

    #[test]
    fn threshold_is_affine_equivariant() {
        let v: Vec<f64> = (0..500)
            .map(|i| ((i * 7919) % 997) as f64 / 997.0)
            .map(|x| x * x * x)
            .collect();
        let a = otsu(&v, &OtsuParams::default()).unwrap();
        let w: Vec<f64> = v.iter().map(|x| 3.0 * x + 5.0).collect();
        let b = otsu(&w, &OtsuParams::default()).unwrap();
        assert_eq!(a.upper_count, b.upper_count);
        assert!((b.threshold - (3.0 * a.threshold + 5.0)).abs() < 1e-9);
    }

    #[test]
    fn equal_values_have_no_upper_class() {
        let r = otsu(&[2.0; 10], &OtsuParams::default()).unwrap();
        assert_eq!(r.upper_count, 0);
        assert!(r.threshold > 2.0);
    }

    #[test]
    fn quantile_range_resists_one_outlier() {
        // 900 small values, 100 mid values, one huge outlier.
        let mut v: Vec<f64> = (0..900).map(|i| (i % 30) as f64 * 1e-3).collect();
        v.extend((0..100).map(|i| 1.0 + (i % 10) as f64 * 0.01));
        v.push(1e6);
        let plain = otsu(&v, &OtsuParams::default()).unwrap();
        assert_eq!(plain.upper_count, 1, "min-max: only the outlier is above");
        let robust = otsu(
            &v,
            &OtsuParams {
                upper_quantile: 0.99,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(robust.upper_count, 101);
    }

    #[test]
    fn rejects_bad_input() {
        assert!(otsu(&[], &OtsuParams::default()).is_err());
        assert!(otsu(&[1.0, f64::NAN], &OtsuParams::default()).is_err());
        assert!(otsu(
            &[1.0, 2.0],
            &OtsuParams {
                bins: 1,
                ..Default::default()
            }
        )
        .is_err());
    }
}
