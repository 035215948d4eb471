//! Mesh clean-up for triangle soups (STL, scanner and CAD exports): merges coincident
//! vertices, drops degenerate and duplicate faces and unreferenced vertices, and keeps the index
//! maps that bring results back to the input's order (outputs keep the input's order and count).
//!
//! Every step is deterministic whatever the thread count: representatives are the lowest input
//! indices, kept vertices and faces stay in input order.

use std::collections::HashMap;
use std::fmt;
use std::hash::{BuildHasherDefault, Hasher};

use rayon::prelude::*;

use super::topology::{has_repeated_vertex, triangle_area};
use super::{vec3, Aabb, Point3, TriMesh};
use crate::{Error, Result};

/// Default merge tolerance, relative to the bounding-box diagonal of the finite vertices.
pub const DEFAULT_RELATIVE_MERGE_TOLERANCE: f64 = 1e-9;
/// Default area tolerance, relative to the squared mean edge length.
pub const DEFAULT_RELATIVE_AREA_TOLERANCE: f64 = 1e-12;

/// Marks a removed element in [`CleanupReport`]'s maps.
pub const REMOVED: u32 = u32::MAX;

/// What [`clean_mesh`] does. Every step can be switched off; `Default` turns all on.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CleanupParams {
    /// Merge vertices closer than the merge tolerance (default `true`).
    pub merge_vertices: bool,
    /// Absolute merge distance. `None` (default): `1e-9 ×` the bounding-box diagonal of the
    /// finite vertices, i.e. positions equal up to float noise. `Some(0.0)` merges only
    /// bit-identical positions (`-0.0 == 0.0`).
    pub merge_tolerance: Option<f64>,
    /// Drop faces with a repeated vertex (after merging) or an area `<= area_tolerance`
    /// (default `true`).
    pub remove_degenerate_faces: bool,
    /// Absolute area threshold. `None` (default): `1e-12 ×` the squared mean edge length (the
    /// mean over all sides of the faces without a repeated vertex), so exactly flat triangles
    /// and triangles flat up to float noise are dropped.
    pub area_tolerance: Option<f64>,
    /// Drop faces with the same vertex set as an earlier face, in any order or orientation; the
    /// first is kept (default `true`).
    pub remove_duplicate_faces: bool,
    /// Drop vertices no kept face uses (default `true`).
    pub remove_unreferenced_vertices: bool,
}

impl Default for CleanupParams {
    fn default() -> Self {
        CleanupParams {
            merge_vertices: true,
            merge_tolerance: None,
            remove_degenerate_faces: true,
            area_tolerance: None,
            remove_duplicate_faces: true,
            remove_unreferenced_vertices: true,
        }
    }
}

/// What [`clean_mesh`] did, with the maps between input and output elements.
///
/// Maps use [`REMOVED`] (`u32::MAX`) for elements with no counterpart. The maps are not
/// serialized (the summary is).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct CleanupReport {
    /// Vertices in the input.
    pub input_vertices: usize,
    /// Faces in the input.
    pub input_faces: usize,
    /// Vertices in the output.
    pub output_vertices: usize,
    /// Faces in the output.
    pub output_faces: usize,
    /// The merge distance used (0 if merging was off).
    pub merge_tolerance: f64,
    /// The area threshold used (0 if degenerate-face removal was off).
    pub area_tolerance: f64,
    /// Input vertices merged into a lower-indexed representative.
    pub vertices_merged: usize,
    /// Faces dropped as degenerate (repeated vertex after merging, or area `<= area_tolerance`).
    pub degenerate_faces: usize,
    /// Of those, faces with three distinct vertices dropped for their area.
    pub zero_area_faces: usize,
    /// Faces dropped as duplicates of an earlier face.
    pub duplicate_faces: usize,
    /// Vertices dropped because no kept face uses them (merged vertices not included).
    pub isolated_vertices: usize,
    /// Input vertex → output vertex that stands for it (its representative after merging);
    /// `REMOVED` if dropped. `input_vertices` entries.
    #[serde(skip)]
    pub vertex_map: Vec<u32>,
    /// Output vertex → input vertex it was copied from. `output_vertices` entries, ascending.
    #[serde(skip)]
    pub vertex_origin: Vec<u32>,
    /// Output face → input face. `output_faces` entries, ascending.
    #[serde(skip)]
    pub face_map: Vec<u32>,
    /// Input face → output face that stands for it (a duplicate maps to the kept copy);
    /// `REMOVED` for degenerate faces. `input_faces` entries.
    #[serde(skip)]
    pub face_target: Vec<u32>,
}

impl CleanupReport {
    /// Brings per-output-vertex values back to the input's vertices.
    ///
    /// Inputs: `values`, `output_vertices` entries. Output: `input_vertices` entries: an input
    /// vertex gets the value of the output vertex standing for it (merged vertices share their
    /// representative's), `fill` if it was dropped. Fails if `values` has the wrong length.
    pub fn vertex_values_to_input<T: Clone + Send + Sync>(
        &self,
        values: &[T],
        fill: T,
    ) -> Result<Vec<T>> {
        map_values(&self.vertex_map, values, fill, "vertex")
    }

    /// Brings per-output-face values back to the input's faces.
    ///
    /// Inputs: `values`, `output_faces` entries. Output: `input_faces` entries: an input face
    /// gets the value of its output face (duplicates that of the kept copy), `fill` if it was
    /// dropped as degenerate. Fails if `values` has the wrong length.
    pub fn face_values_to_input<T: Clone + Send + Sync>(
        &self,
        values: &[T],
        fill: T,
    ) -> Result<Vec<T>> {
        map_values(&self.face_target, values, fill, "face")
    }

    /// Carries per-input-vertex values (e.g. ground-truth labels) to the output vertices.
    ///
    /// Inputs: `values`, `input_vertices` entries. Output: `output_vertices` entries, each the
    /// value of the input vertex it was copied from. Fails if `values` has the wrong length.
    pub fn vertex_values_from_input<T: Clone + Send + Sync>(&self, values: &[T]) -> Result<Vec<T>> {
        select_values(&self.vertex_origin, values, self.input_vertices, "vertex")
    }

    /// Carries per-input-face values to the output faces.
    ///
    /// Inputs: `values`, `input_faces` entries. Output: `output_faces` entries, each the value
    /// of the input face it was copied from. Fails if `values` has the wrong length.
    pub fn face_values_from_input<T: Clone + Send + Sync>(&self, values: &[T]) -> Result<Vec<T>> {
        select_values(&self.face_map, values, self.input_faces, "face")
    }

    /// True if the clean-up changed nothing.
    pub fn is_identity(&self) -> bool {
        self.input_vertices == self.output_vertices && self.input_faces == self.output_faces
    }
}

fn map_values<T: Clone + Send + Sync>(
    map: &[u32],
    values: &[T],
    fill: T,
    what: &str,
) -> Result<Vec<T>> {
    let n = map
        .iter()
        .filter(|&&m| m != REMOVED)
        .max()
        .map_or(0, |&m| m as usize + 1);
    if values.len() < n {
        return Err(Error::InvalidArgument(format!(
            "{} per-{what} values given, but the cleaned mesh has more {what}s (index {} used)",
            values.len(),
            n - 1
        )));
    }
    Ok(map
        .par_iter()
        .map(|&m| {
            if m == REMOVED {
                fill.clone()
            } else {
                values[m as usize].clone()
            }
        })
        .collect())
}

fn select_values<T: Clone + Send + Sync>(
    origin: &[u32],
    values: &[T],
    expected: usize,
    what: &str,
) -> Result<Vec<T>> {
    if values.len() != expected {
        return Err(Error::InvalidArgument(format!(
            "{} per-{what} values given for an input of {expected} {what}s",
            values.len()
        )));
    }
    Ok(origin
        .par_iter()
        .map(|&i| values[i as usize].clone())
        .collect())
}

impl fmt::Display for CleanupReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "clean-up: {} -> {} vertices ({} merged within {:.3e}, {} unreferenced removed), \
             {} -> {} faces ({} degenerate, {} duplicate removed)",
            self.input_vertices,
            self.output_vertices,
            self.vertices_merged,
            self.merge_tolerance,
            self.isolated_vertices,
            self.input_faces,
            self.output_faces,
            self.degenerate_faces,
            self.duplicate_faces
        )
    }
}

/// Cleans a triangle mesh (typically a soup): merges coincident vertices, drops degenerate
/// faces, duplicate faces and unreferenced vertices, in that order, each step as `params` says.
///
/// Inputs: `mesh` with `V` vertices (with optional normals, colours, attributes) and `F` faces
/// (with optional per-face attributes); `params`.
/// Output: the cleaned mesh (`V'` vertices, `F'` faces: kept vertices and faces in input order;
/// a merged group keeps its lowest-indexed vertex and that vertex's per-vertex data; per-face
/// attributes follow their faces) and a [`CleanupReport`] with the counts and the maps
/// (`vertex_map`: `V`, `vertex_origin`: `V'`, `face_map`: `F'`, `face_target`: `F`).
///
/// Errors: `Error::InvalidInput` if a face index is out of range or a per-vertex / per-face
/// array does not have one entry per element.
///
/// Merging is greedy in index order: a vertex joins the lowest-indexed representative within the
/// tolerance, else becomes a representative; so every merged vertex is within the tolerance of
/// its representative (no chaining). Non-finite positions are never merged.
pub fn clean_mesh(mesh: &TriMesh, params: &CleanupParams) -> Result<(TriMesh, CleanupReport)> {
    mesh.check_indices()?;
    mesh.vertices
        .validate()
        .map_err(|e| Error::InvalidInput(format!("mesh vertices: {e}")))?;
    let nv = mesh.num_vertices();
    let nf = mesh.num_faces();
    for a in &mesh.face_attributes {
        if a.values.len() != nf {
            return Err(Error::InvalidInput(format!(
                "face attribute {:?} has {} values for {nf} faces",
                a.name,
                a.values.len()
            )));
        }
    }
    let positions = mesh.positions();

    // 1. Representatives.
    let (rep, merge_tolerance) = if params.merge_vertices {
        let tol = match params.merge_tolerance {
            Some(t) if t.is_finite() && t > 0.0 => t,
            Some(_) => 0.0,
            None => finite_aabb(positions)
                .map_or(0.0, |b| DEFAULT_RELATIVE_MERGE_TOLERANCE * b.diagonal()),
        };
        (merge_representatives(positions, tol), tol)
    } else {
        ((0..nv as u32).collect::<Vec<_>>(), 0.0)
    };
    let vertices_merged = rep
        .iter()
        .enumerate()
        .filter(|&(i, &r)| r as usize != i)
        .count();

    // 2. Faces through the representatives; degenerate ones.
    let faces: Vec<[u32; 3]> = mesh
        .faces
        .par_iter()
        .map(|f| f.map(|v| rep[v as usize]))
        .collect();
    let mut keep = vec![true; nf];
    let mut area_tolerance = 0.0;
    let mut zero_area_faces = 0;
    let mut degenerate_faces = 0;
    if params.remove_degenerate_faces {
        area_tolerance = match params.area_tolerance {
            Some(t) if t.is_finite() => t.max(0.0),
            Some(_) => 0.0,
            None => DEFAULT_RELATIVE_AREA_TOLERANCE * mean_edge_length(positions, &faces).powi(2),
        };
        let p = positions;
        let kind: Vec<u8> = faces
            .par_iter()
            .map(|&f| {
                if has_repeated_vertex(f) {
                    1
                } else if triangle_area(p[f[0] as usize], p[f[1] as usize], p[f[2] as usize])
                    <= area_tolerance
                {
                    2
                } else {
                    0
                }
            })
            .collect();
        for (k, d) in keep.iter_mut().zip(&kind) {
            if *d != 0 {
                *k = false;
                degenerate_faces += 1;
                zero_area_faces += usize::from(*d == 2);
            }
        }
    }

    // 3. Duplicates: first face of each vertex set wins.
    let mut duplicate_of = vec![REMOVED; nf];
    let mut duplicate_faces = 0;
    if params.remove_duplicate_faces {
        let mut keyed: Vec<([u32; 3], u32)> = (0..nf as u32)
            .into_par_iter()
            .filter(|&f| keep[f as usize])
            .map(|f| {
                let mut k = faces[f as usize];
                k.sort_unstable();
                (k, f)
            })
            .collect();
        keyed.par_sort_unstable();
        for run in keyed.chunk_by(|a, b| a.0 == b.0) {
            let first = run[0].1;
            for &(_, f) in &run[1..] {
                keep[f as usize] = false;
                duplicate_of[f as usize] = first;
                duplicate_faces += 1;
            }
        }
    }

    // 4. Kept vertices.
    let is_rep: Vec<bool> = rep
        .iter()
        .enumerate()
        .map(|(i, &r)| r as usize == i)
        .collect();
    let mut used = vec![!params.remove_unreferenced_vertices; nv];
    if params.remove_unreferenced_vertices {
        for (f, _) in faces.iter().zip(&keep).filter(|(_, &k)| k) {
            for &v in f {
                used[v as usize] = true;
            }
        }
    }
    let mut new_index = vec![REMOVED; nv];
    let mut vertex_origin = Vec::new();
    let mut isolated_vertices = 0;
    for i in 0..nv {
        if is_rep[i] {
            if used[i] {
                new_index[i] = vertex_origin.len() as u32;
                vertex_origin.push(i as u32);
            } else {
                isolated_vertices += 1;
            }
        }
    }
    let vertex_map: Vec<u32> = rep.par_iter().map(|&r| new_index[r as usize]).collect();

    // 5. Kept faces and the face maps.
    let face_map: Vec<u32> = (0..nf as u32).filter(|&f| keep[f as usize]).collect();
    let mut face_target = vec![REMOVED; nf];
    for (o, &f) in face_map.iter().enumerate() {
        face_target[f as usize] = o as u32;
    }
    for f in 0..nf {
        let d = duplicate_of[f];
        if d != REMOVED {
            face_target[f] = face_target[d as usize];
        }
    }

    // 6. The output mesh.
    let origin_usize: Vec<usize> = vertex_origin.iter().map(|&i| i as usize).collect();
    let face_usize: Vec<usize> = face_map.iter().map(|&f| f as usize).collect();
    let out = TriMesh {
        vertices: mesh.vertices.select(&origin_usize),
        faces: face_map
            .par_iter()
            .map(|&f| faces[f as usize].map(|v| new_index[v as usize]))
            .collect(),
        face_attributes: mesh.face_attributes.select(&face_usize),
    };
    let report = CleanupReport {
        input_vertices: nv,
        input_faces: nf,
        output_vertices: vertex_origin.len(),
        output_faces: face_map.len(),
        merge_tolerance,
        area_tolerance,
        vertices_merged,
        degenerate_faces,
        zero_area_faces,
        duplicate_faces,
        isolated_vertices,
        vertex_map,
        vertex_origin,
        face_map,
        face_target,
    };
    Ok((out, report))
}

/// Bounding box of the finite positions.
fn finite_aabb(positions: &[Point3]) -> Option<Aabb> {
    let mut it = positions.iter().filter(|p| p.iter().all(|c| c.is_finite()));
    let first = *it.next()?;
    let mut b = Aabb {
        min: first,
        max: first,
    };
    for &p in it {
        b.grow(p);
    }
    Some(b)
}

/// Mean length over all sides of the faces without a repeated vertex (finite lengths only),
/// summed per fixed-size chunk so the result does not depend on the thread count.
pub(crate) fn mean_edge_length(p: &[Point3], faces: &[[u32; 3]]) -> f64 {
    let partial: Vec<(f64, usize)> = faces
        .par_chunks(4096)
        .map(|chunk| {
            let mut s = 0.0;
            let mut n = 0;
            for &f in chunk.iter().filter(|&&f| !has_repeated_vertex(f)) {
                for i in 0..3 {
                    let l = vec3::dist(p[f[i] as usize], p[f[(i + 1) % 3] as usize]);
                    if l.is_finite() {
                        s += l;
                        n += 1;
                    }
                }
            }
            (s, n)
        })
        .collect();
    let (s, n) = partial
        .iter()
        .fold((0.0, 0), |(s, n), &(a, b)| (s + a, n + b));
    if n == 0 {
        0.0
    } else {
        s / n as f64
    }
}

/// For each vertex, its representative: the lowest-indexed earlier representative within `tol`
/// (Euclidean distance `<= tol`), else itself. `tol == 0` merges bit-identical positions.
///
/// Inputs: `V` positions, `tol >= 0`. Output: `V` representative indices (`rep[rep[i]] == rep[i]`).
///
/// Bit-identical positions are grouped first (a parallel sort); the greedy tolerance pass then
/// runs over the distinct positions only, which gives the same result as running it over all
/// vertices (a group's members share their first member's candidates).
fn merge_representatives(p: &[Point3], tol: f64) -> Vec<u32> {
    let mut rep = exact_representatives(p);
    let Some(bbox) = finite_aabb(p) else {
        return rep;
    };
    // Grid of cell size 8 tol: a point within tol of x lies in x's cell or, on an axis where x
    // is closer than tol to a cell face, in the neighbour across it; most points need no
    // neighbour cell at all.
    let cell = CELL_FACTOR * tol;
    if tol == 0.0 || bbox.diagonal() / cell > 1e15 {
        return rep;
    }
    let finite = |i: usize| p[i].iter().all(|c| c.is_finite());
    let cell_of = |x: Point3| -> ([i64; 3], [f64; 3]) {
        let mut c = [0i64; 3];
        let mut frac = [0.0; 3];
        for k in 0..3 {
            let t = (x[k] - bbox.min[k]) / cell + GRID_SHIFT;
            let fl = t.floor();
            c[k] = fl as i64;
            frac[k] = t - fl;
        }
        (c, frac)
    };
    let cell_hash = |c: [i64; 3]| mix3(c.map(|x| x as u64));
    // Distinct points sorted by (cell hash, index); each run of one hash is looked up by hash
    // (cells sharing a hash share a run, which only adds candidates that fail the distance test).
    let mut order: Vec<(u64, u32)> = (0..p.len() as u32)
        .into_par_iter()
        .filter(|&i| rep[i as usize] == i && finite(i as usize))
        .map(|i| (cell_hash(cell_of(p[i as usize]).0), i))
        .collect();
    order.par_sort_unstable();
    let mut runs: HashMap<u64, (u32, u32), BuildHasherDefault<PremixedHasher>> =
        HashMap::with_capacity_and_hasher(order.len(), Default::default());
    let mut run_of = vec![(0u32, 0u32); order.len()];
    let mut start = 0;
    for run in order.chunk_by(|a, b| a.0 == b.0) {
        let r = (start as u32, (start + run.len()) as u32);
        runs.insert(run[0].0, r);
        run_of[start..start + run.len()].fill(r);
        start += run.len();
    }
    let tol2 = tol * tol;
    let near = 1.0 / CELL_FACTOR + 1e-9;
    // Pairs (i, j): j < i, distinct points within tol (rare).
    let mut pairs: Vec<(u32, u32)> = order
        .par_iter()
        .zip(run_of.par_iter())
        .flat_map_iter(|(&(_, i), &(s, e))| {
            let i = i as usize;
            let mut out = Vec::new();
            let mut scan = |range: &[(u64, u32)]| {
                for &(_, j) in range {
                    if (j as usize) < i && vec3::dist2(p[j as usize], p[i]) <= tol2 {
                        out.push((i as u32, j));
                    }
                }
            };
            scan(&order[s as usize..e as usize]);
            let (c, frac) = cell_of(p[i]);
            let steps = |k: usize| -> [i64; 3] {
                [
                    0,
                    if frac[k] < near { -1 } else { 0 },
                    if frac[k] > 1.0 - near { 1 } else { 0 },
                ]
            };
            let (sx, sy, sz) = (steps(0), steps(1), steps(2));
            if sx[1..] != [0, 0] || sy[1..] != [0, 0] || sz[1..] != [0, 0] {
                let own = cell_hash(c);
                let mut seen = [own; 27];
                let mut nseen = 1;
                for ox in sx {
                    for oy in sy {
                        for oz in sz {
                            let key = cell_hash([c[0] + ox, c[1] + oy, c[2] + oz]);
                            if seen[..nseen].contains(&key) {
                                continue;
                            }
                            seen[nseen] = key;
                            nseen += 1;
                            if let Some(&(s, e)) = runs.get(&key) {
                                scan(&order[s as usize..e as usize]);
                            }
                        }
                    }
                }
            }
            out.into_iter()
        })
        .collect();
    pairs.par_sort_unstable();
    // Greedy in index order: join the lowest earlier representative within tol.
    for group in pairs.chunk_by(|a, b| a.0 == b.0) {
        let i = group[0].0 as usize;
        if let Some(&(_, j)) = group.iter().find(|&&(_, j)| rep[j as usize] == j) {
            rep[i] = j;
        }
    }
    // Group members follow their first member.
    for i in 0..rep.len() {
        rep[i] = rep[rep[i] as usize];
    }
    rep
}

/// Grid cell size in units of the merge tolerance.
const CELL_FACTOR: f64 = 8.0;
/// Offset of the grid from the bounding-box corner, in cells: an irrational-looking fraction so
/// that round CAD coordinates do not fall on cell faces (which would make every point look up
/// its neighbour cells).
const GRID_SHIFT: f64 = 0.381_966_011_250_105;

/// Representatives for bit-identical positions (`-0.0` equal to `0.0`; non-finite never merged):
/// the lowest index of each group.
fn exact_representatives(p: &[Point3]) -> Vec<u32> {
    let key = |x: Point3| x.map(|c| if c == 0.0 { 0u64 } else { c.to_bits() });
    let mut order: Vec<([u64; 3], u32)> = (0..p.len() as u32)
        .into_par_iter()
        .filter(|&i| p[i as usize].iter().all(|c| c.is_finite()))
        .map(|i| (key(p[i as usize]), i))
        .collect();
    order.par_sort_unstable();
    let mut rep: Vec<u32> = (0..p.len() as u32).collect();
    for run in order.chunk_by(|a, b| a.0 == b.0) {
        let first = run[0].1;
        for &(_, i) in &run[1..] {
            rep[i as usize] = first;
        }
    }
    rep
}

/// A 64-bit hash of three words (splitmix64 finaliser chain).
#[inline]
fn mix3(x: [u64; 3]) -> u64 {
    #[inline]
    fn fmix(mut z: u64) -> u64 {
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fmix(x[2] ^ fmix(x[1] ^ fmix(x[0].wrapping_add(0x9e37_79b9_7f4a_7c15))))
}

/// A hasher for keys that are already well-mixed 64-bit hashes.
#[derive(Default)]
struct PremixedHasher(u64);

impl Hasher for PremixedHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(8) ^ u64::from(b)).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = x;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merge_greedy_no_chaining() {
        // 0 -- 1 -- 2 spaced 0.6 with tol 1: 1 joins 0, 2 is 1.2 from 0 and stays.
        let p = vec![
            [0.0, 0.0, 0.0],
            [0.6, 0.0, 0.0],
            [1.2, 0.0, 0.0],
            [0.1, 0.0, 0.0],
        ];
        assert_eq!(merge_representatives(&p, 1.0), vec![0, 0, 2, 0]);
        assert_eq!(merge_representatives(&p, 0.0), vec![0, 1, 2, 3]);
    }

    #[test]
    fn merge_at_exactly_the_tolerance_on_round_coordinates() {
        let mut p = Vec::new();
        for i in 0..50 {
            for j in 0..50 {
                p.push([i as f64, j as f64, 0.0]);
                p.push([i as f64 + 0.25, j as f64, 0.0]);
            }
        }
        let rep = merge_representatives(&p, 0.25);
        for k in 0..p.len() / 2 {
            assert_eq!(rep[2 * k], 2 * k as u32);
            assert_eq!(rep[2 * k + 1], 2 * k as u32);
        }
        let rep = merge_representatives(&p, 0.249);
        assert!(rep.iter().enumerate().all(|(i, &r)| r as usize == i));
    }

    #[test]
    fn exact_merge_and_non_finite() {
        let p = vec![
            [0.0, 1.0, 2.0],
            [f64::NAN, 0.0, 0.0],
            [-0.0, 1.0, 2.0],
            [f64::NAN, 0.0, 0.0],
        ];
        assert_eq!(exact_representatives(&p), vec![0, 1, 0, 3]);
        assert_eq!(merge_representatives(&p, 1e-3), vec![0, 1, 0, 3]);
    }

    #[test]
    fn merge_across_cell_faces() {
        // Points straddling many cell boundaries at random offsets all find their twin.
        let mut p = Vec::new();
        for i in 0..1000 {
            let x = i as f64 * 0.0137;
            p.push([x, 0.5 * x, 0.25 * x]);
        }
        for i in 0..1000 {
            let x = i as f64 * 0.0137 + 0.9e-3;
            p.push([x, 0.5 * x, 0.25 * x]);
        }
        let rep = merge_representatives(&p, 1.1e-3);
        for i in 0..1000 {
            assert_eq!(rep[i], i as u32);
            assert_eq!(rep[1000 + i], i as u32);
        }
    }
}
