//! `crease info FILE`: kind, counts, bounding box, spacing, attributes, problems found.

use std::path::Path;

use crate::args::Global;

pub fn run(g: &Global, input: &Path) -> anyhow::Result<()> {
    let (geom, report) = super::load(g, input)?;
    let mut summary = crease::io::summary::summarize(&geom, &report);
    if let Some(mesh) = geom.into_mesh() {
        summary.mesh = Some(crease::io::summary::summarize_mesh(&mesh)?);
    }
    if g.json {
        let mut v = serde_json::to_value(&summary)?;
        v["file"] = serde_json::json!(input);
        crate::ui::print_json(&v)?;
    } else {
        crate::ui::outln(format_args!("file        {}", input.display()))?;
        crate::ui::out(&summary.to_string())?;
    }
    Ok(())
}
