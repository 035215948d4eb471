//! A closed triangle mesh around a point cloud, for reading the B-rep's topology off it.
//!
//! The B-rep of a cloud is built as that of a mesh (`topology`): faces are regions of
//! triangles on one surface, edges the chains between them. A cloud has no triangles, so this
//! module makes some: the boundary of the cloud dilated by a radius `r` (the set of points
//! within `r` of a sample), which is a closed surface at distance `r` outside the part when `r`
//! closes the gaps between samples. Its triangles take the surface of the samples nearest them
//! (in the caller), so each face of the part appears as a region of the envelope, and two faces
//! that meet along an edge as two regions that share a border. The envelope only carries the
//! topology: every vertex and edge of the B-rep is then solved from the analytic surfaces.
//!
//! The dilated set is the negative side of `f(x) = d(x) - r` (`d`: distance to the nearest
//! sample) on a regular grid, with the grid vertices not reachable from the grid's border
//! through `f > 0` (the part's inside, and closed voids) counted as inside too; the surface is
//! `f = 0` by marching tetrahedra over the Kuhn triangulation of the grid's cubes (six
//! tetrahedra per cube around its main diagonal). Marching tetrahedra rather than a
//! marching-cubes or surface-nets crate: the zero set of a piecewise-linear function over a
//! triangulation is a closed 2-manifold by construction (no ambiguous cube cases, no
//! non-manifold vertices), which the half-edge topology requires.

use rayon::prelude::*;

use crate::geometry::{Point3, TriMesh};
use crate::spatial::KdIndex;

use super::pieces;
use crate::{Error, Result};

/// Grid cells along the longest side of the cloud's box, at most: the envelope's resolution
/// stays that of the part's features, not of its sampling (a 10M-point cloud meshes as fast as
/// a 100k one).
pub const MAX_CELLS: f64 = 256.0;

/// Grid vertices per sample, at most: a few hundred scattered points in a large box (a fuzzed
/// input: 957 points) made a grid of 256³ vertices, 1.1 s to mesh (49 s in the fuzzing build);
/// scans and sampled parts stay far below it (Kinect `test0`: 7.7M vertices for 189k points,
/// 41 per point) and keep their grids.
pub const GRID_PER_POINT: f64 = 256.0;

/// Components of the envelope smaller than this fraction of the largest one (in triangles)
/// are dropped: stray points and small clusters away from the part.
pub const MIN_COMPONENT_FRACTION: f64 = 0.05;

/// The envelope and how it was made.
#[derive(Debug, Clone)]
pub(crate) struct Envelope {
    /// The closed, outward-oriented triangle mesh.
    pub mesh: TriMesh,
    /// Dilation radius `r`.
    pub radius: f64,
    /// Grid cell size.
    pub cell: f64,
    /// Components dropped (smaller than [`MIN_COMPONENT_FRACTION`] of the largest).
    pub dropped: usize,
    /// The radius and the cell asked for (before the grid was coarsened to [`MAX_CELLS`] or
    /// [`GRID_PER_POINT`]).
    pub base_radius: f64,
    /// See `base_radius`.
    pub base_cell: f64,
}

/// The envelope of `points` (finite, non-empty; `index` built over them) dilated by `radius`,
/// on a grid of cells of at least `cell` (coarser when the box would need more than
/// [`MAX_CELLS`] along a side; the radius then grows to two cells).
pub(crate) fn envelope(
    points: &[Point3],
    index: &KdIndex,
    radius: f64,
    cell: f64,
) -> Result<Envelope> {
    let bbox = crate::geometry::Aabb::from_points(points)
        .ok_or_else(|| Error::InvalidInput("envelope: no points".into()))?;
    let longest = (0..3)
        .map(|k| bbox.max[k] - bbox.min[k])
        .fold(0.0, f64::max);
    let (base_radius, base_cell) = (radius, cell);
    // At most MAX_CELLS along the box, and at most GRID_PER_POINT grid vertices per sample.
    let padded: f64 = (0..3)
        .map(|k| bbox.max[k] - bbox.min[k] + 2.0 * (radius + 2.0 * cell))
        .product();
    let sparse = (padded / (GRID_PER_POINT * points.len() as f64)).cbrt();
    let cell = cell.max(longest / MAX_CELLS).max(sparse);
    let radius = radius.max(2.0 * cell);
    if !(cell > 0.0 && cell.is_finite()) {
        return Err(Error::InvalidInput(
            "envelope: the points have no extent".into(),
        ));
    }
    // The grid: padded so that its border lies outside the dilated set.
    let pad = radius + 2.0 * cell;
    let origin = bbox.min.map(|m| m - pad);
    let dims: [usize; 3] = std::array::from_fn(|k| {
        ((bbox.max[k] - bbox.min[k] + 2.0 * pad) / cell).ceil() as usize + 1
    });
    let [nx, ny, nz] = dims;
    let n = nx * ny * nz;
    let at = |i: usize, j: usize, k: usize| i + nx * (j + ny * k);
    let coords = |v: usize| [v % nx, (v / nx) % ny, v / (nx * ny)];
    let position = |v: usize| {
        let c = coords(v);
        [0, 1, 2].map(|k| origin[k] + c[k] as f64 * cell)
    };

    // The band: grid vertices within `radius` plus a cell of a sample (a box around each
    // sample's nearest vertex, dilated axis by axis).
    let mut band = vec![false; n];
    for p in points {
        let c: [usize; 3] = std::array::from_fn(|k| {
            (((p[k] - origin[k]) / cell).round() as usize).min(dims[k] - 1)
        });
        band[at(c[0], c[1], c[2])] = true;
    }
    let reach = (radius / cell).ceil() as usize + 1;
    for axis in 0..3 {
        band = dilate(&band, dims, axis, reach);
    }
    // f = d - r on the band, +inf elsewhere (farther than r from every sample).
    let mut field: Vec<f32> = (0..n)
        .into_par_iter()
        .map(|v| {
            if !band[v] {
                return f32::INFINITY;
            }
            let q = position(v);
            (index.nearest_one(&q).1.sqrt() - radius) as f32
        })
        .collect();
    drop(band);

    // Outside: reachable from the grid's border through f > 0 (6-connected). The border's
    // vertices are marked first; the search then walks inner vertices only, whose six
    // neighbours are all in the grid (index steps, no bounds to test).
    let mut outside = vec![false; n];
    let on_border = |v: usize| {
        let c = coords(v);
        (0..3).any(|k| c[k] == 0 || c[k] == dims[k] - 1)
    };
    let mut border: Vec<usize> = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            let row = at(0, j, k);
            if k == 0 || k == nz - 1 || j == 0 || j == ny - 1 {
                border.extend(row..row + nx);
            } else {
                border.push(row);
                border.push(row + nx - 1);
            }
        }
    }
    for &v in &border {
        if field[v] > 0.0 {
            outside[v] = true;
        }
    }
    let steps = [1, nx, nx * ny];
    let mut stack: Vec<usize> = Vec::new();
    for &v in &border {
        if !outside[v] {
            continue;
        }
        let c = coords(v);
        for (k, &step) in steps.iter().enumerate() {
            let below = (c[k] > 0).then(|| v - step);
            let above = (c[k] + 1 < dims[k]).then_some(v + step);
            for w in below.into_iter().chain(above) {
                if !on_border(w) && !outside[w] && field[w] > 0.0 {
                    outside[w] = true;
                    stack.push(w);
                }
            }
        }
    }
    while let Some(v) = stack.pop() {
        for &step in &steps {
            for w in [v - step, v + step] {
                if !outside[w] && field[w] > 0.0 {
                    outside[w] = true;
                    stack.push(w);
                }
            }
        }
    }
    // The signed field: inside (negative) is the dilated set and everything it encloses.
    let cellf = cell as f32;
    field
        .par_iter_mut()
        .zip(outside.par_iter())
        .for_each(|(f, &out)| {
            *f = match (out, f.is_finite()) {
                (true, true) => *f,
                (true, false) => cellf,
                (false, true) if *f < 0.0 => *f,
                (false, true) => -f.max(f32::MIN_POSITIVE),
                (false, false) => -cellf,
            }
        });
    drop(outside);

    // Marching tetrahedra, one z-slab of cubes per task; triangles as triples of grid-edge
    // keys (lower vertex * 8 + direction bits), oriented from inside to outside.
    let inside = |v: usize| field[v] < 0.0;
    let key_point = |key: u64| -> Point3 {
        let v = (key / 8) as usize;
        let dir = (key % 8) as usize;
        let c = coords(v);
        let w = at(
            c[0] + (dir & 1),
            c[1] + ((dir >> 1) & 1),
            c[2] + ((dir >> 2) & 1),
        );
        let (fa, fb) = (field[v] as f64, field[w] as f64);
        let t = (fa / (fa - fb)).clamp(0.05, 0.95);
        let (a, b) = (position(v), position(w));
        [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]))
    };
    let triangles: Vec<[u64; 3]> = (0..nz - 1)
        .into_par_iter()
        .flat_map_iter(|k| {
            let mut out: Vec<[u64; 3]> = Vec::new();
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    let corner = |bits: usize| {
                        at(i + (bits & 1), j + ((bits >> 1) & 1), k + ((bits >> 2) & 1))
                    };
                    let signs: [bool; 8] = std::array::from_fn(|b| inside(corner(b)));
                    if signs.iter().all(|&s| s) || signs.iter().all(|&s| !s) {
                        continue;
                    }
                    for [a, b, _] in PERMUTATIONS {
                        let tet = [0, 1 << a, (1 << a) | (1 << b), 7];
                        tetrahedron(tet, &signs, &corner, &key_point, &mut out);
                    }
                }
            }
            out
        })
        .collect();
    if triangles.is_empty() {
        return Err(Error::InvalidInput(
            "envelope: the dilated cloud has no boundary".into(),
        ));
    }

    // Vertices: the distinct keys, in key order (the same whatever the thread count).
    let mut keys: Vec<u64> = triangles.iter().flatten().copied().collect();
    keys.par_sort_unstable();
    keys.dedup();
    let id = |k: u64| keys.binary_search(&k).map(|i| i as u32).unwrap_or(0);
    let faces: Vec<[u32; 3]> = triangles.par_iter().map(|t| t.map(id)).collect();
    let positions: Vec<Point3> = keys.par_iter().map(|&k| key_point(k)).collect();
    let (faces, dropped) = largest_components(positions.len(), faces);
    let mesh = super::compact(&positions, faces)?;
    Ok(Envelope {
        mesh,
        radius,
        cell,
        dropped,
        base_radius,
        base_cell,
    })
}

/// A cloud is a sheet (a single-view scan, an open surface) rather than the boundary of a
/// solid when at least this fraction of its envelope lies behind the samples' normals.
pub const SHEET_FRACTION: f64 = 0.2;

/// Triangles of the envelope probed (one in this many) before all of them are: a probe with
/// less than half [`SHEET_FRACTION`] behind the samples is a solid's.
const SHEET_PROBE: usize = 16;

/// For a cloud that is a sheet, the triangles of its envelope to keep: those in front of the
/// samples (the side their normals face: the scanner's, or the outside of an open part), one
/// edge-connected piece. The envelope of a sheet wraps both of its sides and meets itself
/// around the rim; its front alone is the open surface the samples lie on, offset by the
/// radius, bounded where the data ends. None when the cloud bounds a solid (less than
/// [`SHEET_FRACTION`] of the envelope behind the samples).
pub(crate) fn front_side(
    mesh: &TriMesh,
    points: &[Point3],
    normals: &[Point3],
    index: &KdIndex,
) -> Option<Vec<bool>> {
    use crate::geometry::vec3::{dist2, dot, sub};
    let p = &mesh.vertices.positions;
    let centre = |f: &[u32; 3]| {
        [0, 1, 2].map(|k| (p[f[0] as usize][k] + p[f[1] as usize][k] + p[f[2] as usize][k]) / 3.0)
    };
    // Whether the point c lies on the side sample i's normal faces.
    let ahead = |c: Point3, i: usize| dot(sub(c, points[i]), normals[i]) > 0.0;
    let in_front = |f: &[u32; 3]| {
        let c = centre(f);
        ahead(c, index.nearest_one(&c).0 as usize)
    };
    let behind_fraction = |front: &[bool]| {
        let ahead = front.iter().filter(|&&f| f).count();
        ahead.min(front.len() - ahead) as f64 / front.len().max(1) as f64
    };
    // A solid's envelope lies all in front of its samples, a sheet's half behind: every
    // [`SHEET_PROBE`]-th triangle tells a solid apart at a fraction of the cost.
    let probe: Vec<bool> = mesh
        .faces
        .par_iter()
        .step_by(SHEET_PROBE)
        .map(in_front)
        .collect();
    if behind_fraction(&probe) < 0.5 * SHEET_FRACTION {
        return None;
    }
    // All triangles: the sample nearest each vertex, and for each triangle the one of its
    // corners' samples nearest its centre (a vertex is shared by about six triangles: half
    // the queries of asking at each centre, for a side test that any sample nearly as near
    // answers alike).
    let nearest: Vec<u32> = p.par_iter().map(|q| index.nearest_one(q).0).collect();
    let mut front: Vec<bool> = mesh
        .faces
        .par_iter()
        .map(|f| {
            let c = centre(f);
            let i = f
                .iter()
                .map(|&v| nearest[v as usize] as usize)
                .min_by(|&a, &b| {
                    dist2(c, points[a])
                        .total_cmp(&dist2(c, points[b]))
                        .then(a.cmp(&b))
                })
                .unwrap_or(0);
            ahead(c, i)
        })
        .collect();
    let n = front.len();
    if behind_fraction(&front) < SHEET_FRACTION {
        return None;
    }
    let neighbours = pieces::edge_neighbours(mesh);
    // The rim's sides are ragged: three rounds of majority among a triangle and its three
    // neighbours.
    for _ in 0..3 {
        front = (0..n)
            .into_par_iter()
            .map(|t| {
                let around = neighbours.row(t);
                let votes = around.iter().filter(|&&u| front[u as usize]).count();
                match (2 * votes).cmp(&around.len()) {
                    std::cmp::Ordering::Greater => true,
                    std::cmp::Ordering::Less => false,
                    std::cmp::Ordering::Equal => front[t],
                }
            })
            .collect();
    }
    // The largest piece of the front, with the holes in it filled (every piece of the back but
    // the largest), and no vertex where the front pinches.
    front = pieces::largest_piece(&front, &neighbours)?;
    let back: Vec<bool> = front.iter().map(|&f| !f).collect();
    let back = pieces::largest_piece(&back, &neighbours)?;
    front = back.iter().map(|&b| !b).collect();
    pieces::manifold_piece(mesh, &front, &neighbours)
}

/// The axis permutations (a, b, c): the Kuhn tetrahedron of a permutation walks from the cube's
/// corner 0 along axis a, then b, then c to corner 7.
const PERMUTATIONS: [[usize; 3]; 6] = [
    [0, 1, 2],
    [0, 2, 1],
    [1, 0, 2],
    [1, 2, 0],
    [2, 0, 1],
    [2, 1, 0],
];

/// The zero set of the linear field over one tetrahedron (corners as cube corner bits, each a
/// subset of the next): a triangle when one or three corners are inside, two when two are,
/// each turned so that its normal points from the inside corners to the outside ones.
fn tetrahedron(
    tet: [usize; 4],
    signs: &[bool; 8],
    corner: &dyn Fn(usize) -> usize,
    key_point: &dyn Fn(u64) -> Point3,
    out: &mut Vec<[u64; 3]>,
) {
    let ins: Vec<usize> = tet.iter().copied().filter(|&c| signs[c]).collect();
    let outs: Vec<usize> = tet.iter().copied().filter(|&c| !signs[c]).collect();
    if ins.is_empty() || outs.is_empty() {
        return;
    }
    // The grid edge between two corners of the tetrahedron: one is a subset of the other.
    let key = |p: usize, q: usize| {
        let (lo, hi) = if p & q == p { (p, q) } else { (q, p) };
        corner(lo) as u64 * 8 + (hi ^ lo) as u64
    };
    let mut tris: Vec<[u64; 3]> = Vec::with_capacity(2);
    match (ins.len(), outs.len()) {
        (1, 3) => tris.push([
            key(ins[0], outs[0]),
            key(ins[0], outs[1]),
            key(ins[0], outs[2]),
        ]),
        (3, 1) => tris.push([
            key(outs[0], ins[0]),
            key(outs[0], ins[1]),
            key(outs[0], ins[2]),
        ]),
        _ => {
            let (a, b, c, d) = (ins[0], ins[1], outs[0], outs[1]);
            // The quad ac, ad, bd, bc: each side on one face of the tetrahedron.
            tris.push([key(a, c), key(a, d), key(b, d)]);
            tris.push([key(a, c), key(b, d), key(b, c)]);
        }
    }
    let mean = |cs: &[usize]| {
        let mut m = [0.0; 3];
        for &c in cs {
            for (k, mk) in m.iter_mut().enumerate() {
                *mk += ((c >> k) & 1) as f64 / cs.len() as f64;
            }
        }
        m
    };
    let (mi, mo) = (mean(&ins), mean(&outs));
    let gradient = [0, 1, 2].map(|k| mo[k] - mi[k]);
    for t in tris {
        let [p, q, r] = t.map(key_point);
        let n = crate::geometry::vec3::cross(
            crate::geometry::vec3::sub(q, p),
            crate::geometry::vec3::sub(r, p),
        );
        if crate::geometry::vec3::dot(n, gradient) >= 0.0 {
            out.push(t);
        } else {
            out.push([t[0], t[2], t[1]]);
        }
    }
}

/// `band` dilated by `reach` vertices along `axis`.
fn dilate(band: &[bool], dims: [usize; 3], axis: usize, reach: usize) -> Vec<bool> {
    let stride = match axis {
        0 => 1,
        1 => dims[0],
        _ => dims[0] * dims[1],
    };
    let len = dims[axis];
    let mut out = vec![false; band.len()];
    out.par_chunks_mut(dims[0] * dims[1])
        .enumerate()
        .for_each(|(k, slab)| {
            let base = k * dims[0] * dims[1];
            for (o, flag) in slab.iter_mut().enumerate() {
                let v = base + o;
                let c = (v / stride) % len;
                let lo = c.saturating_sub(reach);
                let hi = (c + reach).min(len - 1);
                *flag = (lo..=hi).any(|x| band[v - c * stride + x * stride]);
            }
        });
    out
}

/// The triangles of the components (by shared vertices) holding at least
/// [`MIN_COMPONENT_FRACTION`] of the largest one's triangles, and how many were dropped.
fn largest_components(nv: usize, faces: Vec<[u32; 3]>) -> (Vec<[u32; 3]>, usize) {
    let mut sets = crate::geometry::union_find::UnionFind::new(nv);
    for f in &faces {
        sets.union(f[0], f[1]);
        sets.union(f[0], f[2]);
    }
    let roots: Vec<u32> = faces.iter().map(|f| sets.find(f[0])).collect();
    let mut count = vec![0usize; nv];
    for &r in &roots {
        count[r as usize] += 1;
    }
    let largest = count.iter().copied().max().unwrap_or(0);
    let keep = |r: u32| count[r as usize] as f64 >= MIN_COMPONENT_FRACTION * largest as f64;
    let dropped = count
        .iter()
        .enumerate()
        .filter(|&(r, &c)| c > 0 && !keep(r as u32))
        .count();
    let faces = faces
        .into_iter()
        .zip(roots)
        .filter(|&(_, r)| keep(r))
        .map(|(f, _)| f)
        .collect();
    (faces, dropped)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::vec3::norm;

    /// A closed 2-manifold, oriented outward: every directed edge once, its twin once.
    fn assert_closed_manifold(mesh: &TriMesh) {
        let mut directed = std::collections::HashMap::new();
        for f in &mesh.faces {
            for e in 0..3 {
                *directed.entry((f[e], f[(e + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &c) in &directed {
            assert_eq!(c, 1, "edge {a}-{b} walked {c} times");
            assert_eq!(directed.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
        }
    }

    #[test]
    fn the_envelope_of_a_sphere_is_a_closed_outward_surface_at_the_radius() {
        // 4000 points on the unit sphere (Fibonacci lattice): spacing about 0.056.
        let n = 4000;
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        let points: Vec<Point3> = (0..n)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
                let r = (1.0 - z * z).sqrt();
                let t = golden * i as f64;
                [r * t.cos(), r * t.sin(), z]
            })
            .collect();
        let index = KdIndex::new(&points).expect("points");
        let env = envelope(&points, &index, 0.1, 0.05).expect("envelope");
        assert_eq!(env.dropped, 0);
        assert_closed_manifold(&env.mesh);
        // The outer sheet only (the inside is filled): every vertex near 1 + r.
        for p in &env.mesh.vertices.positions {
            let d = norm(*p) - 1.0;
            assert!((d - env.radius).abs() < env.cell, "vertex at {d}");
        }
        // Outward: positive enclosed volume near (4/3)π(1 + r)³.
        let p = &env.mesh.vertices.positions;
        let volume: f64 = env
            .mesh
            .faces
            .iter()
            .map(|f| {
                let [a, b, c] = f.map(|v| p[v as usize]);
                crate::geometry::vec3::dot(a, crate::geometry::vec3::cross(b, c)) / 6.0
            })
            .sum();
        let exact = 4.0 / 3.0 * std::f64::consts::PI * (1.0 + env.radius).powi(3);
        assert!((volume / exact - 1.0).abs() < 0.03, "{volume} vs {exact}");
    }

    #[test]
    fn a_stray_cluster_is_dropped_and_counted() {
        let mut points: Vec<Point3> = Vec::new();
        for i in 0..40 {
            for j in 0..40 {
                for k in [0.0, 1.0] {
                    points.push([i as f64 / 39.0, j as f64 / 39.0, k]);
                    points.push([i as f64 / 39.0, k, j as f64 / 39.0]);
                    points.push([k, i as f64 / 39.0, j as f64 / 39.0]);
                }
            }
        }
        points.push([3.0, 3.0, 3.0]);
        let index = KdIndex::new(&points).expect("points");
        let env = envelope(&points, &index, 0.06, 0.03).expect("envelope");
        assert_eq!(env.dropped, 1);
        assert_closed_manifold(&env.mesh);
        assert!(env.mesh.vertices.positions.iter().all(|p| p[0] < 2.0));
    }
}
