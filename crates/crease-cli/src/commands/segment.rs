//! `crease segment IN -o OUT.ply [--primitives primitives.json] [--render PNG]`: segmentation of
//! a triangle mesh or a point cloud into planes, cylinders, cones, spheres and tori (Mizoguchi
//! et al., `crease::segment`). Writes the mesh with per-face `surface` (int, -1 unassigned) and
//! `surface_type` (uchar: plane 0, cylinder 1, cone 2, sphere 3, torus 4, 255 unassigned) in
//! the input's face order — or, for a file without faces, the cloud with the same two
//! properties per point in the input's point order — and the surfaces with their parameters
//! as JSON.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use crease::geometry::{Attribute, MeshTopology, ScalarKind, TriMesh};
use crease::io::Geometry;
use crease::segment::{segment_mesh, segment_points, PointParams, SegmentParams};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease segment`.
#[derive(Args, Debug)]
pub struct SegmentArgs {
    /// Triangle mesh (.ply .obj .off .stl) or point cloud (any point format; a file without
    /// faces is segmented as a cloud).
    pub input: PathBuf,
    /// Output mesh or cloud (PLY keeps the `surface` and `surface_type` face / point
    /// properties).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write the surfaces (type, parameters, area, counts, RMS error, neighbours) to this JSON
    /// file. (The global --json prints a run summary on stdout, the surfaces included as
    /// `surface_list`.)
    #[arg(long, value_name = "JSON")]
    pub primitives: Option<PathBuf>,
    /// Also draw the mesh coloured by surface type into this PNG.
    #[arg(long, value_name = "PNG")]
    pub render: Option<PathBuf>,
    /// How far a point may lie from its surface, in mean edge lengths (th_pos of equation 4;
    /// widened to the measured noise on noisy clouds).
    #[arg(
        long = "distance-tolerance",
        alias = "th-pos",
        value_name = "EDGES",
        default_value_t = 0.5
    )]
    pub th_pos: f64,
    /// How far a point's normal may turn from its surface's, degrees (th_norm of equation 5).
    #[arg(
        long = "angle-tolerance",
        alias = "th-norm",
        value_name = "DEGREES",
        default_value_t = 8.0
    )]
    pub th_norm: f64,
    /// Clouds: neighbours of the k-nearest-neighbour graph.
    #[arg(short = 'k', long = "neighbours", alias = "k", default_value_t = 8)]
    pub k: usize,
    /// Clouds: estimate normals (PCA + orientation) even when the file has some.
    #[arg(long)]
    pub estimate_normals: bool,
    /// Write text instead of binary where the format has both.
    #[arg(long)]
    pub ascii: bool,
}

pub fn run(g: &Global, a: &SegmentArgs) -> anyhow::Result<()> {
    crease::io::Format::from_path(&a.output).map_err(|e| usage(e.to_string()))?;
    let mut outputs = vec![&a.output];
    outputs.extend(a.primitives.iter());
    outputs.extend(a.render.iter());
    for o in &outputs {
        crate::ui::ensure_not_input(o, &[&a.input])?;
    }
    let params = SegmentParams {
        th_pos: a.th_pos,
        th_norm_degrees: a.th_norm,
        ..Default::default()
    };
    params.validate().map_err(|e| usage(e.to_string()))?;
    PointParams {
        k: a.k,
        ..Default::default()
    }
    .validate()
    .map_err(|e| usage(e.to_string()))?;
    let (mut geom, report) = super::load_shape(g, &a.input)?;
    if !geom.is_mesh() {
        return run_cloud(g, a, geom, report.dropped_nonfinite, &params);
    }
    let mut mesh = TriMesh {
        vertices: std::mem::take(&mut geom.points),
        faces: std::mem::take(&mut geom.faces),
        face_attributes: std::mem::take(&mut geom.face_attributes),
    };
    let start = Instant::now();
    let stage = Stage::start("mesh topology", g.quiet);
    let topo = MeshTopology::new(&mesh).with_context(|| format!("{}", a.input.display()))?;
    stage.finish();
    let stage = Stage::start("segmentation (Mizoguchi)", g.quiet);
    let seg = segment_mesh(&mesh, &topo, &params)
        .with_context(|| format!("cannot segment {}", a.input.display()))?;
    stage.finish();
    let seconds = start.elapsed().as_secs_f64();
    mesh.set_face_attribute(Attribute::int(
        "surface",
        seg.face_surface.iter().map(|&s| s as i64),
    ))?;
    mesh.set_face_attribute(Attribute {
        name: "surface_type".into(),
        kind: ScalarKind::U8,
        values: seg.face_types().into_iter().map(f64::from).collect(),
    })?;
    let out = Geometry::from_mesh(mesh);
    super::save(g, &a.output, &out, a.ascii, &[&a.input])?;
    let assigned = seg.face_surface.iter().filter(|&&s| s >= 0).count();
    let summary = Summary {
        surfaces: &seg.surfaces,
        groups: &seg.groups,
        mean_edge: seg.mean_edge,
        epsilon: seg.epsilon,
        seeds: seg.seeds,
        timings: &seg.timings,
        seconds,
        dropped_nonfinite: report.dropped_nonfinite,
    };
    let extra = serde_json::json!({
        "vertices": out.points.len(), "faces": out.faces.len(), "assigned_faces": assigned,
    });
    let line = format!("{} of {} faces assigned", assigned, out.faces.len());
    finish(g, a, &out, &summary, extra, &line)
}

/// What the mesh and cloud paths report.
struct Summary<'a> {
    surfaces: &'a [crease::segment::SegmentSurface],
    groups: &'a [crease::segment::recognize::Group],
    mean_edge: f64,
    epsilon: f64,
    seeds: usize,
    timings: &'a [(&'static str, f64)],
    seconds: f64,
    dropped_nonfinite: usize,
}

/// The cloud path: per-point `surface` and `surface_type`.
fn run_cloud(
    g: &Global,
    a: &SegmentArgs,
    mut geom: Geometry,
    dropped_nonfinite: usize,
    params: &SegmentParams,
) -> anyhow::Result<()> {
    let start = Instant::now();
    let stage = Stage::start("point-cloud segmentation (Mizoguchi, kNN graph)", g.quiet);
    let given = if a.estimate_normals {
        None
    } else {
        geom.points.normals.as_deref()
    };
    let pp = PointParams {
        k: a.k,
        ..Default::default()
    };
    let seg = segment_points(&geom.points.positions, given, params, &pp)
        .with_context(|| format!("cannot segment {}", a.input.display()))?;
    stage.finish();
    let seconds = start.elapsed().as_secs_f64();
    geom.points.set_attribute(Attribute::int(
        "surface",
        seg.point_surface.iter().map(|&s| s as i64),
    ))?;
    geom.points.set_attribute(Attribute {
        name: "surface_type".into(),
        kind: ScalarKind::U8,
        values: seg.point_types().into_iter().map(f64::from).collect(),
    })?;
    super::save(g, &a.output, &geom, a.ascii, &[&a.input])?;
    let assigned = seg.point_surface.iter().filter(|&&s| s >= 0).count();
    let summary = Summary {
        surfaces: &seg.surfaces,
        groups: &seg.groups,
        mean_edge: seg.mean_edge,
        epsilon: seg.epsilon,
        seeds: seg.seeds,
        timings: &seg.timings,
        seconds,
        dropped_nonfinite,
    };
    let extra = serde_json::json!({
        "points": geom.points.len(), "assigned_points": assigned,
        "normals": if seg.normals_given { "given" } else { "estimated" },
        "k": a.k,
    });
    let line = format!("{} of {} points assigned", assigned, geom.points.len());
    finish(g, a, &geom, &summary, extra, &line)
}

/// Primitives JSON, render and run summary, shared by meshes and clouds.
fn finish(
    g: &Global,
    a: &SegmentArgs,
    out: &Geometry,
    s: &Summary,
    extra: serde_json::Value,
    line: &str,
) -> anyhow::Result<()> {
    let total_area: f64 = s.surfaces.iter().map(|s| s.area).sum();
    let doc = serde_json::json!({
        "input": a.input,
        "surface_type_codes": {"plane": 0, "cylinder": 1, "cone": 2, "sphere": 3, "torus": 4, "unassigned": 255},
        "mean_edge": s.mean_edge,
        "epsilon": s.epsilon,
        "surfaces": s.surfaces,
        "groups": s.groups,
    });
    if let Some(p) = &a.primitives {
        crate::ui::write_text(p, &(serde_json::to_string_pretty(&doc)? + "\n"))?;
    }
    if let Some(png) = &a.render {
        let params = crease::render::RenderParams {
            color_by: crease::render::ColorBy::Attribute("surface_type".into()),
            title: Some(format!(
                "{}: {} surfaces",
                a.input
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                s.surfaces.len()
            )),
            ..Default::default()
        };
        let mesh = if out.is_mesh() {
            Some(out.clone().into_mesh().context("segmented mesh")?)
        } else {
            None
        };
        let scene = crease::render::Scene {
            mesh: mesh.as_ref(),
            points: if out.is_mesh() {
                None
            } else {
                Some(&out.points)
            },
            ..Default::default()
        };
        crease::render::render_png(&scene, &params, png)
            .with_context(|| format!("cannot render {}", png.display()))?;
    }
    let mut counts = std::collections::BTreeMap::new();
    for s in s.surfaces {
        *counts.entry(s.kind.name()).or_insert(0usize) += 1;
    }
    if g.json {
        let timings: serde_json::Map<String, serde_json::Value> = s
            .timings
            .iter()
            .map(|(k, v)| (k.to_string(), (*v).into()))
            .collect();
        let mut j = serde_json::json!({
            "input": a.input, "output": a.output, "primitives": a.primitives,
            "dropped_nonfinite": s.dropped_nonfinite,
            "surfaces": s.surfaces.len(), "by_type": counts,
            "seeds": s.seeds,
            "surface_area": total_area,
            "mean_edge": s.mean_edge, "epsilon": s.epsilon,
            "timings": timings, "seconds": s.seconds,
            "surface_type_codes": doc["surface_type_codes"],
            "surface_list": doc["surfaces"],
            "groups": doc["groups"],
        });
        if let (Some(m), Some(e)) = (j.as_object_mut(), extra.as_object()) {
            for (k, v) in e {
                m.insert(k.clone(), v.clone());
            }
        }
        crate::ui::print_json(&j)?;
    } else if !g.quiet {
        eprintln!(
            "wrote {}: {} surfaces {:?}, {line}, {:.2} s",
            a.output.display(),
            s.surfaces.len(),
            counts,
            s.seconds
        );
    }
    Ok(())
}
