//! Tessellation of the shapes made of trimmed patches: the box with a through-hole, the two
//! intersecting cylinders and the block with fillet, chamfer and cone.
//!
//! Every feature curve (and the seam of every closed cylinder or cone patch) is sampled ONCE, in
//! 3D, as a chain of shared vertices lying exactly on the curve (on the exact polyline vertices
//! for the cylinder–cylinder intersection curves). Each patch is then triangulated in an
//! isometric parameter domain — plane coordinates, the cylinder unrolled as (radius · angle,
//! height), the cone developed into an annular sector — by a constrained Delaunay
//! triangulation (`spade`, exact predicates) whose constraints are the patch's boundary loops,
//! seeded with a hexagonal lattice of interior points at the target spacing (kept away from the
//! boundary) and refined by Delaunay refinement (Ruppert / Chew) to a minimum angle with the
//! constraint edges kept. Triangles outside the domain or inside its holes are dropped (layer
//! parity across the constraints). Both sides of a border use the same chain and constraint
//! edges are never split, so the solids are watertight by construction; interior vertices are
//! mapped back onto the exact surface.

use std::collections::{HashMap, HashSet};
use std::f64::consts::{FRAC_PI_2, TAU};

use spade::handles::{FixedFaceHandle, InnerTag};
use spade::{
    AngleLimit, ConstrainedDelaunayTriangulation, Point2, RefinementParameters, Triangulation,
};

use super::mesh::{steps, Raw};
use super::shapes::Model;
use super::surfaces::{cone_point, cylinder_point, plane_point, Domain};
use super::truth::arc_point;
use super::Shape;
use crate::geometry::vec3::{add, dist, dot, lerp, normalize, scale, sub};
use crate::geometry::Point3;
use crate::{Error, Result};

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Largest angle (radians) one mesh edge may span on an arc: keeps the chord / arc length ratio
/// above 0.998 so that the feature edges measure the curves within 0.2 %.
const MAX_ARC_STEP: f64 = 0.2;

/// Minimum angle the Delaunay refinement aims at (away from the kept constraint edges).
const MIN_ANGLE_DEG: f64 = 25.0;

/// Interior lattice points closer than this × target to the boundary are not inserted.
const MARGIN: f64 = 0.6;

/// Vertices of the polyline of a cylinder–cylinder intersection curve (as in `shapes.rs`).
const INTERSECTION_POINTS: usize = 1 << 15;

/// An isometric map between a patch and its 2D parameter domain.
#[derive(Debug, Clone, Copy)]
enum Map {
    /// `origin + a u + b v` ↔ (a, b).
    Plane {
        origin: Point3,
        u: Point3,
        v: Point3,
        normal: Point3,
    },
    /// `center + h axis + r (cos θ e1 + sin θ e2)` ↔ (r θ, h); the seam is at θ = 0.
    Cylinder {
        center: Point3,
        axis: Point3,
        e1: Point3,
        e2: Point3,
        radius: f64,
        inward: bool,
    },
    /// `apex + l (cos α axis + sin α (cos θ e1 + sin θ e2))` ↔ l (cos φ, sin φ) with
    /// φ = (θ - θc) sin α (the development of the cone); the seam is at θ = 0.
    Cone {
        apex: Point3,
        axis: Point3,
        e1: Point3,
        e2: Point3,
        half_angle: f64,
    },
}

impl Map {
    fn from_domain(d: &Domain) -> Result<Map> {
        Ok(match *d {
            Domain::Plane {
                origin,
                u,
                v,
                normal,
                ..
            } => Map::Plane {
                origin,
                u,
                v,
                normal,
            },
            Domain::Cylinder {
                center,
                axis,
                e1,
                e2,
                radius,
                inward,
                ..
            } => Map::Cylinder {
                center,
                axis,
                e1,
                e2,
                radius,
                inward,
            },
            Domain::Cone {
                apex,
                axis,
                e1,
                e2,
                half_angle,
                ..
            } => Map::Cone {
                apex,
                axis,
                e1,
                e2,
                half_angle,
            },
            Domain::Sphere { .. } | Domain::Torus { .. } => {
                return Err(Error::InvalidInput(
                    "synthetic mesh: trimmed sphere / torus patches are not supported".into(),
                ))
            }
        })
    }

    /// The same map with its seam (θ = 0) moved to the angle `a`.
    fn seam_at(self, a: f64) -> Map {
        let rot = |e1: Point3, e2: Point3| {
            let (s, c) = a.sin_cos();
            (
                add(scale(e1, c), scale(e2, s)),
                add(scale(e1, -s), scale(e2, c)),
            )
        };
        match self {
            Map::Cylinder {
                center,
                axis,
                e1,
                e2,
                radius,
                inward,
            } => {
                let (e1, e2) = rot(e1, e2);
                Map::Cylinder {
                    center,
                    axis,
                    e1,
                    e2,
                    radius,
                    inward,
                }
            }
            Map::Cone {
                apex,
                axis,
                e1,
                e2,
                half_angle,
            } => {
                let (e1, e2) = rot(e1, e2);
                Map::Cone {
                    apex,
                    axis,
                    e1,
                    e2,
                    half_angle,
                }
            }
            plane => plane,
        }
    }

    fn periodic(&self) -> bool {
        !matches!(self, Map::Plane { .. })
    }

    /// Angle of `p` around the axis in (-π, π] (0 for planes).
    fn angle(&self, p: Point3) -> f64 {
        let (o, e1, e2) = match *self {
            Map::Plane { .. } => return 0.0,
            Map::Cylinder { center, e1, e2, .. } => (center, e1, e2),
            Map::Cone { apex, e1, e2, .. } => (apex, e1, e2),
        };
        let v = sub(p, o);
        dot(v, e2).atan2(dot(v, e1))
    }

    /// Exact outward normal of the surface at `p` (a point on it).
    fn normal(&self, p: Point3) -> Point3 {
        match *self {
            Map::Plane { normal, .. } => normal,
            Map::Cylinder {
                center,
                axis,
                e1,
                inward,
                ..
            } => {
                let v = sub(p, center);
                let r = normalize(sub(v, scale(axis, dot(v, axis)))).unwrap_or(e1);
                if inward {
                    scale(r, -1.0)
                } else {
                    r
                }
            }
            Map::Cone {
                apex,
                axis,
                e1,
                half_angle,
                ..
            } => {
                let v = sub(p, apex);
                let r = normalize(sub(v, scale(axis, dot(v, axis)))).unwrap_or(e1);
                let (sa, ca) = half_angle.sin_cos();
                sub(scale(r, ca), scale(axis, sa))
            }
        }
    }

    /// Domain coordinates of `p`, whose unwrapped angle is `theta`; `theta_c` is the central
    /// angle of the developed cone.
    fn to2d(&self, p: Point3, theta: f64, theta_c: f64) -> [f64; 2] {
        match *self {
            Map::Plane { origin, u, v, .. } => {
                let d = sub(p, origin);
                [dot(d, u), dot(d, v)]
            }
            Map::Cylinder {
                center,
                axis,
                radius,
                ..
            } => [radius * theta, dot(sub(p, center), axis)],
            Map::Cone {
                apex, half_angle, ..
            } => {
                let l = dist(p, apex);
                let phi = (theta - theta_c) * half_angle.sin();
                [l * phi.cos(), l * phi.sin()]
            }
        }
    }

    /// The surface point and its outward normal at domain coordinates `q`.
    fn to3d(&self, q: [f64; 2], theta_c: f64) -> (Point3, Point3) {
        match *self {
            Map::Plane {
                origin,
                u,
                v,
                normal,
            } => (plane_point(origin, u, v, q[0], q[1]), normal),
            Map::Cylinder {
                center,
                axis,
                e1,
                e2,
                radius,
                inward,
            } => {
                let (p, n, _) =
                    cylinder_point(center, axis, e1, e2, radius, q[0] / radius, q[1], inward);
                (p, n)
            }
            Map::Cone {
                apex,
                axis,
                e1,
                e2,
                half_angle,
            } => {
                let l = q[0].hypot(q[1]);
                let th = q[1].atan2(q[0]) / half_angle.sin() + theta_c;
                let (p, n, _) = cone_point(apex, axis, e1, e2, half_angle, th, l);
                (p, n)
            }
        }
    }
}

/// The shared vertices and curve chains of a shape under construction.
struct Net {
    raw: Raw,
    target: f64,
    /// One map per patch (index = surface id).
    maps: Vec<Map>,
    /// Open chains keyed by (first vertex, last vertex).
    chains: HashMap<(u32, u32), Vec<u32>>,
}

impl Net {
    fn new(model: &Model, target: f64) -> Result<Net> {
        let maps = model
            .patches
            .iter()
            .map(|p| Map::from_domain(&p.domain))
            .collect::<Result<Vec<_>>>()?;
        Ok(Net {
            raw: Raw::default(),
            target,
            maps,
            chains: HashMap::new(),
        })
    }

    fn map(&self, surface: u32) -> Result<Map> {
        self.maps.get(surface as usize).copied().ok_or_else(|| {
            Error::InvalidInput(format!("synthetic mesh: no patch {surface} in the model"))
        })
    }

    /// A vertex at `p` belonging to `surface` (whose exact normal it gets).
    fn vertex(&mut self, p: Point3, surface: u32) -> Result<u32> {
        let n = self.map(surface)?.normal(p);
        self.raw.positions.push(p);
        self.raw.normals.push(n);
        self.raw.vsurf.push(surface);
        Ok((self.raw.positions.len() - 1) as u32)
    }

    fn pos(&self, v: u32) -> Point3 {
        self.raw.positions[v as usize]
    }

    /// Registers the open chain `a, inner..., b` with new vertices at `inner`.
    fn chain(&mut self, a: u32, b: u32, inner: Vec<Point3>, surface: u32) -> Result<()> {
        let mut c = Vec::with_capacity(inner.len() + 2);
        c.push(a);
        for p in inner {
            c.push(self.vertex(p, surface)?);
        }
        c.push(b);
        self.chains.insert((a, b), c);
        Ok(())
    }

    /// The straight chain between the vertices `a` and `b`.
    fn segment(&mut self, a: u32, b: u32, surface: u32) -> Result<()> {
        let (pa, pb) = (self.pos(a), self.pos(b));
        let n = steps(dist(pa, pb), self.target);
        let inner = (1..n).map(|i| lerp(pa, pb, i as f64 / n as f64)).collect();
        self.chain(a, b, inner, surface)
    }

    /// The chain along the arc `center + r (cos t e1 + sin t e2)`, t from `start` to
    /// `start + sweep`, between the vertices `a` (at `start`) and `b` (at the end).
    #[allow(clippy::too_many_arguments)]
    fn arc(
        &mut self,
        a: u32,
        b: u32,
        center: Point3,
        e1: Point3,
        e2: Point3,
        r: f64,
        start: f64,
        sweep: f64,
        surface: u32,
    ) -> Result<()> {
        let n = arc_steps(r, sweep, self.target);
        let inner = (1..n)
            .map(|i| arc_point(center, e1, e2, r, start + sweep * i as f64 / n as f64))
            .collect();
        self.chain(a, b, inner, surface)
    }

    /// A closed circle chain starting and ending at a new vertex at angle `start`.
    fn circle(
        &mut self,
        center: Point3,
        e1: Point3,
        e2: Point3,
        r: f64,
        start: f64,
        surface: u32,
    ) -> Result<Vec<u32>> {
        let n = arc_steps(r, TAU, self.target);
        let mut c = Vec::with_capacity(n + 1);
        for i in 0..n {
            let t = start + TAU * i as f64 / n as f64;
            c.push(self.vertex(arc_point(center, e1, e2, r, t), surface)?);
        }
        c.push(c[0]);
        Ok(c)
    }

    /// The chain from `a` to `b` (a registered chain, reversed if needed).
    fn between(&self, a: u32, b: u32) -> Result<Vec<u32>> {
        if let Some(c) = self.chains.get(&(a, b)) {
            return Ok(c.clone());
        }
        if let Some(c) = self.chains.get(&(b, a)) {
            return Ok(c.iter().rev().copied().collect());
        }
        Err(Error::InvalidInput(format!(
            "synthetic mesh: no curve between vertices {a} and {b}"
        )))
    }

    /// The closed loop through the corner vertices `corners` along the registered chains.
    fn loop_through(&self, corners: &[u32]) -> Result<Vec<u32>> {
        let parts = (0..corners.len())
            .map(|i| self.between(corners[i], corners[(i + 1) % corners.len()]))
            .collect::<Result<Vec<_>>>()?;
        join(&parts)
    }

    /// Triangulates patch `surface` bounded by `loops` (closed vertex cycles, the first one the
    /// outer boundary) and appends its vertices and faces.
    fn patch(&mut self, surface: u32, loops: &[Vec<u32>]) -> Result<()> {
        let map = self.map(surface)?;
        let t = self.target;
        // Domain coordinates of the loop vertices; periodic maps unwrap the angle along the
        // loops, the outer loop starting near 0 (its seam corner), the holes in its range.
        let mut theta: Vec<Vec<f64>> = Vec::with_capacity(loops.len());
        let mut theta_c = 0.0;
        if map.periodic() {
            let mut hint = 0.0;
            for (k, lp) in loops.iter().enumerate() {
                let mut prev = hint;
                let th: Vec<f64> = lp
                    .iter()
                    .map(|&v| {
                        let a = map.angle(self.pos(v));
                        let u = a + TAU * ((prev - a) / TAU).round();
                        prev = u;
                        u
                    })
                    .collect();
                if k == 0 {
                    let lo = th.iter().copied().fold(f64::INFINITY, f64::min);
                    let hi = th.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    hint = 0.5 * (lo + hi);
                    theta_c = hint;
                }
                theta.push(th);
            }
        } else {
            theta = loops.iter().map(|lp| vec![0.0; lp.len()]).collect();
        }
        let mut pts: Vec<Point2<f64>> = Vec::new();
        let mut ids: Vec<u32> = Vec::new();
        let mut edges: Vec<[usize; 2]> = Vec::new();
        for (lp, th) in loops.iter().zip(&theta) {
            let base = pts.len();
            for (&v, &a) in lp.iter().zip(th) {
                let q = map.to2d(self.pos(v), a, theta_c);
                pts.push(Point2::new(q[0], q[1]));
                ids.push(v);
            }
            let n = lp.len();
            edges.extend((0..n).map(|i| [base + i, base + (i + 1) % n]));
        }
        let n_fixed = pts.len();
        lattice(&mut pts, &edges, t);
        let n_points = pts.len();
        let n_edges = edges.len();
        let mut conflict = false;
        let mut cdt = Cdt::try_bulk_load_cdt(pts, edges, |_| conflict = true)
            .map_err(|e| fail(surface, &format!("{e:?}")))?;
        if conflict || cdt.num_vertices() != n_points || cdt.num_constraints() != n_edges {
            return Err(fail(surface, "its boundary loops overlap or intersect"));
        }
        let area_unit = t * t;
        let result = cdt.refine(
            RefinementParameters::<f64>::new()
                .with_angle_limit(AngleLimit::from_deg(MIN_ANGLE_DEG))
                .keep_constraint_edges()
                .exclude_outer_faces(true)
                .with_min_required_area(0.02 * area_unit)
                .with_max_additional_vertices(n_points / 2 + 64),
        );
        if cdt.num_constraints() != n_edges {
            return Err(fail(surface, "refinement split a boundary edge"));
        }
        let excluded: HashSet<FixedFaceHandle<InnerTag>> =
            result.excluded_faces.into_iter().collect();
        let mut global = vec![u32::MAX; cdt.num_vertices()];
        global[..n_fixed].copy_from_slice(&ids);
        let raw = &mut self.raw;
        for face in cdt.inner_faces() {
            if excluded.contains(&face.fix()) {
                continue;
            }
            let mut tri = [0u32; 3];
            let mut c = [0.0; 2];
            for (k, v) in face.vertices().iter().enumerate() {
                let i = v.fix().index();
                let q = v.position();
                c[0] += q.x / 3.0;
                c[1] += q.y / 3.0;
                if global[i] == u32::MAX {
                    let (p, n) = map.to3d([q.x, q.y], theta_c);
                    raw.positions.push(p);
                    raw.normals.push(n);
                    raw.vsurf.push(surface);
                    global[i] = (raw.positions.len() - 1) as u32;
                }
                tri[k] = global[i];
            }
            raw.faces.push(tri);
            raw.fsurf.push(surface);
            raw.fnormal.push(map.to3d(c, theta_c).1);
        }
        Ok(())
    }
}

fn fail(surface: u32, what: &str) -> Error {
    Error::InvalidInput(format!(
        "synthetic mesh: triangulation of patch {surface} failed: {what}"
    ))
}

/// Number of pieces of an arc of radius `r` and angle `sweep`.
fn arc_steps(r: f64, sweep: f64, target: f64) -> usize {
    steps(r * sweep, target).max((sweep / MAX_ARC_STEP).ceil() as usize)
}

/// Concatenates chains whose ends meet into one closed loop (the closing vertex not repeated).
fn join(parts: &[Vec<u32>]) -> Result<Vec<u32>> {
    let mut out: Vec<u32> = Vec::new();
    for c in parts {
        match (out.last(), c.first()) {
            (Some(&a), Some(&b)) if a != b => {
                return Err(Error::InvalidInput(format!(
                    "synthetic mesh: boundary chains do not meet ({a} vs {b})"
                )))
            }
            (Some(_), _) => out.extend_from_slice(c.get(1..).unwrap_or(&[])),
            (None, _) => out.extend_from_slice(c),
        }
    }
    if out.len() < 4 || out.first() != out.last() {
        return Err(Error::InvalidInput(
            "synthetic mesh: boundary loop is not closed".into(),
        ));
    }
    out.pop();
    Ok(out)
}

/// The loop of a closed chain (whose last vertex repeats the first).
fn closed_loop(c: &[u32]) -> Result<Vec<u32>> {
    match c.split_last() {
        Some((last, rest)) if rest.len() >= 3 && rest.first() == Some(last) => Ok(rest.to_vec()),
        _ => Err(Error::InvalidInput(
            "synthetic mesh: closed curve chain does not return to its start".into(),
        )),
    }
}

/// Appends the points of a hexagonal lattice of spacing `t` over the bounding box of the
/// boundary points `pts[..]` that are at least `MARGIN · t` from every boundary segment.
fn lattice(pts: &mut Vec<Point2<f64>>, edges: &[[usize; 2]], t: f64) {
    if pts.is_empty() {
        return;
    }
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in pts.iter() {
        lo = [lo[0].min(p.x), lo[1].min(p.y)];
        hi = [hi[0].max(p.x), hi[1].max(p.y)];
    }
    // Buckets of cell size t holding the segments that pass near them.
    let cell = |x: f64, y: f64| {
        (
            ((x - lo[0]) / t).floor() as i64,
            ((y - lo[1]) / t).floor() as i64,
        )
    };
    let mut buckets: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (k, &[a, b]) in edges.iter().enumerate() {
        let (pa, pb) = (pts[a], pts[b]);
        let (i0, j0) = cell(pa.x.min(pb.x), pa.y.min(pb.y));
        let (i1, j1) = cell(pa.x.max(pb.x), pa.y.max(pb.y));
        for i in i0..=i1 {
            for j in j0..=j1 {
                buckets.entry((i, j)).or_default().push(k);
            }
        }
    }
    let margin2 = (MARGIN * t) * (MARGIN * t);
    let near = |x: f64, y: f64| -> bool {
        let (ci, cj) = cell(x, y);
        for i in ci - 1..=ci + 1 {
            for j in cj - 1..=cj + 1 {
                for &k in buckets.get(&(i, j)).map(Vec::as_slice).unwrap_or(&[]) {
                    let [a, b] = edges[k];
                    if segment_distance2([x, y], pts[a], pts[b]) < margin2 {
                        return true;
                    }
                }
            }
        }
        false
    };
    let dy = t * 3f64.sqrt() / 2.0;
    let rows = ((hi[1] - lo[1]) / dy).floor() as usize;
    let cols = ((hi[0] - lo[0]) / t).floor() as usize + 1;
    let mut new = Vec::new();
    for j in 0..=rows {
        let y = lo[1] + dy * j as f64;
        let shift = if j % 2 == 1 { 0.5 * t } else { 0.0 };
        for i in 0..=cols {
            let x = lo[0] + shift + t * i as f64;
            if x > hi[0] || near(x, y) {
                continue;
            }
            new.push(Point2::new(x, y));
        }
    }
    pts.extend(new);
}

fn segment_distance2(p: [f64; 2], a: Point2<f64>, b: Point2<f64>) -> f64 {
    let (abx, aby) = (b.x - a.x, b.y - a.y);
    let (apx, apy) = (p[0] - a.x, p[1] - a.y);
    let l2 = abx * abx + aby * aby;
    let s = if l2 > 0.0 {
        ((apx * abx + apy * aby) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let (dx, dy) = (apx - s * abx, apy - s * aby);
    dx * dx + dy * dy
}

/// Tessellates the box with a hole, the two cylinders or the fillet-chamfer-cone block.
pub(super) fn mesh_trimmed(shape: &Shape, model: &Model, target: f64) -> Result<Raw> {
    let mut net = Net::new(model, target)?;
    match *shape {
        Shape::BoxWithHole { size, hole_radius } => box_with_hole(&mut net, size, hole_radius)?,
        Shape::TwoCylinders {
            radius_a,
            half_length_a,
            radius_b,
            half_length_b,
        } => two_cylinders(&mut net, radius_a, half_length_a, radius_b, half_length_b)?,
        Shape::FilletChamferCone {
            length,
            width,
            height,
            fillet_radius,
            chamfer,
            cone_base_radius,
            cone_top_radius,
            cone_height,
        } => fillet_chamfer_cone(
            &mut net,
            [length, width, height],
            fillet_radius,
            chamfer,
            [cone_base_radius, cone_top_radius, cone_height],
        )?,
        _ => {
            return Err(Error::InvalidInput(format!(
                "synthetic mesh: {} is not a trimmed-patch shape",
                shape.name()
            )))
        }
    }
    Ok(net.raw)
}

fn unit(k: usize, s: f64) -> Point3 {
    let mut v = [0.0; 3];
    v[k] = s;
    v
}

/// Box faces: patch `2k + (s > 0)` for the face at `s · h[k]` on axis k; patch 6 the hole.
fn box_with_hole(net: &mut Net, size: [f64; 3], r: f64) -> Result<()> {
    let h = scale(size, 0.5);
    let face = |k: usize, s: f64| (2 * k + usize::from(s > 0.0)) as u32;
    let signs = [-1.0, 1.0];
    let mut corner = HashMap::new();
    for (a, &sx) in signs.iter().enumerate() {
        for (b, &sy) in signs.iter().enumerate() {
            for (c, &sz) in signs.iter().enumerate() {
                let v = net.vertex([sx * h[0], sy * h[1], sz * h[2]], face(0, sx))?;
                corner.insert([a, b, c], v);
            }
        }
    }
    let at = |key: [usize; 3]| corner[&key];
    // The 12 edges: along axis k, at the other two axes' sides.
    for k in 0..3 {
        for (a, &sa) in signs.iter().enumerate() {
            for b in 0..2 {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                let mut lo = [0; 3];
                lo[i] = a;
                lo[j] = b;
                let mut hi = lo;
                hi[k] = 1;
                net.segment(at(lo), at(hi), face(i, sa))?;
            }
        }
    }
    // Hole circles (starting on the hole's seam at +x) and the seam.
    let hz = h[2];
    let bottom = net.circle([0.0, 0.0, -hz], unit(0, 1.0), unit(1, 1.0), r, 0.0, 4)?;
    let top = net.circle([0.0, 0.0, hz], unit(0, 1.0), unit(1, 1.0), r, 0.0, 5)?;
    net.segment(bottom[0], top[0], 6)?;
    for k in 0..3 {
        let (i, j) = ((k + 1) % 3, (k + 2) % 3);
        for (side, &s) in signs.iter().enumerate() {
            let key = |a: usize, b: usize| {
                let mut key = [0; 3];
                key[k] = side;
                key[i] = a;
                key[j] = b;
                key
            };
            let outer =
                net.loop_through(&[at(key(0, 0)), at(key(1, 0)), at(key(1, 1)), at(key(0, 1))])?;
            let mut loops = vec![outer];
            if k == 2 {
                let hole = if side == 0 { &bottom } else { &top };
                loops.push(closed_loop(hole)?);
            }
            net.patch(face(k, s), &loops)?;
        }
    }
    let seam = net.between(bottom[0], top[0])?;
    let rev = |c: &[u32]| c.iter().rev().copied().collect::<Vec<_>>();
    let outer = join(&[bottom.clone(), seam.clone(), rev(&top), rev(&seam)])?;
    net.patch(6, &[outer])
}

/// Patches (see `shapes.rs`): 0 A's side, 1 / 2 A's caps at z = ∓ha, 3 / 4 B's sides at x < 0 /
/// x > 0, 5 / 6 B's caps at x = ∓hb.
fn two_cylinders(net: &mut Net, ra: f64, ha: f64, rb: f64, hb: f64) -> Result<()> {
    // A's seam at +y, far from both intersection curves.
    net.maps[0] = net.maps[0].seam_at(FRAC_PI_2);
    let (x, y, z) = (unit(0, 1.0), unit(1, 1.0), unit(2, 1.0));
    let rev = |c: &[u32]| c.iter().rev().copied().collect::<Vec<_>>();
    let mut a_caps = Vec::new();
    for (i, s) in [-1.0, 1.0].into_iter().enumerate() {
        a_caps.push(net.circle([0.0, 0.0, s * ha], x, y, ra, FRAC_PI_2, 1 + i as u32)?);
    }
    net.segment(a_caps[0][0], a_caps[1][0], 0)?;
    let a_seam = net.between(a_caps[0][0], a_caps[1][0])?;
    // Intersection curves (s x(φ), rb cos φ, rb sin φ): vertices of the exact polyline,
    // spread evenly by arc length, starting at φ = 0 (B's seam at +y).
    let x_int = |phi: f64| (ra * ra - rb * rb * phi.cos().powi(2)).sqrt();
    let n_poly = INTERSECTION_POINTS;
    let curve = |s: f64, i: usize| {
        let phi = TAU * i as f64 / n_poly as f64;
        [s * x_int(phi), rb * phi.cos(), rb * phi.sin()]
    };
    let mut cum = Vec::with_capacity(n_poly + 1);
    cum.push(0.0);
    for i in 0..n_poly {
        let l = cum[i] + dist(curve(1.0, i), curve(1.0, (i + 1) % n_poly));
        cum.push(l);
    }
    let total = cum[n_poly];
    let n = arc_steps(1.0, TAU, 1.0).max(steps(total, net.target));
    let mut picks: Vec<usize> = Vec::with_capacity(n);
    for k in 0..n {
        let want = total * k as f64 / n as f64;
        let i = cum.partition_point(|&c| c < want).min(n_poly - 1);
        let i = if i > 0 && want - cum[i - 1] < cum[i] - want {
            i - 1
        } else {
            i
        };
        if picks.last().is_none_or(|&l| i > l) {
            picks.push(i);
        }
    }
    let mut b_caps = Vec::new();
    for (i, s) in [-1.0, 1.0].into_iter().enumerate() {
        let side = 3 + i as u32;
        let mut c = Vec::with_capacity(picks.len() + 1);
        for &k in &picks {
            c.push(net.vertex(curve(s, k), side)?);
        }
        c.push(c[0]);
        let cap = net.circle([s * hb, 0.0, 0.0], y, z, rb, 0.0, 5 + i as u32)?;
        net.segment(c[0], cap[0], side)?;
        let seam = net.between(c[0], cap[0])?;
        let outer = join(&[c.clone(), seam.clone(), rev(&cap), rev(&seam)])?;
        net.patch(side, &[outer])?;
        net.patch(5 + i as u32, &[closed_loop(&cap)?])?;
        b_caps.push(c);
    }
    let outer = join(&[
        a_caps[0].clone(),
        a_seam.clone(),
        rev(&a_caps[1]),
        rev(&a_seam),
    ])?;
    net.patch(
        0,
        &[outer, closed_loop(&b_caps[0])?, closed_loop(&b_caps[1])?],
    )?;
    for (i, cap) in a_caps.into_iter().enumerate() {
        net.patch(1 + i as u32, &[closed_loop(&cap)?])?;
    }
    Ok(())
}

/// Patches (see `shapes.rs`): 0 bottom, 1 top (minus the cone base), 2 side y = +w, 3 side
/// y = -w, 4 / 5 ends x = ∓l, 6 fillet, 7 chamfer, 8 cone frustum, 9 cone top.
fn fillet_chamfer_cone(
    net: &mut Net,
    [length, width, height]: [f64; 3],
    rf: f64,
    cf: f64,
    [rb, rt, hc]: [f64; 3],
) -> Result<()> {
    let (l, w, hh) = (length / 2.0, width / 2.0, height);
    let yc = (cf - rf) / 2.0;
    let (y, z) = (unit(1, 1.0), unit(2, 1.0));
    // Corners per end x = ∓l: bottom at -w / +w, P1 side / fillet, P2 fillet / top,
    // P3 top / chamfer, P4 chamfer / side.
    struct End {
        b_minus: u32,
        b_plus: u32,
        p: [u32; 4],
    }
    let mut ends = Vec::new();
    for (i, s) in [-1.0, 1.0].into_iter().enumerate() {
        let x = s * l;
        let e = 4 + i as u32;
        ends.push(End {
            b_minus: net.vertex([x, -w, 0.0], e)?,
            b_plus: net.vertex([x, w, 0.0], e)?,
            p: [
                net.vertex([x, w, hh - rf], e)?,
                net.vertex([x, w - rf, hh], e)?,
                net.vertex([x, -w + cf, hh], e)?,
                net.vertex([x, -w, hh - cf], e)?,
            ],
        });
    }
    for (i, e) in ends.iter().enumerate() {
        let x = if i == 0 { -l } else { l };
        let face = 4 + i as u32;
        net.segment(e.b_minus, e.b_plus, face)?;
        net.segment(e.b_plus, e.p[0], face)?;
        net.arc(
            e.p[0],
            e.p[1],
            [x, w - rf, hh - rf],
            y,
            z,
            rf,
            0.0,
            FRAC_PI_2,
            face,
        )?;
        net.segment(e.p[1], e.p[2], face)?;
        net.segment(e.p[2], e.p[3], face)?;
        net.segment(e.p[3], e.b_minus, face)?;
    }
    let (e0, e1) = (&ends[0], &ends[1]);
    net.segment(e0.b_minus, e1.b_minus, 0)?;
    net.segment(e0.b_plus, e1.b_plus, 0)?;
    for k in 0..4 {
        // P1: side/fillet, P2: fillet/top, P3: top/chamfer, P4: chamfer/side.
        let owner = [2, 1, 1, 3][k];
        net.segment(e0.p[k], e1.p[k], owner)?;
    }
    // Cone circles, starting on the cone's seam (θ = 0, along the domain's e1).
    let (cone_e1, cone_e2) = match net.map(8)? {
        Map::Cone { e1, e2, .. } => (e1, e2),
        _ => {
            return Err(Error::InvalidInput(
                "synthetic mesh: patch 8 is not a cone".into(),
            ))
        }
    };
    let base = net.circle([0.0, yc, hh], cone_e1, cone_e2, rb, 0.0, 1)?;
    let top = net.circle([0.0, yc, hh + hc], cone_e1, cone_e2, rt, 0.0, 9)?;
    net.segment(base[0], top[0], 8)?;
    let seam = net.between(base[0], top[0])?;
    let rev = |c: &[u32]| c.iter().rev().copied().collect::<Vec<_>>();

    let lp = |net: &Net, c: &[u32]| net.loop_through(c);
    let bottom = lp(net, &[e0.b_minus, e1.b_minus, e1.b_plus, e0.b_plus])?;
    net.patch(0, &[bottom])?;
    let top_face = lp(net, &[e0.p[2], e1.p[2], e1.p[1], e0.p[1]])?;
    net.patch(1, &[top_face, closed_loop(&base)?])?;
    let side_plus = lp(net, &[e0.b_plus, e1.b_plus, e1.p[0], e0.p[0]])?;
    net.patch(2, &[side_plus])?;
    let side_minus = lp(net, &[e0.b_minus, e1.b_minus, e1.p[3], e0.p[3]])?;
    net.patch(3, &[side_minus])?;
    for (i, e) in ends.iter().enumerate() {
        let outer = lp(net, &[e.b_minus, e.b_plus, e.p[0], e.p[1], e.p[2], e.p[3]])?;
        net.patch(4 + i as u32, &[outer])?;
    }
    let fillet = lp(net, &[e0.p[0], e1.p[0], e1.p[1], e0.p[1]])?;
    net.patch(6, &[fillet])?;
    let chamfer = lp(net, &[e0.p[3], e1.p[3], e1.p[2], e0.p[2]])?;
    net.patch(7, &[chamfer])?;
    let cone = join(&[base.clone(), seam.clone(), rev(&top), rev(&seam)])?;
    net.patch(8, &[cone])?;
    net.patch(9, &[closed_loop(&top)?])?;
    Ok(())
}
