//! `crease normals IN -o OUT [--method pca|ring|mesh] [-k 20] [--orient]`: estimates a normal
//! per point (or mesh vertex) and writes OUT with `nx ny nz` beside every other attribute of IN,
//! in the input order.

use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use crease::estimate::{self, PcaParams, Weighting};

use crate::args::Global;
use crate::ui::Stage;

/// Arguments of `crease normals`.
#[derive(Args, Debug)]
#[command(
    after_help = "Normals already stored in IN are never used: they are replaced by the estimate."
)]
pub struct NormalsArgs {
    /// Point cloud or mesh (any supported format). Normals stored in it are ignored and
    /// replaced.
    pub input: PathBuf,
    /// Output file (.ply keeps every attribute of the input; the format follows the extension).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Estimator: weighted PCA over the k nearest neighbours (tran eq. 1), least-squares plane
    /// of the Delaunay 1-ring (demarsin2007), or mesh vertex normals from the faces.
    #[arg(long, value_enum, default_value_t = Method::Pca)]
    pub method: Method,
    /// Number of nearest neighbours (PCA, ring, and the --orient graph).
    #[arg(short = 'k', long = "neighbours", alias = "k", default_value_t = 20)]
    pub k: usize,
    /// Make the signs consistent (Hoppe 1992: minimum spanning tree over the kNN graph, seeded
    /// at the highest point of each connected part, pointing +z there). Without it PCA and ring
    /// normals have arbitrary signs; mesh normals follow the face winding.
    #[arg(long)]
    pub orient: bool,
    /// How face normals are combined with --method mesh.
    #[arg(long, value_enum, default_value_t = WeightingArg::Uniform)]
    pub weighting: WeightingArg,
    /// Write text instead of binary where the format has both.
    #[arg(long)]
    pub ascii: bool,
}

/// Normal estimator.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Gaussian-weighted PCA over the k nearest neighbours.
    Pca,
    /// Least-squares plane through the Delaunay 1-ring.
    Ring,
    /// Mesh vertex normals (needs a mesh input).
    Mesh,
}

/// Face-normal weighting of mesh vertex normals.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum WeightingArg {
    /// Mean of the incident face normals (Gouraud).
    Uniform,
    /// Weighted by face area.
    Area,
    /// Weighted by the face's angle at the vertex.
    Angle,
}

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Pca => "pca",
            Method::Ring => "ring",
            Method::Mesh => "mesh",
        }
    }
}

pub fn run(g: &Global, a: &NormalsArgs) -> anyhow::Result<()> {
    crease::io::Format::from_path(&a.output).map_err(|e| crate::ui::usage(e.to_string()))?;
    crate::ui::ensure_not_input(&a.output, &[&a.input])?;
    if a.k == 0 && (a.method != Method::Mesh || a.orient) {
        return Err(crate::ui::usage("-k must be at least 1"));
    }
    let t_read = Instant::now();
    let (mut geom, report) = super::load_shape(g, &a.input)?;
    let t_read = t_read.elapsed().as_secs_f64();
    let n = geom.points.len();
    let had_normals = geom.points.normals.is_some();
    let needs_knn = a.method != Method::Mesh || a.orient;
    // PCA without --orient needs no stored neighbourhoods: the fused search visits them in
    // spatial order (faster, no n·k lists); its time is reported under "normals".
    let fused = a.method == Method::Pca && !a.orient;
    // Exact duplicates are estimated once (copies would fill the neighbourhoods, a point
    // repeated k times having no plane at all), and each copy takes its original's normal.
    // The cloud methods read the positions (held apart while the mesh method borrows the
    // geometry as a mesh).
    let positions = if a.method == Method::Mesh {
        Vec::new()
    } else {
        std::mem::take(&mut geom.points.positions)
    };
    let distinct = crease::spatial::distinct_in_input_order(&positions);
    let pts = distinct
        .as_ref()
        .map_or(positions.as_slice(), |d| d.points.as_slice());
    let mut t_knn = 0.0;
    let nbrs = if needs_knn && !fused {
        let stage = Stage::start(&format!("{} nearest neighbours", a.k), g.quiet);
        let nbrs = crease::spatial::knn(pts, a.k)
            .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
        t_knn = stage.finish();
        Some(nbrs)
    } else {
        None
    };
    let stage = Stage::start(&format!("{} normals", a.method.name()), g.quiet);
    let mut normals = match a.method {
        Method::Pca if fused => {
            estimate::normals::pca_normals_direct(
                pts,
                &PcaParams {
                    k: a.k,
                    ..Default::default()
                },
            )
            .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?
            .normals
        }
        Method::Pca => {
            let nbrs = nbrs
                .as_ref()
                .ok_or_else(|| anyhow::anyhow!("internal: no neighbourhoods for --method pca"))?;
            estimate::pca_normals(
                pts,
                nbrs,
                &PcaParams {
                    k: a.k,
                    ..Default::default()
                },
            )?
            .normals
        }
        Method::Ring => {
            let nbrs = nbrs
                .as_ref()
                .ok_or_else(|| anyhow::anyhow!("internal: no neighbourhoods for --method ring"))?;
            let rings =
                crease::spatial::delaunay_rings(pts, nbrs, &crease::spatial::RingParams { k: a.k })
                    .map_err(|e| anyhow::anyhow!("{}: {e}", a.input.display()))?;
            estimate::ring_normals(pts, &rings)
        }
        Method::Mesh => {
            if !geom.is_mesh() {
                return Err(crate::ui::usage(format!(
                    "{}: --method mesh needs a triangle mesh, and this file has no faces (use --method pca)",
                    a.input.display()
                )));
            }
            let weighting = match a.weighting {
                WeightingArg::Uniform => Weighting::Uniform,
                WeightingArg::Area => Weighting::Area,
                WeightingArg::Angle => Weighting::Angle,
            };
            // Borrow the geometry as a mesh without copying it, then give it back.
            let mesh = crease::TriMesh {
                vertices: std::mem::take(&mut geom.points),
                faces: std::mem::take(&mut geom.faces),
                face_attributes: Default::default(),
            };
            let r = estimate::mesh_vertex_normals(&mesh, weighting);
            geom.points = mesh.vertices;
            geom.faces = mesh.faces;
            r?
        }
    };
    let t_normals = stage.finish();
    let mut t_orient = 0.0;
    if a.orient {
        if let Some(nbrs) = &nbrs {
            let stage = Stage::start("orienting normals", g.quiet);
            normals = estimate::orient_normals(pts, &normals, nbrs)?;
            t_orient = stage.finish();
        }
    }
    if let Some(d) = &distinct {
        normals = d.expand(&normals);
    }
    if a.method != Method::Mesh {
        geom.points.positions = positions;
    }
    geom.points.set_normals(normals)?;
    let t_write = Instant::now();
    super::save(g, &a.output, &geom, a.ascii, &[&a.input])?;
    let t_write = t_write.elapsed().as_secs_f64();
    if g.json {
        crate::ui::print_json(&serde_json::json!({
            "input": a.input, "output": a.output,
            "method": a.method.name(),
            "k": if needs_knn { Some(a.k) } else { None },
            "weighting": (a.method == Method::Mesh).then(|| format!("{:?}", a.weighting).to_lowercase()),
            "oriented": a.orient,
            "count": n,
            "replaced_input_normals": had_normals,
            "timings": {
                "read": t_read, "knn": t_knn, "normals": t_normals,
                "orient": t_orient, "write": t_write,
            },
            "read": report,
        }))?;
    } else if !g.quiet {
        eprintln!(
            "wrote {} ({n} {} normals{}; knn {t_knn:.3} s, normals {t_normals:.3} s{})",
            a.output.display(),
            a.method.name(),
            if a.orient { ", oriented" } else { "" },
            if a.orient {
                format!(", orient {t_orient:.3} s")
            } else {
                String::new()
            }
        );
    }
    Ok(())
}
