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
//! 5. per-face surfaces, surface areas, RMS errors and adjacency;
//! 6. fillets, linear extrusions and surfaces of revolution (section 6, [`recognize`]).
//!
//! Point clouds ([`segment_points`], [`points`]): the same stages 2–4 and 6 over the
//! symmetrised k-nearest-neighbour graph, with the quadric-fit curvature; stages 2–4 are one
//! function over any vertex graph ([`crate::spatial::Adjacency`]) for both. Clouds then have
//! two stages of their own, judged against the noise measured on the seeds (not in the paper,
//! for scans with noise of half a spacing and more): regions that are one surface within the
//! noise made one, and curved types given where they clearly explain a region better
//! (`merge`); fillets made tangent to the planes they round (`tangent`).
//!
//! **Model selection (an addition to the paper).** The labels of section 4 decide a seed's type
//! in the paper. They are fragile where curvature estimates are: equation 3 tells cones from
//! cylinders by the variation of `κ_max` over a 2-ring, which is small on both when the mesh is
//! fine or the cone slender and noisy on irregular tessellations; on small CAD patches (the
//! ABC model's cone chamfers) the curvature fits near the borders give neither `κ_min ≈ 0` nor
//! equal curvatures, so the vertices end with label 0 and Step 3 calls them torus. So every seed
//! is fitted with its label's type and with the simpler types that type can degenerate to, and
//! the simplest one that fits about as well as the best is kept (see `SegmentParams::
//! simpler_factor`); cones slimmer than `min_cone_angle_degrees` are not considered.
//!
//! **Units.** The paper's thresholds are absolute (1/length, length); here every one is taken
//! relative to the mean edge length `l̄` (or the bounding-box diagonal `D`), so that the result
//! does not depend on the units of the input: `th_se = 0.4 / l̄` (section 3,
//! [`BezierParams`]), `ε = min(0.01 / l̄, 0.5 / D)` and the torus histogram step `0.01 / l̄`
//! (section 4, [`LabelParams`]), `th_pos · l̄` of equation 4 (growing, faces, planar patches),
//! `2 th_pos · l̄` for the positions of section 6, `simpler_floor · l̄` in the model selection,
//! and, not in the paper, the crease-band RMS floor `1e-6 l̄`, the cap `3 l̄` of the widened
//! tolerance and the least vertex weight `1e-12 l̄²`; angles are dimensionless. The fits use
//! relative steps and tolerances only (see [`fit`]). A scaled input therefore gives the same
//! labels and the same surfaces, scaled: bit for bit when the factor is a power of two, up to
//! round-off otherwise (tests `segmentation_is_independent_of_the_mesh_units` and
//! `cloud_segmentation_is_independent_of_the_units`). Round-off itself decides where the input
//! is so noisy that seeds hold a handful of vertices, or where a fit has a family of equally
//! good optima: fits through as many points as they have unknowns (4-vertex cylinder seeds), a
//! cone fitted to 18 noisy points, a torus fitted to a spherical patch (a spindle torus,
//! `R < r`, of any axis), and the last bits of the coordinates pick the optimum; and on exact
//! data, where a crease vertex lies on both its surfaces and symmetric parts have regions of
//! equal size. How many labels that changes on the synthetic meshes, and the absolute
//! tolerances this replaced: `docs/experiments/segmentation.md`.
//!
//! Surface-type codes (PLY `surface_type`, uchar) are those of
//! [`crate::geometry::SurfaceType`]: plane 0, cylinder 1, cone 2, sphere 3, torus 4,
//! 255 unassigned.

mod blend;
pub mod fit;
pub mod grow;
pub mod labels;
mod merge;
pub mod points;
pub mod recognize;
pub mod score;
mod tangent;

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::estimate::bezier::{bezier_curvature_with_sharp, BezierCurvature, BezierParams};
use crate::geometry::surface::Prepared;
use crate::geometry::{face_areas, Aabb, MeshTopology, Point3, TriMesh};
use crate::geometry::{SurfaceParams, SurfaceType};
use crate::spatial::Adjacency;
use crate::{Error, Result};

pub use fit::Fit;
pub use labels::{label, LabelParams};
pub(crate) use points::segment_core;
pub use points::{
    estimated_normals, neighbours_needed, segment_points, segment_points_with, PointParams,
    PointSegmentation,
};

/// Parameters of [`segment_mesh`]. `Default` = the paper's values (made scale-invariant as
/// documented on each field).
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentParams {
    /// Curvature estimation (section 3; W = 2 then 5, `th_se` relative to the edge length).
    pub bezier: BezierParams,
    /// Vertices on a mesh edge whose dihedral angle exceeds this (degrees) are sharp vertices
    /// in addition to those of `th_se` (default 30). Not in the paper: on CAD tessellations the
    /// vertices of moderate creases (45° chamfers) stay below `th_se`, and the second-pass fits
    /// of the narrow patches between such creases reach across them (measured on the ABC model:
    /// `κ_max l̄` of 0.17–0.29 instead of 0.02 on its chamfer cones). A smooth surface of radius
    /// `r` has dihedral angles of about `l̄ / r` radians, so 30° only touches radii below two
    /// edge lengths.
    pub crease_angle_degrees: f64,
    /// Labels and seeds (section 4).
    pub labels: LabelParams,
    /// `th_pos` of equation 4 in units of the mean edge length (paper: 0.5).
    pub th_pos: f64,
    /// `th_norm` of equation 5 in degrees (paper: 8).
    pub th_norm_degrees: f64,
    /// Model selection: a simpler surface type is kept when its RMS error is at most this
    /// factor times the best candidate's (plus `simpler_floor`); default 1.5.
    pub simpler_factor: f64,
    /// Model selection: allowance added to the RMS bound, in mean edge lengths (default 0.001).
    pub simpler_floor: f64,
    /// Smallest half angle (degrees) a cone may have; slimmer ones are cylinders (default 1).
    pub min_cone_angle_degrees: f64,
    /// After growing, the connected sets of vertices left in no region and not on a crease
    /// (`crease_angle_degrees`; vertices sharp by `th_se` alone take part, as fillets of a few
    /// edges' radius on noisy meshes pass it) (at least
    /// `th_seed` of the torus, 7) become seeds of any type and grow too, for up to three rounds
    /// (default true). Not in
    /// the paper: small patches whose curvature labels are spoiled by their neighbours (the
    /// spherical corners between three fillets) get no seed of their own otherwise. A set
    /// of a cloud that no one surface explains (its best fit off by more than equation 4's tolerance) is
    /// seeded from local patches instead ([`labels::local_patches`]): under noise the
    /// fillets left between the planes of a rounded box and its corners are one connected
    /// set. (On clouds, any grown region along a crease that the surfaces beside it explain
    /// to within their own noise is dissolved again, residual or not: see `crease_band`.)
    pub residual_seeds: bool,
    /// Angle tolerance (degrees) of the parallel / orthogonal tests of the recognition of
    /// section 6 (default 2); positions are compared within `2 · th_pos` mean edge lengths.
    pub recognize_angle_degrees: f64,
    /// Rounds of face propagation for faces whose vertices belong to no compatible region
    /// (default 3).
    pub face_passes: usize,
    /// Widen `th_pos` and `th_norm` to the measured noise of a point cloud (default true): see
    /// `noise_tolerance`.
    pub adapt_to_noise: bool,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            bezier: BezierParams::default(),
            crease_angle_degrees: 30.0,
            labels: LabelParams::default(),
            th_pos: 0.5,
            th_norm_degrees: 8.0,
            simpler_factor: 1.5,
            simpler_floor: 0.001,
            min_cone_angle_degrees: 1.0,
            residual_seeds: true,
            recognize_angle_degrees: 2.0,
            face_passes: 3,
            adapt_to_noise: true,
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
    /// Fillets, linear extrusions and surfaces of revolution (section 6, [`recognize`]).
    pub groups: Vec<recognize::Group>,
    /// Seconds per stage: curvature, labels, seed fits, growing, faces.
    pub timings: Vec<(&'static str, f64)>,
}

impl Segmentation {
    /// Per face: the `surface_type` code (255 when unassigned).
    pub fn face_types(&self) -> Vec<u8> {
        type_codes(&self.face_surface, &self.surfaces)
    }
}

/// The `surface_type` code of every element given its surface id (-1: unassigned, 255).
pub(crate) fn type_codes(ids: &[i32], surfaces: &[SegmentSurface]) -> Vec<u8> {
    ids.iter()
        .map(|&s| {
            if s < 0 {
                SurfaceType::Other.code()
            } else {
                surfaces[s as usize].kind.code()
            }
        })
        .collect()
}

fn type_name<S: serde::Serializer>(t: &SurfaceType, s: S) -> std::result::Result<S::Ok, S::Error> {
    s.serialize_str(t.name())
}

/// Most vertices a model selection reads ([`select_model`], [`reselect`], [`noise_tolerance`]);
/// larger sets are evenly strided, which bounds the cost of the selection on the large
/// regions of million-point inputs (a Kinect table of 150k points took 6 s of fits).
const FIT_SAMPLE: usize = 4096;

/// At most [`FIT_SAMPLE`] of `vs`, evenly strided (all of them when there are fewer), and
/// whether that is fewer than all.
fn fit_sample(vs: &[u32]) -> (impl Iterator<Item = u32> + '_, bool) {
    let step = vs.len().div_ceil(FIT_SAMPLE).max(1);
    (vs.iter().copied().step_by(step), step > 1)
}

/// The fit of a seed: the simplest candidate type (plane, sphere, cylinder, cone, torus in
/// that order) whose RMS error is at most `simpler_factor` times the best candidate's plus
/// `simpler_floor · l̄`. Candidates: the seed's label type and the simpler types it can
/// degenerate to (cylinder / cone seeds: plane, cylinder, cone; sphere: plane, sphere; torus:
/// all five).
fn select_model<G: Adjacency>(
    ctx: &grow::Ctx<G>,
    lab: u8,
    vs: &[u32],
    params: &SegmentParams,
    min_cone: f64,
    l: f64,
) -> Option<(SurfaceType, Fit)> {
    use SurfaceType as T;
    // Large seeds are fitted on an even sample (growing refits on the whole region).
    let sample: Vec<u32>;
    let vs = match fit_sample(vs) {
        (it, true) => {
            sample = it.collect();
            &sample[..]
        }
        (_, false) => vs,
    };
    let cands: &[T] = match lab {
        label::PLANE => &[T::Plane],
        label::CYLINDER | label::CONE => &[T::Plane, T::Cylinder, T::Cone],
        label::SPHERE => &[T::Plane, T::Sphere],
        label::TORUS => &[T::Plane, T::Sphere, T::Cylinder, T::Cone, T::Torus],
        _ => return None,
    };
    let fits: Vec<(T, Fit, usize)> = cands
        .iter()
        .filter_map(|&k| trimmed_fit(ctx, k, vs).map(|(f, inl)| (k, f, inl)))
        .filter(|(_, f, _)| match f.params {
            SurfaceParams::Cone { half_angle, .. } => half_angle >= min_cone,
            _ => true,
        })
        .collect();
    let best_count = fits.iter().map(|x| x.2).max()?;
    let eligible: Vec<&(T, Fit, usize)> = fits
        .iter()
        .filter(|x| x.2 as f64 >= 0.9 * best_count as f64)
        .collect();
    let best = eligible
        .iter()
        .map(|(_, f, _)| f.rms)
        .fold(f64::INFINITY, f64::min);
    let bound = params.simpler_factor * best + params.simpler_floor * l;
    eligible
        .into_iter()
        .find(|(_, f, _)| f.rms <= bound)
        .map(|(k, f, _)| (*k, *f))
}

/// The seeds whose fits measure the noise in [`noise_tolerance`]: the largest (ties by index),
/// at least [`NOISE_PROBE_SEEDS`] of them and as many as hold a quarter of all seed vertices.
///
/// Two reasons, both measured on `crease synth fillet-chamfer-cone --noise 0.5` (Gaussian noise
/// of half a spacing):
/// * a trimmed fit to a small seed absorbs part of the noise (its few points, refitted to its
///   inliers), so the median distance to it is below the noise. Over all seeds σ_d came out at
///   0.238 l̄ on 100k points and 0.155 l̄ on 1M points: 2845 seeds, most of them small. Over
///   the largest seeds it is 0.316 and 0.317 l̄, the same at both sizes, as the noise is. With
///   the low value the 1M cloud's faces grew as 157 surfaces (10 true); it now gives 17, and
///   the sharp points' MCC goes from 0.42 to 0.76;
/// * on noisy clouds every seed was fitted twice, the most expensive step there. Now the probe
///   is fitted, then every seed once with the widened tolerances: `crease sharp` on 1M noisy
///   points 45 s → 23 s, 100k 4.8 s → 4.1 s.
///
/// Where the measure does not widen the tolerances, the other seeds are fitted with the paper's,
/// as before, so noise-free inputs are unchanged bit for bit. The clean PCEDNet plate model
/// 7038, whose seeds straddle both faces, now widens them (12 → 10 surfaces, sharp MCC
/// unchanged).
fn noise_probe(seeds: &[(u8, Vec<u32>)]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..seeds.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(seeds[i].1.len()));
    let total: usize = seeds.iter().map(|s| s.1.len()).sum();
    let mut held = 0;
    let mut out = Vec::new();
    for i in order {
        if out.len() >= NOISE_PROBE_SEEDS && 4 * held >= total {
            break;
        }
        held += seeds[i].1.len();
        out.push(i);
    }
    out
}

/// Least number of seeds in [`noise_probe`].
const NOISE_PROBE_SEEDS: usize = 64;

/// Tolerances of equations 4 and 5 widened to the noise of the input. Not in the paper, whose
/// th_pos = 0.5 l̄ and th_norm = 8° suit CAD tessellations and clean scans: the depth sensors
/// of real scans (the RealSense and Kinect clouds of `../shared/data/scans`) put noise of 0.4
/// spacings and more on the positions, and the estimated normals scatter by more than 8°, so
/// that growing stalled after a few hundred points and 83 % of a RealSense box stayed
/// unassigned. The noise is measured on the seeds' own fits: over the vertices of every fitted
/// seed (at most 4096 per seed, evenly strided), σ_d = median |d| / 0.6745 (half-normal) of the
/// distances to the seed's surface and σ_a = median angle / 1.1774 (Rayleigh) of the angles
/// between the vertex normals and the surface's normals; the medians ignore the minority of
/// vertices of seeds that straddle two surfaces. The tolerances become 3 σ_d and 3 σ_a (99.7 %
/// and 98.9 % of the noise) where those exceed the paper's, capped at 3 l̄ and 30°.
fn noise_tolerance<G: Adjacency>(
    ctx: &grow::Ctx<G>,
    seeds: &[(u8, Vec<u32>)],
    fitted: &[Option<(SurfaceType, Fit)>],
    l: f64,
) -> (grow::Tol, Option<f64>) {
    let (mut d, mut a): (Vec<f64>, Vec<f64>) = seeds
        .par_iter()
        .zip(fitted)
        .flat_map_iter(|((_, vs), f)| {
            let f = f.map(|(_, f)| f);
            fit_sample(vs)
                .0
                .filter_map(move |v| {
                    let f = f.as_ref()?;
                    let p = ctx.pos[v as usize];
                    let n = crate::geometry::surface::surface_normal(&f.params, p);
                    let c = crate::geometry::vec3::dot(n, ctx.vnormal[v as usize])
                        .abs()
                        .min(1.0);
                    Some((
                        crate::geometry::surface::signed_distance(&f.params, p).abs(),
                        c.acos(),
                    ))
                })
                .collect::<Vec<_>>()
        })
        .unzip();
    let median = |x: &mut Vec<f64>| -> Option<f64> {
        if x.is_empty() {
            return None;
        }
        let mid = x.len() / 2;
        let (_, m, _) = x.select_nth_unstable_by(mid, f64::total_cmp);
        m.is_finite().then_some(*m)
    };
    let (Some(md), Some(ma)) = (median(&mut d), median(&mut a)) else {
        return (ctx.tol, None);
    };
    // Caps: beyond them the input is too noisy for any surface of its spacing.
    let tol = grow::Tol {
        pos: (3.0 * md / 0.6745).min(3.0 * l),
        cos_norm: (3.0 * ma / 1.1774).min(30f64.to_radians()).cos(),
    };
    (tol, Some(md / 0.6745))
}

/// Fit of `k` to `vs`, trimmed: refitted to the vertices compatible with the fit (equations
/// 4 and 5), up to three times, so that seeds polluted by mislabelled border vertices still
/// give the surface of their majority. Returns the fit and its number of compatible vertices.
fn trimmed_fit<G: Adjacency>(
    ctx: &grow::Ctx<G>,
    k: SurfaceType,
    vs: &[u32],
) -> Option<(Fit, usize)> {
    if vs.len() < min_points(k) {
        return None;
    }
    let mut f = ctx.fit(k, vs)?;
    let mut current: Vec<u32> = vs.to_vec();
    for _ in 0..3 {
        let prepared = Prepared::new(&f.params);
        let inl: Vec<u32> = vs
            .iter()
            .copied()
            .filter(|&v| ctx.ok(&prepared, v))
            .collect();
        if inl.len() < min_points(k).max(vs.len() / 4) {
            break;
        }
        if inl == current {
            break;
        }
        match ctx.fit(k, &inl) {
            Some(g) => f = g,
            None => break,
        }
        current = inl;
    }
    let prepared = Prepared::new(&f.params);
    let inl = vs.iter().filter(|&&v| ctx.ok(&prepared, v)).count();
    Some((f, inl))
}

/// Model selection ([`select_model`]) on a grown and refined region, over the candidates of
/// its type's label; the region takes a simpler type when one explains it as well, and is
/// then refitted to all its vertices. Returns whether it changed. Not in the paper: a seed
/// that straddled two surfaces keeps the type that explained the mixture (a torus over a
/// spherical corner and its fillets; a large-radius cylinder over a chamfer plane and the
/// blended normals of its creases) after the border refinement took the mixture apart. The
/// selection reads at most 4096 of the region's vertices (evenly strided), which bounds its
/// cost on the large regions of million-point inputs.
fn reselect<G: Adjacency>(
    ctx: &grow::Ctx<G>,
    r: &mut grow::Region,
    params: &SegmentParams,
    min_cone: f64,
    l: f64,
) -> bool {
    use SurfaceType as T;
    let simpler: &[T] = match r.kind {
        T::Plane | T::Other => return false,
        T::Sphere => &[T::Plane],
        T::Cylinder => &[T::Plane],
        // Not the cylinder: the seed selection already chose between the two with the
        // cone's smallest half angle, and on a refined narrow strip the comparison is no
        // better conditioned (the ABC vertex cloud's conical chamfers, two rings of vertices
        // each, read as cylinders when it was tried).
        // Unless its refits made it slimmer than the slimmest cone the selection takes.
        T::Cone => match r.fit.params {
            SurfaceParams::Cone { half_angle, .. } if half_angle < min_cone => {
                &[T::Plane, T::Cylinder]
            }
            _ => &[T::Plane],
        },
        T::Torus => &[T::Plane, T::Sphere, T::Cylinder, T::Cone],
    };
    let (it, sampled) = fit_sample(&r.vertices);
    let sample: Vec<u32> = it.collect();
    let prepared = Prepared::new(&r.fit.params);
    let inl: Vec<u32> = sample
        .iter()
        .copied()
        .filter(|&v| ctx.ok(&prepared, v))
        .collect();
    if inl.is_empty() {
        return false;
    }
    let pts: Vec<Point3> = inl.iter().map(|&v| ctx.pos[v as usize]).collect();
    let w: Vec<f64> = inl.iter().map(|&v| ctx.weight[v as usize]).collect();
    let bound = params.simpler_factor * fit::rms_distance(&r.fit.params, &pts, &w)
        + params.simpler_floor * l;
    for &k in simpler {
        let Some((f, n)) = trimmed_fit(ctx, k, &sample) else {
            continue;
        };
        if let SurfaceParams::Cone { half_angle, .. } = f.params {
            if half_angle < min_cone {
                continue;
            }
        }
        if n as f64 >= 0.9 * inl.len() as f64 && f.rms <= bound {
            r.kind = k;
            r.fit = if sampled {
                ctx.fit(k, &r.vertices).unwrap_or(f)
            } else {
                f
            };
            return true;
        }
    }
    false
}

/// Fewest points a fit of `k` needs.
fn min_points(k: SurfaceType) -> usize {
    match k {
        SurfaceType::Plane => 2,
        SurfaceType::Cylinder | SurfaceType::Cone => 4,
        SurfaceType::Sphere => 4,
        SurfaceType::Torus | SurfaceType::Other => 7,
    }
}

/// Errors on thresholds outside their ranges.
impl SegmentParams {
    /// Errors (`InvalidArgument`) on th_pos not positive or th_norm outside (0, 90) degrees.
    pub fn validate(&self) -> Result<()> {
        check_params(self)
    }
}

pub(crate) fn check_params(params: &SegmentParams) -> Result<()> {
    if !(params.th_pos > 0.0
        && params.th_pos.is_finite()
        && params.th_norm_degrees > 0.0
        && params.th_norm_degrees < 90.0)
    {
        return Err(Error::InvalidArgument(format!(
            "segmentation: th_pos must be positive and th_norm in (0, 90) degrees, got {} and {}",
            params.th_pos, params.th_norm_degrees
        )));
    }
    Ok(())
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
    check_params(params)?;
    let mut timings = Vec::new();
    let t = Instant::now();
    // Vertices on creases of dihedral angle above `crease_angle_degrees` are sharp too.
    let dihedral = topo.dihedral_angles();
    let crease = params.crease_angle_degrees.to_radians();
    let forced: Vec<bool> = (0..mesh.num_vertices())
        .into_par_iter()
        .map(|v| {
            topo.vertex_edges(v)
                .iter()
                .any(|&e| dihedral[e as usize] > crease)
        })
        .collect();
    let bez = bezier_curvature_with_sharp(mesh, topo, &params.bezier, Some(&forced))?;
    timings.push(("curvature", t.elapsed().as_secs_f64()));
    let nv = mesh.num_vertices();
    let l = bez.mean_edge;
    let diag = Aabb::from_points(mesh.positions())
        .map(|b| b.diagonal())
        .filter(|d| *d > 0.0)
        .ok_or_else(|| Error::InvalidInput("segmentation: the mesh has no extent".into()))?;
    // Vertex normals n_i (equation 5) and weights (a third of the incident faces' areas).
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
    let core = segment_graph(
        &GraphInput {
            graph: topo,
            pos: mesh.positions(),
            vnormal: &vnormal,
            bez: &bez,
            weight: &weight,
            no_residual: &forced,
            dissolve_crease_bands: false,
            measure_noise: false,
            noise: None,
            diag,
        },
        params,
    );
    timings.extend(core.timings);
    let tol = core.tol;
    let ctx = grow::Ctx {
        topo,
        pos: mesh.positions(),
        vnormal: &vnormal,
        fnormal: &bez.curvature.normal,
        weight: &weight,
        tol,
    };
    let (mut owner, mut regions) = (core.owner, core.regions);
    let t = Instant::now();
    let mut face_surface =
        grow::assign_faces(mesh, topo, &owner, &regions, &tol, params.face_passes);
    grow::planar_face_patches(
        mesh,
        topo,
        &tol,
        crease,
        &mut face_surface,
        &mut regions,
        &mut owner,
    );
    let surfaces = summarise(topo, &regions, &face_surface, &areas, &ctx);
    let groups = recognize::recognize(
        &surfaces,
        params.recognize_angle_degrees.to_radians(),
        2.0 * params.th_pos * l,
    );
    timings.push(("faces", t.elapsed().as_secs_f64()));
    Ok(Segmentation {
        groups,
        surfaces,
        face_surface,
        vertex_surface: owner,
        vertex_labels: core.labels,
        seeds: core.seeds,
        mean_edge: l,
        epsilon: core.epsilon,
        timings,
    })
}

/// Per-vertex inputs of the graph pipeline (labels, seeds, fits, growing) that meshes and
/// point clouds share.
pub(crate) struct GraphInput<'a, G: Adjacency> {
    /// Mesh edges or the cloud's neighbour graph.
    pub graph: &'a G,
    pub pos: &'a [Point3],
    /// Normals `n_i` of equation 5.
    pub vnormal: &'a [Point3],
    /// Two-pass curvature: `κ`, refitted normals `n'_i`, sharp flags, `l̄`.
    pub bez: &'a BezierCurvature,
    /// Per-vertex area weights.
    pub weight: &'a [f64],
    /// Vertices that never seed a residual region (on creases).
    pub no_residual: &'a [bool],
    /// Dissolve the regions of crease bands (`crease_band`): clouds, whose estimated normals
    /// blend the faces at a crease. Not meshes: a narrow CAD strip (a chamfer one triangle
    /// wide) may have all its vertices on its border curves, which lie on its neighbours too.
    pub dissolve_crease_bands: bool,
    /// Widen the tolerances to the measured noise ([`noise_tolerance`], with
    /// [`SegmentParams::adapt_to_noise`]): clouds. Not meshes: on a coarse or free-form
    /// tessellation the seeds' vertex normals leave their fits by the discretisation, not by
    /// noise (the grooved sharp_sphere.off measured 30°, and its spherical strips then took
    /// in the grooves).
    pub measure_noise: bool,
    /// The noise of the positions across the surface
    /// ([`crate::estimate::noise::noise_sigma`]), where measured (clouds): seeds that their
    /// fits do not explain within it are split ([`split_unexplained`]).
    pub noise: Option<f64>,
    /// Bounding-box diagonal.
    pub diag: f64,
}

/// Output of [`segment_graph`].
pub(crate) struct GraphResult {
    pub owner: Vec<i32>,
    pub regions: Vec<grow::Region>,
    pub labels: Vec<u8>,
    pub seeds: usize,
    pub epsilon: f64,
    pub tol: grow::Tol,
    pub timings: Vec<(&'static str, f64)>,
}

/// Sections 4 and 5 over a vertex graph: labels, seeds, fits with model selection, region
/// growing in descending seed size, then the residual seeds.
pub(crate) fn segment_graph<G: Adjacency>(
    input: &GraphInput<G>,
    params: &SegmentParams,
) -> GraphResult {
    let mut timings = Vec::new();
    let t = Instant::now();
    let topo = input.graph;
    let bez = input.bez;
    let nv = input.pos.len();
    let l = bez.mean_edge;
    let eps = params.labels.epsilon(l, input.diag);
    let c = &bez.curvature;
    let (kmax, kmin): (Vec<f64>, Vec<f64>) =
        c.k1.iter()
            .zip(&c.k2)
            .map(|(&a, &b)| if a.abs() >= b.abs() { (a, b) } else { (b, a) })
            .unzip();
    let vertex_labels =
        labels::vertex_labels(&kmax, &kmin, &bez.sharp, topo, eps, l, &params.labels);
    let seeds = labels::seed_regions(&vertex_labels, topo, &params.labels);
    timings.push(("labels", t.elapsed().as_secs_f64()));

    let t = Instant::now();
    let tol = grow::Tol {
        pos: params.th_pos * l,
        cos_norm: params.th_norm_degrees.to_radians().cos(),
    };
    let ctx = grow::Ctx {
        topo,
        pos: input.pos,
        vnormal: input.vnormal,
        fnormal: &c.normal,
        weight: input.weight,
        tol,
    };
    // Seed fits, with the model selection.
    let min_cone = params.min_cone_angle_degrees.to_radians();
    let fit_seeds =
        |ctx: &grow::Ctx<G>, which: &[usize], fitted: &mut [Option<(SurfaceType, Fit)>]| {
            let r: Vec<Option<(SurfaceType, Fit)>> = which
                .par_iter()
                .map(|&i| select_model(ctx, seeds[i].0, &seeds[i].1, params, min_cone, l))
                .collect();
            for (&i, f) in which.iter().zip(r) {
                fitted[i] = f;
            }
        };
    let mut fitted: Vec<Option<(SurfaceType, Fit)>> = vec![None; seeds.len()];
    let mut ctx = ctx;
    // The noise of the positions (σ_d of `noise_tolerance`), where measured.
    let mut sigma = None;
    if params.adapt_to_noise && input.measure_noise {
        // The noise is measured on the fits of the largest seeds (see [`noise_probe`]); the
        // other seeds are fitted once, with the tolerances that measure gives.
        let probe = noise_probe(&seeds);
        fit_seeds(&ctx, &probe, &mut fitted);
        let (wide, measured) = noise_tolerance(&ctx, &seeds, &fitted, l);
        sigma = measured;
        // Only a clear widening refits the seeds (exact and mildly noisy inputs keep the
        // paper's tolerances, and their results, bit for bit).
        if wide.pos > 1.05 * tol.pos || wide.cos_norm < tol.cos_norm - 1e-4 {
            ctx.tol = grow::Tol {
                pos: wide.pos.max(tol.pos),
                cos_norm: wide.cos_norm.min(tol.cos_norm),
            };
            let all: Vec<usize> = (0..seeds.len()).collect();
            fit_seeds(&ctx, &all, &mut fitted);
        } else {
            let mut probed = vec![false; seeds.len()];
            for &i in &probe {
                probed[i] = true;
            }
            let rest: Vec<usize> = (0..seeds.len()).filter(|&i| !probed[i]).collect();
            fit_seeds(&ctx, &rest, &mut fitted);
        }
    } else {
        let all: Vec<usize> = (0..seeds.len()).collect();
        fit_seeds(&ctx, &all, &mut fitted);
    }
    let tol = ctx.tol;
    // Seeds that straddle surfaces, by the points' own noise: local patches instead.
    let mut seeds = seeds;
    if let (Some(_), Some(noise)) = (sigma, input.noise) {
        let bound = (STRADDLING_SIGMAS * noise).max(params.th_pos * l);
        let min = params.labels.seed_size(label::TORUS);
        let (patches, patch_fits) = split_unexplained(
            &ctx,
            &seeds,
            &mut fitted,
            |f| f.is_some_and(|(_, f)| f.rms > bound),
            min,
            |lab, vs| select_model(&ctx, lab, vs, params, min_cone, l),
        );
        seeds.extend(patches);
        fitted.extend(patch_fits);
    }
    timings.push(("seed fits", t.elapsed().as_secs_f64()));

    // Growing in descending seed size (ties: seed order).
    let t = Instant::now();
    let mut order: Vec<usize> = (0..seeds.len()).collect();
    order.sort_by_key(|&i| std::cmp::Reverse(seeds[i].1.len()));
    let mut owner = vec![-1i32; nv];
    let mut regions: Vec<grow::Region> = Vec::new();
    // Vertices of regions that the surfaces beside them already explained (`crease_band`):
    // they seed no residual region.
    let mut explained = vec![false; nv];
    for i in order {
        let Some((kind, f)) = fitted[i] else { continue };
        let (lab, vs) = &seeds[i];
        let min_seed = params.labels.seed_size(*lab);
        if let Some(r) = grow::grow_seed(
            &ctx,
            kind,
            vs,
            Some(f),
            (min_seed, 0.25),
            regions.len() as i32,
            &mut owner,
        ) {
            add_region(input, &ctx, r, &mut owner, &mut explained, &mut regions);
        }
    }
    // Residual seeds: connected sets of vertices no region took.
    if params.residual_seeds {
        let min = params.labels.seed_size(label::TORUS);
        for _round in 0..3 {
            let mut unowned = vec![label::OTHER; nv];
            for v in 0..nv {
                if owner[v] == -1 && !input.no_residual[v] && !explained[v] {
                    unowned[v] = label::TORUS;
                }
            }
            let mut rest = labels::seed_regions(&unowned, topo, &params.labels);
            rest.retain(|(_, vs)| vs.len() >= min);
            rest.sort_by_key(|(_, vs)| std::cmp::Reverse(vs.len()));
            let mut fitted: Vec<Option<(SurfaceType, Fit)>> = rest
                .par_iter()
                .map(|(lab, vs)| select_model(&ctx, *lab, vs, params, min_cone, l))
                .collect();
            // On clouds whose noise was measured, a set that no one surface explains (no fit,
            // or its best fit off by more than the position tolerance) is seeded from local
            // patches instead (`labels::local_patches`), grown after the sets that one
            // surface explains. Not on meshes: on a free-form tessellation (the grooved
            // sharp_sphere.off) the patches became small spheres of the wrong radius.
            let explains =
                |f: &Option<(SurfaceType, Fit)>| f.is_some_and(|(_, f)| f.rms <= tol.pos);
            if sigma.is_some() && !fitted.iter().all(explains) {
                let (patches, patch_fits) = split_unexplained(
                    &ctx,
                    &rest,
                    &mut fitted,
                    |f| !explains(f),
                    min,
                    |lab, vs| select_model(&ctx, lab, vs, params, min_cone, l),
                );
                rest.extend(patches);
                fitted.extend(patch_fits);
            }
            let before = regions.len();
            for ((_, vs), f) in rest.iter().zip(fitted) {
                let Some((kind, f)) = f else { continue };
                let id = regions.len() as i32;
                if let Some(r) =
                    grow::grow_seed(&ctx, kind, vs, Some(f), (min, 0.25), id, &mut owner)
                {
                    add_region(input, &ctx, r, &mut owner, &mut explained, &mut regions);
                }
            }
            if regions.len() == before {
                break;
            }
        }
    }
    if input.dissolve_crease_bands {
        dissolve_crease_bands(input, &ctx, &mut owner, &mut explained, &mut regions);
    }
    timings.push(("growing", t.elapsed().as_secs_f64()));
    let t = Instant::now();
    grow::refine_borders(&ctx, &mut owner, &mut regions, 3, min_points);
    // Model selection again on the refined regions (`reselect`).
    let retyped = regions
        .par_iter_mut()
        .map(|r| reselect(&ctx, r, params, min_cone, l))
        .reduce(|| false, |a, b| a || b);
    if retyped {
        grow::refine_borders(&ctx, &mut owner, &mut regions, 3, min_points);
    }
    timings.push(("borders", t.elapsed().as_secs_f64()));
    if let Some(sigma) = sigma {
        // One surface within the noise, one region (`merge`).
        let t = Instant::now();
        let floor = params.simpler_floor * l;
        let richer = merge::richer_types(&ctx, &mut regions, floor, min_cone);
        let merged = merge::merge_regions(&ctx, &mut owner, &mut regions, sigma, floor, min_cone);
        // Then the planes that a scanner bent or terraced.
        let seamed = merge::merge_smooth_seams(&ctx, &mut owner, &mut regions, l, floor);
        let merged = merged || seamed;
        if richer || merged {
            grow::refine_borders(&ctx, &mut owner, &mut regions, 3, min_points);
        }
        // Fillets tangent to their planes (`tangent`); the border refinement refits freely,
        // so the tangency is made again on the region each pass gives.
        for _ in 0..3 {
            if !tangent::tangent_fillets(&ctx, &owner, &mut regions, sigma, floor) {
                break;
            }
            grow::refine_borders(&ctx, &mut owner, &mut regions, 1, min_points);
        }
        tangent::tangent_fillets(&ctx, &owner, &mut regions, sigma, floor);
        let plainer = merge::plainer_types(&ctx, &mut regions, l);
        if plainer {
            grow::refine_borders(&ctx, &mut owner, &mut regions, 1, min_points);
        }
        // The merged surfaces explain more: the crease bands they leave are dissolved again.
        if input.dissolve_crease_bands && (richer || merged || plainer) {
            dissolve_crease_bands(input, &ctx, &mut owner, &mut explained, &mut regions);
        }
        // Rounded edges the growing did not find, fitted from their planes (`blend`), on
        // clouds, by the points' own noise (the seeds' overstates it where they straddle
        // surfaces).
        if let Some(noise) = input.noise {
            blend::blends(&ctx, &mut owner, &mut regions, noise, floor, l);
        }
        timings.push(("merge", t.elapsed().as_secs_f64()));
    }
    GraphResult {
        owner,
        regions,
        labels: vertex_labels,
        seeds: seeds.len(),
        epsilon: eps,
        tol,
        timings,
    }
}

/// A seed: its vertex label and its vertices.
type Seed = (u8, Vec<u32>);
/// A seed's fit with its type, if it has one.
type SeedFit = Option<(SurfaceType, Fit)>;

/// A seed is split when its fit is off by more than this many times the noise of the points
/// ([`GraphInput::noise`]).
const STRADDLING_SIGMAS: f64 = 3.0;

/// Seeds whose fit does not explain them, split into local patches (not in the paper; issue
/// 29). Under noise the curvature labels of neighbouring surfaces mix, and one seed joins a
/// face, its fillet and the next face (the rounded cube at noise of a fifth of a spacing: seeds
/// of 2–35 thousand points joining faces, fillets and corners). A fit to such a seed explains
/// none of them, yet holds a quarter of its points and grows: a cone of half angle 45° tangent
/// to two faces along lines swallows both faces' strips and their fillet, a cone around a
/// corner's diagonal three fillets (14 surfaces of 26 on the rounded cube). Each seed for which
/// `unexplained` holds (the seeds: a fit off by more than three times the noise measured on the
/// points by [`crate::estimate::noise::noise_sigma`], independent of the seeds, and at least
/// the paper's th_pos; the residual seeds: no fit within the position tolerance) gives up its
/// fit (`fitted[i] = None`); its local patches of at least `3 min` vertices
/// ([`labels::local_patches`]) are fitted with `fit` and returned for the caller to grow.
/// The noise tolerances of the growing are left as measured on the seeds
/// (`noise_tolerance`): a depth camera's faces are warped by several times their noise, and
/// the wider tolerances are what grow each face as one plane.
fn split_unexplained<G: Adjacency>(
    ctx: &grow::Ctx<G>,
    seeds: &[Seed],
    fitted: &mut [SeedFit],
    unexplained: impl Fn(&SeedFit) -> bool,
    min: usize,
    fit: impl Fn(u8, &[u32]) -> SeedFit + Sync,
) -> (Vec<Seed>, Vec<SeedFit>) {
    let mut patches: Vec<Seed> = Vec::new();
    for (i, (lab, vs)) in seeds.iter().enumerate() {
        if unexplained(&fitted[i]) {
            fitted[i] = None;
            patches.extend(
                labels::local_patches(vs, ctx.topo, 3 * min)
                    .into_iter()
                    .map(|p| (*lab, p)),
            );
        }
    }
    let fits = patches.par_iter().map(|(lab, vs)| fit(*lab, vs)).collect();
    (patches, fits)
}

/// Appends the grown region `r` (id `regions.len()`, its vertices marked in `owner`) to
/// `regions`, unless it is a crease band ([`crease_band`], clouds only): then its vertices are
/// handed to its neighbours ([`hand_over`]).
fn add_region<G: Adjacency>(
    input: &GraphInput<G>,
    ctx: &grow::Ctx<G>,
    r: grow::Region,
    owner: &mut [i32],
    explained: &mut [bool],
    regions: &mut Vec<grow::Region>,
) {
    let id = regions.len() as i32;
    let band = if input.dissolve_crease_bands {
        crease_band(
            input.graph,
            input.pos,
            owner,
            regions,
            &r,
            id,
            input.bez.mean_edge,
        )
    } else {
        None
    };
    match band {
        Some(best) => hand_over(ctx, &r, &best, owner, explained, regions),
        None => regions.push(r),
    }
}

/// The vertices of a dissolved crease band `r` go to the neighbouring region that explains
/// each best (`best`, from [`crease_band`]) when they pass its equations 4 and 5; the others
/// are left unowned and flagged `explained` (they seed no residual region; the left-over
/// assignment gives them to the nearest compatible neighbour). The receiving regions keep
/// their fits. Handing over rather than unmarking all of them matters where a large region is
/// explained by a coplanar neighbour (a Kinect table grown as two planes): the left-over
/// assignment reaches only a few rings into it.
fn hand_over<G: Adjacency>(
    ctx: &grow::Ctx<G>,
    r: &grow::Region,
    best: &[i32],
    owner: &mut [i32],
    explained: &mut [bool],
    regions: &mut [grow::Region],
) {
    for (&v, &s) in r.vertices.iter().zip(best) {
        if s >= 0 && ctx.ok(&Prepared::new(&regions[s as usize].fit.params), v) {
            owner[v as usize] = s;
            regions[s as usize].vertices.push(v);
        } else {
            owner[v as usize] = -1;
            explained[v as usize] = true;
        }
    }
}

/// The crease-band test ([`crease_band`]) again once every region has grown, in ascending
/// region size (ties: id), each against the regions that are left: a face whose seed is
/// smaller than a band's seed grows after the band was tested (at 40k points the 45° chamfer
/// of the fillet-chamfer-cone part, 8 spacings wide, grew after three cylinders of 66–195
/// points along its borders, radius 1.5 spacings). Dissolved regions are removed, the others
/// renumbered in order; their vertices are handed to their neighbours ([`hand_over`]).
fn dissolve_crease_bands<G: Adjacency>(
    input: &GraphInput<G>,
    ctx: &grow::Ctx<G>,
    owner: &mut [i32],
    explained: &mut [bool],
    regions: &mut Vec<grow::Region>,
) {
    let mut order: Vec<usize> = (0..regions.len()).collect();
    order.sort_by_key(|&i| (regions[i].vertices.len(), i));
    let mut dead = vec![false; regions.len()];
    for i in order {
        if let Some(best) = crease_band(
            input.graph,
            input.pos,
            owner,
            regions,
            &regions[i],
            i as i32,
            input.bez.mean_edge,
        ) {
            let r = grow::Region {
                vertices: std::mem::take(&mut regions[i].vertices),
                ..regions[i]
            };
            hand_over(ctx, &r, &best, owner, explained, regions);
            dead[i] = true;
        }
    }
    if dead.iter().any(|&d| d) {
        let alive: Vec<bool> = dead.iter().map(|&d| !d).collect();
        merge::renumber(owner, regions, &alive);
    }
}

/// Whether a grown region `r` (id `id`, its vertices marked in `owner`) is a piece of a
/// crease band that the larger surfaces beside it already explain, and if so, per vertex of
/// `r`, the adjacent region that explains it best. Only regions with more vertices than `r`
/// count (a Kinect table of 150k points was otherwise dissolved into the smaller tilted planes
/// around it). Its vertices lie on the adjacent surfaces as closely as those surfaces' own points do: the third quartile over its
/// vertices of min over the adjacent surfaces s of |d_s(v)| / rms_s is at most 3 (a 3-sigma
/// gate; rms_s is the RMS distance of s's fit, floored at 1e-6 mean edge lengths for exact
/// data). The third quartile rather than the median: a small true surface whose region leaked
/// over its borders has up to half its vertices on its neighbours (measured: a rounded-cube
/// corner with 1 % noise grew as an 80-point torus over the 55-point sphere, median 2.6,
/// third quartile 17, while every band on the synthetic parts stayed below 2).
///
/// Not in the paper. Along creases, estimated normals blend the two faces over a thin band
/// whose positions still lie on the faces: the band's curvature labels seed small cylinders
/// and cones (a 45° chamfer's band reads as a fillet of one or two edge lengths' radius), and
/// its vertices, which fail equation 5 for both faces, seed residual spheres and tori of
/// 10–60 points. Measured on the fillet-chamfer-cone cloud with estimated normals (10 true
/// surfaces): 17 surfaces at 100k points and 36 at 1M without this test, 10 and 10 with it;
/// none of them with exact normals. The test applies to every region, not only to those that
/// touch a crease vertex (a vertex that seeds no residual region): at 1M points two regions
/// of 10–12 points between two planes touched none and stayed as a torus and a sphere.
/// Regions grow in descending seed size, so the faces' large surfaces exist when a band's region is tested (and [`dissolve_crease_bands`] tests every
/// region again once all have grown); the vertices of a dissolved region seed no
/// residual region. A true small surface is not explained by its neighbours to within their
/// noise: a fillet of radius r leaves the planes it joins by up to 0.29 r, a spherical corner
/// its three cylinders by up to 0.18 r. (The position tolerance of equation 4, half an edge
/// length, was tried first as the gate: it dissolved the rounded cube's fillets of 1–2 edge
/// lengths' radius.) Clouds only ([`GraphInput::dissolve_crease_bands`]).
fn crease_band<G: Adjacency>(
    topo: &G,
    pos: &[Point3],
    owner: &[i32],
    regions: &[grow::Region],
    r: &grow::Region,
    id: i32,
    mean_edge: f64,
) -> Option<Vec<i32>> {
    let mut nb: Vec<i32> = Vec::new();
    for &v in &r.vertices {
        topo.for_each_neighbor(v as usize, |w| {
            let o = owner[w as usize];
            if o >= 0 && o != id {
                nb.push(o);
            }
        });
    }
    nb.sort_unstable();
    nb.dedup();
    // Only larger regions explain a band.
    nb.retain(|&s| regions[s as usize].vertices.len() > r.vertices.len());
    if nb.is_empty() || r.vertices.is_empty() {
        return None;
    }
    let floor = 1e-6 * mean_edge;
    let (mut d, best): (Vec<f64>, Vec<i32>) = r
        .vertices
        .iter()
        .map(|&v| {
            nb.iter()
                .map(|&s| {
                    let f = &regions[s as usize].fit;
                    let d =
                        crate::geometry::surface::signed_distance(&f.params, pos[v as usize]).abs();
                    (d / f.rms.max(floor), s)
                })
                .fold((f64::INFINITY, -1), |a, b| if b.0 < a.0 { b } else { a })
        })
        .unzip();
    // The third quartile (see the doc comment).
    let q = ((d.len() * 3) / 4).min(d.len() - 1);
    let (_, q75, _) = d.select_nth_unstable_by(q, f64::total_cmp);
    (*q75 <= 3.0).then_some(best)
}

/// Areas, counts, RMS errors and adjacency of the regions of a mesh.
fn summarise(
    topo: &MeshTopology,
    regions: &[grow::Region],
    face_surface: &[i32],
    areas: &[f64],
    ctx: &grow::Ctx<MeshTopology>,
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
    surfaces_of(regions, &area, &faces, adj, ctx.pos, ctx.weight)
}

/// The surfaces of the grown regions: per region its area, face count and neighbour list
/// (any order, repetitions allowed) given; vertex count and RMS error computed.
pub(crate) fn surfaces_of(
    regions: &[grow::Region],
    area: &[f64],
    faces: &[usize],
    adj: Vec<Vec<u32>>,
    pos: &[Point3],
    weight: &[f64],
) -> Vec<SegmentSurface> {
    regions
        .par_iter()
        .zip(adj)
        .enumerate()
        .map(|(i, (r, mut nb))| {
            let pts: Vec<_> = r.vertices.iter().map(|&v| pos[v as usize]).collect();
            let w: Vec<_> = r.vertices.iter().map(|&v| weight[v as usize]).collect();
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
