//! The estimator of the angle between tangent-plane normals at a mesh edge, at scale r
//! (vidal et al. 2011, section 3).
//!
//! For an edge e with faces f_L, f_R and midpoint m, the *separating plane* contains the edge
//! and the bisector of the two face normals (its normal is `d × (n_L + n_R)`, d the edge
//! direction, oriented towards f_R). Two regions start as {f_L} and {f_R} with normals n_L, n_R.
//! The faces whose barycentre lies in the sphere of radius r around m are visited by increasing
//! distance of the barycentre to the separating plane (a priority order, the distance rounded
//! to f32; ties in a fixed order of the faces); a
//! face on the positive side (distance ≥ 0) is a candidate for the right region, one on the
//! strictly negative side for the left region. A candidate whose normal is within 23° of its
//! region's current normal is accepted and the region normal becomes the area-weighted mean of
//! its faces' normals; otherwise it is rejected. When all faces are visited, the rejected ones
//! are tested again, in the same order, against the final normals (section 3.2, "a second
//! pass"). θ̂ʳ_e is the angle between the two region normals. Boundary and non-manifold
//! edges get π (section 2).
//!
//! **Where the paper is silent (choices made here).**
//! - "Triangles within the sphere": the barycentre is within r of the midpoint. Faces are
//!   found by Euclidean search, not by walking the mesh: the paper's growing is explicitly not
//!   connected, and faces of a nearby but unconnected sheet (the other side of a thin wall)
//!   have opposite normals and are rejected by the 23° test anyway.
//! - Rejected faces accepted in the second pass also update the normal.
//!
//! **Initial normals (crease's change, on by default).** The paper starts each region from the
//! normal of the edge's own face. At the noise of section 6.1 (Gaussian, 0.5 % of the bounding
//! box's largest side, i.e. about 0.3 edge lengths on a 60-edges-per-side mesh) single face
//! normals are off by 20–30°, so the 23° test keeps mostly the faces that agree with the noisy
//! seed and θ̂ʳ stays about as noisy as the dihedral angle. Starting instead from the
//! area-weighted mean normal of all the faces of each side in the sphere (then growing exactly
//! as the paper does) raises the AUC of θ̂ʳ on noisy meshes a lot. The price is localisation:
//! beside a crease the mean mixes both surfaces, so lines come out a few edges wide, and on
//! clean meshes the paper's seeds are exact where the mean initialisation is not.
//! [`TangentParams::mean_init`] = false gives the paper's seeds;
//! [`TangentParams::iterations`] > 1 regrows from the previous normals (no gain measured).
//!
//! **Acceptance angle adapted to the noise (crease's change, on by default).** The 23° of
//! section 6.3 presumes face normals that scatter much less than 23° about their surface's
//! normal. At the noise of section 6.1 on a fine or elongated mesh they do not (the median
//! angle between adjacent face normals exceeds 23° on noisy fandisk, cylinder and bar), so the
//! test rejects faces of the edge's own surface at random and the region normals are truncated
//! means biased towards whatever the seeds say. The angle between two independent noisy
//! normals is about √2 times the scatter of one, so [`TangentParams::noise_accept`] = 1.5 ×
//! the mesh's median adjacent-face angle (≈ 2 scatters of a face about its surface) is the
//! gate, never below the paper's 23° (so clean meshes, whose median is a few degrees, are
//! unchanged) and never above 85° (faces of a perpendicular surface stay out). It raises the
//! noisy mean AUC of θ̂ʳ (factor 1.5 above 1 and 2) and leaves the clean AUCs unchanged.
//!
//! **Smallest sphere (crease's addition).** r is a fraction of the bounding box's smallest
//! side (section 4); on a fine or flat mesh r = 4 % can be shorter than an edge, and the sphere
//! then holds no face but the edge's own two, so θ̂ʳ is the dihedral angle with all its noise
//! (hundreds of false sharp edges on a noisy flat grid). Radii are therefore at least
//! [`TangentParams::min_edge_lengths`] = 2 mean edge lengths.
//!
//! **Sharing work across scales and bounded cost (crease's addition).** The faces in a sphere
//! grow as r² / (mean face area): at r = 28 % of a part on a 1M-edge mesh that is ~10⁵ faces per
//! edge. The area-weighted mean normal is a ratio of sums over the faces, so it is estimated
//! without bias from a uniform random subset of the faces. Every face gets a fixed
//! pseudo-random level (the number of leading zero bits of a hash of its id): level ≥ l keeps
//! a fraction 2⁻ˡ of the faces, the same subset for every edge. Each scale uses the finest
//! level at which a sphere holds at most [`TangentParams::max_faces`] faces on average
//! (a flat disc of radius r), so the estimate is exact (level 0) whenever the sphere is small
//! and the cost per edge and scale is bounded otherwise. Scales that fall on the same level are
//! gathered once at the largest of them and sorted once; the smaller scales read the same
//! order filtered by distance. The per-edge computation is independent of every other edge,
//! so the result does not depend on the thread count. The default budget of 128 faces gives
//! the same Table 2 AUCs as 384 at a quarter of the time.
//!
//! Figures of every choice above: `docs/experiments/mesh-edges-tangent.md`.

use rayon::prelude::*;

use super::grid::BallGrid;
use super::EdgeMesh;
use crate::geometry::{vec3, Point3};
use crate::{Error, Result};

/// Parameters of [`tangent_angles`].
#[derive(Debug, Clone, PartialEq)]
pub struct TangentParams {
    /// The scales r as fractions of [`EdgeMesh::reference_length`] (section 4: 0.04, 0.07, ...,
    /// 0.28).
    pub scales: Vec<f64>,
    /// The acceptance angle of a face into a region, degrees (section 6.3: 23).
    pub accept_degrees: f64,
    /// Acceptance angle adapted to the mesh's face-normal noise (crease's change, see the
    /// module documentation): the angle is max(`accept_degrees`, this factor × the median
    /// angle between adjacent face normals), at most 85°. `None` = always `accept_degrees`
    /// (the paper). Default 1.5.
    pub noise_accept: Option<f64>,
    /// Average number of faces a sphere may hold before the scale switches to a coarser random
    /// subset of the faces (see the module documentation; default 128); `None` = always every
    /// face (exact, cost grows as r²).
    pub max_faces: Option<usize>,
    /// Initial region normals: `false` = the normals of the edge's two faces (the paper);
    /// `true` (default) = the area-weighted mean normal of all the faces of each side in the
    /// sphere (see the module documentation).
    pub mean_init: bool,
    /// Number of growings: each one after the first starts from the previous one's normals.
    pub iterations: usize,
    /// Smallest radius, in mean edge lengths of the mesh (default 2; 0 = none): a sphere
    /// smaller than the faces holds only the edge's own two faces, and θ̂ʳ degenerates to the
    /// dihedral angle (see the module documentation).
    pub min_edge_lengths: f64,
}

/// The scales of section 4 for the tangent-plane angle: 4, 7, ..., 28 % of the reference length.
pub const PAPER_SCALES: [f64; 9] = [0.04, 0.07, 0.10, 0.13, 0.16, 0.19, 0.22, 0.25, 0.28];

impl Default for TangentParams {
    fn default() -> Self {
        TangentParams {
            scales: PAPER_SCALES.to_vec(),
            accept_degrees: 23.0,
            noise_accept: Some(1.5),
            max_faces: Some(128),
            mean_init: true,
            iterations: 1,
            min_edge_lengths: 2.0,
        }
    }
}

/// θ̂ʳ_e for every edge and scale.
#[derive(Debug, Clone, PartialEq)]
pub struct TangentAngles {
    /// The scales in mesh units (radius of the sphere), in the order of the parameters.
    pub radii: Vec<f64>,
    /// The subset level used for each scale (0 = every face).
    pub levels: Vec<u32>,
    /// Angles in radians in [0, π], row-major: `angles[e * radii.len() + s]`.
    pub angles: Vec<f64>,
}

impl TangentAngles {
    /// Number of scales.
    pub fn num_scales(&self) -> usize {
        self.radii.len()
    }

    /// The angles of scale `s` for every edge.
    pub fn scale(&self, s: usize) -> Vec<f64> {
        let k = self.radii.len();
        self.angles
            .iter()
            .skip(s)
            .step_by(k.max(1))
            .copied()
            .collect()
    }

    /// The angles of edge `e`, one per scale.
    pub fn edge(&self, e: usize) -> &[f64] {
        let k = self.radii.len();
        &self.angles[e * k..(e + 1) * k]
    }
}

/// One face in a face grid: what the growing reads (its barycentre is the grid point).
#[derive(Clone, Copy)]
struct Item {
    n: Point3,
    area: f64,
    face: u32,
}

/// A uniform grid over the barycentres of one subset of the faces.
type FaceGrid = BallGrid<Item>;

/// A face in the sphere of an edge: signed distance to the separating plane, squared distance
/// to the midpoint, normal, area.
#[derive(Clone, Copy)]
struct Cand {
    sd: f64,
    d2: f64,
    n: Point3,
    area: f64,
}

/// The grid over `faces` (ascending ids) with cells of about `cell`.
fn face_grid(em: &EdgeMesh, faces: &[u32], cell: f64) -> FaceGrid {
    let items = faces
        .iter()
        .map(|&f| {
            let i = f as usize;
            (
                em.centroids[i],
                Item {
                    n: em.normals[i],
                    area: em.areas[i],
                    face: f,
                },
            )
        })
        .collect();
    BallGrid::new(items, cell)
}

/// Vertices around which [`crowd_counts`] counts the items of a ball.
pub(crate) const CROWD_SAMPLES: usize = 16;
/// A measured ball holding more than this many times the items the area predicts sets the level.
pub(crate) const CROWD_FACTOR: f64 = 8.0;

/// Items (`n` of them, `item(i)` their positions) within each radius of [`CROWD_SAMPLES`]
/// evenly spaced `centres`, on average. The area-based estimate of [`levels_for`] fails where a
/// few huge faces hold most of the area and the items crowd elsewhere (corrupt or degenerate
/// meshes: a fuzzed 19k-face STL took 23 s, every ball holding every edge); this count catches
/// it, at 16 distance computations per item.
pub(crate) fn crowd_counts(
    centres: &[Point3],
    n: usize,
    item: impl Fn(usize) -> Point3 + Sync,
    radii: &[f64],
) -> Vec<f64> {
    if centres.is_empty() {
        return vec![0.0; radii.len()];
    }
    let picks: Vec<Point3> = (0..CROWD_SAMPLES)
        .map(|i| centres[i * centres.len() / CROWD_SAMPLES])
        .collect();
    let counts: Vec<Vec<usize>> = picks
        .par_iter()
        .map(|&q| {
            let mut c = vec![0usize; radii.len()];
            for i in 0..n {
                let d2 = vec3::dist2(item(i), q);
                for (cs, &r) in c.iter_mut().zip(radii) {
                    *cs += usize::from(d2 <= r * r);
                }
            }
            c
        })
        .collect();
    (0..radii.len())
        .map(|s| counts.iter().map(|c| c[s]).sum::<usize>() as f64 / CROWD_SAMPLES as f64)
        .collect()
}

/// The items a ball of radius `r` holds: `by_area` (the area's prediction), or `measured`
/// ([`crowd_counts`]) where that is more than [`CROWD_FACTOR`] times it.
pub(crate) fn expected_items(r: f64, by_area: f64, measured: f64) -> f64 {
    if measured > CROWD_FACTOR * by_area {
        tracing::debug!("balls of radius {r:e} hold {measured} items, not {by_area}");
        measured
    } else {
        by_area
    }
}

/// The level of a face: leading zero bits of a SplitMix64 hash of its id (level ≥ l holds a
/// fraction 2⁻ˡ of the faces, independently of the mesh's face order statistics).
pub(crate) fn subset_level(f: u32) -> u32 {
    let mut z = u64::from(f).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    z.leading_zeros()
}

/// One group of scales sharing a face subset: the scale indices (ascending radius) and grid.
struct Group {
    scales: Vec<usize>,
    grid: FaceGrid,
}

/// Per-thread buffers.
#[derive(Default)]
struct Scratch {
    cand: Vec<Cand>,
    sorted: Vec<Cand>,
    keys: Vec<u64>,
    rejected: Vec<u32>,
}

/// θ̂ʳ_e (section 3) for every edge of `em` at every scale of `params`, in parallel over the
/// edges.
///
/// Errors: no scale, a scale not positive and finite, an acceptance angle outside (0, 180).
pub fn tangent_angles(em: &EdgeMesh, params: &TangentParams) -> Result<TangentAngles> {
    if params.scales.is_empty() {
        return Err(Error::InvalidArgument(
            "tangent-plane angles: at least one scale is needed".into(),
        ));
    }
    if let Some(s) = params.scales.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
        return Err(Error::InvalidArgument(format!(
            "tangent-plane angles: scales must be positive, got {s}"
        )));
    }
    if !(params.accept_degrees > 0.0 && params.accept_degrees < 180.0) {
        return Err(Error::InvalidArgument(format!(
            "tangent-plane angles: the acceptance angle must be in (0, 180) degrees, got {}",
            params.accept_degrees
        )));
    }
    if let Some(k) = params
        .noise_accept
        .filter(|k| !(k.is_finite() && *k >= 0.0))
    {
        return Err(Error::InvalidArgument(format!(
            "tangent-plane angles: the noise factor of the acceptance angle must be >= 0, got {k}"
        )));
    }
    if params.max_faces == Some(0) {
        return Err(Error::InvalidArgument(
            "tangent-plane angles: max_faces must be positive".into(),
        ));
    }
    let topo = &em.topo;
    let nf = topo.num_faces();
    let ne = topo.num_edges();
    let ns = params.scales.len();
    let radii: Vec<f64> = params
        .scales
        .iter()
        .map(|s| (s * em.reference_length).max(params.min_edge_lengths * em.mean_edge_length))
        .collect();

    // Level per scale from the expected number of faces in a disc of radius r.
    let total_area: f64 = em.areas.iter().sum();
    let mean_area = if nf > 0 { total_area / nf as f64 } else { 0.0 };
    let face_levels: Vec<u32> = (0..nf as u32).into_par_iter().map(subset_level).collect();
    let max_level = 40u32;
    let measured = match params.max_faces {
        Some(_) => crowd_counts(em.mesh.positions(), nf, |f| em.centroids[f], &radii),
        None => vec![0.0; ns],
    };
    let levels: Vec<u32> = radii
        .iter()
        .zip(&measured)
        .map(|(&r, &m)| match params.max_faces {
            None => 0,
            Some(budget) => {
                let by_area = if mean_area > 0.0 {
                    std::f64::consts::PI * r * r / mean_area
                } else {
                    0.0
                };
                let expected = expected_items(r, by_area, m);
                let mut l = 0;
                while l < max_level && expected / f64::powi(2.0, l as i32) > budget as f64 {
                    l += 1;
                }
                l
            }
        })
        .collect();

    // Group the scales by level; each group gets a grid over its subset.
    let mut order: Vec<usize> = (0..ns).collect();
    order.sort_by(|&a, &b| radii[a].total_cmp(&radii[b]).then(a.cmp(&b)));
    let mut groups: Vec<Group> = Vec::new();
    let mut distinct: Vec<u32> = levels.clone();
    distinct.sort_unstable();
    distinct.dedup();
    for &l in &distinct {
        let scales: Vec<usize> = order.iter().copied().filter(|&s| levels[s] == l).collect();
        let faces: Vec<u32> = (0..nf as u32)
            .filter(|&f| face_levels[f as usize] >= l && em.areas[f as usize] > 0.0)
            .collect();
        let rmax = scales.iter().map(|&s| radii[s]).fold(0.0, f64::max);
        let grid = face_grid(em, &faces, rmax / 2.0);
        groups.push(Group { scales, grid });
    }

    let cos_accept = accept_angle(em, params).cos();
    let mut angles = vec![std::f64::consts::PI; ne * ns];
    angles
        .par_chunks_mut(ns)
        .enumerate()
        .for_each_init(Scratch::default, |scratch, (e, out)| {
            edge_angles(em, e, &radii, &groups, cos_accept, params, scratch, out);
        });
    Ok(TangentAngles {
        radii,
        levels,
        angles,
    })
}

/// The acceptance angle in radians: `accept_degrees`, raised to `noise_accept` × the median
/// angle between adjacent face normals over the edges with two faces when that is larger, at
/// most 85°.
pub fn accept_angle(em: &EdgeMesh, params: &TangentParams) -> f64 {
    let base = params.accept_degrees.to_radians();
    let Some(k) = params.noise_accept else {
        return base;
    };
    match median_dihedral(em) {
        Some(median) => base.max((k * median).min(85f64.to_radians())),
        None => base,
    }
}

/// The median dihedral angle (radians) over the edges with two faces; `None` without such
/// an edge.
pub fn median_dihedral(em: &EdgeMesh) -> Option<f64> {
    let mut angles: Vec<f64> = (0..em.topo.num_edges())
        .filter(|&e| em.topo.edge_faces(e).len() == 2)
        .map(|e| em.dihedral[e])
        .filter(|d| d.is_finite())
        .collect();
    if angles.is_empty() {
        return None;
    }
    let mid = angles.len() / 2;
    let (_, median, _) = angles.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    Some(*median)
}

/// Fills `out` (one angle per scale) for edge `e`; leaves π for edges without two faces.
#[allow(clippy::too_many_arguments)]
fn edge_angles(
    em: &EdgeMesh,
    e: usize,
    radii: &[f64],
    groups: &[Group],
    cos_accept: f64,
    params: &TangentParams,
    scratch: &mut Scratch,
    out: &mut [f64],
) {
    let faces = em.topo.edge_faces(e);
    if faces.len() != 2 {
        return;
    }
    let (fa, fb) = (faces[0] as usize, faces[1] as usize);
    let (na, nb) = (em.normals[fa], em.normals[fb]);
    if em.areas[fa] <= 0.0 || em.areas[fb] <= 0.0 {
        return;
    }
    let [v0, v1] = em.topo.edges()[e];
    let p = em.mesh.positions();
    let (a, b) = (p[v0 as usize], p[v1 as usize]);
    let m = vec3::scale(vec3::add(a, b), 0.5);
    let d = vec3::sub(b, a);
    // Separating plane normal: d × (n_a + n_b), oriented so that face b is on the positive
    // (right) side; falls back on the barycentre difference when the faces fold back.
    let toward_b = vec3::sub(em.centroids[fb], em.centroids[fa]);
    let s = vec3::normalize(vec3::cross(d, vec3::add(na, nb)))
        .filter(|s| vec3::dot(*s, toward_b).abs() > 1e-12 * vec3::norm(toward_b))
        .or_else(|| {
            let dd = vec3::dot(d, d);
            let k = if dd > 0.0 {
                vec3::dot(toward_b, d) / dd
            } else {
                0.0
            };
            vec3::normalize(vec3::sub(toward_b, vec3::scale(d, k)))
        });
    let Some(mut s) = s else {
        out.fill(vec3::angle(na, nb));
        return;
    };
    if vec3::dot(s, toward_b) < 0.0 {
        s = vec3::scale(s, -1.0);
    }
    // Left = face a (negative side), right = face b.
    for g in groups {
        let Some(&rmax_s) = g.scales.last() else {
            continue;
        };
        let rmax = radii[rmax_s];
        scratch.cand.clear();
        let cand = &mut scratch.cand;
        g.grid.for_each_within(m, rmax, |it, c, d2| {
            if it.face as usize != fa && it.face as usize != fb {
                cand.push(Cand {
                    sd: vec3::dot(vec3::sub(c, m), s),
                    d2,
                    n: it.n,
                    area: it.area,
                });
            }
        });
        // Sort by |distance to the plane| (as f32, whose bits order like the values), ties by
        // the fixed grid order: integer keys sort several times faster than float pairs.
        scratch.keys.clear();
        scratch.keys.extend(
            cand.iter()
                .enumerate()
                .map(|(i, c)| (u64::from((c.sd.abs() as f32).to_bits()) << 32) | i as u64),
        );
        scratch.keys.sort_unstable();
        scratch.sorted.clear();
        scratch.sorted.extend(
            scratch
                .keys
                .iter()
                .map(|&k| cand[(k & 0xFFFF_FFFF) as usize]),
        );
        std::mem::swap(&mut scratch.cand, &mut scratch.sorted);
        for &si in &g.scales {
            let r2 = radii[si] * radii[si];
            let mut init = [na, nb];
            if params.mean_init {
                let mut sum = [[0.0; 3]; 2];
                for c in scratch.cand.iter() {
                    if c.d2 <= r2 {
                        let k = usize::from(c.sd >= 0.0);
                        sum[k] = vec3::add(sum[k], vec3::scale(c.n, c.area));
                    }
                }
                for k in 0..2 {
                    if let Some(u) = vec3::normalize(sum[k]) {
                        init[k] = u;
                    }
                }
            }
            for it in 0..params.iterations.max(1) {
                init = grow(
                    em,
                    fa,
                    fb,
                    init,
                    it == 0,
                    &scratch.cand,
                    r2,
                    cos_accept,
                    &mut scratch.rejected,
                );
            }
            out[si] = vec3::angle(init[0], init[1]);
        }
    }
}

/// The region growing of section 3.2 over the candidates (sorted by distance to the
/// separating plane) whose squared distance to the midpoint is at most `r2`, starting from the
/// normals `init`, with the edge's two faces in their regions from the start if `seeds`.
/// (Testing the two faces like the other candidates instead, with the mean initialisation,
/// gave fewer false edges on a noisy grid but a lower mean AUC of Table 2, clean and noisy:
/// `docs/experiments/mesh-edges-tangent.md`.)
#[allow(clippy::too_many_arguments)]
fn grow(
    em: &EdgeMesh,
    fa: usize,
    fb: usize,
    init: [Point3; 2],
    seeds: bool,
    cand: &[Cand],
    r2: f64,
    cos_accept: f64,
    rejected: &mut Vec<u32>,
) -> [Point3; 2] {
    let w = if seeds { 1.0 } else { 0.0 };
    let mut sum = [
        vec3::scale(em.normals[fa], w * em.areas[fa]),
        vec3::scale(em.normals[fb], w * em.areas[fb]),
    ];
    let mut normal = init;
    rejected.clear();
    let try_add =
        |side: usize, n: Point3, area: f64, sum: &mut [Point3; 2], normal: &mut [Point3; 2]| {
            if vec3::dot(n, normal[side]) > cos_accept {
                sum[side] = vec3::add(sum[side], vec3::scale(n, area));
                if let Some(u) = vec3::normalize(sum[side]) {
                    normal[side] = u;
                }
                true
            } else {
                false
            }
        };
    for (i, c) in cand.iter().enumerate() {
        if c.d2 > r2 {
            continue;
        }
        let side = usize::from(c.sd >= 0.0);
        if !try_add(side, c.n, c.area, &mut sum, &mut normal) {
            rejected.push(i as u32);
        }
    }
    for &i in rejected.iter() {
        let c = &cand[i as usize];
        try_add(usize::from(c.sd >= 0.0), c.n, c.area, &mut sum, &mut normal);
    }
    normal
}
