//! Segmentation of point clouds into analytic surfaces (`crease::segment::segment_points`)
//! scored against exact ground truth: the synthetic parts sampled as clouds (no noise and
//! noise of 1 % of the spacing along the normal, normals estimated by PCA or given), and the
//! vertices of the ABC model 00000006 as a cloud (a vertex's truth is that of its incident
//! faces: "interior" vertices, whose faces all lie on one true surface, are scored separately).
//!
//! Run: `cargo run --release -p crease --example segment_points_eval [-- N [DATA_DIR]]`
//! (N = points per synthetic part, default 20000).

use std::path::PathBuf;
use std::time::Instant;

use crease::geometry::MeshTopology;
use crease::segment::score::{param_error, read_abc_truth, score_faces};
use crease::segment::{segment_points, PointParams, SegmentParams};
use crease::synth::{self, Noise, SampleParams, Shape};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(20_000);
    let dir = std::env::args()
        .nth(2)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let only: Option<String> = std::env::var("PARTS").ok();
    for name in [
        "plane",
        "cylinder",
        "cone",
        "sphere",
        "torus",
        "cube",
        "box-hole",
        "fillet-chamfer-cone",
        "rounded-cube",
        "two-cylinders",
    ] {
        if only
            .as_deref()
            .is_some_and(|o| !o.split(',').any(|x| x == name))
        {
            continue;
        }
        for noise in [0.0, 0.01] {
            for given in [false, true] {
                let part = synth::sample_points(
                    &Shape::from_name(name).ok_or("shape")?,
                    &SampleParams {
                        n,
                        noise: if noise > 0.0 {
                            Noise::AlongNormal(noise)
                        } else {
                            Noise::None
                        },
                        ..Default::default()
                    },
                )?;
                let c = &part.cloud;
                let normals = if given { c.normals.as_deref() } else { None };
                let t = Instant::now();
                let seg = segment_points(
                    &c.positions,
                    normals,
                    &SegmentParams::default(),
                    &point_params(),
                )?;
                let secs = t.elapsed().as_secs_f64();
                let truth: Vec<i32> = c
                    .attributes
                    .get(synth::attr::SURFACE)
                    .ok_or("gt_surface")?
                    .as_i64()
                    .iter()
                    .map(|&v| v as i32)
                    .collect();
                let ttype: Vec<u8> = c
                    .attributes
                    .get(synth::attr::SURFACE_TYPE)
                    .ok_or("gt_surface_type")?
                    .as_i64()
                    .iter()
                    .map(|&v| v as u8)
                    .collect();
                let ones = vec![1.0; truth.len()];
                let score = score_faces(
                    &ones,
                    &seg.point_surface,
                    &seg.point_types(),
                    &truth,
                    &ttype,
                )?;
                let (mut worst_r, mut worst_a, mut wrong) = (0.0f64, 0.0f64, 0);
                let mut min_iou = 1.0f64;
                for mt in &score.matches {
                    min_iou = min_iou.min(mt.iou);
                    if mt.best < 0 || mt.best_type != mt.truth_type {
                        wrong += 1;
                        continue;
                    }
                    let e = param_error(
                        &seg.surfaces[mt.best as usize].params,
                        &part.surfaces[mt.truth].params,
                    );
                    worst_r = worst_r.max(e.radius.unwrap_or(0.0));
                    worst_a = worst_a.max(e.axis_degrees.unwrap_or(0.0));
                }
                println!(
                    "{name:20} noise {noise:4} normals {:9}: {:3} surfaces, typed {:.4}, unassigned {:.4}, \
                     IoU {:.3} (min {:.3}), wrong/missing {wrong}/{}, worst radius {:.5}, axis {:.3}°, {secs:.2} s",
                    if given { "given" } else { "estimated" },
                    seg.surfaces.len(),
                    score.typed_area,
                    score.unassigned_area,
                    score.mean_iou_area,
                    min_iou,
                    score.matches.len(),
                    worst_r,
                    worst_a
                );
                if std::env::var("VERBOSE").is_ok() {
                    for mt in &score.matches {
                        let e = (mt.best >= 0).then(|| {
                            param_error(
                                &seg.surfaces[mt.best as usize].params,
                                &part.surfaces[mt.truth].params,
                            )
                        });
                        println!(
                            "   true {} {:?} {:.0} pts: got {} {:?} IoU {:.3} err {:?}",
                            mt.truth, mt.truth_type, mt.area, mt.best, mt.best_type, mt.iou, e
                        );
                    }
                    println!("   timings {:?}", seg.timings);
                }
            }
        }
    }
    if only.is_some() {
        return Ok(());
    }
    // The ABC model's vertices as a cloud.
    let abc = dir.join("abc");
    let (mesh, _) = crease::io::read_mesh(
        abc.join("00000006_d4fe04f0f5f84b52bd4f10e4_trimesh_001.obj"),
        &Default::default(),
    )?;
    let truth = read_abc_truth(
        &abc.join("00000006_face_surface_labels.txt"),
        &abc.join("00000006_primitives.json"),
    )?;
    let topo = MeshTopology::new(&mesh)?;
    let nv = mesh.num_vertices();
    let t = Instant::now();
    let seg = segment_points(
        mesh.positions(),
        None,
        &SegmentParams::default(),
        &point_params(),
    )?;
    let secs = t.elapsed().as_secs_f64();
    // Vertex truth: the surface of its incident faces when they agree, else -2 (boundary).
    let mut vt = vec![-1i32; nv];
    let mut vtype = vec![255u8; nv];
    for v in 0..nv {
        for &f in topo.vertex_faces(v) {
            let s = truth.face_surface[f as usize];
            if vt[v] == -1 {
                vt[v] = s;
                vtype[v] = truth.face_type[f as usize];
            } else if vt[v] != s {
                vt[v] = -2;
            }
        }
    }
    let all_truth: Vec<i32> = (0..nv)
        .map(|v| {
            // Boundary vertices: the surface of their first face.
            topo.vertex_faces(v)
                .first()
                .map(|&f| truth.face_surface[f as usize])
                .unwrap_or(-1)
        })
        .collect();
    let all_type: Vec<u8> = (0..nv)
        .map(|v| {
            topo.vertex_faces(v)
                .first()
                .map(|&f| truth.face_type[f as usize])
                .unwrap_or(255)
        })
        .collect();
    let types = seg.point_types();
    // A boundary vertex is right when its type is that of any of its faces.
    let mut right_any = 0.0;
    let mut total_any = 0.0;
    for (v, &ty) in types.iter().enumerate() {
        let fs = topo.vertex_faces(v);
        if fs.is_empty() {
            continue;
        }
        total_any += seg.point_area[v];
        if fs.iter().any(|&f| truth.face_type[f as usize] == ty) {
            right_any += seg.point_area[v];
        }
    }
    let interior_truth: Vec<i32> = vt.iter().map(|&s| if s < 0 { -1 } else { s }).collect();
    let si = score_faces(
        &seg.point_area,
        &seg.point_surface,
        &types,
        &interior_truth,
        &vtype,
    )?;
    let sa = score_faces(
        &seg.point_area,
        &seg.point_surface,
        &types,
        &all_truth,
        &all_type,
    )?;
    let interior = vt.iter().filter(|&&s| s >= 0).count();
    println!(
        "ABC 00000006 vertices as a cloud ({nv} points, {interior} interior): {} surfaces, \
         typed area (any incident face) {:.4}, interior typed area {:.4}, unassigned {:.4}, IoU {:.3}; \
         all (first face) typed {:.4}; {secs:.2} s {:?}",
        seg.surfaces.len(),
        right_any / total_any,
        si.typed_area,
        si.unassigned_area,
        si.mean_iou_area,
        sa.typed_area,
        seg.timings
    );
    for mt in &si.matches {
        let e = match (mt.best, truth.surfaces[mt.truth]) {
            (b, Some(t)) if b >= 0 => Some(param_error(&seg.surfaces[b as usize].params, &t)),
            _ => None,
        };
        println!(
            "   true {} {:?} area {:.3}: got {} {:?} IoU {:.3} err {:?}",
            mt.truth, mt.truth_type, mt.area, mt.best, mt.best_type, mt.iou, e
        );
    }
    Ok(())
}

/// Point parameters, overridable by the environment (`K`, `NORMAL_K`) for experiments.
fn point_params() -> PointParams {
    let d = PointParams::default();
    let get = |k: &str, v: usize| {
        std::env::var(k)
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(v)
    };
    PointParams {
        k: get("K", d.k),
        normal_k: get("NORMAL_K", d.normal_k),
        ..d
    }
}
