//! `crease reconstruct IN -o part.step [--mesh part.ply] [--topology topo.json] [--units mm]`:
//! the part as a boundary representation (B-rep) in a STEP file (`crease::brep`): the mesh
//! segmented into analytic surfaces, their intersection curves and vertices, a solid when the
//! mesh is closed and an open shell otherwise; optionally also tessellated. A point cloud goes through the shared analysis and its
//! envelope (`crease::brep::reconstruct_cloud`).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use crease::analysis::AnalysisParams;
use crease::brep::{reconstruct_mesh, reconstruct_points, LengthUnit};
use crease::geometry::TriMesh;
use crease::segment::SegmentParams;

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease reconstruct`.
#[derive(Args, Debug)]
pub struct ReconstructArgs {
    /// The part: a triangle mesh (.ply .obj .off .stl; oriented and 2-manifold) or a point
    /// cloud (any format crease reads; its normals are used when it has them, else estimated).
    pub input: PathBuf,
    /// Output STEP file (.step or .stp).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the B-rep as a triangle mesh (any mesh format crease writes: .ply .obj .off
    /// .stl): each face's triangles on its surface, sharing the vertices of its edges, with the
    /// B-rep face and surface type of every triangle (`face`, `surface_type`).
    #[arg(long, value_name = "MESH")]
    pub mesh: Option<PathBuf>,
    /// Also write the B-rep's topology and geometry as JSON: faces with their surface type and
    /// parameters and loops, edges with their curve and two faces, vertices.
    #[arg(long, value_name = "JSON")]
    pub topology: Option<PathBuf>,
    /// The length unit the coordinates are in, declared in the STEP file (mm, m, in).
    #[arg(long, default_value = "mm")]
    pub units: LengthUnit,
    /// Segmentation: how far a vertex may lie from its surface, in mean edge lengths.
    #[arg(
        long = "distance-tolerance",
        value_name = "EDGES",
        default_value_t = 0.5
    )]
    pub th_pos: f64,
    /// Segmentation: how far a normal may turn from its surface's, degrees.
    #[arg(
        long = "angle-tolerance",
        value_name = "DEGREES",
        default_value_t = 8.0
    )]
    pub th_norm: f64,
    /// Clouds: estimate normals (PCA + orientation) even when the file has some.
    #[arg(long)]
    pub estimate_normals: bool,
}

pub fn run(g: &Global, a: &ReconstructArgs) -> anyhow::Result<()> {
    let ext = a
        .output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("step" | "stp")) {
        return Err(usage(format!(
            "{}: the output must be a STEP file (.step or .stp)",
            a.output.display()
        )));
    }
    let mut outputs = vec![&a.output];
    outputs.extend(a.topology.iter());
    outputs.extend(a.mesh.iter());
    for o in &outputs {
        crate::ui::ensure_not_input(o, &[&a.input])?;
    }
    let params = SegmentParams {
        th_pos: a.th_pos,
        th_norm_degrees: a.th_norm,
        ..Default::default()
    };
    params.validate().map_err(|e| usage(e.to_string()))?;
    let (mut geom, _) = super::load_shape(g, &a.input)?;
    let start = Instant::now();
    let stage = Stage::start("B-rep: surfaces, faces, edges, vertices", g.quiet);
    let rec = if geom.is_mesh() {
        let mesh = TriMesh {
            vertices: std::mem::take(&mut geom.points),
            faces: std::mem::take(&mut geom.faces),
            face_attributes: std::mem::take(&mut geom.face_attributes),
        };
        reconstruct_mesh(&mesh, &params)
    } else {
        let analysis = AnalysisParams {
            segment: params,
            ..Default::default()
        };
        let normals = if a.estimate_normals {
            None
        } else {
            geom.points.normals.as_deref()
        };
        reconstruct_points(&geom.points.positions, normals, analysis)
    };
    let rec = rec.with_context(|| format!("cannot build a B-rep of {}", a.input.display()))?;
    stage.finish();
    let name = a
        .input
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "part".into());
    let uncertainty = rec.uncertainty();
    let text = rec.to_step(&name, a.units);
    crate::ui::write_text(&a.output, &text)
        .with_context(|| format!("cannot write {}", a.output.display()))?;
    if let Some(p) = &a.topology {
        crate::ui::write_text(p, &(serde_json::to_string_pretty(&rec.brep)? + "\n"))
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    if let Some(p) = &a.mesh {
        let out = crease::io::Geometry::from_mesh(rec.tessellate()?);
        super::save(g, p, &out, false, &[&a.input])
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    for w in &rec.report.warnings {
        tracing::warn!("{}: {w}", a.input.display());
    }
    let seconds = start.elapsed().as_secs_f64();
    let r = &rec.report;
    if g.json {
        crate::ui::print_json(&serde_json::json!({
            "input": a.input,
            "output": a.output,
            "solid": r.closed,
            "faces": rec.brep.faces.len(),
            "edges": rec.brep.edges.len(),
            "report": r,
            "uncertainty": uncertainty,
            "seconds": seconds,
        }))?;
    } else if !g.quiet {
        crate::ui::outln(format_args!(
            "wrote {}: {} with {} faces {:?}, {} edges {:?}, {} vertices; max gap {:.3e}, RMS \
             mesh distance {:.3e} in {seconds:.2} s",
            a.output.display(),
            if r.closed { "a solid" } else { "an open shell" },
            rec.brep.faces.len(),
            r.faces_by_type,
            rec.brep.edges.len(),
            r.edges_by_curve,
            r.vertices,
            r.max_gap,
            r.rms_distance,
        ))?;
    }
    Ok(())
}
