//! `crease render IN -o view.png`: a quick-look PNG of points, meshes and polylines.

use std::path::Path;

use anyhow::Context;
use crease::render::{ColorBy, Polyline, RenderParams, Scene, View, ViewLayout};

use crate::args::{Global, RenderArgs, ViewArg};
use crate::ui::Stage;

pub fn run(g: &Global, a: &RenderArgs) -> anyhow::Result<()> {
    let mut inputs: Vec<&Path> = vec![&a.input];
    inputs.extend(a.lines.iter().map(|p| p.as_path()));
    crate::ui::ensure_not_input(&a.output, &inputs)?;
    let (geom, _) = super::load(g, &a.input)?;
    let mut polylines = Vec::new();
    for (i, path) in a.lines.iter().enumerate() {
        let (lines, _) = super::load(g, path)?;
        polylines.extend(polylines_of(&lines, i));
    }
    // The input's own polylines / edges are drawn too.
    polylines.extend(polylines_of(&geom, a.lines.len()));
    let color_by = match a.color_by.as_deref() {
        None if geom.points.colors.is_some() => ColorBy::Rgb,
        None | Some("uniform") => ColorBy::Uniform,
        Some("rgb") => ColorBy::Rgb,
        Some("normal") => ColorBy::Normal,
        Some(name) => ColorBy::Attribute(name.to_string()),
    };
    let layout = match a.view {
        None => ViewLayout::Four,
        Some(ViewArg::Iso) => ViewLayout::Single(View::Iso),
        Some(ViewArg::Front) => ViewLayout::Single(View::Front),
        Some(ViewArg::Top) => ViewLayout::Single(View::Top),
        Some(ViewArg::Side) => ViewLayout::Single(View::Side),
    };
    let params = RenderParams {
        width: a.width,
        height: a.height,
        layout,
        color_by,
        title: Some(a.title.clone().unwrap_or_else(|| {
            a.input
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default()
        })),
        ..Default::default()
    };
    let mesh = geom.clone().into_mesh();
    let scene = Scene {
        points: if mesh.is_none() && geom.edges.is_empty() && geom.polylines.is_empty()
            || mesh.is_none() && !geom.points.is_empty()
        {
            Some(&geom.points)
        } else {
            None
        },
        mesh: mesh.as_ref(),
        polylines,
    };
    let stage = Stage::start("rendering", g.quiet);
    crease::render::render_png(&scene, &params, &a.output)
        .with_context(|| format!("cannot render {}", a.input.display()))?;
    let t = stage.finish();
    if g.json {
        crate::ui::print_json(&serde_json::json!({
            "input": a.input, "output": a.output, "seconds": t,
        }))?;
    } else if !g.quiet {
        eprintln!("wrote {}", a.output.display());
    }
    Ok(())
}

/// The polylines and edges of `geom` as drawable polylines: edges are chained into polylines
/// (split at junctions), separately per kind when a `curve_kind` edge attribute tags them
/// (0 sharp, 1 smooth, 2 boundary, as `crease synth` writes them), each kind in its colour.
pub fn polylines_of(geom: &crease::io::Geometry, file_index: usize) -> Vec<Polyline> {
    let pts = &geom.points.positions;
    let palette = [[220, 30, 30], [30, 90, 220], [40, 160, 60], [200, 120, 0]];
    let default = palette[file_index % palette.len()];
    let to_polyline = |chain: &[u32], color: [u8; 3], label: Option<&str>| Polyline {
        points: chain.iter().map(|&i| pts[i as usize]).collect(),
        closed: chain.len() > 2 && chain.first() == chain.last(),
        color,
        label: label.map(String::from),
    };
    let kinds: [(i64, [u8; 3], Option<&str>); 4] = [
        (0, [220, 30, 30], Some("sharp")),
        (1, [30, 90, 220], Some("smooth")),
        (2, [110, 110, 110], Some("boundary")),
        (-1, default, None),
    ];
    // OBJ groups named as the curve network's (`sharp`, `smooth`, `boundary`) keep their colour.
    let mut out: Vec<Polyline> = geom
        .polylines
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let group = geom.polyline_groups.get(i).map(String::as_str);
            match kinds.iter().find(|k| k.2.is_some() && k.2 == group) {
                Some(&(_, color, label)) => to_polyline(l, color, label),
                None => to_polyline(l, default, group.filter(|g| !g.is_empty())),
            }
        })
        .collect();
    let kind = geom.edge_attributes.get("curve_kind");
    for (code, color, label) in kinds {
        let edges: Vec<[u32; 2]> = geom
            .edges
            .iter()
            .enumerate()
            .filter(|(i, _)| {
                let k = kind.map_or(-1, |k| k.values[*i] as i64);
                k == code || (code == -1 && !(0..=2).contains(&k))
            })
            .map(|(_, e)| *e)
            .collect();
        for chain in crease::geometry::chain_segments(pts.len(), &edges) {
            out.push(to_polyline(&chain, color, label));
        }
    }
    out
}
