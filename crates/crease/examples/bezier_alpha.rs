//! Does Razdan and Bae's α (data weight against a shape term in the biquadratic Bézier fit,
//! mizoguchi's α = 0.9) help? Compares the plain least-squares patch (α = none) with α = 0.9
//! and 0.95 on: the curvature of the synthetic sphere (radius 0.5) and cylinder meshes with
//! noise along the normal of 0, 5 and 10 % of the mean edge (relative RMS error of κ_max over
//! the non-sharp vertices), and the segmentation of the ABC model and of the noisy synthetic
//! parts (area-weighted typed fraction).
//!
//! Run: `cargo run --release -p crease --example bezier_alpha [-- DATA_DIR]`.

use std::path::PathBuf;

use crease::estimate::bezier::{bezier_curvature, BezierParams};
use crease::geometry::{face_areas, MeshTopology};
use crease::segment::score::{read_abc_truth, score_faces};
use crease::segment::{segment_mesh, SegmentParams};
use crease::synth::{self, MeshParams, Noise, NoiseScale, Shape};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data"));
    let alphas = [None, Some(0.9), Some(0.95)];
    let mesh_of = |name: &str, noise: f64| {
        synth::mesh(
            &Shape::from_name(name).unwrap(),
            &MeshParams {
                noise: if noise > 0.0 {
                    Noise::AlongNormal(noise)
                } else {
                    Noise::None
                },
                noise_scale: NoiseScale::Spacing,
                ..Default::default()
            },
        )
    };
    for name in ["sphere", "cylinder"] {
        for noise in [0.0, 0.05, 0.1] {
            let m = mesh_of(name, noise)?;
            let topo = MeshTopology::new(&m.mesh)?;
            let mut line = format!("{name:8} noise {noise:4}:");
            for a in alphas {
                let b = bezier_curvature(
                    &m.mesh,
                    &topo,
                    &BezierParams {
                        alpha: a,
                        ..Default::default()
                    },
                )?;
                let (mut s, mut n) = (0.0, 0usize);
                for (i, k) in b.curvature.max_abs().iter().enumerate() {
                    if b.sharp[i] || !k.is_finite() {
                        continue;
                    }
                    let e = k.abs() * 0.5 - 1.0; // true |κ_max| = 1 / 0.5
                    s += e * e;
                    n += 1;
                }
                line += &format!("  α {a:?}: κ_max rel. RMS {:.4}", (s / n as f64).sqrt());
            }
            println!("{line}");
        }
    }
    let seg_typed = |mesh: &crease::geometry::TriMesh,
                     truth: &[i32],
                     ttype: &[u8],
                     a: Option<f64>|
     -> Result<f64, Box<dyn std::error::Error>> {
        let topo = MeshTopology::new(mesh)?;
        let params = SegmentParams {
            bezier: BezierParams {
                alpha: a,
                ..Default::default()
            },
            ..Default::default()
        };
        let seg = segment_mesh(mesh, &topo, &params)?;
        let s = score_faces(
            &face_areas(mesh),
            &seg.face_surface,
            &seg.face_types(),
            truth,
            ttype,
        )?;
        Ok(s.typed_area)
    };
    for name in ["rounded-cube", "fillet-chamfer-cone", "torus"] {
        for noise in [0.01, 0.1] {
            let m = mesh_of(name, noise)?;
            let fa = &m.mesh.face_attributes;
            let truth: Vec<i32> = fa
                .get("gt_surface")
                .ok_or("gt")?
                .as_i64()
                .iter()
                .map(|&v| v as i32)
                .collect();
            let tt: Vec<u8> = fa
                .get("gt_surface_type")
                .ok_or("gt")?
                .as_i64()
                .iter()
                .map(|&v| v as u8)
                .collect();
            let mut line = format!("{name:20} noise {noise:4} typed:");
            for a in alphas {
                line += &format!("  α {a:?}: {:.4}", seg_typed(&m.mesh, &truth, &tt, a)?);
            }
            println!("{line}");
        }
    }
    let abc = dir.join("abc");
    let (mesh, _) = crease::io::read_mesh(
        abc.join("00000006_d4fe04f0f5f84b52bd4f10e4_trimesh_001.obj"),
        &Default::default(),
    )?;
    let truth = read_abc_truth(
        &abc.join("00000006_face_surface_labels.txt"),
        &abc.join("00000006_primitives.json"),
    )?;
    let mut line = "ABC 00000006 typed:".to_string();
    for a in alphas {
        line += &format!(
            "  α {a:?}: {:.4}",
            seg_typed(&mesh, &truth.face_surface, &truth.face_type, a)?
        );
    }
    println!("{line}");
    Ok(())
}
