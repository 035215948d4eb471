//! Closed sharp feature lines of point clouds: the graph pipeline of Demarsin et al. 2007
//! ("Detection of closed sharp edges in point clouds using normal estimation and graph theory",
//! Algorithm 1):
//!
//! 1. first-order segmentation: Delaunay 1-ring normals, region growing with α_max = 8°
//!    ([`segment`], section 2.2);
//! 2. G_all: a vertex per cluster, edges between clusters whose points' 1-rings overlap; small
//!    and large clusters split by the mean size ([`graph::build_all`], section 2.3);
//! 3. G_extended: edges between small clusters sharing two large neighbours, within the
//!    largest small–small distance of G_all ([`graph::extend`], section 2.4);
//! 4. G_pruned_mst: minimum spanning forest with large-cluster edges weighted last, then those
//!    edges removed ([`graph::pruned_mst`], section 2.5); also removed: edges at small clusters
//!    that reach fewer than two large clusters within 3 steps of G_all
//!    ([`graph::between_patches`]). This is crease's addition for noise: on noisy clouds the
//!    flat faces are sprinkled with small clusters whose tree wires spurious lines across the
//!    faces (figures: `docs/experiments/sharp-lines.md`);
//! 5. G_pruned_branches: Algorithm 2 with d_max = 5 ([`graph::prune_branches`], section 2.6);
//! 6. G_closed: the connect algorithm for every endpoint, then pruning of what still ends
//!    ([`graph::close`], section 2.7).
//!
//! The network is then split into polylines at junctions (vertices of degree other than 2).
//!
//! **Parameters the paper leaves to the user (section 2.7).** n (candidates of the connect
//! algorithm) and d (shortest acceptable path between linked vertices) default to 2 d_max = 10
//! each, and the distance they stand for comes from the data: the candidates of an endpoint are
//! its n nearest linkable vertices within 2 n h, h being the median edge length of
//! G_pruned_branches (the spacing of the clusters along the lines; small clusters average 1.1 to
//! 1.6 points, Table 1, so h is about one point spacing at any density). d = 10 edges means that
//! linking an endpoint never closes a cycle shorter than the branches Algorithm 2 already treats
//! as noise; case-2 links must not close a cycle of 2 d. Both can be overridden
//! (`LinesParams::n`, `LinesParams::d`, `crease lines --n --d`). How the candidates are chosen
//! and the links ordered differs from the literal reading; see [`graph::close`].
//!
//! 7. G_smooth: every vertex moved onto the local intersection of the smooth patches it
//!    separates ([`smooth`], section 2.8, whose cited report is unavailable).
//!
//! Clouds that are not solids have a boundary: its points (flagged by the Delaunay 1-ring) are
//! linked into lines and included in the graph just before the close step, as the paper does
//! for Fig. 9 ([`graph::boundary_graph`]; on by default, [`LinesParams::boundary`]).

pub mod graph;
pub mod segment;
pub mod smooth;

use std::time::Instant;

use serde::Serialize;

pub use graph::{CloseReport, ClusterGraph};
pub use segment::{region_grow, ClusterLabels};

use crate::analysis::CloudAnalysis;
use crate::estimate::ring_normals;
use crate::geometry::{chain_segments, Csr, Point3};
use crate::spatial::{delaunay_rings, distinct_in_input_order, knn, Neighborhoods, RingParams};
use crate::{Error, Result};

/// Parameters of [`extract_lines`].
#[derive(Debug, Clone, PartialEq)]
pub struct LinesParams {
    /// Nearest neighbours triangulated for the Delaunay 1-rings (section 2.2: 20).
    pub k: usize,
    /// α_max of the region growing, degrees (section 2.2: 8).
    pub alpha_max_degrees: f64,
    /// d_max of Algorithm 2 (section 2.6: 5).
    pub d_max: usize,
    /// n of the connect algorithm; `None`: chosen from the data (see the module doc).
    pub n: Option<usize>,
    /// d of the connect algorithm; `None`: chosen from the data (see the module doc).
    pub d: Option<usize>,
    /// Step 7: move the vertices onto the local intersections of the smooth patches.
    pub smooth: bool,
    /// Include the cloud's boundary in the network (Fig. 9); default true.
    pub boundary: bool,
    /// Feature-preserving smoothing of the 1-ring normals before the region growing, scaled
    /// to the measured normal noise (see [`first_order`]); default true. Not in the paper.
    pub denoise_normals: bool,
}

impl Default for LinesParams {
    fn default() -> Self {
        LinesParams {
            k: 20,
            alpha_max_degrees: 8.0,
            d_max: 5,
            n: None,
            d: None,
            smooth: true,
            boundary: true,
            denoise_normals: true,
        }
    }
}

/// Vertex and edge counts of one graph of the pipeline (the paper's Table 2) and its time.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stage {
    /// The graph's name in the paper.
    pub name: &'static str,
    /// Vertices with at least one edge.
    pub vertices: usize,
    /// Edges.
    pub edges: usize,
    /// Seconds spent building it.
    pub seconds: f64,
}

/// The curve network.
#[derive(Debug, Clone, PartialEq)]
pub struct LineNetwork {
    /// Positions of the network's vertices.
    pub vertices: Vec<Point3>,
    /// The cluster each vertex stands for (`u32::MAX` for a boundary point).
    pub vertex_clusters: Vec<u32>,
    /// True for the vertices that are points of the cloud's boundary.
    pub on_boundary: Vec<bool>,
    /// Boundary points in the network before closing.
    pub boundary_points: usize,
    /// Edges between vertices.
    pub edges: Vec<[u32; 2]>,
    /// The edges chained into polylines split at junctions; a closed loop repeats its first
    /// vertex at the end.
    pub polylines: Vec<Vec<u32>>,
    /// Per polyline: true when it runs along the cloud's open border (between boundary
    /// points) rather than along a feature.
    pub boundary_lines: Vec<bool>,
    /// The first-order segmentation (per-point cluster labels).
    pub segmentation: ClusterLabels,
    /// Small / large split of the clusters.
    pub small_clusters: usize,
    /// Per-stage counts and times.
    pub stages: Vec<Stage>,
    /// What the closing step did.
    pub close: CloseReport,
    /// The n and d used.
    pub n: usize,
    /// The d used.
    pub d: usize,
    /// Vertex positions before smoothing (the clusters' centres of mass).
    pub unsmoothed: Vec<Point3>,
}

impl LineNetwork {
    /// Vertices of degree 1.
    pub fn endpoints(&self) -> usize {
        self.counts().endpoints
    }

    /// Vertices of degree 3 or more.
    pub fn junctions(&self) -> usize {
        self.counts().junctions
    }

    /// Polylines that are closed loops.
    pub fn closed_loops(&self) -> usize {
        self.counts().closed_loops
    }

    /// Per polyline, its group: [`crate::geometry::names::BOUNDARY`] along the cloud's open
    /// border, else [`crate::geometry::names::SHARP`] (the OBJ `g` the CLI writes).
    pub fn groups(&self) -> Vec<&'static str> {
        use crate::geometry::names;
        self.boundary_lines
            .iter()
            .map(|&b| if b { names::BOUNDARY } else { names::SHARP })
            .collect()
    }

    fn counts(&self) -> crate::geometry::NetworkCounts {
        crate::geometry::network_counts(self.vertices.len(), &self.edges, &self.polylines)
    }
}

/// How step 7 moves the network's vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Smoothing {
    /// Leave the vertices at their clusters' centres of mass.
    None,
    /// Sharp lines: onto the local intersection of the adjacent smooth patches' planes
    /// ([`smooth::smooth_vertices`]).
    PatchIntersection,
    /// Smooth lines (fillet borders), where the adjacent patches are tangent and their planes do
    /// not intersect: Laplacian smoothing along the polylines, then back onto the cloud's local
    /// plane ([`smooth::smooth_along`]).
    AlongLine,
}

/// The first-order structure of section 2.2 that both the sharp and the smooth pipelines stand
/// on: the symmetrised Delaunay 1-ring adjacency, the boundary flags, the 1-ring normals and the
/// region growing on them.
#[derive(Debug, Clone)]
pub struct FirstOrder {
    /// Symmetrised 1-ring adjacency (p, q adjacent when either is in the other's ring).
    pub adjacency: Csr,
    /// Points on the cloud's boundary (hull of their projected neighbours).
    pub boundary: Vec<bool>,
    /// Least-squares plane normals of the 1-rings.
    pub normals: Vec<Point3>,
    /// Region growing with α_max on the normals.
    pub segmentation: ClusterLabels,
    /// Seconds spent.
    pub seconds: f64,
}

/// The normals are smoothed when their median adjacent angle exceeds this fraction of α_max.
const DENOISE_START: f64 = 0.75;

/// Smoothing stops once the median adjacent angle is at most this fraction of α_max.
const DENOISE_STOP: f64 = 0.25;

/// σ of the bilateral weights, relative to the current median adjacent angle.
const DENOISE_SIGMA: f64 = 1.5;

/// At most this many passes of the bilateral normal smoothing.
const DENOISE_PASSES: usize = 6;

impl LinesParams {
    /// Errors (`InvalidArgument`) on α_max outside (0, 90) degrees, k < 3, d_max = 0, or n
    /// or d given as 0.
    pub fn validate(&self) -> Result<()> {
        check_params(self)
    }
}

fn check_params(params: &LinesParams) -> Result<()> {
    if params.n == Some(0) || params.d == Some(0) {
        return Err(Error::InvalidArgument(
            "sharp lines: n and d of the connect step must be positive".into(),
        ));
    }
    if !(params.alpha_max_degrees > 0.0 && params.alpha_max_degrees < 90.0) {
        return Err(Error::InvalidArgument(format!(
            "alpha_max must be in (0, 90) degrees, got {}",
            params.alpha_max_degrees
        )));
    }
    if params.d_max == 0 || params.k < 3 {
        return Err(Error::InvalidArgument(format!(
            "sharp lines need k >= 3 and d_max >= 1, got k = {} and d_max = {}",
            params.k, params.d_max
        )));
    }
    Ok(())
}

/// Step 1 (section 2.2): Delaunay 1-rings of the `params.k` nearest neighbours, their normals,
/// and region growing with `params.alpha_max_degrees`.
///
/// **Noisy clouds (an addition to the paper).** A 1-ring holds about six points, so its
/// least-squares normal follows the noise: with Gaussian noise of 20 % of the spacing along the
/// normal, adjacent 1-ring normals on a flat face differ by more than α_max = 8° at the median,
/// and the region growing shatters the faces into thousands of small clusters and hundreds of
/// polylines. With `params.denoise_normals`, when the
/// median adjacent angle exceeds 0.75 α_max, the normals are smoothed by bilateral passes
/// ([`segment::smooth_normals`], σ = 1.5 × the current median angle) until that median is at
/// most α_max / 4 (at most 6 passes). Normals across a 90° edge differ by about 45° per step
/// and keep a weight below exp(−4), so the edges stay; shallow creases are blurred, which is
/// why clouds quiet enough for the plain region growing (10 % noise and less) are left as they
/// are. σ = 1.5 × the median keeps the 45° chamfer lines, which σ = 2 erases at 20 % noise
/// (`examples/lines_synth.rs`, figures in `docs/experiments/sharp-lines.md`).
pub fn first_order(points: &[Point3], params: &LinesParams) -> Result<FirstOrder> {
    check_params(params)?;
    let t = Instant::now();
    let nbrs = knn(points, params.k)?;
    let mut first = first_order_with(points, &nbrs, params)?;
    first.seconds = t.elapsed().as_secs_f64();
    Ok(first)
}

/// [`first_order`] from precomputed neighbour lists (at least `params.k` per row, nearest first;
/// the Delaunay 1-rings read the first `params.k`).
///
/// Errors: neighbour lists shorter than `params.k`, invalid parameters.
pub fn first_order_with(
    points: &[Point3],
    nbrs: &Neighborhoods,
    params: &LinesParams,
) -> Result<FirstOrder> {
    check_params(params)?;
    let t = Instant::now();
    let rings = delaunay_rings(points, nbrs, &RingParams { k: params.k })?;
    let normals = ring_normals(points, &rings);
    let adjacency = rings.symmetrized();
    let mut normals = normals;
    if params.denoise_normals {
        let alpha = params.alpha_max_degrees.to_radians();
        let mut noise = segment::median_adjacent_angle(&normals, &adjacency);
        if noise > DENOISE_START * alpha {
            for _ in 0..DENOISE_PASSES {
                normals = segment::smooth_normals(&normals, &adjacency, DENOISE_SIGMA * noise, 1);
                noise = segment::median_adjacent_angle(&normals, &adjacency);
                if noise <= DENOISE_STOP * alpha {
                    break;
                }
            }
        }
    }
    let boundary = rings.boundary.clone();
    drop(rings);
    let segmentation = region_grow(&normals, &adjacency, params.alpha_max_degrees.to_radians());
    Ok(FirstOrder {
        adjacency,
        boundary,
        normals,
        segmentation,
        seconds: t.elapsed().as_secs_f64(),
    })
}

/// Runs the pipeline (see the module documentation) on `points`. Exact duplicates are
/// processed once (their copies take the original's segmentation label).
///
/// Errors: fewer than k + 1 distinct points, non-finite coordinates, invalid parameters.
pub fn extract_lines(points: &[Point3], params: &LinesParams) -> Result<LineNetwork> {
    let Some(distinct) = distinct_in_input_order(points) else {
        let first = first_order(points, params)?;
        return lines_of(points, &first, params);
    };
    let first = first_order(&distinct.points, params)?;
    let mut net = lines_of(&distinct.points, &first, params)?;
    net.segmentation.labels = distinct.expand(&net.segmentation.labels);
    Ok(net)
}

/// [`extract_lines`] on a shared analysis of the cloud: the Delaunay 1-rings are built from its
/// neighbour lists (`params.k` must be at most its `max_k`); the network's per-point
/// segmentation is in the cloud's input order.
///
/// Errors: the analysis' neighbour errors, `params.k` above its `max_k`, invalid parameters.
pub fn extract_lines_from(analysis: &CloudAnalysis, params: &LinesParams) -> Result<LineNetwork> {
    let first = first_order_with(analysis.points(), analysis.neighbours()?, params)?;
    let mut net = lines_of(analysis.points(), &first, params)?;
    net.segmentation.labels = analysis.to_input_order(&net.segmentation.labels);
    Ok(net)
}

/// Steps 2 to 7 on the sharp-line segmentation of `first`.
fn lines_of(points: &[Point3], first: &FirstOrder, params: &LinesParams) -> Result<LineNetwork> {
    let boundary = params.boundary.then_some(first.boundary.as_slice());
    let smoothing = if params.smooth {
        Smoothing::PatchIntersection
    } else {
        Smoothing::None
    };
    network(
        points,
        first.segmentation.clone(),
        &first.adjacency,
        boundary,
        params,
        smoothing,
        first.seconds,
    )
}

/// Steps 2 to 7 on any segmentation of `points` into large clusters (patches) bounded by small
/// clusters (the feature): the sharp lines run it on the 1-ring-normal segmentation, the fillet
/// lines of [`crate::fillets`] on their curvature-label segmentation. `adjacency` is the
/// symmetric point adjacency the segmentation grew over; `boundary`, when given, flags the
/// points whose boundary lines join the graph before the close step; `seg_seconds` is added to
/// the first stage's time.
///
/// Errors: invalid parameters.
pub fn network(
    points: &[Point3],
    seg: ClusterLabels,
    adjacency: &Csr,
    boundary: Option<&[bool]>,
    params: &LinesParams,
    smoothing: Smoothing,
    seg_seconds: f64,
) -> Result<LineNetwork> {
    check_params(params)?;
    let mut stages = Vec::new();
    let t = Instant::now();
    let (mut clusters, mut g) = graph::build_all(points, &seg.labels, &seg.sizes, adjacency);
    stages.push(Stage {
        name: "segmentation+G_all",
        vertices: g.num_active_vertices(),
        edges: g.num_edges(),
        seconds: seg_seconds + t.elapsed().as_secs_f64(),
    });
    let mut timed = |name: &'static str, g: &ClusterGraph, t: Instant| {
        stages.push(Stage {
            name,
            vertices: g.num_active_vertices(),
            edges: g.num_edges(),
            seconds: t.elapsed().as_secs_f64(),
        })
    };
    // Small clusters that border only one smooth patch (noise islands) take no part in lines.
    let feature = graph::between_patches(&clusters, &g, 3);
    let t = Instant::now();
    graph::extend(&clusters, &mut g);
    timed("G_extended", &g, t);
    let t = Instant::now();
    let mut g = graph::pruned_mst(&clusters, &g);
    for [a, b] in g.edges() {
        if !feature[a as usize] || !feature[b as usize] {
            g.remove_edge(a, b);
        }
    }
    timed("G_pruned_mst", &g, t);
    let t = Instant::now();
    graph::prune_branches(&mut g, params.d_max);
    timed("G_pruned_branches", &g, t);
    // The cloud's boundary joins the graph just before the close step (Fig. 9).
    let num_clusters = g.num_vertices();
    let mut boundary_points = 0;
    if let Some(flags) = boundary.filter(|f| f.iter().any(|&b| b)) {
        let t = Instant::now();
        let (ids, bg) = graph::boundary_graph(points, flags, adjacency, params.d_max);
        boundary_points = bg.num_active_vertices();
        g.append(&bg);
        for &i in &ids {
            clusters.centers.push(points[i as usize]);
            clusters.sizes.push(1);
            clusters.small.push(true);
        }
        timed("boundary", &bg, t);
    }
    let n = params.n.unwrap_or(2 * params.d_max);
    let d = params.d.unwrap_or(2 * params.d_max);
    let t = Instant::now();
    let close = graph::close(&clusters, &mut g, n, d);
    timed("G_closed", &g, t);

    // Compact to the vertices in use.
    let mut index = vec![u32::MAX; g.num_vertices()];
    let mut vertices = Vec::new();
    let mut vertex_clusters = Vec::new();
    let mut on_boundary = Vec::new();
    for v in 0..g.num_vertices() as u32 {
        if g.degree(v) > 0 {
            index[v as usize] = vertices.len() as u32;
            vertices.push(clusters.centers[v as usize]);
            let b = v as usize >= num_clusters;
            vertex_clusters.push(if b { u32::MAX } else { v });
            on_boundary.push(b);
        }
    }
    let edges: Vec<[u32; 2]> = g
        .edges()
        .into_iter()
        .map(|[a, b]| [index[a as usize], index[b as usize]])
        .collect();
    // An open scan's border is not a feature line: the edges between two border vertices chain
    // into polylines of their own (`boundary_lines`), never into a sharp line (a sharp line
    // that meets the border ends there, on a vertex both share). Border vertices: the
    // boundary points, and the small clusters made mostly of boundary points (the one-sided
    // neighbourhoods along a border look like a feature to the first-order segmentation).
    let mut on_border = on_boundary.clone();
    if let Some(flags) = boundary {
        let mut share = vec![0u32; seg.sizes.len()];
        for (&l, &b) in seg.labels.iter().zip(flags) {
            if b {
                if let Some(c) = share.get_mut(l as usize) {
                    *c += 1;
                }
            }
        }
        for (border, &c) in on_border.iter_mut().zip(&vertex_clusters) {
            if let (Some(&k), Some(&size)) = (share.get(c as usize), seg.sizes.get(c as usize)) {
                *border |= 2 * k >= size && size > 0;
            }
        }
    }
    let (border, feature): (Vec<[u32; 2]>, Vec<[u32; 2]>) = edges
        .iter()
        .partition(|&&[a, b]| on_border[a as usize] && on_border[b as usize]);
    let mut polylines = chain_segments(vertices.len(), &feature);
    let border_lines = chain_segments(vertices.len(), &border);
    let mut boundary_lines = vec![false; polylines.len()];
    boundary_lines.resize(polylines.len() + border_lines.len(), true);
    polylines.extend(border_lines);
    let t = Instant::now();
    let unsmoothed = vertices.clone();
    let vertices = match smoothing {
        Smoothing::None => vertices,
        Smoothing::PatchIntersection => smooth::smooth_vertices(
            points,
            &seg.labels,
            &clusters.small,
            &vertices,
            3 * params.k,
        ),
        Smoothing::AlongLine => smooth::smooth_along(points, &vertices, &edges, params.k),
    };
    stages.push(Stage {
        name: "G_smooth",
        vertices: vertices.len(),
        edges: edges.len(),
        seconds: t.elapsed().as_secs_f64(),
    });
    let small_clusters = clusters.small.iter().filter(|&&s| s).count();
    Ok(LineNetwork {
        vertices,
        vertex_clusters,
        on_boundary,
        boundary_points,
        edges,
        polylines,
        boundary_lines,
        segmentation: seg,
        small_clusters,
        stages,
        close,
        n,
        d,
        unsmoothed,
    })
}
