//! Snapping: relations the data cannot tell from exact ones made exact before the B-rep is
//! built, within the measured noise, each one reported.
//!
//! A noisy fit leaves a hole's axis a degree off its plate's normal; the B-rep would then meet
//! the plate in an ellipse-like B-spline where the designer drew a circle, and the kernel sees
//! a slanted hole. For every pair of adjacent faces:
//! - a surface of revolution (cylinder, cone, torus) and a plane whose normal is within the
//!   angle tolerance of its axis: the axis is made the normal (the circle of a hole in a plate,
//!   of a boss's top);
//! - a cylinder whose axis is within the tolerance of lying in an adjacent plane's direction:
//!   the axis is made parallel to the plane (the lines where a fillet or a slot meets a face);
//! - two surfaces of revolution with axes within the angle tolerance of each other and within
//!   the distance tolerance of each other where they meet (or a sphere whose centre is that
//!   close to the axis): both put on one axis, the larger face's (a stepped shaft, a fillet
//!   between coaxial cylinders, a ball end).
//!
//! - a fillet nearly touching its face (a cylinder or ball the radius from a plane, a ball in
//!   a cylinder of nearly its radius, a torus's tube nearly touching a plane or a coaxial
//!   cylinder): moved to touch it (`tangent`), so that the two meet in the line or circle the
//!   designer drew instead of in two close curves or not at all.
//!
//! Before those, across the whole part: a plane whose normal is within the angle tolerance of a
//! larger plane's is made parallel to it, and one within the tolerance of perpendicular to
//! larger ones is made perpendicular to them (its offset refitted to its vertices).
//!
//! Tolerances from the data: the distance tolerance is three times the larger RMS residual of
//! the two faces' points (and at least a millionth of the part's size: the precision of a
//! fit to exact samples is not its residual, and no designer's tolerance is finer), the angle tolerance
//! that distance over the smaller face's extent (the tilt a fit of that face cannot resolve).
//! Planes never move: their normals are the best-determined directions of a part. The rules
//! are applied in order, each surface snapped at most once per rule (but see tangency), larger faces first.

use serde::Serialize;

use crate::geometry::vec3::{add, dist, dot, line_distance, normalize, scale, sub};
use crate::geometry::{Point3, SurfaceParams};

/// One relation made exact.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Snap {
    /// What was made exact, in words.
    pub relation: String,
    /// The surface that moved (index into the segmentation's surfaces).
    pub surface: usize,
    /// The surface it was snapped to.
    pub to: usize,
    /// How far it was off: an angle in degrees, or a distance.
    pub off_by: f64,
}

/// What a face tells about the precision of its surface.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FaceStats {
    /// RMS distance of the face's mesh vertices to the surface.
    pub rms: f64,
    /// Largest distance between two of its vertices (approximately: the bounding-box diagonal).
    pub extent: f64,
    /// Area of the face.
    pub area: f64,
    /// Centroid of the face's vertices.
    pub centroid: Point3,
}

/// The surface with its axis moved to the line (`o`, `d`) (`d` unit, turned to agree with the
/// old axis's direction); the axis point is the old one's foot on the new line, so the surface
/// stays where its data is.
fn with_axis(s: &SurfaceParams, o: Point3, d: Point3) -> SurfaceParams {
    let Some((p, old)) = s.axis() else {
        return *s;
    };
    let d = if dot(d, old) < 0.0 { scale(d, -1.0) } else { d };
    let foot = add(o, scale(d, dot(sub(p, o), d)));
    match *s {
        SurfaceParams::Cylinder { radius, .. } => SurfaceParams::Cylinder {
            axis_point: foot,
            axis_dir: d,
            radius,
        },
        SurfaceParams::Cone { half_angle, .. } => SurfaceParams::Cone {
            apex: foot,
            axis_dir: d,
            half_angle,
        },
        SurfaceParams::Torus {
            major_radius,
            minor_radius,
            ..
        } => SurfaceParams::Torus {
            center: foot,
            axis_dir: d,
            major_radius,
            minor_radius,
        },
        other => other,
    }
}

fn degrees(cos: f64) -> f64 {
    cos.abs().min(1.0).acos().to_degrees()
}

/// Snaps `surfaces` (see the module documentation) given the adjacent pairs (sharing an
/// edge), the touching pairs (sharing an edge or a vertex) and each surface's face
/// statistics; returns what was snapped.
pub(crate) fn snap(
    surfaces: &mut [SurfaceParams],
    adjacent: &[(usize, usize)],
    touching: &[(usize, usize)],
    stats: &[FaceStats],
    size: f64,
) -> Vec<Snap> {
    let mut snaps = Vec::new();
    // No tolerance at all for a surface without a face (dissolved into its neighbours).
    let tolerances = |a: usize, b: usize| {
        let d = (3.0 * stats[a].rms.max(stats[b].rms)).max(1e-6 * size);
        let extent = stats[a].extent.min(stats[b].extent);
        if extent > 0.0 {
            (d, d / extent)
        } else {
            (0.0, 0.0)
        }
    };
    // Larger faces first.
    let mut pairs: Vec<(usize, usize)> = adjacent.to_vec();
    pairs.sort_by(|x, y| {
        let ax = stats[x.0].area.max(stats[x.1].area);
        let ay = stats[y.0].area.max(stats[y.1].area);
        ay.total_cmp(&ax).then(x.cmp(y))
    });
    // 0: planes made parallel to a larger plane whose normal is within the tolerance, or
    // perpendicular to the larger ones they nearly are perpendicular to.
    let mut planes: Vec<usize> = (0..surfaces.len())
        .filter(|&i| matches!(surfaces[i], SurfaceParams::Plane { .. }) && stats[i].area > 0.0)
        .collect();
    planes.sort_by(|&x, &y| stats[y].area.total_cmp(&stats[x].area).then(x.cmp(&y)));
    let mut directions: Vec<(Point3, usize)> = Vec::new();
    for &i in &planes {
        let SurfaceParams::Plane { normal, .. } = surfaces[i] else {
            continue;
        };
        let parallel = directions.iter().find(|&&(d, src)| {
            let off = degrees(dot(normal, d));
            off.to_radians() <= tolerances(i, src).1
        });
        let new = if let Some(&(d, src)) = parallel {
            let off = degrees(dot(normal, d));
            let d = if dot(normal, d) < 0.0 {
                scale(d, -1.0)
            } else {
                d
            };
            if off > 0.0 {
                snaps.push(Snap {
                    relation: format!("plane parallel to plane {src}"),
                    surface: i,
                    to: src,
                    off_by: off,
                });
            }
            d
        } else {
            let mut n = normal;
            for &(d, src) in &directions {
                let off = 90.0 - degrees(dot(n, d));
                if off > 0.0 && off.to_radians() <= tolerances(i, src).1 {
                    if let Some(m) = normalize(sub(n, scale(d, dot(n, d)))) {
                        n = m;
                        snaps.push(Snap {
                            relation: format!("plane perpendicular to plane {src}"),
                            surface: i,
                            to: src,
                            off_by: off,
                        });
                    }
                }
            }
            directions.push((n, i));
            n
        };
        if new != normal {
            surfaces[i] = SurfaceParams::Plane {
                normal: new,
                offset: dot(new, stats[i].centroid),
            };
        }
    }
    // 1 and 2: axes against planes (a cylinder's axis may be made parallel to several: a
    // fillet between two faces).
    let mut moved = vec![false; surfaces.len()];
    let mut parallel_to: Vec<Vec<Point3>> = vec![Vec::new(); surfaces.len()];
    for &(a, b) in &pairs {
        for (p, s) in [(a, b), (b, a)] {
            let SurfaceParams::Plane { normal, .. } = surfaces[p] else {
                continue;
            };
            let Some((o, d)) = surfaces[s].axis() else {
                continue;
            };
            if moved[s] && parallel_to[s].is_empty() {
                continue;
            }
            let (_, angle) = tolerances(p, s);
            let c = dot(d, normal);
            let off_parallel = degrees(c);
            let off_perpendicular = 90.0 - off_parallel;
            if off_parallel > 0.0 && off_parallel.to_radians() <= angle && !moved[s] {
                surfaces[s] = with_axis(&surfaces[s], o, normal);
                moved[s] = true;
                snaps.push(Snap {
                    relation: format!(
                        "{} axis along the normal of plane {p}",
                        surfaces[s].kind().name()
                    ),
                    surface: s,
                    to: p,
                    off_by: off_parallel,
                });
            } else if matches!(surfaces[s], SurfaceParams::Cylinder { .. })
                && off_perpendicular > 0.0
                && off_perpendicular.to_radians() <= angle
            {
                // Out of the new normal, and of those it was made parallel to before.
                let mut nd = sub(d, scale(normal, c));
                for &m in &parallel_to[s] {
                    nd = sub(nd, scale(m, dot(nd, m)));
                }
                if let Some(nd) = normalize(nd) {
                    surfaces[s] = with_axis(&surfaces[s], o, nd);
                    moved[s] = true;
                    parallel_to[s].push(normal);
                    snaps.push(Snap {
                        relation: format!("cylinder axis parallel to plane {p}"),
                        surface: s,
                        to: p,
                        off_by: off_perpendicular,
                    });
                }
            }
        }
    }
    // 3: coaxial surfaces of revolution (the larger face's axis kept).
    let mut moved = vec![false; surfaces.len()];
    for &(a, b) in &pairs {
        let (big, small) = if stats[a].area >= stats[b].area {
            (a, b)
        } else {
            (b, a)
        };
        if moved[small] || moved[big] {
            continue;
        }
        let (dtol, atol) = tolerances(big, small);
        match (surfaces[big].axis(), surfaces[small]) {
            (Some((o, d)), SurfaceParams::Sphere { center, radius }) => {
                let off = line_distance(center, o, d);
                if off > 0.0 && off <= dtol {
                    let foot = add(o, scale(d, dot(sub(center, o), d)));
                    surfaces[small] = SurfaceParams::Sphere {
                        center: foot,
                        radius,
                    };
                    moved[small] = true;
                    snaps.push(Snap {
                        relation: format!("sphere centre on the axis of surface {big}"),
                        surface: small,
                        to: big,
                        off_by: off,
                    });
                }
            }
            (Some((o, d)), s) => {
                let Some((os, ds)) = s.axis() else {
                    continue;
                };
                let off_angle = degrees(dot(d, ds));
                // Distance between the axes where the two faces meet.
                let m = scale(add(stats[big].centroid, stats[small].centroid), 0.5);
                let foot = |o: Point3, d: Point3| add(o, scale(d, dot(sub(m, o), d)));
                let off = dist(foot(o, d), foot(os, ds));
                let parallel = off_angle.to_radians() <= atol;
                if parallel && off <= dtol && (off_angle > 0.0 || off > 0.0) {
                    surfaces[small] = with_axis(&s, o, d);
                    moved[small] = true;
                    snaps.push(Snap {
                        relation: format!("{} coaxial with surface {big}", s.kind().name()),
                        surface: small,
                        to: big,
                        off_by: off_angle.max(off),
                    });
                }
            }
            _ => {}
        }
    }
    // 4: tangency (fillets and rounds), the surface of revolution or the ball moving, over
    // the surfaces that meet at an edge or at a vertex (a corner ball touches its faces in a
    // point). First the radii (a ball in its fillet takes the fillet's radius), then the
    // contacts with planes: a surface moved to touch a plane may be moved again to touch one
    // perpendicular to it (a fillet between two faces, a corner ball in three), which keeps
    // the first contact.
    let mut touching_pairs: Vec<(usize, usize)> = touching.to_vec();
    touching_pairs.sort_by(|x, y| {
        let ax = stats[x.0].area.max(stats[x.1].area);
        let ay = stats[y.0].area.max(stats[y.1].area);
        ay.total_cmp(&ax).then(x.cmp(y))
    });
    let mut resized = vec![false; surfaces.len()];
    let mut moved: Vec<Vec<Point3>> = vec![Vec::new(); surfaces.len()];
    for planes in [false, true] {
        for &(a, b) in &touching_pairs {
            for (p, s) in [(a, b), (b, a)] {
                let normal = match surfaces[p] {
                    SurfaceParams::Plane { normal, .. } => Some(normal),
                    _ => None,
                };
                if normal.is_some() != planes {
                    continue;
                }
                let free = match normal {
                    Some(n) => moved[s].iter().all(|m| dot(*m, n).abs() <= 1e-12),
                    None => !resized[s],
                };
                if !free {
                    continue;
                }
                let (dtol, _) = tolerances(p, s);
                let Some((relation, off, new)) = tangent(&surfaces[p], &surfaces[s]) else {
                    continue;
                };
                if off > 0.0 && off <= dtol {
                    surfaces[s] = new;
                    match normal {
                        Some(n) => moved[s].push(n),
                        None => resized[s] = true,
                    }
                    snaps.push(Snap {
                        relation: format!("{} {relation} {p}", surfaces[s].kind().name()),
                        surface: s,
                        to: p,
                        off_by: off,
                    });
                }
            }
        }
    }
    // Keep unit axes exact after the arithmetic.
    for s in surfaces.iter_mut() {
        if let Some((o, d)) = s.axis() {
            if let Some(u) = normalize(d) {
                *s = with_axis(s, o, u);
            }
        }
    }
    snaps
}

/// How far `s` is from touching `p` (a fillet from its face), and `s` moved to touch it:
/// - `p` a plane, `s` a cylinder with its axis parallel to the plane: the axis moved along
///   the normal to lie the radius from the plane;
/// - `p` a plane, `s` a sphere: the centre moved along the normal likewise;
/// - `p` a plane, `s` a torus whose axis is the plane's normal: the centre moved along the
///   axis to lie the tube radius from the plane;
/// - `p` a cylinder, `s` a sphere centred on its axis: the sphere given the cylinder's radius
///   (a corner ball in its fillets);
/// - `p` a cylinder, `s` a torus on its axis: the torus's major radius changed so that its
///   tube touches the cylinder from inside or outside.
///
/// None when the pair is not of those kinds or not in that position (axes exactly parallel or
/// on each other: the earlier rules make them so).
fn tangent(p: &SurfaceParams, s: &SurfaceParams) -> Option<(&'static str, f64, SurfaceParams)> {
    const EXACT: f64 = 1e-12;
    match (*p, *s) {
        (
            SurfaceParams::Plane { normal, offset },
            SurfaceParams::Cylinder {
                axis_point,
                axis_dir,
                radius,
            },
        ) if dot(normal, axis_dir).abs() <= EXACT => {
            let h = dot(normal, axis_point) - offset;
            let shift = h.signum() * radius - h;
            Some((
                "tangent to plane",
                shift.abs(),
                SurfaceParams::Cylinder {
                    axis_point: add(axis_point, scale(normal, shift)),
                    axis_dir,
                    radius,
                },
            ))
        }
        (SurfaceParams::Plane { normal, offset }, SurfaceParams::Sphere { center, radius }) => {
            let h = dot(normal, center) - offset;
            let shift = h.signum() * radius - h;
            Some((
                "tangent to plane",
                shift.abs(),
                SurfaceParams::Sphere {
                    center: add(center, scale(normal, shift)),
                    radius,
                },
            ))
        }
        (
            SurfaceParams::Plane { normal, offset },
            SurfaceParams::Torus {
                center,
                axis_dir: axis,
                major_radius,
                minor_radius,
            },
        ) if 1.0 - dot(normal, axis).abs() <= EXACT => {
            let h = dot(normal, center) - offset;
            let shift = h.signum() * minor_radius - h;
            Some((
                "tangent to plane",
                shift.abs(),
                SurfaceParams::Torus {
                    center: add(center, scale(normal, shift)),
                    axis_dir: axis,
                    major_radius,
                    minor_radius,
                },
            ))
        }
        (
            SurfaceParams::Cylinder {
                axis_point,
                axis_dir,
                radius,
            },
            SurfaceParams::Sphere {
                center,
                radius: ball,
            },
        ) if line_distance(center, axis_point, axis_dir) <= EXACT * (1.0 + radius) => Some((
            "tangent inside cylinder",
            (radius - ball).abs(),
            SurfaceParams::Sphere { center, radius },
        )),
        (
            SurfaceParams::Cylinder {
                axis_point,
                axis_dir,
                radius,
            },
            SurfaceParams::Torus {
                center,
                axis_dir: axis,
                major_radius,
                minor_radius,
            },
        ) if 1.0 - dot(axis_dir, axis).abs() <= EXACT
            && line_distance(center, axis_point, axis_dir) <= EXACT * (1.0 + radius) =>
        {
            // The tube touches from inside (R + r = radius) or outside (R − r = radius).
            let inside = radius - minor_radius;
            let outside = radius + minor_radius;
            let target = if (major_radius - inside).abs() <= (major_radius - outside).abs() {
                inside
            } else {
                outside
            };
            (target > 0.0).then_some((
                "tangent to cylinder",
                (major_radius - target).abs(),
                SurfaceParams::Torus {
                    center,
                    axis_dir: axis,
                    major_radius: target,
                    minor_radius,
                },
            ))
        }
        _ => None,
    }
}

/// How much worse than their own fits the neighbouring surfaces may explain a smaller region's
/// vertices for the region to be dissolved into them.
pub const MERGE_RMS_RATIO: f64 = 1.5;

/// Dissolves regions the data cannot tell from their neighbours, on a mesh: the triangles'
/// centroids (on a coarse CAD mesh every vertex may lie on an edge, and so on the neighbouring
/// surface too) weighted by area, two labels neighbours when they meet at a vertex. See
/// [`merge_elements`].
pub(crate) fn merge_indistinct(
    positions: &[Point3],
    faces: &[[u32; 3]],
    areas: &[f64],
    labels: &mut [i32],
    surfaces: &[SurfaceParams],
) -> Vec<Snap> {
    let centroids: Vec<Point3> = faces
        .iter()
        .map(|f| {
            [0, 1, 2].map(|k| {
                (positions[f[0] as usize][k]
                    + positions[f[1] as usize][k]
                    + positions[f[2] as usize][k])
                    / 3.0
            })
        })
        .collect();
    let mut around: Vec<Vec<i32>> = vec![Vec::new(); positions.len()];
    for (t, f) in faces.iter().enumerate() {
        if labels[t] >= 0 {
            for &v in f {
                around[v as usize].push(labels[t]);
            }
        }
    }
    let mut pairs = Vec::new();
    for a in &mut around {
        a.sort_unstable();
        a.dedup();
        for &x in a.iter() {
            for &y in a.iter() {
                if x != y {
                    pairs.push((x as usize, y as usize));
                }
            }
        }
    }
    merge_elements(&centroids, areas, &pairs, labels, surfaces)
}

/// Dissolves regions the data cannot tell from their neighbours, on a cloud: the points
/// weighted by their areas, two labels neighbours when a point of one has a point of the other
/// among its first `k` neighbours. See [`merge_elements`].
pub(crate) fn merge_indistinct_points(
    points: &[Point3],
    point_area: &[f64],
    nbrs: &crate::spatial::Neighborhoods,
    k: usize,
    labels: &mut [i32],
    surfaces: &[SurfaceParams],
) -> Vec<Snap> {
    let mut pairs = Vec::new();
    for (i, &a) in labels.iter().enumerate() {
        if a < 0 {
            continue;
        }
        for &j in nbrs.prefix(i, k.min(nbrs.k())) {
            let b = labels[j as usize];
            if b >= 0 && b != a {
                pairs.push((a as usize, b as usize));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    let sym: Vec<(usize, usize)> = pairs.iter().flat_map(|&(a, b)| [(a, b), (b, a)]).collect();
    merge_elements(points, point_area, &sym, labels, surfaces)
}

/// Dissolves regions the data cannot tell from their neighbours: a region (the elements
/// labelled `a`: triangles or points, at `at` with weights `weight`) whose elements its larger
/// neighbouring surfaces (`pairs` of labels, both ways) fit, each by the nearest of them, with
/// an RMS distance at most [`MERGE_RMS_RATIO`] times the largest own RMS among `a` and those
/// surfaces, gives each of its elements to the surface nearest it (a plane fitted to a strip of
/// a noisy cylinder, or to the saddle where two cylinders meet; a plane split in two). Smaller
/// regions (by weight) first; returns what was dissolved.
fn merge_elements(
    at: &[Point3],
    weight: &[f64],
    pairs: &[(usize, usize)],
    labels: &mut [i32],
    surfaces: &[SurfaceParams],
) -> Vec<Snap> {
    use crate::geometry::surface::signed_distance;
    let ns = surfaces.len();
    let mut area = vec![0.0; ns];
    let mut sq = vec![0.0; ns];
    let mut count = vec![0usize; ns];
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); ns];
    for (t, &l) in labels.iter().enumerate() {
        let Ok(l) = usize::try_from(l) else {
            continue;
        };
        area[l] += weight[t];
        members[l].push(t);
        sq[l] += signed_distance(&surfaces[l], at[t]).powi(2);
        count[l] += 1;
    }
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); ns];
    for &(x, y) in pairs {
        neighbours[x].push(y);
    }
    for n in &mut neighbours {
        n.sort_unstable();
        n.dedup();
    }
    let mut order: Vec<usize> = (0..ns).filter(|&l| !members[l].is_empty()).collect();
    order.sort_by(|&x, &y| area[x].total_cmp(&area[y]).then(x.cmp(&y)));
    let mut merges = Vec::new();
    for a in order {
        let larger: Vec<usize> = neighbours[a]
            .iter()
            .copied()
            .filter(|&b| !members[b].is_empty() && (area[b], b) > (area[a], a))
            .collect();
        if larger.is_empty() || members[a].is_empty() {
            continue;
        }
        let rms = |l: usize| (sq[l] / count[l].max(1) as f64).sqrt();
        let nearest = |p: Point3| {
            larger
                .iter()
                .map(|&b| (signed_distance(&surfaces[b], p).abs(), b))
                .fold(
                    (f64::INFINITY, usize::MAX),
                    |m, x| if x.0 < m.0 { x } else { m },
                )
        };
        let cross: f64 = members[a].iter().map(|&t| nearest(at[t]).0.powi(2)).sum();
        let rms_cross = (cross / members[a].len().max(1) as f64).sqrt();
        let own = larger.iter().map(|&b| rms(b)).fold(rms(a), f64::max);
        if rms_cross > MERGE_RMS_RATIO * own {
            continue;
        }
        let moved = std::mem::take(&mut members[a]);
        let mut into: Vec<usize> = Vec::new();
        for t in moved {
            let (d, b) = nearest(at[t]);
            labels[t] = b as i32;
            area[b] += weight[t];
            sq[b] += d * d;
            count[b] += 1;
            members[b].push(t);
            if !into.contains(&b) {
                into.push(b);
            }
        }
        area[a] = 0.0;
        for &b in &into {
            for &x in &neighbours[a].clone() {
                if x != b && !neighbours[b].contains(&x) {
                    neighbours[b].push(x);
                }
            }
        }
        merges.push(Snap {
            relation: format!(
                "{} dissolved into the surfaces it lies on ({})",
                surfaces[a].kind().name(),
                into.iter()
                    .map(|b| b.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            surface: a,
            to: into[0],
            off_by: rms_cross,
        });
    }
    merges
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(rms: f64, extent: f64, area: f64, centroid: Point3) -> FaceStats {
        FaceStats {
            rms,
            extent,
            area,
            centroid,
        }
    }

    #[test]
    fn a_slightly_tilted_hole_is_made_square_to_its_plate_and_an_exact_one_is_left() {
        let plate = SurfaceParams::Plane {
            normal: [0.0, 0.0, 1.0],
            offset: 0.5,
        };
        let tilt = 0.01f64; // 0.57°
        let hole = SurfaceParams::Cylinder {
            axis_point: [0.2, 0.1, 0.0],
            axis_dir: [tilt.sin(), 0.0, tilt.cos()],
            radius: 0.1,
        };
        let st = [
            stats(0.005, 1.0, 1.0, [0.0, 0.0, 0.5]),
            stats(0.005, 0.5, 0.2, [0.2, 0.1, 0.2]),
        ];
        let mut s = [plate, hole];
        let snaps = snap(&mut s, &[(0, 1)], &[(0, 1)], &st, 1.0);
        assert_eq!(snaps.len(), 1, "{snaps:?}");
        assert!((snaps[0].off_by - tilt.to_degrees()).abs() < 1e-9);
        let SurfaceParams::Cylinder { axis_dir, .. } = s[1] else {
            panic!()
        };
        assert_eq!(axis_dir, [0.0, 0.0, 1.0]);
        // 3 × 0.005 over 0.5: 1.7°; a tilt of 3° stays.
        let mut s = [
            plate,
            SurfaceParams::Cylinder {
                axis_point: [0.2, 0.1, 0.0],
                axis_dir: [0.05f64.sin(), 0.0, 0.05f64.cos()],
                radius: 0.1,
            },
        ];
        assert!(snap(&mut s, &[(0, 1)], &[(0, 1)], &st, 1.0).is_empty());
    }
}
