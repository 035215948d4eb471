//! Command-line arguments (clap derive).

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

/// Feature lines, sharp edges and analytic surfaces of scanned man-made objects.
#[derive(Parser, Debug)]
#[command(name = "crease", version, about, long_about = None)]
pub struct Cli {
    #[command(flatten)]
    pub global: Global,
    #[command(subcommand)]
    pub command: Command,
}

/// Options every command takes.
#[derive(Args, Debug, Clone)]
pub struct Global {
    /// Number of worker threads (default: all cores).
    #[arg(long, global = true, value_name = "N")]
    pub threads: Option<usize>,
    /// Print nothing but errors (and the --json summary).
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// More logging on stderr (-v info, -vv debug, -vvv trace).
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    pub verbose: u8,
    /// Print a machine-readable JSON summary on stdout.
    #[arg(long, global = true)]
    pub json: bool,
    /// Refuse inputs with NaN or infinite coordinates instead of dropping those points.
    #[arg(long, global = true)]
    pub strict: bool,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// The whole job in one command: sharp points, the curve network (sharp and fillet lines)
    /// and the analytic surfaces of a cloud, or the feature edges and surfaces of a mesh, from
    /// one shared analysis, written into a folder with a JSON summary and a picture.
    Run(crate::commands::run::RunArgs),
    /// Describe a file: kind, counts, bounding box, spacing, attributes, problems found.
    Info {
        /// Point cloud or mesh (.ply .obj .off .stl .xyz .txt .pcd .las .laz .e57).
        input: PathBuf,
    },
    /// Convert between formats (chosen by extension).
    Convert {
        /// Input file.
        input: PathBuf,
        /// Output file.
        output: PathBuf,
        /// Write text instead of binary where the format has both (PLY, STL, PCD).
        #[arg(long)]
        ascii: bool,
    },
    /// Generate a synthetic part with exact ground truth.
    Synth(SynthArgs),
    /// Principal curvatures (k1 k2 mean_curvature) of every point or mesh vertex.
    Curvature(crate::commands::curvature::CurvatureArgs),
    /// Draw points, meshes and polylines into a PNG (four views by default).
    Render(RenderArgs),
    /// An interactive 3D view in one self-contained HTML file (any browser, offline): turn,
    /// zoom, colour by any attribute, toggle line layers, click a point for its surface.
    View(crate::commands::view::ViewArgs),
    /// Estimate a normal per point (PCA, Delaunay 1-ring or mesh faces), optionally oriented.
    Normals(crate::commands::normals::NormalsArgs),
    /// Closed sharp feature lines of a point cloud (Demarsin 2007 graph pipeline).
    Lines(crate::commands::lines::LinesArgs),
    /// Fillet (smooth-edge) lines of a point cloud (Demarsin 2008 curvature histograms).
    Fillets(crate::commands::fillets::FilletsArgs),
    /// The whole curve network of a point cloud: sharp and fillet lines together.
    Network(crate::commands::fillets::NetworkArgs),
    /// Sharp feature points (multi-scale projected distance with automatic thresholds).
    Sharp(crate::commands::sharp::SharpArgs),
    /// Score a labelled output against ground truth: precision, recall, F1, MCC, IoU, tolerant
    /// scores, ROC and AUC.
    Eval(crate::commands::eval::EvalArgs),
    /// Feature edges of a triangle mesh that survive noise (the learned classifier fused with
    /// filtered normals and fitted surfaces by default; tangent-plane angle, Potts energy minimised by
    /// a graph cut; dihedral and hysteresis thresholding as baselines).
    Edges(crate::commands::edges::EdgesArgs),
    /// Train the learned edge classifier (RBF SVM) on meshes with ground truth.
    Train(crate::commands::train::TrainArgs),
    /// Segment a triangle mesh into planes, cylinders, cones, spheres and tori with their
    /// parameters (Mizoguchi et al.).
    Segment(crate::commands::segment::SegmentArgs),
    /// Scan to CAD: the part as a B-rep solid (or an open shell) in a STEP file: analytic faces,
    /// their intersection curves and vertices.
    Reconstruct(crate::commands::reconstruct::ReconstructArgs),
    /// Run every capability on a built-in synthetic part; no input files needed.
    Demo {
        /// Folder to write the results into.
        #[arg(short, long, default_value = "crease-demo")]
        output: PathBuf,
        /// Number of points of the demo part.
        #[arg(short, long, default_value_t = 100_000)]
        n: usize,
    },
}

#[derive(Args, Debug)]
pub struct SynthArgs {
    /// Shape name (`crease synth --list` shows them).
    #[arg(required_unless_present = "list")]
    pub shape: Option<String>,
    /// List the shapes and exit.
    #[arg(long)]
    pub list: bool,
    /// Number of points to sample.
    #[arg(short, default_value_t = 100_000)]
    pub n: usize,
    /// Gaussian noise sigma, relative to the spacing (or to the bounding box with --noise-scale bbox).
    #[arg(long, default_value_t = 0.0)]
    pub noise: f64,
    /// Direction of the noise.
    #[arg(long, value_enum, default_value_t = NoiseMode::Normal)]
    pub noise_mode: NoiseMode,
    /// What the noise sigma is relative to.
    #[arg(long, value_enum, default_value_t = NoiseScaleArg::Spacing)]
    pub noise_scale: NoiseScaleArg,
    /// Fraction of outliers (uniform in the enlarged bounding box).
    #[arg(long, default_value_t = 0.0)]
    pub outliers: f64,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Distance to a sharp curve under which a point is labelled sharp (default: one spacing).
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// Write a triangle mesh instead of a point cloud.
    #[arg(long)]
    pub mesh: bool,
    /// Target edge length of the mesh (default: from -n).
    #[arg(long)]
    pub edge: Option<f64>,
    /// Output file (.ply keeps the ground-truth attributes); the curves go to OUT.curves.ply
    /// and the surfaces and parameters to OUT.truth.json.
    #[arg(short, long, required_unless_present = "list")]
    pub output: Option<PathBuf>,
    /// Write text instead of binary where the format has both.
    #[arg(long)]
    pub ascii: bool,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseMode {
    /// Along the surface normal.
    Normal,
    /// In every direction.
    Isotropic,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum NoiseScaleArg {
    /// Relative to the expected point spacing.
    Spacing,
    /// Relative to the bounding box diagonal.
    Bbox,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// Point cloud or mesh to draw.
    pub input: PathBuf,
    /// Colour by this attribute (e.g. sharp, sharpness, label), or `rgb`, `normal`, `uniform`.
    #[arg(long, value_name = "ATTR")]
    pub color_by: Option<String>,
    /// Polylines to draw on top (e.g. feature curves, .ply with an edge element or .obj with `l`).
    #[arg(long, value_name = "FILE")]
    pub lines: Vec<PathBuf>,
    /// One view instead of four.
    #[arg(long, value_enum)]
    pub view: Option<ViewArg>,
    /// Image width in pixels.
    #[arg(long, default_value_t = 1600)]
    pub width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 1200)]
    pub height: u32,
    /// Title drawn at the top (default: the file name).
    #[arg(long)]
    pub title: Option<String>,
    /// Output PNG.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ViewArg {
    Iso,
    Front,
    Top,
    Side,
}
