//! Trains the default edge classifier shipped with crease (`src/meshfeat/default_model.json`)
//! on the synthetic parts only, so that no classic mesh of `../shared/data` is ever its
//! training data (vidal et al. 2011, section 6.3: RBF SVM, class weight 9, grid search with
//! cross-validation maximising the AUC).
//!
//! ```text
//! cargo run --release -p crease --example train_default [-- --out FILE] [--max-edges N]
//!     [--per-side 40,70] [--noise 0,0.005] [--folds K] [--tangent-budget N]
//!     [--curvature-budget N]
//! ```
//!
//! Prints the grid, the per-feature F-scores (the paper's Table 1 measure) and the model size.

use std::path::PathBuf;
use std::time::Instant;

use crease::meshfeat::features::feature_names;
use crease::meshfeat::svm::train;
use crease::meshfeat::train::f_scores;
use crease::meshfeat::{training_set, FeatureParams, LabelledMesh, SetParams, TrainParams};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut out = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("src/meshfeat/default_model.json");
    let mut sp = SetParams::default();
    let mut per_side = vec![40.0, 70.0];
    let mut tp = TrainParams::default();
    let mut fp = FeatureParams::default();
    let mut i = 0;
    while i + 1 < args.len() {
        let v = &args[i + 1];
        match args[i].as_str() {
            "--out" => out = PathBuf::from(v),
            "--max-edges" => sp.max_edges_per_mesh = v.parse().expect("count"),
            "--per-side" => per_side = v.split(',').map(|s| s.parse().expect("number")).collect(),
            "--folds" => tp.folds = v.parse().expect("count"),
            "--tangent-budget" => fp.tangent.max_faces = Some(v.parse().expect("count")),
            "--curvature-budget" => fp.max_items = Some(v.parse().expect("count")),
            "--noise" => sp.noise = v.split(',').map(|s| s.parse().expect("number")).collect(),
            a => panic!("unknown option {a}"),
        }
        i += 2;
    }
    let t0 = Instant::now();
    let meshes: Vec<LabelledMesh> = crease::synth::training_meshes(&per_side)
        .expect("synthetic meshes")
        .into_iter()
        .map(|(name, m)| LabelledMesh::from_pairs(name, m.mesh, &m.sharp_edges).expect("labels"))
        .collect();
    let set = training_set(&meshes, &fp, &sp).expect("training set");
    let npos = set.y.iter().filter(|&&t| t).count();
    println!(
        "training set: {} meshes x {:?} noise, {} edges ({} feature), {:.1} s",
        meshes.len(),
        sp.noise,
        set.len(),
        npos,
        t0.elapsed().as_secs_f64()
    );
    let names = feature_names(&fp.tangent.scales, &fp.curvature_scales);
    let fs = f_scores(&set);
    for (n, f) in names.iter().zip(&fs) {
        println!("  F-score {n:<28}{f:>10.4}");
    }
    tp.description = format!(
        "crease default: synthetic parts {:?} edges per side, noise {:?}, <= {} edges per mesh",
        per_side, sp.noise, sp.max_edges_per_mesh
    );
    let t1 = Instant::now();
    let (model, grid) = train(&set, &fp, &tp).expect("training");
    for (c, g, auc) in &grid {
        println!("  C {c:>6} gamma {g:>6}: CV AUC {:.3} %", 100.0 * auc);
    }
    println!(
        "chosen C {} gamma {}: CV AUC {:.3} %, {} support vectors, {:.1} s",
        model.c,
        model.gamma,
        100.0 * model.cv_auc,
        model.num_support(),
        t1.elapsed().as_secs_f64()
    );
    model.write(&out).expect("write model");
    println!(
        "wrote {} ({} bytes)",
        out.display(),
        std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0)
    );
}
