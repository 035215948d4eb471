//! Mesh feature edges from filtered face normals (`filtered`, crease's addition to vidal et al.
//! 2011: the mean of the bilateral and the total-variation angle, `meshfeat::bilateral`,
//! `meshfeat::tv`), measured against the section 6.1 protocol on the
//! classic meshes and against exact labels on synthetic parts.

use crate::common;

use crease::eval::roc::roc;
use crease::eval::Confusion;
use crease::geometry::TriMesh;
use crease::meshfeat::{
    add_noise, classic_label_degrees, detect_prepared, dihedral_labels, filtered_dihedral,
    intersection_scores, labels_from_pairs, mean_tangent_angle, sliver_edges, tangent_angles,
    BilateralParams, EdgeMesh, EdgeMethod, EdgeParams, LineParams, TvParams, FILTER_ITERATIONS,
};
use crease::synth::{mesh as synth_mesh, MeshParams, Shape};

fn auc(score: &[f64], truth: &[bool]) -> f64 {
    roc(score, truth).unwrap().auc
}

/// A classic mesh of `../shared/data/meshes` and its section 6.1 labels (`CLASSIC_LABELS`).
fn classic(dir: &std::path::Path, file: &str) -> (TriMesh, Vec<bool>) {
    let (g, _) = crease::io::read(dir.join("meshes").join(file), &Default::default()).unwrap();
    let mesh = g.into_mesh().unwrap();
    let truth = dihedral_labels(
        &EdgeMesh::new(&mesh).unwrap(),
        classic_label_degrees(file).unwrap(),
    );
    (mesh, truth)
}

/// The filtered dihedral angle with the default parameters.
fn filtered(em: &EdgeMesh) -> Vec<f64> {
    filtered_dihedral(
        em,
        FILTER_ITERATIONS,
        &BilateralParams::default(),
        &TvParams::default(),
        &LineParams::default(),
    )
}

fn with(method: EdgeMethod) -> EdgeParams {
    EdgeParams {
        method,
        ..EdgeParams::default()
    }
}

/// Per-edge AUC on the classic meshes, clean and with the section 6.1 noise (0.5 % of the
/// bounding box's largest side, seed 7, as `examples/meshfeat_table2.rs`). Measured, noisy:
/// fandisk 98.8 %, cup 97.1, cylinder 99.8, bar 99.6, sharp_sphere 98.0 (tangent-plane angle
/// 93.9, 92.1, 97.7, 86.3, 86.9; dihedral 81.8, 86.6, 67.2, 75.9, 83.7); clean: all 100 %
/// (block: 99.98 %, its sliver chamfer faces kept by the raw-angle rule).
#[test]
fn filtered_dihedral_beats_the_paper_estimators_on_noisy_classic_meshes() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    for (file, noisy_min) in [
        ("fandisk.off", 0.98),
        ("cup.off", 0.965),
        ("cylinder.off", 0.995),
        ("bar.off", 0.99),
        ("sharp_sphere.off", 0.975),
        ("block.off", 0.0),
    ] {
        let (mesh, truth) = classic(&dir, file);
        let em = EdgeMesh::new(&mesh).unwrap();
        let clean = auc(&filtered(&em), &truth);
        assert!(clean > 0.999, "{file} clean: AUC {clean}");
        if noisy_min == 0.0 {
            continue;
        }
        let noisy = add_noise(&mesh, 0.005, 7).unwrap();
        let em = EdgeMesh::new(&noisy).unwrap();
        let f = auc(&filtered(&em), &truth);
        let tan = mean_tangent_angle(&tangent_angles(&em, &EdgeParams::default().tangent).unwrap());
        let (t, d) = (auc(&tan, &truth), auc(&em.dihedral, &truth));
        eprintln!("{file}: noisy AUC filtered {f:.4} tangent {t:.4} dihedral {d:.4}");
        assert!(f > noisy_min, "{file}: filtered AUC {f}");
        assert!(f > t + 0.012 && f > d + 0.08, "{file}: {f} vs {t} / {d}");
    }
}

/// At noise of 0.2 % of the largest side, where our dihedral thresholding scores what the
/// paper's Table 2 reports for its noisy models (mean 97.2 % over the 11 meshes against the
/// paper's 97.3 %), the filtered angle is above 99 % AUC on the classic meshes without
/// slivers. Measured: fandisk 99.94 %, cup 99.69, cylinder 100.00, bar 99.91 (dihedral
/// thresholding 96.58, 98.78, 98.54, 92.03); block 99.79 % with the edges of its faces narrower than the noise left out (`meshfeat::sliver_edges`:
/// their labels are the clean normal of a sliver a fraction of the noise wide).
#[test]
fn filtered_dihedral_is_above_99_percent_at_the_papers_noise() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    for (file, min) in [
        ("fandisk.off", 0.995),
        ("cup.off", 0.99),
        ("cylinder.off", 0.999),
        ("bar.off", 0.995),
        ("block.off", 0.99),
    ] {
        let (mesh, truth) = classic(&dir, file);
        let clean = EdgeMesh::new(&mesh).unwrap();
        let side = crease::geometry::Aabb::from_points(mesh.positions())
            .unwrap()
            .max_side();
        let keep: Vec<bool> = sliver_edges(&clean, 0.002 * side)
            .iter()
            .map(|&s| !s)
            .collect();
        let pick = |v: &[f64]| -> Vec<f64> {
            v.iter()
                .zip(&keep)
                .filter(|(_, &k)| k)
                .map(|(&x, _)| x)
                .collect()
        };
        let kept_truth: Vec<bool> = truth
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(&t, _)| t)
            .collect();
        let noisy = add_noise(&mesh, 0.002, 7).unwrap();
        let em = EdgeMesh::new(&noisy).unwrap();
        let f = auc(&pick(&filtered(&em)), &kept_truth);
        let d = auc(&pick(&em.dihedral), &kept_truth);
        let left_out = keep.iter().filter(|&&k| !k).count();
        eprintln!("{file}: AUC at 0.2 % noise filtered {f:.4} dihedral {d:.4} ({left_out} sliver edges not scored)");
        assert!(f > min && f > d, "{file}: filtered {f}, dihedral {d}");
        if file != "block.off" {
            assert!(left_out < 10, "{file}: {left_out} sliver edges");
        }
    }
}

/// Exact labels of a noisy synthetic part: F1 at the default operating point (25°) above the
/// tangent-plane angle's (measured 0.75 against 0.45), the same labels whatever the
/// thread count, and few false edges on a noisy flat grid (CGAL issue 9306; measured: 5 and
/// 8 of the grid's 10.6k interior edges at 0.3 % and 0.5 % noise, where the tangent-plane
/// angle marks 1 and 88, dihedral thresholding 181 and 1854: a face whose noisy normal is far
/// from all its neighbours' keeps it through the filtering).
#[test]
fn filtered_labels_a_noisy_part_and_keeps_a_noisy_grid_clean() {
    let shape = Shape::from_name("fillet-chamfer-cone").unwrap();
    let m = synth_mesh(
        &shape,
        &MeshParams {
            target_edge: Some(shape.aabb().max_side() / 60.0),
            ..Default::default()
        },
    )
    .unwrap();
    let noisy = add_noise(&m.mesh, 0.005, 11).unwrap();
    let em = EdgeMesh::new(&noisy).unwrap();
    let (truth, _) = labels_from_pairs(&em.topo, &m.sharp_edges);
    let f1 = |l: &[bool]| Confusion::from_labels(l, &truth).unwrap().metrics().f1;
    let run = |threads: usize, method: EdgeMethod| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| detect_prepared(&em, &with(method)).unwrap())
    };
    let one = run(1, EdgeMethod::Filtered);
    let three = run(3, EdgeMethod::Filtered);
    assert!(one.sharp == three.sharp && one.sharpness == three.sharpness);
    let tan = run(2, EdgeMethod::Tangent);
    let (ff, ft) = (f1(&one.sharp), f1(&tan.sharp));
    eprintln!("F1 filtered {ff:.3} tangent {ft:.3}");
    assert!(
        ff > 0.52 && ff > ft + 0.06,
        "F1 filtered {ff}, tangent {ft}"
    );
    let pf = run(2, EdgeMethod::PottsFiltered);
    assert!(f1(&pf.sharp) > 0.52, "potts-filtered F1 {}", f1(&pf.sharp));

    let plane = Shape::from_name("plane").unwrap();
    let g = synth_mesh(
        &plane,
        &MeshParams {
            target_edge: Some(plane.aabb().max_side() / 60.0),
            ..Default::default()
        },
    )
    .unwrap();
    for (noise, most) in [(0.003, 40), (0.005, 40)] {
        let noisy = add_noise(&g.mesh, noise, 5).unwrap();
        let em = EdgeMesh::new(&noisy).unwrap();
        let count = |m: EdgeMethod| {
            let d = detect_prepared(&em, &with(m)).unwrap();
            d.sharp
                .iter()
                .enumerate()
                .filter(|&(e, &s)| s && !em.topo.is_boundary_edge(e))
                .count()
        };
        let false_edges = count(EdgeMethod::Filtered);
        let tn = count(EdgeMethod::Tangent);
        let dh = count(EdgeMethod::Dihedral);
        eprintln!("noise {noise}: interior false edges filtered {false_edges}, tangent {tn}, dihedral {dh}");
        assert!(false_edges <= most, "noise {noise}: {false_edges}");
        assert!(
            false_edges * 5 < dh,
            "noise {noise}: {false_edges} vs dihedral {dh}"
        );
    }
}

/// `fused` (the default) at the paper's noise (0.2 % of the largest side) on the classic
/// meshes: above both of its parts on the mean, and above 99 % AUC on the meshes without
/// slivers. Measured (shipped model): fandisk 99.93 %, cup 99.79, bar 99.90, block 98.20,
/// sharp_sphere 99.33; filtered 99.94, 99.67, 99.91, 97.52, 98.87; learned 96.57, 93.06,
/// 99.20, 95.13, 97.64.
#[test]
fn fused_beats_filtered_and_learned_at_the_papers_noise() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    let mut sums = [0.0; 3];
    for (file, min) in [
        ("fandisk.off", 0.995),
        ("cup.off", 0.99),
        ("bar.off", 0.995),
        ("block.off", 0.97),
        ("sharp_sphere.off", 0.985),
    ] {
        let (mesh, truth) = classic(&dir, file);
        let noisy = add_noise(&mesh, 0.002, 7).unwrap();
        let em = EdgeMesh::new(&noisy).unwrap();
        let fused = detect_prepared(&em, &with(EdgeMethod::Fused)).unwrap();
        let filtered = detect_prepared(&em, &with(EdgeMethod::Filtered)).unwrap();
        let learned = detect_prepared(&em, &with(EdgeMethod::Learned)).unwrap();
        let a = [
            auc(&fused.sharpness, &truth),
            auc(&filtered.sharpness, &truth),
            auc(&learned.sharpness, &truth),
        ];
        eprintln!(
            "{file}: AUC at 0.2 % noise fused {:.4} filtered {:.4} learned {:.4}",
            a[0], a[1], a[2]
        );
        assert!(a[0] > min, "{file}: fused AUC {}", a[0]);
        for k in 0..3 {
            sums[k] += a[k];
        }
    }
    assert!(
        sums[0] > sums[1] + 0.005 && sums[0] > sums[2] + 0.1,
        "sums of AUC: fused {} filtered {} learned {}",
        sums[0],
        sums[1],
        sums[2]
    );
}

/// At the 0.5 % noise of our protocol (0.3 to 0.5 edge lengths), total-variation normal
/// filtering (`meshfeat::tv`) keeps the creases of fine meshes one edge wide where bilateral
/// filtering alone spreads them over the neighbouring edges: the filtered angle with its
/// total-variation half scores above the bilateral angle alone, and `fused` above 98 % AUC.
/// Measured (both smoothed along the lines): fandisk bilateral 97.01 % → filtered 98.77 %,
/// fused 98.54 %; ABC 93.99 % → 99.04 %, fused 98.75 %.
#[test]
fn total_variation_keeps_noisy_creases_one_edge_wide() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    let (abc_mesh, pairs) = common::abc_model(&dir);
    let (abc_truth, missing) = labels_from_pairs(&EdgeMesh::new(&abc_mesh).unwrap().topo, &pairs);
    assert_eq!(missing, 0);
    let bilateral_only = TvParams {
        weight: 0.0,
        ..TvParams::default()
    };
    let (fandisk, fandisk_truth) = classic(&dir, "fandisk.off");
    for (name, mesh, truth, gain, fused_min) in [
        ("fandisk", fandisk, fandisk_truth, 0.01, 0.98),
        ("ABC 00000006", abc_mesh, abc_truth, 0.04, 0.985),
    ] {
        let noisy = add_noise(&mesh, 0.005, 7).unwrap();
        let em = EdgeMesh::new(&noisy).unwrap();
        let before = auc(
            &filtered_dihedral(
                &em,
                FILTER_ITERATIONS,
                &BilateralParams::default(),
                &bilateral_only,
                &LineParams::default(),
            ),
            &truth,
        );
        let after = auc(&filtered(&em), &truth);
        let fused = auc(
            &detect_prepared(&em, &with(EdgeMethod::Fused))
                .unwrap()
                .sharpness,
            &truth,
        );
        eprintln!("{name} at 0.5 % noise: AUC bilateral {before:.4}, filtered {after:.4}, fused {fused:.4}");
        assert!(after > before + gain, "{name}: {after} vs {before}");
        assert!(fused > fused_min, "{name}: fused {fused}");
    }
}

/// Every method gives the same labels and the same sharpness whatever the mesh's units: a
/// noisy part scaled by 1000 and by 1/1000 (millimetres to micrometres or metres). The total
/// variation's data term depended on the units until it was divided by the mean face area.
/// Measured: `fused` 0 labels differ, sharpness within 3e-6 (the segmentation's fits); every
/// other method within 1e-6.
#[test]
fn every_method_is_independent_of_the_mesh_units() {
    let shape = Shape::from_name("fillet-chamfer-cone").unwrap();
    let m = synth_mesh(
        &shape,
        &MeshParams {
            target_edge: Some(shape.aabb().max_side() / 30.0),
            ..Default::default()
        },
    )
    .unwrap();
    let noisy = add_noise(&m.mesh, 0.005, 5).unwrap();
    let scaled = |k: f64| {
        let p: Vec<[f64; 3]> = noisy
            .positions()
            .iter()
            .map(|q| [q[0] * k, q[1] * k, q[2] * k])
            .collect();
        TriMesh::new(p, noisy.faces.clone()).unwrap()
    };
    let em = EdgeMesh::new(&noisy).unwrap();
    for method in EdgeMethod::ALL {
        let reference = detect_prepared(&em, &with(method)).unwrap();
        assert!(reference.sharp.iter().any(|&s| s), "{}", method.name());
        for k in [1e3, 1e-3] {
            let mesh = scaled(k);
            let other = detect_prepared(&EdgeMesh::new(&mesh).unwrap(), &with(method)).unwrap();
            let differ = reference
                .sharp
                .iter()
                .zip(&other.sharp)
                .filter(|(a, b)| a != b)
                .count();
            let worst = reference
                .sharpness
                .iter()
                .zip(&other.sharpness)
                .map(|(a, b)| (a - b).abs() / a.abs().max(1.0))
                .fold(0.0, f64::max);
            // `fused` reads the surfaces of the segmentation, whose iterative fits stop at a
            // relative step of about 1e-7: their round-off moves its score by a few 1e-6.
            let tol = if method == EdgeMethod::Fused {
                1e-5
            } else {
                1e-6
            };
            assert!(
                differ == 0 && worst < tol,
                "{} at scale {k}: {differ} labels differ, sharpness off by {worst:e}",
                method.name()
            );
        }
    }
}

/// The surface-intersection term of `fused` (`meshfeat::surfaces`) at the 0.5 % noise of our
/// protocol: on cup.off, whose shallow creases and coarse toroidal facets local estimators
/// cannot tell apart, the fitted surfaces' intersections rank the edges better than anything
/// local and lift `fused`; on fandisk it costs nothing. Measured (seed 7): cup intersections
/// alone 99.22 %, fused 97.16 % → 98.71 %; fandisk alone 83.74 %, fused 98.42 % → 98.54 %.
#[test]
fn surface_intersections_lift_fused_on_the_coarse_cup() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    for (file, alone_min, gain) in [("cup.off", 0.98, 0.01), ("fandisk.off", 0.8, 0.0)] {
        let (mesh, truth) = classic(&dir, file);
        let noisy = add_noise(&mesh, 0.005, 7).unwrap();
        let em = EdgeMesh::new(&noisy).unwrap();
        let params = EdgeParams::default();
        let alone = auc(
            &intersection_scores(&em, &params.intersection, params.filtered_degrees).unwrap(),
            &truth,
        );
        let with_term = auc(&detect_prepared(&em, &params).unwrap().sharpness, &truth);
        let mut without = params.clone();
        without.intersection.weight = 0.0;
        let without = auc(&detect_prepared(&em, &without).unwrap().sharpness, &truth);
        eprintln!(
            "{file} at 0.5 % noise: intersections {alone:.4}, fused {without:.4} -> {with_term:.4}"
        );
        assert!(alone > alone_min, "{file}: intersections alone {alone}");
        assert!(
            with_term > without + gain,
            "{file}: fused {without} -> {with_term}"
        );
    }
}
