//! Two-pass biquadratic Bézier curvature of triangle meshes (mizoguchi section 3, after Razdan
//! and Bae's biquadratic Bézier patch fit, mizoguchi reference \[2\]).
//!
//! **Fit region (mizoguchi equation 1).** For vertex `v_i` the fit uses `v_i` and the vertices
//! "directly connected to `v_i`" among those with `‖v_j − v_i‖ < W · l_i,avg`, `l_i,avg` being
//! the mean length of the edges at `v_i`. W is therefore a radius in units of the local edge
//! length, not a ring count or a parameter grid; "directly connected" is implemented as the
//! connected part of that ball: a breadth-first search from `v_i` along mesh edges that only
//! enters vertices inside the ball.
//!
//! **Fit.** The region is projected on the tangent plane of the area-weighted vertex normal
//! `n_i` (origin `v_i`; in-plane axes = principal axes of the projected points), the projections'
//! bounding rectangle is mapped to the parameter square `[0, 1]²`, and the heights over the plane
//! are fitted in the least-squares sense by a biquadratic Bézier patch
//! `z(u, v) = Σ b_jk B_j(u) B_k(v)` (Bernstein polynomials of degree 2, 9 control heights;
//! fitting full 3D control points gives the same surface, as the projected `x, y` are affine in
//! `u, v`). Curvatures, principal directions and the refitted normal `n'_i` are those of the patch
//! at the parameters of `v_i` ([`super::curvature`]'s Monge formulas; positive where the surface
//! bends away from the normal, normals on the side of the faces' orientation, so outward-oriented
//! closed meshes give `+1/r` on spheres). With fewer than 9 vertices in the region (or a singular
//! system) the 6-coefficient quadric is fitted instead; with fewer than 6 the vertex has no
//! estimate (`NaN`).
//!
//! **Razdan and Bae's α.** Mizoguchi runs Razdan's estimator "with the parameter α = 0.9". The
//! paper itself (CAD 37(14), 2005) is not available to us; a public implementation of it
//! (psapirstein/mesh-comparing, `getCurvatureBezierPatch.m`, bicubic variant) shows what α is:
//! the weight between the data term and a shape-optimising term, the least-squares system
//! being the data rows scaled by one weight and the second differences of the control net's
//! boundary rows and columns scaled by the other (0.1 on the shape term there, i.e. 0.9 on the
//! data: consistent with mizoguchi's 0.9). [`BezierParams::alpha`] implements it for the
//! biquadratic net: `α² Σ (z_i − patch(u_i, v_i))² + (1 − α)² Σ (b_j0 − 2 b_j1 + b_j2)²` over
//! all three rows and columns of the 3 × 3 control heights (heights scaled by the region's
//! extent); the distance weights of that implementation are not used. α = 0.9 helps on noisy
//! synthetic parts but flattens the patch without noise and lowers the segmentation of the
//! real ABC model (`examples/bezier_alpha.rs`, figures in `docs/experiments/curvature.md`), so
//! it is off by default (`alpha: None`, the plain least-squares patch).
//!
//! **Two passes.** First pass with W = 2: a vertex whose maximum curvature `κ_max` (the principal
//! curvature of larger absolute value) exceeds `th_se` is a *sharp vertex*. Second pass with
//! W = 5 for the other vertices, the breadth-first search never entering a sharp vertex, so sharp
//! vertices and the vertices beyond them are left out of the fit. Sharp vertices keep their first
//! pass values; a vertex whose second fit fails keeps its first-pass values too.
//!
//! **th_se.** Mizoguchi leaves `th_se` to the user (in 1/length units, which depend on the
//! model's scale). To make the default scale-invariant it is expressed relative to the mesh's
//! mean edge length `l̄`: `th_se = sharp_threshold / l̄` (see [`BezierParams`]). A crease of
//! dihedral angle θ fitted over a W = 2 region bends by about θ over a width of a few `l̄`, so its
//! first-pass `|κ_max| · l̄` grows with θ and does not depend on the mesh resolution, whereas a
//! smooth surface of radius `r` gives `l̄ / r`, small on any mesh that resolves it.

use nalgebra::{SMatrix, SVector};
use rayon::prelude::*;

use super::curvature::{least_axis, monge_curvature, Curvature, Derivatives, PointCurvature};
use crate::geometry::normal_eq::{add_outer, symmetrize};
use crate::geometry::vec3::{add, cross, dist, dist2, dot, normalize, scale, sub};
use crate::geometry::{MeshTopology, Point3, TriMesh};
use crate::spatial::Adjacency;
use crate::{Error, Result};

/// Parameters of [`bezier_curvature`]. `Default` = mizoguchi's values (W = 2, then W = 5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BezierParams {
    /// W of the first pass (mizoguchi: 2).
    pub first_width: f64,
    /// W of the second pass (mizoguchi: 5).
    pub second_width: f64,
    /// `th_se` relative to the mean edge length `l̄`: a vertex is sharp when its first-pass
    /// `|κ_max| > sharp_threshold / l̄`. Default 0.4, i.e. a radius of curvature below 2.5 edge
    /// lengths: well below the cube's 90° edges and above a noisy smooth sphere on the
    /// synthetic meshes (`docs/experiments/curvature.md`).
    pub sharp_threshold: f64,
    /// An absolute `th_se` (1/length) that overrides `sharp_threshold` when set.
    pub sharp_threshold_absolute: Option<f64>,
    /// The local surface fitted to each region (default the biquadratic Bézier patch; point
    /// clouds use the 6-coefficient quadric, see [`PatchModel`]).
    pub patch: PatchModel,
    /// Razdan and Bae's α, the weight of the data term against a shape (fairness) term in the
    /// Bézier fit: `α² Σ (z_i − patch(u_i, v_i))² + (1 − α)² Σ (b_j0 − 2 b_j1 + b_j2)²` over
    /// the three rows and three columns of the control heights (see the module
    /// documentation). `None` (default): plain least squares.
    pub alpha: Option<f64>,
}

/// The height function fitted over a vertex's region.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PatchModel {
    /// Biquadratic Bézier patch over the region's bounding rectangle (mizoguchi / Razdan; the
    /// quadric when the region has fewer than 9 points).
    #[default]
    Bezier,
    /// `z = a x² + b xy + c y² + d x + e y + f` (the quadric fit of
    /// [`super::curvature`]): 6 coefficients instead of 9, so less sensitive to noise and to
    /// the uneven spread of random samples, and exact to second order on every analytic
    /// surface.
    Quadric,
}

impl Default for BezierParams {
    fn default() -> Self {
        BezierParams {
            first_width: 2.0,
            second_width: 5.0,
            sharp_threshold: 0.4,
            sharp_threshold_absolute: None,
            patch: PatchModel::Bezier,
            alpha: None,
        }
    }
}

/// Result of [`bezier_curvature`] (one entry per mesh vertex, vertex order).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BezierCurvature {
    /// Final curvatures: second pass for non-sharp vertices, first pass for sharp ones. `normal`
    /// is the refitted normal `n'` of the fitted patch.
    pub curvature: Curvature,
    /// Sharp vertices of the first pass.
    pub sharp: Vec<bool>,
    /// The `th_se` used (1/length).
    pub th_se: f64,
    /// Mean edge length of the mesh.
    pub mean_edge: f64,
}

/// Mizoguchi's two-pass curvature estimation (see the module documentation).
///
/// Inputs: `mesh` with `V` vertices and `topo` its topology.
/// Output: per-vertex curvatures, refitted normals and sharp flags, identical whatever the
/// thread count. Vertices without a usable fit region (isolated vertices, fewer than 6 region
/// vertices) get `NaN` curvatures and are not sharp.
/// Errors: `topo` was built from another mesh (vertex count), non-positive widths or threshold,
/// or a mesh without edges.
pub fn bezier_curvature(
    mesh: &TriMesh,
    topo: &MeshTopology,
    params: &BezierParams,
) -> Result<BezierCurvature> {
    bezier_curvature_with_sharp(mesh, topo, params, None)
}

/// [`bezier_curvature`] with vertices known to be sharp beforehand (e.g. on creases found by
/// their dihedral angle): they are sharp whatever their first-pass curvature, so the second
/// pass neither fits them nor reaches past them. `forced` has one flag per vertex.
///
/// Errors: as [`bezier_curvature`], or `forced` of the wrong length.
pub fn bezier_curvature_with_sharp(
    mesh: &TriMesh,
    topo: &MeshTopology,
    params: &BezierParams,
    forced: Option<&[bool]>,
) -> Result<BezierCurvature> {
    check(mesh, topo)?;
    let mean_edge = mean_edge_length(mesh, topo).ok_or_else(|| {
        Error::InvalidInput("Bézier curvature: the mesh has no edge of finite length".into())
    })?;
    let normals = vertex_normals(mesh, topo);
    two_pass_curvature(topo, mesh.positions(), &normals, mean_edge, params, forced)
}

/// Mizoguchi's two passes over any vertex graph (mesh edges or a point cloud's neighbour
/// graph): the fit region of a vertex is the connected part, along `graph`, of the ball of
/// equation 1 around it, `l_i,avg` being the mean distance to its graph neighbours; the
/// tangent planes are those of `normals` (zero normals: no estimate). `mean_edge` (`l̄`) scales
/// `th_se`.
///
/// Errors: lengths differ from the graph's vertex count, `mean_edge` not positive, invalid
/// parameters.
pub fn two_pass_curvature<G: Adjacency>(
    graph: &G,
    points: &[Point3],
    normals: &[Point3],
    mean_edge: f64,
    params: &BezierParams,
    forced: Option<&[bool]>,
) -> Result<BezierCurvature> {
    let n = graph.num_nodes();
    if points.len() != n || normals.len() != n {
        return Err(Error::InvalidArgument(format!(
            "two-pass curvature: {} points and {} normals for a graph of {n} vertices",
            points.len(),
            normals.len()
        )));
    }
    if forced.is_some_and(|f| f.len() != n) {
        return Err(Error::InvalidArgument(
            "Bézier curvature: one forced-sharp flag per vertex expected".into(),
        ));
    }
    for (name, w) in [
        ("first width", params.first_width),
        ("second width", params.second_width),
        ("sharp threshold", params.sharp_threshold),
        ("mean edge length", mean_edge),
    ] {
        if !(w > 0.0 && w.is_finite()) {
            return Err(Error::InvalidArgument(format!(
                "Bézier curvature: {name} must be positive, got {w}"
            )));
        }
    }
    if let Some(a) = params.alpha {
        if !(a > 0.0 && a <= 1.0) {
            return Err(Error::InvalidArgument(format!(
                "Bézier curvature: alpha must be in (0, 1], got {a}"
            )));
        }
    }
    let th_se = match params.sharp_threshold_absolute {
        Some(t) if t > 0.0 && t.is_finite() => t,
        Some(t) => {
            return Err(Error::InvalidArgument(format!(
                "Bézier curvature: th_se must be positive, got {t}"
            )))
        }
        None => params.sharp_threshold / mean_edge,
    };
    let pass = |width: f64, excluded: Option<&[bool]>| {
        fit_pass(
            graph,
            points,
            normals,
            width,
            excluded,
            params.patch,
            params.alpha,
        )
    };
    let first = pass(params.first_width, None);
    let sharp: Vec<bool> = first
        .iter()
        .enumerate()
        .map(|(i, c)| c.k1.abs().max(c.k2.abs()) > th_se || forced.is_some_and(|f| f[i]))
        .collect();
    let second = pass(params.second_width, Some(&sharp));
    let items: Vec<PointCurvature> = first
        .into_iter()
        .zip(second)
        .zip(&sharp)
        .map(|((a, b), &s)| if s || b.k1.is_nan() { a } else { b })
        .collect();
    Ok(BezierCurvature {
        curvature: Curvature::from_points(items),
        sharp,
        th_se,
        mean_edge,
    })
}

/// One pass of the Bézier fit with width `W` (mizoguchi equation 1) on every vertex, no vertex
/// excluded: Razdan-style single-pass curvature.
///
/// Inputs/outputs/errors as [`bezier_curvature`] (no sharp flags).
pub fn bezier_curvature_single(
    mesh: &TriMesh,
    topo: &MeshTopology,
    width: f64,
) -> Result<Curvature> {
    check(mesh, topo)?;
    if !(width > 0.0 && width.is_finite()) {
        return Err(Error::InvalidArgument(format!(
            "Bézier curvature: width must be positive, got {width}"
        )));
    }
    let normals = vertex_normals(mesh, topo);
    Ok(Curvature::from_points(fit_pass(
        topo,
        mesh.positions(),
        &normals,
        width,
        None,
        PatchModel::Bezier,
        None,
    )))
}

fn check(mesh: &TriMesh, topo: &MeshTopology) -> Result<()> {
    if topo.num_vertices() != mesh.num_vertices() {
        return Err(Error::InvalidArgument(format!(
            "topology of {} vertices given for a mesh of {} vertices",
            topo.num_vertices(),
            mesh.num_vertices()
        )));
    }
    Ok(())
}

/// Mean length of the mesh's finite edges.
fn mean_edge_length(mesh: &TriMesh, topo: &MeshTopology) -> Option<f64> {
    let p = mesh.positions();
    let lengths: Vec<f64> = topo
        .edges()
        .par_iter()
        .map(|&[a, b]| dist(p[a as usize], p[b as usize]))
        .collect();
    let (mut s, mut n) = (0.0, 0usize);
    for l in lengths {
        if l.is_finite() {
            s += l;
            n += 1;
        }
    }
    (n > 0 && s > 0.0).then(|| s / n as f64)
}

/// Area-weighted vertex normals (zero where undefined): the tangent planes of the fits.
fn vertex_normals(mesh: &TriMesh, topo: &MeshTopology) -> Vec<Point3> {
    let p = mesh.positions();
    let faces = topo.faces();
    (0..mesh.num_vertices())
        .into_par_iter()
        .with_min_len(1024)
        .map(|v| {
            let mut s = [0.0; 3];
            for &f in topo.vertex_faces(v) {
                let [a, b, c] = faces[f as usize].map(|i| p[i as usize]);
                s = add(s, cross(sub(b, a), sub(c, a)));
            }
            normalize(s).unwrap_or([0.0; 3])
        })
        .collect()
}

/// Per-thread scratch of a pass.
#[derive(Default)]
struct Scratch {
    /// `mark[u] == stamp`: vertex u is in the current region. A stamp per query instead of a
    /// hash set of the region: the membership test is one load (the hash set's probing was a
    /// fifth of the segmentation's time, see `docs/experiments/curvature.md`).
    /// Allocated zeroed on first use; only the pages a task's Morton-local queries touch are
    /// ever written.
    mark: Vec<u32>,
    stamp: u32,
    region: Vec<u32>,
    local: Vec<Point3>,
}

impl Scratch {
    /// Starts a new region over `n` vertices: no vertex marked.
    fn next_region(&mut self, n: usize) {
        if self.mark.len() != n {
            self.mark = vec![0; n];
            self.stamp = 0;
        }
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.mark.iter_mut().for_each(|m| *m = 0);
            self.stamp = 1;
        }
    }

    /// Marks `u`; true if it was not marked in this region yet.
    #[inline]
    fn insert(&mut self, u: u32) -> bool {
        let m = &mut self.mark[u as usize];
        if *m == self.stamp {
            false
        } else {
            *m = self.stamp;
            true
        }
    }
}

fn fit_pass<G: Adjacency>(
    graph: &G,
    points: &[Point3],
    normals: &[Point3],
    width: f64,
    excluded: Option<&[bool]>,
    patch: PatchModel,
    alpha: Option<f64>,
) -> Vec<PointCurvature> {
    (0..points.len())
        .into_par_iter()
        .with_min_len(64)
        .map_init(Scratch::default, |s, v| {
            if excluded.is_some_and(|e| e[v]) {
                return PointCurvature::FAILED;
            }
            fit_vertex(
                graph,
                points,
                normals,
                width,
                excluded,
                (patch, alpha),
                v,
                s,
            )
        })
        .collect()
}

#[allow(clippy::too_many_arguments)]
fn fit_vertex<G: Adjacency>(
    graph: &G,
    p: &[Point3],
    normals: &[Point3],
    width: f64,
    excluded: Option<&[bool]>,
    (patch, alpha): (PatchModel, Option<f64>),
    v: usize,
    s: &mut Scratch,
) -> PointCurvature {
    let pv = p[v];
    let n = normals[v];
    if n == [0.0; 3] {
        return PointCurvature::FAILED;
    }
    // l_i,avg and the region of equation 1.
    let (mut sum, mut cnt) = (0.0, 0usize);
    graph.for_each_neighbor(v, |u| {
        sum += dist(p[u as usize], pv);
        cnt += 1;
    });
    let l_avg = sum / cnt as f64;
    if cnt == 0 || !(l_avg > 0.0 && l_avg.is_finite()) {
        return PointCurvature::FAILED;
    }
    let r2 = (width * l_avg).powi(2);
    s.next_region(p.len());
    s.region.clear();
    s.insert(v as u32);
    s.region.push(v as u32);
    let mut head = 0;
    while head < s.region.len() {
        let u = s.region[head] as usize;
        head += 1;
        let (mark, stamp, region) = (&mut s.mark, s.stamp, &mut s.region);
        graph.for_each_neighbor(u, |w| {
            let wi = w as usize;
            if mark[wi] == stamp {
                return;
            }
            // Marked once seen, kept or not: whether it belongs depends on it alone, and a
            // vertex just outside the ball is the neighbour of several inside.
            mark[wi] = stamp;
            if excluded.is_some_and(|e| e[wi]) || dist2(p[wi], pv) >= r2 {
                return;
            }
            region.push(w);
        });
    }
    if s.region.len() < 6 {
        return PointCurvature::FAILED;
    }
    // Local coordinates over the tangent plane; in-plane axes from the projected spread.
    let t0 = normalize(cross(n, least_axis(n))).unwrap_or([1.0, 0.0, 0.0]);
    let t1 = cross(n, t0);
    s.local.clear();
    let (mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0);
    for &u in &s.region {
        let d = sub(p[u as usize], pv);
        let (x, y, z) = (dot(d, t0), dot(d, t1), dot(d, n));
        sxx += x * x;
        sxy += x * y;
        syy += y * y;
        s.local.push([x, y, z]);
    }
    let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
    let (c, sn) = (angle.cos(), angle.sin());
    let e1 = add(scale(t0, c), scale(t1, sn));
    let e2 = cross(n, e1);
    let (mut xmin, mut xmax, mut ymin, mut ymax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for q in s.local.iter_mut() {
        let (x, y) = (c * q[0] + sn * q[1], -sn * q[0] + c * q[1]);
        q[0] = x;
        q[1] = y;
        xmin = xmin.min(x);
        xmax = xmax.max(x);
        ymin = ymin.min(y);
        ymax = ymax.max(y);
    }
    let (sx, sy) = (xmax - xmin, ymax - ymin);
    if !(sx > 0.0 && sy > 0.0 && sx.is_finite() && sy.is_finite()) {
        return PointCurvature::FAILED;
    }
    let (u0, v0) = (-xmin / sx, -ymin / sy);
    if s.local.len() >= 9 && patch == PatchModel::Bezier {
        if let Some(d) = fit_bezier(&s.local, (xmin, ymin, sx, sy), (u0, v0), alpha) {
            return monge_curvature(&d, [e1, e2, n]);
        }
    }
    match fit_quadric(&s.local, width * l_avg) {
        Some(d) => monge_curvature(&d, [e1, e2, n]),
        None => PointCurvature::FAILED,
    }
}

/// Bernstein polynomials of degree 2 and their first and second derivatives at `t`.
#[inline]
fn bernstein2(t: f64) -> ([f64; 3], [f64; 3], [f64; 3]) {
    let s = 1.0 - t;
    (
        [s * s, 2.0 * t * s, t * t],
        [-2.0 * s, 2.0 - 4.0 * t, 2.0 * t],
        [2.0, -4.0, 2.0],
    )
}

/// Least-squares biquadratic Bézier height patch over the bounding rectangle; derivatives at
/// the parameters `(u0, v0)` in the local (unscaled) coordinates.
fn fit_bezier(
    local: &[Point3],
    (xmin, ymin, sx, sy): (f64, f64, f64, f64),
    (u0, v0): (f64, f64),
    alpha: Option<f64>,
) -> Option<Derivatives> {
    let mut ata = SMatrix::<f64, 9, 9>::zeros();
    let mut atb = SVector::<f64, 9>::zeros();
    let scale_z = sx.max(sy);
    for q in local {
        let (bu, _, _) = bernstein2((q[0] - xmin) / sx);
        let (bv, _, _) = bernstein2((q[1] - ymin) / sy);
        let mut m = SVector::<f64, 9>::zeros();
        for j in 0..3 {
            for k in 0..3 {
                m[3 * j + k] = bu[j] * bv[k];
            }
        }
        ata += m * m.transpose();
        atb += m * (q[2] / scale_z);
    }
    if let Some(a) = alpha {
        // Razdan and Bae: data rows weighted by α, the second differences of the control
        // heights along the rows and columns of the 3 × 3 net by 1 − α.
        ata *= a * a;
        atb *= a * a;
        let w = (1.0 - a) * (1.0 - a);
        for line in 0..3 {
            for (i0, step) in [(3 * line, 1), (line, 3)] {
                let mut r = SVector::<f64, 9>::zeros();
                r[i0] = 1.0;
                r[i0 + step] = -2.0;
                r[i0 + 2 * step] = 1.0;
                ata += r * r.transpose() * w;
            }
        }
    }
    let b = ata.cholesky()?.solve(&atb);
    if b.iter().any(|x| !x.is_finite()) {
        return None;
    }
    // Reject near-singular systems: the fitted heights must stay of the data's order.
    if b.iter().any(|x| x.abs() > 1e6) {
        return None;
    }
    let (bu, du, ddu) = bernstein2(u0);
    let (bv, dv, ddv) = bernstein2(v0);
    let (mut fu, mut fv, mut fuu, mut fuv, mut fvv) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for j in 0..3 {
        for k in 0..3 {
            let c = b[3 * j + k];
            fu += c * du[j] * bv[k];
            fv += c * bu[j] * dv[k];
            fuu += c * ddu[j] * bv[k];
            fuv += c * du[j] * dv[k];
            fvv += c * bu[j] * ddv[k];
        }
    }
    // z = scale_z · patch(u, v) with u = (x − xmin) / sx, v = (y − ymin) / sy.
    Some(Derivatives {
        fx: scale_z * fu / sx,
        fy: scale_z * fv / sy,
        fxx: scale_z * fuu / (sx * sx),
        fxy: scale_z * fuv / (sx * sy),
        fyy: scale_z * fvv / (sy * sy),
    })
}

/// Fallback: the 6-coefficient quadric `z = a x² + b xy + c y² + d x + e y + f`, derivatives at
/// the origin.
fn fit_quadric(local: &[Point3], h: f64) -> Option<Derivatives> {
    let inv = 1.0 / h;
    let mut ata = SMatrix::<f64, 6, 6>::zeros();
    let mut atb = SVector::<f64, 6>::zeros();
    for q in local {
        let (x, y, z) = (q[0] * inv, q[1] * inv, q[2] * inv);
        let m = SVector::<f64, 6>::from([x * x, x * y, y * y, x, y, 1.0]);
        add_outer(&mut ata, &m, 1.0);
        atb += m * z;
    }
    symmetrize(&mut ata);
    let c = ata.cholesky()?.solve(&atb);
    if c.iter().any(|x| !x.is_finite()) {
        return None;
    }
    Some(Derivatives {
        fx: c[3],
        fy: c[4],
        fxx: 2.0 * c[0] * inv,
        fxy: c[1] * inv,
        fyy: 2.0 * c[2] * inv,
    })
}
