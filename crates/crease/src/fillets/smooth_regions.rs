//! Step 1 of the module documentation of [`super`]: the smooth regions of the first-order
//! segmentation (noise islands joined to the patch around them) and the adjacency of one region
//! in its own indices.

use rayon::prelude::*;

use crate::geometry::Csr;

/// The smooth region every first-order cluster belongs to: a large cluster to itself; a group
/// of adjacent small clusters that touches exactly one large cluster (a noise island inside a
/// smooth patch, section 3 of demarsin2007: "small clusters are created at the noisy parts")
/// to that large cluster; the others (the bands along sharp edges, between two or more large
/// clusters) to themselves, which leaves them out of every region. Without this, every noise
/// island punches a hole with a boundary into its region, and the fillet graph wires lines
/// to those holes. Groups larger than `max_island` points stay out: they are the bands of
/// sharp edges that the region growing went around (two faces joined elsewhere into one large
/// cluster), not noise.
pub(super) fn island_owners(
    labels: &[u32],
    sizes: &[u32],
    mean: f64,
    adjacency: &Csr,
    max_island: usize,
) -> Vec<u32> {
    let m = sizes.len();
    let large = |c: u32| sizes[c as usize] as f64 >= mean;
    let mut parent: Vec<u32> = (0..m as u32).collect();
    fn find(parent: &mut [u32], mut a: u32) -> u32 {
        while parent[a as usize] != a {
            parent[a as usize] = parent[parent[a as usize] as usize];
            a = parent[a as usize];
        }
        a
    }
    let mut touches: Vec<(u32, u32)> = Vec::new();
    for (p, &lp) in labels.iter().enumerate() {
        if large(lp) || p >= adjacency.num_rows() {
            continue;
        }
        for &q in adjacency.row(p) {
            let lq = labels[q as usize];
            if lq == lp {
                continue;
            }
            if large(lq) {
                touches.push((lp, lq));
            } else {
                let (a, b) = (find(&mut parent, lp), find(&mut parent, lq));
                if a != b {
                    parent[a.max(b) as usize] = a.min(b);
                }
            }
        }
    }
    // Large clusters touched by each group of small clusters.
    let mut seen: Vec<(u32, u32)> = touches
        .into_iter()
        .map(|(s, l)| (find(&mut parent, s), l))
        .collect();
    seen.sort_unstable();
    seen.dedup();
    let mut only = vec![u32::MAX; m];
    let mut count = vec![0u32; m];
    for &(g, l) in &seen {
        count[g as usize] += 1;
        only[g as usize] = l;
    }
    let mut group_size = vec![0usize; m];
    for c in 0..m as u32 {
        if !large(c) {
            group_size[find(&mut parent, c) as usize] += sizes[c as usize] as usize;
        }
    }
    (0..m as u32)
        .map(|c| {
            if large(c) {
                return c;
            }
            let g = find(&mut parent, c) as usize;
            if count[g] == 1 && group_size[g] <= max_island {
                only[g]
            } else {
                c
            }
        })
        .collect()
}

/// What every region reads of the whole cloud: the 1-ring adjacency, the smooth region
/// (first-order cluster) each point belongs to and its index within that region, and the cloud's
/// boundary flags.
pub(super) struct Shared<'a> {
    pub(super) adjacency: &'a Csr,
    pub(super) owner: &'a [u32],
    pub(super) local: &'a [u32],
    pub(super) cloud_boundary: Option<&'a [bool]>,
}

/// The adjacency of region `cluster` (points `ids`) in local indices: neighbours outside the
/// region dropped.
pub(super) fn local_adjacency(ids: &[u32], cluster: u32, shared: &Shared) -> Csr {
    let adjacency = shared.adjacency;
    let rows: Vec<Vec<u32>> = ids
        .par_iter()
        .map(|&i| {
            if (i as usize) >= adjacency.num_rows() {
                return Vec::new();
            }
            adjacency
                .row(i as usize)
                .iter()
                .filter(|&&q| shared.owner[q as usize] == cluster)
                .map(|&q| shared.local[q as usize])
                .collect()
        })
        .collect();
    let counts: Vec<u32> = rows.iter().map(|r| r.len() as u32).collect();
    Csr {
        offsets: Csr::offsets_from_counts(&counts),
        indices: rows.concat(),
    }
}
