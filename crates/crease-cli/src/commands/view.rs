//! `crease view IN -o view.html`: an interactive 3D view in one self-contained HTML file that any
//! browser opens offline (`crease::render::html`): the points or the mesh coloured by any
//! attribute, polylines as layers, a click shows a point's or face's attributes and its surface.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use crease::geometry::names;
use crease::io::Geometry;
use crease::render::html::{page, PageParams};
use crease::render::{Polyline, Scene};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// Point cloud or mesh to show (any supported format).
    pub input: PathBuf,
    /// Polylines to show as layers (OBJ groups such as `sharp`, `smooth`, `boundary` each a
    /// layer; PLY edges; repeatable).
    #[arg(long, value_name = "FILE")]
    pub lines: Vec<PathBuf>,
    /// The attribute the points (or faces) are first coloured by (default: `surface` when
    /// present, else stored colours); the page lets you switch.
    #[arg(long, value_name = "ATTR")]
    pub color_by: Option<String>,
    /// A segmentation of the same input (`crease segment -o seg.ply`): its `surface` and
    /// `surface_type` labels are shown with the input's attributes.
    #[arg(long, value_name = "FILE")]
    pub surfaces: Option<PathBuf>,
    /// The surfaces' parameters (`crease segment --primitives`, `crease run`'s surfaces.json):
    /// a click on a point shows its surface's type, parameters, point count and RMS.
    #[arg(long, value_name = "JSON")]
    pub primitives: Option<PathBuf>,
    /// Above this many points, an even subsample of this size is shown (the page says so).
    #[arg(long, value_name = "N", default_value_t = 2_000_000)]
    pub max_points: usize,
    /// Title shown on the page (default: the input's file name).
    #[arg(long)]
    pub title: Option<String>,
    /// Output HTML file.
    #[arg(short, long)]
    pub output: PathBuf,
}

pub fn run(g: &Global, a: &ViewArgs) -> anyhow::Result<()> {
    let ext = a
        .output
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("html" | "htm")) {
        return Err(usage(format!(
            "{}: the view is an HTML file (.html)",
            a.output.display()
        )));
    }
    if a.max_points == 0 {
        return Err(usage("--max-points must be at least 1".to_string()));
    }
    let mut inputs: Vec<&Path> = vec![&a.input];
    inputs.extend(a.lines.iter().map(PathBuf::as_path));
    inputs.extend(a.surfaces.as_deref());
    inputs.extend(a.primitives.as_deref());
    crate::ui::ensure_not_input(&a.output, &inputs)?;
    let (mut geom, _) = super::load(g, &a.input)?;
    if let Some(seg) = &a.surfaces {
        let (s, _) = super::load(g, seg)?;
        attach_segmentation(&mut geom, &s, seg, &a.input)?;
    }
    let surfaces = match &a.primitives {
        Some(p) => Some(read_json(p)?),
        None => None,
    };
    let title = a.title.clone().unwrap_or_else(|| file_name(&a.input));
    let stage = Stage::start("writing the view", g.quiet);
    let polylines = polylines_of_files(g, &geom, &a.lines)?;
    let params = PageParams {
        title,
        color_by: a.color_by.clone(),
        surfaces,
        max_points: a.max_points,
        overlays: Vec::new(),
    };
    let n = geom.points.len();
    let bytes = write_view(&a.output, &geom, polylines, &params)
        .with_context(|| format!("cannot make a view of {}", a.input.display()))?;
    let t = stage.finish();
    if g.json {
        crate::ui::print_json(&serde_json::json!({
            "input": a.input, "output": a.output, "points": n, "bytes": bytes, "seconds": t,
        }))?;
    } else if !g.quiet {
        eprintln!(
            "wrote {} ({:.1} MB)",
            a.output.display(),
            bytes as f64 / 1e6
        );
    }
    Ok(())
}

/// The polylines of the files `lines` (each group a layer; unnamed ones take the file's name)
/// and those of `geom` itself.
fn polylines_of_files(
    g: &Global,
    geom: &Geometry,
    lines: &[PathBuf],
) -> anyhow::Result<Vec<Polyline>> {
    let mut polylines = Vec::new();
    for (i, path) in lines.iter().enumerate() {
        let (l, _) = super::load(g, path)?;
        let stem = file_name(path);
        polylines.extend(super::render::polylines_of(&l, i).into_iter().map(|mut p| {
            p.label.get_or_insert_with(|| stem.clone());
            p
        }));
    }
    polylines.extend(super::render::polylines_of(geom, lines.len()));
    Ok(polylines)
}

/// Writes the view of `geom` (a cloud, or a mesh when it has faces) with `polylines` to `out`
/// (atomically); returns the file's size.
pub fn write_view(
    out: &Path,
    geom: &Geometry,
    polylines: Vec<Polyline>,
    params: &PageParams,
) -> anyhow::Result<usize> {
    // A cloud is shown as it is: no copy of its points and attributes (a million points with
    // the labels of `crease run` are 170 MB).
    let mesh = if geom.is_mesh() {
        geom.clone().into_mesh()
    } else {
        None
    };
    let scene = Scene {
        points: if mesh.is_none() {
            Some(&geom.points)
        } else {
            None
        },
        mesh: mesh.as_ref(),
        polylines,
    };
    let html = page(&scene, params)?;
    crate::ui::write_text(out, &html)?;
    Ok(html.len())
}

/// Copies the `surface` and `surface_type` labels of a segmentation of the same input (per face
/// when both are meshes of as many faces, else per point).
fn attach_segmentation(
    geom: &mut Geometry,
    seg: &Geometry,
    seg_path: &Path,
    input: &Path,
) -> anyhow::Result<()> {
    let mut copied = 0;
    for name in [names::SURFACE, names::SURFACE_TYPE] {
        if !geom.faces.is_empty() && seg.faces.len() == geom.faces.len() {
            if let Some(a) = seg.face_attributes.get(name) {
                geom.face_attributes.insert(geom.faces.len(), a.clone())?;
                copied += 1;
            }
        } else if let Some(a) = seg.points.attribute(name) {
            if seg.points.len() != geom.points.len() {
                return Err(usage(format!(
                    "{}: {} points, where {} has {}: not a segmentation of it",
                    seg_path.display(),
                    seg.points.len(),
                    input.display(),
                    geom.points.len()
                )));
            }
            geom.points.set_attribute(a.clone())?;
            copied += 1;
        }
    }
    if copied == 0 {
        return Err(usage(format!(
            "{}: no `surface` labels (make it with `crease segment`)",
            seg_path.display()
        )));
    }
    Ok(())
}

fn read_json(path: &Path) -> anyhow::Result<serde_json::Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{}: not valid JSON", path.display()))
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}
