//! `crease segment IN -o OUT.ply [--primitives primitives.json] [--render PNG]`: segmentation of
//! a triangle mesh into planes, cylinders, cones, spheres and tori (Mizoguchi et al.,
//! `crease::segment`). Writes the mesh with per-face `surface` (int, -1 unassigned) and
//! `surface_type` (uchar: plane 0, cylinder 1, cone 2, sphere 3, torus 4, 255 unassigned) in
//! the input's face order, and the surfaces with their parameters as JSON.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use crease::geometry::{Attribute, MeshTopology, ScalarKind, TriMesh};
use crease::io::Geometry;
use crease::segment::{segment_mesh, SegmentParams};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease segment`.
#[derive(Args, Debug)]
pub struct SegmentArgs {
    /// Triangle mesh (.ply .obj .off .stl).
    pub input: PathBuf,
    /// Output mesh (PLY keeps the `surface` and `surface_type` face properties).
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
    /// th_pos of equation 4, in mean edge lengths.
    #[arg(long, default_value_t = 0.5)]
    pub th_pos: f64,
    /// th_norm of equation 5, degrees.
    #[arg(long, default_value_t = 8.0)]
    pub th_norm: f64,
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
    if !(a.th_pos > 0.0 && a.th_pos.is_finite() && a.th_norm > 0.0 && a.th_norm < 90.0) {
        return Err(usage(format!(
            "--th-pos must be positive and --th-norm in (0, 90) degrees, got {} and {}",
            a.th_pos, a.th_norm
        )));
    }
    let (mut geom, report) = super::load(g, &a.input)?;
    if !geom.is_mesh() {
        return Err(usage(format!(
            "{}: segmentation needs a triangle mesh, and this file has no faces",
            a.input.display()
        )));
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
    let params = SegmentParams {
        th_pos: a.th_pos,
        th_norm_degrees: a.th_norm,
        ..Default::default()
    };
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
    let total_area: f64 = seg.surfaces.iter().map(|s| s.area).sum();
    let assigned = seg.face_surface.iter().filter(|&&s| s >= 0).count();
    let doc = serde_json::json!({
        "input": a.input,
        "surface_type_codes": {"plane": 0, "cylinder": 1, "cone": 2, "sphere": 3, "torus": 4, "unassigned": 255},
        "mean_edge": seg.mean_edge,
        "epsilon": seg.epsilon,
        "surfaces": seg.surfaces,
        "groups": seg.groups,
    });
    if let Some(p) = &a.primitives {
        std::fs::write(p, serde_json::to_string_pretty(&doc)? + "\n")
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    if let Some(png) = &a.render {
        let mesh = out.clone().into_mesh().context("segmented mesh")?;
        let params = crease::render::RenderParams {
            color_by: crease::render::ColorBy::Attribute("surface_type".into()),
            title: Some(format!(
                "{}: {} surfaces",
                a.input
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default(),
                seg.surfaces.len()
            )),
            ..Default::default()
        };
        let scene = crease::render::Scene {
            mesh: Some(&mesh),
            ..Default::default()
        };
        crease::render::render_png(&scene, &params, png)
            .with_context(|| format!("cannot render {}", png.display()))?;
    }
    let mut counts = std::collections::BTreeMap::new();
    for s in &seg.surfaces {
        *counts.entry(s.kind.name()).or_insert(0usize) += 1;
    }
    if g.json {
        let timings: serde_json::Map<String, serde_json::Value> = seg
            .timings
            .iter()
            .map(|(k, v)| (k.to_string(), (*v).into()))
            .collect();
        crate::ui::print_json(&serde_json::json!({
            "input": a.input, "output": a.output, "primitives": a.primitives,
            "vertices": out.points.len(), "faces": out.faces.len(),
            "dropped_nonfinite": report.dropped_nonfinite,
            "surfaces": seg.surfaces.len(), "by_type": counts,
            "seeds": seg.seeds,
            "assigned_faces": assigned, "surface_area": total_area,
            "mean_edge": seg.mean_edge, "epsilon": seg.epsilon,
            "timings": timings, "seconds": seconds,
            "surface_type_codes": doc["surface_type_codes"],
            "surface_list": doc["surfaces"],
            "groups": doc["groups"],
        }))?;
    } else if !g.quiet {
        eprintln!(
            "wrote {}: {} surfaces {:?}, {} of {} faces assigned, {seconds:.2} s",
            a.output.display(),
            seg.surfaces.len(),
            counts,
            assigned,
            out.faces.len()
        );
    }
    Ok(())
}
