//! Segmentation of a point cloud into analytic surfaces: mizoguchi's pipeline "over
//! k-nearest-neighbour graphs with the quadric-fit curvature" (issue 7), sharing every stage
//! after the curvature with the mesh path (`segment_graph`).
//!
//! **Graph.** The mesh edges are replaced by the symmetrised k-nearest-neighbour graph
//! (`k = 8` by default, [`PointParams::k`]; an edge i–j when j is among the k nearest of i or
//! i among those of j). It plays every role the mesh edges play: the fit regions of equation 1
//! (the connected part of the ball of radius `W · l_i,avg` along the graph), the 2-rings of
//! equation 3, the connected seeds of Step 4, the adjacency of the region growing and the
//! neighbour lists of the surfaces. The mean edge length `l̄` becomes the mean length of the
//! graph's edges (each point's mean distance to its graph neighbours, averaged): on a regular
//! triangular sampling the eight nearest neighbours are the six at one edge length and two at
//! √3, and on a uniform random sampling of spacing `s` (`s² =` area per point) `l̄ ≈ 1.1 s`,
//! close to the edge length of a mesh of the same density (`1.07 s`), so the scale-invariant
//! thresholds (`th_se`, ε, `th_pos`) keep their mesh meaning.
//!
//! **Normals.** `n_i` of equation 5 are the given normals when the cloud has them, else
//! weighted-PCA normals over the `normal_k` (20) nearest neighbours, oriented consistently by
//! Hoppe's minimum-spanning-tree propagation ([`crate::estimate::orient_normals`]); the
//! curvature signs, equation 3 and the torus histogram need consistent orientation.
//!
//! **Curvature (section 3).** The two passes of [`crate::estimate::bezier::two_pass_curvature`]
//! over the graph, fitting the 6-coefficient quadric of [`crate::estimate::curvature`] (the
//! point-cloud curvature of the issue) over the region of each point in the tangent plane of
//! `n_i`; the refitted normal of the quadric is `n'_i` (used by the fits, as on meshes). First
//! pass W = 2 (about 15 points), points with `|κ_max| l̄ > 0.4` are sharp, second pass W = 5
//! (about 90 points) never entering a sharp point.
//!
//! **Sharp points: why more than `th_se`.** Across a crease the quadric blends the two faces,
//! and the first-pass threshold alone does not stop that on clouds: only about half of the
//! points near an edge pass `th_se` (the fit's linear terms tilt the plane and halve the
//! apparent bend), and the graph's edges jump over the thin band that does, so second-pass
//! fits a few spacings away still reach across (measured on the synthetic cube, see
//! `docs/experiments/segmentation.md`). So, like
//! the mesh path's dihedral rule (`crease_angle_degrees`), a point is also sharp when the
//! normal `n` turns towards a graph neighbour faster than the crease angle per mean edge
//! length: `∠(n_i, n_j) > 30° · |p_i − p_j| / l̄` (unsigned angle). Every graph edge that
//! crosses a crease has both ends flagged, so no fit region crosses one; a smooth surface is
//! flagged only where its radius is below about 1.9 `l̄`. These points seed no residual
//! region either, as on meshes.
//!
//! **Left-over points.** On a mesh the faces at a crease are shared out among the regions of
//! their vertices. A cloud has no faces, and its crease points have PCA normals blended
//! between the two faces, so they fail equation 5 for both. After growing, each unassigned
//! point therefore joins the region of a graph neighbour whose surface is nearest to it, if
//! that distance passes equation 4 (no normal test), over up to `face_passes` rounds
//! (Jacobi-style: each round reads the previous one, so the result does not depend on the
//! thread count). On the synthetic cube this leaves almost no point unassigned
//! (`docs/experiments/segmentation.md`).
//!
//! **Order.** The work walks the graph; on a cloud in random order every step is a cache miss,
//! so the cloud is processed in Morton order and the per-point results are put back into the
//! input order (the curvature stage more than twice as fast, see
//! `docs/experiments/segmentation.md`).
//!
//! **Areas.** A point stands for the area `π r_k² / k`, `r_k` being the distance to its k-th
//! nearest neighbour (the k-nearest-neighbour density estimate); a surface's area is the sum
//! over its points, and the same values weight the fits (as the vertex areas do on meshes).
//! Points on open borders are given a little too much area (their k-ball is half empty), so
//! surface areas of open scans are overestimated by about a spacing times the border length.

use std::time::Instant;

use rayon::prelude::*;

use super::SegmentSurface;
use super::{check_params, grow, recognize, segment_graph, GraphInput, SegmentParams};
use crate::estimate::bezier::{two_pass_curvature, PatchModel};
use crate::estimate::orient::orient_normals_k;
use crate::estimate::{pca_normals, PcaParams};
use crate::geometry::vec3::{dist, dot, normalize};
use crate::geometry::{Aabb, Csr, Point3};
use crate::spatial::{gather, knn, morton_order_unique, Adjacency, Neighborhoods};
use crate::{Error, Result};

use crate::geometry::surface::signed_distance;

/// Points whose mean graph edge is longer than this many times the median one (isolated
/// outliers) do not count in the mean edge length, the segmentation's unit of length.
const OUTLIER_EDGE: f64 = 10.0;

/// Parameters of the point-cloud path (the thresholds are those of [`SegmentParams`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointParams {
    /// k of the neighbour graph (default 8).
    pub k: usize,
    /// k of the PCA normals when the cloud has none (default 20).
    pub normal_k: usize,
    /// The local surface of the curvature fits (default the quadric).
    pub patch: PatchModel,
}

impl Default for PointParams {
    fn default() -> Self {
        PointParams {
            k: 8,
            normal_k: 20,
            patch: PatchModel::Quadric,
        }
    }
}

/// Result of [`segment_points`]; per-point vectors follow the input order.
#[derive(Debug, Clone)]
pub struct PointSegmentation {
    /// The surfaces, id = index (`faces` is 0 for clouds; `area` from the point areas).
    pub surfaces: Vec<SegmentSurface>,
    /// Per point: surface id or -1.
    pub point_surface: Vec<i32>,
    /// Per point: label of section 4.
    pub point_labels: Vec<u8>,
    /// Per point: sharp (first curvature pass).
    pub sharp: Vec<bool>,
    /// Per point: the area it stands for.
    pub point_area: Vec<f64>,
    /// Number of seed regions.
    pub seeds: usize,
    /// Mean edge length `l̄` of the neighbour graph.
    pub mean_edge: f64,
    /// ε of equation 2 used (1/length).
    pub epsilon: f64,
    /// Whether the normals were given (else PCA + orientation).
    pub normals_given: bool,
    /// Fillets, linear extrusions and surfaces of revolution (section 6).
    pub groups: Vec<recognize::Group>,
    /// Seconds per stage.
    pub timings: Vec<(&'static str, f64)>,
}

impl PointSegmentation {
    /// Per point: the `surface_type` code (255 when unassigned).
    pub fn point_types(&self) -> Vec<u8> {
        super::type_codes(&self.point_surface, &self.surfaces)
    }
}

/// Segments a point cloud into analytic surfaces (see the module documentation).
///
/// Inputs: `points`; optional `normals` (one per point, consistently oriented, non-zero and
/// finite), the thresholds `params` and the cloud parameters `pp`.
/// Output: per-point surface ids and the surfaces, identical whatever the thread count.
/// Errors: fewer than `max(k, normal_k) + 1` points, a non-finite coordinate, normals of the
/// wrong length or zero / non-finite, invalid parameters, all points coincident.
pub fn segment_points(
    points: &[Point3],
    normals: Option<&[Point3]>,
    params: &SegmentParams,
    pp: &PointParams,
) -> Result<PointSegmentation> {
    // The per-point work (curvature regions, growing) walks the neighbour graph; on a cloud in
    // random order every step is a cache miss. So the cloud is processed in Morton order and
    // the per-point results are put back into the input order. Exact duplicates are segmented
    // once (zero-length edges would fill their neighbourhoods) and take their first copy's
    // surface (and area: the area a point stands for is counted on each copy).
    let finite = points.iter().all(|p| p.iter().all(|v| v.is_finite()));
    let unique = if finite && normals.is_none_or(|n| n.len() == points.len()) {
        morton_order_unique(points)
    } else {
        None
    };
    let Some((order, rank)) = unique else {
        return segment_ordered(points, normals, params, pp);
    };
    if order.len() < points.len() {
        tracing::info!(
            "{} of {} points repeat another exactly: segmented once",
            points.len() - order.len(),
            points.len()
        );
    }
    let sorted: Vec<Point3> = order.par_iter().map(|&i| points[i as usize]).collect();
    let sorted_normals: Option<Vec<Point3>> =
        normals.map(|n| order.par_iter().map(|&i| n[i as usize]).collect());
    let mut seg = segment_ordered(&sorted, sorted_normals.as_deref(), params, pp)?;
    seg.point_surface = gather(&rank, &seg.point_surface);
    seg.point_labels = gather(&rank, &seg.point_labels);
    seg.sharp = gather(&rank, &seg.sharp);
    seg.point_area = gather(&rank, &seg.point_area);
    Ok(seg)
}

/// [`segment_points`] on the points in the given order.
fn segment_ordered(
    points: &[Point3],
    normals: Option<&[Point3]>,
    params: &SegmentParams,
    pp: &PointParams,
) -> Result<PointSegmentation> {
    check_point_params(params, pp)?;
    let t = Instant::now();
    let nbrs = knn(points, neighbours_needed(pp, normals.is_some()))?;
    let knn_seconds = t.elapsed().as_secs_f64();
    segment_points_with(points, &nbrs, normals, params, pp).map(|mut seg| {
        seg.timings.insert(0, ("knn", knn_seconds));
        seg
    })
}

/// The neighbour count the point path reads: `pp.k` for the graph, and `pp.normal_k` for the
/// PCA normals when none are given.
pub fn neighbours_needed(pp: &PointParams, normals_given: bool) -> usize {
    if normals_given {
        pp.k
    } else {
        pp.k.max(pp.normal_k)
    }
}

fn check_point_params(params: &SegmentParams, pp: &PointParams) -> Result<()> {
    check_params(params)?;
    pp.validate()
}

impl PointParams {
    /// Errors (`InvalidArgument`) on k or normal_k below 3.
    pub fn validate(&self) -> Result<()> {
        if self.k < 3 || self.normal_k < 3 {
            return Err(Error::InvalidArgument(format!(
                "point segmentation: k = {} and normal_k = {} must be at least 3",
                self.k, self.normal_k
            )));
        }
        Ok(())
    }
}

/// The normals the point path estimates when none are given: weighted-PCA normals over the
/// `pp.normal_k` nearest neighbours, oriented consistently over the graph of the
/// [`neighbours_needed`] nearest (the prefixes of `nbrs`, which may hold more).
///
/// Errors: `nbrs` shorter than [`neighbours_needed`] or of another length than `points`.
pub fn estimated_normals(
    points: &[Point3],
    nbrs: &Neighborhoods,
    pp: &PointParams,
) -> Result<Vec<Point3>> {
    let pca = pca_normals(
        points,
        nbrs,
        &PcaParams {
            k: pp.normal_k,
            ..Default::default()
        },
    )?;
    orient_normals_k(points, &pca.normals, nbrs, neighbours_needed(pp, false))
}

/// [`segment_points`] from precomputed neighbour lists (at least [`neighbours_needed`] per row,
/// nearest first; longer rows are read through their prefixes), on the points in the order
/// given (the caller chooses it: [`segment_points`] sorts along the Morton curve first).
///
/// Errors: as [`segment_points`], and neighbour lists too short or of another length.
pub fn segment_points_with(
    points: &[Point3],
    nbrs: &Neighborhoods,
    normals: Option<&[Point3]>,
    params: &SegmentParams,
    pp: &PointParams,
) -> Result<PointSegmentation> {
    check_point_params(params, pp)?;
    let t = Instant::now();
    let vnormal: Vec<Point3> = match normals {
        Some(given) => {
            if given.len() != points.len() {
                return Err(Error::InvalidArgument(format!(
                    "point segmentation: {} normals for {} points",
                    given.len(),
                    points.len()
                )));
            }
            given
                .iter()
                .enumerate()
                .map(|(i, &v)| {
                    normalize(v).ok_or_else(|| {
                        Error::InvalidInput(format!(
                            "point segmentation: normal {i} is zero or not finite"
                        ))
                    })
                })
                .collect::<Result<_>>()?
        }
        None => {
            check_neighbours(points, nbrs, neighbours_needed(pp, false))?;
            estimated_normals(points, nbrs, pp)?
        }
    };
    let normal_seconds = t.elapsed().as_secs_f64();
    let mut seg = segment_core(points, nbrs, &vnormal, normals.is_some(), params, pp)?;
    seg.timings.insert(1, ("normals", normal_seconds));
    Ok(seg)
}

fn check_neighbours(points: &[Point3], nbrs: &Neighborhoods, k: usize) -> Result<()> {
    if nbrs.len() != points.len() || nbrs.k() < k {
        return Err(Error::InvalidArgument(format!(
            "point segmentation: {} neighbour lists of k = {} for {} points (k >= {k} needed)",
            nbrs.len(),
            nbrs.k(),
            points.len()
        )));
    }
    Ok(())
}

/// Errors when the points lie on one line: every plane through it fits them, so no surface is
/// theirs. Decided on neighbourhoods (their spread across below 1e-6 of their spread along:
/// the closed-form eigenvalues are exact to about 1e-16 of the largest, not relatively),
/// so that a far outlier, which makes the whole cloud look like a line, does not count: up to
/// 256 evenly spaced points of the (spatially sorted) cloud, each with its first k
/// neighbours; one neighbourhood that is not a line is enough.
fn check_not_collinear(points: &[Point3], nbrs: &Neighborhoods, k: usize) -> Result<()> {
    const SAMPLES: usize = 256;
    let n = points.len();
    let step = n.div_ceil(SAMPLES).max(1);
    let spread = |i: usize| -> bool {
        let row = nbrs.prefix(i, k);
        let m = (row.len() + 1) as f64;
        let all = || std::iter::once(points[i]).chain(row.iter().map(|&j| points[j as usize]));
        let mut c = [0.0; 3];
        for p in all() {
            for a in 0..3 {
                c[a] += p[a] / m;
            }
        }
        let mut cov = [0.0; 6];
        for p in all() {
            let d = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
            let terms = [
                d[0] * d[0],
                d[0] * d[1],
                d[0] * d[2],
                d[1] * d[1],
                d[1] * d[2],
                d[2] * d[2],
            ];
            for (s, t) in cov.iter_mut().zip(terms) {
                *s += t;
            }
        }
        let (_, ev) = crate::estimate::normals::smallest_eigen(cov);
        ev[2] > 0.0 && ev[1] > 1e-12 * ev[2]
    };
    if (0..n).step_by(step).any(spread) {
        return Ok(());
    }
    Err(Error::InvalidInput(
        "point segmentation: the points lie on one line, so no surface is theirs".into(),
    ))
}

/// The point path after the neighbours and normals: `vnormal` are unit normals, one per point
/// (`normals_given` is reported), `nbrs` holds at least `pp.k` neighbours per row.
pub(crate) fn segment_core(
    points: &[Point3],
    nbrs: &Neighborhoods,
    vnormal: &[Point3],
    normals_given: bool,
    params: &SegmentParams,
    pp: &PointParams,
) -> Result<PointSegmentation> {
    check_point_params(params, pp)?;
    check_neighbours(points, nbrs, pp.k)?;
    check_not_collinear(points, nbrs, pp.k)?;
    if vnormal.len() != points.len() {
        return Err(Error::InvalidArgument(format!(
            "point segmentation: {} normals for {} points",
            vnormal.len(),
            points.len()
        )));
    }
    let mut timings = Vec::new();
    let t = Instant::now();
    let n = points.len();
    // The graph: the first k of every row, symmetrised.
    let prefix = {
        let rows: Vec<&[u32]> = (0..n).map(|i| nbrs.prefix(i, pp.k)).collect();
        let counts: Vec<u32> = rows.iter().map(|r| r.len() as u32).collect();
        Csr {
            offsets: Csr::offsets_from_counts(&counts),
            indices: rows.concat(),
        }
    };
    let graph = prefix.symmetrized();
    // Point areas π r_k² / k.
    let point_area: Vec<f64> = (0..n)
        .into_par_iter()
        .map(|i| {
            let row = nbrs.prefix(i, pp.k);
            let r = row
                .last()
                .map(|&j| dist(points[i], points[j as usize]))
                .unwrap_or(0.0);
            std::f64::consts::PI * r * r / row.len().max(1) as f64
        })
        .collect();
    drop(prefix);
    let edge_means: Vec<(f64, usize)> = (0..n)
        .into_par_iter()
        .map(|i| {
            let row = graph.row(i);
            let s: f64 = row
                .iter()
                .map(|&j| dist(points[i], points[j as usize]))
                .sum();
            (s, row.len())
        })
        .collect();
    // The mean over points whose own mean edge is within OUTLIER_EDGE times the median: one
    // point 1e19 away (its edges 1e19 long) made the plain mean 1e15 and merged a cube's faces.
    let mut per_point: Vec<f64> = edge_means
        .iter()
        .filter(|&&(_, c)| c > 0)
        .map(|&(s, c)| s / c as f64)
        .collect();
    let cut = if per_point.is_empty() {
        f64::INFINITY
    } else {
        let mid = per_point.len() / 2;
        let (_, m, _) = per_point.select_nth_unstable_by(mid, f64::total_cmp);
        if *m > 0.0 {
            OUTLIER_EDGE * *m
        } else {
            f64::INFINITY
        }
    };
    let (sum, cnt) = edge_means
        .iter()
        .filter(|&&(s, c)| c > 0 && s / c as f64 <= cut)
        .fold((0.0, 0usize), |(s, c), &(a, b)| (s + a, c + b));
    let l = sum / cnt.max(1) as f64;
    if !l.is_finite() {
        return Err(Error::InvalidInput(
            "point segmentation: distances between neighbours overflow (coordinates near \
             1e308); move or scale the cloud, or remove the far outliers"
                .into(),
        ));
    }
    if l <= 0.0 {
        return Err(Error::InvalidInput(
            "point segmentation: the points are all coincident".into(),
        ));
    }
    // The extent of the part, outliers left out as above (the curvature threshold is scaled by
    // it: a point 1e19 away made it 5e-20, and every curved label a plane's).
    let inliers: Vec<Point3> = points
        .iter()
        .zip(&edge_means)
        .filter(|&(_, &(s, c))| c > 0 && s / c as f64 <= cut)
        .map(|(p, _)| *p)
        .collect();
    let diag = Aabb::from_points(if inliers.is_empty() { points } else { &inliers })
        .map(|b| b.diagonal())
        .filter(|d| *d > 0.0)
        .ok_or_else(|| Error::InvalidInput("point segmentation: the cloud has no extent".into()))?;
    timings.push(("graph", t.elapsed().as_secs_f64()));

    let t = Instant::now();
    // Crease points: a graph neighbour whose normal turns faster than the crease angle per
    // mean edge length (the mesh path's dihedral rule, per unit length because graph edges
    // vary in length).
    let crease_rate = params.crease_angle_degrees.to_radians() / l;
    let forced: Vec<bool> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut hit = false;
            graph.for_each_neighbor(i, |j| {
                let j = j as usize;
                let a = dot(vnormal[i], vnormal[j]).abs().min(1.0).acos();
                hit |= a > crease_rate * dist(points[i], points[j]);
            });
            hit
        })
        .collect();
    let bparams = crate::estimate::bezier::BezierParams {
        patch: pp.patch,
        ..params.bezier
    };
    let bez = two_pass_curvature(&graph, points, vnormal, l, &bparams, Some(&forced))?;
    timings.push(("curvature", t.elapsed().as_secs_f64()));
    let weight: Vec<f64> = point_area
        .iter()
        .map(|&a| {
            if a > 0.0 && a.is_finite() {
                a
            } else {
                1e-12 * l * l
            }
        })
        .collect();
    // The points' noise, by which seeds that straddle surfaces are told apart.
    let t = Instant::now();
    let noise = params
        .adapt_to_noise
        .then(|| crate::estimate::noise::noise_sigma(points))
        .flatten();
    timings.push(("noise", t.elapsed().as_secs_f64()));
    let core = segment_graph(
        &GraphInput {
            graph: &graph,
            pos: points,
            vnormal,
            bez: &bez,
            weight: &weight,
            no_residual: &forced,
            dissolve_crease_bands: true,
            measure_noise: true,
            noise,
            diag,
        },
        params,
    );
    timings.extend(core.timings.iter().copied());

    let t = Instant::now();
    let mut owner = core.owner;
    let regions = core.regions;
    assign_sharp(
        &graph,
        points,
        &bez.sharp,
        &regions,
        core.tol.pos,
        params.face_passes,
        &mut owner,
    );
    // Region vertex lists follow the final owners (the fits stay those of the growing).
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); regions.len()];
    for (i, &o) in owner.iter().enumerate() {
        if o >= 0 {
            members[o as usize].push(i as u32);
        }
    }
    let regions: Vec<grow::Region> = regions
        .into_iter()
        .zip(members)
        .map(|(r, vertices)| grow::Region { vertices, ..r })
        .collect();
    let nr = regions.len();
    let mut area = vec![0.0; nr];
    for (i, &o) in owner.iter().enumerate() {
        if o >= 0 {
            area[o as usize] += weight[i];
        }
    }
    let adj_rows: Vec<Vec<u32>> = (0..n)
        .into_par_iter()
        .map(|i| {
            let mut v = Vec::new();
            let o = owner[i];
            if o >= 0 {
                graph.for_each_neighbor(i, |j| {
                    let p = owner[j as usize];
                    if p >= 0 && p != o {
                        v.push(p as u32);
                    }
                });
            }
            v
        })
        .collect();
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); nr];
    for (i, row) in adj_rows.into_iter().enumerate() {
        if owner[i] >= 0 {
            adj[owner[i] as usize].extend(row);
        }
    }
    let surfaces = super::surfaces_of(&regions, &area, &vec![0; nr], adj, points, &weight);
    let groups = recognize::recognize(
        &surfaces,
        params.recognize_angle_degrees.to_radians(),
        2.0 * params.th_pos * l,
    );
    timings.push(("points", t.elapsed().as_secs_f64()));
    Ok(PointSegmentation {
        surfaces,
        point_surface: owner,
        point_labels: core.labels,
        sharp: bez.sharp,
        point_area,
        seeds: core.seeds,
        mean_edge: l,
        epsilon: core.epsilon,
        normals_given,
        groups,
        timings,
    })
}

/// Unassigned sharp points join the region of a graph neighbour whose surface is nearest,
/// within `tol_pos` (equation 4), over up to `passes` rounds (see the module documentation).
fn assign_sharp<G: Adjacency>(
    graph: &G,
    points: &[Point3],
    sharp: &[bool],
    regions: &[grow::Region],
    tol_pos: f64,
    passes: usize,
    owner: &mut [i32],
) {
    for _ in 0..passes {
        let next: Vec<i32> = (0..points.len())
            .into_par_iter()
            .map(|i| {
                if owner[i] >= 0 {
                    return owner[i];
                }
                let _ = sharp;
                let mut best = (tol_pos, -1i32);
                graph.for_each_neighbor(i, |j| {
                    let r = owner[j as usize];
                    if r < 0 {
                        return;
                    }
                    let d = signed_distance(&regions[r as usize].fit.params, points[i]).abs();
                    if d < best.0 || (d == best.0 && best.1 >= 0 && r < best.1) {
                        best = (d, r);
                    }
                });
                best.1
            })
            .collect();
        if next == owner {
            break;
        }
        owner.copy_from_slice(&next);
    }
}
