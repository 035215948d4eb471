//! Feature-preserving smoothing of the face normals of a noisy mesh: bilateral normal filtering
//! (Y. Zheng, H. Fu, O. K.-C. Au, C.-L. Tai, "Bilateral normal filtering for mesh denoising",
//! IEEE TVCG 17(10), 2011, equation 4), one of the two sources of the `filtered` and
//! `potts-filtered` methods' angle ([`super::filtered_dihedral`]; the other is
//! [`super::tv`]).
//!
//! **Why (crease's addition to vidal et al. 2011).** At the noise of section 6.1 (Gaussian,
//! 0.5 % of the bounding box's largest side: 0.3 to 0.5 edge lengths on our meshes) adjacent
//! face normals differ by more than many crease angles, so the dihedral angle and the
//! tangent-plane estimator of section 3 lose the position of the line, and the learned
//! classifier loses AUC to the edges one or two rings beside the true lines. A few iterations
//! of bilateral filtering pull each face normal towards the normals of the neighbouring faces
//! that are already similar to it, so the faces on either side of a crease keep their own
//! plane's normal and the crease stays at the mesh edge between them: the dihedral angle of
//! the filtered normals alone ranks edges better than the raw angle and the paper's learned
//! classifier (figures: `docs/experiments/mesh-edges-filtered-angle.md`).
//!
//! One iteration (Jacobi: every face reads the previous iteration's normals):
//!
//! n_i ← normalise( Σ_j A_j W_s(‖c_i − c_j‖) W_r(‖n_i − n_j‖) n_j ),
//!
//! j over the faces sharing a vertex with face i (i included), A_j the area, c_j the
//! barycentre, W_s(x) = exp(−x² / 2σ_s²), W_r(x) = exp(−x² / 2σ_r²).
//!
//! **Choices made here (the paper leaves σ_s and σ_r to the user).**
//! - σ_s is the mean length of face i's edges, so that the spatial kernel follows the local
//!   resolution of unevenly tessellated CAD meshes (a global mean edge length scored lower).
//! - σ_r = [`BilateralParams::range_factor`] (2.5) × the median chord ‖n_i − n_j‖ = 2 sin(θ/2)
//!   of the dihedral angles θ over the edges with two faces, never below the chord of
//!   [`BilateralParams::min_range_degrees`] (10°): it follows the measured noise as the
//!   tangent-plane estimator's acceptance angle does ([`super::tangent::accept_angle`]), and a
//!   clean mesh (median near 0) is filtered with a narrow range kernel that keeps its creases.
//!   2.5 scored best among the factors 1.5 to 3; a higher floor gained only through block.off's
//!   sliver faces (see [`super::truth`]), so the floor that keeps creases stays.
//! - Vertices are not moved (the paper's second stage): only the normals are needed. Zheng's
//!   vertex update (rounds of filtering and moving the vertices onto the filtered planes) and
//!   guided normal filtering (Zhang et al. 2015) scored lower: at this noise no 1-ring patch is
//!   consistent enough to guide.
//!
//! The figures of each choice: `docs/experiments/mesh-edges-filtered-angle.md`.
//!
//! Parallel over the faces; each value depends only on the mesh, never on the thread count.

use rayon::prelude::*;

use super::tangent::median_dihedral;
use super::EdgeMesh;
use crate::geometry::{vec3, Point3};

/// Parameters of [`filter_normals`].
#[derive(Debug, Clone, PartialEq)]
pub struct BilateralParams {
    /// σ_r as a multiple of the median chord between adjacent face normals.
    pub range_factor: f64,
    /// The smallest σ_r, as the chord of this angle in degrees.
    pub min_range_degrees: f64,
}

impl Default for BilateralParams {
    fn default() -> Self {
        BilateralParams {
            range_factor: 2.5,
            min_range_degrees: 10.0,
        }
    }
}

/// σ_r of `em` (see the module documentation).
pub fn range_sigma(em: &EdgeMesh, params: &BilateralParams) -> f64 {
    let floor = 2.0 * (0.5 * params.min_range_degrees.to_radians()).sin();
    let median = median_dihedral(em).unwrap_or(0.0);
    (params.range_factor * 2.0 * (0.5 * median).sin()).max(floor)
}

/// The face normals of `em` after each of the given numbers of iterations (sorted ascending;
/// one normal vector per face and requested count, in the order of `iterations`). Degenerate
/// faces keep their zero normal and weigh nothing.
pub fn filter_normals(
    em: &EdgeMesh,
    iterations: &[usize],
    params: &BilateralParams,
) -> Vec<Vec<Point3>> {
    let topo = &em.topo;
    let faces = topo.faces();
    let p = em.mesh.positions();
    let sr = range_sigma(em, params);
    let inv_r = 1.0 / (2.0 * sr * sr);
    let inv_s: Vec<f64> = faces
        .par_iter()
        .map(|&[a, b, c]| {
            let (a, b, c) = (p[a as usize], p[b as usize], p[c as usize]);
            let h = (vec3::norm(vec3::sub(b, a))
                + vec3::norm(vec3::sub(c, b))
                + vec3::norm(vec3::sub(a, c)))
                / 3.0;
            if h > 0.0 {
                1.0 / (2.0 * h * h)
            } else {
                0.0
            }
        })
        .collect();
    let mut out = Vec::with_capacity(iterations.len());
    let mut n = em.normals.clone();
    let mut done = 0;
    for &target in iterations {
        while done < target {
            n = (0..faces.len())
                .into_par_iter()
                .map(|i| {
                    let fi = faces[i];
                    let mut acc = [0.0; 3];
                    for (k, &v) in fi.iter().enumerate() {
                        for &j in topo.vertex_faces(v as usize) {
                            let fj = faces[j as usize];
                            // Each neighbour once: skip it at the later vertices it shares.
                            if fi[..k].iter().any(|u| fj.contains(u)) {
                                continue;
                            }
                            let j = j as usize;
                            let ds = {
                                let d = vec3::sub(em.centroids[i], em.centroids[j]);
                                vec3::dot(d, d)
                            };
                            let dn = {
                                let d = vec3::sub(n[i], n[j]);
                                vec3::dot(d, d)
                            };
                            let w = em.areas[j] * (-ds * inv_s[i] - dn * inv_r).exp();
                            acc = vec3::add(acc, vec3::scale(n[j], w));
                        }
                    }
                    vec3::normalize(acc).unwrap_or(n[i])
                })
                .collect();
            done += 1;
        }
        out.push(n.clone());
    }
    out
}

/// The dihedral angle (radians) of normals `n` at every edge: π for boundary and non-manifold
/// edges, as [`EdgeMesh::dihedral`].
pub fn dihedral_of(em: &EdgeMesh, n: &[Point3]) -> Vec<f64> {
    (0..em.topo.num_edges())
        .into_par_iter()
        .map(|e| {
            let fs = em.topo.edge_faces(e);
            if fs.len() != 2 {
                return std::f64::consts::PI;
            }
            vec3::dot(n[fs[0] as usize], n[fs[1] as usize])
                .clamp(-1.0, 1.0)
                .acos()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::meshfeat::add_noise;
    use crate::meshfeat::test_support::{cube, median, median_degrees};

    /// On a noisy cube the filtered normals of the faces away from the edges return to the
    /// face planes' normals, and the dihedral angle at the cube's edges stays near 90°.
    #[test]
    fn filtering_restores_the_planes_of_a_noisy_cube() {
        let m = cube(40.0);
        let noisy = add_noise(&m.mesh, 0.003, 3).expect("noise");
        let em = EdgeMesh::new(&noisy).expect("topology");
        let (truth, _) = crate::meshfeat::labels_from_pairs(&em.topo, &m.sharp_edges);
        let filtered = filter_normals(&em, &[0, 3], &BilateralParams::default());
        assert_eq!(filtered[0], em.normals);
        // Angle of each face normal to the nearest axis, before and after.
        let axis_err = |n: &Point3| {
            let m = n.iter().fold(0.0f64, |a, c| a.max(c.abs()));
            m.clamp(-1.0, 1.0).acos().to_degrees()
        };
        let before = median(em.normals.iter().map(axis_err).collect());
        let after = median(filtered[1].iter().map(axis_err).collect());
        assert!(
            before > 8.0,
            "noise: median normal error {before:.1} degrees"
        );
        assert!(
            after < 0.3 * before,
            "filtered: {after:.1} vs {before:.1} degrees"
        );
        let d = dihedral_of(&em, &filtered[1]);
        let on = median_degrees(&d, |e| truth[e]);
        let off = median_degrees(&d, |e| !truth[e]);
        assert!(on > 60.0, "median filtered dihedral at the edges {on:.1}");
        assert!(off < 5.0, "median filtered dihedral elsewhere {off:.1}");
    }
}
