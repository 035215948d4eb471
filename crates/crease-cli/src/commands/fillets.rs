//! `crease fillets IN -o FILLETS.obj [--labels LABELS.ply]`: fillet (smooth-edge) lines of a
//! point cloud by multi-resolution curvature histograms (Demarsin et al. 2008,
//! `crease::fillets`), and `crease network IN -o NET.obj`: the whole curve network, sharp and
//! smooth lines together (OBJ groups `sharp` / `smooth` / `boundary`; PLY vertex property
//! `smooth`), anchored on the surfaces by default (`crease::network`).

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use crease::fillets::{
    curve_network, extract_fillets, CurveNetwork, FilletParams, Fillets, Label, Search,
    ThresholdCount,
};
use crease::geometry::{Attribute, PointCloud};
use crease::io::Geometry;
use crease::lines::LinesParams;
use crease::network::{network_of_points, NetworkSummary};

use crate::args::Global;
use crate::ui::{usage, Stage};

/// Arguments of `crease fillets` and `crease network`.
#[derive(Args, Debug)]
pub struct FilletsArgs {
    /// Point cloud (a mesh's vertices are used as points).
    pub input: PathBuf,
    /// Output polylines (.obj writes `l` lines; .ply writes vertices and an `edge` element).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write per-point labels to this file: `fillet_label` (0 low, 1 inner, 2 border,
    /// 3 noisy, 255 outside the smooth regions), `smooth_edge` (1 on a fillet border),
    /// `patch` (curvature patch, 255 outside), `region` (-1 outside), `mean_curvature`.
    #[arg(long)]
    pub labels: Option<PathBuf>,
    /// Nearest neighbours triangulated for the Delaunay 1-rings.
    #[arg(short = 'k', long = "neighbours", alias = "k", default_value_t = 20)]
    pub k: usize,
    /// Region-growing angle threshold between adjacent normals, degrees (the sharp edges that
    /// bound the smooth regions).
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
    /// Neighbours of the quadric fit of the mean curvature.
    #[arg(long, default_value_t = 20)]
    pub curvature_k: usize,
    /// Taubin smoothing iterations of each smooth region before the curvature (section 2.4).
    #[arg(long, default_value_t = 0)]
    pub smoothing: usize,
    /// Median-filter passes over the signed mean curvature.
    #[arg(long, default_value_t = 1)]
    pub median: usize,
    /// Fraction of the highest curvatures left out of the histogram (section 2.4).
    #[arg(long, default_value_t = 0.005)]
    pub trim: f64,
    /// Start resolution of the histogram, L_start (section 2.2).
    #[arg(long, default_value_t = 50)]
    pub bins: usize,
    /// Use the paper's one-run search (start_curv = min only) instead of the full search.
    #[arg(long)]
    pub one_run: bool,
    /// Thresholds per smooth region: `auto` (decided per region) or a number (the splits
    /// of largest ratio are taken).
    #[arg(long, default_value = "auto")]
    pub thresholds: String,
    /// Upper bound of `--thresholds auto`.
    #[arg(long, default_value_t = 4)]
    pub max_thresholds: usize,
    /// Curvature thresholds given by hand (comma-separated, used in every region).
    #[arg(long, value_delimiter = ',')]
    pub tau: Vec<f64>,
    /// Noisy scans: examine a region where no threshold is accepted once more with the
    /// curvature at twice --curvature-k (may split sharp edges the segmentation missed).
    #[arg(long)]
    pub coarse_retry: bool,
    /// Leave the cloud's boundary out of the network.
    #[arg(long)]
    pub no_boundary: bool,
    /// Write text instead of binary where the format has both.
    #[arg(long)]
    pub ascii: bool,
}

/// Arguments of `crease network`.
#[derive(Args, Debug)]
pub struct NetworkArgs {
    #[command(flatten)]
    pub fillets: FilletsArgs,
    /// Where the lines come from: `surfaces` (the edges of the B-rep built from the fitted
    /// surfaces, which average the noise over whole faces; Demarsin's lines where no surface
    /// explains the points) or `points` (Demarsin's graph lines only, from each point's
    /// neighbourhood: faster, but they break up under noise of half a spacing).
    #[arg(long, value_enum, default_value_t = LinesFrom::Surfaces)]
    pub lines_from: LinesFrom,
}

/// See [`NetworkArgs::lines_from`].
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinesFrom {
    /// The B-rep's edges where the surfaces explain the part, Demarsin's lines elsewhere.
    Surfaces,
    /// Demarsin's graph lines only.
    Points,
}

fn params(a: &FilletsArgs) -> anyhow::Result<FilletParams> {
    let thresholds = if !a.tau.is_empty() {
        if a.tau.iter().any(|t| *t < 0.0) {
            return Err(usage("--tau values must be non-negative".to_string()));
        }
        ThresholdCount::Manual(a.tau.clone())
    } else if a.thresholds == "auto" {
        ThresholdCount::Auto {
            max: a.max_thresholds,
        }
    } else {
        match a.thresholds.parse::<usize>() {
            Ok(n) => ThresholdCount::Exactly(n),
            Err(_) => {
                return Err(usage(format!(
                    "--thresholds must be `auto` or a number, got `{}`",
                    a.thresholds
                )))
            }
        }
    };
    let params = FilletParams {
        lines: LinesParams {
            k: a.k,
            alpha_max_degrees: a.alpha_max,
            d_max: a.d_max,
            boundary: !a.no_boundary,
            ..Default::default()
        },
        curvature_k: a.curvature_k,
        smoothing_iterations: a.smoothing,
        median_iterations: a.median,
        trim: a.trim,
        bins: a.bins,
        search: if a.one_run {
            Search::OneRun
        } else {
            Search::Full
        },
        thresholds,
        coarse_retry: a.coarse_retry,
        ..Default::default()
    };
    params.validate().map_err(|e| usage(e.to_string()))?;
    Ok(params)
}

/// `crease fillets` (`network` none) and `crease network` (`network`: where its lines come
/// from).
pub fn run(g: &Global, a: &FilletsArgs, network: Option<LinesFrom>) -> anyhow::Result<()> {
    crease::io::Format::from_path(&a.output).map_err(|e| usage(e.to_string()))?;
    crate::ui::ensure_not_input(&a.output, &[&a.input])?;
    if let Some(s) = &a.labels {
        crease::io::Format::from_path(s).map_err(|e| usage(e.to_string()))?;
        crate::ui::ensure_not_input(s, &[&a.input])?;
    }
    let params = params(a)?;
    let (geom, report) = super::load_shape(g, &a.input)?;
    let n_points = geom.points.len();
    let need = a.k.max(a.curvature_k) + 1;
    if n_points < need {
        anyhow::bail!(
            "{}: {n_points} points, fillet lines need at least {need}",
            a.input.display()
        );
    }
    let start = Instant::now();
    let stage = Stage::start(
        match network {
            Some(LinesFrom::Surfaces) => "curve network (B-rep edges + Demarsin 2007/2008)",
            Some(LinesFrom::Points) => "curve network (Demarsin 2007 + 2008)",
            None => "fillet lines (Demarsin 2008)",
        },
        g.quiet,
    );
    let named = |e: crease::Error| anyhow::anyhow!("{}: {e}", a.input.display());
    let points = &geom.points.positions;
    let (f, net) = match network {
        Some(LinesFrom::Surfaces) => {
            let r = network_of_points(points, &params, a.labels.is_some()).map_err(named)?;
            (r.fillets, Some((r.network, r.summary)))
        }
        Some(LinesFrom::Points) => {
            let f = extract_fillets(points, &params, true).map_err(named)?;
            let net = curve_network(&f);
            let summary = NetworkSummary::new(&net, 0, Some("asked for lines from points".into()));
            (Some(f), Some((net, summary)))
        }
        None => (
            Some(extract_fillets(points, &params, false).map_err(named)?),
            None,
        ),
    };
    stage.finish();
    let seconds = start.elapsed().as_secs_f64();

    let out = match (&net, &f) {
        (Some((net, _)), _) => network_geometry(net)?,
        (None, Some(f)) => {
            let mut out =
                Geometry::from_cloud(PointCloud::from_positions(f.lines.vertices.clone()));
            out.polylines = f.lines.polylines.clone();
            out
        }
        (None, None) => unreachable!("the fillet lines are computed without a network"),
    };
    super::save(g, &a.output, &out, a.ascii, &[&a.input])?;
    if let (Some(path), Some(f)) = (&a.labels, &f) {
        let cloud = labelled(&geom.points, f)?;
        super::save(g, path, &Geometry::from_cloud(cloud), a.ascii, &[&a.input])?;
    }
    if g.json {
        let mut summary = serde_json::json!({
            "input": a.input, "output": a.output, "points": n_points,
            "dropped_nonfinite": report.dropped_nonfinite,
            "seconds": seconds,
        });
        if let Some(f) = &f {
            let border = f
                .label
                .iter()
                .filter(|l| **l == Some(Label::Border))
                .count();
            let fillets = serde_json::json!({
                "smooth_regions": f.regions.len(),
                "regions": f.regions,
                "border_points": border,
                "polylines": f.lines.polylines.len(),
                "closed_loops": f.lines.closed_loops(),
                "junctions": f.lines.junctions(),
                "endpoints": f.lines.endpoints(),
                "sharp_stages": f.sharp.as_ref().map(|s| &s.stages),
                "timing": f.seconds,
            });
            if let (Some(map), serde_json::Value::Object(more)) = (summary.as_object_mut(), fillets)
            {
                map.extend(more);
            }
        }
        if let Some((_, s)) = &net {
            summary["network"] = serde_json::to_value(s)?;
        }
        crate::ui::print_json(&summary)?;
    } else if !g.quiet {
        match (&net, &f) {
            (Some((_, s)), _) => {
                eprintln!(
                    "wrote {}: {} sharp, {} smooth and {} border polylines, {} junctions, {} \
                     free ends, {} of them B-rep edges{}, {:.2} s",
                    a.output.display(),
                    s.sharp_polylines,
                    s.smooth_polylines,
                    s.boundary_polylines,
                    s.junctions,
                    s.endpoints,
                    s.from_surfaces,
                    s.not_anchored
                        .as_ref()
                        .map(|w| format!(" (not anchored on surfaces: {w})"))
                        .unwrap_or_default(),
                    seconds
                );
            }
            (None, Some(f)) => {
                let accepted: usize = f
                    .regions
                    .iter()
                    .map(|r| r.thresholds.iter().filter(|t| t.accepted).count())
                    .sum();
                eprintln!(
                    "wrote {}: {} smooth polylines ({} closed loops, {} endpoints) from {} smooth \
                     regions and {} thresholds, {:.2} s",
                    a.output.display(),
                    f.lines.polylines.len(),
                    f.lines.closed_loops(),
                    f.lines.endpoints(),
                    f.regions.len(),
                    accepted,
                    seconds
                );
            }
            (None, None) => {}
        }
    }
    Ok(())
}

/// The network as written: its vertices (with a `smooth` flag) and its polylines in groups.
fn network_geometry(net: &CurveNetwork) -> anyhow::Result<Geometry> {
    let mut cloud = PointCloud::from_positions(net.vertices.clone());
    let mut smooth_vertex = vec![false; net.vertices.len()];
    for (l, &s) in net.polylines.iter().zip(&net.smooth) {
        if s {
            for &v in l {
                smooth_vertex[v as usize] = true;
            }
        }
    }
    cloud.set_attribute(Attribute::flag("smooth", smooth_vertex))?;
    let mut out = Geometry::from_cloud(cloud);
    out.polylines = net.polylines.clone();
    out.polyline_groups = net.groups().iter().map(|g| g.to_string()).collect();
    Ok(out)
}

/// The input cloud with the per-point fillet outputs as properties.
fn labelled(points: &PointCloud, f: &Fillets) -> anyhow::Result<PointCloud> {
    let mut cloud = points.clone();
    let code = |l: Option<Label>| l.map_or(255u8, |l| l as u8);
    cloud.set_attribute(uchar("fillet_label", f.label.iter().map(|&l| code(l))))?;
    cloud.set_attribute(Attribute::flag(
        "smooth_edge",
        f.label.iter().map(|&l| l == Some(Label::Border)),
    ))?;
    cloud.set_attribute(uchar("patch", f.patch.iter().copied()))?;
    cloud.set_attribute(Attribute::int(
        "region",
        f.region
            .iter()
            .map(|&r| if r == u32::MAX { -1 } else { r as i64 }),
    ))?;
    cloud.set_attribute(Attribute::float("mean_curvature", f.curvature.clone()))?;
    Ok(cloud)
}

/// A `uchar` attribute.
fn uchar(name: &str, values: impl IntoIterator<Item = u8>) -> Attribute {
    Attribute {
        name: name.to_string(),
        kind: crease::geometry::ScalarKind::U8,
        values: values.into_iter().map(f64::from).collect(),
    }
}
