//! A B-rep of several pieces: a scan whose points fall apart into separate pieces (objects of
//! a scene, a backdrop seen through a gap) is built piece by piece (`super::reconstruct_cloud`)
//! and the pieces are put side by side here, one shell each. A piece that cannot be built is
//! left out and said so; the B-rep is refused when the pieces built cover less than
//! [`super::MIN_EXPLAINED`] of the envelope's area, as one piece is.
//!
//! The pieces share the segmentation's surfaces (a face's `surface_id`), nothing else: their
//! vertices, edges and faces are numbered one after the other, and so are the triangles of
//! their tessellation sources. A writer finds the shells again as the groups of faces joined by
//! edges ([`shells`]).

use std::collections::BTreeMap;

use crate::geometry::{Point3, TriMesh};
use crate::Result;

use super::{BrepEdge, Reconstruction, TessellationCache, TessellationSource};

/// A piece built, with its envelope's area.
pub(crate) struct Piece {
    /// Its number among all pieces (from 1, the largest first).
    pub number: usize,
    /// The piece's B-rep.
    pub rec: Reconstruction,
    /// Its envelope's area (after a sheet's back was cut away).
    pub area: f64,
}

/// The pieces, in order, as one reconstruction of `total` envelope area over `of` pieces (the
/// pieces that could not be built included): their B-reps side by side, the report's counts
/// summed, the shares of area (`left_out`, `unexplained`) made shares of the whole, each
/// piece's warnings prefixed with where it lies. `pieces` is not empty.
pub(crate) fn assemble(pieces: Vec<Piece>, total: f64, of: usize) -> Result<Reconstruction> {
    let n = pieces.len();
    let mut iter = pieces.into_iter();
    let first = iter
        .next()
        .ok_or_else(|| crate::Error::InvalidInput("reconstruct: no piece was built".into()))?;
    if n == 1 && first.area >= total {
        return Ok(first.rec);
    }
    let share = |p: &Piece| p.area / total.max(f64::MIN_POSITIVE);
    let mut out = first.rec.clone();
    out.report.warnings = Vec::new();
    out.report.left_out = Vec::new();
    out.report.faces_by_type = BTreeMap::new();
    out.report.edges_by_curve = BTreeMap::new();
    out.report.vertices = 0;
    out.report.seams = 0;
    out.report.unexplained = 0.0;
    out.report.snaps = Vec::new();
    out.report.closed = true;
    out.report.max_gap = 0.0;
    out.brep.vertices.clear();
    out.brep.edges.clear();
    out.brep.faces.clear();
    out.brep.closed = true;
    out.tessellation = TessellationCache::default();
    out.source = TessellationSource {
        mesh: TriMesh::new(Vec::new(), Vec::new())?,
        region_of_face: Vec::new(),
        regions: Vec::new(),
        chains: Vec::new(),
        vertex_mesh: Vec::new(),
        reversed: false,
        relax: first.rec.source.relax,
    };
    let mut positions: Vec<Point3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut sq = 0.0;
    let mut weight = 0.0;
    for piece in std::iter::once(first).chain(iter) {
        let s = share(&piece);
        let number = piece.number;
        let Reconstruction {
            brep,
            report,
            source,
            ..
        } = piece.rec;
        // The B-rep, renumbered.
        let (nv, ne, nf) = (
            out.brep.vertices.len(),
            out.brep.edges.len(),
            out.brep.faces.len(),
        );
        out.brep.vertices.extend(brep.vertices);
        out.brep
            .edges
            .extend(brep.edges.into_iter().map(|e| BrepEdge {
                start: e.start + nv,
                end: e.end + nv,
                faces: e.faces.map(|f| f.map(|f| f + nf)),
                ..e
            }));
        out.brep.faces.extend(brep.faces.into_iter().map(|mut f| {
            for l in &mut f.loops {
                for (e, _) in l.iter_mut() {
                    *e += ne;
                }
            }
            f
        }));
        out.brep.closed &= brep.closed;
        // The report.
        let r = &mut out.report;
        for (kind, c) in report.faces_by_type {
            *r.faces_by_type.entry(kind).or_insert(0) += c;
        }
        for (kind, c) in report.edges_by_curve {
            *r.edges_by_curve.entry(kind).or_insert(0) += c;
        }
        r.vertices += report.vertices;
        r.closed &= report.closed;
        r.max_gap = r.max_gap.max(report.max_gap);
        r.seams += report.seams;
        sq += s * report.rms_distance * report.rms_distance;
        weight += s;
        r.unexplained += s * report.unexplained;
        for snap in report.snaps {
            if !r.snaps.contains(&snap) {
                r.snaps.push(snap);
            }
        }
        r.left_out.extend(report.left_out.into_iter().map(|mut l| {
            l.area_fraction *= s;
            l
        }));
        let at = centre(&source.mesh);
        let place = place(number, of, at, s);
        r.warnings
            .extend(report.warnings.into_iter().map(|w| format!("{place}: {w}")));
        // The tessellation source, renumbered; a piece walked clockwise turned over here.
        let (mv, nr) = (positions.len() as u32, out.source.regions.len() as u32);
        positions.extend_from_slice(&source.mesh.vertices.positions);
        triangles.extend(source.mesh.faces.iter().map(|f| {
            let f = f.map(|v| v + mv);
            if source.reversed {
                [f[0], f[2], f[1]]
            } else {
                f
            }
        }));
        let t = &mut out.source;
        t.region_of_face
            .extend(source.region_of_face.iter().map(|&r| r + nr));
        t.regions.extend(
            source
                .regions
                .into_iter()
                .map(|(s, f)| (s, f.map(|f| f + nf))),
        );
        t.chains.extend(
            source
                .chains
                .into_iter()
                .map(|(c, s)| (c.into_iter().map(|v| v + mv).collect(), s)),
        );
        t.vertex_mesh
            .extend(source.vertex_mesh.iter().map(|&v| v + mv));
    }
    out.report.rms_distance = (sq / weight.max(f64::MIN_POSITIVE)).sqrt();
    out.source.mesh = TriMesh::new(positions, triangles)?;
    Ok(out)
}

/// A piece named for a message: "piece `number` of `of` (near `at`, `share` of the area)".
pub(crate) fn place(number: usize, of: usize, at: Point3, share: f64) -> String {
    format!(
        "piece {number} of {of} (near ({:.4}, {:.4}, {:.4}), {:.0} % of the area)",
        at[0],
        at[1],
        at[2],
        100.0 * share
    )
}

/// The area-weighted centre of a mesh's triangles (the origin for an empty mesh).
pub(crate) fn centre(mesh: &TriMesh) -> Point3 {
    let p = &mesh.vertices.positions;
    let areas = crate::geometry::face_areas(mesh);
    let mut c = [0.0; 3];
    for (f, w) in mesh.faces.iter().zip(&areas) {
        for v in f {
            for k in 0..3 {
                c[k] += w * p[*v as usize][k] / 3.0;
            }
        }
    }
    let area: f64 = areas.iter().sum();
    if area > 0.0 {
        c.map(|x| x / area)
    } else {
        c
    }
}

/// The shells of a B-rep with `nf` faces: the groups of faces joined by edges, each in face
/// order, the groups ordered by their first face.
pub fn shells(nf: usize, edges: &[BrepEdge]) -> Vec<Vec<usize>> {
    let mut sets = crate::geometry::union_find::UnionFind::new(nf);
    for e in edges {
        if let [Some(a), Some(b)] = e.faces {
            sets.union(a as u32, b as u32);
        }
    }
    let mut group_of_root: BTreeMap<u32, usize> = BTreeMap::new();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for f in 0..nf {
        let root = sets.find(f as u32);
        let g = *group_of_root.entry(root).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(f);
    }
    groups
}
