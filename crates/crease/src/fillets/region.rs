//! One smooth region end to end (steps 2 to 4): its curvature, its thresholds, the labels and
//! the lines of each threshold, and its share of the per-point outputs.

use std::time::Instant;

use super::curvature::{region_curvature, taubin};
use super::labels::{self, Label};
use super::smooth_regions::{local_adjacency, Shared};
use super::thresholds::{report, select_thresholds};
use super::{FilletParams, Fillets, RegionReport, ThresholdCount};
use crate::geometry::Point3;
use crate::lines::{self, Smoothing};
use crate::Result;

pub(super) fn process_region(
    points: &[Point3],
    ids: &[u32],
    cluster: u32,
    shared: &Shared,
    params: &FilletParams,
    out: &mut Fillets,
    region_id: u32,
) -> Result<RegionReport> {
    let t = Instant::now();
    let adj = local_adjacency(ids, cluster, shared);
    let original: Vec<Point3> = ids.iter().map(|&i| points[i as usize]).collect();
    let smoothed = taubin(&original, &adj, params.smoothing_iterations);
    let mut values = region_curvature(&smoothed, params.curvature_k, params.median_iterations)?;
    out.seconds.curvature += t.elapsed().as_secs_f64();
    let t = Instant::now();
    let (mut lo, mut hi, mut chosen, mut rejected) = select_thresholds(&values, &adj, params);
    out.seconds.thresholds += t.elapsed().as_secs_f64();
    let mut curvature_k = params.curvature_k;
    // Nothing found in a noisy region may be the quadric's curvature noise at k hiding the
    // valley: once more with 2k (curvature noise falls about as k^-1.5), accepted only with the
    // tests at 2k (patch interiors of 6k points).
    if chosen.is_empty()
        && params.coarse_retry
        && matches!(params.thresholds, ThresholdCount::Auto { .. })
        && ids.len() > 2 * params.curvature_k
    {
        let t = Instant::now();
        let coarse = FilletParams {
            curvature_k: 2 * params.curvature_k,
            ..params.clone()
        };
        let coarse_values =
            region_curvature(&smoothed, coarse.curvature_k, params.median_iterations)?;
        out.seconds.curvature += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let (clo, chi, cchosen, crejected) = select_thresholds(&coarse_values, &adj, &coarse);
        out.seconds.thresholds += t.elapsed().as_secs_f64();
        if !cchosen.is_empty() {
            (lo, hi, chosen) = (clo, chi, cchosen);
            rejected.extend(crejected);
            values = coarse_values;
            curvature_k = coarse.curvature_k;
        }
    }

    // Per-point outputs.
    let t = Instant::now();
    for (k, &i) in ids.iter().enumerate() {
        let i = i as usize;
        out.region[i] = region_id;
        out.curvature[i] = values[k];
        out.patch[i] = chosen.iter().filter(|c| values[k] > c.split.tau).count() as u8;
        let rank = |l: Label| match l {
            Label::Low => 0,
            Label::Noisy => 1,
            Label::Inner => 2,
            Label::Border => 3,
        };
        out.label[i] = chosen
            .iter()
            .map(|c| c.labels[k])
            .max_by_key(|&l| rank(l))
            .or(Some(Label::Low));
    }
    // The region's own boundary (points with a 1-ring neighbour outside the region, i.e. next
    // to a sharp-edge band, plus the cloud's boundary) joins each graph as the cloud boundary
    // does in demarsin2007 (Fig. 8 of demarsin2008): a fillet line that ends at a sharp edge
    // is closed through it instead of being pruned as a dangling branch.
    // A point with a neighbour outside the region has a shorter local row.
    let region_boundary: Vec<bool> = ids
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            let i = i as usize;
            shared.cloud_boundary.is_some_and(|b| b[i])
                || (i < shared.adjacency.num_rows() && adj.row_len(k) < shared.adjacency.row_len(i))
        })
        .collect();
    let mut thresholds = Vec::new();
    for c in &chosen {
        let seg = labels::grow(&c.labels, &adj);
        let net = lines::network(
            &original,
            seg,
            &adj,
            Some(&region_boundary),
            &params.lines,
            if params.lines.smooth {
                Smoothing::AlongLine
            } else {
                Smoothing::None
            },
            0.0,
        )?;
        out.lines.append_feature(&net);
        thresholds.push(report(c, Some(&net)));
    }
    thresholds.extend(rejected.iter().map(|c| report(c, None)));
    out.seconds.smooth_lines += t.elapsed().as_secs_f64();
    Ok(RegionReport {
        cluster: 0,
        points: ids.len(),
        curvature_k,
        histogram_range: [lo, hi],
        thresholds,
    })
}
