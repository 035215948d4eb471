//! `crease run IN -o DIR`: the whole job in one command, every stage reading one shared
//! analysis of the input (`crease::analysis`).
//!
//! A point cloud gets its sharp points, its curve network (sharp and fillet lines) and its
//! analytic surfaces from one neighbour query and one segmentation; a triangle mesh gets its
//! feature edges (the default `fused` method), their polylines and its segmentation into
//! surfaces (`crease::pipeline`). DIR receives:
//!
//! | file | cloud | mesh |
//! |---|---|---|
//! | `labels.ply` | the points with `sharp`, `sharpness`, `surface`, `surface_type`, `fillet_label`, `smooth_edge` (input order) | the mesh with per-face `surface`, `surface_type` and an `edge` element with `sharp`, `sharpness` |
//! | `network.obj` | sharp, fillet and open-border polylines (OBJ groups `sharp`, `smooth`, `boundary`), anchored on the surfaces (`crease::network`) | the feature-edge polylines (group `sharp`) |
//! | `surfaces.json` | the surfaces with their parameters | the same |
//! | `part.step` | the B-rep (`crease::brep::reconstruct_cloud` on the same analysis): a solid, or an open shell saying what it leaves out; when none can be built the summary says why | the same (`crease::brep::reconstruct_segmented_mesh` on the same segmentation) |
//! | `summary.json` | counts, per-stage times, how often each shared piece was computed | the same |
//! | `picture.png` | the points coloured by surface, the network on top | the mesh coloured by surface, the edges on top |
//! | `report.html` | an interactive 3D view (`crease view`): the points with every label, the network's groups as layers, a click shows a point's surface | the mesh's faces with their surfaces, the edges |

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use crease::analysis::{AnalysisParams, CloudAnalysis};
use crease::brep::LengthUnit;
use crease::fillets::Label;
use crease::geometry::{names, Attribute, PointCloud, ScalarKind, TriMesh};
use crease::io::Geometry;
use crease::pipeline::{run_cloud as run_cloud_job, run_mesh as run_mesh_job};
use crease::render::html::{Overlay, PageParams};
use crease::render::{ColorBy, Polyline, RenderParams, Scene};
use crease::segment::SegmentSurface;

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// Point cloud or triangle mesh (any supported format; a file with faces is a mesh).
    pub input: PathBuf,
    /// Output folder (created if missing; files in it with the names above are replaced).
    #[arg(short, long, value_name = "DIR")]
    pub output: PathBuf,
    /// Do not draw `picture.png`.
    #[arg(long)]
    pub no_picture: bool,
    /// Write text instead of binary PLY.
    #[arg(long)]
    pub ascii: bool,
}

/// The colour of sharp lines in the picture.
const SHARP_COLOR: [u8; 3] = [220, 30, 30];
/// The colour of smooth (fillet) lines in the picture.
const SMOOTH_COLOR: [u8; 3] = [30, 90, 220];
/// The cloud's open border in the picture: dark grey (no feature).
const BOUNDARY_COLOR: [u8; 3] = [90, 90, 90];

pub fn run(g: &Global, a: &RunArgs) -> anyhow::Result<()> {
    // The folder is made (or found unwritable) before any computation.
    if a.output.exists() && !a.output.is_dir() {
        return Err(usage(format!(
            "{}: exists and is not a folder; `crease run` writes several files into a folder",
            a.output.display()
        )));
    }
    std::fs::create_dir_all(&a.output)
        .with_context(|| format!("cannot create the output folder {}", a.output.display()))?;
    for name in [
        "labels.ply",
        "network.obj",
        "surfaces.json",
        "summary.json",
        "picture.png",
        "part.step",
        "report.html",
    ] {
        crate::ui::ensure_not_input(&a.output.join(name), &[&a.input])?;
    }
    let start = Instant::now();
    let (geom, report) = super::load_shape(g, &a.input)?;
    let mut summary = if geom.is_mesh() {
        run_mesh(g, a, geom)?
    } else {
        run_cloud(g, a, geom)?
    };
    summary["input"] = serde_json::json!(a.input);
    summary["output"] = serde_json::json!(a.output);
    summary["dropped_nonfinite"] = serde_json::json!(report.dropped_nonfinite);
    summary["seconds"] = serde_json::json!(start.elapsed().as_secs_f64());
    write_json(&a.output.join("summary.json"), &summary)?;
    if g.json {
        crate::ui::print_json(&summary)?;
    } else if !g.quiet {
        eprintln!(
            "wrote {}: {} in {:.2} s",
            a.output.display(),
            summary["line"].as_str().unwrap_or_default(),
            start.elapsed().as_secs_f64()
        );
    }
    Ok(())
}

/// Shows each stage of a [`crease::pipeline`] run while it computes.
struct Progress {
    quiet: bool,
    current: Option<Stage>,
}

impl Progress {
    fn new(quiet: bool) -> Progress {
        Progress {
            quiet,
            current: None,
        }
    }

    fn start(&mut self, stage: crease::pipeline::Stage) {
        self.end();
        self.current = Some(Stage::start(stage.what, self.quiet));
    }

    fn end(&mut self) {
        if let Some(s) = self.current.take() {
            s.finish();
        }
    }
}

/// Seconds per stage as a JSON object.
fn timings_json(t: &[(&'static str, f64)]) -> serde_json::Map<String, serde_json::Value> {
    t.iter()
        .map(|(k, v)| (k.to_string(), serde_json::json!(v)))
        .collect()
}

/// The cloud path: one analysis, then sharp points, the curve network and the surfaces.
fn run_cloud(g: &Global, a: &RunArgs, geom: Geometry) -> anyhow::Result<serde_json::Value> {
    let name = a.input.display().to_string();
    let points = &geom.points.positions;
    let analysis =
        CloudAnalysis::new(points, AnalysisParams::default()).with_context(|| name.clone())?;
    let mut progress = Progress::new(g.quiet);
    let run = run_cloud_job(&analysis, |s| progress.start(s)).with_context(|| name.clone());
    progress.end();
    let run = run?;
    // The outputs are written from `run` alone: the analysis (neighbour lists, normals, the
    // segmentation's graph) goes, and the input's points become the labelled cloud without a
    // copy (together 30 % of the peak memory at a million points, which was in the report).
    drop(analysis);
    let sharp = &run.sharp;
    let network = &run.network;

    let mut cloud = geom.points;
    cloud.set_attribute(Attribute::flag(names::SHARP, sharp.sharp.iter().copied()))?;
    cloud.set_attribute(Attribute::float(names::SHARPNESS, sharp.sharpness.clone()))?;
    cloud.set_attribute(Attribute::int(
        names::SURFACE,
        run.surface.iter().map(|&s| i64::from(s)),
    ))?;
    cloud.set_attribute(uchar(names::SURFACE_TYPE, run.surface_type.iter().copied()))?;
    cloud.set_attribute(uchar(
        names::FILLET_LABEL,
        run.fillet_label.iter().map(|l| l.map_or(255, |l| l as u8)),
    ))?;
    cloud.set_attribute(Attribute::flag(
        names::SMOOTH_EDGE,
        run.fillet_label.iter().map(|&l| l == Some(Label::Border)),
    ))?;
    let labels = Geometry::from_cloud(cloud);
    super::save(
        g,
        &a.output.join("labels.ply"),
        &labels,
        a.ascii,
        &[&a.input],
    )?;

    let mut net = Geometry::from_cloud(PointCloud::from_positions(network.vertices.clone()));
    net.polylines = network.polylines.clone();
    net.polyline_groups = network.groups().iter().map(|g| g.to_string()).collect();
    super::save(g, &a.output.join("network.obj"), &net, false, &[&a.input])?;
    let surfaces = write_surfaces(&a.output, &run.surfaces, &run.groups, run.mean_edge)?;
    let points = &labels.points.positions;
    let brep = write_brep(a, &name, &run.brep)?;

    let sharp_lines = network.count(names::SHARP);
    let smooth_lines = network.count(names::SMOOTH);
    let lines: Vec<Polyline> = network
        .polylines
        .iter()
        .zip(network.groups())
        .map(|(l, group)| picture_line(l, &network.vertices, group))
        .collect();
    if !a.no_picture {
        picture(a, &labels, None, lines.clone(), run.surfaces.len())?;
    }
    report(a, &labels, lines, surfaces, &run.brep)?;
    let assigned = run.surface.iter().filter(|&&s| s >= 0).count();
    Ok(serde_json::json!({
        "kind": "cloud",
        "points": points.len(),
        "sharp_points": sharp.num_sharp(),
        "noise_ratio": sharp.noise_ratio,
        "regularized": sharp.regularized,
        "surfaces": run.surfaces.len(),
        "assigned_points": assigned,
        "sharp_polylines": sharp_lines,
        "smooth_polylines": smooth_lines,
        "boundary_polylines": network.count(names::BOUNDARY),
        "joined_smooth_ends": network.joined_ends,
        "open_smooth_ends": network.open_ends,
        "curve_network": run.network_summary,
        "analysis": run.counts,
        "brep": brep,
        "timings": timings_json(&run.timings),
        "segmentation_stages": timings_json(&run.segmentation_timings),
        "sharp_surface_stage": sharp.surfaces,
        "line": format!(
            "{} sharp points, {} sharp and {} fillet polylines, {} surfaces ({} of {} points)",
            sharp.num_sharp(), sharp_lines, smooth_lines, run.surfaces.len(), assigned,
            points.len()
        ),
    }))
}

/// Writes `part.step` from the B-rep of the part, and returns its
/// summary; a part that cannot be built is reported in the summary, not fatal (the other
/// outputs stand).
fn write_brep(
    a: &RunArgs,
    name: &str,
    rec: &crease::Result<crease::brep::Reconstruction>,
) -> anyhow::Result<serde_json::Value> {
    Ok(match rec {
        Ok(rec) => {
            let stem = a
                .input
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "part".into());
            let path = a.output.join("part.step");
            crate::ui::write_text(&path, &rec.to_step(&stem, LengthUnit::Millimetre))
                .with_context(|| format!("cannot write {}", path.display()))?;
            for w in &rec.report.warnings {
                tracing::warn!("{name}: B-rep: {w}");
            }
            serde_json::json!({
                "solid": rec.report.closed,
                "faces": rec.brep.faces.len(),
                "edges": rec.brep.edges.len(),
                "report": rec.report,
            })
        }
        Err(e) => {
            tracing::warn!("{name}: no B-rep: {e}");
            serde_json::json!({ "error": e.to_string() })
        }
    })
}

/// The mesh path: feature edges, their polylines, the segmentation of the faces, the B-rep.
fn run_mesh(g: &Global, a: &RunArgs, geom: Geometry) -> anyhow::Result<serde_json::Value> {
    let name = a.input.display().to_string();
    let mut mesh = geom
        .into_mesh()
        .with_context(|| format!("{name}: faces that are not a triangle mesh"))?;
    let mut progress = Progress::new(g.quiet);
    let run = run_mesh_job(&mesh, |s| progress.start(s)).with_context(|| name.clone());
    progress.end();
    let run = run?;
    let seg = &run.segmentation;
    let brep = write_brep(a, &name, &run.brep)?;

    mesh.set_face_attribute(Attribute::int(
        names::SURFACE,
        seg.face_surface.iter().map(|&s| i64::from(s)),
    ))?;
    mesh.set_face_attribute(uchar(names::SURFACE_TYPE, seg.face_types()))?;
    let det = &run.detection;
    let n_edges = run.edges.len();
    let n_sharp = det.sharp.iter().filter(|&&s| s).count();
    let lines = &run.polylines;
    let mut out = Geometry::from_mesh(mesh);
    out.edges = run.edges.clone();
    out.edge_attributes.insert(
        n_edges,
        Attribute::flag(names::SHARP, det.sharp.iter().copied()),
    )?;
    out.edge_attributes.insert(
        n_edges,
        Attribute::float(names::SHARPNESS, det.sharpness.clone()),
    )?;
    super::save(g, &a.output.join("labels.ply"), &out, a.ascii, &[&a.input])?;
    let mut net = Geometry::from_cloud(PointCloud::from_positions(out.points.positions.clone()));
    net.polylines = lines.clone();
    net.polyline_groups = vec![names::SHARP.to_string(); lines.len()];
    super::save(g, &a.output.join("network.obj"), &net, false, &[&a.input])?;
    let surfaces = write_surfaces(&a.output, &seg.surfaces, &seg.groups, seg.mean_edge)?;
    let drawn: Vec<Polyline> = lines
        .iter()
        .map(|l| picture_line(l, &out.points.positions, names::SHARP))
        .collect();
    if !a.no_picture {
        let mesh = out.clone().into_mesh().context("labelled mesh")?;
        picture(a, &out, Some(&mesh), drawn.clone(), seg.surfaces.len())?;
    }
    report(a, &out, drawn, surfaces, &run.brep)?;
    let assigned = seg.face_surface.iter().filter(|&&s| s >= 0).count();
    Ok(serde_json::json!({
        "kind": "mesh",
        "vertices": out.points.len(),
        "faces": out.faces.len(),
        "edges": n_edges,
        "sharp_edges": n_sharp,
        "sharp_polylines": lines.len(),
        "surfaces": seg.surfaces.len(),
        "assigned_faces": assigned,
        "brep": brep,
        "timings": timings_json(&run.timings),
        "line": format!(
            "{n_sharp} of {n_edges} edges sharp in {} polylines, {} surfaces ({} of {} faces)",
            lines.len(), seg.surfaces.len(), assigned, out.faces.len()
        ),
    }))
}

/// `surfaces.json`: the surfaces with their parameters (as `crease segment --primitives`);
/// returns what it wrote.
fn write_surfaces(
    dir: &Path,
    surfaces: &[SegmentSurface],
    groups: &[crease::segment::recognize::Group],
    mean_edge: f64,
) -> anyhow::Result<serde_json::Value> {
    let doc = serde_json::json!({
        "surface_type_codes": {"plane": 0, "cylinder": 1, "cone": 2, "sphere": 3, "torus": 4, "unassigned": 255},
        "mean_edge": mean_edge,
        "surfaces": surfaces,
        "groups": groups,
    });
    write_json(&dir.join("surfaces.json"), &doc)?;
    Ok(doc)
}

/// `report.html`: the interactive view of the labelled input, its lines, its surfaces and the
/// B-rep's faces (a layer, off when the page opens).
fn report(
    a: &RunArgs,
    labels: &Geometry,
    lines: Vec<Polyline>,
    surfaces: serde_json::Value,
    brep: &crease::Result<crease::brep::Reconstruction>,
) -> anyhow::Result<()> {
    let overlays = match brep.as_ref().map(|r| r.tessellate()) {
        Ok(Ok(mesh)) => vec![Overlay {
            name: "B-rep".into(),
            mesh,
            visible: false,
        }],
        Ok(Err(e)) => {
            tracing::warn!(
                "{}: the B-rep could not be tessellated for the report: {e}",
                a.input.display()
            );
            Vec::new()
        }
        Err(_) => Vec::new(),
    };
    let params = PageParams {
        overlays,
        title: a
            .input
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        surfaces: Some(surfaces),
        ..Default::default()
    };
    super::view::write_view(&a.output.join("report.html"), labels, lines, &params)
        .context("cannot write report.html")?;
    Ok(())
}

/// Writes pretty JSON to `path`, replaced atomically.
fn write_json(path: &Path, value: &serde_json::Value) -> anyhow::Result<()> {
    crate::ui::write_text(path, &(serde_json::to_string_pretty(value)? + "\n"))
}

/// A polyline of the network in the picture, coloured by its group ([`names::SHARP`],
/// [`names::SMOOTH`], [`names::BOUNDARY`]).
fn picture_line(ids: &[u32], vertices: &[[f64; 3]], group: &str) -> Polyline {
    let closed = ids.len() > 2 && ids.first() == ids.last();
    let ids = if closed { &ids[..ids.len() - 1] } else { ids };
    let (color, label) = match group {
        names::SMOOTH => (SMOOTH_COLOR, "fillet line"),
        names::BOUNDARY => (BOUNDARY_COLOR, "open border"),
        _ => (SHARP_COLOR, "sharp line"),
    };
    Polyline {
        points: ids.iter().map(|&v| vertices[v as usize]).collect(),
        closed,
        color,
        label: Some(label.to_string()),
    }
}

/// `picture.png`: coloured by surface id (each surface its own colour), lines on top.
fn picture(
    a: &RunArgs,
    labels: &Geometry,
    mesh: Option<&TriMesh>,
    polylines: Vec<Polyline>,
    surfaces: usize,
) -> anyhow::Result<()> {
    let path = a.output.join("picture.png");
    let params = RenderParams {
        color_by: ColorBy::Attribute(names::SURFACE.into()),
        title: Some(format!(
            "{}: {surfaces} surfaces",
            a.input
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        )),
        ..Default::default()
    };
    let scene = Scene {
        mesh,
        points: if mesh.is_some() {
            None
        } else {
            Some(&labels.points)
        },
        polylines,
    };
    crease::render::render_png(&scene, &params, &path)
        .with_context(|| format!("cannot draw {}", path.display()))
}

fn uchar(name: &str, values: impl IntoIterator<Item = u8>) -> Attribute {
    Attribute {
        name: name.to_string(),
        kind: ScalarKind::U8,
        values: values.into_iter().map(f64::from).collect(),
    }
}
