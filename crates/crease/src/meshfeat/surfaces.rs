//! Surface-intersection evidence (crease's addition to vidal et al. 2011, read by the `fused`
//! score, [`super::fused_scores`]): the mesh's vertices are segmented into analytic surfaces
//! (mizoguchi's pipeline, [`crate::segment::segment_points`]) and an edge scores high when
//! both its end vertices lie on the intersection of two of the fitted surfaces that meet at
//! an angle.
//!
//! **Why.** At the noise of section 6.1 (0.5 % of the bounding box's largest side, a quarter
//! to half an edge length on our meshes) every local estimator, the dihedral angle of
//! filtered normals as much as the multi-scale tangent-plane features of section 4, reads a
//! neighbourhood a few edges wide, where a shallow crease and the facets of a coarse curved
//! tessellation look alike (on cup.off its creases and the facet edges of its toroidal rims
//! come out at the same filtered angle). A fitted plane, cylinder, cone,
//! sphere or torus averages the noise over thousands of vertices, and a CAD part is made of
//! them: where two fitted surfaces meet, the line is where the vertices are on both.
//!
//! **The score.** Every vertex v gets the surface s(v) of its segmentation (or none). For an
//! edge e = (a, b), the candidate surfaces are those of the vertices within two rings of a
//! and b (one ring scored a little lower on every noise draw but one). For every pair
//! (A, B) of them,
//!
//! s_AB(e) = exp(−Σ_{v ∈ {a, b}} (d_A(v)² + d_B(v)²) / (8 W² σ̂²)) · min(1, ∠(n_A, n_B) / θ_t),
//!
//! d the orthogonal distance to the fitted surface ([`crate::geometry::surface::signed_distance`]),
//! n_A and n_B the surfaces' normals at the edge's midpoint, θ_t the decision angle of the
//! filtered dihedral angle ([`super::FILTERED_DEGREES`]), σ̂ the noise: the median distance of
//! the segmented vertices to their own surface divided by 0.6745 (the median of |N(0, σ²)|),
//! never below [`IntersectionParams::noise_floor`] mean edge lengths (on a clean CAD tessellation
//! the vertices lie exactly on their surfaces). An edge on the intersection has its four
//! distances of the order of σ̂ (s ≈ e^{-1/2} with W = 1); the edge one ring beside it has
//! its vertices an edge length off one of the surfaces (times the sine of the angle). The
//! edge's score is the largest s_AB, 0 when fewer than two surfaces are around.
//!
//! **Measured** (`examples/meshfeat_learned.rs`, the 11 meshes of Table 2): the term raises
//! the mean AUC of `fused` on noisy meshes, most on cup; on block and sharp_sphere the
//! segmentation finds few of the small faces and little changes. Other weights, widths W,
//! angle caps and noise estimates scored within a few hundredths of a point and were not kept
//! (`docs/experiments/mesh-edges-fused.md`).
//!
//! **Why the cloud path.** The mesh path of the segmentation ([`crate::segment::segment_mesh`])
//! keeps the paper's tolerances of equations 4 and 5 (0.5 l̄, 8°), which the noise of the
//! protocol exceeds: it split the noisy cube into more than a thousand surfaces and its edge
//! score ranked no better than chance. The cloud path widens them to the measured noise
//! (`SegmentParams::adapt_to_noise`) and finds a handful on the same cube.
//!
//! **Large meshes.** The seed fits dominate the segmentation, so
//! above [`IntersectionParams::max_points`] vertices only a pseudo-random subset of that size
//! (a hash of the vertex index, so independent of the thread count) is segmented, and every
//! other vertex takes the surface nearest to it among those of the segmented vertices within
//! two rings.

use rayon::prelude::*;
use serde::Serialize;

use super::EdgeMesh;
use crate::geometry::surface::{signed_distance, surface_normal};
use crate::geometry::{vec3, Aabb, Csr, Point3};
use crate::segment::{segment_points, PointParams, SegmentParams};
use crate::spatial::mesh_rings::vertex_k_rings;
use crate::Result;

/// Parameters of [`intersection_scores`] and of its weight in `fused`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct IntersectionParams {
    /// Weight of the score in `fused` (default 0.3; 0 skips the segmentation).
    pub weight: f64,
    /// W: the width of the distance kernel in units of σ̂ (default 1).
    pub width: f64,
    /// The smallest σ̂, in mean edge lengths (default 0.05).
    pub noise_floor: f64,
    /// The most vertices segmented (default 100 000; more are subsampled).
    pub max_points: usize,
}

impl Default for IntersectionParams {
    fn default() -> Self {
        IntersectionParams {
            weight: 0.3,
            width: 1.0,
            noise_floor: 0.05,
            max_points: 100_000,
        }
    }
}

/// SplitMix64: a well-mixed hash of the vertex index for the deterministic subsample.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Per vertex, the id of its fitted surface (−1 for none), and the surfaces' parameters;
/// `None` when too few vertices are on faces to segment.
/// `rings`: the 2-ring of every vertex ([`vertex_k_rings`]).
fn vertex_surfaces(
    em: &EdgeMesh,
    rings: &Csr,
    params: &IntersectionParams,
) -> Result<Option<(Vec<i32>, Vec<crate::geometry::SurfaceParams>)>> {
    let p = em.mesh.positions();
    let n = p.len();
    let on_faces: Vec<u32> = (0..n as u32)
        .filter(|&v| !em.topo.vertex_faces(v as usize).is_empty())
        .collect();
    let sampled: Vec<u32> = if on_faces.len() > params.max_points.max(1) {
        let cut = (params.max_points as f64 / on_faces.len() as f64 * u64::MAX as f64) as u64;
        on_faces
            .iter()
            .copied()
            .filter(|&v| mix(u64::from(v)) < cut)
            .collect()
    } else {
        on_faces
    };
    let pp = PointParams::default();
    let pts: Vec<Point3> = sampled.iter().map(|&v| p[v as usize]).collect();
    let flat = Aabb::from_points(&pts).is_none_or(|b| b.max_side() <= 0.0);
    if pts.len() <= pp.k.max(pp.normal_k) + 1 || flat {
        return Ok(None);
    }
    // Vertices the point segmentation refuses (on one line, say: a strip of slivers) give no
    // evidence; the edges are scored without it.
    let seg = match segment_points(&pts, None, &SegmentParams::default(), &pp) {
        Ok(seg) => seg,
        Err(crate::Error::InvalidInput(_)) => return Ok(None),
        Err(e) => return Err(e),
    };
    let surfaces: Vec<crate::geometry::SurfaceParams> =
        seg.surfaces.iter().map(|s| s.params).collect();
    let mut label = vec![-1i32; n];
    let mut is_sampled = vec![false; n];
    for (i, &v) in sampled.iter().enumerate() {
        label[v as usize] = seg.point_surface[i];
        is_sampled[v as usize] = true;
    }
    if sampled.len() < n {
        // Every other vertex: the nearest surface among those of the segmented vertices within
        // two rings (reads only the segmented labels, so the order does not matter).
        let filled: Vec<i32> = (0..n as u32)
            .into_par_iter()
            .map(|v| {
                if is_sampled[v as usize] {
                    return label[v as usize];
                }
                let q = p[v as usize];
                rings
                    .row(v as usize)
                    .iter()
                    .filter(|&&u| is_sampled[u as usize] && label[u as usize] >= 0)
                    .map(|&u| label[u as usize])
                    .map(|s| (signed_distance(&surfaces[s as usize], q).abs(), s))
                    .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                    .map_or(-1, |(_, s)| s)
            })
            .collect();
        label = filled;
    }
    Ok(Some((label, surfaces)))
}

/// The surface-intersection score of every edge (see the module documentation), in [0, 1];
/// `decision_degrees` is θ_t. All zeros when the mesh has too few vertices to segment
/// (fewer than 22 on faces) or no two surfaces.
pub fn intersection_scores(
    em: &EdgeMesh,
    params: &IntersectionParams,
    decision_degrees: f64,
) -> Result<Vec<f64>> {
    // Two rings: the crease vertices of a noisy cloud are often left to one surface, or to
    // none, so the other surface's vertices can be a ring further.
    let rings = vertex_k_rings(&em.topo, 2)?;
    let Some((label, surfaces)) = vertex_surfaces(em, &rings, params)? else {
        return Ok(vec![0.0; em.num_edges()]);
    };
    let p = em.mesh.positions();
    let mut own: Vec<f64> = label
        .par_iter()
        .enumerate()
        .filter(|(_, &s)| s >= 0)
        .map(|(v, &s)| signed_distance(&surfaces[s as usize], p[v]).abs())
        .collect();
    let median = if own.is_empty() {
        0.0
    } else {
        let mid = own.len() / 2;
        *own.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
    };
    let sigma = (median / 0.6745).max(params.noise_floor * em.mean_edge_length);
    let inv = if sigma > 0.0 && params.width > 0.0 {
        1.0 / (8.0 * params.width * params.width * sigma * sigma)
    } else {
        return Ok(vec![0.0; em.num_edges()]);
    };
    let inv_cap = 1.0 / decision_degrees.to_radians().max(f64::MIN_POSITIVE);
    let edges = em.topo.edges();
    Ok((0..em.num_edges())
        .into_par_iter()
        .map(|e| {
            let [a, b] = edges[e];
            let around = [a, b].into_iter().chain(
                (rings.row(a as usize).iter())
                    .chain(rings.row(b as usize))
                    .copied(),
            );
            let mut ids: Vec<i32> = around
                .map(|u| label[u as usize])
                .filter(|&s| s >= 0)
                .collect();
            ids.sort_unstable();
            ids.dedup();
            if ids.len() < 2 {
                return 0.0;
            }
            let (pa, pb) = (p[a as usize], p[b as usize]);
            let mid = vec3::scale(vec3::add(pa, pb), 0.5);
            // d² of both end vertices to each candidate surface.
            let d2: Vec<f64> = ids
                .iter()
                .map(|&s| {
                    let s = &surfaces[s as usize];
                    signed_distance(s, pa).powi(2) + signed_distance(s, pb).powi(2)
                })
                .collect();
            let mut best = 0.0f64;
            for i in 0..ids.len() {
                for j in i + 1..ids.len() {
                    let closeness = (-(d2[i] + d2[j]) * inv).exp();
                    if closeness <= best {
                        continue;
                    }
                    let na = surface_normal(&surfaces[ids[i] as usize], mid);
                    let nb = surface_normal(&surfaces[ids[j] as usize], mid);
                    if na == [0.0; 3] || nb == [0.0; 3] {
                        continue; // on an axis: no normal
                    }
                    let angle = vec3::dot(na, nb).abs().min(1.0).acos();
                    best = best.max(closeness * (angle * inv_cap).min(1.0));
                }
            }
            best
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::roc::roc;
    use crate::geometry::TriMesh;
    use crate::meshfeat::test_support::{cube, median};
    use crate::meshfeat::{add_noise, detect_prepared, labels_from_pairs, EdgeParams};

    fn noisy_cube() -> (TriMesh, Vec<[u32; 2]>) {
        let m = cube(40.0);
        // 0.8 % of the side: a third of an edge length, as the noise of section 6.1 on our
        // meshes.
        (add_noise(&m.mesh, 0.008, 3).expect("noise"), m.sharp_edges)
    }

    /// On a noisy cube the segmentation finds the six planes, and the score is near 1 on the
    /// cube's edges and near 0 elsewhere (measured: AUC 0.9955, medians 0.65 and 0).
    #[test]
    fn the_cube_edges_are_the_intersections_of_its_planes() {
        let (mesh, sharp) = noisy_cube();
        let em = EdgeMesh::new(&mesh).expect("topology");
        let (truth, _) = labels_from_pairs(&em.topo, &sharp);
        let s = intersection_scores(&em, &IntersectionParams::default(), 25.0).expect("scores");
        let auc = roc(&s, &truth).expect("roc").auc;
        let on = median((0..s.len()).filter(|&e| truth[e]).map(|e| s[e]).collect());
        let off = median((0..s.len()).filter(|&e| !truth[e]).map(|e| s[e]).collect());
        eprintln!("noisy cube: AUC {auc:.5}, medians {on:.3} / {off:.3}");
        assert!(auc > 0.99, "AUC {auc}");
        assert!(on > 0.5 && off < 0.01, "medians {on} / {off}");
        assert!(s.iter().all(|v| (0.0..=1.0).contains(v)));
    }

    /// Above `max_points` a subsample is segmented and the other vertices take the nearest
    /// surface around them: the lines stay, and the result does not depend on the number of
    /// threads (measured: AUC 0.9956).
    #[test]
    fn a_subsample_keeps_the_lines_whatever_the_thread_count() {
        let (mesh, sharp) = noisy_cube();
        let em = EdgeMesh::new(&mesh).expect("topology");
        let (truth, _) = labels_from_pairs(&em.topo, &sharp);
        let params = IntersectionParams {
            max_points: mesh.num_vertices() / 3,
            ..IntersectionParams::default()
        };
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("pool")
                .install(|| intersection_scores(&em, &params, 25.0).expect("scores"))
        };
        let one = run(1);
        assert_eq!(one, run(2));
        let auc = roc(&one, &truth).expect("roc").auc;
        eprintln!("noisy cube, a third of the vertices segmented: AUC {auc:.5}");
        assert!(auc > 0.985, "AUC {auc}");
    }

    /// A mesh with too few vertices to segment gets no evidence: `fused` scores it as without
    /// the term.
    #[test]
    fn too_few_vertices_give_no_evidence() {
        let tetra = TriMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        )
        .expect("mesh");
        let em = EdgeMesh::new(&tetra).expect("topology");
        let s = intersection_scores(&em, &IntersectionParams::default(), 25.0).expect("scores");
        assert_eq!(s, vec![0.0; 6]);
        let with = detect_prepared(&em, &EdgeParams::default()).expect("fused");
        let mut params = EdgeParams::default();
        params.intersection.weight = 0.0;
        let without = detect_prepared(&em, &params).expect("fused");
        assert_eq!(with.sharpness, without.sharpness);
    }
}
