//! Recognition of fillet surfaces, linear extrusion surfaces and surfaces of revolution among
//! the extracted surfaces (mizoguchi section 6, Fig. 5).
//!
//! - **Fillets** (Fig. 5): a cylinder adjacent to two planes whose normals are both orthogonal
//!   to its axis and not parallel to each other; a torus adjacent to a cylinder and a plane with
//!   `n_p ∥ d_t ∥ d_c`, or to a sphere and a plane with the sphere's centre on the torus axis
//!   and `n_p ∥ d_t`; a sphere or torus adjacent to three cylinder-type fillets. Besides the
//!   paper's direction conditions, a cylinder fillet must be tangent to its two planes (axis
//!   at distance `r` from each, within `position_tol`): two planes meeting a cylinder at
//!   right angles (a hole through a plate) satisfy the directions but are no fillet.
//! - **Linear extrusions**: topologically connected planes and cylinders with every plane
//!   normal orthogonal to a common direction and every cylinder axis parallel to it, with at
//!   least three planes (their normals then coplanar) or two cylinders. The candidate directions
//!   are the cylinders' axes and the cross products of adjacent planes' normals; the largest
//!   group is taken first, then the largest among the remaining surfaces, and so on.
//! - **Surfaces of revolution**: topologically connected planes (normal parallel to the axis),
//!   cylinders, cones and tori (axis parallel and on the same line) and spheres (centre on the
//!   line), at least two surfaces. Candidate axes: those of the cylinders, cones and tori in
//!   surface order; a surface joins at most one revolution.
//!
//! Angles are compared with `angle_tol` (default 2°), positions with `position_tol` (default one
//! mean edge length). The paper gives no tolerances.

use serde::Serialize;

use crate::geometry::vec3::{cross, dot, line_distance, norm, normalize};
use crate::geometry::Point3;
use crate::geometry::{SurfaceParams, SurfaceType};

use super::SegmentSurface;

/// Kind of a recognised group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GroupKind {
    /// A fillet: `surfaces[0]` is the fillet, the others the surfaces it blends.
    Fillet,
    /// A linear extrusion surface.
    Extrusion,
    /// A surface of revolution.
    Revolution,
}

/// A recognised higher-level surface.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Group {
    /// Kind.
    pub kind: GroupKind,
    /// Member surface ids (for a fillet: the fillet first, then the surfaces it blends).
    pub surfaces: Vec<u32>,
    /// Extrusion direction or revolution axis direction (fillets: the fillet's axis, zero for a
    /// sphere).
    pub direction: Point3,
    /// A point on the revolution axis (other kinds: zero).
    pub point: Point3,
}

/// The axis as (direction, point).
fn axis_of(s: &SurfaceParams) -> Option<(Point3, Point3)> {
    s.axis().map(|(p, d)| (d, p))
}

fn plane_of(s: &SurfaceParams) -> Option<(Point3, f64)> {
    match *s {
        SurfaceParams::Plane { normal, offset } => Some((normal, offset)),
        _ => None,
    }
}

/// The most surfaces [`recognize`] groups. A part has a few dozen to a few hundred surfaces; a
/// segmentation of thousands is fragmented (a noisy mesh whose regions are single triangles),
/// its groups mean nothing, and the extrusion search, quadratic in the surfaces, would take
/// hours on it (a noisy 1M-triangle mesh: 50k planes).
pub const MAX_RECOGNIZED_SURFACES: usize = 2000;

/// Recognises fillets, extrusions and revolutions among `surfaces` (their `neighbours` give
/// the adjacency); none beyond [`MAX_RECOGNIZED_SURFACES`] surfaces (with a warning).
/// Deterministic: surfaces are visited in id order.
pub fn recognize(surfaces: &[SegmentSurface], angle_tol: f64, position_tol: f64) -> Vec<Group> {
    if surfaces.len() > MAX_RECOGNIZED_SURFACES {
        tracing::warn!(
            "{} surfaces: the segmentation is fragmented; fillets, extrusions and revolutions \
             are not looked for beyond {MAX_RECOGNIZED_SURFACES}",
            surfaces.len()
        );
        return Vec::new();
    }
    let parallel = |a: Point3, b: Point3| dot(a, b).abs() > angle_tol.cos();
    let orthogonal = |a: Point3, b: Point3| dot(a, b).abs() < angle_tol.sin();
    let mut groups = Vec::new();
    let is_fillet_cyl = |s: &SegmentSurface| -> Option<Vec<u32>> {
        let SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            radius,
        } = s.params
        else {
            return None;
        };
        let planes: Vec<(u32, Point3)> = s
            .neighbours
            .iter()
            .filter_map(|&n| {
                let (normal, offset) = plane_of(&surfaces[n as usize].params)?;
                let tangent = ((dot(normal, axis_point) - offset).abs() - radius).abs();
                (orthogonal(normal, axis_dir) && tangent < position_tol).then_some((n, normal))
            })
            .collect();
        for (i, a) in planes.iter().enumerate() {
            for b in &planes[i + 1..] {
                if !parallel(a.1, b.1) {
                    return Some(vec![a.0, b.0]);
                }
            }
        }
        None
    };
    let fillet_cyls: Vec<Option<Vec<u32>>> = surfaces.iter().map(is_fillet_cyl).collect();
    for (i, s) in surfaces.iter().enumerate() {
        let id = i as u32;
        match s.kind {
            SurfaceType::Cylinder => {
                if let (Some(p), SurfaceParams::Cylinder { axis_dir, .. }) =
                    (&fillet_cyls[i], s.params)
                {
                    groups.push(Group {
                        kind: GroupKind::Fillet,
                        surfaces: [vec![id], p.clone()].concat(),
                        direction: axis_dir,
                        point: [0.0; 3],
                    });
                }
            }
            SurfaceType::Torus | SurfaceType::Sphere => {
                // Between three cylinder-type fillets.
                let fil: Vec<u32> = s
                    .neighbours
                    .iter()
                    .copied()
                    .filter(|&n| fillet_cyls[n as usize].is_some())
                    .collect();
                if fil.len() >= 3 {
                    groups.push(Group {
                        kind: GroupKind::Fillet,
                        surfaces: [vec![id], fil].concat(),
                        direction: axis_of(&s.params).map_or([0.0; 3], |a| a.0),
                        point: [0.0; 3],
                    });
                    continue;
                }
                let Some((dt, ct)) = axis_of(&s.params) else {
                    continue;
                };
                // Torus between a cylinder or a sphere and a plane.
                let plane = s.neighbours.iter().copied().find(|&n| {
                    plane_of(&surfaces[n as usize].params).is_some_and(|(np, _)| parallel(np, dt))
                });
                let other =
                    s.neighbours
                        .iter()
                        .copied()
                        .find(|&n| match surfaces[n as usize].params {
                            SurfaceParams::Cylinder { axis_dir, .. } => parallel(axis_dir, dt),
                            SurfaceParams::Sphere { center, .. } => {
                                line_distance(center, ct, dt) < position_tol
                            }
                            _ => false,
                        });
                if let (Some(p), Some(o)) = (plane, other) {
                    groups.push(Group {
                        kind: GroupKind::Fillet,
                        surfaces: vec![id, o, p],
                        direction: dt,
                        point: [0.0; 3],
                    });
                }
            }
            _ => {}
        }
    }
    // Linear extrusions.
    let mut used = vec![false; surfaces.len()];
    let fits_dir = |s: &SegmentSurface, d: Point3| match s.params {
        SurfaceParams::Plane { normal, .. } => orthogonal(normal, d),
        SurfaceParams::Cylinder { axis_dir, .. } => parallel(axis_dir, d),
        _ => false,
    };
    let mut candidates: Vec<Point3> = Vec::new();
    for s in surfaces {
        match s.params {
            SurfaceParams::Cylinder { axis_dir, .. } => candidates.push(axis_dir),
            SurfaceParams::Plane { normal, .. } => {
                for &n in &s.neighbours {
                    if let Some((n2, _)) = plane_of(&surfaces[n as usize].params) {
                        if let Some(d) = normalize(cross(normal, n2)) {
                            if norm(cross(normal, n2)) > angle_tol.sin() {
                                candidates.push(d);
                            }
                        }
                    }
                }
            }
            _ => {}
        }
    }
    // Greedy: the direction whose group is largest first, then the next among the rest.
    loop {
        let mut best: (Vec<u32>, Point3) = (Vec::new(), [0.0; 3]);
        for &d in &candidates {
            let mut seen = vec![false; surfaces.len()];
            for s0 in 0..surfaces.len() {
                if seen[s0] || used[s0] || !fits_dir(&surfaces[s0], d) {
                    continue;
                }
                let comp = component(surfaces, s0, &mut seen, |j| {
                    !used[j] && fits_dir(&surfaces[j], d)
                });
                let planes = comp
                    .iter()
                    .filter(|&&j| surfaces[j as usize].kind == SurfaceType::Plane)
                    .count();
                let cyls = comp.len() - planes;
                if (planes >= 3 || cyls >= 2) && comp.len() > best.0.len() {
                    best = (comp, d);
                }
            }
        }
        if best.0.is_empty() {
            break;
        }
        for &j in &best.0 {
            used[j as usize] = true;
        }
        groups.push(Group {
            kind: GroupKind::Extrusion,
            surfaces: best.0,
            direction: best.1,
            point: [0.0; 3],
        });
    }
    // Surfaces of revolution.
    let mut used = vec![false; surfaces.len()];
    for i in 0..surfaces.len() {
        let Some((d, q)) = axis_of(&surfaces[i].params) else {
            continue;
        };
        if used[i] {
            continue;
        }
        let fits = |j: usize| -> bool {
            let s = &surfaces[j];
            match s.params {
                SurfaceParams::Plane { normal, .. } => parallel(normal, d),
                SurfaceParams::Sphere { center, .. } => line_distance(center, q, d) < position_tol,
                _ => axis_of(&s.params).is_some_and(|(d2, q2)| {
                    parallel(d2, d) && line_distance(q2, q, d) < position_tol
                }),
            }
        };
        let mut seen = vec![false; surfaces.len()];
        let comp = component(surfaces, i, &mut seen, |j| !used[j] && fits(j));
        if comp.len() >= 2 {
            for &j in &comp {
                used[j as usize] = true;
            }
            groups.push(Group {
                kind: GroupKind::Revolution,
                surfaces: comp,
                direction: d,
                point: q,
            });
        }
    }
    groups
}

/// The connected set (through `neighbours`) of surfaces accepted by `ok`, from `start`;
/// sorted ids.
fn component(
    surfaces: &[SegmentSurface],
    start: usize,
    seen: &mut [bool],
    ok: impl Fn(usize) -> bool,
) -> Vec<u32> {
    let mut out = vec![start as u32];
    seen[start] = true;
    let mut head = 0;
    while head < out.len() {
        let u = out[head] as usize;
        head += 1;
        for &n in &surfaces[u].neighbours {
            let ni = n as usize;
            if !seen[ni] && ok(ni) {
                seen[ni] = true;
                out.push(n);
            }
        }
    }
    out.sort_unstable();
    out
}
