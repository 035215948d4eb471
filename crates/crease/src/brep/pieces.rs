//! A subset of a mesh's triangles made one piece the half-edge topology can read: the largest
//! edge-connected piece, with no vertex where it pinches (two fans of kept triangles meeting
//! in a single vertex: the smaller fans go). Used for a sheet's front side (`envelope`) and for
//! a part with regions left out (`super::build_open`). Also the pieces of a mesh
//! ([`components`]), for a cloud that falls apart (`super::assembly`).

use rayon::prelude::*;

use crate::geometry::{Csr, TriMesh};

/// Per triangle (row): the triangles that share an edge with it.
pub(crate) fn edge_neighbours(mesh: &TriMesh) -> Csr {
    let mut by_edge: Vec<(u32, u32, u32)> = mesh
        .faces
        .iter()
        .enumerate()
        .flat_map(|(t, f)| {
            (0..3).map(move |e| {
                let (a, b) = (f[e], f[(e + 1) % 3]);
                (a.min(b), a.max(b), t as u32)
            })
        })
        .collect();
    by_edge.par_sort_unstable();
    rows_of(mesh.faces.len(), || {
        by_edge
            .windows(2)
            .filter(|w| (w[0].0, w[0].1) == (w[1].0, w[1].1))
            .flat_map(|w| [(w[0].2, w[1].2), (w[1].2, w[0].2)])
    })
}

/// The CSR rows of `rows` rows holding the `(row, entry)` pairs that `entries` yields (called
/// twice: to count, then to fill), each row in the order they come.
fn rows_of<I: Iterator<Item = (u32, u32)>>(rows: usize, entries: impl Fn() -> I) -> Csr {
    let mut counts = vec![0u32; rows];
    for (r, _) in entries() {
        counts[r as usize] += 1;
    }
    let offsets = Csr::offsets_from_counts(&counts);
    let mut next: Vec<u32> = offsets[..rows].to_vec();
    let mut indices = vec![0u32; offsets[rows] as usize];
    for (r, e) in entries() {
        indices[next[r as usize] as usize] = e;
        next[r as usize] += 1;
    }
    Csr { offsets, indices }
}

/// The triangles of each piece of `mesh` (triangles joined by a shared vertex), the largest
/// first (ties: the one with the lowest triangle), each in triangle order.
pub(crate) fn components(mesh: &TriMesh) -> Vec<Vec<u32>> {
    let mut sets = crate::geometry::union_find::UnionFind::new(mesh.vertices.positions.len());
    for f in &mesh.faces {
        sets.union(f[0], f[1]);
        sets.union(f[0], f[2]);
    }
    let mut piece_of_root = std::collections::HashMap::new();
    let mut out: Vec<Vec<u32>> = Vec::new();
    for (t, f) in mesh.faces.iter().enumerate() {
        let p = *piece_of_root.entry(sets.find(f[0])).or_insert_with(|| {
            out.push(Vec::new());
            out.len() - 1
        });
        out[p].push(t as u32);
    }
    out.sort_by_key(|p| (std::cmp::Reverse(p.len()), p[0]));
    out
}

/// The largest edge-connected piece of the flagged triangles (ties: the one with the lowest
/// triangle), or none when no triangle is flagged.
pub(crate) fn largest_piece(flag: &[bool], neighbours: &Csr) -> Option<Vec<bool>> {
    let n = flag.len();
    let mut piece = vec![u32::MAX; n];
    let mut sizes = Vec::new();
    for t in 0..n {
        if !flag[t] || piece[t] != u32::MAX {
            continue;
        }
        let id = sizes.len() as u32;
        let mut stack = vec![t];
        piece[t] = id;
        let mut size = 0usize;
        while let Some(u) = stack.pop() {
            size += 1;
            for &v in neighbours.row(u) {
                if flag[v as usize] && piece[v as usize] == u32::MAX {
                    piece[v as usize] = id;
                    stack.push(v as usize);
                }
            }
        }
        sizes.push(size);
    }
    let largest = (0..sizes.len()).max_by_key(|&i| (sizes[i], std::cmp::Reverse(i)))? as u32;
    Some(piece.iter().map(|&p| p == largest).collect())
}

/// The largest piece of the flagged triangles with no pinched vertex (see the module doc), or
/// none when no triangle is flagged.
pub(crate) fn manifold_piece(mesh: &TriMesh, flag: &[bool], neighbours: &Csr) -> Option<Vec<bool>> {
    let mut keep = largest_piece(flag, neighbours)?;
    // Per vertex (row): its triangles.
    let around = rows_of(mesh.vertices.positions.len(), || {
        mesh.faces
            .iter()
            .enumerate()
            .flat_map(|(t, f)| f.map(|v| (v, t as u32)))
    });
    let (mut kept, mut fan, mut sizes, mut stack) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for _ in 0..4 {
        let mut changed = false;
        for (v, tris) in around.rows().enumerate() {
            kept.clear();
            kept.extend(tris.iter().copied().filter(|&t| keep[t as usize]));
            if kept.len() < 2 {
                continue;
            }
            // Fans: kept triangles about v joined across an edge through v.
            fan.clear();
            fan.resize(kept.len(), usize::MAX);
            sizes.clear();
            for i in 0..kept.len() {
                if fan[i] != usize::MAX {
                    continue;
                }
                fan[i] = sizes.len();
                stack.clear();
                stack.push(i);
                let mut size = 0;
                while let Some(a) = stack.pop() {
                    size += 1;
                    for j in 0..kept.len() {
                        if fan[j] == usize::MAX && share_edge_at(mesh, kept[a], kept[j], v as u32) {
                            fan[j] = fan[i];
                            stack.push(j);
                        }
                    }
                }
                sizes.push(size);
            }
            if sizes.len() > 1 {
                let big = (0..sizes.len()).max_by_key(|&i| (sizes[i], std::cmp::Reverse(i)))?;
                for (i, &t) in kept.iter().enumerate() {
                    if fan[i] != big {
                        keep[t as usize] = false;
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            break;
        }
        keep = largest_piece(&keep, neighbours)?;
    }
    Some(keep)
}

/// Whether triangles `a` and `b` share an edge through vertex `v`.
fn share_edge_at(mesh: &TriMesh, a: u32, b: u32, v: u32) -> bool {
    let (fa, fb) = (mesh.faces[a as usize], mesh.faces[b as usize]);
    fa.iter().any(|&x| x != v && fb.contains(&x))
}
