//! The curve network of a point cloud, anchored on its surfaces.
//!
//! Where the segmentation's surfaces explain the part, its lines are the edges of the B-rep
//! built from them ([`crate::brep::reconstruct_cloud`]): a sharp line is the intersection curve
//! of two fitted surfaces, trimmed at vertices solved from the surfaces; a fillet border is the
//! edge where a fillet surface meets its neighbour tangentially. Both average the noise over
//! every point of two surfaces instead of one neighbourhood, so they hold at noise of a whole
//! spacing, where the graph of Demarsin et al. (2007, [`crate::lines`]) breaks into hundreds of
//! pieces (figures: `docs/experiments/anchored-network.md`).
//!
//! 1. Each B-rep edge is a polyline between its two vertices (a whole circle is a closed loop);
//!    the B-rep's vertices are the network's junctions.
//! 2. Its group: `smooth` where the normals of its two faces' surfaces differ by less than
//!    [`TANGENT_DEGREES`] along it, `sharp` otherwise; an edge between two faces of one surface
//!    (a seam) is no line. An edge with one face is the cloud's open border (`boundary`) where
//!    no point lies beyond it; otherwise it borders a region the B-rep left out, and it is kept
//!    (as `sharp` or `smooth`) where Demarsin's lines of that group run along it.
//! 3. Where the B-rep leaves points out (regions whose surfaces do not meet their neighbours),
//!    or when no B-rep can be built or it leaves more than a tenth of the part out
//!    ([`MIN_ANCHORED`]; the summary says why), Demarsin's lines
//!    ([`crate::fillets::curve_network`]) fill in, less what the surfaces explain: the pieces
//!    of them off the B-rep's faces (farther than two spacings) and not inside one surface of
//!    the segmentation (a feature line separates surfaces: where every assigned neighbour of
//!    its nearest point, in the analysis' lists, lies on one surface, and most of them are
//!    assigned, a line is noise),
//!    at least 2 d_max edges long (shorter, Algorithm 2 of Demarsin 2007 would have pruned
//!    them as spurs). This is what clears the meandering lines off a scan's flat faces.
//!    Where a B-rep is anchored on, Demarsin's graph is built only on the points off its faces
//!    and [`OFF_FACES_MARGIN`] spacings around them ([`network_off_faces`]): 12 % of a Kinect
//!    scene, whose whole-scene Delaunay rings were most of the network's time. Departure: the
//!    graph of a part of the cloud is not the same as that of the whole (Demarsin splits
//!    small and large clusters by their mean size, which the part changes), so its noise
//!    lines move. On the scans of `../shared/data` the network's free ends went 2 → 0 (Kinect
//!    test0), 28 → 25 (learn33), 6 → 4 (RealSense box), but 3 → 5 (test16) and 2 → 6 (the
//!    CurvSurf sample, whose scan border around the third its B-rep leaves out now comes in
//!    open pieces); see `docs/experiments/run-profile.md`.

use rayon::prelude::*;
use serde::Serialize;

use crate::analysis::CloudAnalysis;
use crate::brep::{reconstruct_cloud, Reconstruction};
use crate::fillets::{
    curve_network, extract_fillets_from, extract_fillets_with, CurveNetwork, FilletParams, Fillets,
    Label,
};
use crate::geometry::surface::surface_normal;
use crate::geometry::vec3::{cross, dist, dot, normalize, sub};
use crate::geometry::Point3;
use crate::spatial::KdIndex;
use crate::Result;

/// Two faces whose surfaces' normals differ by less than this along their edge, in degrees,
/// meet tangentially: the edge is a fillet border (`smooth`), not a sharp line. The B-rep snaps
/// a fillet tangent to its faces where the data cannot tell otherwise, so tangent edges measure
/// about 0°; mechanical parts have no sharp edge this flat.
pub const TANGENT_DEGREES: f64 = 10.0;

/// The least share of the part's area the B-rep must explain for the network to be anchored on
/// it: regions whose surfaces do not meet their neighbours tell that the segmentation missed or
/// mistyped surfaces, and where they are a tenth of the part or more, the B-rep's other faces
/// are not trusted either (two cylinders with noise of half a spacing, 20 % left out: anchored,
/// precision 0.46 and the least coverage of a curve 0.37; from the points, 0.83 and 0.66).
pub const MIN_ANCHORED: f64 = 0.9;

/// What the network is made of.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct NetworkSummary {
    /// Sharp polylines.
    pub sharp_polylines: usize,
    /// Smooth (fillet border) polylines.
    pub smooth_polylines: usize,
    /// Open-border polylines.
    pub boundary_polylines: usize,
    /// Vertices where three or more polyline ends meet (a closed loop's start counts twice).
    pub junctions: usize,
    /// Polyline ends that meet no other line.
    pub endpoints: usize,
    /// Smooth-line ends joined to another line.
    pub joined_smooth_ends: usize,
    /// Smooth-line ends left open.
    pub open_smooth_ends: usize,
    /// Polylines that are edges of the B-rep.
    pub from_surfaces: usize,
    /// Polylines (or pieces of them) from Demarsin's graph.
    pub from_points: usize,
    /// Why the lines are not anchored on surfaces (no B-rep could be built), if so.
    pub not_anchored: Option<String>,
}

impl NetworkSummary {
    /// The counts of `net`, whose first `from_surfaces` polylines are B-rep edges.
    pub fn new(net: &CurveNetwork, from_surfaces: usize, not_anchored: Option<String>) -> Self {
        let degree = degrees(net);
        NetworkSummary {
            sharp_polylines: net.count(crate::geometry::names::SHARP),
            smooth_polylines: net.count(crate::geometry::names::SMOOTH),
            boundary_polylines: net.count(crate::geometry::names::BOUNDARY),
            junctions: degree.iter().filter(|&&d| d >= 3).count(),
            endpoints: degree.iter().filter(|&&d| d == 1).count(),
            joined_smooth_ends: net.joined_ends,
            open_smooth_ends: net.open_ends,
            from_surfaces,
            from_points: net.polylines.len() - from_surfaces,
            not_anchored,
        }
    }
}

/// Per network vertex: the number of polyline segments that end there.
fn degrees(net: &CurveNetwork) -> Vec<u32> {
    let mut degree = vec![0u32; net.vertices.len()];
    for l in &net.polylines {
        for w in l.windows(2) {
            degree[w[0] as usize] += 1;
            degree[w[1] as usize] += 1;
        }
    }
    degree
}

/// The curve network of a cloud and what it is made of.
#[derive(Debug)]
pub struct CloudNetwork {
    /// The polylines with their groups.
    pub network: CurveNetwork,
    /// Demarsin's fillet lines and per-point labels, when they were computed (see
    /// [`cloud_network`]).
    pub fillets: Option<Fillets>,
    /// Counts.
    pub summary: NetworkSummary,
}

/// The curve network of the cloud of `analysis` (see the module documentation). `params` are
/// Demarsin's, used where the surfaces do not explain the part; with `want_fillets` his fillet
/// lines and per-point labels are computed and returned even where the B-rep alone gives the
/// network.
///
/// Errors: those of the analysis and of [`extract_fillets_from`] (a B-rep that cannot be built
/// is not an error: the summary says why).
pub fn cloud_network(
    analysis: &CloudAnalysis,
    params: &FilletParams,
    want_fillets: bool,
) -> Result<CloudNetwork> {
    let brep = reconstruct_cloud(analysis);
    let whole = || -> Result<(Option<Fillets>, CurveNetwork)> {
        let f = extract_fillets_from(analysis, params, true)?;
        let net = curve_network(&f);
        Ok((Some(f), net))
    };
    let fillets = match brep.as_ref().ok().filter(|_| !want_fillets) {
        Some(rec) if explains_all(rec) => None,
        // Demarsin's graph only where the B-rep leaves the cloud out; on the whole cloud if
        // that fails (too few points there for his neighbourhoods).
        Some(rec) if anchorable(rec).is_ok() => Some(
            network_off_faces(analysis, rec, params)
                .map(|off| (None, off.network))
                .or_else(|_| whole())?,
        ),
        _ => Some(whole()?),
    };
    let (network, summary) = anchored(
        analysis,
        brep.as_ref().map_err(|e| e.to_string()),
        fillets.as_ref().map(|(_, n)| n),
        params.lines.d_max,
    )?;
    Ok(CloudNetwork {
        network,
        fillets: fillets.and_then(|(f, _)| f),
        summary,
    })
}

/// [`cloud_network`] in one call on raw points: their analysis built with neighbourhoods large
/// enough for `params` (`params.lines.k`), then the network.
///
/// Errors: those of [`CloudAnalysis::new`] and [`cloud_network`].
pub fn network_of_points(
    points: &[Point3],
    params: &FilletParams,
    want_fillets: bool,
) -> Result<CloudNetwork> {
    let analysis = CloudAnalysis::new(
        points,
        crate::analysis::AnalysisParams {
            max_k: crate::analysis::DEFAULT_MAX_K.max(params.lines.k),
            ..Default::default()
        },
    )?;
    cloud_network(&analysis, params, want_fillets)
}

/// Whether the B-rep explains the whole cloud (nothing left out), so that its edges are the
/// whole network.
pub fn explains_all(rec: &Reconstruction) -> bool {
    rec.report.left_out.is_empty() && rec.report.unexplained == 0.0
}

/// Per-point fillet labels, in the analysis' order, read off a B-rep `rec` that
/// [`explains_all`] of the cloud of `analysis`, in place of Demarsin's (whose Delaunay rings
/// were most of the time of `crease run` on a million points): a point whose surface is a
/// fillet's (not a plane, and meeting a neighbour along a smooth edge, as the network groups
/// them) is [`Label::Inner`], or [`Label::Border`] within one spacing of such an edge; a point
/// of any other surface is [`Label::Low`]; an unassigned point (a crease band along a sharp
/// edge, where Demarsin's regions end too) has none.
///
/// Errors: those of the analysis.
pub fn fillet_labels(analysis: &CloudAnalysis, rec: &Reconstruction) -> Result<Vec<Option<Label>>> {
    let seg = analysis.segmentation()?;
    let spacing = seg.mean_edge;
    let b = &rec.brep;
    let mut fillet = vec![false; seg.surfaces.len()];
    let mut along: Vec<Point3> = Vec::new();
    for e in &b.edges {
        let pts = crate::brep::edge_polyline(e, &b.vertices);
        if edge_group(b, e, &pts) != Some(Group::Smooth) {
            continue;
        }
        for face in e.faces.iter().flatten().map(|&f| &b.faces[f]) {
            if face.surface.kind() != crate::geometry::SurfaceType::Plane {
                if let Some(x) = fillet.get_mut(face.surface_id) {
                    *x = true;
                }
            }
        }
        // The edge sampled at half a spacing.
        for w in pts.windows(2) {
            let steps = (dist(w[0], w[1]) / (0.5 * spacing)).ceil().max(1.0) as usize;
            along.extend((0..steps).map(|i| {
                let t = i as f64 / steps as f64;
                std::array::from_fn(|k| w[0][k] + t * (w[1][k] - w[0][k]))
            }));
        }
        along.extend(pts.last().copied());
    }
    let index = KdIndex::new(&along);
    Ok(analysis
        .points()
        .par_iter()
        .zip(&seg.point_surface)
        .map(|(&p, &s)| {
            let s = usize::try_from(s).ok()?;
            Some(if !fillet.get(s).copied().unwrap_or(false) {
                Label::Low
            } else if index
                .as_ref()
                .is_some_and(|ix| ix.nearest_one(&p).1 <= spacing * spacing)
            {
                Label::Border
            } else {
                Label::Inner
            })
        })
        .collect())
}

/// The group of B-rep edge `e` (its points `pts`): none for a seam (both faces on one
/// surface), smooth where its two surfaces are [`tangent`], sharp otherwise, one-sided with a
/// single face.
fn edge_group(b: &crate::brep::Brep, e: &crate::brep::BrepEdge, pts: &[Point3]) -> Option<Group> {
    match e.faces {
        [Some(f), Some(g)] if b.faces[f].surface_id == b.faces[g].surface_id => None,
        [Some(f), Some(g)] => Some(if tangent(&b.faces[f].surface, &b.faces[g].surface, pts) {
            Group::Smooth
        } else {
            Group::Sharp
        }),
        _ => Some(Group::OneSided),
    }
}

/// `rec` if it explains enough of the part for lines anchored on it ([`MIN_ANCHORED`]),
/// otherwise why not.
pub fn anchorable(rec: &Reconstruction) -> std::result::Result<&Reconstruction, String> {
    let left_out: f64 = rec.report.left_out.iter().map(|l| l.area_fraction).sum();
    let explained = 1.0 - left_out - rec.report.unexplained;
    if explained < MIN_ANCHORED {
        Err(format!(
            "the B-rep leaves {:.0} % of the part out (at most {:.0} % for lines anchored on it)",
            100.0 * (1.0 - explained),
            100.0 * (1.0 - MIN_ANCHORED)
        ))
    } else {
        Ok(rec)
    }
}

/// The network anchored on the B-rep `brep` of the cloud of `analysis` (or, when it could not
/// be built, the reason), completed by `points_network` (Demarsin's, [`curve_network`]) where
/// the B-rep leaves points out (its pieces of at least `2 d_max` edges); with no B-rep,
/// `points_network` itself. `points_network` may be `None` only when the B-rep
/// [`explains_all`].
///
/// Errors: a missing `points_network` where it is needed (`InvalidArgument`), and the
/// analysis' errors.
pub fn anchored(
    analysis: &CloudAnalysis,
    brep: std::result::Result<&Reconstruction, String>,
    points_network: Option<&CurveNetwork>,
    d_max: usize,
) -> Result<(CurveNetwork, NetworkSummary)> {
    let missing = || {
        crate::Error::InvalidArgument(
            "network: the B-rep leaves points out, Demarsin's lines are needed there".into(),
        )
    };
    let rec = match brep.and_then(anchorable) {
        Ok(rec) => rec,
        Err(why) => {
            let others = points_network.ok_or_else(missing)?;
            let mut net = CurveNetwork::default();
            let index = KdIndex::new(analysis.points());
            let keep = not_inside_one_surface(analysis, index.as_ref(), others)?;
            add_pieces(&mut net, others, &keep, 2 * d_max);
            smooth_ends(&mut net);
            let summary = NetworkSummary::new(&net, 0, Some(why));
            return Ok((net, summary));
        }
    };
    let spacing = analysis.segmentation()?.mean_edge;
    let complete = explains_all(rec);
    let others = if complete {
        None
    } else {
        Some(points_network.ok_or_else(missing)?)
    };
    let mut net = CurveNetwork::default();
    let b = &rec.brep;
    net.vertices.extend_from_slice(&b.vertices);
    let polylines: Vec<(Vec<Point3>, Option<Group>)> = b
        .edges
        .par_iter()
        .map(|e| {
            let pts = crate::brep::edge_polyline(e, &b.vertices);
            let group = edge_group(b, e, &pts);
            (pts, group)
        })
        .collect();
    // One-sided edges: the open border where no point lies beyond, otherwise the border of a
    // region left out, kept where Demarsin's lines of a group run along it.
    // The analysis' points, indexed once for both tests that read them (built only if needed).
    let index = std::cell::OnceCell::new();
    let points_index = || {
        index
            .get_or_init(|| KdIndex::new(analysis.points()))
            .as_ref()
    };
    let data = polylines
        .iter()
        .any(|(_, g)| *g == Some(Group::OneSided))
        .then(points_index)
        .flatten();
    let along = others.map(GroupIndex::new);
    let mut from_surfaces = 0;
    for (e, (pts, group)) in b.edges.iter().zip(polylines) {
        let group = match group {
            Some(Group::OneSided) => {
                let face = e
                    .faces
                    .iter()
                    .flatten()
                    .next()
                    .map(|&f| &b.faces[f].surface);
                match (face, &data) {
                    (Some(s), Some(data)) if !beyond(data, s, &pts, spacing) => {
                        Some(Group::Boundary)
                    }
                    _ => along.as_ref().and_then(|a| a.along(&pts, 2.0 * spacing)),
                }
            }
            g => g,
        };
        let Some(group) = group else { continue };
        let mut line = Vec::with_capacity(pts.len());
        line.push(e.start as u32);
        for &p in &pts[1..pts.len().saturating_sub(1)] {
            line.push(net.vertices.len() as u32);
            net.vertices.push(p);
        }
        line.push(e.end as u32);
        net.polylines.push(line);
        net.smooth.push(group == Group::Smooth);
        net.boundary.push(group == Group::Boundary);
        from_surfaces += 1;
    }
    if let Some(others) = others {
        let off = off_faces(rec, others, spacing)?;
        let keep = not_inside_one_surface(analysis, points_index(), others)?;
        let keep: Vec<bool> = off.iter().zip(&keep).map(|(a, b)| *a && *b).collect();
        add_pieces(&mut net, others, &keep, 2 * d_max);
    }
    smooth_ends(&mut net);
    let summary = NetworkSummary::new(&net, from_surfaces, None);
    Ok((net, summary))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Group {
    Sharp,
    Smooth,
    Boundary,
    OneSided,
}

/// Whether two surfaces meet tangentially along `pts`: the median angle between their normals
/// at five points along it is under [`TANGENT_DEGREES`].
fn tangent(
    a: &crate::geometry::SurfaceParams,
    b: &crate::geometry::SurfaceParams,
    pts: &[Point3],
) -> bool {
    let mut angles: Vec<f64> = along_fractions(pts, 5)
        .into_iter()
        .map(|p| {
            let c = dot(surface_normal(a, p), surface_normal(b, p)).abs();
            c.clamp(0.0, 1.0).acos().to_degrees()
        })
        .collect();
    angles.sort_by(f64::total_cmp);
    angles[angles.len() / 2] < TANGENT_DEGREES
}

/// `n` points evenly spread along the polyline `pts` (at arc-length fractions i / (n + 1)).
fn along_fractions(pts: &[Point3], n: usize) -> Vec<Point3> {
    let mut cumulative = vec![0.0];
    for w in pts.windows(2) {
        let last = cumulative[cumulative.len() - 1];
        cumulative.push(last + dist(w[0], w[1]));
    }
    let total = cumulative[cumulative.len() - 1];
    (1..=n)
        .map(|i| {
            let s = total * i as f64 / (n + 1) as f64;
            let j = cumulative.partition_point(|&c| c < s).min(pts.len() - 1);
            if j == 0 {
                return pts[0];
            }
            let (a, b) = (pts[j - 1], pts[j]);
            let len = cumulative[j] - cumulative[j - 1];
            let t = if len > 0.0 {
                (s - cumulative[j - 1]) / len
            } else {
                0.0
            };
            [0, 1, 2].map(|k| a[k] + t * (b[k] - a[k]))
        })
        .collect()
}

/// Whether points of the cloud lie on both sides of the one-sided edge `pts` of a face on
/// `surface` (a region left out lies beyond it), rather than on one only (the data ends
/// there): at most of seven points along it, a point within 2 spacings of each of the two
/// spots 3 spacings away across it, in the surface.
fn beyond(
    data: &KdIndex,
    surface: &crate::geometry::SurfaceParams,
    pts: &[Point3],
    spacing: f64,
) -> bool {
    if pts.len() < 2 {
        return false;
    }
    let spots = along_fractions(pts, 7);
    let both = spots
        .iter()
        .filter(|&&q| {
            // The tangent at q: the chord of the nearest polyline vertices.
            let i = (0..pts.len())
                .min_by(|&i, &j| dist(pts[i], q).total_cmp(&dist(pts[j], q)))
                .unwrap_or(0);
            let (a, b) = (pts[i.saturating_sub(1)], pts[(i + 1).min(pts.len() - 1)]);
            let Some(across) = normalize(cross(surface_normal(surface, q), sub(b, a))) else {
                return false;
            };
            [1.0, -1.0].iter().all(|&side| {
                let spot = [0, 1, 2].map(|k| q[k] + side * 3.0 * spacing * across[k]);
                data.nearest_one(&spot).1.sqrt() <= 2.0 * spacing
            })
        })
        .count();
    2 * both > spots.len()
}

/// Demarsin's sharp and smooth vertices, to tell which group runs along an edge.
struct GroupIndex {
    sharp: Option<KdIndex>,
    smooth: Option<KdIndex>,
}

impl GroupIndex {
    fn new(net: &CurveNetwork) -> GroupIndex {
        let of = |want_smooth: bool| {
            let pts: Vec<Point3> = net
                .polylines
                .iter()
                .zip(net.smooth.iter().zip(&net.boundary))
                .filter(|(_, (&s, &b))| s == want_smooth && !b)
                .flat_map(|(l, _)| l.iter().map(|&v| net.vertices[v as usize]))
                .collect();
            KdIndex::new(&pts)
        };
        GroupIndex {
            sharp: of(false),
            smooth: of(true),
        }
    }

    /// The group whose lines pass within `tol` of most of seven points along `pts`.
    fn along(&self, pts: &[Point3], tol: f64) -> Option<Group> {
        let spots = along_fractions(pts, 7);
        let near = |index: &Option<KdIndex>| {
            index.as_ref().map_or(0, |idx| {
                spots
                    .iter()
                    .filter(|q| idx.nearest_one(q).1.sqrt() <= tol)
                    .count()
            })
        };
        let (sharp, smooth) = (near(&self.sharp), near(&self.smooth));
        if 2 * sharp.max(smooth) <= spots.len() {
            None
        } else if sharp >= smooth {
            Some(Group::Sharp)
        } else {
            Some(Group::Smooth)
        }
    }
}

/// The B-rep's faces, to tell how far a point lies from them: the nearest vertex of their
/// tessellation, and the distance beyond which a point is off them (twice the spacing, or the
/// tessellation's median edge if longer).
struct FaceDistance {
    index: Option<KdIndex>,
    tol: f64,
}

impl FaceDistance {
    fn new(rec: &Reconstruction, spacing: f64) -> Result<FaceDistance> {
        let tess = rec.tessellation()?;
        let verts = &tess.vertices.positions;
        let mut edges: Vec<f64> = tess
            .faces
            .iter()
            .map(|f| dist(verts[f[0] as usize], verts[f[1] as usize]))
            .collect();
        edges.sort_by(f64::total_cmp);
        let median = edges.get(edges.len() / 2).copied().unwrap_or(0.0);
        Ok(FaceDistance {
            index: KdIndex::new(verts),
            tol: (2.0 * spacing).max(median),
        })
    }

    /// The distance from `p` to the nearest tessellation vertex (infinite with no faces).
    fn distance(&self, p: &Point3) -> f64 {
        self.index
            .as_ref()
            .map_or(f64::INFINITY, |ix| ix.nearest_one(p).1.sqrt())
    }
}

/// Per vertex of `others`: whether it lies off the B-rep's faces (farther than
/// [`FaceDistance`]'s tolerance from their tessellation).
fn off_faces(rec: &Reconstruction, others: &CurveNetwork, spacing: f64) -> Result<Vec<bool>> {
    let faces = FaceDistance::new(rec, spacing)?;
    Ok(others
        .vertices
        .par_iter()
        .map(|v| faces.distance(v) > faces.tol)
        .collect())
}

/// Demarsin's graph where the B-rep leaves the cloud unexplained (see
/// [`network_off_faces`]).
#[derive(Debug)]
pub struct OffFaces {
    /// Per point, in the analysis' order: Demarsin's fillet label off the B-rep's faces,
    /// [`fillet_labels`]' on them.
    pub labels: Vec<Option<Label>>,
    /// Demarsin's sharp and fillet lines of the points around those off the faces.
    pub network: CurveNetwork,
    /// How many points Demarsin's graph was built on.
    pub points: usize,
}

/// How far around the points off a B-rep's faces Demarsin's graph is built, in spacings: his
/// lines run where first-order regions meet, and a region needs a few rings of points on each
/// side of a line to be told from its neighbour (the 20-neighbour Delaunay rings reach about
/// 2.5 spacings; a line of fewer than `2 d_max` = 10 edges is dropped anyway).
pub const OFF_FACES_MARGIN: f64 = 10.0;

/// Demarsin's lines and fillet labels ([`extract_fillets_with`]) of the cloud of `analysis`
/// only where the B-rep `rec` does not explain it: on the points off its faces and those
/// within [`OFF_FACES_MARGIN`] spacings of them (their own neighbourhoods). A point is off the
/// faces when its nearest vertex of their tessellation lies beyond the tolerance [`anchored`]
/// reads lines off the faces with (twice the spacing, or the tessellation's median edge), and
/// its own surface has no face or it lies three tolerances away (a noisy point of a face's own
/// surface is no seed: on a Kinect scene 1 % of them lie beyond one tolerance, and dilated they
/// cover the scene). [`anchored`] keeps of the lines only what lies off the faces and borders
/// the regions left out, so the rest of the cloud (88 % of a Kinect scene whose B-rep leaves 4
/// small regions out) need not pay for Delaunay rings. Labels elsewhere are
/// [`fillet_labels`]'.
///
/// Errors: those of the analysis, and Demarsin's on the points off the faces (too few for
/// his neighbourhoods, all on one line).
pub fn network_off_faces(
    analysis: &CloudAnalysis,
    rec: &Reconstruction,
    params: &FilletParams,
) -> Result<OffFaces> {
    let seg = analysis.segmentation()?;
    let spacing = seg.mean_edge;
    let faces = FaceDistance::new(rec, spacing)?;
    let mut has_face = vec![false; seg.surfaces.len()];
    for f in &rec.brep.faces {
        if let Some(x) = has_face.get_mut(f.surface_id) {
            *x = true;
        }
    }
    let pts = analysis.points();
    let away: Vec<f64> = pts.par_iter().map(|p| faces.distance(p)).collect();
    // Off the faces: beyond the tolerance, and not a noisy point of a face's own surface.
    let off = |i: usize| {
        let own = usize::try_from(seg.point_surface[i])
            .ok()
            .is_some_and(|s| has_face.get(s).copied().unwrap_or(false));
        away[i] > faces.tol && (!own || away[i] > 3.0 * faces.tol)
    };
    let seeds: Vec<Point3> = (0..pts.len()).filter(|&i| off(i)).map(|i| pts[i]).collect();
    let mut labels = fillet_labels(analysis, rec)?;
    let Some(seeds) = KdIndex::new(&seeds) else {
        return Ok(OffFaces {
            labels,
            network: CurveNetwork::default(),
            points: 0,
        });
    };
    let reach = OFF_FACES_MARGIN * spacing;
    let members: Vec<usize> = (0..pts.len())
        .into_par_iter()
        .filter(|&i| off(i) || seeds.nearest_one(&pts[i]).1 <= reach * reach)
        .collect();
    let sub: Vec<Point3> = members.iter().map(|&i| pts[i]).collect();
    let nbrs = crate::spatial::knn(&sub, params.lines.k)?;
    let mut first = crate::lines::first_order_with(&sub, &nbrs, &params.lines)?;
    drop(nbrs);
    // A point next to the cut (a neighbour of its, in the whole cloud, left out of the
    // subset) has a one-sided ring, but it is no border of the scan.
    let mut member = vec![false; pts.len()];
    for &i in &members {
        member[i] = true;
    }
    let nbrs = analysis.neighbours()?;
    let k = params.lines.k.min(nbrs.k());
    for (b, &i) in first.boundary.iter_mut().zip(&members) {
        if nbrs.prefix(i, k).iter().any(|&j| !member[j as usize]) {
            *b = false;
        }
    }
    let f = extract_fillets_with(&sub, &first, params, true)?;
    for (&i, &l) in members.iter().zip(&f.label) {
        if off(i) {
            labels[i] = l;
        }
    }
    // The lines within half the margin of a point off the faces: nearer the subset's cut, its
    // points' rings are one-sided and Demarsin's regions break along the cut.
    let lines = curve_network(&f);
    let keep: Vec<bool> = lines
        .vertices
        .par_iter()
        .map(|v| seeds.nearest_one(v).1 <= 0.25 * reach * reach)
        .collect();
    let mut network = CurveNetwork::default();
    add_pieces(&mut network, &lines, &keep, 1);
    Ok(OffFaces {
        labels,
        network,
        points: sub.len(),
    })
}

/// Per vertex of `others`: whether it is not inside one surface of the segmentation (see the
/// module documentation); the open border's vertices are.
/// `index` holds the analysis' points.
fn not_inside_one_surface(
    analysis: &CloudAnalysis,
    index: Option<&KdIndex>,
    others: &CurveNetwork,
) -> Result<Vec<bool>> {
    let seg = analysis.segmentation()?;
    let nbrs = analysis.neighbours()?;
    let Some(index) = index else {
        return Ok(vec![true; others.vertices.len()]);
    };
    let labels = &seg.point_surface;
    // The open border lies at the edge of a surface by definition: its vertices are kept.
    let mut border = vec![false; others.vertices.len()];
    for (l, &b) in others.polylines.iter().zip(&others.boundary) {
        if b {
            for &v in l {
                border[v as usize] = true;
            }
        }
    }
    Ok(others
        .vertices
        .par_iter()
        .zip(&border)
        .map(|(v, &border)| {
            if border {
                return true;
            }
            let Some(&(i, _)) = index.nearest(v, 1).first() else {
                return true;
            };
            let i = i as usize;
            let voters = std::iter::once(i as u32).chain(nbrs.of(i).iter().copied());
            let (mut first, mut assigned, mut total) = (-1i32, 0usize, 0usize);
            for j in voters {
                total += 1;
                let l = labels[j as usize];
                if l < 0 {
                    continue;
                }
                if first >= 0 && l != first {
                    return true;
                }
                first = l;
                assigned += 1;
            }
            2 * assigned <= total
        })
        .collect())
}

/// Adds the runs of kept vertices (`keep`) of `others`' polylines, each run of more than
/// `min_edges` edges a polyline of its own group.
fn add_pieces(net: &mut CurveNetwork, others: &CurveNetwork, keep: &[bool], min_edges: usize) {
    let mut index = vec![u32::MAX; others.vertices.len()];
    for (l, (&smooth, &boundary)) in others
        .polylines
        .iter()
        .zip(others.smooth.iter().zip(&others.boundary))
    {
        let mut run: Vec<u32> = Vec::new();
        let mut flush = |run: &mut Vec<u32>, net: &mut CurveNetwork| {
            if run.len() > min_edges.max(1) {
                let line = run
                    .iter()
                    .map(|&v| {
                        if index[v as usize] == u32::MAX {
                            index[v as usize] = net.vertices.len() as u32;
                            net.vertices.push(others.vertices[v as usize]);
                        }
                        index[v as usize]
                    })
                    .collect();
                net.polylines.push(line);
                net.smooth.push(smooth);
                net.boundary.push(boundary);
            }
            run.clear();
        };
        for &v in l {
            if keep[v as usize] {
                run.push(v);
            } else {
                flush(&mut run, net);
            }
        }
        flush(&mut run, net);
    }
}

/// Counts the smooth lines' ends joined to another line and those left open.
fn smooth_ends(net: &mut CurveNetwork) {
    let degree = degrees(net);
    let (mut joined, mut open) = (0, 0);
    for (l, &s) in net.polylines.iter().zip(&net.smooth) {
        if !s || l.len() < 2 || l.first() == l.last() {
            continue;
        }
        for end in [l[0], l[l.len() - 1]] {
            if degree[end as usize] >= 2 {
                joined += 1;
            } else {
                open += 1;
            }
        }
    }
    net.joined_ends = joined;
    net.open_ends = open;
}
