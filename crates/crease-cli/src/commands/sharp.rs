//! `crease sharp IN -o OUT [--method projected-distance|normal-variation|mean-curvature|
//! surface-variation] [--scales 12,16,...]`: sharp feature points of a cloud or mesh vertices,
//! written as PLY properties `sharp` (0/1) and `sharpness` (≥ 1 exactly for sharp points) in
//! the input's order. The algorithms live in `crease::sharp` (tran et al., multi-scale projected
//! distance with Otsu thresholds, and the measures of its section 4.1).

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use crease::analysis::CloudAnalysis;
use crease::geometry::{Attribute, TriMesh};
use crease::sharp::{detect, detect_mesh, Measure, SharpParams, ThresholdRule};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease sharp`.
#[derive(Args, Debug)]
pub struct SharpArgs {
    /// Point cloud or mesh.
    pub input: PathBuf,
    /// Output file (PLY keeps the `sharp` and `sharpness` properties).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The sharpness measure.
    #[arg(long, value_enum, default_value_t = Method::ProjectedDistance)]
    pub method: Method,
    /// Scales, comma-separated: neighbour counts k for clouds (default 12,16,...,40), ring
    /// sizes for meshes (default 1,2,3,4). A point is sharp when detected at every scale.
    #[arg(long, value_delimiter = ',')]
    pub scales: Vec<usize>,
    /// A fixed threshold in (0, 1] on the values normalised by their maximum at each scale,
    /// instead of Otsu's automatic threshold.
    #[arg(long)]
    pub threshold: Option<f64>,
    /// Top of Otsu's histogram as a quantile of the values (1 = the maximum, as in the paper).
    #[arg(long, default_value_t = SharpParams::default().otsu.upper_quantile)]
    pub upper_quantile: f64,
    /// Use the raw length-valued measures (the paper as written) instead of dividing them by
    /// the neighbourhood's size, which makes them independent of the sampling density.
    #[arg(long)]
    pub raw: bool,
    /// Clouds: relabel the points by a Potts energy over the 10 nearest neighbours, minimised
    /// exactly by a graph cut, with this weight λ of the smoothness term (e.g. 0.5): removes
    /// isolated detections on noisy scans at the price of some thin-line detail.
    #[arg(long)]
    pub regularize: Option<f64>,
    /// Clouds: skip the surface stage (by default, where the cloud's segmentation into planes,
    /// cylinders, cones, spheres and tori explains a point's neighbourhood, the point is sharp
    /// when it lies on the intersection of two of them meeting at an angle; see
    /// `crease::sharp::surfaces`). Faster, and tran's method as published.
    #[arg(long)]
    pub no_surfaces: bool,
    /// Treat a mesh as a point cloud (ignore its faces).
    #[arg(long)]
    pub points_only: bool,
    /// Write text instead of binary where the format has both.
    #[arg(long)]
    pub ascii: bool,
}

/// The sharpness measure of `crease sharp`.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Projected distance to the neighbourhood centroid along the normal (tran equation 3).
    ProjectedDistance,
    /// Mean angle to the neighbours' normals (tran equation 6).
    NormalVariation,
    /// Absolute mean curvature of a quadric fit.
    MeanCurvature,
    /// Surface variation λ0 / (λ0 + λ1 + λ2) (Pauly; tran equation 7).
    SurfaceVariation,
}

impl Method {
    fn measure(self) -> Measure {
        match self {
            Method::ProjectedDistance => Measure::ProjectedDistance,
            Method::NormalVariation => Measure::NormalVariation,
            Method::MeanCurvature => Measure::MeanCurvature,
            Method::SurfaceVariation => Measure::SurfaceVariation,
        }
    }
}

pub fn run(g: &Global, a: &SharpArgs) -> anyhow::Result<()> {
    crease::io::Format::from_path(&a.output).map_err(|e| usage(e.to_string()))?;
    crate::ui::ensure_not_input(&a.output, &[&a.input])?;
    let mut params = SharpParams {
        measure: a.method.measure(),
        scales: (!a.scales.is_empty()).then(|| a.scales.clone()),
        threshold: a
            .threshold
            .map_or(ThresholdRule::Otsu, ThresholdRule::Manual),
        density_invariant: !a.raw,
        ..Default::default()
    };
    if a.no_surfaces {
        params.surfaces = None;
    }
    params.otsu.upper_quantile = a.upper_quantile;
    if let Some(lambda) = a.regularize {
        params.regularize = Some(crease::sharp::Regularize {
            lambda,
            ..Default::default()
        });
    }
    params.validate().map_err(|e| usage(e.to_string()))?;
    let (mut geom, report) = super::load_shape(g, &a.input)?;
    let n = geom.points.len();
    let on_mesh = geom.is_mesh() && !a.points_only;
    let start = Instant::now();
    let stage = Stage::start(
        &format!("{} at {} scales", a.method.measure().name(), {
            params.scales.as_ref().map_or(
                if on_mesh {
                    crease::sharp::MESH_SCALES.len()
                } else {
                    crease::sharp::CLOUD_SCALES.len()
                },
                Vec::len,
            )
        }),
        g.quiet,
    );
    let mut knn_seconds = None;
    let result = if on_mesh {
        let mesh = TriMesh {
            vertices: std::mem::take(&mut geom.points),
            faces: std::mem::take(&mut geom.faces),
            face_attributes: std::mem::take(&mut geom.face_attributes),
        };
        let r = detect_mesh(&mesh, &params);
        geom.points = mesh.vertices;
        geom.faces = mesh.faces;
        geom.face_attributes = mesh.face_attributes;
        r
    } else {
        let ap = crease::sharp::analysis_params(&params)
            .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
        let kmax = ap.max_k;
        if n < kmax + 1 {
            anyhow::bail!(
                "{}: {n} points, sharp features at k = {kmax} need at least {}",
                a.input.display(),
                kmax + 1
            );
        }
        // One kNN query at the largest scale serves every scale; timed apart for --json. The
        // analysis holds the distinct points in Morton order (cache-friendly neighbour reads)
        // and the result is mapped back to the input order.
        let t = Instant::now();
        let in_file = |e: crease::Error| anyhow::anyhow!("{}: {e}", a.input.display());
        let analysis = CloudAnalysis::new(&geom.points.positions, ap).map_err(in_file)?;
        analysis.neighbours().map_err(in_file)?;
        knn_seconds = Some(t.elapsed().as_secs_f64());
        detect(&analysis, &params)
    }
    .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
    stage.finish();
    let seconds = start.elapsed().as_secs_f64();
    let num_sharp = result.num_sharp();
    geom.points
        .set_attribute(Attribute::flag("sharp", result.sharp.clone()))?;
    geom.points
        .set_attribute(Attribute::float("sharpness", result.sharpness.clone()))?;
    super::save(g, &a.output, &geom, a.ascii, &[&a.input])?;
    if g.json {
        let summary = serde_json::json!({
            "input": a.input, "output": a.output, "points": n,
            "dropped_nonfinite": report.dropped_nonfinite,
            "mesh": on_mesh,
            "method": a.method.measure().name(),
            "density_invariant": !a.raw,
            "threshold": match a.threshold { Some(t) => serde_json::json!(t), None => "otsu".into() },
            "sharp": num_sharp,
            "noise_ratio": result.noise_ratio,
            "regularized": result.regularized,
            "surfaces": result.surfaces,
            "scales": result.scales,
            "seconds": seconds,
            "timings": {
                "knn": knn_seconds,
                "detection": seconds - knn_seconds.unwrap_or(0.0),
            },
        });
        crate::ui::print_json(&summary)?;
    } else if !g.quiet {
        eprintln!(
            "wrote {} ({num_sharp} of {n} {} sharp, {seconds:.2} s)",
            a.output.display(),
            if on_mesh { "vertices" } else { "points" }
        );
        for s in &result.scales {
            eprintln!(
                "  scale {:>3}: threshold {:.4} (normalised {:.3}), {} detected",
                s.scale, s.threshold, s.normalized_threshold, s.detected
            );
        }
    }
    Ok(())
}
