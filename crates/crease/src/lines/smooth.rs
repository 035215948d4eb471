//! Step 7 of demarsin2007 (section 2.8): smoothing G_closed into G_smooth.
//!
//! The paper defers to a technical report that is not available, so crease uses a method that
//! keeps corners sharp and lines on the surface, as the issue asks: every vertex of the network
//! is moved onto the local intersection of the smooth patches it separates.
//!
//! For a vertex at c (its cluster's centre of mass), the `k` cloud points nearest to c are split
//! by their first-order segmentation cluster; the large clusters (the smooth patches) with at
//! least `MIN_PATCH_POINTS` points among them are fitted with least-squares planes (their local
//! tangent planes). With three patches whose normals are independent (|det| ≥ 0.1, i.e. the
//! planes meet at a point), the vertex is a corner and moves to the planes' common point; with
//! two patches meeting at more than `MIN_ANGLE_DEG`, it moves to the nearest point of their
//! intersection line; otherwise (one patch, nearly parallel planes, or a move longer than the
//! search radius, which means the fit is unreliable) it stays where it is. Only the first-order
//! segmentation decides which points belong to which patch, so the lines stay where the
//! segmentation put them and only their jaggedness (the scatter of cluster centres across the
//! edge) is removed.

use rayon::prelude::*;

use crate::geometry::fit_plane;
use crate::geometry::{vec3, Point3};
use crate::spatial::KdIndex;

/// Patches with fewer points near a vertex are ignored.
const MIN_PATCH_POINTS: usize = 6;
/// Two patches meeting at a smaller angle do not define a crease line.
const MIN_ANGLE_DEG: f64 = 10.0;

/// Moves every position in `vertices` onto the local intersection of the large clusters around
/// it (see the module documentation). `labels` are the per-point clusters, `small[c]` tells the
/// small clusters, `k` is the number of nearest points examined.
pub fn smooth_vertices(
    points: &[Point3],
    labels: &[u32],
    small: &[bool],
    vertices: &[Point3],
    k: usize,
) -> Vec<Point3> {
    let Some(index) = KdIndex::new(points) else {
        return vertices.to_vec();
    };
    let cos_min = MIN_ANGLE_DEG.to_radians().cos();
    vertices
        .par_iter()
        .map(|&c| {
            let near = index.nearest(&c, k.min(points.len()));
            let radius = near.iter().map(|n| n.1).fold(0.0f64, f64::max).sqrt();
            // Group the large-cluster points by cluster.
            let mut groups: Vec<(u32, Vec<Point3>)> = Vec::new();
            for &(j, _) in &near {
                let l = labels[j as usize];
                if small[l as usize] {
                    continue;
                }
                match groups.iter_mut().find(|g| g.0 == l) {
                    Some(g) => g.1.push(points[j as usize]),
                    None => groups.push((l, vec![points[j as usize]])),
                }
            }
            groups.retain(|g| g.1.len() >= MIN_PATCH_POINTS);
            groups.sort_by(|a, b| b.1.len().cmp(&a.1.len()).then(a.0.cmp(&b.0)));
            let planes: Vec<(Point3, Point3)> = groups
                .iter()
                .take(3)
                .filter_map(|g| {
                    fit_plane(g.1.iter().map(|&p| (p, 1.0))).map(|pl| (pl.centroid, pl.normal))
                })
                .collect();
            let moved = match planes.as_slice() {
                [a, b, c3] => corner(a, b, c3).or_else(|| line_point(c, a, b, cos_min)),
                [a, b] => line_point(c, a, b, cos_min),
                _ => None,
            };
            match moved {
                Some(m) if vec3::dist(m, c) <= radius => m,
                _ => c,
            }
        })
        .collect()
}

/// The common point of three planes (point, normal), if their normals are independent.
fn corner(a: &(Point3, Point3), b: &(Point3, Point3), c: &(Point3, Point3)) -> Option<Point3> {
    let (n1, n2, n3) = (a.1, b.1, c.1);
    let det = vec3::dot(n1, vec3::cross(n2, n3));
    if det.abs() < 0.1 {
        return None;
    }
    let (d1, d2, d3) = (vec3::dot(n1, a.0), vec3::dot(n2, b.0), vec3::dot(n3, c.0));
    // x = (d1 (n2 × n3) + d2 (n3 × n1) + d3 (n1 × n2)) / det
    let x = vec3::add(
        vec3::add(
            vec3::scale(vec3::cross(n2, n3), d1),
            vec3::scale(vec3::cross(n3, n1), d2),
        ),
        vec3::scale(vec3::cross(n1, n2), d3),
    );
    Some(vec3::scale(x, 1.0 / det))
}

/// The point of the intersection line of two planes nearest to `p`, if they meet at more than
/// the minimum angle.
fn line_point(
    p: Point3,
    a: &(Point3, Point3),
    b: &(Point3, Point3),
    cos_min: f64,
) -> Option<Point3> {
    let (n1, n2) = (a.1, b.1);
    if vec3::dot(n1, n2).abs() > cos_min {
        return None;
    }
    let dir = vec3::normalize(vec3::cross(n1, n2))?;
    // A point on the line: the third plane through p perpendicular to the line closes the
    // system, so its solution is the nearest point of the line to p.
    corner(a, b, &(p, dir))
}

/// Laplacian iterations of [`smooth_along`].
const ALONG_ITERATIONS: usize = 3;

/// Smoothing for lines between tangent-continuous patches (fillet borders, demarsin2008
/// section 3, which keeps the step of demarsin2007 without detail): the patches' planes are
/// parallel there, so [`smooth_vertices`] has nothing to intersect. Every vertex of degree 2 in
/// `edges` is moved `ALONG_ITERATIONS` times halfway towards the midpoint of its two neighbours
/// (Jacobi iterations; endpoints and junctions stay, so corners of the network stay where they
/// are), which removes the zig-zag of one-point clusters across the border, and then projected
/// onto the least-squares plane of its `k` nearest cloud points, which keeps it on the surface
/// (the Laplacian step cuts a curved line's chords by a fraction of a spacing).
pub fn smooth_along(
    points: &[Point3],
    vertices: &[Point3],
    edges: &[[u32; 2]],
    k: usize,
) -> Vec<Point3> {
    let n = vertices.len();
    let mut nbrs: Vec<Vec<u32>> = vec![Vec::new(); n];
    for &[a, b] in edges {
        if (a as usize) < n && (b as usize) < n && a != b {
            nbrs[a as usize].push(b);
            nbrs[b as usize].push(a);
        }
    }
    let mut cur = vertices.to_vec();
    for _ in 0..ALONG_ITERATIONS {
        cur = (0..n)
            .into_par_iter()
            .map(|v| match nbrs[v].as_slice() {
                &[a, b] => {
                    let mid = vec3::scale(vec3::add(cur[a as usize], cur[b as usize]), 0.5);
                    vec3::scale(vec3::add(cur[v], mid), 0.5)
                }
                _ => cur[v],
            })
            .collect();
    }
    let Some(index) = KdIndex::new(points) else {
        return cur;
    };
    cur.par_iter()
        .enumerate()
        .map(|(v, &c)| {
            if nbrs[v].len() != 2 {
                return c;
            }
            let near = index.nearest(&c, k.min(points.len()));
            match fit_plane(near.iter().map(|&(j, _)| (points[j as usize], 1.0))) {
                Some(pl) => {
                    let off = vec3::dot(vec3::sub(c, pl.centroid), pl.normal);
                    vec3::sub(c, vec3::scale(pl.normal, off))
                }
                None => c,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_corner_of_planes() {
        let x = ([1.0, 0.0, 0.0], [1.0, 0.0, 0.0]); // plane x = 1
        let y = ([0.0, 2.0, 0.0], [0.0, 1.0, 0.0]); // plane y = 2
        let z = ([0.0, 0.0, 3.0], [0.0, 0.0, -1.0]); // plane z = 3
        let c = corner(&x, &y, &z).unwrap();
        assert!(vec3::dist(c, [1.0, 2.0, 3.0]) < 1e-12);
        let p = line_point([5.0, 5.0, 7.0], &x, &y, 0.9).unwrap();
        assert!(vec3::dist(p, [1.0, 2.0, 7.0]) < 1e-12);
        assert!(line_point([0.0; 3], &x, &x, 0.9).is_none());
    }
}
