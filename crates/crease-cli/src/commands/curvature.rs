//! `crease curvature IN -o OUT [--method quadric|bezier] [-k 20]`: principal curvatures of every
//! point (mesh vertex), written as PLY properties `k1 k2 mean_curvature gaussian_curvature`
//! (plus `sharp` for the Bézier method) in the input's order. The algorithms live in
//! `crease::estimate::curvature` (quadric fit, demarsin2008 section 2.1) and
//! `crease::estimate::bezier` (two-pass Bézier fit, mizoguchi section 3).

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use crease::estimate::bezier::{bezier_curvature, BezierParams};
use crease::estimate::curvature::{quadric_curvature_of, Curvature, QuadricParams};
use crease::geometry::{Attribute, MeshTopology, TriMesh};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease curvature`.
#[derive(Args, Debug)]
pub struct CurvatureArgs {
    /// Point cloud or mesh.
    pub input: PathBuf,
    /// Output file (PLY keeps the curvature properties).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Estimator: quadric fit over the k nearest neighbours (clouds and mesh vertices) or the
    /// two-pass Bézier fit of Mizoguchi et al. (meshes only).
    #[arg(long, value_enum, default_value_t = Method::Quadric)]
    pub method: Method,
    /// Number of nearest neighbours of the quadric fit (at least 5).
    #[arg(short = 'k', long = "neighbours", alias = "k", default_value_t = 20)]
    pub k: usize,
    /// Orient the quadric's normals with the normals stored in the input file (signed
    /// curvatures); without it each point is oriented so that its mean curvature is >= 0.
    #[arg(long)]
    pub use_normals: bool,
    /// Bézier: th_se relative to the mean edge length (a vertex is sharp when its first-pass
    /// |k_max| x mean edge length exceeds it).
    #[arg(long, default_value_t = BezierParams::default().sharp_threshold)]
    pub sharp_threshold: f64,
    /// Write text instead of binary where the format has both.
    #[arg(long)]
    pub ascii: bool,
}

/// The curvature estimator.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Quadric fit in the local PCA frame (demarsin2008 section 2.1).
    Quadric,
    /// Two-pass biquadratic Bézier fit with sharp vertices (mizoguchi section 3).
    Bezier,
}

pub fn run(g: &Global, a: &CurvatureArgs) -> anyhow::Result<()> {
    crease::io::Format::from_path(&a.output).map_err(|e| usage(e.to_string()))?;
    crate::ui::ensure_not_input(&a.output, &[&a.input])?;
    if a.method == Method::Quadric && a.k < 5 {
        return Err(usage(format!(
            "-k must be at least 5 for the quadric fit, got {}",
            a.k
        )));
    }
    if !(a.sharp_threshold > 0.0 && a.sharp_threshold.is_finite()) {
        return Err(usage(format!(
            "--sharp-threshold must be a positive number, got {}",
            a.sharp_threshold
        )));
    }
    let (mut geom, report) = super::load_shape(g, &a.input)?;
    if a.method == Method::Bezier && !geom.is_mesh() {
        return Err(usage(format!(
            "{}: the Bézier method needs a triangle mesh, and this file has no faces \
             (use --method quadric for point clouds)",
            a.input.display()
        )));
    }
    let n = geom.points.len();
    let start = Instant::now();
    let mut summary = serde_json::json!({
        "input": a.input, "output": a.output, "points": n,
        "dropped_nonfinite": report.dropped_nonfinite,
    });
    let (curv, sharp) = match a.method {
        Method::Quadric => {
            if n < a.k + 1 {
                anyhow::bail!(
                    "{}: {n} points, the quadric fit with -k {} needs at least {}",
                    a.input.display(),
                    a.k,
                    a.k + 1
                );
            }
            // One call: the k nearest neighbours among the distinct points (exact duplicates
            // fitted once, each copy taking its original's estimate), then the fit.
            let stage = Stage::start("quadric curvature", g.quiet);
            let normals = if a.use_normals {
                Some(geom.points.normals.as_deref().ok_or_else(|| {
                    usage(format!(
                        "{}: --use-normals given but the file has no normals",
                        a.input.display()
                    ))
                })?)
            } else {
                None
            };
            let c =
                quadric_curvature_of(&geom.points.positions, normals, &QuadricParams { k: a.k })
                    .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
            stage.finish();
            summary["method"] = "quadric".into();
            summary["k"] = a.k.into();
            summary["oriented_by_input_normals"] = a.use_normals.into();
            (c, None)
        }
        Method::Bezier => {
            let mesh = TriMesh {
                vertices: std::mem::take(&mut geom.points),
                faces: std::mem::take(&mut geom.faces),
                face_attributes: std::mem::take(&mut geom.face_attributes),
            };
            let stage = Stage::start("mesh topology", g.quiet);
            let topo = MeshTopology::new(&mesh)?;
            stage.finish();
            let stage = Stage::start("two-pass Bézier curvature", g.quiet);
            let params = BezierParams {
                sharp_threshold: a.sharp_threshold,
                ..Default::default()
            };
            let b = bezier_curvature(&mesh, &topo, &params)?;
            stage.finish();
            geom.points = mesh.vertices;
            geom.faces = mesh.faces;
            geom.face_attributes = mesh.face_attributes;
            summary["method"] = "bezier".into();
            summary["th_se"] = b.th_se.into();
            summary["mean_edge"] = b.mean_edge.into();
            summary["sharp_threshold"] = a.sharp_threshold.into();
            summary["sharp_vertices"] = b.sharp.iter().filter(|&&s| s).count().into();
            (b.curvature, Some(b.sharp))
        }
    };
    let seconds = start.elapsed().as_secs_f64();
    summary["failed"] = curv.num_failed().into();
    summary["seconds"] = seconds.into();
    summary["mean_curvature"] = stats(&curv.mean);
    summary["k1"] = stats(&curv.k1);
    summary["k2"] = stats(&curv.k2);
    add_attributes(&mut geom.points, &curv, sharp)?;
    super::save(g, &a.output, &geom, a.ascii, &[&a.input])?;
    if g.json {
        crate::ui::print_json(&summary)?;
    } else if !g.quiet {
        eprintln!(
            "wrote {} ({n} points, curvature in {seconds:.2} s{})",
            a.output.display(),
            match curv.num_failed() {
                0 => String::new(),
                f => format!(", {f} without an estimate (NaN)"),
            }
        );
    }
    Ok(())
}

fn add_attributes(
    points: &mut crease::geometry::PointCloud,
    c: &Curvature,
    sharp: Option<Vec<bool>>,
) -> anyhow::Result<()> {
    points.set_attribute(Attribute::float("k1", c.k1.clone()))?;
    points.set_attribute(Attribute::float("k2", c.k2.clone()))?;
    points.set_attribute(Attribute::float("mean_curvature", c.mean.clone()))?;
    points.set_attribute(Attribute::float("gaussian_curvature", c.gaussian.clone()))?;
    if let Some(s) = sharp {
        points.set_attribute(Attribute::flag("sharp", s))?;
    }
    Ok(())
}

/// Median, 5th and 95th percentiles of the finite values.
fn stats(v: &[f64]) -> serde_json::Value {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return serde_json::Value::Null;
    }
    s.sort_by(f64::total_cmp);
    let q = |p: f64| s[((s.len() - 1) as f64 * p).round() as usize];
    serde_json::json!({ "p05": q(0.05), "median": q(0.5), "p95": q(0.95) })
}
