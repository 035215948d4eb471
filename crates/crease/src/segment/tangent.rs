//! Fillets made tangent to the planes they round (not in the paper; issue 29).
//!
//! Under noise the planes beside a fillet take the first part of its arc on each side: past a
//! tangent border a point leaves the plane by only `r (1 − cos θ)`, within the widened
//! tolerance of equation 4 for tens of degrees. The fillet's region is then the middle of its
//! arc, and a free cylinder fitted to it comes out too thin (the rounded cube's fillets of
//! radius 0.1 came out 0.081–0.084 at σ = 0.5 spacings), which no reassignment of the border
//! points repairs: they lie nearer the plane than the thin cylinder. A designer's fillet is
//! tangent to both its planes, and that leaves one unknown: the radius. So:
//! - a **cylinder** whose axis is within [`AXIS_DEGREES`] of perpendicular to the normals of
//!   two adjacent, non-parallel planes has its axis made their intersection's direction and
//!   its axis line put at distance `r` from both, on its side of each;
//! - a **sphere** adjacent to three planes of independent normals (a rounded corner) has its
//!   centre put at distance `r` from all three;
//!
//! - a **plane** strip between two adjacent planes that both turn from it by more than
//!   [`PARALLEL_DEGREES`], running along their edge (its normal within [`AXIS_DEGREES`] of
//!   perpendicular to the edge), is the middle of a fillet's arc when the planes took its
//!   flanks: a 45° strip of the rounded cube's fillets leaves its chord by 0.0076 at radius
//!   0.1, within noise of half a spacing (0.0055 at 50k points), so the seed's model
//!   selection took the plane. It becomes the cylinder tangent to both (radius started from
//!   its centroid's depth below them, `r (1 − cos φ/2)` at the middle of an arc turning by φ);
//!
//! and `r` is fitted to the region's points (Gauss–Newton in one unknown, from the free fit's
//! radius). The tangent surface replaces the free one when its RMS distance is within
//! `MERGE_SLACK` of the larger of the free fit's and the noise, a plane only when the tangent
//! cylinder's RMS distance is below the plane's (a chamfer keeps its plane: a cylinder tangent
//! to both its planes leaves it by far more than the noise); the border refinement then gives
//! it back the flanks of its arc, and the fit is repeated on the region it grew to. Measured
//! on `crease synth rounded-cube -n 50000 --noise 0.5` with estimated normals: 7 cylinders
//! and 11 planes (5 of them fillet strips) before, the 12 cylinders and 6 planes after (radii
//! 0.102–0.105 for 0.1; the 8 corner spheres are still not found).

use rayon::prelude::*;

use super::fit::Fit;
use super::grow::{Ctx, Region};
use super::merge::{contacts, Part, MERGE_SLACK};
use crate::geometry::vec3::{cross, dot, normalize, scale};
use crate::geometry::{Point3, SurfaceParams, SurfaceType};
use crate::spatial::Adjacency;

/// A cylinder's axis this close (degrees) to perpendicular to two planes' normals is taken to
/// round their edge.
const AXIS_DEGREES: f64 = 10.0;

/// Planes whose normals are this close (degrees) to parallel bound no fillet between them.
const PARALLEL_DEGREES: f64 = 10.0;

/// The planes a fillet is tangent to: (normal, offset, side), `side` the sign `s` with which
/// the centre satisfies `n · c = offset − s r`.
pub(super) type Tangent = (Point3, f64, f64);

/// Solves the 3 × 3 system with rows `m` for `rhs` (Cramer), if it is well conditioned.
pub(super) fn solve3(m: [Point3; 3], rhs: Point3) -> Option<Point3> {
    let det = dot(m[0], cross(m[1], m[2]));
    if det.abs() < 1e-6 {
        return None;
    }
    let c = [cross(m[1], m[2]), cross(m[2], m[0]), cross(m[0], m[1])];
    // x = (rhs0 c0 + rhs1 c1 + rhs2 c2) / det: the columns of the inverse are the cofactors.
    Some([0, 1, 2].map(|k| (rhs[0] * c[0][k] + rhs[1] * c[1][k] + rhs[2] * c[2][k]) / det))
}

/// The surface of the family at radius `r`: a cylinder of axis `d` (rows: two planes and the
/// axis, whose component `along` is kept), or a sphere (rows: three planes).
fn at_radius(planes: &[Tangent], axis: Option<(Point3, f64)>, r: f64) -> Option<SurfaceParams> {
    let rhs = |i: usize| planes[i].1 - planes[i].2 * r;
    match axis {
        Some((d, along)) => {
            let c = solve3([planes[0].0, planes[1].0, d], [rhs(0), rhs(1), along])?;
            Some(SurfaceParams::Cylinder {
                axis_point: c,
                axis_dir: d,
                radius: r,
            })
        }
        None => {
            let c = solve3(
                [planes[0].0, planes[1].0, planes[2].0],
                [rhs(0), rhs(1), rhs(2)],
            )?;
            Some(SurfaceParams::Sphere {
                center: c,
                radius: r,
            })
        }
    }
}

/// Weighted residuals of `part` to `s` (orthogonal distances).
fn residuals(part: &Part, s: &SurfaceParams) -> Vec<f64> {
    part.pts
        .iter()
        .map(|&p| crate::geometry::surface::signed_distance(s, p))
        .collect()
}

/// Gauss–Newton in `r` from `r0`: the tangent surface that fits `part` best, and its RMS.
pub(super) fn fit_radius(
    part: &Part,
    planes: &[Tangent],
    axis: Option<(Point3, f64)>,
    r0: f64,
) -> Option<(SurfaceParams, f64)> {
    let wsum: f64 = part.w.iter().sum();
    if wsum <= 0.0 || r0 <= 0.0 {
        return None;
    }
    let mut r = r0;
    for _ in 0..30 {
        let h = 1e-6 * r;
        let s0 = at_radius(planes, axis, r)?;
        let (sp, sm) = (
            at_radius(planes, axis, r + h)?,
            at_radius(planes, axis, r - h)?,
        );
        let (g, gp, gm) = (
            residuals(part, &s0),
            residuals(part, &sp),
            residuals(part, &sm),
        );
        let (mut jtj, mut jtg) = (0.0, 0.0);
        for i in 0..g.len() {
            let j = (gp[i] - gm[i]) / (2.0 * h);
            jtj += part.w[i] * j * j;
            jtg += part.w[i] * j * g[i];
        }
        if jtj <= 0.0 {
            return None;
        }
        // Steps of at most half the radius keep it positive.
        let step = (-jtg / jtj).clamp(-0.5 * r, 0.5 * r);
        r += step;
        if step.abs() <= 1e-10 * r {
            break;
        }
    }
    let s = at_radius(planes, axis, r)?;
    let g = residuals(part, &s);
    let ss: f64 = g.iter().zip(&part.w).map(|(d, w)| w * d * d).sum();
    (r > 0.0 && r.is_finite()).then(|| (s, (ss / wsum).sqrt()))
}

/// The tangent version of region `r`'s surface, if its planes are found and it explains the
/// region within the noise.
fn tangent_fit<G: Adjacency>(
    ctx: &Ctx<G>,
    regions: &[Region],
    i: usize,
    neighbours: &[u32],
    sigma: f64,
    floor: f64,
) -> Option<Fit> {
    let r = &regions[i];
    let mut planes: Vec<(usize, Point3, f64)> = neighbours
        .iter()
        .filter_map(|&j| match regions[j as usize].fit.params {
            SurfaceParams::Plane { normal, offset } => {
                Some((regions[j as usize].vertices.len(), normal, offset))
            }
            _ => None,
        })
        .collect();
    // Largest first (ties: neighbour order, which is by id).
    planes.sort_by_key(|p| std::cmp::Reverse(p.0));
    let parallel = PARALLEL_DEGREES.to_radians().cos();
    let side = |n: Point3, o: f64, c: Point3| if dot(n, c) < o { 1.0 } else { -1.0 };
    let part = Part::of(ctx, &r.vertices);
    let (want, axis, centre, r0) = match r.fit.params {
        SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            radius,
        } => {
            let across = AXIS_DEGREES.to_radians().sin();
            planes.retain(|p| dot(p.1, axis_dir).abs() < across);
            (2, Some(axis_dir), axis_point, radius)
        }
        SurfaceParams::Sphere { center, radius } => (3, None, center, radius),
        // A strip between two planes, turned from both: the middle of a fillet's arc.
        SurfaceParams::Plane { normal, .. } => {
            planes.retain(|p| dot(p.1, normal).abs() < parallel);
            let centroid = part.centroid()?;
            (2, Some(normal), centroid, 0.0)
        }
        _ => return None,
    };
    // The first `want` planes of independent normals.
    let mut chosen: Vec<Tangent> = Vec::new();
    for &(_, n, o) in &planes {
        if chosen.len() == want {
            break;
        }
        if chosen.iter().all(|c| dot(c.0, n).abs() < parallel) {
            if want == 3 && chosen.len() == 2 {
                let det = dot(chosen[0].0, cross(chosen[1].0, n));
                if det.abs() < 0.1 {
                    continue;
                }
            }
            chosen.push((n, o, side(n, o, centre)));
        }
    }
    if chosen.len() < want {
        return None;
    }
    let strip = matches!(r.fit.params, SurfaceParams::Plane { .. });
    let (axis, r0) = match axis {
        Some(old) => {
            let d = normalize(cross(chosen[0].0, chosen[1].0))?;
            if strip {
                // The strip runs along the edge of the two planes (its normal `old` across the
                // edge's direction); its centroid lies about `r (1 − cos φ/2)` from both, φ the
                // angle the arc turns through.
                if dot(d, old).abs() > AXIS_DEGREES.to_radians().sin() {
                    return None;
                }
                let turn = dot(chosen[0].0, chosen[1].0).clamp(-1.0, 1.0).acos();
                let depth = chosen
                    .iter()
                    .map(|&(n, o, _)| (dot(n, centre) - o).abs())
                    .sum::<f64>()
                    / 2.0;
                (
                    Some((d, dot(d, centre))),
                    depth / (1.0 - (turn / 2.0).cos()),
                )
            } else {
                let d = if dot(d, old) < 0.0 { scale(d, -1.0) } else { d };
                (Some((d, dot(d, centre))), r0)
            }
        }
        None => (None, r0),
    };
    let (free, _) = part.score(ctx, &r.fit.params);
    let (s, rms) = fit_radius(&part, &chosen, axis, r0)?;
    // The centre must stay on the side of each plane it was fitted on (a fillet, not a bead).
    let centre_now = match s {
        SurfaceParams::Cylinder { axis_point, .. } => axis_point,
        SurfaceParams::Sphere { center, .. } => center,
        _ => return None,
    };
    if chosen
        .iter()
        .any(|&(n, o, sd)| side(n, o, centre_now) != sd)
    {
        return None;
    }
    // A plane becomes a cylinder only when the cylinder explains the strip better (a chamfer
    // keeps its plane); a free cylinder or sphere takes the tangent one within the noise.
    let bound = if strip {
        free
    } else {
        MERGE_SLACK * free.max(sigma) + floor
    };
    (rms <= bound).then_some(Fit { params: s, rms })
}

/// Makes the cylinders and spheres of `regions` that round the edges and corners of planes
/// tangent to them (see the module documentation); returns whether any changed.
pub(crate) fn tangent_fillets<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &[i32],
    regions: &mut [Region],
    sigma: f64,
    floor: f64,
) -> bool {
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); regions.len()];
    for (a, b) in contacts(ctx, owner) {
        neighbours[a as usize].push(b);
        neighbours[b as usize].push(a);
    }
    for n in &mut neighbours {
        n.sort_unstable();
    }
    let fits: Vec<Option<Fit>> = (0..regions.len())
        .into_par_iter()
        .map(|i| match regions[i].kind {
            SurfaceType::Cylinder | SurfaceType::Sphere | SurfaceType::Plane => {
                tangent_fit(ctx, regions, i, &neighbours[i], sigma, floor)
            }
            _ => None,
        })
        .collect();
    let mut any = false;
    for (r, f) in regions.iter_mut().zip(fits) {
        if let Some(f) = f {
            any |= f != r.fit;
            r.fit = f;
            r.kind = f.params.kind();
        }
    }
    any
}
