//! One module per subcommand; each reads its inputs, calls the library, writes its outputs.

mod convert;
pub mod curvature;
mod demo;
pub(crate) mod edges;
pub(crate) mod eval;
pub(crate) mod fillets;
mod info;
pub(crate) mod lines;
pub(crate) mod normals;
pub(crate) mod reconstruct;
mod render;
pub(crate) mod run;
pub(crate) mod segment;
pub(crate) mod sharp;
mod synth;
pub(crate) mod train;
pub mod view;

use std::path::Path;

use crease::io::{Geometry, ReadOptions, ReadReport};

use crate::args::{Cli, Command, Global};
use crate::ui::Stage;

/// Runs the parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    let g = &cli.global;
    match cli.command {
        Command::Run(a) => run::run(g, &a),
        Command::Info { input } => info::run(g, &input),
        Command::Convert {
            input,
            output,
            ascii,
        } => convert::run(g, &input, &output, ascii),
        Command::Synth(a) => synth::run(g, &a),
        Command::Render(a) => render::run(g, &a),
        Command::View(a) => view::run(g, &a),
        Command::Curvature(a) => curvature::run(g, &a),
        Command::Demo { output, n } => demo::run(g, &output, n),
        Command::Normals(a) => normals::run(g, &a),
        Command::Sharp(a) => sharp::run(g, &a),
        Command::Lines(a) => lines::run(g, &a),
        Command::Eval(a) => eval::run(g, &a),
        Command::Fillets(a) => fillets::run(g, &a, None),
        Command::Network(a) => fillets::run(g, &a.fillets, Some(a.lines_from)),
        Command::Edges(a) => edges::run(g, &a),
        Command::Train(a) => train::run(g, &a),
        Command::Segment(a) => segment::run(g, &a),
        Command::Reconstruct(a) => reconstruct::run(g, &a),
    }
}

/// Reads any supported file, with a spinner, reporting dropped points as a warning.
pub fn load(g: &Global, path: &Path) -> anyhow::Result<(Geometry, ReadReport)> {
    let stage = Stage::start(&format!("reading {}", path.display()), g.quiet);
    let opts = ReadOptions { strict: g.strict };
    let (geom, report) = crease::io::read(path, &opts)?;
    stage.finish();
    if report.dropped_nonfinite > 0 {
        tracing::warn!(
            "{}: dropped {} points with NaN or infinite coordinates (use --strict to refuse such files)",
            path.display(),
            report.dropped_nonfinite
        );
    }
    Ok((geom, report))
}

/// [`load`] for the commands that analyse a shape: refuses a file whose points all coincide
/// (no neighbourhood, normal or surface is theirs), which would otherwise get meaningless
/// answers, or span so little or so much that squared distances leave f64's range.
pub fn load_shape(g: &Global, path: &Path) -> anyhow::Result<(Geometry, ReadReport)> {
    let (geom, report) = load(g, path)?;
    crease::spatial::check_shape(&geom.points.positions)
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    Ok((geom, report))
}

/// Writes `geom` to `path`, refusing to overwrite any of `inputs`.
pub fn save(
    g: &Global,
    path: &Path,
    geom: &Geometry,
    ascii: bool,
    inputs: &[&Path],
) -> anyhow::Result<()> {
    crate::ui::ensure_not_input(path, inputs)?;
    let stage = Stage::start(&format!("writing {}", path.display()), g.quiet);
    crease::io::write(path, geom, &crease::io::WriteOptions { ascii })?;
    stage.finish();
    Ok(())
}
