//! The whole job on one input, every stage reading one shared analysis: what `crease run` and
//! the Python package's `crease.run` compute.
//!
//! * A point cloud ([`run_cloud`]): from one [`CloudAnalysis`] (one neighbour query, one
//!   segmentation), its sharp points ([`crate::sharp::detect`]), its analytic surfaces and its
//!   B-rep ([`crate::brep::reconstruct_cloud`]), and its curve network of sharp and fillet
//!   lines anchored on them ([`crate::network::anchored`]: the B-rep's edges, and Demarsin's
//!   lines, [`crate::fillets::extract_fillets_from`], where no surface explains the points).
//!   Its per-point fillet labels come from the B-rep's fillet faces when the B-rep explains
//!   every point ([`crate::network::fillet_labels`]), and Demarsin's are not computed at all
//!   (their Delaunay rings were most of the network's time at a million points); otherwise
//!   they are Demarsin's.
//! * A triangle mesh ([`run_mesh`]): its feature edges ([`detect_edges`], the default `fused`
//!   method) and their polylines, its segmentation into surfaces on the same edge topology, and
//!   its B-rep from that segmentation.
//!
//! Each stage runs with its default parameters (those of the CLI commands). A B-rep that cannot
//! be built is not an error of the run: the other results stand and [`CloudRun::brep`] holds the
//! reason. The callback `stage` is told when each stage starts (for progress display).

use std::time::Instant;

use crate::analysis::{AnalysisCounts, CloudAnalysis};
use crate::brep::{reconstruct_cloud, reconstruct_segmented_mesh, Reconstruction};
use crate::fillets::{curve_network, extract_fillets_from, CurveNetwork, FilletParams, Label};
use crate::geometry::TriMesh;
use crate::meshfeat::{detect_edges, feature_polylines, EdgeDetection, EdgeParams};
use crate::network::{
    anchorable, anchored, explains_all, fillet_labels, network_off_faces, NetworkSummary,
};
use crate::segment::recognize::Group;
use crate::segment::{segment_mesh, SegmentParams, SegmentSurface, Segmentation};
use crate::sharp::{detect, SharpParams, SharpResult};
use crate::Result;

/// One stage of a run, as told to the progress callback.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Stage {
    /// Its key in [`CloudRun::timings`] / [`MeshRun::timings`].
    pub key: &'static str,
    /// What it computes, for a person.
    pub what: &'static str,
}

const NEIGHBOURS: Stage = Stage {
    key: "neighbours",
    what: "neighbours",
};
const SEGMENTATION: Stage = Stage {
    key: "segmentation",
    what: "segmentation into analytic surfaces",
};
const SHARP_POINTS: Stage = Stage {
    key: "sharp_points",
    what: "sharp points",
};
const CURVE_NETWORK: Stage = Stage {
    key: "curve_network",
    what: "curve network (sharp + fillet lines)",
};
const FEATURE_EDGES: Stage = Stage {
    key: "feature_edges",
    what: "feature edges",
};
const BREP: Stage = Stage {
    key: "brep",
    what: "B-rep",
};

/// Everything [`run_cloud`] finds; per-point values in the input order (copies of a point
/// share its values).
#[derive(Debug)]
pub struct CloudRun {
    /// Sharp points and their sharpness.
    pub sharp: SharpResult,
    /// Per-point fillet labels: from the B-rep's fillet faces where it explains every point
    /// ([`crate::network::fillet_labels`]), otherwise Demarsin's
    /// ([`crate::fillets::Fillets::label`]).
    pub fillet_label: Vec<Option<Label>>,
    /// Sharp, fillet and open-border polylines together, anchored on the surfaces
    /// ([`crate::network::anchored`]: the B-rep's edges, Demarsin's lines where no surface
    /// explains the points).
    pub network: CurveNetwork,
    /// What the network is made of.
    pub network_summary: NetworkSummary,
    /// The surface of every point (−1: none).
    pub surface: Vec<i32>,
    /// The `surface_type` code of every point (as [`crate::segment::PointSegmentation::point_types`]; 255: none).
    pub surface_type: Vec<u8>,
    /// The surfaces with their parameters.
    pub surfaces: Vec<SegmentSurface>,
    /// Surfaces recognised as one feature (a hole's two halves, a fillet's pieces).
    pub groups: Vec<Group>,
    /// The segmentation's unit of length (mean neighbour distance).
    pub mean_edge: f64,
    /// The segmentation's own stage times, seconds.
    pub segmentation_timings: Vec<(&'static str, f64)>,
    /// The B-rep, or why none could be built.
    pub brep: Result<Reconstruction>,
    /// How many times each shared piece of the analysis was computed (1 each).
    pub counts: AnalysisCounts,
    /// Seconds per stage, in the order run.
    pub timings: Vec<(&'static str, f64)>,
}

/// Times the stages of a run, telling `notify` when each starts.
struct Clock<F: FnMut(Stage)> {
    notify: F,
    timings: Vec<(&'static str, f64)>,
}

impl<F: FnMut(Stage)> Clock<F> {
    fn time<T>(&mut self, stage: Stage, f: impl FnOnce() -> T) -> T {
        (self.notify)(stage);
        let start = Instant::now();
        let out = f();
        self.timings
            .push((stage.key, start.elapsed().as_secs_f64()));
        out
    }
}

/// The whole job on a point cloud from its analysis (see the module documentation). Errors:
/// those of the stages (too few points for the neighbourhoods, points on one line, ...), except
/// the B-rep's, which [`CloudRun::brep`] holds.
pub fn run_cloud(analysis: &CloudAnalysis, stage: impl FnMut(Stage)) -> Result<CloudRun> {
    let mut clock = Clock {
        notify: stage,
        timings: Vec::new(),
    };
    clock.time(NEIGHBOURS, || analysis.neighbours().map(|_| ()))?;
    let seg = clock.time(SEGMENTATION, || analysis.segmentation())?;
    let sharp = clock.time(SHARP_POINTS, || detect(analysis, &SharpParams::default()))?;
    let brep = clock.time(BREP, || reconstruct_cloud(analysis));
    let params = FilletParams::default();
    let (fillet_label, network, network_summary) = clock.time(CURVE_NETWORK, || {
        if let Some(rec) = brep.as_ref().ok().filter(|rec| explains_all(rec)) {
            // The B-rep's edges are the whole network and its faces give the labels.
            let labels = analysis.to_input_order(&fillet_labels(analysis, rec)?);
            let (net, summary) = anchored(analysis, Ok(rec), None, params.lines.d_max)?;
            return Ok((labels, net, summary));
        }
        if let Some(rec) = brep.as_ref().ok().filter(|rec| anchorable(rec).is_ok()) {
            // Demarsin's graph only where the B-rep leaves the cloud out (on the whole cloud
            // below if that fails: too few points there for his neighbourhoods).
            if let Ok(off) = network_off_faces(analysis, rec, &params) {
                let (net, summary) =
                    anchored(analysis, Ok(rec), Some(&off.network), params.lines.d_max)?;
                return Ok((analysis.to_input_order(&off.labels), net, summary));
            }
        }
        let f = extract_fillets_from(analysis, &params, true)?;
        let points_network = curve_network(&f);
        let (net, summary) = anchored(
            analysis,
            brep.as_ref().map_err(|e| e.to_string()),
            Some(&points_network),
            params.lines.d_max,
        )?;
        Ok::<_, crate::Error>((f.label, net, summary))
    })?;
    Ok(CloudRun {
        sharp,
        fillet_label,
        network,
        network_summary,
        surface: analysis.to_input_order(&seg.point_surface),
        surface_type: analysis.to_input_order(&seg.point_types()),
        surfaces: seg.surfaces.clone(),
        groups: seg.groups.clone(),
        mean_edge: seg.mean_edge,
        segmentation_timings: seg.timings.clone(),
        brep,
        counts: analysis.counts(),
        timings: clock.timings,
    })
}

/// Everything [`run_mesh`] finds.
#[derive(Debug)]
pub struct MeshRun {
    /// The mesh's edges (vertex pairs), in the order of the per-edge results.
    pub edges: Vec<[u32; 2]>,
    /// Per-edge sharp labels and sharpness.
    pub detection: EdgeDetection,
    /// The sharp edges chained into polylines (vertex indices).
    pub polylines: Vec<Vec<u32>>,
    /// The faces' surfaces with their parameters.
    pub segmentation: Segmentation,
    /// The B-rep, or why none could be built.
    pub brep: Result<Reconstruction>,
    /// Seconds per stage, in the order run.
    pub timings: Vec<(&'static str, f64)>,
}

/// The whole job on a triangle mesh (see the module documentation). Errors: those of the edge
/// detection and the segmentation, except the B-rep's, which [`MeshRun::brep`] holds.
pub fn run_mesh(mesh: &TriMesh, stage: impl FnMut(Stage)) -> Result<MeshRun> {
    let mut clock = Clock {
        notify: stage,
        timings: Vec::new(),
    };
    let (em, detection) =
        clock.time(FEATURE_EDGES, || detect_edges(mesh, &EdgeParams::default()))?;
    let edges = em.topo.edges().to_vec();
    let polylines = feature_polylines(&em.topo, &detection.sharp);
    // The segmentation reads the edge topology the feature edges were computed on.
    let segmentation = clock.time(SEGMENTATION, || {
        segment_mesh(mesh, &em.topo, &SegmentParams::default())
    })?;
    drop(em);
    let brep = clock.time(BREP, || {
        reconstruct_segmented_mesh(mesh, segmentation.clone(), &SegmentParams::default())
    });
    Ok(MeshRun {
        edges,
        detection,
        polylines,
        segmentation,
        brep,
        timings: clock.timings,
    })
}
