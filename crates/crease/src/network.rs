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

use rayon::prelude::*;
use serde::Serialize;

use crate::analysis::CloudAnalysis;
use crate::brep::{reconstruct_cloud, Reconstruction};
use crate::fillets::{
    curve_network, extract_fillets_from, CurveNetwork, FilletParams, Fillets, Label,
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
    let fillets = match &brep {
        Ok(rec) if !want_fillets && explains_all(rec) => None,
        _ => {
            let f = extract_fillets_from(analysis, params, true)?;
            let net = curve_network(&f);
            Some((f, net))
        }
    };
    let (network, summary) = anchored(
        analysis,
        brep.as_ref().map_err(|e| e.to_string()),
        fillets.as_ref().map(|(_, n)| n),
        params.lines.d_max,
    )?;
    Ok(CloudNetwork {
        network,
        fillets: fillets.map(|(f, _)| f),
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
    let brep = brep.and_then(|rec| {
        let left_out: f64 = rec.report.left_out.iter().map(|l| l.area_fraction).sum();
        if 1.0 - left_out - rec.report.unexplained < MIN_ANCHORED {
            Err(format!(
                "the B-rep leaves {:.0} % of the part out (at most {:.0} % for lines anchored on \
                 it)",
                100.0 * (1.0 - (1.0 - left_out - rec.report.unexplained)),
                100.0 * (1.0 - MIN_ANCHORED)
            ))
        } else {
            Ok(rec)
        }
    });
    let rec = match brep {
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

/// Per vertex of `others`: whether it lies off the B-rep's faces (farther than twice the
/// spacing, or than the tessellation's median edge, from its tessellation).
fn off_faces(rec: &Reconstruction, others: &CurveNetwork, spacing: f64) -> Result<Vec<bool>> {
    let tess = rec.tessellate()?;
    let verts = &tess.vertices.positions;
    let mut edges: Vec<f64> = tess
        .faces
        .iter()
        .map(|f| dist(verts[f[0] as usize], verts[f[1] as usize]))
        .collect();
    edges.sort_by(f64::total_cmp);
    let median = edges.get(edges.len() / 2).copied().unwrap_or(0.0);
    let tol = (2.0 * spacing).max(median);
    let Some(faces) = KdIndex::new(verts) else {
        return Ok(vec![true; others.vertices.len()]);
    };
    Ok(others
        .vertices
        .par_iter()
        .map(|v| faces.nearest_one(v).1.sqrt() > tol)
        .collect())
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
