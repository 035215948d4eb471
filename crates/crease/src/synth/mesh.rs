//! Tessellation of the synthetic parts with vertices exactly on the surfaces and on the feature
//! curves, so that the mesh edges along the curves are known exactly.
//!
//! Structured grids: the cube, the rounded cube and the sphere are one construction (a grid on
//! the surface of a "virtual" cube, each virtual point t mapped to `c + r·normalize(t - c)` with
//! `c = clamp(t, -a, a)`, a = half side of the inner box, r = fillet radius; r = 0 gives the
//! cube, a = 0 the sphere), whose grid lines at ±a are the plane / fillet / corner borders. The
//! torus and the open primitives (plane, cylinder, cone) use their (angle, angle) or
//! (angle, height) grids. Shared vertices are identified by their integer grid keys, so the
//! solids are watertight by construction. The box with a hole, the two cylinders and the
//! fillet-chamfer-cone block are triangulated patch by patch in their parameter domains
//! (constrained Delaunay triangulation of the trimmed domain, see `trimmed.rs`).

use std::collections::HashMap;
use std::f64::consts::{FRAC_PI_4, TAU};

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;

use super::sample::{check_sigma, check_tolerance, mix, truth_attributes};
use super::shapes::{rounded_cube_corner_id, rounded_cube_fillet_id, rounded_cube_plane_id, Model};
use super::truth::{CurveIndex, CurveKind};
use super::{attr, FeatureCurve, Noise, NoiseScale, Shape, Surface};
use crate::geometry::vec3::{add, cross, dot, normalize, scale, sub};
use crate::geometry::SurfaceType;
use crate::geometry::{Attribute, Point3, PointCloud, ScalarKind, TriMesh};
use crate::{Error, Result};

/// Parameters of [`mesh`].
#[derive(Debug, Clone, PartialEq)]
pub struct MeshParams {
    /// Target edge length; default: the shape's largest extent / 40.
    pub target_edge: Option<f64>,
    /// Noise on the vertices (default none).
    pub noise: Noise,
    /// What the noise sigma is relative to: `Spacing` = the mean edge length of the clean
    /// mesh, `BoundingBox` = the bounding-box diagonal.
    pub noise_scale: NoiseScale,
    /// Random seed of the noise.
    pub seed: u64,
    /// Label tolerance of `gt_sharp` / `gt_smooth`; default: the mean edge length.
    pub sharp_tolerance: Option<f64>,
}

impl Default for MeshParams {
    fn default() -> Self {
        MeshParams {
            target_edge: None,
            noise: Noise::None,
            noise_scale: NoiseScale::Spacing,
            seed: 1,
            sharp_tolerance: None,
        }
    }
}

/// A tessellated synthetic part with exact ground truth.
#[derive(Debug, Clone)]
pub struct SyntheticMesh {
    /// The mesh. Vertices carry exact normals (of the surface `gt_surface` names; a vertex on a
    /// border between patches gets one of them) and the `gt_*` attributes of the noise-free
    /// positions; faces carry `gt_surface` (I32) and `gt_surface_type` (U8).
    pub mesh: TriMesh,
    /// The patches; `gt_surface` indexes this list.
    pub surfaces: Vec<Surface>,
    /// The exact feature curves.
    pub curves: Vec<FeatureCurve>,
    /// Mesh edges (sorted vertex pairs, sorted) lying on sharp curves: their two faces belong to
    /// different patches meeting at a crease.
    pub sharp_edges: Vec<[u32; 2]>,
    /// Mesh edges lying on smooth curves.
    pub smooth_edges: Vec<[u32; 2]>,
    /// Mean edge length of the noise-free mesh.
    pub mean_edge: f64,
    /// Tolerance used for the vertex labels.
    pub sharp_tolerance: f64,
}

/// Tessellates `shape` (see the module documentation for the supported shapes).
pub fn mesh(shape: &Shape, p: &MeshParams) -> Result<SyntheticMesh> {
    check_sigma(p.noise)?;
    check_tolerance(p.sharp_tolerance)?;
    let model = shape.model()?;
    let size = shape.aabb().max_side();
    let target = p.target_edge.unwrap_or(size / 40.0);
    if !(target.is_finite() && target > 0.0 && target >= size * 1e-4) {
        return Err(Error::InvalidInput(format!(
            "synthetic mesh: target edge length must be positive and at least 1e-4 of the size \
             ({size}), got {target}"
        )));
    }
    let raw = match *shape {
        Shape::Cube { size } => cube_grid(size / 2.0, 0.0, target),
        Shape::RoundedCube { size, radius } => cube_grid(size / 2.0 - radius, radius, target),
        Shape::Sphere { radius } => cube_grid(0.0, radius, target),
        Shape::Torus {
            major_radius,
            minor_radius,
        } => {
            let nt = steps(TAU * (major_radius + minor_radius), target).max(3);
            let np = steps(TAU * minor_radius, target).max(3);
            let patch = &model.patches[0];
            periodic_grid(nt, np, true, |i, j| {
                let th = TAU * i as f64 / nt as f64;
                let ph = TAU * j as f64 / np as f64;
                let (q, n) = torus(major_radius, minor_radius, th, ph);
                (q, n, patch.surface.id)
            })
        }
        Shape::Cylinder { radius, height } => {
            let nt = steps(TAU * radius, target).max(3);
            let nz = steps(height, target);
            periodic_grid(nt, nz + 1, false, |i, j| {
                let th = TAU * i as f64 / nt as f64;
                let z = -height / 2.0 + height * j as f64 / nz as f64;
                let (s, c) = th.sin_cos();
                ([radius * c, radius * s, z], [c, s, 0.0], 0)
            })
        }
        Shape::Cone {
            bottom_radius,
            top_radius,
            height,
        } => {
            let nt = steps(TAU * bottom_radius, target).max(3);
            let slant = (bottom_radius - top_radius).hypot(height);
            let nz = steps(slant, target);
            let alpha = ((bottom_radius - top_radius) / height).atan();
            let (sa, ca) = alpha.sin_cos();
            periodic_grid(nt, nz + 1, false, |i, j| {
                let th = TAU * i as f64 / nt as f64;
                let f = j as f64 / nz as f64;
                let r = bottom_radius + (top_radius - bottom_radius) * f;
                let z = height * f;
                let (s, c) = th.sin_cos();
                ([r * c, r * s, z], [ca * c, ca * s, sa], 0)
            })
        }
        Shape::Plane { size } => {
            let n = steps(size, target);
            let h = size / 2.0;
            let coord = |i: usize| -h + size * i as f64 / n as f64;
            let mut raw = Raw::default();
            for j in 0..=n {
                for i in 0..=n {
                    raw.positions.push([coord(i), coord(j), 0.0]);
                    raw.normals.push([0.0, 0.0, 1.0]);
                    raw.vsurf.push(0);
                }
            }
            let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
            for j in 0..n {
                for i in 0..n {
                    raw.quad(
                        [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)],
                        0,
                        [0.0, 0.0, 1.0],
                    );
                }
            }
            raw
        }
        Shape::BoxWithHole { .. }
        | Shape::TwoCylinders { .. }
        | Shape::FilletChamferCone { .. } => super::trimmed::mesh_trimmed(shape, &model, target)?,
    };
    finish(shape, model, raw, p)
}

/// Number of pieces of about `target` length on a curve of length `length` (at least 1).
pub(super) fn steps(length: f64, target: f64) -> usize {
    ((length / target).round() as usize).max(1)
}

/// Vertices, normals, vertex surface ids, faces, face surface ids.
#[derive(Default)]
pub(super) struct Raw {
    pub positions: Vec<Point3>,
    pub normals: Vec<Point3>,
    pub vsurf: Vec<u32>,
    pub faces: Vec<[u32; 3]>,
    pub fsurf: Vec<u32>,
    /// Exact outward normal of the face's patch near the face (orients it).
    pub fnormal: Vec<Point3>,
}

impl Raw {
    /// Two triangles of the quad a b c d (counter-clockwise seen from outside).
    fn quad(&mut self, [a, b, c, d]: [u32; 4], surface: u32, normal: Point3) {
        self.faces.push([a, b, c]);
        self.faces.push([a, c, d]);
        self.fsurf.push(surface);
        self.fsurf.push(surface);
        self.fnormal.push(normal);
        self.fnormal.push(normal);
    }
}

fn torus(major: f64, minor: f64, th: f64, ph: f64) -> (Point3, Point3) {
    let (s, c) = th.sin_cos();
    let (sp, cp) = ph.sin_cos();
    let n = [cp * c, cp * s, sp];
    let rho = major + minor * cp;
    ([rho * c, rho * s, minor * sp], n)
}

/// Grid over (i, j), i periodic with `ni` steps, j with `nj` rows (periodic if `wrap_j`). The
/// quads are oriented afterwards from the normals.
fn periodic_grid(
    ni: usize,
    nj: usize,
    wrap_j: bool,
    at: impl Fn(usize, usize) -> (Point3, Point3, u32),
) -> Raw {
    let mut raw = Raw::default();
    for j in 0..nj {
        for i in 0..ni {
            let (q, n, s) = at(i, j);
            raw.positions.push(q);
            raw.normals.push(n);
            raw.vsurf.push(s);
        }
    }
    let id = |i: usize, j: usize| ((j % nj) * ni + i % ni) as u32;
    let rows = if wrap_j { nj } else { nj - 1 };
    for j in 0..rows {
        for i in 0..ni {
            let s = raw.vsurf[id(i, j) as usize];
            let n = raw.normals[id(i, j) as usize];
            raw.quad(
                [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)],
                s,
                n,
            );
        }
    }
    raw
}

/// The cube / rounded cube / sphere grid: inner half side `a`, radius `r`.
fn cube_grid(a: f64, r: f64, target: f64) -> Raw {
    // Virtual coordinates per axis: the round parts a + r tan θ (θ uniform in (0, π/4]), the
    // flat part [-a, a] uniform.
    let kr = if r > 0.0 {
        steps(r * FRAC_PI_4, target)
    } else {
        0
    };
    let m = if a > 0.0 { steps(2.0 * a, target) } else { 0 };
    let mut table = Vec::new();
    for q in (1..=kr).rev() {
        table.push(-a - r * (FRAC_PI_4 * q as f64 / kr as f64).tan());
    }
    if m == 0 {
        table.push(0.0);
    } else {
        for q in 0..=m {
            // Exact ±a at the ends.
            let t = if q == m {
                a
            } else {
                -a + 2.0 * a * q as f64 / m as f64
            };
            table.push(t);
        }
    }
    for q in 1..=kr {
        table.push(a + r * (FRAC_PI_4 * q as f64 / kr as f64).tan());
    }
    let n = table.len() - 1;
    let map = |t: Point3| -> (Point3, Point3, u32) {
        let beyond: Vec<usize> = (0..3).filter(|&k| t[k].abs() > a).collect();
        let sign = |k: usize| if t[k] > 0.0 { 1.0 } else { -1.0 };
        if r == 0.0 {
            // Cube: the face is the first axis at ±a.
            let k = (0..3).find(|&k| t[k].abs() >= a).unwrap_or(0);
            let mut nn = [0.0; 3];
            nn[k] = sign(k);
            return (t, nn, rounded_cube_plane_id(k, sign(k)));
        }
        let c: Point3 = std::array::from_fn(|k| t[k].clamp(-a, a));
        let nn = normalize(sub(t, c)).unwrap_or([0.0, 0.0, 1.0]);
        let q = add(c, scale(nn, r));
        let id = if a == 0.0 {
            0
        } else {
            match beyond.len() {
                1 => rounded_cube_plane_id(beyond[0], sign(beyond[0])),
                2 => {
                    let k = (0..3).find(|k| !beyond.contains(k)).unwrap_or(0);
                    rounded_cube_fillet_id(k, sign((k + 1) % 3), sign((k + 2) % 3))
                }
                _ => rounded_cube_corner_id([sign(0), sign(1), sign(2)]),
            }
        };
        (q, nn, id)
    };
    let mut raw = Raw::default();
    let mut index: HashMap<[usize; 3], u32> = HashMap::new();
    let mut vertex = |key: [usize; 3], raw: &mut Raw| -> u32 {
        *index.entry(key).or_insert_with(|| {
            let t = [table[key[0]], table[key[1]], table[key[2]]];
            let (q, nn, s) = map(t);
            raw.positions.push(q);
            raw.normals.push(nn);
            raw.vsurf.push(s);
            (raw.positions.len() - 1) as u32
        })
    };
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        for side in [0, n] {
            for u in 0..n {
                for v in 0..n {
                    let key = |du: usize, dv: usize| {
                        let mut key = [0; 3];
                        key[k] = side;
                        key[i] = u + du;
                        key[j] = v + dv;
                        key
                    };
                    let ids = [
                        vertex(key(0, 0), &mut raw),
                        vertex(key(1, 0), &mut raw),
                        vertex(key(1, 1), &mut raw),
                        vertex(key(0, 1), &mut raw),
                    ];
                    let mut centre = [0.0; 3];
                    centre[k] = table[side];
                    centre[i] = 0.5 * (table[u] + table[u + 1]);
                    centre[j] = 0.5 * (table[v] + table[v + 1]);
                    let (_, nn, s) = map(centre);
                    raw.quad(ids, s, nn);
                }
            }
        }
    }
    raw
}

fn finish(shape: &Shape, model: Model, mut raw: Raw, p: &MeshParams) -> Result<SyntheticMesh> {
    // Orient every face along the exact normal of its patch.
    for (f, &n) in raw.faces.iter_mut().zip(&raw.fnormal) {
        let [a, b, c] = f.map(|v| raw.positions[v as usize]);
        let g = cross(sub(b, a), sub(c, a));
        if dot(g, n) < 0.0 {
            f.swap(1, 2);
        }
    }
    // Edges with their faces, in a deterministic order.
    let mut edge_faces: HashMap<[u32; 2], Vec<u32>> = HashMap::new();
    for (fi, f) in raw.faces.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            edge_faces
                .entry([a.min(b), a.max(b)])
                .or_default()
                .push(fi as u32);
        }
    }
    let mut edges: Vec<([u32; 2], Vec<u32>)> = edge_faces.into_iter().collect();
    edges.sort_unstable_by_key(|e| e.0);
    let mean_edge = edges
        .iter()
        .map(|(e, _)| {
            crate::geometry::vec3::dist(raw.positions[e[0] as usize], raw.positions[e[1] as usize])
        })
        .sum::<f64>()
        / edges.len().max(1) as f64;
    let sharp_index = CurveIndex::new(&model.curves, CurveKind::Sharp);
    let smooth_index = CurveIndex::new(&model.curves, CurveKind::Smooth);
    let mut sharp_edges = Vec::new();
    let mut smooth_edges = Vec::new();
    for (e, faces) in &edges {
        let [f0, f1] = match faces.as_slice() {
            [f0, f1] => [*f0, *f1],
            _ => continue,
        };
        if raw.fsurf[f0 as usize] == raw.fsurf[f1 as usize] {
            continue;
        }
        // A border between two patches: classify by the nearest curve kind at its midpoint.
        let a = raw.positions[e[0] as usize];
        let b = raw.positions[e[1] as usize];
        let mid = scale(add(a, b), 0.5);
        let ds = sharp_index.nearest(mid).0;
        let dm = smooth_index.nearest(mid).0;
        if ds <= dm {
            sharp_edges.push(*e);
        } else {
            smooth_edges.push(*e);
        }
    }
    let tol = p.sharp_tolerance.unwrap_or(mean_edge);
    let kinds: Vec<SurfaceType> = model.patches.iter().map(|q| q.surface.kind).collect();
    let surface: Vec<i64> = raw.vsurf.iter().map(|&s| i64::from(s)).collect();
    let attrs = truth_attributes(&raw.positions, &surface, &kinds, &model.curves, tol);
    let sigma = p.noise.sigma()
        * match p.noise_scale {
            NoiseScale::Spacing => mean_edge,
            NoiseScale::BoundingBox => model.bbox.diagonal(),
        };
    let mut rng = Pcg64::seed_from_u64(mix(p.seed, 0x6d65_7368));
    let positions: Vec<Point3> = raw
        .positions
        .iter()
        .zip(&raw.normals)
        .map(|(&q, &n)| match p.noise {
            Noise::None => q,
            Noise::AlongNormal(_) => {
                let g: f64 = StandardNormal.sample(&mut rng);
                add(q, scale(n, g * sigma))
            }
            Noise::Isotropic(_) => {
                let g: Point3 = [
                    StandardNormal.sample(&mut rng),
                    StandardNormal.sample(&mut rng),
                    StandardNormal.sample(&mut rng),
                ];
                add(q, scale(g, sigma))
            }
        })
        .collect();
    let mut vertices = PointCloud::from_positions(positions);
    vertices.set_normals(raw.normals)?;
    for a in attrs {
        vertices.set_attribute(a)?;
    }
    let mut tm = TriMesh {
        vertices,
        faces: raw.faces,
        face_attributes: Default::default(),
    };
    tm.set_face_attribute(Attribute::int(
        attr::SURFACE,
        raw.fsurf.iter().map(|&s| i64::from(s)),
    ))?;
    tm.set_face_attribute(Attribute {
        name: attr::SURFACE_TYPE.into(),
        kind: ScalarKind::U8,
        values: raw
            .fsurf
            .iter()
            .map(|&s| {
                f64::from(
                    kinds
                        .get(s as usize)
                        .copied()
                        .unwrap_or(SurfaceType::Other)
                        .code(),
                )
            })
            .collect(),
    })?;
    let _ = shape;
    Ok(SyntheticMesh {
        mesh: tm,
        surfaces: model.patches.iter().map(|q| q.surface.clone()).collect(),
        curves: model.curves,
        sharp_edges,
        smooth_edges,
        mean_edge,
        sharp_tolerance: tol,
    })
}

impl SyntheticMesh {
    /// The feature curves as a line set (same layout as `SyntheticPart::curves_geometry`).
    pub fn curves_geometry(&self) -> crate::io::Geometry {
        super::sample::curves_geometry(&self.curves)
    }
}

/// The synthetic parts the default edge classifier is trained on: every shape of
/// [`Shape::names`] tessellated with edges of 1/`per_side` of its largest side, named
/// `synth NAME /PER_SIDE`; each [`SyntheticMesh::sharp_edges`] labels it exactly.
pub fn training_meshes(per_side: &[f64]) -> Result<Vec<(String, SyntheticMesh)>> {
    let mut out = Vec::new();
    for &k in per_side {
        for name in Shape::names() {
            let shape = Shape::from_name(name)
                .ok_or_else(|| Error::InvalidArgument(format!("unknown shape {name}")))?;
            let m = mesh(
                &shape,
                &MeshParams {
                    target_edge: Some(shape.aabb().max_side() / k),
                    ..Default::default()
                },
            )?;
            out.push((format!("synth {name} /{k}"), m));
        }
    }
    Ok(out)
}
