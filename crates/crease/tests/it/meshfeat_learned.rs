//! The learned edge classifier (vidal et al. 2011, sections 4, 5 and 6.3): the feature vector,
//! the SVM solver and model file, and the learned methods measured against ground truth.

use crate::common;

use crease::eval::roc::roc;
use crease::eval::Confusion;
use crease::geometry::TriMesh;
use crease::meshfeat::features::{CURVATURE_OFFSET, TANGENT_OFFSET};
use crease::meshfeat::svm::{train, TrainingSet};
use crease::meshfeat::{
    add_noise, classic_label_degrees, default_model, detect_prepared, dihedral_labels,
    edge_features, labels_from_pairs, mean_tangent_angle, tangent_angles, EdgeFeatures, EdgeMesh,
    EdgeMethod, EdgeParams, FeatureParams, SvmModel, TrainParams, NUM_FEATURES,
};
use crease::synth::{mesh as synth_mesh, MeshParams, Shape};

fn synth(name: &str, per_side: f64) -> (TriMesh, Vec<[u32; 2]>) {
    let shape = Shape::from_name(name).expect("shape");
    let m = synth_mesh(
        &shape,
        &MeshParams {
            target_edge: Some(shape.aabb().max_side() / per_side),
            ..Default::default()
        },
    )
    .expect("mesh");
    (m.mesh, m.sharp_edges)
}

#[test]
fn features_are_the_43_of_section_4_with_analytic_values() {
    // Clean cube: cos of the dihedral angle is 0 on the 12 edges, 1 elsewhere; so is the
    // tangent-plane cosine at every scale with the paper's seeds.
    let (mesh, sharp) = synth("cube", 20.0);
    let em = EdgeMesh::new(&mesh).unwrap();
    let (truth, _) = labels_from_pairs(&em.topo, &sharp);
    let mut p = FeatureParams::default();
    p.tangent.mean_init = false;
    let f = edge_features(&em, &p).unwrap();
    assert_eq!(f.dim, NUM_FEATURES);
    assert_eq!(f.len(), em.num_edges());
    for (e, &t) in truth.iter().enumerate() {
        let want = if t { 0.0 } else { 1.0 };
        let r = f.row(e);
        assert!(
            (r[0] - want).abs() < 1e-5,
            "edge {e}: cos dihedral {}",
            r[0]
        );
        for s in 0..9 {
            assert!(
                (r[TANGENT_OFFSET + s] - want).abs() < 1e-4,
                "edge {e} scale {s}: {}",
                r[TANGENT_OFFSET + s]
            );
        }
    }
    // Sphere of radius 0.5: both principal curvatures are 1 / 0.5 = 2, K = 4, H = 2, K_max −
    // K_min = 0 (normal cycle, Cohen-Steiner & Morvan); the features hold them times the ball
    // radius r (K times r²). Means over the edges, exact balls (every edge), and with the
    // default budget, where the larger balls read a random subset of the edges: that spreads
    // K_min and K_max apart but leaves H (measured, exact: H 1.95–2.06, K_min 1.94–2.00,
    // K_max 1.97–2.12; budget 64: H 1.96–2.06, K_max − K_min up to 0.73).
    let (mesh, _) = synth("sphere", 40.0);
    let em = EdgeMesh::new(&mesh).unwrap();
    for budget in [None, FeatureParams::default().max_items] {
        let p = FeatureParams {
            max_items: budget,
            ..FeatureParams::default()
        };
        let f = edge_features(&em, &p).unwrap();
        for (s, &scale) in p.curvature_scales.iter().enumerate() {
            let r = (scale * em.reference_length).max(p.min_edge_lengths * em.mean_edge_length);
            let base = CURVATURE_OFFSET + 6 * s;
            let mean = |k: usize| {
                let pow = if k == 2 { 2 } else { 1 };
                (0..f.len())
                    .map(|e| f64::from(f.row(e)[base + k]))
                    .sum::<f64>()
                    / f.len() as f64
                    / r.powi(pow)
            };
            let (kmin, kmax, gauss, h, diff) = (mean(0), mean(1), mean(2), mean(3), mean(4));
            eprintln!(
                "budget {budget:?} scale {s}: {kmin:.3} {kmax:.3} {gauss:.3} {h:.3} {diff:.3}"
            );
            assert!((h - 2.0).abs() < 0.1, "scale {s}: H {h}");
            if budget.is_none() {
                assert!((kmin - 2.0).abs() < 0.15, "scale {s}: kmin {kmin}");
                assert!((kmax - 2.0).abs() < 0.15, "scale {s}: kmax {kmax}");
                assert!((gauss - 4.0).abs() < 0.3, "scale {s}: K {gauss}");
                assert!(diff < 0.3, "scale {s}: kmax - kmin {diff}");
            }
            // Constant curvature: (almost) no saliency.
            assert!(mean(5) * r < 0.05, "scale {s}: saliency {}", mean(5) * r);
        }
    }
}

#[test]
fn features_do_not_depend_on_the_thread_count() {
    let (mesh, _) = synth("fillet-chamfer-cone", 25.0);
    let noisy = add_noise(&mesh, 0.005, 5).unwrap();
    let em = EdgeMesh::new(&noisy).unwrap();
    let p = FeatureParams {
        max_items: Some(32),
        ..FeatureParams::default()
    };
    let run = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(|| edge_features(&em, &p).unwrap())
    };
    assert_eq!(run(1), run(2));
}

/// Two noisy blobs in 43 dimensions, 1 positive in 10.
fn blobs(n: usize, seed: u64) -> (EdgeFeatures, Vec<bool>) {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut values = Vec::new();
    let mut y = Vec::new();
    for i in 0..n {
        let pos = i % 10 == 0;
        for k in 0..NUM_FEATURES {
            let c = if pos && k < 3 { 0.6 } else { 0.0 };
            values.push(c + rng.random_range(-0.5f32..0.5));
        }
        y.push(pos);
    }
    (
        EdgeFeatures {
            dim: NUM_FEATURES,
            values,
        },
        y,
    )
}

#[test]
fn svm_separates_blobs_and_its_model_file_round_trips() {
    let (f, y) = blobs(600, 1);
    let mut set = TrainingSet::default();
    set.add_mesh("blobs", &f, &y, 600, 0).unwrap();
    let (model, grid) = train(
        &set,
        &FeatureParams::default(),
        &TrainParams {
            c_grid: vec![1.0, 10.0],
            gamma_grid: vec![0.03, 0.3],
            ..TrainParams::default()
        },
    )
    .unwrap();
    assert_eq!(grid.len(), 4);
    assert!(model.cv_auc > 0.95, "cross-validation AUC {}", model.cv_auc);
    // Held-out blobs.
    let (g, t) = blobs(2000, 2);
    let d = model.decision_values(&g).unwrap();
    let auc = roc(&d, &t).unwrap().auc;
    assert!(auc > 0.95, "held-out AUC {auc}");
    let acc = d.iter().zip(&t).filter(|(&s, &t)| (s > 0.0) == t).count() as f64 / t.len() as f64;
    assert!(acc > 0.9, "held-out accuracy {acc}");
    // The file round-trips to the same decision values.
    let dir = common::tempdir();
    let path = dir.path().join("m.json");
    model.write(&path).unwrap();
    let back = SvmModel::read(&path).unwrap();
    assert_eq!(back.decision_values(&g).unwrap(), d);
    // Bad files: a clear error naming the file.
    std::fs::write(&path, "{\"format\": \"x\"}").unwrap();
    let e = SvmModel::read(&path).unwrap_err().to_string();
    assert!(e.contains("m.json"), "{e}");
    // A version-1 file (before the tangent-plane features recorded their noise-adapted
    // acceptance angle) reads as the paper's fixed 23 degrees; a newer version is refused.
    let v1 = model
        .to_json()
        .replacen(
            &format!("\"version\":{}", model.version),
            "\"version\":1",
            1,
        )
        .replace(",\"tangent_noise_accept\":1.5", "")
        .replace(",\"tangent_noise_accept\":null", "");
    assert!(!v1.contains("tangent_noise_accept"), "{}", &v1[..300]);
    let old = SvmModel::from_json(&v1).unwrap();
    assert_eq!(old.version, 1);
    assert_eq!(old.features.params().tangent.noise_accept, None);
    let newer = model.to_json().replacen(
        &format!("\"version\":{}", model.version),
        "\"version\":99",
        1,
    );
    assert!(SvmModel::from_json(&newer).is_err());
    let mut wrong = model.clone();
    wrong.coef.push(1.0);
    assert!(SvmModel::from_json(&wrong.to_json()).is_err());
    // Wrong feature dimension.
    let bad = EdgeFeatures {
        dim: 3,
        values: vec![0.0; 9],
    };
    assert!(model.decision_values(&bad).is_err());
}

/// The shipped model (trained on synthetic parts only) against the tangent-plane angle on
/// noisy fandisk (section 6.1 protocol: clean dihedral above fandisk's 17.5° of
/// `CLASSIC_LABELS`, 0.5 % noise): measured with `examples/meshfeat_learned.rs`, AUC 93.81 %
/// against 93.89 % (with the old 25° labels, which left out 56 edges of the shallow creases:
/// 95.0 % against 94.75 %). The two rank fandisk's edges alike; the learned model is ahead on
/// the mean of the noisy meshes (95.07 % against 93.48 %).
#[test]
fn learned_matches_the_tangent_angle_on_noisy_fandisk() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    let (g, _) = crease::io::read(dir.join("meshes/fandisk.off"), &Default::default()).unwrap();
    let mesh = g.into_mesh().unwrap();
    let degrees = classic_label_degrees("fandisk.off").unwrap();
    let truth = dihedral_labels(&EdgeMesh::new(&mesh).unwrap(), degrees);
    let noisy = add_noise(&mesh, 0.005, 7).unwrap();
    let em = EdgeMesh::new(&noisy).unwrap();
    let tan = mean_tangent_angle(&tangent_angles(&em, &EdgeParams::default().tangent).unwrap());
    let auc_tangent = roc(&tan, &truth).unwrap().auc;
    let learned = detect_prepared(
        &em,
        &EdgeParams {
            method: EdgeMethod::Learned,
            ..EdgeParams::default()
        },
    )
    .unwrap();
    let auc_learned = roc(&learned.sharpness, &truth).unwrap().auc;
    assert!(
        auc_learned > auc_tangent - 0.005 && auc_learned > 0.93 && auc_tangent > 0.93,
        "learned {auc_learned} tangent {auc_tangent}"
    );
    // The graph cut with the SVM data term (eq. 2): a labelling at least as good as the
    // plain decision d > 0 (F1 against the truth).
    let potts = detect_prepared(
        &em,
        &EdgeParams {
            method: EdgeMethod::PottsLearned,
            ..EdgeParams::default()
        },
    )
    .unwrap();
    let f1 = |l: &[bool]| Confusion::from_labels(l, &truth).unwrap().metrics().f1;
    let (fl, fp) = (f1(&learned.sharp), f1(&potts.sharp));
    eprintln!("F1 learned {fl:.3} potts-learned {fp:.3}; AUC {auc_learned:.4} vs {auc_tangent:.4}");
    assert!(fl > 0.6, "F1 learned {fl}");
    assert!(fp >= fl - 0.02, "F1 potts-learned {fp} learned {fl}");
    // The shipped model is the synthetic-parts one.
    assert!(default_model().description.contains("synthetic"));
}
