//! Region growing (mizoguchi section 5.2) and the assignment of faces to the grown regions.
//!
//! **Growing.** Seeds are processed in descending order of their vertex count. A seed's fit
//! (section 5.1, refined, see [`super::fit`]) is first checked against the seed itself: only
//! the seed vertices compatible with it (equations 4 and 5) are kept, and the seed is dropped
//! when fewer than a quarter of its free vertices (or fewer than `th_seed`) are. This check is
//! not in the paper; it discards the seeds of mislabelled vertices (e.g. blends between two
//! surfaces labelled torus by Step 3) before they grow, while a seed that spans two surfaces
//! (a fillet's cylinder labels running on into the spherical corner) still grows from the part
//! its fit explains; the rest is picked up by the residual seeds. A vertex adjacent to the region joins it when it belongs
//! to no region yet and satisfies
//! - equation 4: `|v_i − p(v_i)| < th_pos · l̄`, with `p(v_i)` the nearest point of the
//!   surface (the paper projects along `n_i`; near the surface, where the test matters, both
//!   agree to first order, and the orthogonal distance is defined everywhere);
//! - equation 5: the angle between the vertex normal `n_i` (from the incident faces) and the
//!   surface normal at `p(v_i)` is below `th_norm`; orientation is ignored (unsigned angle), so
//!   the meshes need not be oriented.
//!
//! The paper grows once. Here the surface is refitted to the grown region and growing resumes
//! from it with the refitted surface (the seed's fit extrapolates poorly from a small seed),
//! then the surface is refitted a last time: the "refit" after growing.
//!
//! **Faces.** The output is per face. A face takes, among the regions of its three vertices,
//! the one it agrees with best (centroid distance over `th_pos · l̄` plus normal angle over
//! `th_norm`, both below 1); this resolves the vertices on creases, which belong to one region
//! but whose faces lie on both sides. Faces with no compatible candidate then take, over up to
//! `face_passes` rounds, a compatible region of an edge-adjacent face (faces whose three
//! vertices are all on creases, common in CAD tessellations). Faces left without one keep the
//! region holding two or three of their vertices, else -1.
//!
//! **Planar face patches (not in the paper).** A coarse CAD tessellation may have planar faces
//! without a single interior vertex (a cube of 12 triangles: every vertex is on a crease, so
//! none gets a label and no seed exists). The faces still unassigned are therefore joined
//! across the edges that are no creases (dihedral angle at most `crease_angle_degrees`), and
//! every such patch that is enclosed by creases and mesh borders (no smooth edge to an
//! assigned face: otherwise it is a left-over piece of a curved region) and has at least two
//! faces, whose vertices all pass equation 4 and whose face normals all pass
//! equation 5 against the area-weighted plane of its faces becomes a plane.

use crate::geometry::vec3::{dot, scale};
use crate::geometry::{MeshTopology, Point3, TriMesh};
use crate::geometry::{SurfaceParams, SurfaceType};
use crate::spatial::Adjacency;

use super::fit::{fit, Fit};
use crate::geometry::surface::{signed_distance, surface_normal, Prepared};
use crate::geometry::topology::NO_EDGE;

/// Tolerances of the compatibility tests.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tol {
    /// `th_pos · l̄` (length).
    pub pos: f64,
    /// cos(th_norm).
    pub cos_norm: f64,
}

impl Tol {
    /// Equations 4 and 5.
    #[inline]
    pub fn ok(&self, s: &Prepared, p: Point3, n: Point3) -> bool {
        s.signed_distance(p).abs() < self.pos && dot(s.normal(p), n).abs() > self.cos_norm
    }
}

/// Data the growing reads.
pub(crate) struct Ctx<'a, G: Adjacency> {
    pub topo: &'a G,
    pub pos: &'a [Point3],
    /// Face-based vertex normals `n_i` (equation 5).
    pub vnormal: &'a [Point3],
    /// Refitted normals `n'_i` (fits).
    pub fnormal: &'a [Point3],
    /// Vertex weights (areas).
    pub weight: &'a [f64],
    pub tol: Tol,
}

impl<G: Adjacency> Ctx<'_, G> {
    /// Fit of `kind` to vertices `vs`.
    pub fn fit(&self, kind: SurfaceType, vs: &[u32]) -> Option<Fit> {
        let pts: Vec<Point3> = vs.iter().map(|&v| self.pos[v as usize]).collect();
        let nrm: Vec<Point3> = vs.iter().map(|&v| self.fnormal[v as usize]).collect();
        let w: Vec<f64> = vs.iter().map(|&v| self.weight[v as usize]).collect();
        fit(kind, &pts, &nrm, &w)
    }

    /// Equations 4 and 5 for vertex `v`.
    pub fn ok(&self, s: &Prepared, v: u32) -> bool {
        self.tol
            .ok(s, self.pos[v as usize], self.vnormal[v as usize])
    }
}

/// A grown region.
#[derive(Debug, Clone)]
pub(crate) struct Region {
    pub kind: SurfaceType,
    pub fit: Fit,
    pub vertices: Vec<u32>,
}

/// Breadth-first growth of `region` (owned vertices marked with `id` in `owner`) by the
/// compatible unowned neighbours.
fn grow_bfs<G: Adjacency>(
    ctx: &Ctx<G>,
    s: &SurfaceParams,
    id: i32,
    region: &mut Vec<u32>,
    owner: &mut [i32],
) {
    let s = &Prepared::new(s);
    let mut head = 0;
    while head < region.len() {
        let u = region[head] as usize;
        head += 1;
        ctx.topo.for_each_neighbor(u, |w| {
            let wi = w as usize;
            if owner[wi] == -1 && ctx.ok(s, w) {
                owner[wi] = id;
                region.push(w);
            }
        });
    }
}

/// Grows `seed` (type, vertices, its fit) into a region with id `id`. `None` if the seed fails
/// its own check: fewer than `min_seed` compatible vertices, or fewer than `min_core_fraction`
/// of its vertices still free.
pub(crate) fn grow_seed<G: Adjacency>(
    ctx: &Ctx<G>,
    kind: SurfaceType,
    seed: &[u32],
    seed_fit: Option<Fit>,
    (min_seed, min_core_fraction): (usize, f64),
    id: i32,
    owner: &mut [i32],
) -> Option<Region> {
    let free: Vec<u32> = seed
        .iter()
        .copied()
        .filter(|&v| owner[v as usize] == -1)
        .collect();
    if free.len() < min_seed.max(1) {
        return None;
    }
    // The seed's fit stays valid when bigger regions took some of its vertices.
    let f = match seed_fit {
        Some(f) => f,
        None => ctx.fit(kind, &free)?,
    };
    let prepared = Prepared::new(&f.params);
    let core: Vec<u32> = free
        .iter()
        .copied()
        .filter(|&v| ctx.ok(&prepared, v))
        .collect();
    if core.len() < min_seed.max(1) || (core.len() as f64) < min_core_fraction * free.len() as f64 {
        return None;
    }
    let mut region = core;
    for &v in &region {
        owner[v as usize] = id;
    }
    grow_bfs(ctx, &f.params, id, &mut region, owner);
    let mut f = ctx.fit(kind, &region).unwrap_or(f);
    let before = region.len();
    grow_bfs(ctx, &f.params, id, &mut region, owner);
    if region.len() > before {
        f = ctx.fit(kind, &region).unwrap_or(f);
    }
    Some(Region {
        kind,
        fit: f,
        vertices: region,
    })
}

/// Border refinement (not in the paper): up to `passes` rounds in which every vertex owned by
/// a region moves to the region of a graph neighbour whose surface lies nearer to it
/// (orthogonal distance) and that it passes equations 4 and 5 for; the regions that changed
/// are then refitted. A round reads the owners of the previous one (results do not depend on
/// the thread count). A region left with fewer than `min_size(kind)` vertices gets its
/// vertices back.
///
/// Why: where two surfaces meet tangentially (a fillet and the planes it joins, a spherical
/// corner and its three fillets) the tolerances of equations 4 and 5 accept a strip of the
/// neighbour's points, and the surface that grows first takes it: on the rounded cube (fillet
/// radius 6 spacings) the planes took the first 8° of every fillet and the corner spheres a
/// fifth of their points from the fillets, which biased the spheres' radii by up to 1.3 % on
/// exact data. Past a tangent border the neighbour's points leave a surface quadratically but
/// lie on their own, so the nearer surface is the right owner; at a crease both distances grow
/// linearly from the crease line and the nearer one again is the right owner. With noise the
/// vertices of a tangent border whose noise points outwards lie nearer the neighbour's
/// surface and move, which biases a fillet's radius a little: on the rounded-cube mesh at 1 %
/// noise the fillets come out 0.7–1.1 % off (0.1–0.9 % without the refinement) but the
/// 19-vertex corner spheres 0.2–1.8 % (up to 24 % without). Moving only vertices that gain
/// more than 3 robust noise scales (1.4826 × median distance) kept the fillets at 0.1–0.9 %
/// but left the corner spheres up to 9.5 % off and typed 1.2 % less of the noisy rounded-cube
/// cloud; refitting on the interior vertices only (all neighbours in the region) made one
/// fillet 2.5 % off. Both were dropped.
pub(crate) fn refine_borders<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &mut [i32],
    regions: &mut [Region],
    passes: usize,
    min_size: impl Fn(SurfaceType) -> usize,
) {
    use rayon::prelude::*;
    for _ in 0..passes {
        let prepared: Vec<Prepared> = regions
            .iter()
            .map(|r| Prepared::new(&r.fit.params))
            .collect();
        let next: Vec<i32> = (0..owner.len())
            .into_par_iter()
            .map(|v| {
                let o = owner[v];
                if o < 0 {
                    return o;
                }
                let p = ctx.pos[v];
                let mut best = (prepared[o as usize].signed_distance(p).abs(), o);
                let mut seen = [o; 8];
                let mut nseen = 1;
                ctx.topo.for_each_neighbor(v, |w| {
                    let c = owner[w as usize];
                    if c < 0 || seen[..nseen].contains(&c) {
                        return;
                    }
                    if nseen < seen.len() {
                        seen[nseen] = c;
                        nseen += 1;
                    }
                    let s = &prepared[c as usize];
                    let d = s.signed_distance(p).abs();
                    if d < best.0 && ctx.ok(s, v as u32) {
                        best = (d, c);
                    }
                });
                best.1
            })
            .collect();
        // Sizes after the moves; regions that would fall below their minimum keep theirs.
        let mut size = vec![0usize; regions.len()];
        for &o in &next {
            if o >= 0 {
                size[o as usize] += 1;
            }
        }
        let mut next = next;
        for (v, n) in next.iter_mut().enumerate() {
            let o = owner[v];
            if o >= 0 && *n != o && size[o as usize] < min_size(regions[o as usize].kind) {
                *n = o;
            }
        }
        let mut changed = vec![false; regions.len()];
        for (v, &n) in next.iter().enumerate() {
            if n != owner[v] {
                changed[n as usize] = true;
                changed[owner[v] as usize] = true;
            }
        }
        if !changed.iter().any(|&c| c) {
            break;
        }
        owner.copy_from_slice(&next);
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); regions.len()];
        for (v, &o) in owner.iter().enumerate() {
            if o >= 0 {
                members[o as usize].push(v as u32);
            }
        }
        regions
            .par_iter_mut()
            .zip(members)
            .zip(&changed)
            .for_each(|((r, vs), &ch)| {
                if ch {
                    if let Some(f) = ctx.fit(r.kind, &vs) {
                        r.fit = f;
                    }
                }
                r.vertices = vs;
            });
    }
}

/// Per-face region (see the module documentation).
pub(crate) fn assign_faces(
    mesh: &TriMesh,
    topo: &MeshTopology,
    owner: &[i32],
    regions: &[Region],
    tol: &Tol,
    face_passes: usize,
) -> Vec<i32> {
    use rayon::prelude::*;
    let p = mesh.positions();
    let fnormals = topo.face_normals();
    let score = |f: usize, r: i32| -> f64 {
        let [a, b, c] = mesh.faces[f];
        let cen = scale(
            crate::geometry::vec3::add(
                crate::geometry::vec3::add(p[a as usize], p[b as usize]),
                p[c as usize],
            ),
            1.0 / 3.0,
        );
        let s = &regions[r as usize].fit.params;
        let d = signed_distance(s, cen).abs() / tol.pos;
        let cosang = dot(surface_normal(s, cen), fnormals[f]).abs().min(1.0);
        let a = cosang.acos() / tol.cos_norm.acos().max(1e-9);
        if d < 1.0 && a < 1.0 {
            d + a
        } else {
            f64::INFINITY
        }
    };
    let best = |f: usize, cands: &mut Vec<i32>| -> i32 {
        cands.sort_unstable();
        cands.dedup();
        let mut best = (f64::INFINITY, -1);
        for &r in cands.iter() {
            if r < 0 {
                continue;
            }
            let s = score(f, r);
            if s < best.0 {
                best = (s, r);
            }
        }
        best.1
    };
    let mut face: Vec<i32> = (0..mesh.faces.len())
        .into_par_iter()
        .map(|f| {
            let mut c: Vec<i32> = mesh.faces[f].iter().map(|&v| owner[v as usize]).collect();
            best(f, &mut c)
        })
        .collect();
    let fe = topo.face_edges();
    for _ in 0..face_passes {
        let next: Vec<i32> = (0..face.len())
            .into_par_iter()
            .map(|f| {
                if face[f] >= 0 {
                    return face[f];
                }
                let mut c = Vec::new();
                for &e in fe[f].iter().filter(|&&e| e != NO_EDGE) {
                    for &g in topo.edge_faces(e as usize) {
                        if g as usize != f {
                            c.push(face[g as usize]);
                        }
                    }
                }
                best(f, &mut c)
            })
            .collect();
        let changed = next != face;
        face = next;
        if !changed {
            break;
        }
    }
    // Fallback: the majority region of the face's vertices.
    face.par_iter_mut().enumerate().for_each(|(f, r)| {
        if *r < 0 {
            let o = mesh.faces[f].map(|v| owner[v as usize]);
            if o[0] >= 0 && (o[0] == o[1] || o[0] == o[2]) {
                *r = o[0];
            } else if o[1] >= 0 && o[1] == o[2] {
                *r = o[1];
            }
        }
    });
    face
}

/// Unassigned faces joined across non-crease edges into planar patches that become planes
/// (see the module documentation). New regions are appended to `regions`; their vertices that
/// belong to no region yet take the new id in `owner`.
pub(crate) fn planar_face_patches(
    mesh: &TriMesh,
    topo: &MeshTopology,
    tol: &Tol,
    crease: f64,
    face: &mut [i32],
    regions: &mut Vec<Region>,
    owner: &mut [i32],
) {
    let p = mesh.positions();
    let fnormals = topo.face_normals();
    let dihedral = topo.dihedral_angles();
    let fe = topo.face_edges();
    let areas = crate::geometry::face_areas(mesh);
    let mut seen = vec![false; face.len()];
    for start in 0..face.len() {
        if seen[start] || face[start] >= 0 {
            continue;
        }
        seen[start] = true;
        let mut comp = vec![start as u32];
        let mut head = 0;
        // Enclosed: every non-crease edge leads to another face of the patch.
        let mut enclosed = true;
        while head < comp.len() {
            let f = comp[head] as usize;
            head += 1;
            for &e in fe[f].iter().filter(|&&e| e != NO_EDGE) {
                if dihedral[e as usize] > crease {
                    continue;
                }
                for &g in topo.edge_faces(e as usize) {
                    let gi = g as usize;
                    if face[gi] >= 0 {
                        enclosed = false;
                    } else if !seen[gi] {
                        seen[gi] = true;
                        comp.push(g);
                    }
                }
            }
        }
        // Area-weighted plane of the patch (normals sign-aligned to the first face).
        let n0 = fnormals[comp[0] as usize];
        let (mut nsum, mut csum, mut asum) = ([0.0; 3], [0.0; 3], 0.0);
        for &f in &comp {
            let a = areas[f as usize];
            if !a.is_finite() {
                continue;
            }
            let n = fnormals[f as usize];
            let sgn = if dot(n, n0) < 0.0 { -a } else { a };
            nsum = crate::geometry::vec3::add(nsum, scale(n, sgn));
            let [i, j, k] = mesh.faces[f as usize];
            let c = crate::geometry::vec3::add(
                crate::geometry::vec3::add(p[i as usize], p[j as usize]),
                p[k as usize],
            );
            csum = crate::geometry::vec3::add(csum, scale(c, a / 3.0));
            asum += a;
        }
        let Some(normal) = crate::geometry::vec3::normalize(nsum) else {
            continue;
        };
        if asum <= 0.0 {
            continue;
        }
        let offset = dot(normal, scale(csum, 1.0 / asum));
        let plane = SurfaceParams::Plane { normal, offset };
        let mut verts: Vec<u32> = comp.iter().flat_map(|&f| mesh.faces[f as usize]).collect();
        verts.sort_unstable();
        verts.dedup();
        let planar = verts
            .iter()
            .all(|&v| signed_distance(&plane, p[v as usize]).abs() < tol.pos)
            && comp
                .iter()
                .all(|&f| dot(fnormals[f as usize], normal).abs() > tol.cos_norm);
        // A single triangle is planar whatever the surface under it.
        if !planar || !enclosed || comp.len() < 2 {
            continue;
        }
        let id = regions.len() as i32;
        let pts: Vec<Point3> = verts.iter().map(|&v| p[v as usize]).collect();
        let w = vec![1.0; pts.len()];
        let rms = super::fit::rms_distance(&plane, &pts, &w);
        for &f in &comp {
            face[f as usize] = id;
        }
        for &v in &verts {
            if owner[v as usize] < 0 {
                owner[v as usize] = id;
            }
        }
        regions.push(Region {
            kind: SurfaceType::Plane,
            fit: Fit { params: plane, rms },
            vertices: verts,
        });
    }
}
