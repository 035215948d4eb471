//! `crease lines IN -o LINES.obj [--segmentation SEG.ply]`: closed sharp feature lines of a
//! point cloud (Demarsin et al. 2007, `crease::lines`), written as polylines (OBJ `l`; PLY
//! vertices plus an `edge` element), with per-stage graph sizes as the paper's Table 2.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use crease::geometry::{Attribute, PointCloud};
use crease::io::Geometry;
use crease::lines::{extract_lines, LinesParams};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease lines`.
#[derive(Args, Debug)]
pub struct LinesArgs {
    /// Point cloud (a mesh's vertices are used as points).
    pub input: PathBuf,
    /// Output polylines (.obj writes `l` lines; .ply writes vertices and an `edge` element).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the per-point cluster labels of the first-order segmentation (PLY property
    /// `cluster`) to this file.
    #[arg(long)]
    pub segmentation: Option<PathBuf>,
    /// Nearest neighbours triangulated for the Delaunay 1-rings.
    #[arg(short = 'k', long = "neighbours", alias = "k", default_value_t = 20)]
    pub k: usize,
    /// Region-growing angle threshold between adjacent normals, degrees.
    /// (α_max of demarsin2007 section 2.2.)
    #[arg(
        long = "region-angle",
        alias = "alpha-max",
        value_name = "DEGREES",
        default_value_t = 8.0
    )]
    pub alpha_max: f64,
    /// Spurs of at most this many edges are pruned from the lines (d_max of Algorithm 2).
    #[arg(
        long = "spur-length",
        alias = "d-max",
        value_name = "EDGES",
        default_value_t = 5
    )]
    pub d_max: usize,
    /// Do not smooth noisy 1-ring normals before the region growing (the paper as written).
    #[arg(long)]
    pub no_denoise: bool,
    /// Closing the network: how many nearest line vertices an open end may link to (the
    /// paper's n; default: 2 × --spur-length, within a reach from the data).
    #[arg(long = "close-candidates", alias = "n", value_name = "N")]
    pub n: Option<usize>,
    /// Closing the network: two vertices already joined by a path of at most this many edges
    /// are not linked (the paper's d; default: 2 × --spur-length).
    #[arg(long = "close-path", alias = "d", value_name = "D")]
    pub d: Option<usize>,
    /// Leave the cloud's boundary out of the network.
    #[arg(long)]
    pub no_boundary: bool,
    /// Keep the clusters' centres of mass as vertices (skip step 7, the smoothing).
    #[arg(long)]
    pub no_smooth: bool,
    /// Write text instead of binary where the format has both.
    #[arg(long)]
    pub ascii: bool,
}

pub fn run(g: &Global, a: &LinesArgs) -> anyhow::Result<()> {
    crease::io::Format::from_path(&a.output).map_err(|e| usage(e.to_string()))?;
    crate::ui::ensure_not_input(&a.output, &[&a.input])?;
    if let Some(s) = &a.segmentation {
        crease::io::Format::from_path(s).map_err(|e| usage(e.to_string()))?;
        crate::ui::ensure_not_input(s, &[&a.input])?;
    }
    let params = LinesParams {
        k: a.k,
        alpha_max_degrees: a.alpha_max,
        d_max: a.d_max,
        n: a.n,
        d: a.d,
        smooth: !a.no_smooth,
        boundary: !a.no_boundary,
        denoise_normals: !a.no_denoise,
    };
    params.validate().map_err(|e| usage(e.to_string()))?;
    let (geom, report) = super::load_shape(g, &a.input)?;
    let n_points = geom.points.len();
    if n_points < a.k + 1 {
        anyhow::bail!(
            "{}: {n_points} points, sharp lines with -k {} need at least {}",
            a.input.display(),
            a.k,
            a.k + 1
        );
    }
    let start = Instant::now();
    let stage = Stage::start("sharp lines (Demarsin 2007)", g.quiet);
    let net = extract_lines(&geom.points.positions, &params)
        .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
    stage.finish();
    let seconds = start.elapsed().as_secs_f64();
    let mut out = Geometry::from_cloud(PointCloud::from_positions(net.vertices.clone()));
    out.polylines = net.polylines.clone();
    // OBJ groups: the feature lines, and the cloud's open border apart.
    out.polyline_groups = net.groups().iter().map(|g| g.to_string()).collect();
    super::save(g, &a.output, &out, a.ascii, &[&a.input])?;
    if let Some(path) = &a.segmentation {
        let mut cloud = geom.points.clone();
        cloud.set_attribute(Attribute::int(
            "cluster",
            net.segmentation.labels.iter().map(|&l| l as i64),
        ))?;
        super::save(g, path, &Geometry::from_cloud(cloud), a.ascii, &[&a.input])?;
    }
    if g.json {
        let summary = serde_json::json!({
            "input": a.input, "output": a.output, "points": n_points,
            "dropped_nonfinite": report.dropped_nonfinite,
            "clusters": net.segmentation.num_clusters(),
            "small_clusters": net.small_clusters,
            "boundary_points": net.boundary_points,
            "stages": net.stages,
            "close": net.close,
            "n": net.n, "d": net.d,
            "polylines": net.polylines.len(),
            "boundary_polylines": net.boundary_lines.iter().filter(|&&b| b).count(),
            "closed_loops": net.closed_loops(),
            "junctions": net.junctions(),
            "endpoints": net.endpoints(),
            "seconds": seconds,
        });
        crate::ui::print_json(&summary)?;
    } else if !g.quiet {
        eprintln!(
            "wrote {}: {} polylines ({} closed loops), {} junctions, {} endpoints, {:.2} s",
            a.output.display(),
            net.polylines.len(),
            net.closed_loops(),
            net.junctions(),
            net.endpoints(),
            seconds
        );
        for s in &net.stages {
            eprintln!(
                "  {:<20} {:>8} vertices {:>8} edges  {:.3} s",
                s.name, s.vertices, s.edges, s.seconds
            );
        }
    }
    Ok(())
}
