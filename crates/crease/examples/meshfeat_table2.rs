//! Reproduces Table 2 of vidal et al. 2011 on the meshes crease has: per-edge AUC of dihedral
//! thresholding, hysteresis thresholding, the tangent-plane angle, and the Potts energy with the
//! dihedral and the tangent-plane data terms, and crease's default, the dihedral angle of
//! bilaterally filtered normals (`filtered`, alone and as the Potts data term), on clean and
//! noisy meshes (0.5 % Gaussian noise of the bounding box's largest side, section 6.1).
//!
//! ```text
//! cargo run --release -p crease --example meshfeat_table2 [-- [--samples N] [--only NAME]
//!     [--mu M] [--beta B] [--lambda L] [--sigma S] [--scales 0.04,0.07] [--label-degrees D]
//!     [--noise R]]
//! ```
//!
//! `--noise R` sets the noise (default 0.005 × the largest side). At R = 0.002 our dihedral
//! thresholding scores what the paper's Table 2 reports for its noisy models (mean 97.18 %
//! against 97.3 %), so that is the level comparable with the paper. Noisy tables end with a
//! second mean that leaves out the edges of faces narrower than the noise in the clean mesh
//! (`meshfeat::sliver_edges`): their labels are the clean normal of a sliver, which noise of
//! that size erases.
//!
//! Ground truth: synthetic parts exact (`crease::synth::mesh`), the ABC model's sharp curves,
//! and for the classic meshes of `../shared/data/meshes` the clean mesh's edges whose dihedral
//! angle exceeds the mesh's threshold in `crease::meshfeat::CLASSIC_LABELS` (meshes without feature
//! lines are not scored), or `--label-degrees D` for every mesh (25 until 2026-12-03). The Potts columns trace their ROC by sweeping
//! θ_true over [0, π] (`--samples`, default 200, as the paper), the others by their score.
//! Also printed per method: F1 and false-positive rate at the default operating point.

#![allow(clippy::needless_range_loop)] // five parallel per-method arrays

use std::path::PathBuf;
use std::time::Instant;

use crease::eval::roc::roc;
use crease::eval::Confusion;
use crease::geometry::TriMesh;
use crease::meshfeat::{
    add_noise, classic_label_degrees, dihedral_labels, filtered_dihedral, hysteresis_scores,
    labels_from_pairs, mean_tangent_angle, potts_labels, read_abc_sharp_edges, sliver_edges,
    sweep_auc, tangent_angles, threshold, EdgeMesh, EdgePairs, EdgeParams, PottsParams,
    TangentParams,
};
use crease::synth::{mesh as synth_mesh, MeshParams, Shape};

struct Opts {
    samples: usize,
    only: Option<String>,
    potts: PottsParams,
    scales: Vec<f64>,
    label_degrees: Option<f64>,
    noise: f64,
    mean_init: bool,
    iterations: usize,
    compact: bool,
    best: bool,
}

fn parse() -> Opts {
    let d = EdgeParams::default();
    let mut o = Opts {
        samples: 200,
        only: None,
        potts: d.potts,
        scales: d.tangent.scales.clone(),
        label_degrees: None,
        noise: 0.005,
        mean_init: d.tangent.mean_init,
        iterations: d.tangent.iterations,
        compact: false,
        best: false,
    };
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if let Some(i) = args.iter().position(|a| a == "--compact") {
        o.compact = true;
        args.remove(i);
    }
    let mut i = 0;
    while i + 1 < args.len() {
        let v = &args[i + 1];
        let f = || v.parse::<f64>().expect("a number");
        match args[i].as_str() {
            "--samples" => o.samples = v.parse().expect("a count"),
            "--only" => o.only = Some(v.clone()),
            "--mu" => o.potts.mu = f(),
            "--beta" => o.potts.beta = f(),
            "--lambda" => o.potts.lambda = f(),
            "--sigma" => o.potts.sigma = f(),
            "--theta-true" => o.potts.theta_true = f().to_radians(),
            "--label-degrees" => o.label_degrees = Some(f()),
            "--noise" => o.noise = f(),
            "--best" => o.best = v == "1",
            "--mean-init" => o.mean_init = v == "1",
            "--iterations" => o.iterations = v.parse().expect("a count"),
            "--scales" => o.scales = v.split(',').map(|s| s.parse().expect("scale")).collect(),
            a => panic!("unknown option {a}"),
        }
        i += 2;
    }
    o
}

/// One mesh of the table: name, clean mesh, per-edge truth.
struct Case {
    name: String,
    mesh: TriMesh,
    truth: Vec<bool>,
}

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data")
}

fn cases(o: &Opts) -> Vec<Case> {
    let mut out = Vec::new();
    for name in ["cube", "box-hole", "two-cylinders", "fillet-chamfer-cone"] {
        let shape = Shape::from_name(name).expect("shape");
        let edge = shape.aabb().max_side() / 60.0;
        let m = synth_mesh(
            &shape,
            &MeshParams {
                target_edge: Some(edge),
                ..Default::default()
            },
        )
        .expect("synthetic mesh");
        let em = EdgeMesh::new(&m.mesh).expect("topology");
        let (truth, missing) = labels_from_pairs(&em.topo, &m.sharp_edges);
        assert_eq!(missing, 0);
        drop(em);
        out.push(Case {
            name: format!("synth {name}"),
            mesh: m.mesh,
            truth,
        });
    }
    let dir = data_dir();
    for file in [
        "fandisk.off",
        "cup.off",
        "cylinder.off",
        "block.off",
        "bar.off",
        "rocker-arm.off",
        "screwdriver.off",
        "sharp_sphere.off",
        "torus.off",
    ] {
        let path = dir.join("meshes").join(file);
        let (g, _) = crease::io::read(&path, &Default::default()).expect("mesh file");
        let mesh = g.into_mesh().expect("faces");
        let em = EdgeMesh::new(&mesh).expect("topology");
        // Section 6.1 labels: the mesh's own threshold (`CLASSIC_LABELS`) unless one is given
        // for all; meshes without feature lines are not scored.
        let degrees = o.label_degrees.or_else(|| classic_label_degrees(file));
        let Some(degrees) = degrees else {
            println!("{file}: no feature lines (section 6.1, checked by eye), not scored");
            continue;
        };
        let truth = dihedral_labels(&em, degrees);
        drop(em);
        out.push(Case {
            name: file.trim_end_matches(".off").to_string(),
            mesh,
            truth,
        });
    }
    let abc = dir.join("abc");
    let obj = abc.join("00000006_d4fe04f0f5f84b52bd4f10e4_trimesh_001.obj");
    let yml = abc.join("00000006_d4fe04f0f5f84b52bd4f10e4_features_001.yml");
    let (g, _) = crease::io::read(&obj, &Default::default()).expect("ABC obj");
    let mesh = g.into_mesh().expect("faces");
    let pairs = read_abc_sharp_edges(&yml).expect("ABC yml");
    let em = EdgeMesh::new(&mesh).expect("topology");
    let (truth, missing) = labels_from_pairs(&em.topo, &pairs);
    if missing > 0 {
        eprintln!("ABC: {missing} curve segments are not mesh edges");
    }
    drop(em);
    out.push(Case {
        name: "abc 00000006".into(),
        mesh,
        truth,
    });
    if let Some(only) = &o.only {
        out.retain(|c| c.name.contains(only.as_str()));
    }
    out
}

/// Scores of one mesh: per method, AUC (all edges; without the edges of faces narrower than
/// the noise, `meshfeat::sliver_edges`) and the labels at the default operating point.
struct Row {
    auc: [f64; NM],
    auc_kept: [f64; NM],
    conf: [Confusion; NM],
}

const NM: usize = 7;
const METHODS: [&str; NM] = [
    "thres.", "hys.", "tangent", "dih+G", "tan+G", "filtered", "filt+G",
];

/// The entries of `v` where `keep` is true.
fn kept<T: Clone>(v: &[T], keep: &[bool]) -> Vec<T> {
    v.iter()
        .zip(keep)
        .filter(|(_, &k)| k)
        .map(|(x, _)| x.clone())
        .collect()
}

fn score(o: &Opts, mesh: &TriMesh, truth: &[bool], keep: &[bool], times: &mut [f64; 2]) -> Row {
    let em = EdgeMesh::new(mesh).expect("topology");
    let d = EdgeParams::default();
    let t0 = Instant::now();
    let ta = tangent_angles(
        &em,
        &TangentParams {
            scales: o.scales.clone(),
            mean_init: o.mean_init,
            iterations: o.iterations,
            ..TangentParams::default()
        },
    )
    .expect("tangent");
    let tan = mean_tangent_angle(&ta);
    let filt = filtered_dihedral(&em, d.filter_iterations, &d.bilateral, &d.tv, &d.line);
    let tf = d.filtered_degrees.to_radians();
    let hys = hysteresis_scores(&em, &em.dihedral, d.low_ratio).expect("hysteresis");
    let t = d.threshold_degrees.to_radians();
    let auc_of = |s: &[f64]| roc(s, truth).map(|r| r.auc).unwrap_or(f64::NAN);
    let truth_kept = kept(truth, keep);
    let kept_auc_of = |s: &[f64]| {
        roc(&kept(s, keep), &truth_kept)
            .map(|r| r.auc)
            .unwrap_or(f64::NAN)
    };
    let conf = |l: &[bool]| Confusion::from_labels(l, truth).expect("lengths");
    if o.best {
        for (name, sc) in [
            ("dihedral", &em.dihedral),
            ("tangent", &tan),
            ("filtered", &filt),
        ] {
            let mut best = (0.0, 0.0);
            for deg in 1..90 {
                let f = conf(&threshold(sc, (deg as f64).to_radians())).metrics().f1;
                if f > best.0 {
                    best = (f, deg as f64);
                }
            }
            eprint!(" [{name} best F1 {:.3} at {} deg]", best.0, best.1);
        }
    }
    times[0] += t0.elapsed().as_secs_f64();
    let pairs = EdgePairs::new(&em);
    let t1 = Instant::now();
    let sweep = |angles: &[f64], theta: f64| -> (f64, f64, Confusion) {
        let labellings: Vec<Vec<bool>> = (0..o.samples)
            .map(|i| {
                let p = PottsParams {
                    theta_true: std::f64::consts::PI * i as f64 / (o.samples - 1).max(1) as f64,
                    ..o.potts
                };
                potts_labels(&em, &pairs, angles, &p).expect("cut")
            })
            .collect();
        let auc = sweep_auc(&labellings, truth)
            .map(|r| r.0)
            .unwrap_or(f64::NAN);
        let labellings_kept: Vec<Vec<bool>> = labellings.iter().map(|l| kept(l, keep)).collect();
        let auc_kept = sweep_auc(&labellings_kept, &truth_kept)
            .map(|r| r.0)
            .unwrap_or(f64::NAN);
        let p = PottsParams {
            theta_true: theta,
            ..o.potts
        };
        let l = potts_labels(&em, &pairs, angles, &p).expect("cut");
        (auc, auc_kept, conf(&l))
    };
    let (auc_dg, kept_dg, c_dg) = sweep(&em.dihedral, o.potts.theta_true);
    let (auc_tg, kept_tg, c_tg) = sweep(&tan, o.potts.theta_true);
    let (auc_fg, kept_fg, c_fg) = sweep(&filt, tf);
    times[1] += t1.elapsed().as_secs_f64();
    Row {
        auc: [
            auc_of(&em.dihedral),
            auc_of(&hys),
            auc_of(&tan),
            auc_dg,
            auc_tg,
            auc_of(&filt),
            auc_fg,
        ],
        auc_kept: [
            kept_auc_of(&em.dihedral),
            kept_auc_of(&hys),
            kept_auc_of(&tan),
            kept_dg,
            kept_tg,
            kept_auc_of(&filt),
            kept_fg,
        ],
        conf: [
            conf(&threshold(&em.dihedral, t)),
            conf(&threshold(&hys, t)),
            conf(&threshold(&tan, t)),
            c_dg,
            c_tg,
            conf(&threshold(&filt, tf)),
            c_fg,
        ],
    }
}

fn main() {
    let o = parse();
    println!(
        "Potts: mu {} beta {} lambda {} sigma {} theta_true {:.1} deg; tangent scales {:?}",
        o.potts.mu,
        o.potts.beta,
        o.potts.lambda,
        o.potts.sigma,
        o.potts.theta_true.to_degrees(),
        o.scales
    );
    let cs = cases(&o);
    let mut times = [0.0; 2];
    for noisy in [false, true] {
        println!(
            "\n{} models: AUC % (F1 / false-positive rate x1e-4 at the default operating point)",
            if noisy {
                format!("b) noisy ({} % GN)", 100.0 * o.noise)
            } else {
                "a) clean".to_string()
            }
        );
        print!("{:<26}{:>8}{:>6}", "mesh", "#edges", "#f.e.");
        for m in METHODS {
            print!("{m:>22}");
        }
        println!();
        let mut sum = [0.0; NM];
        let mut sum_kept = [0.0; NM];
        let mut slivers = Vec::new();
        let mut n = 0;
        let mut tot = [Confusion::default(); NM];
        for c in &cs {
            let mesh = if noisy {
                add_noise(&c.mesh, o.noise, 7).expect("noise")
            } else {
                c.mesh.clone()
            };
            let pos = c.truth.iter().filter(|&&t| t).count();
            print!("{:<26}{:>8}{:>6}", c.name, c.truth.len(), pos);
            // Edges of faces narrower than the noise (in the clean mesh) are also left out, in
            // a second mean: their labels are the clean normal of a sliver (block.off).
            let keep: Vec<bool> = if noisy {
                let em = EdgeMesh::new(&c.mesh).expect("topology");
                let width = o.noise
                    * crease::geometry::Aabb::from_points(c.mesh.positions())
                        .map_or(0.0, |b| b.max_side());
                sliver_edges(&em, width).iter().map(|&s| !s).collect()
            } else {
                vec![true; c.truth.len()]
            };
            let left_out = keep.iter().filter(|&&k| !k).count();
            if left_out > 0 {
                slivers.push(format!("{} {left_out}", c.name));
            }
            let r = score(&o, &mesh, &c.truth, &keep, &mut times);
            for k in 0..NM {
                let m = r.conf[k].metrics();
                if o.compact {
                    print!("{:>8.2} {:.2}", 100.0 * r.auc[k], m.f1);
                } else {
                    print!(
                        "{:>8.2} ({:.2}/{:>5.0})",
                        100.0 * r.auc[k],
                        m.f1,
                        1e4 * (1.0 - m.specificity)
                    );
                }
                tot[k] = tot[k].merged(&r.conf[k]);
            }
            println!();
            if pos > 0 {
                for k in 0..NM {
                    sum[k] += r.auc[k];
                    sum_kept[k] += r.auc_kept[k];
                }
                n += 1;
            }
        }
        print!("{:<40}", "mean AUC / pooled F1");
        for k in 0..NM {
            let m = tot[k].metrics();
            print!(
                "{:>8.2} ({:.2}/{:>5.0})",
                100.0 * sum[k] / n as f64,
                m.f1,
                1e4 * (1.0 - m.specificity)
            );
        }
        println!();
        if !slivers.is_empty() {
            print!("{:<40}", "mean AUC, sliver edges not scored");
            for k in 0..NM {
                print!("{:>8.2}{:>14}", 100.0 * sum_kept[k] / n as f64, "");
            }
            println!(
                "\n  (edges of faces narrower than the noise: {})",
                slivers.join(", ")
            );
        }
    }
    println!(
        "\ntime: tangent-plane angles {:.1} s, Potts sweeps {:.1} s",
        times[0], times[1]
    );
}
