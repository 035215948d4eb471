//! Step 3: the thresholds of one region's curvature (demarsin2008 sections 2.2 and 2.3): the
//! candidates of the histogram, the tests that accept one, and the refinement below and above.

use super::histogram::{self, Split};
use super::labels::{self, Label};
use super::{
    FilletParams, ThresholdCount, ThresholdReport, INTERIOR_FACTOR, MAX_TRIES, MIN_CONTRAST,
    MIN_RATIO, MIN_RIGHT_RATIO,
};
use crate::geometry::Csr;
use crate::lines::LineNetwork;

/// Median of the finite values in `(a, b]` (NaN when there is none).
fn band_median(values: &[f64], a: f64, b: f64) -> f64 {
    let mut v: Vec<f64> = values
        .iter()
        .copied()
        .filter(|&x| x.is_finite() && x > a && x <= b)
        .collect();
    if v.is_empty() {
        return f64::NAN;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// The value below which a fraction `1 - trim` of the finite values lie.
fn upper_quantile(values: &[f64], trim: f64) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_unstable_by(f64::total_cmp);
    let lo = v[0];
    let k = (((v.len() - 1) as f64) * (1.0 - trim)).round() as usize;
    Some((lo, v[k.min(v.len() - 1)]))
}

pub(super) struct Candidate {
    pub(super) split: Split,
    pub(super) labels: Vec<Label>,
    /// Interiors of the interval's bands below and above τ.
    interiors: [usize; 2],
    contrast: f64,
    accepted: bool,
    /// The interval split (-∞ / +∞ at the ends of the value range).
    range: [f64; 2],
}

fn examine(
    values: &[f64],
    hist_range: (f64, f64),
    range: [f64; 2],
    adjacency: &Csr,
    params: &FilletParams,
) -> Option<Candidate> {
    let (lo, hi) = hist_range;
    let splits = histogram::ranked(
        values,
        range[0].max(lo),
        range[1].min(hi),
        params.bins,
        params.search,
    );
    let mut first = None;
    for split in splits.into_iter().take(MAX_TRIES) {
        if split.ratio < MIN_RATIO && first.is_some() {
            break;
        }
        let c = candidate(values, split, range, adjacency, params);
        if c.accepted {
            return Some(c);
        }
        first.get_or_insert(c);
    }
    first
}

/// Examines the split `split` of the interval `range`: the histogram tests first, then the
/// contrast of the medians, then the band interiors (each only when the cheaper ones pass), and
/// the labels only for an accepted split. Labels of a split taken anyway (a count or values
/// forced by the user) come from [`with_labels`].
fn candidate(
    values: &[f64],
    split: Split,
    range: [f64; 2],
    adjacency: &Csr,
    params: &FilletParams,
) -> Candidate {
    let min_patch = INTERIOR_FACTOR * params.curvature_k;
    let mut c = Candidate {
        split,
        labels: Vec::new(),
        interiors: [0, 0],
        contrast: 0.0,
        accepted: false,
        range,
    };
    if !(split.ratio >= MIN_RATIO
        && split.right_ratio() >= MIN_RIGHT_RATIO
        && split.b1.min(split.b3) >= min_patch as u64)
    {
        return c;
    }
    let medians = [
        band_median(values, range[0], split.tau),
        band_median(values, split.tau, range[1]),
    ];
    c.contrast = (medians[1] - medians[0]) / medians[1].abs().max(f64::MIN_POSITIVE);
    if c.contrast.is_nan() || c.contrast < MIN_CONTRAST {
        return c;
    }
    c.interiors = [
        labels::band_interior(values, range[0], split.tau, adjacency),
        labels::band_interior(values, split.tau, range[1], adjacency),
    ];
    c.accepted = c.interiors.iter().all(|&s| s >= min_patch);
    if c.accepted {
        c.labels = labels::label(values, split.tau, adjacency);
    }
    c
}

/// `c` accepted, with its labels.
fn with_labels(mut c: Candidate, values: &[f64], adjacency: &Csr) -> Candidate {
    if c.labels.is_empty() {
        c.labels = labels::label(values, c.split.tau, adjacency);
    }
    c.accepted = true;
    c
}

pub(super) type Selection = (f64, f64, Vec<Candidate>, Vec<Candidate>);

/// The thresholds of one region's curvature values (see [`ThresholdCount`]): the histogram
/// range after trimming, the chosen candidates in increasing τ and the rejected ones.
pub(super) fn select_thresholds(values: &[f64], adj: &Csr, params: &FilletParams) -> Selection {
    let (lo, hi) = upper_quantile(values, params.trim).unwrap_or((0.0, 0.0));
    let mut chosen: Vec<Candidate> = Vec::new();
    let mut rejected: Vec<Candidate> = Vec::new();
    match &params.thresholds {
        ThresholdCount::Manual(taus) => {
            for &tau in taus {
                let split = Split {
                    tau,
                    ratio: 0.0,
                    start: lo,
                    joined: 0,
                    b1: 0,
                    b2: 0,
                    b3: 0,
                };
                let c = candidate(
                    values,
                    split,
                    [f64::NEG_INFINITY, f64::INFINITY],
                    adj,
                    params,
                );
                chosen.push(with_labels(c, values, adj));
            }
        }
        ThresholdCount::Auto { max } => {
            // Breadth-first refinement: the whole range, then below and above each accepted τ.
            let mut queue = std::collections::VecDeque::from([[f64::NEG_INFINITY, f64::INFINITY]]);
            while let Some(range) = queue.pop_front() {
                if chosen.len() >= *max {
                    break;
                }
                let Some(c) = examine(values, (lo, hi), range, adj, params) else {
                    continue;
                };
                if c.accepted {
                    queue.push_back([range[0], c.split.tau]);
                    queue.push_back([c.split.tau, range[1]]);
                    chosen.push(c);
                } else {
                    rejected.push(c);
                }
            }
        }
        ThresholdCount::Exactly(count) => {
            // Greedy: split the interval whose best split has the largest ratio.
            let mut open: Vec<Candidate> = examine(
                values,
                (lo, hi),
                [f64::NEG_INFINITY, f64::INFINITY],
                adj,
                params,
            )
            .into_iter()
            .collect();
            while chosen.len() < *count && !open.is_empty() {
                let best = (0..open.len())
                    .max_by(|&a, &b| {
                        open[a]
                            .split
                            .ratio
                            .total_cmp(&open[b].split.ratio)
                            .then(b.cmp(&a))
                    })
                    .unwrap_or(0);
                let c = with_labels(open.swap_remove(best), values, adj);
                for r in [[c.range[0], c.split.tau], [c.split.tau, c.range[1]]] {
                    if let Some(next) = examine(values, (lo, hi), r, adj, params) {
                        open.push(next);
                    }
                }
                chosen.push(c);
            }
        }
    }
    chosen.sort_by(|a, b| a.split.tau.total_cmp(&b.split.tau));
    (lo, hi, chosen, rejected)
}

pub(super) fn report(c: &Candidate, net: Option<&LineNetwork>) -> ThresholdReport {
    let count = |l: Label| c.labels.iter().filter(|&&x| x == l).count();
    ThresholdReport {
        split: c.split,
        interval: c.range.map(|x| x.is_finite().then_some(x)),
        contrast: c.contrast,
        accepted: c.accepted,
        high: c.labels.len() - count(Label::Low),
        inner: count(Label::Inner),
        border: count(Label::Border),
        noisy: count(Label::Noisy),
        band_interiors: c.interiors,
        polylines: net.map_or(0, |n| n.polylines.len()),
        closed_loops: net.map_or(0, |n| n.closed_loops()),
    }
}
