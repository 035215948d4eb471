//! Segmentation of a triangle mesh into analytic surfaces — planes, cylinders, cones, spheres
//! and tori with their parameters — after Mizoguchi, Date, Kanai and Kishinami, "Segmentation
//! of Scanned Mesh into Analytic Surfaces Based on Robust Curvature Estimation and Region
//! Growing" (`mizoguchi-analytic-surface-segmentation`).
//!
//! Pipeline ([`segment_mesh`]):
//! 1. two-pass Bézier curvature with sharp-vertex recognition (section 3,
//!    [`crate::estimate::bezier`]);
//! 2. vertex labels and seed regions (section 4, [`labels`]);
//! 3. a fit per seed (section 5.1, [`fit`]: the paper's linear fits, then a geometric
//!    Levenberg–Marquardt refinement);
//! 4. region growing in descending seed size with the tolerances of equations 4 and 5, and a
//!    refit (section 5.2, [`grow`]);
//! 5. per-face surfaces, surface areas, RMS errors and adjacency.
//!
//! **Type choice between cylinder and cone.** Equation 3 tells cones from cylinders by the
//! variation of `κ_max` over a 2-ring, which is small on both when the mesh is fine or the cone
//! slender, and noisy on irregular tessellations. So a seed labelled cylinder or cone is fitted
//! with both, and the cone is kept only when its RMS error is below `cone_gain` times the
//! cylinder's (and its half angle above `min_cone_angle`). This model selection is an addition
//! to the paper.
//!
//! Surface-type codes (PLY `surface_type`, uchar) are those of
//! [`SurfaceType`](crate::synth::SurfaceType): plane 0, cylinder 1, cone 2, sphere 3, torus 4,
//! 255 unassigned.

pub mod fit;
pub mod grow;
pub mod labels;
pub mod score;

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::estimate::bezier::{bezier_curvature, BezierParams};
use crate::geometry::{face_areas, Aabb, MeshTopology, TriMesh};
use crate::synth::{SurfaceParams, SurfaceType};
use crate::{Error, Result};

pub use fit::Fit;
pub use labels::{label, LabelParams};

/// Parameters of [`segment_mesh`]. `Default` = the paper's values (made scale-invariant as
/// documented on each field).
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentParams {
    /// Curvature estimation (section 3; W = 2 then 5, `th_se` relative to the edge length).
    pub bezier: BezierParams,
    /// Labels and seeds (section 4).
    pub labels: LabelParams,
    /// `th_pos` of equation 4 in units of the mean edge length (paper: 0.5).
    pub th_pos: f64,
    /// `th_norm` of equation 5 in degrees (paper: 8).
    pub th_norm_degrees: f64,
    /// A cone replaces a cylinder fit when its RMS error is below this fraction of the
    /// cylinder's (default 0.5).
    pub cone_gain: f64,
    /// Smallest half angle (degrees) a cone may have; slimmer ones are cylinders (default 1).
    pub min_cone_angle_degrees: f64,
    /// Rounds of face propagation for faces whose vertices belong to no compatible region
    /// (default 3).
    pub face_passes: usize,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            bezier: BezierParams::default(),
            labels: LabelParams::default(),
            th_pos: 0.5,
            th_norm_degrees: 8.0,
            cone_gain: 0.5,
            min_cone_angle_degrees: 1.0,
            face_passes: 3,
        }
    }
}

/// One extracted analytic surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SegmentSurface {
    /// Surface id (the `surface` values).
    pub id: u32,
    /// Type (serialised as its lower-case name).
    #[serde(rename = "type", serialize_with = "type_name")]
    pub kind: SurfaceType,
    /// Parameters (plane: normal and offset; cylinder: axis point, direction, radius; cone:
    /// apex, axis direction from the apex into the patch, half angle in radians; sphere:
    /// centre, radius; torus: centre, axis, major and minor radius).
    pub params: SurfaceParams,
    /// Total area of its faces.
    pub area: f64,
    /// Number of its vertices (the grown region).
    pub vertices: usize,
    /// Number of its faces.
    pub faces: usize,
    /// Area-weighted RMS of the orthogonal distances of its vertices to the surface.
    pub rms: f64,
    /// Ids of the surfaces sharing a mesh edge with it, ascending.
    pub neighbours: Vec<u32>,
}

/// Result of [`segment_mesh`]. Per-vertex and per-face vectors follow the input order.
#[derive(Debug, Clone)]
pub struct Segmentation {
    /// The surfaces, id = index; ordered by decreasing vertex count of their seeds' growth.
    pub surfaces: Vec<SegmentSurface>,
    /// Per face: surface id or -1.
    pub face_surface: Vec<i32>,
    /// Per vertex: surface id of the region it was grown into, or -1.
    pub vertex_surface: Vec<i32>,
    /// Per vertex: label of section 4 ([`label`]).
    pub vertex_labels: Vec<u8>,
    /// Number of seed regions.
    pub seeds: usize,
    /// Mean edge length `l̄`.
    pub mean_edge: f64,
    /// ε of equation 2 used (1/length).
    pub epsilon: f64,
    /// Seconds per stage: curvature, labels, seed fits, growing, faces.
    pub timings: Vec<(&'static str, f64)>,
}

impl Segmentation {
    /// Per face: the `surface_type` code (255 when unassigned).
    pub fn face_types(&self) -> Vec<u8> {
        self.face_surface
            .iter()
            .map(|&s| {
                if s < 0 {
                    SurfaceType::Other.code()
                } else {
                    self.surfaces[s as usize].kind.code()
                }
            })
            .collect()
    }
}

fn type_name<S: serde::Serializer>(t: &SurfaceType, s: S) -> std::result::Result<S::Ok, S::Error> {
    s.serialize_str(t.name())
}

fn seed_kind(l: u8) -> SurfaceType {
    match l {
        label::PLANE => SurfaceType::Plane,
        label::CYLINDER => SurfaceType::Cylinder,
        label::SPHERE => SurfaceType::Sphere,
        label::CONE => SurfaceType::Cone,
        label::TORUS => SurfaceType::Torus,
        _ => SurfaceType::Other,
    }
}

/// Segments `mesh` into analytic surfaces (see the module documentation).
///
/// Inputs: a triangle mesh and its topology (same vertex count).
/// Output: per-face and per-vertex surface ids and the surfaces with their parameters,
/// identical whatever the thread count.
/// Errors: topology of another mesh, invalid parameters, a mesh without edges.
pub fn segment_mesh(
    mesh: &TriMesh,
    topo: &MeshTopology,
    params: &SegmentParams,
) -> Result<Segmentation> {
    if !(params.th_pos > 0.0 && params.th_pos.is_finite())
        || !(params.th_norm_degrees > 0.0 && params.th_norm_degrees < 90.0)
    {
        return Err(Error::InvalidArgument(format!(
            "segmentation: th_pos must be positive and th_norm in (0, 90) degrees, got {} and {}",
            params.th_pos, params.th_norm_degrees
        )));
    }
    let mut timings = Vec::new();
    let t = Instant::now();
    let bez = bezier_curvature(mesh, topo, &params.bezier)?;
    timings.push(("curvature", t.elapsed().as_secs_f64()));
    let t = Instant::now();
    let nv = mesh.num_vertices();
    let l = bez.mean_edge;
    let diag = Aabb::from_points(mesh.positions())
        .map(|b| b.diagonal())
        .filter(|d| *d > 0.0)
        .ok_or_else(|| Error::InvalidInput("segmentation: the mesh has no extent".into()))?;
    let eps = params.labels.epsilon(l, diag);
    let c = &bez.curvature;
    let (kmax, kmin): (Vec<f64>, Vec<f64>) = c
        .k1
        .iter()
        .zip(&c.k2)
        .map(|(&a, &b)| if a.abs() >= b.abs() { (a, b) } else { (b, a) })
        .unzip();
    let vertex_labels =
        labels::vertex_labels(&kmax, &kmin, &bez.sharp, topo, eps, l, &params.labels);
    let seeds = labels::seed_regions(&vertex_labels, topo, &params.labels);
    timings.push(("labels", t.elapsed().as_secs_f64()));

    // Vertex normals n_i (equation 5) and weights (a third of the incident faces' areas).
    let t = Instant::now();
    let vnormal = crate::estimate::mesh_vertex_normals(mesh, crate::estimate::Weighting::Area)?;
    let areas = face_areas(mesh);
    let weight: Vec<f64> = (0..nv)
        .into_par_iter()
        .map(|v| {
            let a: f64 = topo
                .vertex_faces(v)
                .iter()
                .map(|&f| areas[f as usize])
                .filter(|a| a.is_finite())
                .sum::<f64>()
                / 3.0;
            // Isolated or degenerate vertices still count a little.
            a.max(1e-12 * l * l)
        })
        .collect();
    let tol = grow::Tol {
        pos: params.th_pos * l,
        cos_norm: params.th_norm_degrees.to_radians().cos(),
    };
    let ctx = grow::Ctx {
        topo,
        pos: mesh.positions(),
        vnormal: &vnormal,
        fnormal: &c.normal,
        weight: &weight,
        tol,
    };
    // Seed fits, with the cylinder / cone model selection.
    let min_cone = params.min_cone_angle_degrees.to_radians();
    let fitted: Vec<Option<(SurfaceType, Fit)>> = seeds
        .par_iter()
        .map(|(lab, vs)| {
            let kind = seed_kind(*lab);
            match kind {
                SurfaceType::Cylinder | SurfaceType::Cone => {
                    let cyl = ctx.fit(SurfaceType::Cylinder, vs);
                    let cone = if vs.len() >= 6 {
                        ctx.fit(SurfaceType::Cone, vs)
                    } else {
                        None
                    };
                    let cone_ok = |c: &Fit| match c.params {
                        SurfaceParams::Cone { half_angle, .. } => half_angle >= min_cone,
                        _ => false,
                    };
                    match (cyl, cone) {
                        (Some(a), Some(b)) if cone_ok(&b) && b.rms < params.cone_gain * a.rms => {
                            Some((SurfaceType::Cone, b))
                        }
                        (Some(a), _) => Some((SurfaceType::Cylinder, a)),
                        (None, Some(b)) if cone_ok(&b) => Some((SurfaceType::Cone, b)),
                        _ => None,
                    }
                }
                _ => ctx.fit(kind, vs).map(|f| (kind, f)),
            }
        })
        .collect();
    timings.push(("seed fits", t.elapsed().as_secs_f64()));

    // Growing in descending seed size (ties: seed order).
    let t = Instant::now();
    let mut order: Vec<usize> = (0..seeds.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(seeds[i].1.len()));
    let mut owner = vec![-1i32; nv];
    let mut regions: Vec<grow::Region> = Vec::new();
    for i in order {
        let Some((kind, f)) = fitted[i] else { continue };
        let (lab, vs) = &seeds[i];
        let min_seed = params.labels.seed_size(*lab);
        if let Some(r) = grow::grow_seed(
            &ctx,
            kind,
            vs,
            Some(f),
            min_seed,
            regions.len() as i32,
            &mut owner,
        ) {
            regions.push(r);
        }
    }
    timings.push(("growing", t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let face_surface =
        grow::assign_faces(mesh, topo, &owner, &regions, &tol, params.face_passes);
    let surfaces = summarise(topo, &regions, &face_surface, &areas, &ctx);
    timings.push(("faces", t.elapsed().as_secs_f64()));
    Ok(Segmentation {
        surfaces,
        face_surface,
        vertex_surface: owner,
        vertex_labels,
        seeds: seeds.len(),
        mean_edge: l,
        epsilon: eps,
        timings,
    })
}

/// Areas, counts, RMS errors and adjacency of the regions.
fn summarise(
    topo: &MeshTopology,
    regions: &[grow::Region],
    face_surface: &[i32],
    areas: &[f64],
    ctx: &grow::Ctx,
) -> Vec<SegmentSurface> {
    let n = regions.len();
    let mut area = vec![0.0; n];
    let mut faces = vec![0usize; n];
    for (f, &s) in face_surface.iter().enumerate() {
        if s >= 0 && areas[f].is_finite() {
            area[s as usize] += areas[f];
            faces[s as usize] += 1;
        }
    }
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
    for e in 0..topo.num_edges() {
        let fs = topo.edge_faces(e);
        for (i, &a) in fs.iter().enumerate() {
            for &b in &fs[i + 1..] {
                let (sa, sb) = (face_surface[a as usize], face_surface[b as usize]);
                if sa >= 0 && sb >= 0 && sa != sb {
                    adj[sa as usize].push(sb as u32);
                    adj[sb as usize].push(sa as u32);
                }
            }
        }
    }
    regions
        .par_iter()
        .enumerate()
        .map(|(i, r)| {
            let pts: Vec<_> = r.vertices.iter().map(|&v| ctx.pos[v as usize]).collect();
            let w: Vec<_> = r.vertices.iter().map(|&v| ctx.weight[v as usize]).collect();
            let mut nb = adj[i].clone();
            nb.sort_unstable();
            nb.dedup();
            SegmentSurface {
                id: i as u32,
                kind: r.kind,
                params: r.fit.params,
                area: area[i],
                vertices: r.vertices.len(),
                faces: faces[i],
                rms: fit::rms_distance(&r.fit.params, &pts, &w),
                neighbours: nb,
            }
        })
        .collect()
}
