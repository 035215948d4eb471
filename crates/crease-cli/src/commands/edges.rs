//! `crease edges MESH -o OUT.ply [--method ...] [--lines LINES.obj]`: feature edges of a
//! triangle mesh (vidal et al. 2011, `crease::meshfeat`). The output is the input mesh (its
//! vertices in the input's order) with a PLY `edge` element: `vertex1 vertex2` (vertex1 <
//! vertex2), `sharp` (uchar 0/1) and `sharpness` (float, degrees), one row per undirected edge.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use crease::geometry::{Attribute, PointCloud};
use crease::io::Geometry;
use crease::meshfeat::{detect_edges, feature_polylines, EdgeMethod, EdgeParams};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease edges`.
#[derive(Args, Debug)]
pub struct EdgesArgs {
    /// Triangle mesh (.ply .obj .off .stl).
    pub input: PathBuf,
    /// Output mesh with the per-edge `sharp` and `sharpness` (PLY keeps them).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The method (default: the most accurate measured on noisy meshes).
    #[arg(long, value_enum, default_value_t = MethodArg::Fused)]
    pub method: MethodArg,
    /// Threshold angle, degrees: of `dihedral`, `tangent`, `filtered` and the filtered term of
    /// `fused`, the high threshold
    /// of `hysteresis` (the low one is half), θ_true of the `potts-*` data term.
    #[arg(long)]
    pub threshold: Option<f64>,
    /// Scales of the tangent-plane angle, fractions of the bounding box's smallest side
    /// (comma-separated; the edge's angle is their mean).
    #[arg(long, value_delimiter = ',')]
    pub scales: Vec<f64>,
    /// Weight μ of the Potts pairwise term.
    #[arg(long)]
    pub mu: Option<f64>,
    /// SVM model of `learned` / `potts-learned` / `fused` (written by `crease train`; default: the
    /// model shipped with crease, trained on synthetic parts).
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// Added to the SVM decision value before thresholding at 0 (`learned`) or entering the
    /// data term (`potts-learned`), or in `fused`: > 0 finds more edges.
    #[arg(long, allow_hyphen_values = true)]
    pub bias: Option<f64>,
    /// Also write the feature edges chained into polylines (.obj `l` lines or .ply edges).
    #[arg(long, value_name = "FILE")]
    pub lines: Option<PathBuf>,
    /// Write text instead of binary where the format has both.
    #[arg(long)]
    pub ascii: bool,
}

/// The methods of `crease edges`.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodArg {
    /// Dihedral angle above the threshold (what CGAL, libigl, MeshLab do).
    Dihedral,
    /// Hysteresis thresholding of the dihedral angle.
    Hysteresis,
    /// Multi-scale tangent-plane angle (section 3) above the threshold.
    Tangent,
    /// Potts energy with the dihedral data term, minimised exactly by a graph cut.
    PottsDihedral,
    /// Potts energy with the tangent-plane angle as data term.
    PottsTangent,
    /// RBF SVM on the 43 features of section 4 (decision value above 0).
    Learned,
    /// Potts energy with the SVM data term (equation 2), minimised exactly by a graph cut.
    PottsLearned,
    /// Mean dihedral angle of bilaterally and total-variation filtered face normals above the
    /// threshold.
    Filtered,
    /// Potts energy with the filtered dihedral angle as data term.
    PottsFiltered,
    /// The SVM decision value, the filtered dihedral angle and the intersections of the
    /// segmentation's fitted surfaces combined (0.1 d + 0.9 (θ / 25° − 1) + 0.3 s above 0): the
    /// most accurate on clean and noisy meshes.
    Fused,
}

impl From<MethodArg> for EdgeMethod {
    fn from(m: MethodArg) -> EdgeMethod {
        match m {
            MethodArg::Dihedral => EdgeMethod::Dihedral,
            MethodArg::Hysteresis => EdgeMethod::Hysteresis,
            MethodArg::Tangent => EdgeMethod::Tangent,
            MethodArg::PottsDihedral => EdgeMethod::PottsDihedral,
            MethodArg::PottsTangent => EdgeMethod::PottsTangent,
            MethodArg::Learned => EdgeMethod::Learned,
            MethodArg::PottsLearned => EdgeMethod::PottsLearned,
            MethodArg::Filtered => EdgeMethod::Filtered,
            MethodArg::PottsFiltered => EdgeMethod::PottsFiltered,
            MethodArg::Fused => EdgeMethod::Fused,
        }
    }
}

pub fn run(g: &Global, a: &EdgesArgs) -> anyhow::Result<()> {
    crease::io::Format::from_path(&a.output).map_err(|e| usage(e.to_string()))?;
    crate::ui::ensure_not_input(&a.output, &[&a.input])?;
    if let Some(l) = &a.lines {
        crease::io::Format::from_path(l).map_err(|e| usage(e.to_string()))?;
        crate::ui::ensure_not_input(l, &[&a.input])?;
    }
    let mut params = EdgeParams {
        method: a.method.into(),
        ..EdgeParams::default()
    };
    if let Some(t) = a.threshold {
        if !(t.is_finite() && t > 0.0 && t < 180.0) {
            return Err(usage(format!(
                "--threshold must be in (0, 180) degrees, got {t}"
            )));
        }
        params.threshold_degrees = t;
        params.potts.theta_true = t.to_radians();
        params.filtered_degrees = t;
    }
    if !a.scales.is_empty() {
        if let Some(s) = a.scales.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(usage(format!("--scales must be positive, got {s}")));
        }
        params.tangent.scales = a.scales.clone();
    }
    if let Some(mu) = a.mu {
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(usage(format!("--mu must be finite and >= 0, got {mu}")));
        }
        params.potts.mu = mu;
    }
    if let Some(b) = a.bias {
        if !b.is_finite() {
            return Err(usage(format!("--bias must be finite, got {b}")));
        }
        params.decision_bias = b;
    }
    if let Some(path) = &a.model {
        if !params.method.uses_model() {
            return Err(usage(format!(
                "--model is used by the learned methods, not by --method {}",
                params.method.name()
            )));
        }
        params.model = Some(std::sync::Arc::new(crease::meshfeat::SvmModel::read(path)?));
    }
    let (geom, report) = super::load_shape(g, &a.input)?;
    let Some(mesh) = geom.into_mesh() else {
        anyhow::bail!(
            "{}: no faces; feature edges need a triangle mesh",
            a.input.display()
        );
    };
    let start = Instant::now();
    let stage = Stage::start(
        &format!("feature edges ({})", EdgeMethod::from(a.method).name()),
        g.quiet,
    );
    let (em, det) =
        detect_edges(&mesh, &params).map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
    stage.finish();
    let seconds = start.elapsed().as_secs_f64();
    let edges = em.topo.edges().to_vec();
    let n_edges = edges.len();
    let n_sharp = det.sharp.iter().filter(|&&s| s).count();
    let lines = a
        .lines
        .as_ref()
        .map(|_| feature_polylines(&em.topo, &det.sharp));
    let flipped = em.flipped_faces;
    let boundary = em.topo.boundary_edges().len();
    drop(em);
    let mut out = Geometry::from_mesh(mesh);
    out.edges = edges;
    out.edge_attributes
        .insert(n_edges, Attribute::flag("sharp", det.sharp.iter().copied()))?;
    out.edge_attributes.insert(
        n_edges,
        Attribute::float("sharpness", det.sharpness.clone()),
    )?;
    super::save(g, &a.output, &out, a.ascii, &[&a.input])?;
    let mut n_lines = 0;
    let mut closed = 0;
    if let (Some(path), Some(lines)) = (&a.lines, lines) {
        n_lines = lines.len();
        closed = lines
            .iter()
            .filter(|l| l.len() > 2 && l.first() == l.last())
            .count();
        let mut lg = Geometry::from_cloud(PointCloud::from_positions(out.points.positions.clone()));
        lg.polylines = lines;
        super::save(g, path, &lg, a.ascii, &[&a.input])?;
    }
    if g.json {
        let summary = serde_json::json!({
            "input": a.input, "output": a.output, "lines": a.lines,
            "method": EdgeMethod::from(a.method).name(),
            "vertices": out.points.len(), "faces": out.faces.len(),
            "dropped_nonfinite": report.dropped_nonfinite,
            "edges": n_edges, "sharp_edges": n_sharp,
            "boundary_edges": boundary, "flipped_faces": flipped,
            "polylines": n_lines, "closed_loops": closed,
            "threshold_degrees": params.threshold_degrees,
            "filtered_degrees": params.filtered_degrees,
            "fused_svm_weight": params.fused_svm_weight,
            "filter_iterations": params.filter_iterations,
            "total_variation": params.tv,
            "line_smoothing": params.line,
            "surface_intersection": params.intersection,
            "tangent_scales": params.tangent.scales,
            "potts": params.potts,
            "model": a.model,
            "decision_bias": params.decision_bias,
            "timings": det.timings,
            "seconds": seconds,
        });
        crate::ui::print_json(&summary)?;
    } else if !g.quiet {
        eprintln!(
            "wrote {}: {n_sharp} of {n_edges} edges sharp ({}), {:.2} s",
            a.output.display(),
            EdgeMethod::from(a.method).name(),
            seconds
        );
        if let Some(p) = &a.lines {
            eprintln!(
                "wrote {}: {n_lines} polylines ({closed} closed loops)",
                p.display()
            );
        }
    }
    Ok(())
}
