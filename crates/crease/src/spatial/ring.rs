//! The Delaunay 1-ring of every point of a cloud (demarsin2007 section 2.2).
//!
//! For a point p: take its k (= 20, the paper's value) nearest neighbours, fit the least-squares
//! plane through them and p, project them onto it, build the 2D Delaunay triangulation of the
//! projections (spade, exact predicates) and keep the neighbours that share an edge with p: the
//! "Delaunay neighbourhood" demarsin2007 uses as an approximation of a mesh's 1-ring. The point
//! is flagged as a boundary point when its projection lies on the convex hull of the projected
//! neighbourhood (p is adjacent to the outer face of the triangulation), which happens on the
//! open borders of a scan.
//!
//! Rings are not symmetric: q in ring(p) does not imply p in ring(q), because the two
//! triangulations are built from different neighbourhoods and planes. [`Rings::symmetrized`]
//! gives the union, the undirected adjacency the cluster graph of demarsin2007 section 2.3
//! ("clusters that contain at least one point with overlapping 1-ring neighborhood") needs.

use rayon::prelude::*;
use spade::handles::FixedVertexHandle;
use spade::{DelaunayTriangulation, Point2, Triangulation};

use crate::geometry::fit_plane;
use crate::geometry::{Csr, Point3};
use crate::spatial::Neighborhoods;
use crate::{Error, Result};

/// A neighbourhood whose second eigenvalue is at most this fraction of the largest one (its
/// width at most 1e-6 of its length) is treated as collinear: it is projected onto its line, so
/// that rounding noise in the plane's second axis cannot create sliver triangles.
pub const COLLINEAR_RATIO: f64 = 1e-12;

/// A point whose triangles have an angle at p within this many radians of π is on the hull of
/// its projected neighbourhood up to rounding (a point on a straight border that the rounding
/// of the projection moved slightly inside), and is flagged as a boundary point.
pub const HULL_ANGLE_TOLERANCE: f64 = 1e-9;

/// Points per parallel work unit (results are assembled in index order, so they do not depend
/// on the thread count).
const CHUNK: usize = 2048;

/// Parameters of [`delaunay_rings`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RingParams {
    /// Number of nearest neighbours projected and triangulated (default 20, demarsin2007
    /// section 2.2: "setting the value of this parameter to 20 was suitable for all the tested
    /// point clouds"). The first `k` entries of each neighbourhood are used, so the
    /// neighbourhoods must have been built for at least this k.
    pub k: usize,
}

impl Default for RingParams {
    fn default() -> Self {
        RingParams { k: 20 }
    }
}

/// The Delaunay 1-rings of a cloud, in the input order.
#[derive(Debug, Clone, PartialEq)]
pub struct Rings {
    /// Row i: the 1-ring of point i, in angular order around p in its fitted plane (cyclic; the
    /// direction, clockwise or counter-clockwise, depends on the plane's arbitrary frame).
    /// Interior points start at their nearest ring member; boundary points start just after
    /// the gap facing the outside, so the row is the fan of triangles from first to last
    /// member. Neighbours whose projection coincides exactly with another one's appear next to
    /// each other (nearest first); neighbours projecting exactly onto p are left out.
    pub rings: Csr,
    /// True where the point lies on the convex hull of its projected neighbourhood (up to
    /// [`HULL_ANGLE_TOLERANCE`]), and for
    /// points whose ring is empty (no plane could be fitted, or all neighbours coincide with
    /// p) or collinear. On a random sample of a closed surface an interior point is flagged
    /// when all its k neighbours happen to lie in a half-plane around it (probability about
    /// k·2^(1−k), 4e-5 at k = 20, for a Poisson sample).
    pub boundary: Vec<bool>,
    /// Unit normal of the least-squares plane through the point and its k nearest neighbours
    /// (the projection plane), with the sign rule of [`canonical_sign`];
    /// `[NaN; 3]` where no plane could be fitted (non-finite coordinates, fewer than two
    /// neighbours). The fallback of the 1-ring normal.
    pub plane_normals: Vec<Point3>,
}

impl Rings {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.boundary.len()
    }

    /// True for an empty cloud.
    pub fn is_empty(&self) -> bool {
        self.boundary.is_empty()
    }

    /// The 1-ring of point `i` (panics if `i >= len()`).
    #[inline]
    pub fn ring(&self, i: usize) -> &[u32] {
        self.rings.row(i)
    }

    /// Whether point `i` is a boundary point (panics if `i >= len()`).
    #[inline]
    pub fn is_boundary(&self, i: usize) -> bool {
        self.boundary[i]
    }

    /// The undirected 1-ring graph: row i holds every q with q in ring(i) or i in ring(q),
    /// sorted by index, without repetitions (the angular order is lost).
    ///
    /// demarsin2007 section 2.3 connects two clusters when they "contain at least one point with
    /// overlapping 1-ring neighborhood"; since the rings of two points are built from different
    /// neighbourhoods they need not agree, and the union keeps every adjacency either side saw.
    pub fn symmetrized(&self) -> Csr {
        self.rings.symmetrized()
    }
}

/// Flips `n` so that its component of largest magnitude is positive (the first such axis on
/// ties): a deterministic sign for unoriented normals (orientation is another module's job).
pub fn canonical_sign(n: Point3) -> Point3 {
    let mut a = 0;
    for k in 1..3 {
        if n[k].abs() > n[a].abs() {
            a = k;
        }
    }
    if n[a] < 0.0 {
        [-n[0], -n[1], -n[2]]
    } else {
        n
    }
}

/// Per-thread scratch: one triangulation reused (`clear()` keeps its buffers) and the maps
/// from triangulation vertices back to neighbourhood positions.
struct Scratch {
    tri: DelaunayTriangulation<Point2<f64>>,
    /// Triangulation vertex → first (nearest) local index inserted at its position.
    first: Vec<u32>,
    /// Triangulation vertex → last local index inserted at its position.
    last: Vec<u32>,
    /// Local index → next local index at the same position (`NONE` at the end).
    next: Vec<u32>,
    /// Out-edges of p in counter-clockwise order: (target vertex, the face to the left is the
    /// outer face, angle of the target around p).
    fan: Vec<(usize, bool, f64)>,
}

const NONE: u32 = u32::MAX;

impl Scratch {
    fn new() -> Self {
        Scratch {
            tri: DelaunayTriangulation::new(),
            first: Vec::new(),
            last: Vec::new(),
            next: Vec::new(),
            fan: Vec::new(),
        }
    }
}

/// One chunk of results.
struct Chunk {
    counts: Vec<u32>,
    indices: Vec<u32>,
    boundary: Vec<bool>,
    plane_normals: Vec<Point3>,
}

/// The Delaunay 1-ring of every point (demarsin2007 section 2.2), in parallel.
///
/// Inputs: `points` (n positions), `nbrs` (their k-nearest-neighbour lists, nearest first, for
/// a k of at least `params.k`; the first `params.k` of each are used). Output: [`Rings`], one
/// row per point in the input order, identical whatever the thread count.
///
/// Degenerate neighbourhoods: neighbours with the same projected position are merged by the
/// triangulation and mapped back to all of them; a neighbourhood (with p) that is collinear
/// (see [`COLLINEAR_RATIO`]) is projected onto its line, where p's ring is its nearest
/// neighbour on each side (one if p is at an end), flagged boundary; if every neighbour
/// coincides with p, or the plane is not finite, the ring is empty and p is flagged boundary.
///
/// Errors when `params.k` is 0 or larger than the neighbourhoods' k, when `nbrs` does not have
/// one row per point, or when a neighbour index is out of range.
pub fn delaunay_rings(
    points: &[Point3],
    nbrs: &Neighborhoods,
    params: &RingParams,
) -> Result<Rings> {
    let k = params.k;
    if k == 0 {
        return Err(Error::InvalidArgument("Delaunay 1-rings with k = 0".into()));
    }
    if k > nbrs.k() {
        return Err(Error::InvalidArgument(format!(
            "Delaunay 1-rings with k = {k} need neighbourhoods of at least {k} points, got k = {}",
            nbrs.k()
        )));
    }
    if nbrs.len() != points.len() {
        return Err(Error::InvalidInput(format!(
            "{} neighbourhoods for {} points",
            nbrs.len(),
            points.len()
        )));
    }
    let n = points.len();
    if let Some(bad) = nbrs
        .csr()
        .indices
        .par_iter()
        .find_any(|&&j| j as usize >= n)
    {
        return Err(Error::InvalidInput(format!(
            "neighbour index {bad} out of range for {n} points"
        )));
    }
    let n_chunks = n.div_ceil(CHUNK);
    let chunks: Vec<Chunk> = (0..n_chunks)
        .into_par_iter()
        .map_init(Scratch::new, |s, c| {
            let range = c * CHUNK..((c + 1) * CHUNK).min(n);
            let mut out = Chunk {
                counts: Vec::with_capacity(range.len()),
                indices: Vec::with_capacity(range.len() * 7),
                boundary: Vec::with_capacity(range.len()),
                plane_normals: Vec::with_capacity(range.len()),
            };
            for i in range {
                let before = out.indices.len();
                let (boundary, normal) = ring_of(points, i, nbrs.prefix(i, k), s, &mut out.indices);
                out.counts.push((out.indices.len() - before) as u32);
                out.boundary.push(boundary);
                out.plane_normals.push(normal);
            }
            out
        })
        .collect();
    let total: usize = chunks.iter().map(|c| c.indices.len()).sum();
    let mut counts = Vec::with_capacity(n);
    let mut indices = Vec::with_capacity(total);
    let mut boundary = Vec::with_capacity(n);
    let mut plane_normals = Vec::with_capacity(n);
    for c in chunks {
        counts.extend_from_slice(&c.counts);
        indices.extend_from_slice(&c.indices);
        boundary.extend_from_slice(&c.boundary);
        plane_normals.extend_from_slice(&c.plane_normals);
    }
    Ok(Rings {
        rings: Csr {
            offsets: Csr::offsets_from_counts(&counts),
            indices,
        },
        boundary,
        plane_normals,
    })
}

/// The ring of point `i` with neighbours `nb`, appended to `out`; returns (boundary, plane
/// normal).
fn ring_of(
    points: &[Point3],
    i: usize,
    nb: &[u32],
    s: &mut Scratch,
    out: &mut Vec<u32>,
) -> (bool, Point3) {
    const NAN3: Point3 = [f64::NAN; 3];
    let p = points[i];
    let plane = fit_plane(
        std::iter::once(p)
            .chain(nb.iter().map(|&j| points[j as usize]))
            .map(|q| (q, 1.0)),
    );
    let Some(plane) = plane else {
        return (true, NAN3);
    };
    if !p.iter().all(|v| v.is_finite()) {
        return (true, NAN3);
    }
    let normal = canonical_sign(plane.normal);
    let [_, l1, l2] = plane.eigenvalues;
    if l2.is_nan() || l2 <= 0.0 {
        // Every neighbour coincides with p.
        return (true, normal);
    }
    let collinear = l1 <= COLLINEAR_RATIO * l2;
    let (u, v) = if collinear {
        ([0.0; 3], plane.axes[2])
    } else {
        (plane.axes[1], plane.axes[2])
    };

    s.tri.clear();
    s.first.clear();
    s.last.clear();
    s.next.clear();
    s.next.resize(nb.len() + 1, NONE);
    // p first: vertex 0 at the origin, local index 0.
    if s.tri.insert(Point2::new(0.0, 0.0)).is_err() {
        return (true, normal);
    }
    s.first.push(0);
    s.last.push(0);
    for (li, &j) in nb.iter().enumerate() {
        let local = li as u32 + 1;
        let q = points[j as usize];
        let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
        let x = d[0] * u[0] + d[1] * u[1] + d[2] * u[2];
        let y = d[0] * v[0] + d[1] * v[1] + d[2] * v[2];
        let pos = spade::mitigate_underflow(Point2::new(x, y));
        let before = s.tri.num_vertices();
        let Ok(h) = s.tri.insert(pos) else {
            // Not representable by spade (non-finite or beyond its range): left out.
            continue;
        };
        let vi = h.index();
        if s.tri.num_vertices() > before {
            s.first.push(local);
            s.last.push(local);
        } else {
            // Same position as an earlier vertex: chain it behind that vertex's points.
            let tail = s.last[vi] as usize;
            s.next[tail] = local;
            s.last[vi] = local;
        }
    }

    s.fan.clear();
    for e in s.tri.vertex(FixedVertexHandle::from_index(0)).out_edges() {
        let q = e.to().position();
        s.fan
            .push((e.to().index(), e.face().is_outer(), q.y.atan2(q.x)));
    }
    if s.fan.is_empty() {
        return (true, normal);
    }
    // Start: after the outer gap for boundary points, else at the nearest member.
    // On the hull: p adjacent to the outer face, or (rounding in the projection can move a
    // point of a straight border slightly inside) an angle between consecutive members, i.e.
    // an angle of a triangle at p, within HULL_ANGLE_TOLERANCE of π.
    let m = s.fan.len();
    let outer = s.fan.iter().position(|&(_, o, _)| o).or_else(|| {
        (0..m).find(|&t| {
            let a = s.fan[t].2;
            let b = s.fan[(t + 1) % m].2;
            let mut gap = b - a;
            if gap < 0.0 {
                gap += std::f64::consts::TAU;
            }
            gap >= std::f64::consts::PI - HULL_ANGLE_TOLERANCE
        })
    });
    let start = match outer {
        Some(g) => (g + 1) % s.fan.len(),
        None => {
            let mut best = 0;
            for (t, &(vtx, _, _)) in s.fan.iter().enumerate() {
                if s.first[vtx] < s.first[s.fan[best].0] {
                    best = t;
                }
            }
            best
        }
    };
    for t in 0..m {
        let (vtx, _, _) = s.fan[(start + t) % m];
        let mut local = s.first[vtx];
        while local != NONE {
            out.push(nb[local as usize - 1]);
            local = s.next[local as usize];
        }
    }
    (outer.is_some() || collinear, normal)
}
