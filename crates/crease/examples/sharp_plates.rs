//! Thin-plate diagnostics on the PCEDNet models: how many of each point's k nearest neighbours
//! lie on the opposite face of a plate, measured with the benchmark's stored (oriented, mesh)
//! normals, which the detector itself never uses.
//!
//! `cargo run --release -p crease --example sharp_plates -- [set]`

use std::path::PathBuf;

use crease::eval::truth::{class_of_color, PointClass};
use crease::geometry::vec3;
use crease::io::{read, ReadOptions};
use crease::spatial::average_spacing;
use crease::spatial::knn;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let set = args.first().cloned().unwrap_or("abc".into());
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/points-gt");
    let mut names: Vec<_> = std::fs::read_dir(root.join(&set))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .collect();
    names.sort();
    for path in names {
        let (g, _) = read(&path, &ReadOptions::default())?;
        let cloud = g.points;
        let colors = cloud.colors.clone().ok_or("no colours")?;
        let normals = cloud.normals.clone().ok_or("no normals")?;
        let truth: Vec<bool> = colors
            .iter()
            .map(|c| class_of_color(*c) == Some(PointClass::Sharp))
            .collect();
        let pts = &cloud.positions;
        let h = average_spacing(pts).ok_or("spacing")?;
        let nb = knn(pts, 40)?;
        // Opposite face: stored normals more than 120 degrees apart and the neighbour lies
        // behind the point's face (along -n) by more than half a spacing.
        let opposite = |i: usize, j: usize| {
            vec3::dot(normals[i], normals[j]) < -0.5
                && vec3::dot(vec3::sub(pts[j], pts[i]), normals[i]) < -0.5 * h
        };
        let mut line = format!(
            "{:<5} n={:>6} h={h:.4}",
            path.file_stem().unwrap_or_default().to_string_lossy(),
            pts.len()
        );
        for k in [8usize, 12, 24, 40] {
            let counts: Vec<usize> = (0..pts.len())
                .map(|i| {
                    nb.prefix(i, k)
                        .iter()
                        .filter(|&&j| opposite(i, j as usize))
                        .count()
                })
                .collect();
            let any = counts.iter().filter(|&&c| c > 0).count() as f64 / pts.len() as f64;
            let mean = counts.iter().sum::<usize>() as f64 / (pts.len() * k) as f64;
            line += &format!(
                " | k={k}: {:.0}% pts, {:.1}% nbrs",
                100.0 * any,
                100.0 * mean
            );
        }
        // Thickness: distance to the nearest opposite-face neighbour, in spacings (median over
        // the points that have one among their 40 nearest).
        let mut thick: Vec<f64> = (0..pts.len())
            .filter_map(|i| {
                nb.of(i)
                    .iter()
                    .find(|&&j| opposite(i, j as usize))
                    .map(|&j| vec3::dot(vec3::sub(pts[i], pts[j as usize]), normals[i]) / h)
            })
            .collect();
        thick.sort_by(f64::total_cmp);
        let med = thick.get(thick.len() / 2).copied().unwrap_or(f64::NAN);
        let truth_n = truth.iter().filter(|&&t| t).count();
        println!(
            "{line} | thickness median {med:.2} h (of {} pts) gt={truth_n}",
            thick.len()
        );
    }
    Ok(())
}
