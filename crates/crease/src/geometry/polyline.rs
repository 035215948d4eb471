//! Chaining line segments into polylines: split at junctions (points used by other than two
//! segments) and at ends, so that every polyline is a maximal chain of degree-2 points and every
//! closed loop without a junction becomes one closed polyline.

use super::Csr;

/// Counts of a curve network (vertices, edges, polylines): the shape of its topology.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NetworkCounts {
    /// Vertices of degree 1 (open ends).
    pub endpoints: usize,
    /// Vertices of degree 3 or more.
    pub junctions: usize,
    /// Polylines that are closed loops (first index repeated at the end).
    pub closed_loops: usize,
}

/// Endpoints and junctions of the graph (`num_points` vertices, `segments`) and the closed loops
/// among `polylines`.
pub fn network_counts(
    num_points: usize,
    segments: &[[u32; 2]],
    polylines: &[Vec<u32>],
) -> NetworkCounts {
    let mut deg = vec![0u32; num_points];
    for e in segments {
        deg[e[0] as usize] += 1;
        deg[e[1] as usize] += 1;
    }
    NetworkCounts {
        endpoints: deg.iter().filter(|&&d| d == 1).count(),
        junctions: deg.iter().filter(|&&d| d >= 3).count(),
        closed_loops: polylines
            .iter()
            .filter(|l| l.len() > 2 && l.first() == l.last())
            .count(),
    }
}

/// Chains `segments` (pairs of point indices below `num_points`) into polylines.
///
/// Output: point-index chains in a deterministic order (chains starting at the lowest
/// junction or end point first, then closed loops by their lowest point). A closed loop repeats
/// its first index at the end. Duplicate segments and self-loops (`a == a`) are ignored.
pub fn chain_segments(num_points: usize, segments: &[[u32; 2]]) -> Vec<Vec<u32>> {
    let mut segs: Vec<[u32; 2]> = segments
        .iter()
        .filter(|s| s[0] != s[1] && (s[0] as usize) < num_points && (s[1] as usize) < num_points)
        .map(|s| [s[0].min(s[1]), s[0].max(s[1])])
        .collect();
    segs.sort_unstable();
    segs.dedup();
    // Point -> incident segments (CSR).
    let mut counts = vec![0u32; num_points];
    for s in &segs {
        counts[s[0] as usize] += 1;
        counts[s[1] as usize] += 1;
    }
    let offsets = Csr::offsets_from_counts(&counts);
    let mut fill = offsets.clone();
    let mut indices = vec![0u32; segs.len() * 2];
    for (i, s) in segs.iter().enumerate() {
        for &v in s {
            indices[fill[v as usize] as usize] = i as u32;
            fill[v as usize] += 1;
        }
    }
    let incident = Csr { offsets, indices };
    let mut used = vec![false; segs.len()];
    let mut out = Vec::new();
    let walk = |start: u32, first_seg: u32, used: &mut [bool]| {
        let mut chain = vec![start];
        let (mut at, mut seg) = (start, first_seg);
        loop {
            used[seg as usize] = true;
            let s = segs[seg as usize];
            let next = if s[0] == at { s[1] } else { s[0] };
            chain.push(next);
            at = next;
            if counts[at as usize] != 2 || at == start {
                break;
            }
            match incident
                .row(at as usize)
                .iter()
                .find(|&&e| !used[e as usize])
            {
                Some(&e) => seg = e,
                None => break,
            }
        }
        chain
    };
    // Open chains and chains between junctions start at points of degree != 2.
    for (v, &c) in counts.iter().enumerate() {
        if c == 2 || c == 0 {
            continue;
        }
        for k in 0..incident.row_len(v) {
            let e = incident.row(v)[k];
            if !used[e as usize] {
                let chain = walk(v as u32, e, &mut used);
                out.push(chain);
            }
        }
    }
    // What is left are closed loops through degree-2 points only.
    for (v, &c) in counts.iter().enumerate() {
        if c != 2 {
            continue;
        }
        if let Some(&e) = incident.row(v).iter().find(|&&e| !used[e as usize]) {
            let chain = walk(v as u32, e, &mut used);
            out.push(chain);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn open_chain_loop_and_junction() {
        // 0-1-2-3 open; 4-5-6-4 closed; a star at 7 with arms to 8, 9, 10.
        let segs = [
            [2, 1],
            [0, 1],
            [3, 2],
            [4, 5],
            [6, 5],
            [4, 6],
            [7, 8],
            [9, 7],
            [7, 10],
            [1, 0],
        ];
        let lines = chain_segments(11, &segs);
        assert_eq!(lines.len(), 5);
        assert!(lines.contains(&vec![0, 1, 2, 3]));
        assert!(lines.contains(&vec![4, 5, 6, 4]));
        for arm in [8, 9, 10] {
            assert!(lines.contains(&vec![7, arm]));
        }
        // Every segment appears exactly once.
        let total: usize = lines.iter().map(|l| l.len() - 1).sum();
        assert_eq!(total, 9);
    }

    #[test]
    fn figure_eight_splits_at_the_junction() {
        let segs = [[0, 1], [1, 2], [2, 0], [0, 3], [3, 4], [4, 0]];
        let lines = chain_segments(5, &segs);
        assert_eq!(lines.len(), 2);
        for l in &lines {
            assert_eq!(l.first(), Some(&0));
            assert_eq!(l.last(), Some(&0));
            assert_eq!(l.len(), 4);
        }
    }
}
