//! End-to-end tests of `crease normals`: PCA and mesh normals written as `nx ny nz` beside the
//! input's attributes in input order, orientation, the JSON summary, and clear errors.

use std::path::Path;

use crate::common::{crease, json_of};
use crease::geometry::vec3;
use crease::io::ReadOptions;

fn synth(dir: &Path, shape: &str, extra: &[&str]) -> std::path::PathBuf {
    let out = dir.join(format!("{shape}.ply"));
    crease()
        .args(["synth", shape, "-n", "5000", "-q", "-o"])
        .arg(&out)
        .args(extra)
        .assert()
        .success();
    out
}

#[test]
fn pca_oriented_keeps_attributes_and_order() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), "sphere", &[]);
    let output = dir.path().join("out.ply");
    let out = crease()
        .args(["normals", "--orient", "--json", "-k", "15"])
        .arg(&input)
        .arg("-o")
        .arg(&output)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let j = json_of(&out.stdout);
    assert_eq!(j["method"], "pca");
    assert_eq!(j["k"], 15);
    assert_eq!(j["count"], 5000);
    assert_eq!(j["oriented"], true);
    assert_eq!(j["replaced_input_normals"], true);
    assert!(j["timings"]["normals"].as_f64().unwrap() >= 0.0);
    let (a, _) = crease::io::read_cloud(&input, &ReadOptions::default()).unwrap();
    let (b, _) = crease::io::read_cloud(&output, &ReadOptions::default()).unwrap();
    assert_eq!(a.positions, b.positions);
    // Every ground-truth attribute survives.
    for attr in &a.attributes {
        assert_eq!(b.attribute(&attr.name), Some(attr), "{}", attr.name);
    }
    // The input's (exact) normals were replaced by estimates, all pointing outward.
    let (na, nb) = (a.normals.unwrap(), b.normals.unwrap());
    assert_ne!(na, nb);
    for (e, t) in nb.iter().zip(&na) {
        assert!(vec3::dot(*e, *t) > 0.95, "{e:?} vs {t:?}");
    }
}

#[test]
fn mesh_method_on_mesh_and_refused_on_cloud() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = synth(dir.path(), "torus", &["--mesh"]);
    let output = dir.path().join("mesh-normals.ply");
    crease()
        .args(["normals", "--method", "mesh", "--weighting", "angle", "-q"])
        .arg(&mesh)
        .arg("-o")
        .arg(&output)
        .assert()
        .success();
    let (m, _) = crease::io::read_mesh(&output, &ReadOptions::default()).unwrap();
    let (orig, _) = crease::io::read_mesh(&mesh, &ReadOptions::default()).unwrap();
    assert_eq!(m.faces, orig.faces);
    let n = m.vertices.normals.unwrap();
    // Torus around z, major radius 0.5: the outward normal points from the tube centre.
    for (p, v) in m.vertices.positions.iter().zip(&n) {
        let rho = (p[0] * p[0] + p[1] * p[1]).sqrt();
        let c = [p[0] * 0.5 / rho, p[1] * 0.5 / rho, 0.0];
        let t = vec3::normalize(vec3::sub(*p, c)).unwrap();
        assert!(vec3::dot(*v, t) > 0.99);
    }
    let cloud = synth(dir.path(), "plane", &[]);
    let out = crease()
        .args(["normals", "--method", "mesh"])
        .arg(&cloud)
        .arg("-o")
        .arg(dir.path().join("x.ply"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("needs a triangle mesh"));
}

#[test]
fn errors_are_clear() {
    let dir = tempfile::tempdir().unwrap();
    let input = synth(dir.path(), "plane", &[]);
    // Never overwrite the input.
    let out = crease()
        .args(["normals"])
        .arg(&input)
        .arg("-o")
        .arg(&input)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("never overwrites"));
    // k = 0.
    let o = dir.path().join("o.ply");
    let out = crease()
        .args(["normals", "-k", "0"])
        .arg(&input)
        .arg("-o")
        .arg(&o)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    // Ring normals (demarsin2007 1-ring plane) on the sphere: unoriented, close to the exact
    // (radial) normals the synthetic input carries.
    let out = crease()
        .args(["normals", "--method", "ring"])
        .arg(&input)
        .arg("-o")
        .arg(&o)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (exact, _) = crease::io::read_cloud(&input, &ReadOptions::default()).unwrap();
    let (ring, _) = crease::io::read_cloud(&o, &ReadOptions::default()).unwrap();
    let (en, rn) = (exact.normals.unwrap(), ring.normals.unwrap());
    let mut errs: Vec<f64> = en
        .iter()
        .zip(&rn)
        .map(|(a, b)| {
            let c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).abs().min(1.0);
            c.acos()
        })
        .collect();
    errs.sort_by(f64::total_cmp);
    let median = errs[errs.len() / 2];
    assert!(median < 0.05, "median ring-normal error {median} rad");
    // Too few points for k.
    let small = dir.path().join("small.xyz");
    std::fs::write(&small, "0 0 0\n1 0 0\n0 1 0\n1 1 0\n").unwrap();
    let out = crease()
        .args(["normals", "-k", "20"])
        .arg(&small)
        .arg("-o")
        .arg(&o)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("small.xyz") && err.contains("at least 21 points"),
        "{err}"
    );
    // Three neighbours of four coplanar points: every normal is ±z.
    let xyz_out = dir.path().join("small-out.xyz");
    crease()
        .args(["normals", "-k", "3", "-q"])
        .arg(&small)
        .arg("-o")
        .arg(&xyz_out)
        .assert()
        .success();
    let (c, _) = crease::io::read_cloud(&xyz_out, &ReadOptions::default()).unwrap();
    for n in c.normals.unwrap() {
        assert!((n[2].abs() - 1.0).abs() < 1e-9);
    }
}
