//! `crease synth SHAPE -n N -o OUT`: a synthetic part with exact ground truth. Writes the part
//! (points or mesh, with the `gt_*` attributes), its feature curves (`OUT.curves.ply`, edges
//! tagged by `kind`: 0 sharp, 1 smooth, 2 boundary) and its surfaces with their parameters
//! (`OUT.truth.json`).

use std::path::{Path, PathBuf};

use crease::synth::{self, MeshParams, Noise, NoiseScale, SampleParams, Shape};

use crate::args::{Global, NoiseMode, NoiseScaleArg, SynthArgs};
use crate::ui::{usage, Stage};

pub fn run(g: &Global, a: &SynthArgs) -> anyhow::Result<()> {
    if a.list {
        for name in Shape::names() {
            crate::ui::outln(format_args!("{name}"))?;
        }
        return Ok(());
    }
    let name = a.shape.as_deref().unwrap_or_default();
    let shape = Shape::from_name(name).ok_or_else(|| {
        usage(format!(
            "unknown shape {name:?}; known shapes: {}",
            Shape::names().join(", ")
        ))
    })?;
    let output = a
        .output
        .as_deref()
        .ok_or_else(|| usage("missing -o OUTPUT"))?;
    crease::io::Format::from_path(output).map_err(|e| usage(e.to_string()))?;
    if !(a.noise >= 0.0 && a.noise.is_finite()) {
        return Err(usage(format!(
            "--noise must be a non-negative number, got {}",
            a.noise
        )));
    }
    if !(0.0..1.0).contains(&a.outliers) {
        return Err(usage(format!(
            "--outliers must be a fraction in [0, 1), got {}",
            a.outliers
        )));
    }
    let noise = match a.noise_mode {
        _ if a.noise == 0.0 => Noise::None,
        NoiseMode::Normal => Noise::AlongNormal(a.noise),
        NoiseMode::Isotropic => Noise::Isotropic(a.noise),
    };
    let noise_scale = match a.noise_scale {
        NoiseScaleArg::Spacing => NoiseScale::Spacing,
        NoiseScaleArg::Bbox => NoiseScale::BoundingBox,
    };
    let stage = Stage::start(&format!("generating {name}"), g.quiet);
    let (geom, curves, truth) = if a.mesh {
        let m = synth::mesh(
            &shape,
            &MeshParams {
                target_edge: a.edge,
                noise,
                noise_scale,
                seed: a.seed,
                sharp_tolerance: a.tolerance,
            },
        )?;
        let curves = m.curves_geometry();
        let truth = m.ground_truth_json(&shape);
        (crease::io::Geometry::from_mesh(m.mesh), curves, truth)
    } else {
        let p = synth::sample_points(
            &shape,
            &SampleParams {
                n: a.n,
                noise,
                noise_scale,
                outliers: a.outliers,
                seed: a.seed,
                sharp_tolerance: a.tolerance,
            },
        )?;
        let curves = p.curves_geometry();
        let truth = p.ground_truth_json();
        (crease::io::Geometry::from_cloud(p.cloud), curves, truth)
    };
    stage.finish();
    let curves_path = sibling(output, "curves.ply");
    let truth_path = sibling(output, "truth.json");
    super::save(g, output, &geom, a.ascii, &[])?;
    super::save(g, &curves_path, &curves, a.ascii, &[])?;
    crate::ui::write_text(&truth_path, &serde_json::to_string_pretty(&truth)?)?;
    if g.json {
        crate::ui::print_json(&serde_json::json!({
            "shape": name, "output": output, "curves": curves_path, "truth": truth_path,
            "points": geom.points.len(), "faces": geom.faces.len(), "ground_truth": truth,
        }))?;
    } else if !g.quiet {
        eprintln!(
            "wrote {} ({} points{}), {} and {}",
            output.display(),
            geom.points.len(),
            if geom.faces.is_empty() {
                String::new()
            } else {
                format!(", {} faces", geom.faces.len())
            },
            curves_path.display(),
            truth_path.display()
        );
    }
    Ok(())
}

/// `dir/stem.SUFFIX` for `dir/stem.ext`.
pub fn sibling(path: &Path, suffix: &str) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    path.with_file_name(format!("{stem}.{suffix}"))
}
