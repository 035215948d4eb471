//! End-to-end tests of the `crease` binary: real data loads, bad input gives clear errors and
//! the right exit codes, outputs never overwrite inputs, and the commands' outputs are correct.

use std::path::{Path, PathBuf};

use crate::common::{self, crease, data_dir, json_of};

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("readable directory")
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            files_under(&p, out);
        } else {
            out.push(p);
        }
    }
}

#[test]
fn every_shared_data_file_loads_with_info() {
    let Some(dir) = data_dir() else { return };
    let mut files = Vec::new();
    files_under(&dir, &mut files);
    let geometry_exts = [
        "ply", "obj", "off", "stl", "xyz", "pcd", "las", "laz", "e57",
    ];
    let mut checked = 0;
    for f in files {
        let ext = f
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        if !geometry_exts.contains(&ext.as_str()) {
            continue;
        }
        let out = crease().arg("info").arg("--json").arg(&f).output().unwrap();
        assert!(
            out.status.success(),
            "crease info {} failed: {}",
            f.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        let v = json_of(&out.stdout);
        let points = v["points"].as_u64().unwrap_or(0);
        let min = if v["faces"].as_u64().unwrap_or(0) > 0 {
            8
        } else {
            1000
        };
        assert!(points >= min, "{}: only {points} points", f.display());
        assert!(
            v["spacing"].as_f64().unwrap_or(0.0) > 0.0,
            "{}: no spacing",
            f.display()
        );
        checked += 1;
    }
    assert!(checked >= 38, "only {checked} data files found");
}

#[test]
fn info_reports_known_counts() {
    let Some(dir) = data_dir() else { return };
    let out = crease()
        .args(["info", "--json"])
        .arg(dir.join("meshes/fandisk.off"))
        .output()
        .unwrap();
    assert!(out.status.success());
    let v = json_of(&out.stdout);
    assert_eq!(v["kind"], "triangle mesh");
    assert_eq!(v["points"], 7229);
    assert_eq!(v["faces"], 14454);
}

/// Every file of the bad-input corpus fails with exit code 1 and a message naming the file,
/// except the files with NaN coordinates, which load with the bad points dropped and fail with
/// --strict.
#[test]
fn bad_input_corpus_gives_clear_errors() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../crease/tests/bad_input");
    let mut files = Vec::new();
    files_under(&dir, &mut files);
    assert!(
        files.len() >= 20,
        "bad-input corpus too small: {}",
        files.len()
    );
    for f in files {
        let name = f.file_name().unwrap().to_string_lossy().into_owned();
        let nan = name.contains("nan");
        let mut cmd = crease();
        cmd.arg("info").arg(&f);
        if nan {
            let out = crease().arg("info").arg(&f).output().unwrap();
            assert!(out.status.success(), "{name}: NaN points should be dropped");
            assert!(
                String::from_utf8_lossy(&out.stdout).contains("NaN"),
                "{name}: the dropped points are reported"
            );
            cmd.arg("--strict");
        }
        let out = cmd.output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            out.status.code(),
            Some(1),
            "{name}: exit code, stderr {stderr}"
        );
        assert!(
            stderr.starts_with("error: ") && stderr.contains(&name),
            "{name}: message must name the file: {stderr}"
        );
        assert!(!stderr.contains("panicked"), "{name}: panic: {stderr}");
    }
}

#[test]
fn unknown_format_and_missing_file_are_errors() {
    let tmp = tempfile::tempdir().unwrap();
    let f = tmp.path().join("cloud.abc");
    std::fs::write(&f, "1 2 3\n").unwrap();
    let out = crease().arg("info").arg(&f).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("cloud.abc") && e.contains("unknown file format"),
        "{e}"
    );

    let out = crease()
        .arg("info")
        .arg(tmp.path().join("missing.ply"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.ply"));

    // A usage error is exit code 2.
    let out = crease().arg("frobnicate").output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn convert_never_overwrites_its_input() {
    let tmp = tempfile::tempdir().unwrap();
    let f = tmp.path().join("pts.xyz");
    let text = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n";
    std::fs::write(&f, text).unwrap();
    let out = crease().arg("convert").arg(&f).arg(&f).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("never overwrites"));
    // The same file reached by another path.
    let other = tmp.path().join(".").join("pts.xyz");
    let out = crease()
        .arg("convert")
        .arg(&f)
        .arg(&other)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read_to_string(&f).unwrap(), text);
}

#[test]
fn convert_round_trips_through_every_writable_format() {
    let tmp = tempfile::tempdir().unwrap();
    let src = tmp.path().join("cube.ply");
    let out = crease()
        .args(["synth", "cube", "--mesh", "-o"])
        .arg(&src)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let info = |p: &Path| {
        let o = crease().args(["info", "--json"]).arg(p).output().unwrap();
        assert!(
            o.status.success(),
            "{}: {}",
            p.display(),
            String::from_utf8_lossy(&o.stderr)
        );
        json_of(&o.stdout)
    };
    let base = info(&src);
    for ext in ["obj", "off", "stl", "ply"] {
        let dst = tmp.path().join(format!("converted.{ext}"));
        let o = crease()
            .arg("convert")
            .arg(&src)
            .arg(&dst)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let v = info(&dst);
        assert_eq!(v["faces"], base["faces"], "{ext}");
        assert_eq!(v["points"], base["points"], "{ext}");
    }
    for ext in ["xyz", "pcd", "las", "laz", "e57"] {
        let dst = tmp.path().join(format!("converted.{ext}"));
        let o = crease()
            .arg("convert")
            .arg(&src)
            .arg(&dst)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{ext}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert_eq!(info(&dst)["points"], base["points"], "{ext}");
    }
}

#[test]
fn synth_writes_exact_ground_truth() {
    let tmp = tempfile::tempdir().unwrap();
    let out_path = tmp.path().join("cube.ply");
    let o = crease()
        .args(["synth", "cube", "-n", "20000", "--json", "-o"])
        .arg(&out_path)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = json_of(&o.stdout);
    assert_eq!(v["points"], 20000);
    assert!(tmp.path().join("cube.curves.ply").is_file());
    assert!(tmp.path().join("cube.truth.json").is_file());
    let o = crease()
        .args(["info", "--json"])
        .arg(&out_path)
        .output()
        .unwrap();
    let info = json_of(&o.stdout);
    let names: Vec<&str> = info["attributes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["name"].as_str().unwrap())
        .collect();
    for want in [
        "gt_sharp",
        "gt_edge_distance",
        "gt_surface",
        "gt_surface_type",
    ] {
        assert!(names.contains(&want), "{want} missing from {names:?}");
    }
    // Six planes, all of surface type 0.
    let st = info["attributes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == "gt_surface_type")
        .unwrap();
    assert_eq!(st["histogram"].as_array().unwrap().len(), 1);
    assert!(info["normals"].as_bool().unwrap());

    let o = crease()
        .args(["synth", "no-such-shape", "-o"])
        .arg(&out_path)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("known shapes"));
}

#[test]
fn render_writes_a_png() {
    let tmp = tempfile::tempdir().unwrap();
    let pts = tmp.path().join("cube.ply");
    assert!(crease()
        .args(["synth", "cube", "-n", "5000", "-o"])
        .arg(&pts)
        .output()
        .unwrap()
        .status
        .success());
    let png = tmp.path().join("view.png");
    let o = crease()
        .arg("render")
        .arg(&pts)
        .args(["--color-by", "gt_sharp", "--lines"])
        .arg(tmp.path().join("cube.curves.ply"))
        .arg("-o")
        .arg(&png)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
    // An attribute the file does not have is an error that lists the available ones.
    let o = crease()
        .arg("render")
        .arg(&pts)
        .args(["--color-by", "nope", "-o"])
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("gt_sharp"));
}

#[test]
fn demo_writes_its_results() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("demo");
    let o = crease()
        .args(["demo", "-n", "20000", "--json", "-o"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v = json_of(&o.stdout);
    for f in v["files"].as_array().unwrap() {
        let p = dir.join(f.as_str().unwrap());
        assert!(
            p.is_file() && std::fs::metadata(&p).unwrap().len() > 0,
            "{}",
            p.display()
        );
    }
    assert_eq!(v["points"], 20000);
    assert!(v["sharp_points"].as_u64().unwrap() > 0);
    assert_eq!(v["mesh"]["closed_manifold"], true);
    // The demo part's mesh as a B-rep: a solid of 8 planes, a cylinder and a cone (its STEP
    // file is checked by OpenCASCADE in reconstruct_cli).
    assert_eq!(v["brep"]["solid"], true);
    assert_eq!(
        v["brep"]["faces"],
        serde_json::json!({"cone": 1, "cylinder": 1, "plane": 8})
    );
    // Oriented PCA normals of the noisy demo part: most points are on flat faces, so the median
    // error is small; the 95th percentile is dominated by points next to sharp edges.
    let median = v["normals"]["angle_error_degrees"]["median"]
        .as_f64()
        .unwrap();
    assert!(median < 3.0, "median normal error {median} degrees");
    // Sharp points of the demo part: the detected lines lie on the true edges (tolerant F1
    // 0.92 measured at 100k points), and the mesh's sharp vertices are exact (F1 1.0).
    let tolerant = v["sharp_detection"]["tolerant"]["f1"].as_f64().unwrap();
    assert!(tolerant > 0.85, "tolerant F1 {tolerant}");
    let mesh_f1 = v["sharp_detection"]["mesh_vertices"]["exact"]["f1"]
        .as_f64()
        .unwrap();
    assert!(mesh_f1 > 0.95, "mesh F1 {mesh_f1}");
    // The curve network: the fillet's two border lines, each joined at both ends to the sharp
    // lines of the block's end faces.
    let net = &v["curve_network"];
    assert_eq!(net["smooth_polylines"], 2, "{net}");
    assert_eq!(net["joined_smooth_ends"], 4, "{net}");
    assert!(net["sharp_polylines"].as_u64().unwrap() >= 10, "{net}");
    // The mesh segmented into its 10 analytic surfaces: 8 planes, the fillet's cylinder and
    // the cone, every face assigned.
    let seg = &v["segmentation"];
    assert_eq!(seg["surfaces"], 10, "{seg}");
    assert_eq!(seg["types"]["plane"], 8, "{seg}");
    assert_eq!(seg["types"]["cylinder"], 1, "{seg}");
    assert_eq!(seg["types"]["cone"], 1, "{seg}");
    assert_eq!(seg["unassigned_faces"], 0, "{seg}");
    // Feature edges of the noisy mesh (0.5 % of the largest side) against the exact sharp
    // edges: measured AUC / F1 fused (the default) 0.991 / 0.819, filtered 0.993 / 0.824,
    // dihedral thresholding 0.919 / 0.525.
    let edges = &v["mesh_feature_edges"]["methods"];
    let auc = |m: &str| edges[m]["auc"].as_f64().unwrap();
    let f1 = |m: &str| edges[m]["exact"]["f1"].as_f64().unwrap();
    let (da, df) = (auc("dihedral"), f1("dihedral"));
    for m in ["fused", "filtered"] {
        let (fa, ff) = (auc(m), f1(m));
        assert!(fa > 0.98 && fa > da + 0.04, "AUC {m} {fa}, dihedral {da}");
        assert!(ff > 0.75 && ff > df + 0.2, "F1 {m} {ff}, dihedral {df}");
    }
}

/// Reads a PLY attribute as 0/1 flags.
fn flags(cloud: &crease::PointCloud, name: &str) -> Vec<bool> {
    cloud
        .attribute(name)
        .unwrap_or_else(|| panic!("attribute {name}"))
        .values
        .iter()
        .map(|&v| v > 0.0)
        .collect()
}

/// Fraction of the points whose detected surface's most common true surface is their own.
fn surface_purity(found: &[f64], truth: &[f64]) -> f64 {
    let mut votes: std::collections::BTreeMap<(i64, i64), usize> = Default::default();
    for (&f, &t) in found.iter().zip(truth) {
        *votes.entry((f as i64, t as i64)).or_default() += 1;
    }
    let mut best: std::collections::BTreeMap<i64, (usize, i64)> = Default::default();
    for (&(f, t), &c) in &votes {
        let b = best.entry(f).or_insert((0, t));
        if c > b.0 {
            *b = (c, t);
        }
    }
    let good = found
        .iter()
        .zip(truth)
        .filter(|(&f, &t)| f >= 0.0 && best[&(f as i64)].1 == t as i64)
        .count();
    good as f64 / found.len() as f64
}

#[test]
fn run_on_a_cloud_shares_one_analysis_and_writes_every_result() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::synth(
        dir.path(),
        &["synth", "fillet-chamfer-cone", "-n", "20000"],
        "part.ply",
    );
    let out = dir.path().join("made/by/run");
    let a = crease()
        .args(["run", "--json"])
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    let s = json_of(&a.get_output().stdout);
    // One neighbour query, one normal estimation, one noise measure, one segmentation.
    for piece in ["neighbours", "normals", "noise", "segmentations"] {
        assert_eq!(s["analysis"][piece], 1, "{piece}: {}", s["analysis"]);
    }
    let on_disk: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(on_disk["analysis"], s["analysis"]);

    let (src, _) = crease::io::read(&input, &Default::default()).unwrap();
    let (lab, _) = crease::io::read(out.join("labels.ply"), &Default::default()).unwrap();
    assert_eq!(
        src.points.positions, lab.points.positions,
        "input order kept"
    );
    // Sharp points: distance-tolerant F1 against the exact labels (README: 0.915 for `sharp`).
    let pts = &lab.points.positions;
    let tol = crease::eval::tolerant::default_tolerance(pts).unwrap();
    let f1 = crease::eval::tolerant::tolerant_scores(
        pts,
        &flags(&lab.points, "sharp"),
        &flags(&lab.points, "gt_sharp"),
        tol,
    )
    .unwrap()
    .f1;
    assert!(f1 > 0.88, "tolerant F1 {f1}");
    // Surfaces: the part's 10 patches, each found as one surface.
    assert_eq!(s["surfaces"], 10);
    let found = &lab.points.attribute("surface").unwrap().values;
    let truth = &lab.points.attribute("gt_surface").unwrap().values;
    let purity = surface_purity(found, truth);
    assert!(purity > 0.97, "surface purity {purity}");
    let prims: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("surfaces.json")).unwrap()).unwrap();
    assert_eq!(prims["surfaces"].as_array().unwrap().len(), 10);
    // The curve network: the part's sharp curves as closed polylines, the fillet's borders.
    let obj = std::fs::read_to_string(out.join("network.obj")).unwrap();
    let (mut group, mut sharp_lines, mut smooth_lines) = ("", 0, 0);
    for line in obj.lines() {
        if let Some(g) = line.strip_prefix("g ") {
            group = g;
        } else if line.starts_with("l ") {
            match group {
                "sharp" => sharp_lines += 1,
                "smooth" => smooth_lines += 1,
                g => panic!("polyline in group {g:?}"),
            }
        }
    }
    assert_eq!(s["sharp_polylines"], sharp_lines);
    // Anchored on the surfaces: each of the part's 18 sharp curves one edge of the B-rep, the
    // fillet's two borders its tangent edges, the 12 corners junctions, no free end.
    assert_eq!(sharp_lines, 18, "{}", s["curve_network"]);
    assert_eq!(smooth_lines, 2, "the fillet's two borders");
    assert_eq!(
        s["curve_network"]["from_surfaces"], 20,
        "{}",
        s["curve_network"]
    );
    assert_eq!(
        s["curve_network"]["junctions"], 12,
        "{}",
        s["curve_network"]
    );
    assert_eq!(s["curve_network"]["endpoints"], 0, "{}", s["curve_network"]);
    // The B-rep, from the same analysis (the counts above): a solid of the part's 10 faces,
    // which OpenCASCADE reads as valid with the exact faces.
    assert_eq!(s["brep"]["solid"], true, "{}", s["brep"]);
    assert_eq!(
        s["brep"]["report"]["faces_by_type"],
        serde_json::json!({"cone": 1, "cylinder": 1, "plane": 8})
    );
    let occ = crate::reconstruct_cli::check(&out.join("part.step"), None);
    assert_eq!(occ["valid"], true, "{occ}");
    assert_eq!(occ["solids"], 1, "{occ}");
    let png = std::fs::read(out.join("picture.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}

#[test]
fn run_on_a_mesh_finds_its_feature_edges_and_surfaces() {
    let dir = tempfile::tempdir().unwrap();
    let shape = crease::synth::Shape::from_name("fillet-chamfer-cone").unwrap();
    let m = crease::synth::mesh(&shape, &Default::default()).unwrap();
    let input = dir.path().join("part.ply");
    crease::io::write(
        &input,
        &crease::io::Geometry::from_mesh(m.mesh.clone()),
        &Default::default(),
    )
    .unwrap();
    let out = dir.path().join("out");
    let a = crease()
        .args(["run", "--json"])
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    let s = json_of(&a.get_output().stdout);
    assert_eq!(s["kind"], "mesh");
    assert_eq!(s["surfaces"], 10);
    let (lab, _) = crease::io::read(out.join("labels.ply"), &Default::default()).unwrap();
    let truth: std::collections::BTreeSet<[u32; 2]> = m.sharp_edges.iter().copied().collect();
    let sharp = &lab.edge_attributes.get("sharp").unwrap().values;
    let (mut tp, mut fp) = (0usize, 0usize);
    for (e, &v) in lab.edges.iter().zip(sharp) {
        if v > 0.0 {
            let key = [e[0].min(e[1]), e[0].max(e[1])];
            if truth.contains(&key) {
                tp += 1;
            } else {
                fp += 1;
            }
        }
    }
    let precision = tp as f64 / (tp + fp).max(1) as f64;
    let recall = tp as f64 / truth.len() as f64;
    assert!(
        precision > 0.97 && recall > 0.97,
        "P {precision} R {recall}"
    );
    let found = &lab.face_attributes.get("surface").unwrap().values;
    let gt = &lab.face_attributes.get("gt_surface").unwrap().values;
    let purity = surface_purity(found, gt);
    assert!(purity > 0.99, "face purity {purity}");
    // The B-rep from the same segmentation: the part's solid, checked by OpenCASCADE
    // (exact volume 0.39375 less the mesh's chords on the cone, under 0.1 %).
    assert_eq!(s["brep"]["solid"], true, "{s}");
    let occ = crate::reconstruct_cli::check(&out.join("part.step"), None);
    assert_eq!(occ["valid"], true, "{occ}");
    assert_eq!(occ["solids"], 1, "{occ}");
    assert_eq!(
        occ["faces"],
        serde_json::json!({"plane": 8, "cylinder": 1, "cone": 1}),
        "{occ}"
    );
    let volume = occ["volume"].as_f64().unwrap_or(0.0);
    assert!((volume - 0.39375).abs() < 1e-3 * 0.39375, "volume {volume}");
}

#[test]
fn run_refuses_a_file_as_its_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::synth(dir.path(), &["synth", "cube", "-n", "2000"], "cube.ply");
    crease()
        .arg("run")
        .arg(&input)
        .arg("-o")
        .arg(&input)
        .assert()
        .code(2)
        .stderr(predicates::str::contains("not a folder"));
}

#[test]
fn a_missing_output_folder_is_reported_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::synth(dir.path(), &["synth", "cube", "-n", "2000"], "cube.ply");
    for cmd in [
        "sharp",
        "normals",
        "segment",
        "network",
        "lines",
        "curvature",
    ] {
        let out = dir.path().join("no/such/folder/out.ply");
        let o = crease()
            .arg(cmd)
            .arg(&input)
            .arg("-o")
            .arg(&out)
            .arg("-v")
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(1), "{cmd}");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("does not exist"), "{cmd}: {err}");
        // Nothing was read: the reading stage would have logged the file.
        assert!(
            !err.contains("reading"),
            "{cmd} read its input first: {err}"
        );
        assert!(!out.exists());
    }
}

#[test]
fn a_face_repeating_a_vertex_is_no_panic() {
    // Seen by a mutation fuzzer: `f 1 1 2` made `crease edges` and `crease segment` index an
    // edge that a degenerate face side does not have.
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("r.obj");
    std::fs::write(
        &input,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 1 2\nf 2 4 3\n",
    )
    .unwrap();
    for (cmd, out) in [("edges", "e.ply"), ("segment", "s.ply")] {
        let o = crease()
            .arg(cmd)
            .arg(&input)
            .arg("-o")
            .arg(dir.path().join(out))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{cmd}: {err}");
        assert!(!err.contains("panicked"), "{cmd}: {err}");
    }
    // The real face's three edges and the degenerate face's one real side (vertices 1-2).
    let (g, _) = crease::io::read(dir.path().join("e.ply"), &Default::default()).unwrap();
    assert_eq!(g.edges.len(), 4);
}

#[test]
fn a_closed_output_pipe_ends_quietly() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::synth(dir.path(), &["synth", "cube", "-n", "2000"], "cube.ply");
    for args in [vec!["info"], vec!["info", "--json"]] {
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("crease"))
            .args(&args)
            .arg(&input)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // The reader goes away before crease writes: every write fails with a broken pipe.
        drop(child.stdout.take());
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{args:?}: {err}");
        assert!(err.is_empty(), "{args:?}: {err}");
    }
}

#[test]
fn error_messages_quote_short_excerpts() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("long.ply");
    let keyword = "x".repeat(1_000_000);
    std::fs::write(
        &input,
        format!(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n{keyword}\nend_header\n0\n"
        ),
    )
    .unwrap();
    let o = crease().arg("info").arg(&input).output().unwrap();
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("header line 5: unknown keyword"), "{err}");
    assert!(err.contains("1000000 bytes"), "{err}");
    assert!(err.len() < 400, "{} bytes of error", err.len());
}

#[test]
fn a_killed_convert_never_leaves_a_truncated_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::synth(dir.path(), &["synth", "cube", "-n", "1000000"], "cube.ply");
    let (src, _) = crease::io::read(&input, &Default::default()).unwrap();
    let out = dir.path().join("copy.xyz");
    // A complete previous output.
    crease()
        .args(["convert", "-q"])
        .arg(&input)
        .arg(&out)
        .assert()
        .success();
    let previous = std::fs::read(&out).unwrap();
    // 1M points: the kills land while reading, computing and writing.
    for delay_ms in [5u64, 60, 400, 1000, 2000] {
        let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("crease"))
            .args(["convert", "-q"])
            .arg(&input)
            .arg(&out)
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        // Either the previous file or a complete new one (the same bytes): never a part.
        let now = std::fs::read(&out).unwrap();
        assert_eq!(now.len(), previous.len(), "killed after {delay_ms} ms");
        assert!(now == previous, "killed after {delay_ms} ms");
    }
    let (copy, _) = crease::io::read(&out, &Default::default()).unwrap();
    assert_eq!(copy.points.len(), src.points.len());
}

#[test]
fn a_hard_link_to_the_input_is_refused_as_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = common::synth(dir.path(), &["synth", "cube", "-n", "2000"], "cube.ply");
    let link = dir.path().join("cube-link.xyz");
    std::fs::hard_link(&input, &link).unwrap();
    let before = std::fs::read(&input).unwrap();
    crease()
        .arg("convert")
        .arg(&input)
        .arg(&link)
        .assert()
        .code(2)
        .stderr(predicates::str::contains("is the input file"));
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

#[test]
fn inputs_that_are_not_files_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("scan.ply");
    std::fs::create_dir(&folder).unwrap();
    for input in [folder.as_path(), Path::new("/dev/zero.ply")] {
        if !input.exists() {
            continue;
        }
        crease()
            .arg("info")
            .arg(input)
            .timeout(std::time::Duration::from_secs(20))
            .assert()
            .code(1)
            .stderr(predicates::str::contains("not a regular file"));
    }
    // A FIFO named like a point cloud: refused at once, not read forever.
    let fifo = dir.path().join("pipe.xyz");
    if std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        crease()
            .arg("info")
            .arg(&fifo)
            .timeout(std::time::Duration::from_secs(20))
            .assert()
            .code(1)
            .stderr(predicates::str::contains("not a regular file"));
    }
}

#[test]
fn extreme_coordinates_give_answers_or_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("grid.xyz");
    let text: String = (0..25)
        .map(|i| format!("{} {} 0\n", (i % 5) as f64 * 1e19, (i / 5) as f64 * 1e19))
        .collect();
    std::fs::write(&grid, text).unwrap();
    for cmd in ["normals", "segment"] {
        let o = crease()
            .arg(cmd)
            .arg(&grid)
            .arg("-o")
            .arg(dir.path().join(format!("{cmd}.ply")))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{cmd}: {err}");
    }
    // A flat grid spaced 1e19 is one plane.
    let (seg, _) = crease::io::read(dir.path().join("segment.ply"), &Default::default()).unwrap();
    let surface = &seg.points.attribute("surface").unwrap().values;
    assert!(surface.iter().all(|&s| s == 0.0), "{surface:?}");

    let far = dir.path().join("far.xyz");
    let mut text: String = (0..400)
        .map(|i| format!("{} {} {}\n", (i % 20) as f64, (i / 20) as f64, 0.0))
        .collect();
    text += "1e308 0 0\n";
    std::fs::write(&far, text).unwrap();
    crease()
        .arg("segment")
        .arg(&far)
        .arg("-o")
        .arg(dir.path().join("far.ply"))
        .assert()
        .code(1)
        .stderr(predicates::str::contains("overflow"));
}

/// A seeded mutation fuzz of every format (`scripts/mutation-fuzz.py`: bit flips, truncations,
/// inserted bytes, header counts that lie, NaN / 1e308 values, over small real files and a
/// cube converted to every format crease writes), 240 runs of `info`, `sharp`, `edges`,
/// `segment`, `normals`, `lines` and `reconstruct` under a 4 GB address-space cap: each ends
/// in a result or a clear error, never a panic, a timeout or an allocation failure.
#[test]
fn mutated_files_of_every_format_give_results_or_errors() {
    let Some(_) = common::data_dir() else {
        return;
    };
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../scripts/mutation-fuzz.py");
    let out = tempfile::tempdir().unwrap();
    let o = std::process::Command::new("python3")
        .arg(&script)
        .args(["--runs", "240", "--seed", "ci", "--timeout", "60"])
        .args(["--max-seed-bytes", "150000", "--out"])
        .arg(out.path())
        .arg("--crease")
        .arg(assert_cmd::cargo::cargo_bin("crease"))
        .output()
        .expect("python3 runs");
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success(),
        "defects found:\n{text}{}",
        String::from_utf8_lossy(&o.stderr)
    );
    // Most mutants are refused, and some still read.
    assert!(text.contains(" ok ") && text.contains("error "), "{text}");
}

/// `crease info` reports a cloud's noise (σ across the surface, `crease::estimate::noise`):
/// about the σ `crease synth --noise` added (the part's spacing is √(area / n): the cube's
/// area is 6), zero on a clean cloud, none for a mesh.
#[test]
fn info_reports_the_noise_of_a_cloud() {
    let dir = tempfile::tempdir().unwrap();
    let noise = |args: &[&str], name: &str| {
        let f = common::synth(dir.path(), args, name);
        let out = crease().args(["info", "--json"]).arg(&f).output().unwrap();
        assert!(out.status.success());
        let text = crease().arg("info").arg(&f).output().unwrap();
        let text = String::from_utf8_lossy(&text.stdout).into_owned();
        (json_of(&out.stdout)["noise"].as_f64(), text)
    };
    let (clean, _) = noise(&["synth", "cube", "-n", "20000"], "clean.ply");
    assert!(clean.unwrap() < 1e-6, "{clean:?}");
    let (noisy, text) = noise(
        &["synth", "cube", "-n", "20000", "--noise", "0.5"],
        "noisy.ply",
    );
    let sigma = 0.5 * (6.0f64 / 20000.0).sqrt();
    let ratio = noisy.unwrap() / sigma;
    assert!(
        (0.8..=1.2).contains(&ratio),
        "measured {ratio} of the noise added"
    );
    assert!(text.contains("\nnoise "), "{text}");
    let (mesh, _) = noise(&["synth", "cube", "--mesh"], "mesh.ply");
    assert_eq!(mesh, None);
}
