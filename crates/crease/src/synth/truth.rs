//! Exact feature curves of the synthetic parts and exact point-to-curve distances.
//!
//! A curve is a straight segment, a circular arc (or full circle), or a dense polyline (the
//! cylinder–cylinder intersection curve, which has no simple closed form). Distances to
//! segments and arcs are computed in closed form; distances to a polyline are exact distances to
//! the polyline, whose deviation from the true curve is documented where it is built. A bounding
//! volume hierarchy over all curve elements makes a query logarithmic in the number of elements.

use serde::Serialize;

use crate::geometry::vec3::{add, cross, dist, dot, scale, sub};
use crate::geometry::Point3;

/// What a feature curve is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveKind {
    /// Two patches meet at a crease (normal discontinuity). Code 0 in `curve_kind`.
    Sharp = 0,
    /// Two patches meet tangent-continuously (e.g. fillet / plane border). Code 1.
    Smooth = 1,
    /// An open boundary of the surface (edge of an open primitive, not a feature). Code 2.
    Boundary = 2,
}

impl CurveKind {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            CurveKind::Sharp => "sharp",
            CurveKind::Smooth => "smooth",
            CurveKind::Boundary => "boundary",
        }
    }
}

/// The exact geometry of a feature curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum CurveGeometry {
    /// The straight segment from `a` to `b`.
    Segment {
        /// Start point.
        a: Point3,
        /// End point.
        b: Point3,
    },
    /// `center + radius (cos t e1 + sin t e2)` for t in `[start, start + sweep]`; a full circle
    /// when `sweep` = 2π. `e1`, `e2` are orthonormal.
    Arc {
        /// Centre.
        center: Point3,
        /// First in-plane unit vector.
        e1: Point3,
        /// Second in-plane unit vector.
        e2: Point3,
        /// Radius.
        radius: f64,
        /// Start angle (radians).
        start: f64,
        /// Angular extent (radians), in (0, 2π].
        sweep: f64,
    },
    /// A curve without a simple closed form, given by the curve's dense polyline `points`.
    Polyline,
}

/// A feature curve: its kind, a polyline through it and its exact geometry.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureCurve {
    /// Sharp, smooth or boundary.
    pub kind: CurveKind,
    /// Polyline whose vertices lie on the exact curve, dense enough that the chord error is at
    /// most 1e-4 of the part's size (segments: pieces no longer than 1/100 of the size).
    /// A closed curve does not repeat its first point: the last point connects to the first.
    pub points: Vec<Point3>,
    /// True if the curve is a closed loop.
    pub closed: bool,
    /// The exact geometry (used for exact distances).
    pub geometry: CurveGeometry,
    /// Exact length of the curve (for polylines: the polyline's length).
    pub length: f64,
}

impl FeatureCurve {
    /// A straight segment, sampled with pieces no longer than `max_piece`.
    pub(crate) fn segment(kind: CurveKind, a: Point3, b: Point3, max_piece: f64) -> Self {
        let length = dist(a, b);
        let n = ((length / max_piece).ceil() as usize).max(1);
        let points = (0..=n)
            .map(|i| crate::geometry::vec3::lerp(a, b, i as f64 / n as f64))
            .collect();
        FeatureCurve {
            kind,
            points,
            closed: false,
            geometry: CurveGeometry::Segment { a, b },
            length,
        }
    }

    /// A circular arc (a full circle when `sweep` ≥ 2π), sampled so that the chord error is at
    /// most `chord_error`.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn arc(
        kind: CurveKind,
        center: Point3,
        e1: Point3,
        e2: Point3,
        radius: f64,
        start: f64,
        sweep: f64,
        chord_error: f64,
    ) -> Self {
        let closed = sweep >= std::f64::consts::TAU - 1e-12;
        let sweep = sweep.min(std::f64::consts::TAU);
        // Sagitta r (1 - cos(Δ/2)) <= e  <=>  Δ <= 2 acos(1 - e / r).
        let max_step = 2.0 * (1.0 - (chord_error / radius).min(1.0)).acos();
        let n = ((sweep / max_step).ceil() as usize).max(if closed { 8 } else { 2 });
        let count = if closed { n } else { n + 1 };
        let points = (0..count)
            .map(|i| {
                let t = start + sweep * i as f64 / n as f64;
                arc_point(center, e1, e2, radius, t)
            })
            .collect();
        FeatureCurve {
            kind,
            points,
            closed,
            geometry: CurveGeometry::Arc {
                center,
                e1,
                e2,
                radius,
                start,
                sweep,
            },
            length: radius * sweep,
        }
    }

    /// A curve given only by a dense polyline.
    pub(crate) fn polyline(kind: CurveKind, points: Vec<Point3>, closed: bool) -> Self {
        let mut length: f64 = points.windows(2).map(|w| dist(w[0], w[1])).sum();
        if closed {
            if let (Some(&f), Some(&l)) = (points.first(), points.last()) {
                length += dist(f, l);
            }
        }
        FeatureCurve {
            kind,
            points,
            closed,
            geometry: CurveGeometry::Polyline,
            length,
        }
    }

    /// Exact distance from `p` to the curve.
    pub fn distance(&self, p: Point3) -> f64 {
        match &self.geometry {
            CurveGeometry::Segment { a, b } => segment_distance(p, *a, *b),
            CurveGeometry::Arc {
                center,
                e1,
                e2,
                radius,
                start,
                sweep,
            } => arc_distance(p, *center, *e1, *e2, *radius, *start, *sweep),
            CurveGeometry::Polyline => {
                let n = self.points.len();
                let mut best = f64::INFINITY;
                for i in 0..n {
                    let j = if i + 1 < n {
                        i + 1
                    } else if self.closed {
                        0
                    } else {
                        break;
                    };
                    best = best.min(segment_distance(p, self.points[i], self.points[j]));
                }
                if n == 1 {
                    best = dist(p, self.points[0]);
                }
                best
            }
        }
    }
}

#[inline]
pub(crate) fn arc_point(center: Point3, e1: Point3, e2: Point3, radius: f64, t: f64) -> Point3 {
    let (s, c) = t.sin_cos();
    add(center, scale(add(scale(e1, c), scale(e2, s)), radius))
}

/// Distance from `p` to the segment `ab` (the geometry's, re-exported for the tests).
pub use crate::geometry::vec3::segment_distance;

/// Distance from `p` to the arc `center + r (cos t e1 + sin t e2)`, t in [start, start+sweep].
#[inline]
pub fn arc_distance(
    p: Point3,
    center: Point3,
    e1: Point3,
    e2: Point3,
    radius: f64,
    start: f64,
    sweep: f64,
) -> f64 {
    let q = sub(p, center);
    let x = dot(q, e1);
    let y = dot(q, e2);
    let n = cross(e1, e2);
    let z = dot(q, n);
    let rho = x.hypot(y);
    if rho == 0.0 {
        // Every circle point is equally far.
        return radius.hypot(z);
    }
    let t = y.atan2(x);
    let rel = (t - start).rem_euclid(std::f64::consts::TAU);
    if rel <= sweep {
        (rho - radius).hypot(z)
    } else {
        let a = arc_point(center, e1, e2, radius, start);
        let b = arc_point(center, e1, e2, radius, start + sweep);
        dist(p, a).min(dist(p, b))
    }
}

/// One primitive of a curve set: a segment or an arc, tagged with its curve index.
#[derive(Debug, Clone, Copy)]
enum Element {
    Segment(Point3, Point3),
    Arc {
        center: Point3,
        e1: Point3,
        e2: Point3,
        radius: f64,
        start: f64,
        sweep: f64,
    },
}

impl Element {
    fn distance(&self, p: Point3) -> f64 {
        match *self {
            Element::Segment(a, b) => segment_distance(p, a, b),
            Element::Arc {
                center,
                e1,
                e2,
                radius,
                start,
                sweep,
            } => arc_distance(p, center, e1, e2, radius, start, sweep),
        }
    }

    fn aabb(&self) -> ([f64; 3], [f64; 3]) {
        match *self {
            Element::Segment(a, b) => (
                [a[0].min(b[0]), a[1].min(b[1]), a[2].min(b[2])],
                [a[0].max(b[0]), a[1].max(b[1]), a[2].max(b[2])],
            ),
            Element::Arc {
                center,
                e1,
                e2,
                radius,
                ..
            } => {
                // Box of the whole circle (conservative for an arc).
                let n = cross(e1, e2);
                let mut lo = [0.0; 3];
                let mut hi = [0.0; 3];
                for k in 0..3 {
                    let ext = radius * (1.0 - n[k] * n[k]).max(0.0).sqrt();
                    lo[k] = center[k] - ext;
                    hi[k] = center[k] + ext;
                }
                (lo, hi)
            }
        }
    }
}

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    /// Leaf: elements [start, start + count); inner: children at `start` and `start + 1`
    /// (count == 0).
    start: u32,
    count: u32,
}

/// A set of curves with a bounding volume hierarchy for nearest-distance queries.
#[derive(Debug, Clone, Default)]
pub(crate) struct CurveIndex {
    elements: Vec<(Element, u32)>,
    nodes: Vec<Node>,
}

const LEAF: usize = 4;

impl CurveIndex {
    /// Index over the curves of `curves` whose kind is `kind`.
    pub fn new(curves: &[FeatureCurve], kind: CurveKind) -> Self {
        let mut elements = Vec::new();
        for (ci, c) in curves.iter().enumerate() {
            if c.kind != kind {
                continue;
            }
            let ci = ci as u32;
            match &c.geometry {
                CurveGeometry::Segment { a, b } => elements.push((Element::Segment(*a, *b), ci)),
                CurveGeometry::Arc {
                    center,
                    e1,
                    e2,
                    radius,
                    start,
                    sweep,
                } => elements.push((
                    Element::Arc {
                        center: *center,
                        e1: *e1,
                        e2: *e2,
                        radius: *radius,
                        start: *start,
                        sweep: *sweep,
                    },
                    ci,
                )),
                CurveGeometry::Polyline => {
                    let n = c.points.len();
                    for i in 0..n {
                        let j = if i + 1 < n {
                            i + 1
                        } else if c.closed && n > 2 {
                            0
                        } else {
                            break;
                        };
                        elements.push((Element::Segment(c.points[i], c.points[j]), ci));
                    }
                }
            }
        }
        let mut index = CurveIndex {
            elements,
            nodes: Vec::new(),
        };
        if !index.elements.is_empty() {
            let boxes: Vec<_> = index.elements.iter().map(|(e, _)| e.aabb()).collect();
            let mut order: Vec<usize> = (0..index.elements.len()).collect();
            index.nodes.push(Node {
                lo: [0.0; 3],
                hi: [0.0; 3],
                start: 0,
                count: 0,
            });
            build(&mut index.nodes, 0, &mut order, 0, &boxes);
            index.elements = order.iter().map(|&i| index.elements[i]).collect();
        }
        index
    }

    /// Distance from `p` to the nearest curve and that curve's index; `(inf, None)` if empty.
    pub fn nearest(&self, p: Point3) -> (f64, Option<u32>) {
        let mut best = f64::INFINITY;
        let mut best_curve = None;
        if self.nodes.is_empty() {
            return (best, best_curve);
        }
        let mut stack: Vec<(usize, f64)> = Vec::with_capacity(64);
        stack.push((0, box_distance(p, &self.nodes[0])));
        while let Some((ni, lb)) = stack.pop() {
            if lb >= best {
                continue;
            }
            let node = self.nodes[ni];
            if node.count > 0 {
                let s = node.start as usize;
                for (e, ci) in &self.elements[s..s + node.count as usize] {
                    let d = e.distance(p);
                    if d < best {
                        best = d;
                        best_curve = Some(*ci);
                    }
                }
            } else {
                let a = node.start as usize;
                let b = a + 1;
                let da = box_distance(p, &self.nodes[a]);
                let db = box_distance(p, &self.nodes[b]);
                // Push the farther child first so that the nearer one is visited first.
                if da <= db {
                    stack.push((b, db));
                    stack.push((a, da));
                } else {
                    stack.push((a, da));
                    stack.push((b, db));
                }
            }
        }
        (best, best_curve)
    }
}

fn build(
    nodes: &mut Vec<Node>,
    ni: usize,
    order: &mut [usize],
    offset: usize,
    boxes: &[([f64; 3], [f64; 3])],
) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &i in order.iter() {
        for k in 0..3 {
            lo[k] = lo[k].min(boxes[i].0[k]);
            hi[k] = hi[k].max(boxes[i].1[k]);
        }
    }
    if order.len() <= LEAF {
        nodes[ni] = Node {
            lo,
            hi,
            start: offset as u32,
            count: order.len() as u32,
        };
        return;
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let centre = |i: usize| boxes[i].0[axis] + boxes[i].1[axis];
    order.sort_by(|&a, &b| centre(a).total_cmp(&centre(b)).then(a.cmp(&b)));
    let mid = order.len() / 2;
    let child = nodes.len();
    let empty = Node {
        lo: [0.0; 3],
        hi: [0.0; 3],
        start: 0,
        count: 0,
    };
    nodes.push(empty);
    nodes.push(empty);
    nodes[ni] = Node {
        lo,
        hi,
        start: child as u32,
        count: 0,
    };
    let (left, right) = order.split_at_mut(mid);
    build(nodes, child, left, offset, boxes);
    build(nodes, child + 1, right, offset + mid, boxes);
}

#[inline]
fn box_distance(p: Point3, n: &Node) -> f64 {
    let s: f64 = (0..3)
        .map(|k| {
            let d = (n.lo[k] - p[k]).max(p[k] - n.hi[k]).max(0.0);
            d * d
        })
        .sum();
    s.sqrt()
}
