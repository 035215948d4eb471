//! Scan to CAD: a boundary representation (B-rep) of the part, written as a STEP file.
//!
//! From a triangle mesh and its segmentation into analytic surfaces ([`crate::segment`]; a
//! noisy mesh through its vertices, see [`reconstruct_mesh`]):
//! 1. topology (`topology`): faces are the connected regions of triangles on one surface,
//!    edges the chains of mesh edges between two regions, vertices where three or more meet;
//!    islands of a surface inside another region are absorbed;
//! 2. snapping ([`snap`]): regions their neighbours explain as well dissolved into them, then
//!    planes made parallel or perpendicular, axes made a plane's normal or parallel to it,
//!    coaxial surfaces put on one axis, fillets made tangent to their faces, each within the
//!    measured noise and reported;
//! 3. vertices (`intersect::on_surfaces`): solved from the surfaces that meet there, by
//!    Levenberg–Marquardt from the mesh vertex (where a ball touches a face: the contact
//!    point), not taken from the (noisy) mesh; edges whose two ends then coincide (faces
//!    touching in a point) are collapsed;
//! 4. edges (`intersect::analytic_curve`): the exact intersection line, circle or ellipse of the two
//!    faces' surfaces where the pair has one, otherwise a cubic B-spline through points
//!    marched along the exact intersection (`intersect::march`) where the chain leads,
//!    refined until it stays on both surfaces;
//! 5. faces: the analytic surface, oriented like the mesh (outward on a closed part), bounded
//!    by the loops of oriented edges, its seam placed off its boundary;
//! 6. checks: a vertex or an edge farther than [`MAX_GAP`] mesh edges from one of its
//!    surfaces, a vertex solved more than [`MAX_MOVE`] mesh edges from its mesh vertex, a
//!    face wider than that whose edges all shrink to points, or a fitted edge turning by more
//!    than [`MAX_TURN`] (a corner of the intersection): the surfaces found do not meet
//!    where the regions do (a free-form patch fitted by a cylinder, a surface missed). The
//!    smallest region at each such place is left out and the rest built again, until it
//!    builds: an open shell, bounded by the mesh's border where those regions were, each one
//!    reported (refused when less than [`MIN_EXPLAINED`] of the area would remain).
//!    Unassigned triangles no surface explains (`explained_triangles`) are left out the same
//!    way; faces falling into separate shells refuse the part;
//! 7. output ([`step`]): a `MANIFOLD_SOLID_BREP` per shell when every edge has a face on both
//!    sides, `OPEN_SHELL`s (with a warning naming the border) otherwise.
//!
//! A point cloud ([`reconstruct_cloud`]) goes through the shared analysis (its segmentation)
//! and its envelope (`envelope`: the closed surface of the cloud dilated by a few spacings),
//! whose triangles take the surfaces of the nearest samples and play the mesh's part; the
//! residuals and tolerances are measured on the points. An open cloud (a sheet) keeps the front
//! of its envelope. A cloud whose envelope falls apart into pieces (a scene's objects, a
//! backdrop beyond a gap) is built piece by piece, one shell each (`assembly`); a piece that
//! cannot be built is left out and reported.
//!
//! Not yet done (issue "scan to CAD"): a cloud's border where the samples end rather than at
//! its envelope's rim; surfaces meeting in singular curves (two equal cylinders crossing: a
//! cross bore) built exactly (they are left out today); a plane's parabolas
//! and hyperbolas on a cone (B-splines today); a whole sphere or torus as one face with a seam edge (two faces
//! today). The border of an open shell is the surface's curve in the border's plane when the
//! border is planar (a tube's circular ends), a line where it is straight on a plane, the
//! mesh's polyline otherwise (for a cloud's ragged envelope rim across a curved surface: the
//! chain smoothed on the surface, as a spline on it). Measured figures:
//! `docs/experiments/brep.md`.

pub(crate) mod assembly;
pub(crate) mod envelope;
pub(crate) mod intersect;
pub(crate) mod pieces;
pub mod snap;
pub mod step;
pub(crate) mod topology;

use std::collections::BTreeMap;

use serde::Serialize;

use crate::estimate::noise::{noise_ratio, NOISE_K, NOISY_RATIO};
use crate::geometry::surface::{signed_distance, surface_normal};
use crate::geometry::vec3::{cross, dist, dot, norm, normalize, scale, segment_distance, sub};
use crate::geometry::MeshTopology;
use crate::geometry::{face_areas, face_normals, Aabb, Point3, SurfaceParams, TriMesh};
use crate::segment::{neighbours_needed, segment_mesh, segment_points, PointParams, SegmentParams};
use crate::spatial::knn;
use crate::{Error, Result};

pub use step::{to_step, LengthUnit};

/// The largest gap allowed between a vertex or an edge and a surface it lies on, in mean mesh
/// edge lengths: beyond it the surfaces do not meet where the mesh's regions do (a surface
/// missed or mistyped by the segmentation), and the B-rep is refused rather than written
/// invalid.
pub const MAX_GAP: f64 = 0.1;

/// The farthest a vertex may be solved from its mesh vertex, in mean mesh edge lengths: the
/// mesh vertex of a junction lies within the noise and a few edges of it; farther, the surfaces
/// meet elsewhere, not where the mesh's regions do, and the B-rep is refused.
pub const MAX_MOVE: f64 = 10.0;

/// Two surfaces meeting at a vertex with normals this close to parallel (cos 2°) are tangent
/// there (see `tangent_band` in [`build`]).
const TANGENT_COS: f64 = 0.999_390_827;

/// The radius of curvature across a fillet-like surface (cylinder, sphere, torus tube); none
/// for planes and cones.
fn curvature_radius(s: &SurfaceParams) -> Option<f64> {
    match *s {
        SurfaceParams::Cylinder { radius, .. } | SurfaceParams::Sphere { radius, .. } => {
            Some(radius)
        }
        SurfaceParams::Torus { minor_radius, .. } => Some(minor_radius),
        _ => None,
    }
}

/// The sharpest turn, in degrees, a fitted edge's control polygon may take between two legs:
/// away from its ends, an intersection curve sampled finely enough turns by a few degrees per
/// leg (at most 9 on the parts measured); a turn of tens of degrees is a corner of the
/// intersection (the surfaces nearly tangent there: two cylinders of nearly equal radii
/// crossing), and the B-rep is not built with that edge.
pub const MAX_TURN: f64 = 45.0;

/// The 3D curve of an edge.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Curve {
    /// The line through `origin` along the unit `dir`.
    Line {
        /// A point of the line.
        origin: Point3,
        /// Unit direction.
        dir: Point3,
    },
    /// The circle of `radius` about `center` in the plane normal to the unit `axis`; its
    /// parameter starts at `ref_dir` and turns counter-clockwise about `axis`.
    Circle {
        /// Centre.
        center: Point3,
        /// Unit normal of the circle's plane.
        axis: Point3,
        /// Unit direction from the centre to the parameter origin.
        ref_dir: Point3,
        /// Radius.
        radius: f64,
    },
    /// The ellipse about `center` in the plane normal to the unit `axis`, of semi-axes
    /// `semi_major` along the unit `ref_dir` and `semi_minor` along `axis × ref_dir`; its
    /// parameter `t` gives `center + semi_major cos t ref_dir + semi_minor sin t (axis ×
    /// ref_dir)` (STEP's `ELLIPSE`).
    Ellipse {
        /// Centre.
        center: Point3,
        /// Unit normal of the ellipse's plane.
        axis: Point3,
        /// Unit direction of the major axis.
        ref_dir: Point3,
        /// Semi-axis along `ref_dir` (at least `semi_minor`).
        semi_major: f64,
        /// Semi-axis along `axis × ref_dir`.
        semi_minor: f64,
    },
    /// A non-rational B-spline with clamped ends.
    BSpline {
        /// Degree.
        degree: usize,
        /// Control points.
        control_points: Vec<Point3>,
        /// Distinct knot values.
        knots: Vec<f64>,
        /// Multiplicity of each knot value.
        multiplicities: Vec<usize>,
    },
}

impl Curve {
    /// A name for reports: `line`, `circle`, `ellipse`, `bspline`.
    pub fn name(&self) -> &'static str {
        match self {
            Curve::Line { .. } => "line",
            Curve::Circle { .. } => "circle",
            Curve::Ellipse { .. } => "ellipse",
            Curve::BSpline { .. } => "bspline",
        }
    }

    /// A circle or an ellipse as (centre, unit normal, unit major direction, semi-major,
    /// semi-minor); none for the other curves.
    fn conic(&self) -> Option<(Point3, Point3, Point3, f64, f64)> {
        match *self {
            Curve::Circle {
                center,
                axis,
                ref_dir,
                radius,
            } => Some((center, axis, ref_dir, radius, radius)),
            Curve::Ellipse {
                center,
                axis,
                ref_dir,
                semi_major,
                semi_minor,
            } => Some((center, axis, ref_dir, semi_major, semi_minor)),
            _ => None,
        }
    }

    /// The degree-1 B-spline through `points`.
    pub fn polyline(points: Vec<Point3>) -> Curve {
        let n = points.len();
        let mut multiplicities = vec![1; n];
        multiplicities[0] = 2;
        multiplicities[n - 1] = 2;
        Curve::BSpline {
            degree: 1,
            control_points: points,
            knots: (0..n).map(|i| i as f64).collect(),
            multiplicities,
        }
    }

    /// Points along a B-spline (16 per control point, ends included); none for the analytic
    /// curves, which lie on their surfaces exactly.
    pub fn samples(&self) -> Vec<Point3> {
        match self {
            Curve::BSpline {
                degree,
                control_points,
                knots,
                multiplicities,
            } => {
                let (a, b) = (knots[0], knots[knots.len() - 1]);
                let m = 16 * control_points.len();
                let ts = (0..=m).map(|i| a + (b - a) * i as f64 / m as f64);
                intersect::bspline_points(*degree, control_points, knots, multiplicities, ts)
            }
            _ => Vec::new(),
        }
    }

    /// The largest angle, in degrees, between consecutive legs of a B-spline's control polygon
    /// away from its ends (where an interpolating spline may hook; 0 for a line or a circle).
    pub fn max_turn(&self) -> f64 {
        let Curve::BSpline { control_points, .. } = self else {
            return 0.0;
        };
        let n = control_points.len();
        if n < 5 {
            return 0.0;
        }
        control_points[1..n - 1]
            .windows(3)
            .filter_map(|w| {
                let a = normalize(sub(w[1], w[0]))?;
                let b = normalize(sub(w[2], w[1]))?;
                Some(dot(a, b).clamp(-1.0, 1.0).acos().to_degrees())
            })
            .fold(0.0, f64::max)
    }

    /// Distance from `p` to the curve (for a B-spline, to the polygon of its
    /// [`Curve::samples`]).
    pub fn distance(&self, p: Point3) -> f64 {
        match self {
            Curve::Line { origin, dir } => {
                let v = sub(p, *origin);
                norm(cross(v, *dir))
            }
            Curve::Circle {
                center,
                axis,
                radius,
                ..
            } => {
                let v = sub(p, *center);
                let h = dot(v, *axis);
                let rho = (dot(v, v) - h * h).max(0.0).sqrt();
                (rho - radius).hypot(h)
            }
            Curve::Ellipse {
                center,
                axis,
                ref_dir,
                semi_major,
                semi_minor,
            } => {
                let v = sub(p, *center);
                let (x, y) = (dot(v, *ref_dir), dot(v, cross(*axis, *ref_dir)));
                ellipse_distance(*semi_major, *semi_minor, x, y).hypot(dot(v, *axis))
            }
            Curve::BSpline { .. } => self
                .samples()
                .windows(2)
                .map(|w| segment_distance(p, w[0], w[1]))
                .fold(f64::INFINITY, f64::min),
        }
    }
}

/// Distance from `(x, y)` to the ellipse of semi-axes `a ≥ b` along x and y, in its plane:
/// the iteration of the evolute's circle of curvature (Chou, "A simple method for the
/// distance from a point to an ellipse", 2017; robust everywhere), on the quadrant of the
/// point.
fn ellipse_distance(a: f64, b: f64, x: f64, y: f64) -> f64 {
    let (px, py) = (x.abs(), y.abs());
    let (mut tx, mut ty) = (
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
    );
    // (Slow to converge on long thin ellipses: 2e-2 of the minor axis off after 6 steps
    // at a / b = 10⁴, 3e-14 after 40.)
    for _ in 0..40 {
        let (ex, ey) = (
            (a * a - b * b) * tx.powi(3) / a,
            (b * b - a * a) * ty.powi(3) / b,
        );
        let (rx, ry) = (a * tx - ex, b * ty - ey);
        let (qx, qy) = (px - ex, py - ey);
        let (r, q) = (rx.hypot(ry), qx.hypot(qy));
        if q <= 0.0 {
            break;
        }
        tx = ((qx * r / q + ex) / a).clamp(0.0, 1.0);
        ty = ((qy * r / q + ey) / b).clamp(0.0, 1.0);
        let t = tx.hypot(ty);
        tx /= t;
        ty /= t;
    }
    (px - a * tx).hypot(py - b * ty)
}

/// The point of parameter `t` on a conic (see [`Curve::conic`]).
fn conic_point(
    (center, axis, ref_dir, a, b): (Point3, Point3, Point3, f64, f64),
    t: f64,
) -> Point3 {
    let other = cross(axis, ref_dir);
    [0, 1, 2].map(|k| center[k] + a * t.cos() * ref_dir[k] + b * t.sin() * other[k])
}

/// The parameter on a conic of the point `p` on it (or of its projection along the axes).
fn conic_parameter(
    (center, axis, ref_dir, a, b): (Point3, Point3, Point3, f64, f64),
    p: Point3,
) -> f64 {
    let v = sub(p, center);
    (dot(v, cross(axis, ref_dir)) / b).atan2(dot(v, ref_dir) / a)
}

/// An edge: a curve trimmed by two vertices.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BrepEdge {
    /// Start vertex.
    pub start: usize,
    /// End vertex (equal to `start` for a closed edge).
    pub end: usize,
    /// The curve.
    pub curve: Curve,
    /// Whether the edge runs along the curve's parameter (false: against it).
    pub curve_sense: bool,
    /// The face that walks the edge forwards, and the one that walks it backwards (none on
    /// the border of an open shell).
    pub faces: [Option<usize>; 2],
}

/// A face: an analytic surface bounded by loops of oriented edges.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BrepFace {
    /// The surface.
    pub surface: SurfaceParams,
    /// Index of the segmentation surface it lies on.
    pub surface_id: usize,
    /// Whether the surface's normal ([`surface_normal`]) points out of the part.
    pub same_sense: bool,
    /// Loops of (edge, walked forwards); the face lies on the left of each, seen from outside.
    pub loops: Vec<Vec<(usize, bool)>>,
    /// The outer loop, for planar faces.
    pub outer: Option<usize>,
    /// The face's mean surface normal (area-weighted; not unit): where the face lies about an
    /// axis or a centre, so that a writer can keep the parametrisation's seam and poles off it.
    pub direction: Point3,
    /// For a cylinder, cone or torus: where to put the parametrisation's seam (a unit
    /// direction from the axis), in the widest angle around the axis that the face's
    /// boundary does not cross; none when every edge goes all the way round.
    pub seam: Option<Point3>,
    /// RMS distance of the face's mesh vertices (counted once per triangle) to its surface.
    pub rms: f64,
}

/// A boundary representation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Brep {
    /// Vertex positions.
    pub vertices: Vec<Point3>,
    /// Edges.
    pub edges: Vec<BrepEdge>,
    /// Faces.
    pub faces: Vec<BrepFace>,
    /// Whether every edge has a face on both sides (a closed shell: a solid).
    pub closed: bool,
}

/// What the reconstruction found and how well the B-rep fits the input.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BrepReport {
    /// The noise ratio measured on the mesh's vertices ([`noise_ratio`]).
    pub noise_ratio: f64,
    /// How the surfaces were found: `mesh` (Mizoguchi's mesh path) or `vertices` (the point
    /// path over the vertices, for a noisy mesh).
    pub segmentation: &'static str,
    /// Faces per surface type.
    pub faces_by_type: BTreeMap<&'static str, usize>,
    /// Edges per curve type.
    pub edges_by_curve: BTreeMap<&'static str, usize>,
    /// Number of vertices.
    pub vertices: usize,
    /// A solid (closed shell) or an open shell.
    pub closed: bool,
    /// Largest distance of a vertex from one of the surfaces that meet there, and of an
    /// edge's vertices from its curve: the gap a kernel must close (written as the file's
    /// uncertainty).
    pub max_gap: f64,
    /// RMS distance of the mesh vertices to the surfaces of their faces.
    pub rms_distance: f64,
    /// Closed regions cut in two by a plane (whole spheres and tori).
    pub seams: usize,
    /// Relations made exact before building (`snap`).
    pub snaps: Vec<snap::Snap>,
    /// What is missing or approximate, in words.
    pub warnings: Vec<String>,
    /// Regions left out because their surfaces do not meet their neighbours (an open shell).
    pub left_out: Vec<LeftOut>,
    /// The share of the input's area on no surface found, left out (an open shell).
    pub unexplained: f64,
}

/// A B-rep and its report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reconstruction {
    /// The boundary representation.
    pub brep: Brep,
    /// Counts and residuals.
    pub report: BrepReport,
    /// What [`Reconstruction::tessellate`] needs of the mesh the B-rep was read from.
    #[serde(skip)]
    source: TessellationSource,
    /// The tessellation, once made.
    #[serde(skip)]
    tessellation: TessellationCache,
}

/// [`Reconstruction::tessellation`] once made: the curve network, the report's picture and
/// the `--mesh` output each read it. Not part of a reconstruction's value (equal whether made
/// or not).
#[derive(Debug, Clone, Default)]
struct TessellationCache(std::sync::OnceLock<TriMesh>);

impl PartialEq for TessellationCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// What the tessellation of a B-rep needs of the mesh (or envelope) it was read from, kept so
/// that it is made only when asked for.
#[derive(Debug, Clone, PartialEq)]
struct TessellationSource {
    mesh: TriMesh,
    /// Per triangle: its region.
    region_of_face: Vec<u32>,
    /// Per region: its surface and its B-rep face (none: dropped).
    regions: Vec<(SurfaceParams, Option<usize>)>,
    /// Per edge: its chain of mesh vertices and the surfaces it lies on.
    chains: Vec<(Vec<u32>, Vec<SurfaceParams>)>,
    /// Per B-rep vertex: its mesh vertex.
    vertex_mesh: Vec<u32>,
    /// Triangles to turn over (a mesh walked clockwise).
    reversed: bool,
    /// Relax the vertices near the edges (a cloud's envelope).
    relax: bool,
}

impl Reconstruction {
    /// The STEP file of the B-rep (see [`to_step`]) named `name`, in `unit`, with the
    /// uncertainty a kernel needs to close its gaps (see [`Reconstruction::uncertainty`]).
    pub fn to_step(&self, name: &str, unit: LengthUnit) -> String {
        to_step(&self.brep, name, unit, self.uncertainty())
    }

    /// The uncertainty [`Reconstruction::to_step`] writes: twice the largest gap, and never
    /// below the round-off of coordinates of the part (the diagonal of the mesh or envelope
    /// it was built on: points left out, a stray one far away, do not count).
    pub fn uncertainty(&self) -> f64 {
        let size = crate::geometry::Aabb::from_points(&self.source.mesh.vertices.positions)
            .map_or(1.0, |b| b.diagonal());
        (2.0 * self.report.max_gap).max(1e-9 * size)
    }

    /// The B-rep as triangles: the mesh's (or a cloud's envelope's) triangles of each face,
    /// with every vertex put on the B-rep (a vertex's mesh vertex on the solved vertex, an
    /// edge's chain on the surfaces of its faces, the rest on its face's surface; for a cloud,
    /// also drawn in from the edges, which its envelope rounds off), so that faces sharing an
    /// edge share its vertices; per triangle its face (`face`) and surface type
    /// (`surface_type`) as attributes.
    pub fn tessellate(&self) -> Result<TriMesh> {
        self.tessellation().cloned()
    }

    /// [`Reconstruction::tessellate`] without the copy, made once and kept.
    pub fn tessellation(&self) -> Result<&TriMesh> {
        if let Some(mesh) = self.tessellation.0.get() {
            return Ok(mesh);
        }
        let mesh = tessellate(&self.source, &self.brep)?;
        Ok(self.tessellation.0.get_or_init(|| mesh))
    }
}

/// The B-rep of `mesh`, whose triangle `t` lies on `surfaces[face_surface[t]]` (negative:
/// unassigned; such triangles join the nearest region). See the module documentation.
///
/// Errors (`InvalidInput`): a mesh that is not an oriented 2-manifold, no assigned triangle,
/// a closed region on a surface that cannot close, borders that do not form loops.
pub fn brep_from_mesh(
    mesh: &TriMesh,
    face_surface: &[i32],
    surfaces: &[SurfaceParams],
) -> Result<Reconstruction> {
    build_open(mesh, face_surface, surfaces, None)
}

/// Residuals of the data the surfaces were fitted to, when that is not the mesh the topology
/// is read from (a cloud's envelope lies off the part by its dilation radius).
struct Fit {
    /// Per surface: RMS distance, extent, area and centroid of its points.
    stats: Vec<snap::FaceStats>,
    /// RMS distance of every assigned point to its surface.
    rms: f64,
    /// How far from its plane a border chain may stray (RMS) and still be taken as planar, in
    /// mean mesh edges: the rim of a cloud's envelope is ragged by about a grid cell.
    border_flatness: f64,
}

/// The least fraction of a part's area that must remain for an open shell to be written when
/// some of its surfaces do not meet their neighbours (see [`brep_from_mesh`]); with less, the
/// B-rep is refused: the surfaces found are not the part's.
pub const MIN_EXPLAINED: f64 = 0.5;

/// A region left out of the B-rep because its surface does not meet its neighbours'.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeftOut {
    /// Its surface (index into the segmentation's surfaces).
    pub surface: usize,
    /// The surface's type.
    pub kind: &'static str,
    /// Its share of the input's area.
    pub area_fraction: f64,
    /// Its centroid.
    pub near: Point3,
}

/// [`build`]; where the surfaces found do not meet where the mesh's regions do (a free-form
/// patch fitted by a cylinder, a surface missed), the smallest region at each such place is
/// left out and the rest built again, until the B-rep builds: an open shell bounded by the
/// mesh's border where the regions were, each one reported. Refused when less than
/// [`MIN_EXPLAINED`] of the area would remain.
fn build_open(
    mesh: &TriMesh,
    face_surface: &[i32],
    surfaces: &[SurfaceParams],
    fit: Option<&Fit>,
) -> Result<Reconstruction> {
    let nt = mesh.faces.len();
    let areas = face_areas(mesh);
    let total: f64 = areas.iter().sum();
    // The share of the area of the kept triangles.
    let share_of = |keep: &[bool]| -> f64 {
        keep.iter()
            .zip(&areas)
            .filter(|(&k, _)| k)
            .map(|(_, a)| a)
            .sum::<f64>()
            / total
    };
    let mut keep = vec![true; nt];
    let mut left_out: Vec<LeftOut> = Vec::new();
    let mut first: Option<String> = None;
    // Triangles across each edge: only needed when something is left out.
    let neighbours = std::cell::OnceCell::new();
    let neighbours = || neighbours.get_or_init(|| pieces::edge_neighbours(mesh));
    let mut labels_now = face_surface.to_vec();
    // Unassigned triangles that no surface explains (a free-form patch, a missed surface) are
    // left out; the rest fill the strips between regions.
    let mut unexplained = 0.0;
    if fit.is_none() && face_surface.iter().any(|&l| l < 0) {
        let explained = explained_triangles(mesh, face_surface, surfaces, neighbours());
        for (t, e) in explained.iter().enumerate() {
            if !e {
                keep[t] = false;
                unexplained += areas[t];
            }
        }
        if unexplained > 0.0 {
            let remaining = pieces::manifold_piece(mesh, &keep, neighbours());
            let share = remaining.as_deref().map_or(0.0, share_of);
            if share < MIN_EXPLAINED {
                // (A mesh the topology cannot read says so first.)
                topology::check(mesh)?;
                return Err(Error::InvalidInput(format!(
                    "reconstruct: the surfaces found explain {:.0} % of the part (at least {:.0} % \
                     is needed for an open shell): free-form, or its surfaces were not all found",
                    100.0 * share,
                    100.0 * MIN_EXPLAINED
                )));
            }
            if let Some(r) = remaining {
                keep = r;
            }
            unexplained = total * (1.0 - share_of(&keep));
        }
    }
    loop {
        let kept: Vec<u32> = (0..nt as u32).filter(|&t| keep[t as usize]).collect();
        let sub;
        let (part, labels): (&TriMesh, std::borrow::Cow<[i32]>) = if kept.len() == nt {
            (mesh, labels_now.as_slice().into())
        } else {
            sub = compact(
                &mesh.vertices.positions,
                kept.iter().map(|&t| mesh.faces[t as usize]).collect(),
            )?;
            let labels: Vec<i32> = kept.iter().map(|&t| labels_now[t as usize]).collect();
            (&sub, labels.into())
        };
        let refusal = |first: &str, why: String| {
            Error::InvalidInput(format!(
                "reconstruct: {first}, so no valid B-rep can be built{why}; the part's surfaces \
                 were not all found (free-form or too noisy?)"
            ))
        };
        match build(part, &labels, surfaces, fit) {
            Ok(mut rec) => {
                if unexplained > 0.0 {
                    rec.report.warnings.push(format!(
                        "{:.1} % of the part's area lies on no surface found (free-form, or a \
                         surface missed): left out, the B-rep is open there",
                        100.0 * unexplained / total
                    ));
                    rec.report.unexplained = unexplained / total;
                }
                if !left_out.is_empty() {
                    let share: f64 = left_out.iter().map(|l| l.area_fraction).sum();
                    let list: Vec<String> = left_out
                        .iter()
                        .map(|l| {
                            format!(
                                "a {} near ({:.4}, {:.4}, {:.4}), {:.1} % of the area",
                                l.kind,
                                l.near[0],
                                l.near[1],
                                l.near[2],
                                100.0 * l.area_fraction
                            )
                        })
                        .collect();
                    rec.report.warnings.push(format!(
                        "{}; left out {} region(s) whose surfaces do not meet their neighbours \
                         ({:.1} % of the area: {}): the B-rep is open where they were",
                        first.as_deref().unwrap_or_default(),
                        left_out.len(),
                        100.0 * share,
                        list.join("; ")
                    ));
                    rec.report.left_out = left_out;
                }
                return Ok(rec);
            }
            Err(Failure::Error(e)) => {
                return Err(match first {
                    None => e,
                    Some(first) => refusal(&first, format!(" (and without those surfaces: {e})")),
                })
            }
            Err(Failure::Mismatch {
                regions,
                message,
                labels,
            }) => {
                tracing::debug!("leaving out {} region(s): {message}", regions.len());
                let first = first.get_or_insert(message);
                for (&t, l) in kept.iter().zip(labels) {
                    labels_now[t as usize] = l;
                }
                for (surface, triangles) in regions {
                    let (mut area, mut centroid) = (0.0, [0.0; 3]);
                    for &t in &triangles {
                        let t = kept[t as usize] as usize;
                        keep[t] = false;
                        area += areas[t];
                        let c = mesh.faces[t].map(|v| mesh.vertices.positions[v as usize]);
                        for k in 0..3 {
                            centroid[k] += areas[t] * (c[0][k] + c[1][k] + c[2][k]) / 3.0;
                        }
                    }
                    left_out.push(LeftOut {
                        surface,
                        kind: surfaces[surface].kind().name(),
                        area_fraction: area / total,
                        near: scale(centroid, 1.0 / area.max(f64::MIN_POSITIVE)),
                    });
                }
                let remaining = pieces::manifold_piece(mesh, &keep, neighbours());
                let explained: f64 = remaining.as_deref().map_or(0.0, share_of);
                if explained < MIN_EXPLAINED {
                    return Err(refusal(
                        first,
                        format!(
                            " (without the surfaces that do not meet, {:.0} % of the part would \
                             remain; at least {:.0} % is needed for an open shell)",
                            100.0 * explained,
                            100.0 * MIN_EXPLAINED
                        ),
                    ));
                }
                if let Some(r) = remaining {
                    keep = r;
                }
            }
        }
    }
}

/// Per triangle: whether a surface explains it. Assigned triangles are explained; an
/// unassigned one is when a neighbouring explained triangle's surface passes within its
/// longest edge (plus three times the RMS residual of the assigned corners: the noise) of
/// each of its corners (a triangle straddling the edge between two faces), breadth first from
/// the assigned ones, so that the strips the segmentation leaves between faces fill and a
/// free-form patch does not.
fn explained_triangles(
    mesh: &TriMesh,
    face_surface: &[i32],
    surfaces: &[SurfaceParams],
    neighbours: &crate::geometry::Csr,
) -> Vec<bool> {
    let p = &mesh.vertices.positions;
    let (mut sq, mut count) = (0.0, 0usize);
    for (f, &l) in mesh.faces.iter().zip(face_surface) {
        if let Ok(l) = usize::try_from(l) {
            for &v in f {
                sq += signed_distance(&surfaces[l], p[v as usize]).powi(2);
                count += 1;
            }
        }
    }
    let noise = 3.0 * (sq / count.max(1) as f64).sqrt();
    let mut label: Vec<i32> = face_surface.to_vec();
    let mut frontier: Vec<u32> = (0..label.len() as u32)
        .filter(|&t| label[t as usize] >= 0)
        .collect();
    while !frontier.is_empty() {
        let mut claims: Vec<(u32, i32)> = Vec::new();
        for &t in &frontier {
            let l = label[t as usize];
            for &u in neighbours.row(t as usize) {
                if label[u as usize] >= 0 {
                    continue;
                }
                let corners = mesh.faces[u as usize].map(|v| p[v as usize]);
                let reach = noise
                    + (0..3)
                        .map(|k| dist(corners[k], corners[(k + 1) % 3]))
                        .fold(0.0, f64::max);
                let s = &surfaces[l as usize];
                if corners
                    .iter()
                    .all(|&c| signed_distance(s, c).abs() <= reach)
                {
                    claims.push((u, l));
                }
            }
        }
        // The lowest label wins a triangle claimed twice in one round.
        claims.sort_unstable();
        frontier.clear();
        for (u, l) in claims {
            if label[u as usize] < 0 {
                label[u as usize] = l;
                frontier.push(u);
            }
        }
    }
    label.iter().map(|&l| l >= 0).collect()
}

/// Why [`build`] gave no B-rep.
enum Failure {
    /// The surfaces found do not meet where the mesh's regions do: the smallest region at each
    /// place where they fail (its surface and triangles), and what failed (the worst place).
    Mismatch {
        regions: Vec<(usize, Vec<u32>)>,
        message: String,
        /// Per triangle: the surface of its region (unassigned triangles and islands
        /// resolved), for building again without the regions.
        labels: Vec<i32>,
    },
    /// Anything else.
    Error(Error),
}

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        Failure::Error(e)
    }
}

/// [`brep_from_mesh`], with the residuals measured on `fit` when given (else on the mesh).
fn build(
    mesh: &TriMesh,
    face_surface: &[i32],
    surfaces: &[SurfaceParams],
    fit: Option<&Fit>,
) -> std::result::Result<Reconstruction, Failure> {
    if let Some(&bad) = face_surface
        .iter()
        .find(|&&s| s >= 0 && s as usize >= surfaces.len())
    {
        return Err(Error::InvalidArgument(format!(
            "reconstruct: face label {bad} but only {} surfaces",
            surfaces.len()
        ))
        .into());
    }
    let mut topo = topology::topology(mesh, face_surface, surfaces)?;
    let pos = |v: u32| topology::position(mesh, v);
    let size = Aabb::from_points(&mesh.vertices.positions)
        .map(|b| b.diagonal())
        .filter(|d| *d > 0.0)
        .ok_or_else(|| Error::InvalidInput("reconstruct: the mesh has no extent".into()))?;
    let nr = topo.surface_of_region.len();
    tracing::debug!(
        "topology: {nr} regions on surfaces {:?}, {} edges {:?}, {} vertices",
        topo.surface_of_region,
        topo.edges.len(),
        topo.edges
            .iter()
            .map(|e| (e.left, e.right, e.start, e.end, e.chain.len()))
            .collect::<Vec<_>>(),
        topo.vertices.len()
    );
    // Relations within the noise made exact (module `snap`).
    let (surfaces, snaps, stats) = snap_surfaces(mesh, &topo, surfaces, size, fit);
    let surfaces = &surfaces[..];
    let surface_of_region = topo.surface_of_region.clone();
    let cuts = topo.cuts.clone();
    let region_surface = |r: u32| -> Option<SurfaceParams> {
        (r != topology::OUTSIDE).then(|| surfaces[surface_of_region[r as usize]])
    };
    // The surfaces an edge lies on: its two regions' (a cut's plane where both are one surface).
    let edge_surfaces = |l: u32, r: u32| -> Vec<SurfaceParams> {
        let mut v = Vec::new();
        if let Some(a) = region_surface(l) {
            v.push(a);
        }
        if r != topology::OUTSIDE {
            if surface_of_region[l as usize] == surface_of_region[r as usize] {
                if let Some(&(_, _, plane)) = cuts
                    .iter()
                    .find(|c| (c.0 == l && c.1 == r) || (c.0 == r && c.1 == l))
                {
                    v.push(plane);
                }
            } else if let Some(b) = region_surface(r) {
                v.push(b);
            }
        }
        v
    };

    // Vertices from every surface meeting there; then the edges whose two ends coincide (faces
    // that touch in a point, as a plane touches a fillet's corner ball) are removed and their
    // ends merged, and the merged vertices solved again.
    let (mut at_vertex, mut vertices) = solve_vertices(&topo, &edge_surfaces, &pos);
    let spacing = crate::geometry::cleanup::mean_edge_length(&mesh.vertices.positions, &mesh.faces);
    // A mesh's planar border is planar to a tenth of an edge.
    let border_flatness = fit.map_or(0.1, |f| f.border_flatness);
    let tol = 0.1 * spacing;
    // (Only when the mesh has the whole edge within `MAX_MOVE` of that point: a long chain
    // whose ends solve to one point is surfaces meeting elsewhere, which the checks below
    // catch, not a point contact.)
    let drop: Vec<bool> = topo
        .edges
        .iter()
        .map(|e| {
            let p = vertices[e.start];
            e.start != e.end
                && dist(p, vertices[e.end]) < tol
                && e.chain
                    .iter()
                    .all(|&v| dist(pos(v), p) <= MAX_MOVE * spacing)
        })
        .collect();
    if drop.contains(&true) {
        tracing::debug!(
            "edges collapsed (their ends solved within {tol:.3e}): {:?}",
            (0..drop.len()).filter(|&e| drop[e]).collect::<Vec<_>>()
        );
        topo.collapse_edges(&drop);
        (at_vertex, vertices) = solve_vertices(&topo, &edge_surfaces, &pos);
    }
    // A region left without edges is gone (a ball touching a face in a point leaves a sliver);
    // one wider than `MAX_MOVE` each way cannot have shrunk to a point: its surface does not
    // meet its neighbours where the mesh says.
    let mut extent: Vec<Option<Aabb>> = vec![None; nr];
    for (t, f) in mesh.faces.iter().enumerate() {
        let b = &mut extent[topo.region_of_face[t] as usize];
        for &v in f {
            match b {
                Some(b) => b.grow(pos(v)),
                None => *b = Aabb::from_points(&[pos(v)]),
            }
        }
    }
    let vanished: Vec<u32> = (0..nr as u32)
        .filter(|&r| {
            topo.loops[r as usize].is_empty()
                && extent[r as usize].is_some_and(|b| b.diagonal() > 2.0 * MAX_MOVE * spacing)
        })
        .collect();
    // The largest gap, and where: a point and the surfaces that should meet there.
    let mut max_gap: f64 = 0.0;
    let mut worst = String::new();
    let mut note = |gap: f64, at: Point3, surfs: &[SurfaceParams], max_gap: &mut f64| {
        if gap > *max_gap {
            *max_gap = gap;
            let kinds: Vec<&str> = surfs.iter().map(|s| s.kind().name()).collect();
            worst = format!(
                "near ({:.4}, {:.4}, {:.4}), where the {} meet",
                at[0],
                at[1],
                at[2],
                kinds.join(", ")
            );
        }
    };
    // Where the surfaces do not meet (a vertex or an edge off its surfaces by more than
    // `MAX_GAP` edges, a vertex solved more than `MAX_MOVE` edges from its mesh vertex): the
    // regions there.
    let limit = MAX_GAP * spacing;
    let mut failing: Vec<Vec<u32>> = vanished.iter().map(|&r| vec![r]).collect();
    let mut corner: Option<String> = None;
    let mut around: Vec<Vec<u32>> = vec![Vec::new(); vertices.len()];
    for e in &topo.edges {
        for v in [e.start, e.end] {
            for r in [e.left, e.right] {
                if r != topology::OUTSIDE && !around[v].contains(&r) {
                    around[v].push(r);
                }
            }
        }
    }
    // Where two of a vertex's surfaces are tangent (a fillet's border), the mesh's regions meet
    // anywhere in the band where they lie within the noise of each other: a curved surface of
    // radius ρ leaves its tangent plane by 3 RMS residuals at √(2 ρ · 3 rms) from the tangent
    // line (0.05 on a fillet of radius 0.1 under noise of 0.004, where the regions' border
    // lay 11 mesh edges up the arc). A vertex may be solved that much farther from its mesh
    // vertex.
    let tangent_band = |regions: &[u32], p: Point3| -> f64 {
        let ids: Vec<usize> = regions
            .iter()
            .map(|&r| surface_of_region[r as usize])
            .collect();
        let mut band: f64 = 0.0;
        for &a in &ids {
            for &c in &ids {
                let Some(rho) = curvature_radius(&surfaces[c]) else {
                    continue;
                };
                if a == c
                    || dot(
                        surface_normal(&surfaces[a], p),
                        surface_normal(&surfaces[c], p),
                    )
                    .abs()
                        < TANGENT_COS
                {
                    continue;
                }
                let d = 3.0 * stats[a].rms.max(stats[c].rms);
                band = band.max((2.0 * rho * d).sqrt());
            }
        }
        band
    };
    // The first vertex solved far from its mesh vertex, and how far.
    let mut moved_far: Option<(usize, f64)> = None;
    let mut vertex_fails = vec![false; vertices.len()];
    for (v, (p, surfs)) in vertices.iter().zip(&at_vertex).enumerate() {
        let mesh_vertex = pos(topo.vertices[v]);
        let mut gap: f64 = 0.0;
        for s in surfs {
            let d = signed_distance(s, *p).abs();
            note(d, mesh_vertex, surfs, &mut max_gap);
            gap = gap.max(d);
        }
        let moved = dist(*p, mesh_vertex);
        let allowed = MAX_MOVE * spacing + tangent_band(&around[v], *p);
        if moved > allowed && moved_far.is_none() {
            moved_far = Some((v, moved));
        }
        if gap > limit || moved > allowed {
            failing.push(around[v].clone());
            vertex_fails[v] = true;
        }
    }

    // Edges.
    let mut warnings = Vec::new();
    let mut border_edges = 0;
    let mut edges = Vec::with_capacity(topo.edges.len());
    for e in &topo.edges {
        let surfs = edge_surfaces(e.left, e.right);
        let (p0, p1) = (vertices[e.start], vertices[e.end]);
        let analytic = match surfs.as_slice() {
            [a, b] => intersect::analytic_curve(a, b, p0, p1, size),
            // A border that lies in a plane (a tube cut square, a scan's planar rim): the
            // surface's intersection with that plane, where it reaches the end vertex (else
            // the border is not that curve: a line or the spline below).
            // (A plane's planar border lies in the plane itself.)
            [a] => (!matches!(a, SurfaceParams::Plane { .. }))
                .then(|| border_plane(&e.chain, &pos, border_flatness * spacing))
                .flatten()
                .map(|plane| square_to_axis(plane, a, &e.chain, &pos, border_flatness * spacing))
                .and_then(|plane| intersect::analytic_curve(a, &plane, p0, p1, size))
                .filter(|c| c.distance(p1) <= limit)
                .or_else(|| border_line(a, &e.chain, &pos, p0, p1, spacing)),
            _ => None,
        };
        let conic = analytic.as_ref().and_then(Curve::conic);
        let (curve, curve_sense) = match (analytic, conic) {
            (Some(c @ Curve::Line { .. }), _) => (c, true),
            (Some(c), Some((center, axis, ref_dir, _, _))) => {
                // The way the whole chain turns about the axis (its first step alone may
                // point back on a jagged mesh such as a cloud's envelope).
                let sense = turning(center, axis, ref_dir, e.chain.iter().map(|&v| pos(v))) >= 0.0;
                (c, sense)
            }
            _ => {
                let n = e.chain.len();
                let mut pts = Vec::with_capacity(n);
                pts.push(p0);
                for &v in &e.chain[1..n - 1] {
                    pts.push(intersect::on_surfaces(&surfs, pos(v)));
                }
                pts.push(p1);
                if let [a, b] = surfs[..] {
                    // March along the exact intersection where the chain leads; the chain's
                    // own points, thinned, where the march fails.
                    let length: f64 = pts.windows(2).map(|w| dist(w[0], w[1])).sum();
                    let step = length / (length / spacing).clamp(16.0, 200.0);
                    let along = intersect::march(&a, &b, p0, p1, &pts, step)
                        .unwrap_or_else(|| thin_chain(&pts, spacing));
                    (spline_on(&surfs, along, spacing), true)
                } else if fit.is_some()
                    && !matches!(surfs[..], [SurfaceParams::Plane { .. }])
                    && pts.len() > 3
                {
                    // A cloud's rim across a curved surface: the envelope's ragged chain,
                    // smoothed on the surface, as a spline on it (a polyline leaves the surface
                    // between its points, and its zigzags fold the face).
                    let smooth = smooth_on(&surfs, pts, 3);
                    (
                        spline_on(&surfs, thin_chain(&smooth, spacing), spacing),
                        true,
                    )
                } else {
                    (Curve::polyline(pts), true)
                }
            }
        };
        let mut gap = curve.distance(p0).max(curve.distance(p1));
        // (Reported where the mesh has the edge: the curve may stray far from it.)
        let at = pos(e.chain[e.chain.len() / 2]);
        note(curve.distance(p0), at, &surfs, &mut max_gap);
        note(curve.distance(p1), at, &surfs, &mut max_gap);
        // A fitted curve leaves its surfaces between its points.
        for q in curve.samples() {
            for sf in &surfs {
                let d = signed_distance(sf, q).abs();
                note(d, at, &surfs, &mut max_gap);
                gap = gap.max(d);
            }
        }
        // A spline that turns sharply between two control points follows a corner of the
        // intersection (surfaces nearly tangent there, as two equal cylinders crossing),
        // which it cannot represent, nor a kernel project onto the surfaces.
        // (A border's polyline may turn: only an intersection is checked.)
        let turn = if surfs.len() == 2 {
            curve.max_turn()
        } else {
            0.0
        };
        if turn > MAX_TURN && corner.is_none() {
            let kinds: Vec<&str> = surfs.iter().map(|s| s.kind().name()).collect();
            corner = Some(format!(
                "near ({:.4}, {:.4}, {:.4}), the {} meet in a curve with a corner (a turn of \
                 {turn:.0} degrees between two control points of its spline, at most {MAX_TURN}; \
                 the surfaces are nearly tangent there)",
                p0[0],
                p0[1],
                p0[2],
                kinds.join(", ")
            ));
        }
        // An edge from a failing vertex fails there: the blame is the vertex's place's (a
        // small torus where two large planes meet, the planes' edge off by the torus's gap).
        let from_failing = vertex_fails[e.start] || vertex_fails[e.end];
        if (gap > limit || turn > MAX_TURN) && !from_failing {
            tracing::debug!(
                "edge {}-{} between regions {} and {} fails: gap {gap:.3e}, turn {turn:.1}",
                e.start,
                e.end,
                e.left,
                e.right
            );
            failing.push(
                [e.left, e.right]
                    .into_iter()
                    .filter(|&r| r != topology::OUTSIDE)
                    .collect(),
            );
        }
        if e.right == topology::OUTSIDE {
            border_edges += 1;
        }
        edges.push(BrepEdge {
            start: e.start,
            end: e.end,
            curve,
            curve_sense,
            faces: [
                Some(e.left as usize),
                (e.right != topology::OUTSIDE).then_some(e.right as usize),
            ],
        });
    }
    // A line from a vertex to itself bounds nothing: the chain between two regions closed on
    // itself where the intersection was taken for a line (on the Kinect scene a thin pole's
    // cylinder against the table had such an edge for its only loop, and OpenCASCADE read
    // the face as the whole infinite cylinder: valid, area 4e98). And a cylinder face bounded
    // by a single loop around its axis runs to infinity on one side. Their regions go.
    for e in &edges {
        if matches!(e.curve, Curve::Line { .. }) && e.start == e.end {
            failing.push(e.faces.iter().flatten().map(|&r| r as u32).collect());
            if corner.is_none() {
                let at = vertices[e.start];
                corner = Some(format!(
                    "near ({:.4}, {:.4}, {:.4}), an edge closes on itself as a straight line",
                    at[0], at[1], at[2]
                ));
            }
        }
    }
    // And a loop that goes more than once around the axis of a cylinder or cone and back
    // bounds no face: its parameter domain overlaps itself (on a Kinect scene a can's
    // cylinder had one spanning 520°: OpenCASCADE reads a self-intersecting wire).
    for r in 0..nr {
        let (o, d, cylinder) = match surfaces[surface_of_region[r]] {
            SurfaceParams::Cylinder {
                axis_point,
                axis_dir,
                ..
            } => (axis_point, axis_dir, true),
            SurfaceParams::Cone { apex, axis_dir, .. } => (apex, axis_dir, false),
            _ => continue,
        };
        let turns: Vec<(i64, f64)> = topo.loops[r]
            .iter()
            .map(|l| winding(l, &edges, &vertices, o, d))
            .collect();
        if turns
            .iter()
            .any(|&(w, span)| w == 0 && span >= std::f64::consts::TAU)
        {
            failing.push(vec![r as u32]);
            if corner.is_none() {
                let at = extent[r].map_or([0.0; 3], |b| b.center());
                corner = Some(format!(
                    "near ({:.4}, {:.4}, {:.4}), a loop goes around the axis of a {} and back",
                    at[0],
                    at[1],
                    at[2],
                    if cylinder { "cylinder" } else { "cone" }
                ));
            }
        }
        let rings = turns.iter().filter(|&&(w, _)| w != 0).count();
        if cylinder && rings == 1 {
            failing.push(vec![r as u32]);
            if corner.is_none() {
                let at = extent[r].map_or([0.0; 3], |b| b.center());
                corner = Some(format!(
                    "near ({:.4}, {:.4}, {:.4}), a cylinder is bounded at one end only",
                    at[0], at[1], at[2]
                ));
            }
        }
    }
    // Two straight edges of one face on top of each other: the loop runs over the same
    // stretch twice and bounds no area there (on the Kinect scene a narrow box side met the
    // next box face along a short edge whose vertices, where the scan's border comes in, were
    // solved onto the long edge the side shares with another face). A vertex merely touching
    // another edge (a kernel accepts that) is not an overlap: the edge must run along it.
    for r in 0..nr {
        if let Some(p) = overlapping_lines(&topo.loops[r], &edges, &vertices, 0.01 * spacing) {
            failing.push(vec![r as u32]);
            if corner.is_none() {
                corner = Some(format!(
                    "near ({:.4}, {:.4}, {:.4}), two edges of a face run on top of each other",
                    p[0], p[1], p[2]
                ));
            }
        }
    }
    // A vertex solved far from where the mesh has it: the surfaces meet, but elsewhere (two
    // nearly coaxial cylinders cross far away).
    let areas = face_areas(mesh);
    if !failing.is_empty() {
        let message = match moved_far {
            Some((v, moved)) => {
                let at = pos(topo.vertices[v]);
                let kinds: Vec<&str> = at_vertex[v].iter().map(|s| s.kind().name()).collect();
                format!(
                    "near ({:.4}, {:.4}, {:.4}), the {} meet {moved:.3e} away ({:.1} mesh edges, \
                     at most {MAX_MOVE} allowed)",
                    at[0],
                    at[1],
                    at[2],
                    kinds.join(", "),
                    moved / spacing
                )
            }
            None if max_gap > limit => format!(
                "{worst}, a vertex or an edge lies {max_gap:.3e} from one of them ({:.2} mesh \
                 edges, at most {MAX_GAP} allowed)",
                max_gap / spacing
            ),
            None => match vanished.first() {
                Some(&r) => {
                    let at = extent[r as usize].map_or([0.0; 3], |b| b.center());
                    format!(
                        "near ({:.4}, {:.4}, {:.4}), the edges of a {} face all shrink to points",
                        at[0],
                        at[1],
                        at[2],
                        surfaces[surface_of_region[r as usize]].kind().name()
                    )
                }
                None => corner.unwrap_or_default(),
            },
        };
        // The smallest region at each place: the surface with the least evidence.
        let mut region_area = vec![0.0; nr];
        for (t, &r) in topo.region_of_face.iter().enumerate() {
            region_area[r as usize] += areas[t];
        }
        let mut out = vec![false; nr];
        for regions in &failing {
            if let Some(&r) = regions
                .iter()
                .min_by(|&&a, &&b| region_area[a as usize].total_cmp(&region_area[b as usize]))
            {
                out[r as usize] = true;
            }
        }
        for r in (0..nr).filter(|&r| out[r]) {
            tracing::debug!(
                "leaving out region {r} (surface {}, a {}, area {:.3e})",
                surface_of_region[r],
                surfaces[surface_of_region[r]].kind().name(),
                region_area[r]
            );
        }
        let mut triangles: Vec<Vec<u32>> = vec![Vec::new(); nr];
        for (t, &r) in topo.region_of_face.iter().enumerate() {
            if out[r as usize] {
                triangles[r as usize].push(t as u32);
            }
        }
        let regions = triangles
            .into_iter()
            .enumerate()
            .filter(|(_, t)| !t.is_empty())
            .map(|(r, t)| (topo.surface_of_region[r], t))
            .collect();
        let labels = topo
            .region_of_face
            .iter()
            .map(|&r| topo.surface_of_region[r as usize] as i32)
            .collect();
        return Err(Failure::Mismatch {
            labels,
            regions,
            message: format!(
                "the surfaces found do not meet where the mesh says they do: {message}"
            ),
        });
    }
    if border_edges > 0 {
        warnings.push(format!(
            "the B-rep has an open border ({border_edges} edges with a face on one side only): \
             written as an open shell, not a solid"
        ));
    }

    // Faces: orientation from the mesh, residuals of the mesh vertices.
    let normals = face_normals(mesh);
    let mut orient = vec![0.0; nr];
    let mut direction = vec![[0.0; 3]; nr];
    for (t, f) in mesh.faces.iter().enumerate() {
        let r = topo.region_of_face[t] as usize;
        let s = surfaces[topo.surface_of_region[r]];
        let c = [0, 1, 2].map(|k| (pos(f[0])[k] + pos(f[1])[k] + pos(f[2])[k]) / 3.0);
        let sn = surface_normal(&s, c);
        orient[r] += areas[t] * dot(normals[t], sn);
        for k in 0..3 {
            direction[r][k] += areas[t] * sn[k];
        }
    }
    let (mut sq, mut count) = (0.0, 0usize);
    let (mut face_sq, mut face_count) = (vec![0.0; nr], vec![0usize; nr]);
    let mut seen = vec![false; mesh.vertices.positions.len()];
    for (t, f) in mesh.faces.iter().enumerate() {
        let r = topo.region_of_face[t] as usize;
        let s = surfaces[topo.surface_of_region[r]];
        for &v in f {
            let d = signed_distance(&s, pos(v));
            face_sq[r] += d * d;
            face_count[r] += 1;
            if !std::mem::replace(&mut seen[v as usize], true) {
                sq += d * d;
                count += 1;
            }
        }
    }
    let faces: Vec<BrepFace> = (0..nr)
        .map(|r| {
            let surface = surfaces[topo.surface_of_region[r]];
            let loops = topo.loops[r].clone();
            let outer = match surface {
                SurfaceParams::Plane { normal, .. } => loops
                    .iter()
                    .enumerate()
                    .map(|(i, l)| (i, loop_area(l, &edges, &vertices, normal).abs()))
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(i, _)| i),
                _ => None,
            };
            BrepFace {
                surface,
                surface_id: topo.surface_of_region[r],
                same_sense: orient[r] >= 0.0,
                loops,
                outer,
                direction: direction[r],
                seam: seam_direction(&surface, &topo.loops[r], &edges, &vertices),
                rms: match fit {
                    Some(f) => f.stats[topo.surface_of_region[r]].rms,
                    None => (face_sq[r] / face_count[r].max(1) as f64).sqrt(),
                },
            }
        })
        .collect();
    // A face whose every edge was collapsed (a ball touching a face in a point) is gone.
    let mut face_of_region = vec![None; nr];
    for (r, id) in (0..nr)
        .filter(|&r| !topo.loops[r].is_empty())
        .enumerate()
        .map(|(id, r)| (r, id))
    {
        face_of_region[r] = Some(id);
    }
    let (faces, edges) = drop_empty_faces(faces, edges);
    let shells = assembly::shells(faces.len(), &edges).len();
    if shells > 1 {
        return Err(Error::InvalidInput(format!(
            "reconstruct: the faces found form {shells} separate shells where the input is one \
             piece (the surfaces found do not meet where the mesh says they do; too noisy?)"
        ))
        .into());
    }
    let closed = border_edges == 0;
    let mut brep = Brep {
        vertices,
        edges,
        faces,
        closed,
    };
    // A closed mesh walked clockwise from outside (negative volume) gives a part inside out.
    let reversed = closed && signed_volume(mesh) < 0.0;
    if reversed {
        brep.reverse();
    }
    let source = TessellationSource {
        mesh: mesh.clone(),
        region_of_face: topo.region_of_face.clone(),
        regions: (0..nr)
            .map(|r| (surfaces[topo.surface_of_region[r]], face_of_region[r]))
            .collect(),
        chains: topo
            .edges
            .iter()
            .map(|e| (e.chain.clone(), edge_surfaces(e.left, e.right)))
            .collect(),
        vertex_mesh: topo.vertices.clone(),
        reversed,
        relax: fit.is_some(),
    };
    let mut faces_by_type = BTreeMap::new();
    for f in &brep.faces {
        *faces_by_type.entry(f.surface.kind().name()).or_insert(0) += 1;
    }
    let mut edges_by_curve = BTreeMap::new();
    for e in &brep.edges {
        *edges_by_curve.entry(e.curve.name()).or_insert(0) += 1;
    }
    let report = BrepReport {
        noise_ratio: 0.0,
        segmentation: "given",
        faces_by_type,
        edges_by_curve,
        vertices: brep.vertices.len(),
        closed,
        max_gap,
        rms_distance: match fit {
            Some(f) => f.rms,
            None => (sq / count.max(1) as f64).sqrt(),
        },
        seams: topo.cuts.len(),
        snaps,
        warnings,
        left_out: Vec::new(),
        unexplained: 0.0,
    };
    Ok(Reconstruction {
        brep,
        report,
        source,
        tessellation: TessellationCache::default(),
    })
}

/// `p` put on all of `surfs` (a single surface: along its normal; none: `p`).
fn onto(surfs: &[SurfaceParams], p: Point3) -> Point3 {
    match surfs {
        [] => p,
        [s] => {
            let q = sub(p, scale(surface_normal(s, p), signed_distance(s, p)));
            // (A cone's or torus's normal step lands near it: finish on the surface.)
            if signed_distance(s, q).abs() > 1e-12 * (1.0 + norm(p)) {
                intersect::on_surfaces(surfs, q)
            } else {
                q
            }
        }
        _ => intersect::on_surfaces(surfs, p),
    }
}

/// Rounds of relaxation of a cloud's tessellation (see `tessellate`): the envelope's rounded
/// edges are a few grid cells wide.
const RELAX_ROUNDS: usize = 30;

/// How many rings of vertices around a cloud's edges relax (see `tessellate`): the envelope's
/// rounded edges are a few grid cells wide.
const RELAX_RINGS: usize = 8;

/// [`Reconstruction::tessellate`].
fn tessellate(source: &TessellationSource, brep: &Brep) -> Result<TriMesh> {
    use rayon::prelude::*;
    let mesh = &source.mesh;
    let positions = &mesh.vertices.positions;
    // Per mesh vertex: the surfaces it lies on (none yet: unused).
    let mut on: Vec<Vec<SurfaceParams>> = vec![Vec::new(); positions.len()];
    for (t, f) in mesh.faces.iter().enumerate() {
        let r = source.region_of_face[t] as usize;
        for &v in f {
            if on[v as usize].is_empty() {
                on[v as usize] = vec![source.regions[r].0];
            }
        }
    }
    for (chain, surfs) in &source.chains {
        for &v in chain {
            on[v as usize].clone_from(surfs);
        }
    }
    let mut placed: Vec<Point3> = positions
        .par_iter()
        .zip(&on)
        .map(|(&p, surfs)| onto(surfs, p))
        .collect();
    for (&mv, &p) in source.vertex_mesh.iter().zip(&brep.vertices) {
        placed[mv as usize] = p;
    }
    if source.relax {
        // A face's vertices near its edges, put on its surface, overshoot the edge (the
        // envelope rounds the part's edges off): each is moved to the mean of its neighbours on
        // the surface, edges and vertices fixed, until the flaps are drawn in.
        // (An edge's chain relaxes along the chain, on its curve, between its fixed ends.) Only
        // the vertices within `RELAX_RINGS` rings of an edge move: farther in, a face's vertices
        // already lie inside it.
        let mut around: Vec<Vec<u32>> = vec![Vec::new(); positions.len()];
        for f in &mesh.faces {
            for k in 0..3 {
                let (a, b) = (f[k], f[(k + 1) % 3]);
                around[a as usize].push(b);
                around[b as usize].push(a);
            }
        }
        let mut ring = vec![usize::MAX; positions.len()];
        let mut band: Vec<u32> = Vec::new();
        for (chain, _) in &source.chains {
            for &v in chain {
                if ring[v as usize] == usize::MAX {
                    ring[v as usize] = 0;
                    band.push(v);
                }
            }
        }
        let mut frontier = band.clone();
        for r in 1..=RELAX_RINGS {
            let mut next = Vec::new();
            for &v in &frontier {
                for &u in &around[v as usize] {
                    if ring[u as usize] == usize::MAX {
                        ring[u as usize] = r;
                        next.push(u);
                    }
                }
            }
            band.extend_from_slice(&next);
            frontier = next;
        }
        for (chain, _) in &source.chains {
            for w in chain.windows(3) {
                around[w[1] as usize] = vec![w[0], w[2]];
            }
        }
        for &v in &source.vertex_mesh {
            around[v as usize].clear();
        }
        band.sort_unstable();
        for _ in 0..RELAX_ROUNDS {
            let moved: Vec<Point3> = band
                .par_iter()
                .map(|&v| {
                    let v = v as usize;
                    if around[v].is_empty() || on[v].is_empty() {
                        return placed[v];
                    }
                    let mut c = [0.0; 3];
                    for &u in &around[v] {
                        c = crate::geometry::vec3::add(c, placed[u as usize]);
                    }
                    onto(&on[v], scale(c, 1.0 / around[v].len() as f64))
                })
                .collect();
            for (&v, p) in band.iter().zip(moved) {
                placed[v as usize] = p;
            }
        }
    }
    let mut faces = Vec::with_capacity(mesh.faces.len());
    let mut face_id = Vec::with_capacity(mesh.faces.len());
    for (t, f) in mesh.faces.iter().enumerate() {
        if let Some(id) = source.regions[source.region_of_face[t] as usize].1 {
            faces.push(if source.reversed {
                [f[0], f[2], f[1]]
            } else {
                *f
            });
            face_id.push(id);
        }
    }
    let mut out = compact(&placed, faces)?;
    out.set_face_attribute(crate::geometry::Attribute::int(
        "face",
        face_id.iter().map(|&f| f as i64),
    ))?;
    out.set_face_attribute(crate::geometry::Attribute {
        name: "surface_type".into(),
        kind: crate::geometry::ScalarKind::U8,
        values: face_id
            .iter()
            .map(|&f| f64::from(brep.faces[f].surface.kind().code()))
            .collect(),
    })?;
    Ok(out)
}

/// The B-rep of a triangle mesh: its segmentation into analytic surfaces, then
/// [`brep_from_mesh`].
///
/// The mesh path ([`segment_mesh`]) first. When it leaves more than half of the triangles
/// unassigned and the vertices are measured noisy ([`noise_ratio`] above [`NOISY_RATIO`]: a
/// scan's mesh), the mesh is segmented again as a cloud of its vertices ([`segment_points`],
/// whose tolerances follow the measured noise; the mesh path's Bézier curvature marks most
/// vertices of such a mesh sharp and finds few seeds), each triangle taking the surface of two
/// or three of its corners. (The noise measure alone cannot decide: on a coarse CAD mesh the
/// seven nearest vertices span several faces and read as noise.)
///
/// Errors: those of the segmentation and of [`brep_from_mesh`].
pub fn reconstruct_mesh(mesh: &TriMesh, params: &SegmentParams) -> Result<Reconstruction> {
    let topo = MeshTopology::new(mesh)?;
    let seg = segment_mesh(mesh, &topo, params)?;
    drop(topo);
    reconstruct_segmented_mesh(mesh, seg, params)
}

/// [`reconstruct_mesh`] from the mesh path's segmentation `seg` of `mesh` (made with
/// `params`), when the caller has it already (`crease run`).
pub fn reconstruct_segmented_mesh(
    mesh: &TriMesh,
    seg: crate::segment::Segmentation,
    params: &SegmentParams,
) -> Result<Reconstruction> {
    let positions = &mesh.vertices.positions;
    let assigned = seg.face_surface.iter().filter(|&&s| s >= 0).count();
    let noise = if positions.len() > neighbours_needed(&PointParams::default(), false) {
        noise_ratio(positions, &knn(positions, NOISE_K)?)
    } else {
        0.0
    };
    let (labels, surfaces, how) = if 2 * assigned >= mesh.faces.len() || noise <= NOISY_RATIO {
        let surfaces: Vec<SurfaceParams> = seg.surfaces.iter().map(|s| s.params).collect();
        (seg.face_surface, surfaces, "mesh")
    } else {
        // PCA normals over 20 neighbours: the noisy mesh's own vertex normals (its one-ring)
        // average too few points.
        let seg = segment_points(positions, None, params, &PointParams::default())?;
        let labels = face_labels_from_vertices(&mesh.faces, &seg.point_surface);
        let surfaces: Vec<SurfaceParams> = seg.surfaces.iter().map(|s| s.params).collect();
        (labels, surfaces, "vertices")
    };
    let mut labels = labels;
    let merges = snap::merge_indistinct(
        positions,
        &mesh.faces,
        &face_areas(mesh),
        &mut labels,
        &surfaces,
    );
    let mut rec = brep_from_mesh(mesh, &labels, &surfaces)?;
    rec.report.snaps.splice(0..0, merges);
    rec.report.noise_ratio = noise;
    rec.report.segmentation = how;
    Ok(rec)
}

/// The dilation radius of a cloud's envelope, in units of the 90th percentile of the distance
/// from a point to its [`ENVELOPE_NEIGHBOUR`]-th neighbour: wide enough to close the gaps of a
/// random sampling (the largest empty disc among a million uniform samples has about twice
/// their spacing for radius), narrow enough to keep holes and slots a few spacings wide open.
pub const ENVELOPE_RADIUS: f64 = 1.5;

/// The neighbour whose distance measures the sampling for [`ENVELOPE_RADIUS`].
pub const ENVELOPE_NEIGHBOUR: usize = 8;

/// A piece of a cloud that falls apart is built on the envelope's grid when its samples span at
/// least this many of its cells (the grid is sized to the whole cloud, at most
/// `envelope::MAX_CELLS` along its box): narrower, its envelope is a blob a few cells wide that
/// cannot carry its faces, and it is made again on a grid of its own samples (a part beside a
/// far outlier); a piece still that narrow there (the outlier) is left out.
pub const MIN_PIECE_CELLS: f64 = 8.0;

/// The B-rep of a point cloud, from its shared analysis (segmentation, neighbours).
///
/// A cloud has no triangles to read faces and edges from, so it is given some: its envelope
/// (module `envelope`), the closed surface of the cloud dilated by [`ENVELOPE_RADIUS`] times
/// its sampling distance, whose triangles take the surface of the samples nearest them (the
/// majority of the 8 nearest assigned ones). The regions the point segmentation cannot tell
/// from their neighbours are first dissolved into them ([`snap`]), on the points. Then
/// [`brep_from_mesh`] on the envelope, with the residuals measured on the points: every
/// vertex and edge comes from the surfaces, none from the envelope. An envelope in several
/// pieces gives a B-rep of several shells, the pieces that cannot be built left out.
///
/// Errors: those of the segmentation and of [`brep_from_mesh`]; a cloud with no surface found;
/// a cloud in pieces whose pieces built cover less than [`MIN_EXPLAINED`] of its envelope.
pub fn reconstruct_cloud(analysis: &crate::analysis::CloudAnalysis) -> Result<Reconstruction> {
    use rayon::prelude::*;
    let points = analysis.points();
    let nbrs = analysis.neighbours()?;
    let seg = analysis.segmentation()?;
    let surfaces: Vec<SurfaceParams> = seg.surfaces.iter().map(|s| s.params).collect();
    if surfaces.is_empty() {
        return Err(Error::InvalidInput(
            "reconstruct: no analytic surface was found in the cloud (a free-form object, or \
             too few points)"
                .into(),
        ));
    }
    let mut labels = seg.point_surface.clone();
    let merges = snap::merge_indistinct_points(
        points,
        &seg.point_area,
        nbrs,
        ENVELOPE_NEIGHBOUR,
        &mut labels,
        &surfaces,
    );
    // The sampling distance: the 90th percentile of the distance to the 8th neighbour.
    let kth = ENVELOPE_NEIGHBOUR.min(nbrs.k());
    let mut far: Vec<f64> = (0..points.len())
        .into_par_iter()
        .map(|i| {
            nbrs.prefix(i, kth)
                .last()
                .map_or(0.0, |&j| dist(points[i], points[j as usize]))
        })
        .collect();
    far.par_sort_unstable_by(f64::total_cmp);
    let sampling = far[(far.len() * 9 / 10).min(far.len() - 1)];
    let radius = ENVELOPE_RADIUS * sampling;
    let index = crate::spatial::KdIndex::new(points)
        .ok_or_else(|| Error::InvalidInput("reconstruct: no points".into()))?;
    let env = envelope::envelope(points, &index, radius, radius / 2.0)?;
    tracing::debug!(
        "envelope: radius {:.3e}, cell {:.3e}, {} triangles",
        env.radius,
        env.cell,
        env.mesh.faces.len()
    );
    // Residuals, extents, areas and centroids on the points.
    let (stats, rms) = face_stats(
        &surfaces,
        points
            .iter()
            .zip(&labels)
            .zip(&seg.point_area)
            .filter_map(|((p, &l), &a)| usize::try_from(l).ok().map(|l| (l, *p, a))),
    );
    let fit = Fit {
        stats,
        rms,
        border_flatness: 1.0,
    };
    let normals = analysis.normals()?;
    let all = Samples {
        points: points.into(),
        normals: normals.into(),
        labels: labels.as_slice().into(),
        index,
    };
    // One piece of the envelope of the samples `s`: its B-rep and its area.
    let build_piece = |piece: TriMesh, s: &Samples| -> (f64, Point3, Result<Reconstruction>) {
        // A sheet (an open surface, a single-view scan): the envelope's front only.
        let mesh = match envelope::front_side(&piece, &s.points, &s.normals, &s.index) {
            Some(keep) => {
                let faces: Vec<[u32; 3]> = piece
                    .faces
                    .iter()
                    .zip(&keep)
                    .filter(|(_, &k)| k)
                    .map(|(f, _)| *f)
                    .collect();
                match compact(&piece.vertices.positions, faces) {
                    Ok(m) => m,
                    Err(e) => return (0.0, assembly::centre(&piece), Err(e)),
                }
            }
            None => piece,
        };
        let area: f64 = face_areas(&mesh).iter().sum();
        // Each vertex takes the majority surface of its 8 nearest assigned samples (ties: the
        // nearest); a triangle the surface of two or three of its corners.
        let vertex_label: Vec<i32> = mesh
            .vertices
            .positions
            .par_iter()
            .map(|q| {
                let near = s.index.nearest(q, ENVELOPE_NEIGHBOUR);
                let labels = &s.labels;
                let mut best = (0usize, -1i32);
                for (i, &(p, _)) in near.iter().enumerate() {
                    let l = labels[p as usize];
                    if l < 0 || near[..i].iter().any(|&(o, _)| labels[o as usize] == l) {
                        continue;
                    }
                    let votes = near
                        .iter()
                        .filter(|&&(o, _)| labels[o as usize] == l)
                        .count();
                    if votes > best.0 {
                        best = (votes, l);
                    }
                }
                best.1
            })
            .collect();
        let face_labels = face_labels_from_vertices(&mesh.faces, &vertex_label);
        let rec = build_open(&mesh, &face_labels, &surfaces, Some(&fit));
        (area, assembly::centre(&mesh), rec)
    };
    let parts = pieces::components(&env.mesh);
    let mut rec = if parts.len() == 1 {
        build_piece(env.mesh, &all).2?
    } else {
        // A cloud that falls apart (a scene's objects, a backdrop seen through a gap): each
        // piece its own shell; those that cannot be built left out and said so.
        let n = parts.len();
        let (mut built, mut failed, mut total) = (Vec::new(), Vec::new(), 0.0);
        for (k, tris) in parts.iter().enumerate() {
            let piece = compact(
                &env.mesh.vertices.positions,
                tris.iter().map(|&t| env.mesh.faces[t as usize]).collect(),
            )?;
            // A piece whose samples span a few of the grid's cells (a part beside a far
            // outlier, the grid sized to both) has an envelope that cannot carry its faces.
            // Its envelope is then made again from its samples alone (on a grid sized to
            // them), and built when it is one piece wide enough.
            let (area, at, rec) = if span_cells(&piece, &env) < MIN_PIECE_CELLS {
                match finer_piece(&piece, &all, &env) {
                    (_, Ok((finer, sub))) => build_piece(finer, &sub),
                    (area, Err(why)) => (area, assembly::centre(&piece), Err(why)),
                }
            } else {
                build_piece(piece, &all)
            };
            total += area;
            match rec {
                Ok(rec) => built.push(assembly::Piece {
                    number: k + 1,
                    rec,
                    area,
                }),
                Err(e) => failed.push((k, area, at, e)),
            }
        }
        let covered = built.iter().fold(0.0, |a, p| a + p.area) / total.max(f64::MIN_POSITIVE);
        let why = |(k, area, at, e): &(usize, f64, Point3, Error)| {
            let place = assembly::place(k + 1, n, *at, area / total.max(f64::MIN_POSITIVE));
            format!("{place}: {e}")
        };
        if built.is_empty() || covered < MIN_EXPLAINED {
            return Err(Error::InvalidInput(format!(
                "reconstruct: the cloud falls apart into {n} pieces (its points, widened by \
                 {:.3e}, do not join up: a gap in the sampling, or several parts), and the \
                 pieces built cover {:.0} % of it (at least {:.0} % is needed); {}",
                env.radius,
                100.0 * covered,
                100.0 * MIN_EXPLAINED,
                failed.iter().map(why).collect::<Vec<_>>().join("; ")
            )));
        }
        let mut rec = assembly::assemble(built, total, n)?;
        rec.report.warnings.insert(
            0,
            format!(
                "the cloud falls apart into {n} pieces (its points, widened by {:.3e}, do not \
                 join up): {} built, one shell each",
                env.radius,
                n - failed.len()
            ),
        );
        rec.report
            .warnings
            .extend(failed.iter().map(|f| format!("left out {}", why(f))));
        rec
    };
    rec.report.snaps.splice(0..0, merges);
    rec.report.noise_ratio = analysis.noise_ratio()?;
    rec.report.segmentation = "points";
    if env.dropped > 0 {
        rec.report.warnings.push(format!(
            "{} small clusters of points away from the part were left out",
            env.dropped
        ));
    }
    Ok(rec)
}

/// The samples an envelope is made of: a cloud's points (or those of one of its pieces), their
/// normals and surface labels, and an index over them.
struct Samples<'a> {
    points: std::borrow::Cow<'a, [Point3]>,
    normals: std::borrow::Cow<'a, [Point3]>,
    labels: std::borrow::Cow<'a, [i32]>,
    index: crate::spatial::KdIndex,
}

/// How many of `env`'s grid cells the samples under a piece of it span (the piece's box less
/// the dilation, along its longest side).
fn span_cells(piece: &TriMesh, env: &envelope::Envelope) -> f64 {
    let span = Aabb::from_points(&piece.vertices.positions).map_or(0.0, |b| {
        (0..3).map(|k| b.max[k] - b.min[k]).fold(0.0, f64::max)
    }) - 2.0 * env.radius;
    span / env.cell
}

/// A piece of `env` (the envelope of `all`) too narrow for its grid (see [`MIN_PIECE_CELLS`]),
/// made again from the samples in its box alone: the new envelope and those samples, with the
/// new envelope's area (the old one's when none was made). Errors (the reason the piece is
/// left out): the samples still span too few cells (a stray point), or they fall apart again.
fn finer_piece(
    piece: &TriMesh,
    all: &Samples,
    env: &envelope::Envelope,
) -> (f64, Result<(TriMesh, Samples<'static>)>) {
    use rayon::prelude::*;
    let coarse = |cells: f64| {
        Error::InvalidInput(format!(
            "its samples span {:.1} cells of the envelope's grid (at least {MIN_PIECE_CELLS} \
             are needed to carry its faces): a point or a cluster far from the rest?",
            cells.max(0.0)
        ))
    };
    let area = |m: &TriMesh| face_areas(m).iter().sum::<f64>();
    let Some(bbox) = Aabb::from_points(&piece.vertices.positions) else {
        return (0.0, Err(coarse(0.0)));
    };
    let ids: Vec<usize> = (0..all.points.len())
        .into_par_iter()
        .filter(|&i| (0..3).all(|k| (bbox.min[k]..=bbox.max[k]).contains(&all.points[i][k])))
        .collect();
    fn gather<T: Copy + Send + Sync>(ids: &[usize], of: &[T]) -> Vec<T> {
        ids.par_iter().map(|&i| of[i]).collect()
    }
    let points = gather(&ids, &all.points);
    let Some(index) = crate::spatial::KdIndex::new(&points) else {
        return (area(piece), Err(coarse(span_cells(piece, env))));
    };
    let finer = match envelope::envelope(&points, &index, env.base_radius, env.base_cell) {
        Ok(f) => f,
        Err(e) => return (area(piece), Err(e)),
    };
    let a = area(&finer.mesh);
    let parts = pieces::components(&finer.mesh).len();
    if parts > 1 {
        return (
            a,
            Err(Error::InvalidInput(format!(
                "made again from its {} samples alone, it falls apart into {parts} pieces",
                points.len()
            ))),
        );
    }
    let cells = span_cells(&finer.mesh, &finer);
    if cells < MIN_PIECE_CELLS {
        return (a, Err(coarse(cells)));
    }
    let sub = Samples {
        normals: gather(&ids, &all.normals).into(),
        labels: gather(&ids, &all.labels).into(),
        points: points.into(),
        index,
    };
    (a, Ok((finer.mesh, sub)))
}

/// Per triangle: the label two or three of its corners share (-1 if none).
fn face_labels_from_vertices(faces: &[[u32; 3]], vertex_label: &[i32]) -> Vec<i32> {
    faces
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| vertex_label[v as usize]);
            if a == b || a == c {
                a
            } else if b == c {
                b
            } else {
                -1
            }
        })
        .collect()
}

/// The mesh of `faces` over only the vertices they use (in their order).
fn compact(positions: &[Point3], faces: Vec<[u32; 3]>) -> Result<TriMesh> {
    let mut new_id = vec![u32::MAX; positions.len()];
    let mut kept = Vec::new();
    for f in &faces {
        for &v in f {
            if new_id[v as usize] == u32::MAX {
                new_id[v as usize] = 0;
                kept.push(v);
            }
        }
    }
    kept.sort_unstable();
    for (i, &v) in kept.iter().enumerate() {
        new_id[v as usize] = i as u32;
    }
    TriMesh::new(
        kept.iter().map(|&v| positions[v as usize]).collect(),
        faces
            .iter()
            .map(|f| f.map(|v| new_id[v as usize]))
            .collect(),
    )
}

/// The B-rep of a point cloud (any order) with its normals when it has them (else they are
/// estimated): [`reconstruct_cloud`] on a new analysis with `params`.
pub fn reconstruct_points(
    points: &[Point3],
    normals: Option<&[Point3]>,
    params: crate::analysis::AnalysisParams,
) -> Result<Reconstruction> {
    let analysis = match normals {
        Some(n) => crate::analysis::CloudAnalysis::with_normals(points, n, params)?,
        None => crate::analysis::CloudAnalysis::new(points, params)?,
    };
    reconstruct_cloud(&analysis)
}

/// `surfaces` with the relations the mesh cannot tell from exact ones made exact (see
/// `snap`), and what was snapped.
fn snap_surfaces(
    mesh: &TriMesh,
    topo: &topology::Topology,
    surfaces: &[SurfaceParams],
    size: f64,
    fit: Option<&Fit>,
) -> (Vec<SurfaceParams>, Vec<snap::Snap>, Vec<snap::FaceStats>) {
    if let Some(f) = fit {
        let mut snapped = surfaces.to_vec();
        let snaps = snap::snap(
            &mut snapped,
            &adjacent_surfaces(topo),
            &touching_surfaces(topo),
            &f.stats,
            size,
        );
        return (snapped, snaps, f.stats.clone());
    }
    let p = &mesh.vertices.positions;
    let areas = face_areas(mesh);
    // Each triangle's vertices, its area counted once.
    let (stats, _) = face_stats(
        surfaces,
        mesh.faces.iter().enumerate().flat_map(|(t, f)| {
            let s = topo.surface_of_region[topo.region_of_face[t] as usize];
            let area = areas[t];
            f.iter()
                .enumerate()
                .map(move |(i, &v)| (s, p[v as usize], if i == 0 { area } else { 0.0 }))
        }),
    );
    let mut snapped = surfaces.to_vec();
    let snaps = snap::snap(
        &mut snapped,
        &adjacent_surfaces(topo),
        &touching_surfaces(topo),
        &stats,
        size,
    );
    (snapped, snaps, stats)
}

/// Per surface: the RMS distance, extent, area and centroid of its `samples` (surface, point,
/// area the point stands for); and the RMS distance of them all.
fn face_stats(
    surfaces: &[SurfaceParams],
    samples: impl Iterator<Item = (usize, Point3, f64)>,
) -> (Vec<snap::FaceStats>, f64) {
    let ns = surfaces.len();
    let (mut sq, mut count, mut area) = (vec![0.0; ns], vec![0usize; ns], vec![0.0; ns]);
    let mut sum = vec![[0.0; 3]; ns];
    let mut boxes: Vec<Option<Aabb>> = vec![None; ns];
    for (s, p, a) in samples {
        sq[s] += signed_distance(&surfaces[s], p).powi(2);
        count[s] += 1;
        area[s] += a;
        for k in 0..3 {
            sum[s][k] += p[k];
        }
        match &mut boxes[s] {
            Some(b) => b.grow(p),
            None => boxes[s] = Some(Aabb { min: p, max: p }),
        }
    }
    let stats = (0..ns)
        .map(|s| {
            let c = count[s].max(1) as f64;
            snap::FaceStats {
                rms: (sq[s] / c).sqrt(),
                extent: boxes[s].map(|b| b.diagonal()).unwrap_or(0.0),
                area: area[s],
                centroid: sum[s].map(|x| x / c),
            }
        })
        .collect();
    let rms = (sq.iter().sum::<f64>() / count.iter().sum::<usize>().max(1) as f64).sqrt();
    (stats, rms)
}

/// The pairs of distinct surfaces whose regions share an edge or a vertex, ascending.
fn touching_surfaces(topo: &topology::Topology) -> Vec<(usize, usize)> {
    let mut at_vertex: Vec<Vec<usize>> = vec![Vec::new(); topo.vertices.len()];
    for e in &topo.edges {
        for r in [e.left, e.right] {
            if r != topology::OUTSIDE {
                let s = topo.surface_of_region[r as usize];
                at_vertex[e.start].push(s);
                at_vertex[e.end].push(s);
            }
        }
    }
    let mut pairs = Vec::new();
    for mut v in at_vertex {
        v.sort_unstable();
        v.dedup();
        for (i, &a) in v.iter().enumerate() {
            for &b in &v[i + 1..] {
                pairs.push((a, b));
            }
        }
    }
    pairs.sort_unstable();
    pairs.dedup();
    pairs
}

/// The pairs of distinct surfaces whose regions share an edge, ascending.
fn adjacent_surfaces(topo: &topology::Topology) -> Vec<(usize, usize)> {
    let mut adjacent: Vec<(usize, usize)> = topo
        .edges
        .iter()
        .filter(|e| e.right != topology::OUTSIDE)
        .map(|e| {
            let a = topo.surface_of_region[e.left as usize];
            let b = topo.surface_of_region[e.right as usize];
            (a.min(b), a.max(b))
        })
        .filter(|(a, b)| a != b)
        .collect();
    adjacent.sort_unstable();
    adjacent.dedup();
    adjacent
}

/// The signed angle that the points turn through about the axis (`center`, unit `axis`;
/// `ref_dir` unit and perpendicular to it), counter-clockwise positive.
fn turning(
    center: Point3,
    axis: Point3,
    ref_dir: Point3,
    points: impl Iterator<Item = Point3>,
) -> f64 {
    let other = cross(axis, ref_dir);
    let mut total = 0.0;
    let mut last: Option<f64> = None;
    for p in points {
        let v = sub(p, center);
        let a = dot(v, other).atan2(dot(v, ref_dir));
        if let Some(l) = last {
            let mut d = a - l;
            if d > std::f64::consts::PI {
                d -= std::f64::consts::TAU;
            } else if d < -std::f64::consts::PI {
                d += std::f64::consts::TAU;
            }
            total += d;
        }
        last = Some(a);
    }
    total
}

/// `faces` without those left with no loop, and `edges` with their face indices renumbered.
fn drop_empty_faces(
    faces: Vec<BrepFace>,
    mut edges: Vec<BrepEdge>,
) -> (Vec<BrepFace>, Vec<BrepEdge>) {
    if faces.iter().all(|f| !f.loops.is_empty()) {
        return (faces, edges);
    }
    let mut new_id = vec![None; faces.len()];
    let mut kept = Vec::with_capacity(faces.len());
    for (i, f) in faces.into_iter().enumerate() {
        if !f.loops.is_empty() {
            new_id[i] = Some(kept.len());
            kept.push(f);
        }
    }
    for e in &mut edges {
        e.faces = e.faces.map(|f| f.and_then(|f| new_id[f]));
    }
    (kept, edges)
}

/// Per B-rep vertex: the surfaces that meet there (`edge_surfaces` of each incident edge), and
/// the point on all of them nearest its mesh vertex.
fn solve_vertices(
    topo: &topology::Topology,
    edge_surfaces: &dyn Fn(u32, u32) -> Vec<SurfaceParams>,
    pos: &dyn Fn(u32) -> Point3,
) -> (Vec<Vec<SurfaceParams>>, Vec<Point3>) {
    let mut at_vertex: Vec<Vec<SurfaceParams>> = vec![Vec::new(); topo.vertices.len()];
    for e in &topo.edges {
        for s in edge_surfaces(e.left, e.right) {
            for v in [e.start, e.end] {
                if !at_vertex[v].contains(&s) {
                    at_vertex[v].push(s);
                }
            }
        }
    }
    let vertices = topo
        .vertices
        .iter()
        .zip(&at_vertex)
        .map(|(&mv, surfs)| {
            intersect::contact_point(surfs)
                .unwrap_or_else(|| intersect::on_surfaces(surfs, pos(mv)))
        })
        .collect();
    (at_vertex, vertices)
}

/// The plane of a border chain, when its mesh vertices lie in one within `tolerance` (RMS).
fn border_plane(
    chain: &[u32],
    pos: &dyn Fn(u32) -> Point3,
    tolerance: f64,
) -> Option<SurfaceParams> {
    if chain.len() < 4 {
        return None;
    }
    let plane = crate::geometry::fit_plane(chain.iter().map(|&v| (pos(v), 1.0)))?;
    let rms = plane.eigenvalues[0].max(0.0).sqrt();
    let flat = rms <= tolerance;
    // A straight border (a line: two vanishing eigenvalues) has no plane of its own.
    let straight = plane.eigenvalues[1].max(0.0).sqrt() <= tolerance;
    if !flat || straight {
        return None;
    }
    Some(SurfaceParams::Plane {
        normal: plane.normal,
        offset: dot(plane.normal, plane.centroid),
    })
}

/// A border's plane made square to the axis of the surface it bounds (a tube cut square) when
/// its tilt is within what the chain's ragged points (`tolerance`, RMS) cannot resolve over its
/// extent; through the chain's centroid.
fn square_to_axis(
    plane: SurfaceParams,
    surface: &SurfaceParams,
    chain: &[u32],
    pos: &dyn Fn(u32) -> Point3,
    tolerance: f64,
) -> SurfaceParams {
    let (SurfaceParams::Plane { normal, .. }, Some((_, axis))) = (plane, surface.axis()) else {
        return plane;
    };
    let Some(extent) =
        Aabb::from_points(&chain.iter().map(|&v| pos(v)).collect::<Vec<_>>()).map(|b| b.diagonal())
    else {
        return plane;
    };
    let c = dot(normal, axis);
    let tilt = (1.0 - c.abs()).max(0.0);
    if extent <= 0.0 || tilt > 0.5 * (tolerance / extent).powi(2) {
        return plane;
    }
    let n = if c < 0.0 { scale(axis, -1.0) } else { axis };
    let m = chain.len() as f64;
    let centroid = chain.iter().fold([0.0; 3], |acc, &v| {
        let p = pos(v);
        [acc[0] + p[0] / m, acc[1] + p[1] / m, acc[2] + p[2] / m]
    });
    SurfaceParams::Plane {
        normal: n,
        offset: dot(n, centroid),
    }
}

/// The line of a straight border chain on a plane (its mesh vertices within a tenth of the mesh
/// spacing, RMS, of the line through its ends).
fn border_line(
    surface: &SurfaceParams,
    chain: &[u32],
    pos: &dyn Fn(u32) -> Point3,
    p0: Point3,
    p1: Point3,
    spacing: f64,
) -> Option<Curve> {
    if !matches!(surface, SurfaceParams::Plane { .. }) || chain.first() == chain.last() {
        return None;
    }
    let dir = normalize(sub(p1, p0))?;
    let line = Curve::Line { origin: p0, dir };
    let sq: f64 = chain.iter().map(|&v| line.distance(pos(v)).powi(2)).sum();
    ((sq / chain.len() as f64).sqrt() <= 0.1 * spacing).then_some(line)
}

/// The points of a chain moved onto a curve, thinned to a monotone sequence: a point is kept
/// when it lies at least `spacing` from the last one kept and does not turn back on the step
/// before (the border between two regions of a noisy mesh zigzags about the curve, and its
/// points projected onto it can step backwards, which an interpolating spline turns into
/// loops). The ends are kept.
/// The chain `pts` (ends fixed) smoothed by `rounds` of averaging each inner point with its
/// two neighbours on each side, put back on the surfaces after each round.
fn smooth_on(surfs: &[SurfaceParams], mut pts: Vec<Point3>, rounds: usize) -> Vec<Point3> {
    let n = pts.len();
    for _ in 0..rounds {
        let old = pts.clone();
        for (i, p) in pts.iter_mut().enumerate().take(n - 1).skip(1) {
            let (lo, hi) = (i.saturating_sub(2), (i + 2).min(n - 1));
            let mut c = [0.0; 3];
            for q in &old[lo..=hi] {
                c = crate::geometry::vec3::add(c, *q);
            }
            *p = intersect::on_surfaces(surfs, scale(c, 1.0 / (hi - lo + 1) as f64));
        }
    }
    pts
}

fn thin_chain(pts: &[Point3], spacing: f64) -> Vec<Point3> {
    let n = pts.len();
    if n <= 2 {
        return pts.to_vec();
    }
    let mut kept = vec![pts[0]];
    let mut step: Option<Point3> = None;
    for &q in &pts[1..n - 1] {
        let last = kept[kept.len() - 1];
        let d = sub(q, last);
        if norm(d) < spacing || step.is_some_and(|s| dot(s, d) <= 0.0) {
            continue;
        }
        step = Some(d);
        kept.push(q);
    }
    let end = pts[n - 1];
    // Kept points too close to the end, or just past it (the step to the end turns back),
    // give way to the end: a spline through them would hook.
    while kept.len() > 1 {
        let last = kept[kept.len() - 1];
        let before = sub(last, kept[kept.len() - 2]);
        let near = dist(last, end);
        if near < 0.5 * spacing || (near < 2.0 * spacing && dot(before, sub(end, last)) <= 0.0) {
            kept.pop();
        } else {
            break;
        }
    }
    kept.push(end);
    kept
}

/// The cubic B-spline through `pts` (points on every surface of `surfs`), refined until it
/// leaves the surfaces by at most 1e-4 `spacing` between its points: each pass adds the
/// midpoint of every pair of consecutive points, moved onto the surfaces (at most three
/// passes, and no pass beyond 128 points).
fn spline_on(surfs: &[SurfaceParams], mut pts: Vec<Point3>, spacing: f64) -> Curve {
    let mut curve = intersect::interpolate(&pts);
    for _ in 0..3 {
        let gap = curve
            .samples()
            .iter()
            .flat_map(|&q| surfs.iter().map(move |s| signed_distance(s, q).abs()))
            .fold(0.0, f64::max);
        if gap <= 1e-4 * spacing || pts.len() > 128 {
            break;
        }
        let mut finer = Vec::with_capacity(2 * pts.len());
        for w in pts.windows(2) {
            finer.push(w[0]);
            let mid = [0, 1, 2].map(|k| 0.5 * (w[0][k] + w[1][k]));
            finer.push(intersect::on_surfaces(surfs, mid));
        }
        finer.push(pts[pts.len() - 1]);
        pts = finer;
        curve = intersect::interpolate(&pts);
    }
    curve
}

/// The volume enclosed by a closed mesh, positive when its triangles turn counter-clockwise
/// seen from outside.
fn signed_volume(mesh: &TriMesh) -> f64 {
    let p = &mesh.vertices.positions;
    mesh.faces
        .iter()
        .map(|f| dot(p[f[0] as usize], cross(p[f[1] as usize], p[f[2] as usize])) / 6.0)
        .sum()
}

impl Brep {
    /// Turns the B-rep inside out: every loop walked the other way, every face's sense
    /// flipped.
    pub fn reverse(&mut self) {
        for f in &mut self.faces {
            f.same_sense = !f.same_sense;
            for l in &mut f.loops {
                l.reverse();
                for (_, fwd) in l.iter_mut() {
                    *fwd = !*fwd;
                }
            }
        }
        for e in &mut self.edges {
            e.faces.swap(0, 1);
        }
    }
}

/// Where one straight edge of a face's loops runs along another: a vertex lies within `tol`
/// of the inside of another line edge of the face (not one of its ends) and most of the
/// vertex's own line edge lies within `tol` of it. `None` when no line overlaps another.
///
/// Only lines are tested: on the Kinect scenes B-spline and conic edges of one face were
/// found touching along a stretch too (where three surfaces nearly meet along a curve), and
/// OpenCASCADE reads those faces as valid; leaving them out lost faces (`learn33` 17 → 15)
/// for no gain in validity (`docs/experiments/run-profile.md`, 2026-12-07).
fn overlapping_lines(
    loops: &[Vec<(usize, bool)>],
    edges: &[BrepEdge],
    vertices: &[Point3],
    tol: f64,
) -> Option<Point3> {
    let lines: Vec<&BrepEdge> = loops
        .iter()
        .flatten()
        .map(|&(e, _)| &edges[e])
        .filter(|e| matches!(e.curve, Curve::Line { .. }))
        .collect();
    for (i, e) in lines.iter().enumerate() {
        let (a, b) = (vertices[e.start], vertices[e.end]);
        for (j, f) in lines.iter().enumerate() {
            if i == j {
                continue;
            }
            let (c, d) = (vertices[f.start], vertices[f.end]);
            let on_f = |p: Point3| segment_distance(p, c, d) <= tol;
            for v in [e.start, e.end] {
                if f.start == v || f.end == v || !on_f(vertices[v]) {
                    continue;
                }
                // The share of e along f, from samples along e.
                const SAMPLES: usize = 17;
                let on = (0..SAMPLES)
                    .filter(|&k| {
                        let t = k as f64 / (SAMPLES - 1) as f64;
                        on_f(std::array::from_fn(|c| a[c] + t * (b[c] - a[c])))
                    })
                    .count();
                if 2 * on > SAMPLES {
                    return Some(vertices[v]);
                }
            }
        }
    }
    None
}

/// Points along an edge from its start vertex to its end vertex (a line's two vertices, a
/// circle's arc, a B-spline's samples), the ends exactly on the vertices.
pub fn edge_polyline(edge: &BrepEdge, vertices: &[Point3]) -> Vec<Point3> {
    let (p0, p1) = (vertices[edge.start], vertices[edge.end]);
    let mut pts = edge_points(edge, vertices);
    if pts.len() < 2 {
        return vec![p0, p1];
    }
    if edge.start != edge.end && dist(pts[0], p0) > dist(pts[pts.len() - 1], p0) {
        pts.reverse();
    }
    let last = pts.len() - 1;
    pts[0] = p0;
    pts[last] = p1;
    pts
}

/// Points along an edge: its vertices, a circle's arc, a B-spline's samples.
fn edge_points(edge: &BrepEdge, vertices: &[Point3]) -> Vec<Point3> {
    let (p0, p1) = (vertices[edge.start], vertices[edge.end]);
    match (&edge.curve, edge.curve.conic()) {
        (Curve::BSpline { .. }, _) => edge.curve.samples(),
        (_, None) => vec![p0, p1],
        (_, Some(conic)) => {
            let tau = std::f64::consts::TAU;
            let (a0, a1) = (conic_parameter(conic, p0), conic_parameter(conic, p1));
            // The arc from p0 to p1 along the edge's direction (a whole turn when closed).
            let sweep = if edge.start == edge.end {
                tau
            } else if edge.curve_sense {
                (a1 - a0).rem_euclid(tau)
            } else {
                -(a0 - a1).rem_euclid(tau)
            };
            let sweep = if edge.curve_sense {
                sweep
            } else {
                -sweep.abs()
            };
            (0..=64)
                .map(|i| conic_point(conic, a0 + sweep * i as f64 / 64.0))
                .collect()
        }
    }
}

/// See [`BrepFace::seam`]: the middle of the widest angular gap between the face's boundary
/// points around the axis (edges that are circles about the axis itself are left out: every
/// seam crosses them).
fn seam_direction(
    surface: &SurfaceParams,
    loops: &[Vec<(usize, bool)>],
    edges: &[BrepEdge],
    vertices: &[Point3],
) -> Option<Point3> {
    let (o, d) = surface.axis()?;
    let u = step::perpendicular(d);
    let v = cross(d, u);
    let mut angles: Vec<f64> = Vec::new();
    for &(e, _) in loops.iter().flatten() {
        let edge = &edges[e];
        // (An ellipse about the axis is a cylinder's oblique cut.)
        if let Some((center, _, _, _, _)) = edge.curve.conic() {
            let axis = match edge.curve {
                Curve::Circle { axis, .. } => axis,
                _ => d,
            };
            let c = sub(center, o);
            if 1.0 - dot(axis, d).abs() < 1e-9 && norm(cross(c, d)) <= 1e-9 * (1.0 + norm(c)) {
                continue;
            }
        }
        for p in edge_points(edge, vertices) {
            let r = sub(p, o);
            angles.push(dot(r, v).atan2(dot(r, u)));
        }
    }
    if angles.is_empty() {
        return None;
    }
    angles.sort_by(f64::total_cmp);
    let tau = std::f64::consts::TAU;
    let mut best = (
        angles[0] + tau - angles[angles.len() - 1],
        angles[angles.len() - 1],
    );
    for w in angles.windows(2) {
        if w[1] - w[0] > best.0 {
            best = (w[1] - w[0], w[0]);
        }
    }
    let mid = best.1 + 0.5 * best.0;
    normalize([0, 1, 2].map(|k| mid.cos() * u[k] + mid.sin() * v[k]))
}

/// How many times a loop turns around the axis through `o` along `d` (its edges' points in
/// the loop's order; 0 for a loop that does not go around it), and the angle its points span
/// about the axis, unwrapped (more than a turn for a loop that overlaps itself there).
fn winding(
    l: &[(usize, bool)],
    edges: &[BrepEdge],
    vertices: &[Point3],
    o: Point3,
    d: Point3,
) -> (i64, f64) {
    let u = step::perpendicular(d);
    let v = cross(d, u);
    let mut pts: Vec<Point3> = Vec::new();
    for &(e, fwd) in l {
        let mut p = edge_points(&edges[e], vertices);
        if !fwd {
            p.reverse();
        }
        pts.extend(p);
    }
    let angle = |p: Point3| {
        let r = sub(p, o);
        dot(r, v).atan2(dot(r, u))
    };
    let tau = std::f64::consts::TAU;
    let (mut total, mut low, mut high) = (0.0, 0.0f64, 0.0f64);
    for (a, b) in pts.iter().zip(pts.iter().cycle().skip(1)) {
        let step =
            (angle(*b) - angle(*a) + std::f64::consts::PI).rem_euclid(tau) - std::f64::consts::PI;
        total += step;
        low = low.min(total);
        high = high.max(total);
    }
    ((total / tau).round() as i64, high - low)
}

/// Signed area of a loop in the plane of normal `n`, from its edges' polylines (vertices and
/// B-spline control points; circles by their start only, enough to rank loops).
fn loop_area(l: &[(usize, bool)], edges: &[BrepEdge], vertices: &[Point3], n: Point3) -> f64 {
    let mut pts: Vec<Point3> = Vec::new();
    for &(e, fwd) in l {
        let edge = &edges[e];
        let mut run: Vec<Point3> = match (&edge.curve, edge.curve.conic()) {
            (Curve::BSpline { control_points, .. }, _) => control_points.clone(),
            (_, Some(conic)) if edge.start == edge.end => {
                // A whole circle or ellipse: its polygon.
                let s = if edge.curve_sense { 1.0 } else { -1.0 };
                (0..=32)
                    .map(|i| conic_point(conic, s * std::f64::consts::TAU * i as f64 / 32.0))
                    .collect()
            }
            _ => vec![vertices[edge.start], vertices[edge.end]],
        };
        if !fwd {
            run.reverse();
        }
        pts.extend(run);
    }
    let mut a = [0.0; 3];
    for i in 0..pts.len() {
        let c = cross(pts[i], pts[(i + 1) % pts.len()]);
        for k in 0..3 {
            a[k] += c[k];
        }
    }
    0.5 * dot(a, n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(start: usize, end: usize) -> BrepEdge {
        BrepEdge {
            start,
            end,
            curve: Curve::Line {
                origin: [0.0; 3],
                dir: [1.0, 0.0, 0.0],
            },
            curve_sense: true,
            faces: [Some(0), None],
        }
    }

    #[test]
    fn a_line_along_another_of_its_face_is_an_overlap_and_a_touch_is_not() {
        // A square's loop 0 → 1 → 2 → 3 → 0, with vertex 4 on the bottom side (0 → 1).
        let vertices = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.0, 0.0],
            [0.5, 0.5, 0.0],
        ];
        let tol = 1e-6;
        // A spur 5 → 4 touching the bottom side at its middle: a touch, no overlap.
        let edges = vec![line(0, 1), line(1, 2), line(2, 3), line(3, 0), line(5, 4)];
        let loops = vec![(0..5).map(|e| (e, true)).collect::<Vec<_>>()];
        assert_eq!(overlapping_lines(&loops, &edges, &vertices, tol), None);
        // An edge 4 → 1 running along the bottom side over its second half: an overlap.
        let edges = vec![line(0, 1), line(1, 2), line(2, 3), line(3, 0), line(4, 1)];
        assert_eq!(
            overlapping_lines(&loops, &edges, &vertices, tol),
            Some([0.5, 0.0, 0.0])
        );
    }
}
