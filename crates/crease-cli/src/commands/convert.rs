//! `crease convert IN OUT`: any supported format to any other, keeping every attribute the
//! output format can hold.

use std::path::Path;

use crate::args::Global;

pub fn run(g: &Global, input: &Path, output: &Path, ascii: bool) -> anyhow::Result<()> {
    crease::io::Format::from_path(output).map_err(|e| crate::ui::usage(e.to_string()))?;
    crate::ui::ensure_not_input(output, &[input])?;
    let (geom, report) = super::load(g, input)?;
    super::save(g, output, &geom, ascii, &[input])?;
    if g.json {
        crate::ui::print_json(&serde_json::json!({
            "input": input, "output": output,
            "points": geom.points.len(), "faces": geom.faces.len(),
            "edges": geom.edges.len(), "polylines": geom.polylines.len(),
            "read": report,
        }))?;
    } else if !g.quiet {
        eprintln!(
            "wrote {} ({} points, {} faces)",
            output.display(),
            geom.points.len(),
            geom.faces.len()
        );
    }
    Ok(())
}
