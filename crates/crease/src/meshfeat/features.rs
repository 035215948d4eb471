//! The 43-dimensional feature vector F_e of an edge (vidal et al. 2011, section 4), the input of
//! the learned classifier ([`super::svm`]).
//!
//! | index | feature |
//! |---|---|
//! | 0 | cos θ_e, the dihedral angle (−1 for boundary edges, θ = π) |
//! | 1 | cos of the angle between the unit normals of the two vertices opposite to the edge (−1 for boundary and non-manifold edges) |
//! | 2 | mean over the two edge vertices of the minimum over the vertex's edges of cos θ |
//! | 3 | mean over the two edge vertices of the normal variation (see below) |
//! | 4–12 | cos θ̂ʳ_e, the tangent-plane angle of section 3, at r = 4, 7, ..., 28 % |
//! | 13 + 6 s + k | at the curvature scale s (r = 1, 5, 9, 13, 17 %), mean over the two edge vertices of k = 0: K_min, 1: K_max, 2: Gaussian K_min K_max, 3: mean ½(K_min + K_max), 4: K_max − K_min, 5: the similarity (saliency) measure |
//!
//! That is 4 + 9 + 5 × 6 = 43 features. The values here are raw (curvatures made
//! dimensionless by the ball radius); the normalisation of every feature to [−1, 1] is
//! part of the trained model ([`super::svm::Normalizer`]), computed on the training set and
//! applied to every mesh, as LIBSVM's `svm-scale` does.
//!
//! **Where the paper is vague (choices made here).**
//! - r is a fraction of [`EdgeMesh::reference_length`] (the bounding box's smallest side, at
//!   least a quarter of the largest), and never less than 2 mean edge lengths (as for θ̂ʳ: a
//!   sphere smaller than the faces holds nothing to estimate from).
//! - Vertex normals are the area-weighted means of the (consistently oriented) face normals.
//! - The "normal variation" of Lee & Lee 2002 at a vertex is taken as the area-weighted mean
//!   of n_f · n_v over its faces f (1 on a flat fan, lower the more the normals spread).
//! - Principal curvatures (Cohen-Steiner & Morvan 2003, normal cycle): at vertex v and radius
//!   r, T = (1 / |B|) Σ_e β(e) |e ∩ B| ē ēᵀ over the edges e whose midpoint is in the ball B of
//!   radius r around v, β the signed dihedral angle (positive where convex with outward
//!   normals; the orientation is the one of positive enclosed volume), |e ∩ B| the length of
//!   the edge clipped to the ball, |B| the area in the ball (each edge carries a third of its
//!   faces' area, times the fraction of it inside the ball). Of the eigenvalues of T, the one of
//!   smallest magnitude belongs to the normal; the other two are K_min ≤ K_max. Curvatures are
//!   multiplied by the ball's radius r (K by r²): dimensionless (the angle the normal turns
//!   over the ball), so they do not depend on the mesh's units, and at the scales clamped to 2
//!   edge lengths they do not grow with the resolution either (in units of the reference
//!   length instead, the default model found no feature edge on a mesh much finer than its
//!   training meshes, see `docs/experiments/mesh-edges-tangent.md`).
//! - The "similarity measure" of Lee et al. 2005 (mesh saliency) at scale r: |G(H, σ) −
//!   G(H, 2σ)| with σ = r / 4, G(H, σ) the Gaussian-weighted (standard deviation σ) mean of the
//!   vertices' mean curvature H within 2σ, H taken at the smallest curvature scale.
//! - **Bounded cost.** As for θ̂ʳ ([`super::tangent`]), large balls read a fixed pseudo-random
//!   subset of the edges (vertices for the saliency) holding a fraction 2⁻ˡ of them, with the
//!   level l the finest at which a ball holds at most [`FeatureParams::max_items`] on average;
//!   every sum is a ratio of sums over the subset, estimated without bias. Scales on the same
//!   level are gathered once at the largest of them.
//!
//! Everything runs in parallel over vertices and edges, and each value depends only on the
//! mesh, never on the thread count.

use nalgebra::{Matrix3, SymmetricEigen};
use rayon::prelude::*;

use super::grid::BallGrid;
use super::tangent::{
    crowd_counts, expected_items, subset_level, tangent_angles, TangentParams, PAPER_SCALES,
};
use super::EdgeMesh;
use crate::geometry::{vec3, Point3};
use crate::{Error, Result};

/// Number of features of section 4.
pub const NUM_FEATURES: usize = 43;

/// The scales of the curvature and similarity features (section 4: 1, 5, 9, 13, 17 %).
pub const CURVATURE_SCALES: [f64; 5] = [0.01, 0.05, 0.09, 0.13, 0.17];

/// Index of the first tangent-plane feature.
pub const TANGENT_OFFSET: usize = 4;
/// Index of the first curvature feature.
pub const CURVATURE_OFFSET: usize = 13;

/// Parameters of [`edge_features`].
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureParams {
    /// The tangent-plane estimator; its scales are the 9 of section 4 (default), its budget
    /// `max_faces` bounds the cost (default 24: models trained with larger budgets give the
    /// same Table 2 AUCs at a far higher cost, see `docs/experiments/mesh-edges-tangent.md`).
    pub tangent: TangentParams,
    /// The five curvature scales (fractions of the reference length).
    pub curvature_scales: Vec<f64>,
    /// Average number of edges (vertices) a curvature (saliency) ball may hold before it reads
    /// a random subset; `None` = all.
    pub max_items: Option<usize>,
    /// Smallest radius of the curvature balls, in mean edge lengths.
    pub min_edge_lengths: f64,
}

impl Default for FeatureParams {
    fn default() -> Self {
        FeatureParams {
            tangent: TangentParams {
                scales: PAPER_SCALES.to_vec(),
                max_faces: Some(24),
                ..TangentParams::default()
            },
            curvature_scales: CURVATURE_SCALES.to_vec(),
            max_items: Some(64),
            min_edge_lengths: 2.0,
        }
    }
}

/// The raw feature vectors of every edge.
#[derive(Debug, Clone, PartialEq)]
pub struct EdgeFeatures {
    /// Features per edge.
    pub dim: usize,
    /// Row-major, `values[e * dim + k]`.
    pub values: Vec<f32>,
}

impl EdgeFeatures {
    /// Number of edges.
    pub fn len(&self) -> usize {
        self.values.len() / self.dim.max(1)
    }

    /// True if there is no edge.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The features of edge `e`.
    pub fn row(&self, e: usize) -> &[f32] {
        &self.values[e * self.dim..(e + 1) * self.dim]
    }
}

/// Names of the features (for reports and the model file).
pub fn feature_names(tangent_scales: &[f64], curvature_scales: &[f64]) -> Vec<String> {
    let mut n = vec![
        "cos_dihedral".to_string(),
        "cos_opposite_vertex_normals".into(),
        "mean_min_cos_dihedral".into(),
        "mean_normal_variation".into(),
    ];
    for s in tangent_scales {
        n.push(format!("cos_tangent_{:.0}", s * 100.0));
    }
    for s in curvature_scales {
        for k in [
            "kmin",
            "kmax",
            "gauss",
            "mean",
            "kmax_minus_kmin",
            "saliency",
        ] {
            n.push(format!("{k}_{:.0}", s * 100.0));
        }
    }
    n
}

/// What a curvature ball reads of an edge.
#[derive(Clone, Copy)]
struct EdgeItem {
    a: Point3,
    b: Point3,
    /// Signed dihedral angle β.
    beta: f64,
    /// A third of the area of the edge's faces.
    area: f64,
    /// Subset weight 2^level of the group.
    weight: f64,
}

/// Level per radius: the finest l at which a ball of radius r holds at most `budget` items on
/// average, `density` items per unit area, or `measured[s]` ([`crowd_counts`]) where that is
/// much more than the area predicts ([`expected_items`]).
fn levels_for(radii: &[f64], density: f64, measured: &[f64], budget: Option<usize>) -> Vec<u32> {
    radii
        .iter()
        .zip(measured)
        .map(|(&r, &m)| match budget {
            None => 0,
            Some(b) => {
                let expected = expected_items(r, std::f64::consts::PI * r * r * density, m);
                let mut l = 0;
                while l < 40 && expected / f64::powi(2.0, l as i32) > b.max(1) as f64 {
                    l += 1;
                }
                l
            }
        })
        .collect()
}

/// Groups of scale indices sharing a level, each sorted by radius.
fn group_by_level(radii: &[f64], levels: &[u32]) -> Vec<(u32, Vec<usize>)> {
    let mut distinct = levels.to_vec();
    distinct.sort_unstable();
    distinct.dedup();
    distinct
        .into_iter()
        .map(|l| {
            let mut s: Vec<usize> = (0..radii.len()).filter(|&i| levels[i] == l).collect();
            s.sort_by(|&a, &b| radii[a].total_cmp(&radii[b]));
            (l, s)
        })
        .collect()
}

/// Length of the segment a–b inside the ball of radius r around q.
fn clipped_length(a: Point3, b: Point3, q: Point3, r2: f64) -> f64 {
    let d = vec3::sub(b, a);
    let f = vec3::sub(a, q);
    let aa = vec3::dot(d, d);
    if aa <= 0.0 {
        return 0.0;
    }
    let bb = 2.0 * vec3::dot(f, d);
    let cc = vec3::dot(f, f) - r2;
    let disc = bb * bb - 4.0 * aa * cc;
    if disc <= 0.0 {
        return 0.0;
    }
    let s = disc.sqrt();
    let t0 = ((-bb - s) / (2.0 * aa)).max(0.0);
    let t1 = ((-bb + s) / (2.0 * aa)).min(1.0);
    if t1 <= t0 {
        0.0
    } else {
        (t1 - t0) * aa.sqrt()
    }
}

/// Per vertex and curvature scale: [K_min, K_max, K, H, K_max − K_min] (dimensionless).
fn vertex_curvatures(em: &EdgeMesh, radii: &[f64], params: &FeatureParams) -> Vec<[f64; 5]> {
    let topo = &em.topo;
    let p = em.mesh.positions();
    let ne = topo.num_edges();
    let nv = topo.num_vertices();
    let ns = radii.len();
    // Orientation: outward if the enclosed (signed) volume is positive.
    let volume: f64 = (0..topo.num_faces())
        .into_par_iter()
        .map(|f| vec3::dot(em.centroids[f], em.normals[f]) * em.areas[f])
        .sum();
    let sign = if volume < 0.0 { -1.0 } else { 1.0 };
    let beta: Vec<f64> = (0..ne)
        .into_par_iter()
        .map(|e| {
            let fs = topo.edge_faces(e);
            if fs.len() != 2 {
                return 0.0;
            }
            let (fa, fb) = (fs[0] as usize, fs[1] as usize);
            if em.areas[fa] <= 0.0 || em.areas[fb] <= 0.0 {
                return 0.0;
            }
            // Convex: face b's barycentre lies below face a's plane.
            let concave = vec3::dot(
                em.normals[fa],
                vec3::sub(em.centroids[fb], em.centroids[fa]),
            );
            let s = if concave > 0.0 { -1.0 } else { 1.0 };
            sign * s * em.dihedral[e]
        })
        .collect();
    let edge_area: Vec<f64> = (0..ne)
        .into_par_iter()
        .map(|e| {
            topo.edge_faces(e)
                .iter()
                .map(|&f| em.areas[f as usize] / 3.0)
                .sum()
        })
        .collect();
    let total_area: f64 = em.areas.iter().sum();
    let density = if total_area > 0.0 {
        ne as f64 / total_area
    } else {
        0.0
    };
    let edges = topo.edges();
    let measured = match params.max_items {
        Some(_) => crowd_counts(
            p,
            ne,
            |e| {
                let [a, b] = edges[e];
                vec3::lerp(p[a as usize], p[b as usize], 0.5)
            },
            radii,
        ),
        None => vec![0.0; ns],
    };
    let levels = levels_for(radii, density, &measured, params.max_items);
    let groups = group_by_level(radii, &levels);
    let edge_levels: Vec<u32> = (0..ne as u32).into_par_iter().map(subset_level).collect();
    let grids: Vec<(BallGrid<EdgeItem>, Vec<usize>)> = groups
        .iter()
        .map(|(l, scales)| {
            let w = f64::powi(2.0, *l as i32);
            let pts: Vec<(Point3, EdgeItem)> = (0..ne)
                .filter(|&e| edge_levels[e] >= *l)
                .map(|e| {
                    let [a, b] = topo.edges()[e];
                    let (a, b) = (p[a as usize], p[b as usize]);
                    (
                        vec3::lerp(a, b, 0.5),
                        EdgeItem {
                            a,
                            b,
                            beta: beta[e],
                            area: edge_area[e],
                            weight: w,
                        },
                    )
                })
                .collect();
            let rmax = scales.iter().map(|&s| radii[s]).fold(0.0, f64::max);
            (BallGrid::new(pts, rmax / 2.0), scales.clone())
        })
        .collect();
    let mut out = vec![[0.0; 5]; nv * ns];
    out.par_chunks_mut(ns).enumerate().for_each_init(
        Vec::<(EdgeItem, f64)>::new,
        |buf, (v, row)| {
            let q = p[v];
            for (grid, scales) in &grids {
                let Some(&last) = scales.last() else { continue };
                buf.clear();
                grid.for_each_within(q, radii[last], |it, _, d2| buf.push((*it, d2)));
                for &s in scales {
                    let r2 = radii[s] * radii[s];
                    let mut t = Matrix3::<f64>::zeros();
                    let mut area = 0.0;
                    for (it, d2) in buf.iter() {
                        if *d2 > r2 {
                            continue;
                        }
                        let len = vec3::dist(it.a, it.b);
                        if len <= 0.0 {
                            continue;
                        }
                        let inside = clipped_length(it.a, it.b, q, r2);
                        area += it.weight * it.area * inside / len;
                        if it.beta != 0.0 {
                            let d = vec3::scale(vec3::sub(it.b, it.a), 1.0 / len);
                            let w = it.weight * it.beta * inside;
                            for i in 0..3 {
                                for j in 0..3 {
                                    t[(i, j)] += w * d[i] * d[j];
                                }
                            }
                        }
                    }
                    if area <= 0.0 {
                        continue;
                    }
                    t /= area;
                    let eig = SymmetricEigen::new(t);
                    let mut ev = [eig.eigenvalues[0], eig.eigenvalues[1], eig.eigenvalues[2]];
                    ev.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
                    let r = radii[s];
                    let (k1, k2) = (ev[1].min(ev[2]) * r, ev[1].max(ev[2]) * r);
                    row[s] = [k1, k2, k1 * k2, 0.5 * (k1 + k2), k2 - k1];
                }
            }
        },
    );
    out
}

/// Per vertex and scale: the saliency |G(H, σ) − G(H, 2σ)|, σ = r / 4.
fn vertex_saliency(em: &EdgeMesh, radii: &[f64], h: &[f64], params: &FeatureParams) -> Vec<f64> {
    let p = em.mesh.positions();
    let nv = p.len();
    let ns = radii.len();
    let total_area: f64 = em.areas.iter().sum();
    let density = if total_area > 0.0 {
        nv as f64 / total_area
    } else {
        0.0
    };
    let measured = match params.max_items {
        Some(_) => crowd_counts(p, nv, |v| p[v], radii),
        None => vec![0.0; ns],
    };
    let levels = levels_for(radii, density, &measured, params.max_items);
    let groups = group_by_level(radii, &levels);
    let grids: Vec<(BallGrid<f64>, Vec<usize>)> = groups
        .iter()
        .map(|(l, scales)| {
            let pts: Vec<(Point3, f64)> = (0..nv)
                .filter(|&v| subset_level(v as u32) >= *l)
                .map(|v| (p[v], h[v]))
                .collect();
            let rmax = scales.iter().map(|&s| radii[s]).fold(0.0, f64::max);
            (BallGrid::new(pts, rmax / 2.0), scales.clone())
        })
        .collect();
    let mut out = vec![0.0; nv * ns];
    out.par_chunks_mut(ns)
        .enumerate()
        .for_each_init(Vec::<(f64, f64)>::new, |buf, (v, row)| {
            for (grid, scales) in &grids {
                let Some(&last) = scales.last() else { continue };
                buf.clear();
                grid.for_each_within(p[v], radii[last], |hv, _, d2| buf.push((*hv, d2)));
                for &s in scales {
                    let sigma = radii[s] / 4.0;
                    let g = |sg: f64| {
                        let (mut num, mut den) = (0.0, 0.0);
                        let lim = 4.0 * sg * sg;
                        for &(hv, d2) in buf.iter() {
                            if d2 <= lim {
                                let w = (-d2 / (2.0 * sg * sg)).exp();
                                num += w * hv;
                                den += w;
                            }
                        }
                        if den > 0.0 {
                            num / den
                        } else {
                            0.0
                        }
                    };
                    row[s] = (g(sigma) - g(2.0 * sigma)).abs();
                }
            }
        });
    out
}

/// The raw feature vector of section 4 for every edge of `em` (see the module documentation),
/// in parallel.
///
/// Errors: a scale not positive and finite, and the errors of [`tangent_angles`].
pub fn edge_features(em: &EdgeMesh, params: &FeatureParams) -> Result<EdgeFeatures> {
    if params.curvature_scales.is_empty() {
        return Err(Error::InvalidArgument(
            "edge features: at least one curvature scale is needed".into(),
        ));
    }
    if let Some(s) = params
        .curvature_scales
        .iter()
        .find(|s| !(s.is_finite() && **s > 0.0))
    {
        return Err(Error::InvalidArgument(format!(
            "edge features: curvature scales must be positive, got {s}"
        )));
    }
    if params.max_items == Some(0) {
        return Err(Error::InvalidArgument(
            "edge features: max_items must be positive".into(),
        ));
    }
    let topo = &em.topo;
    let nv = topo.num_vertices();
    let ne = topo.num_edges();
    let t0 = std::time::Instant::now();
    let tangent = tangent_angles(em, &params.tangent)?;
    tracing::info!(
        "features: tangent-plane angles {:.2} s",
        t0.elapsed().as_secs_f64()
    );
    let nt = tangent.num_scales();
    let nc = params.curvature_scales.len();
    let dim = 4 + nt + 6 * nc;

    // Vertex normals, normal variation, min cos dihedral.
    let vnormal: Vec<Point3> = (0..nv)
        .into_par_iter()
        .map(|v| {
            let mut s = [0.0; 3];
            for &f in topo.vertex_faces(v) {
                s = vec3::add(s, vec3::scale(em.normals[f as usize], em.areas[f as usize]));
            }
            vec3::normalize(s).unwrap_or([0.0; 3])
        })
        .collect();
    let variation: Vec<f64> = (0..nv)
        .into_par_iter()
        .map(|v| {
            let (mut num, mut den) = (0.0, 0.0);
            for &f in topo.vertex_faces(v) {
                let a = em.areas[f as usize];
                num += a * vec3::dot(em.normals[f as usize], vnormal[v]);
                den += a;
            }
            if den > 0.0 {
                num / den
            } else {
                1.0
            }
        })
        .collect();
    let min_cos: Vec<f64> = (0..nv)
        .into_par_iter()
        .map(|v| {
            topo.vertex_edges(v)
                .iter()
                .map(|&e| em.dihedral[e as usize].cos())
                .fold(1.0, f64::min)
        })
        .collect();

    let radii: Vec<f64> = params
        .curvature_scales
        .iter()
        .map(|s| (s * em.reference_length).max(params.min_edge_lengths * em.mean_edge_length))
        .collect();
    let t0 = std::time::Instant::now();
    let curv = vertex_curvatures(em, &radii, params);
    tracing::info!("features: curvatures {:.2} s", t0.elapsed().as_secs_f64());
    let t0 = std::time::Instant::now();
    // H at the smallest curvature scale drives the saliency.
    let smallest = (0..nc)
        .min_by(|&a, &b| radii[a].total_cmp(&radii[b]))
        .unwrap_or(0);
    let h: Vec<f64> = (0..nv).map(|v| curv[v * nc + smallest][3]).collect();
    let sal = vertex_saliency(em, &radii, &h, params);
    tracing::info!("features: saliency {:.2} s", t0.elapsed().as_secs_f64());

    let mut values = vec![0f32; ne * dim];
    values.par_chunks_mut(dim).enumerate().for_each(|(e, row)| {
        let [a, b] = topo.edges()[e];
        let (a, b) = (a as usize, b as usize);
        row[0] = em.dihedral[e].cos() as f32;
        let opp: Vec<u32> = if topo.edge_faces(e).len() == 2 {
            topo.edge_opposite_vertices(e).collect()
        } else {
            Vec::new()
        };
        row[1] = if opp.len() == 2 {
            vec3::dot(vnormal[opp[0] as usize], vnormal[opp[1] as usize]) as f32
        } else {
            -1.0
        };
        row[2] = (0.5 * (min_cos[a] + min_cos[b])) as f32;
        row[3] = (0.5 * (variation[a] + variation[b])) as f32;
        for (s, ang) in tangent.edge(e).iter().enumerate() {
            row[4 + s] = ang.cos() as f32;
        }
        for s in 0..nc {
            let base = 4 + nt + 6 * s;
            let (ca, cb) = (curv[a * nc + s], curv[b * nc + s]);
            for k in 0..5 {
                row[base + k] = (0.5 * (ca[k] + cb[k])) as f32;
            }
            row[base + 5] = (0.5 * (sal[a * nc + s] + sal[b * nc + s])) as f32;
        }
    });
    Ok(EdgeFeatures { dim, values })
}
