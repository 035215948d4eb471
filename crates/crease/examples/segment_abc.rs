//! Segmentation of the ABC model 00000006 (mizoguchi, `crease::segment`) scored against its
//! per-face surface ground truth: area-weighted type accuracy, IoU per true surface, parameter
//! errors, timings.
//!
//! Run: `cargo run --release -p crease --example segment_abc [-- DATA_DIR]` (default
//! `../shared/data` beside the repository).

use std::path::PathBuf;
use std::time::Instant;

use crease::geometry::{face_areas, MeshTopology};
use crease::segment::score::{param_error, read_abc_truth, score_faces};
use crease::segment::{segment_mesh, SegmentParams};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let abc = dir.join("abc");
    let obj = abc.join("00000006_d4fe04f0f5f84b52bd4f10e4_trimesh_001.obj");
    let (mesh, _) = crease::io::read_mesh(&obj, &Default::default())?;
    let truth = read_abc_truth(
        &abc.join("00000006_face_surface_labels.txt"),
        &abc.join("00000006_primitives.json"),
    )?;
    if truth.face_surface.len() != mesh.num_faces() {
        return Err(format!(
            "{} faces in the mesh but {} in the labels",
            mesh.num_faces(),
            truth.face_surface.len()
        )
        .into());
    }
    let start = Instant::now();
    let topo = MeshTopology::new(&mesh)?;
    let seg = segment_mesh(&mesh, &topo, &SegmentParams::default())?;
    let seconds = start.elapsed().as_secs_f64();
    let score = score_faces(
        &face_areas(&mesh),
        &seg.face_surface,
        &seg.face_types(),
        &truth.face_surface,
        &truth.face_type,
    )?;
    println!(
        "ABC 00000006: {} vertices, {} faces, mean edge {:.4}",
        mesh.num_vertices(),
        mesh.num_faces(),
        seg.mean_edge
    );
    println!(
        "{} surfaces from {} seeds in {seconds:.2} s ({:?})",
        seg.surfaces.len(),
        seg.seeds,
        seg.timings
    );
    println!(
        "area correctly typed {:.2} %, unassigned {:.2} %, IoU (area-weighted) {:.3}, mean IoU {:.3}",
        100.0 * score.typed_area,
        100.0 * score.unassigned_area,
        score.mean_iou_area,
        score.mean_iou
    );
    println!(
        "{:>4} {:>9} {:>8} {:>5} {:>9} {:>6} {:>9} {:>8} {:>10} {:>8}",
        "true", "type", "area", "got", "type", "IoU", "radius%", "axis°", "position", "angle°"
    );
    for m in &score.matches {
        let e = match (m.best, truth.surfaces[m.truth]) {
            (b, Some(t)) if b >= 0 => param_error(&seg.surfaces[b as usize].params, &t),
            _ => Default::default(),
        };
        let f = |x: Option<f64>, s: f64| x.map_or("-".to_string(), |v| format!("{:.4}", v * s));
        println!(
            "{:>4} {:>9} {:>8.3} {:>5} {:>9} {:>6.3} {:>9} {:>8} {:>10} {:>8}",
            m.truth,
            m.truth_type.name(),
            m.area,
            m.best,
            m.best_type.name(),
            m.iou,
            f(e.radius, 100.0),
            f(e.axis_degrees, 1.0),
            f(e.position, 1.0),
            f(e.half_angle_degrees, 1.0)
        );
    }
    for g in &seg.groups {
        let types: Vec<&str> = g
            .surfaces
            .iter()
            .map(|&s| seg.surfaces[s as usize].kind.name())
            .collect();
        println!(
            "{:?}: surfaces {:?} ({})",
            g.kind,
            g.surfaces,
            types.join(", ")
        );
    }
    Ok(())
}
