//! `crease demo`: runs every capability crease has on a built-in synthetic part, with no input
//! files, and writes the results (PLY, polylines, PNG, JSON summary) into one folder.

use std::path::Path;

use anyhow::Context;
use crease::render::{ColorBy, RenderParams, Scene, ViewLayout};
use crease::synth::{self, MeshParams, Noise, NoiseScale, SampleParams, Shape};

use crate::args::Global;
use crate::ui::Stage;

/// The demo part: a block with a fillet, a chamfer and a cone: sharp edges, smooth (fillet)
/// edges and four kinds of analytic surfaces in one part.
const SHAPE: &str = "fillet-chamfer-cone";

pub fn run(g: &Global, dir: &Path, n: usize) -> anyhow::Result<()> {
    if n < 1000 {
        return Err(crate::ui::usage(format!(
            "-n {n}: the demo needs at least 1000 points"
        )));
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let shape = Shape::from_name(SHAPE).context("built-in demo shape missing")?;
    let mut timings = serde_json::Map::new();
    let mut time = |name: &str, stage: Stage| {
        timings.insert(name.to_string(), serde_json::json!(stage.finish()));
    };

    // 1. A scanned-like point cloud: noise of 10 % of the spacing along the normal.
    let s = Stage::start("sampling the part", g.quiet);
    let part = synth::sample_points(
        &shape,
        &SampleParams {
            n,
            noise: Noise::AlongNormal(0.1),
            noise_scale: NoiseScale::Spacing,
            seed: 7,
            ..Default::default()
        },
    )?;
    time("sample_points", s);
    let cloud_path = dir.join("part.ply");
    let curves_path = dir.join("part.curves.ply");
    let s = Stage::start("writing", g.quiet);
    let cloud_geom = crease::io::Geometry::from_cloud(part.cloud.clone());
    super::save(g, &cloud_path, &cloud_geom, false, &[])?;
    let curves = part.curves_geometry();
    super::save(g, &curves_path, &curves, false, &[])?;
    crate::ui::write_text(
        &dir.join("part.truth.json"),
        &serde_json::to_string_pretty(&part.ground_truth_json())?,
    )?;
    time("write", s);

    // 1b. The whole job in one command (`crease run part.ply -o run/`): sharp points, curve
    //     network and surfaces from one shared analysis.
    let s = Stage::start("crease run part.ply -o run/", g.quiet);
    let quiet_global = Global {
        json: false,
        quiet: true,
        ..g.clone()
    };
    super::run::run(
        &quiet_global,
        &super::run::RunArgs {
            input: cloud_path.clone(),
            output: dir.join("run"),
            no_picture: false,
            ascii: false,
        },
    )?;
    time("run", s);

    // 2. Estimators: k-nearest neighbours once, PCA normals (oriented) and quadric curvature
    //    from them, scored against the exact normals of the synthetic part.
    let s = Stage::start("normals and curvature", g.quiet);
    let pts = &part.cloud.positions;
    let nbrs = crease::spatial::knn(pts, 20)?;
    let pca = crease::estimate::pca_normals(pts, &nbrs, &Default::default())?;
    let normals = crease::estimate::orient_normals(pts, &pca.normals, &nbrs)?;
    let curvature =
        crease::estimate::curvature::quadric_curvature(pts, &nbrs, &Default::default())?;
    time("normals_and_curvature", s);
    let mut errors: Vec<f64> = part
        .cloud
        .normals
        .as_ref()
        .map(|exact| {
            exact
                .iter()
                .zip(&normals)
                .map(|(a, b)| crease::geometry::vec3::angle(*a, *b).to_degrees())
                .collect()
        })
        .unwrap_or_default();
    errors.sort_by(f64::total_cmp);
    let pct = |q: f64| {
        errors
            .get(((errors.len() as f64 - 1.0) * q) as usize)
            .copied()
    };
    let mut estimated = part.cloud.clone();
    estimated.set_normals(normals)?;
    estimated.set_attribute(crease::Attribute::float(
        "mean_curvature",
        curvature.mean.clone(),
    ))?;

    // 3. Sharp feature points (tran: multi-scale projected distance, Otsu thresholds), scored
    //    against the exact labels (exact and within two spacings).
    let s = Stage::start("sharp feature points", g.quiet);
    let detected = crease::sharp::detect_points(pts, &Default::default())?;
    time("sharp_points", s);
    let truth: Vec<bool> = part
        .cloud
        .attribute("gt_sharp")
        .map(|a| a.values.iter().map(|v| *v > 0.0).collect())
        .unwrap_or_default();
    let confusion = crease::eval::Confusion::from_labels(&detected.sharp, &truth)?;
    let tolerant = crease::eval::tolerant::default_tolerance(pts)
        .map(|t| crease::eval::tolerant::tolerant_scores(pts, &detected.sharp, &truth, t))
        .transpose()?;
    estimated.set_attribute(crease::Attribute::flag("sharp", detected.sharp.clone()))?;
    estimated.set_attribute(crease::Attribute::float(
        "sharpness",
        detected.sharpness.clone(),
    ))?;
    super::save(
        g,
        &dir.join("part-estimated.ply"),
        &crease::io::Geometry::from_cloud(estimated.clone()),
        false,
        &[],
    )?;

    // 3b. Closed sharp feature lines (Demarsin 2007), written as OBJ polylines.
    let s = Stage::start("closed sharp lines", g.quiet);
    let net = crease::lines::extract_lines(pts, &Default::default())?;
    time("sharp_lines", s);
    let mut lines_geom =
        crease::io::Geometry::from_cloud(crease::PointCloud::from_positions(net.vertices.clone()));
    lines_geom.polylines = net.polylines.clone();
    super::save(g, &dir.join("part-lines.obj"), &lines_geom, false, &[])?;

    // 3c. The whole curve network, sharp and fillet lines (Demarsin 2007 + 2008), on a scan of
    //     the part with less noise (5 % of the spacing): at 10 % the quadric curvature's noise
    //     hides the fillet's histogram valley (see the README).
    let s = Stage::start("curve network (sharp + fillet lines)", g.quiet);
    let quiet_scan = synth::sample_points(
        &shape,
        &SampleParams {
            n,
            noise: Noise::AlongNormal(0.05),
            noise_scale: NoiseScale::Spacing,
            seed: 7,
            ..Default::default()
        },
    )?;
    let fillets =
        crease::fillets::extract_fillets(&quiet_scan.cloud.positions, &Default::default(), true)?;
    let network = crease::fillets::curve_network(&fillets);
    time("curve_network", s);
    let mut network_geom = crease::io::Geometry::from_cloud(crease::PointCloud::from_positions(
        network.vertices.clone(),
    ));
    network_geom.polylines = network.polylines.clone();
    network_geom.polyline_groups = network.groups().iter().map(|g| g.to_string()).collect();
    super::save(g, &dir.join("part-network.obj"), &network_geom, false, &[])?;
    let smooth_lines = network.smooth.iter().filter(|&&s| s).count();

    // 4. The same part as a triangle mesh, and its sharp vertices over the 1- to 4-rings.
    let s = Stage::start("meshing the part", g.quiet);
    let m = synth::mesh(&shape, &MeshParams::default())?;
    time("mesh", s);
    let s = Stage::start("sharp mesh vertices", g.quiet);
    let mesh_sharp = crease::sharp::detect_mesh(&m.mesh, &Default::default())?;
    time("sharp_mesh_vertices", s);
    let mut mesh_truth = vec![false; m.mesh.num_vertices()];
    for e in &m.sharp_edges {
        mesh_truth[e[0] as usize] = true;
        mesh_truth[e[1] as usize] = true;
    }
    let mesh_confusion = crease::eval::Confusion::from_labels(&mesh_sharp.sharp, &mesh_truth)?;
    let mesh_path = dir.join("part-mesh.ply");
    let mesh_faces = m.mesh.num_faces();
    let mesh_vertices = m.mesh.num_vertices();
    let topo = crease::geometry::MeshTopology::new(&m.mesh)?;
    let mesh_curves = m.curves_geometry();
    super::save(
        g,
        &mesh_path,
        &crease::io::Geometry::from_mesh(m.mesh.clone()),
        false,
        &[],
    )?;

    // 4b. The mesh segmented into analytic surfaces with their parameters (Mizoguchi).
    let s = Stage::start("segmentation into analytic surfaces", g.quiet);
    let seg = crease::segment::segment_mesh(&m.mesh, &topo, &Default::default())?;
    time("segmentation", s);
    let mut segmented = m.mesh.clone();
    segmented.set_face_attribute(crease::Attribute::int(
        "surface",
        seg.face_surface.iter().map(|&s| s as i64),
    ))?;
    segmented.set_face_attribute(crease::Attribute {
        name: "surface_type".into(),
        kind: crease::geometry::ScalarKind::U8,
        values: seg.face_types().into_iter().map(f64::from).collect(),
    })?;
    super::save(
        g,
        &dir.join("part-segments.ply"),
        &crease::io::Geometry::from_mesh(segmented.clone()),
        false,
        &[],
    )?;
    let mut surface_types = serde_json::Map::new();
    for surf in &seg.surfaces {
        let name = serde_json::to_value(surf)?["type"]
            .as_str()
            .unwrap_or("other")
            .to_string();
        let count = surface_types
            .get(&name)
            .and_then(|v| v.as_u64())
            .unwrap_or(0);
        surface_types.insert(name, serde_json::json!(count + 1));
    }

    // 4b'. The mesh as a B-rep solid in STEP (scan to CAD).
    let s = Stage::start("B-rep (STEP)", g.quiet);
    let rec = crease::brep::reconstruct_mesh(&m.mesh, &Default::default())?;
    crate::ui::write_text(
        &dir.join("part.step"),
        &rec.to_step("demo-part", crease::brep::LengthUnit::Millimetre),
    )?;
    time("brep", s);

    // 4c. Feature edges of the mesh with the noise of vidal 2011 section 6.1 (0.5 % of the
    // largest side): crease's default `fused` (the paper's SVM and the filtered dihedral
    // angle), `filtered` alone, and dihedral thresholding (what CGAL, libigl and MeshLab do),
    // scored against the exact sharp edges.
    let s = Stage::start("mesh feature edges", g.quiet);
    let noisy_mesh = crease::meshfeat::add_noise(&m.mesh, 0.005, 1)?;
    let em = crease::meshfeat::EdgeMesh::new(&noisy_mesh)?;
    let (edge_truth, _) = crease::meshfeat::labels_from_pairs(&em.topo, &m.sharp_edges);
    let mut edge_scores = serde_json::Map::new();
    let mut default_sharp = Vec::new();
    for method in [
        crease::meshfeat::EdgeMethod::Fused,
        crease::meshfeat::EdgeMethod::Filtered,
        crease::meshfeat::EdgeMethod::Dihedral,
    ] {
        let params = crease::meshfeat::EdgeParams {
            method,
            ..Default::default()
        };
        let d = crease::meshfeat::detect_prepared(&em, &params)?;
        let auc = crease::eval::roc::roc(&d.sharpness, &edge_truth)?.auc;
        let c = crease::eval::Confusion::from_labels(&d.sharp, &edge_truth)?;
        edge_scores.insert(
            method.name().to_string(),
            serde_json::json!({ "auc": auc, "exact": c.metrics(), "detected": c.tp + c.fp }),
        );
        if method == crease::meshfeat::EdgeParams::default().method {
            default_sharp = d.sharp;
        }
    }
    let edge_lines = crease::meshfeat::feature_polylines(&em.topo, &default_sharp);
    let mut edges_geom = crease::io::Geometry::from_cloud(noisy_mesh.vertices.clone());
    edges_geom.polylines = edge_lines.clone();
    super::save(g, &dir.join("part-edges.obj"), &edges_geom, false, &[])?;
    let edge_polylines: Vec<crease::render::Polyline> = edge_lines
        .iter()
        .map(|c| crease::render::Polyline {
            points: c
                .iter()
                .map(|&i| noisy_mesh.positions()[i as usize])
                .collect(),
            closed: c.len() > 2 && c.first() == c.last(),
            color: [220, 30, 30],
            label: None,
        })
        .collect();
    let num_edges = em.num_edges();
    drop(em);
    time("mesh_feature_edges", s);

    // 5. Reading back and summarising, as `crease info` does.
    let s = Stage::start("reading back", g.quiet);
    let (back, report) = crease::io::read(&cloud_path, &Default::default())?;
    let summary = crease::io::summary::summarize(&back, &report);
    time("read_and_summarize", s);

    // 6. Pictures.
    let s = Stage::start("rendering", g.quiet);
    // The exact curves, drawn apart from anything detected: dark grey for sharp curves, green
    // for fillet borders, each with its own legend entry (detected points and lines are red and
    // blue).
    let lines: Vec<crease::render::Polyline> = super::render::polylines_of(&curves, 0)
        .into_iter()
        .map(|mut l| {
            let (color, label) = match l.label.as_deref() {
                Some("smooth") => ([40, 160, 60], "true fillet curve"),
                Some("boundary") => ([110, 110, 110], "true boundary"),
                _ => ([40, 40, 40], "true sharp curve"),
            };
            l.color = color;
            l.label = Some(label.to_string());
            l
        })
        .collect();
    let pictures = [
        (
            "part-sharp.png",
            "gt_sharp",
            "ground truth: sharp points and feature curves",
        ),
        (
            "part-surfaces.png",
            "gt_surface_type",
            "ground truth: surface types",
        ),
    ];
    for (file, attr, title) in pictures {
        let scene = Scene {
            points: Some(&part.cloud),
            mesh: None,
            polylines: lines.clone(),
        };
        let params = RenderParams {
            layout: ViewLayout::Four,
            color_by: ColorBy::Attribute(attr.into()),
            title: Some(format!("{SHAPE}, {n} points - {title}")),
            ..Default::default()
        };
        crease::render::render_png(&scene, &params, &dir.join(file))?;
    }
    let scene = Scene {
        points: Some(&estimated),
        mesh: None,
        polylines: lines.clone(),
    };
    let params = RenderParams {
        color_by: ColorBy::Attribute("mean_curvature".into()),
        title: Some(format!(
            "{SHAPE}, {n} points - estimated mean curvature (quadric, k = 20)"
        )),
        ..Default::default()
    };
    crease::render::render_png(&scene, &params, &dir.join("part-curvature.png"))?;
    let params = RenderParams {
        color_by: ColorBy::Attribute("sharp".into()),
        title: Some(format!(
            "{SHAPE}, {n} points - detected sharp points (Tran)"
        )),
        ..Default::default()
    };
    crease::render::render_png(&scene, &params, &dir.join("part-detected-sharp.png"))?;
    let scene = Scene {
        points: Some(&part.cloud),
        mesh: None,
        polylines: super::render::polylines_of(&lines_geom, 0),
    };
    let params = RenderParams {
        color_by: ColorBy::Uniform,
        title: Some(format!(
            "{SHAPE}, {n} points - closed sharp lines (Demarsin 2007)"
        )),
        ..Default::default()
    };
    crease::render::render_png(&scene, &params, &dir.join("part-lines.png"))?;
    // Sharp lines red, fillet lines blue.
    let mut network_lines = Vec::new();
    for (k, want_smooth) in [(0, false), (1, true)] {
        let mut part_geom = network_geom.clone();
        let keep: Vec<bool> = network.smooth.iter().map(|&s| s == want_smooth).collect();
        part_geom.polylines = network
            .polylines
            .iter()
            .zip(&keep)
            .filter(|(_, &k)| k)
            .map(|(l, _)| l.clone())
            .collect();
        part_geom.polyline_groups.clear();
        network_lines.extend(super::render::polylines_of(&part_geom, k));
    }
    let scene = Scene {
        points: Some(&quiet_scan.cloud),
        mesh: None,
        polylines: network_lines,
    };
    let params = RenderParams {
        color_by: ColorBy::Uniform,
        title: Some(format!(
            "{SHAPE}, {n} points - curve network: sharp (red) and fillet (blue) lines"
        )),
        ..Default::default()
    };
    crease::render::render_png(&scene, &params, &dir.join("part-network.png"))?;
    let scene = Scene {
        points: None,
        mesh: Some(&m.mesh),
        polylines: super::render::polylines_of(&mesh_curves, 0),
    };
    let params = RenderParams {
        color_by: ColorBy::Attribute("gt_surface_type".into()),
        title: Some(format!("{SHAPE}, mesh of {mesh_faces} triangles")),
        ..Default::default()
    };
    crease::render::render_png(&scene, &params, &dir.join("part-mesh.png"))?;
    let scene = Scene {
        points: None,
        mesh: Some(&segmented),
        polylines: Vec::new(),
    };
    let params = RenderParams {
        // By surface id: each surface its own colour (by type, the 8 planes would look alike).
        color_by: ColorBy::Attribute("surface".into()),
        title: Some(format!(
            "{SHAPE}, mesh segmented into {} analytic surfaces (Mizoguchi)",
            seg.surfaces.len()
        )),
        ..Default::default()
    };
    crease::render::render_png(&scene, &params, &dir.join("part-segments.png"))?;
    let scene = Scene {
        points: None,
        mesh: Some(&noisy_mesh),
        polylines: edge_polylines,
    };
    let params = RenderParams {
        title: Some(format!(
            "{SHAPE}, noisy mesh (0.5 %): feature edges (fused)"
        )),
        ..Default::default()
    };
    crease::render::render_png(&scene, &params, &dir.join("part-edges.png"))?;
    time("render", s);

    let sharp = part
        .cloud
        .attribute("gt_sharp")
        .map(|a| a.values.iter().filter(|v| **v > 0.0).count())
        .unwrap_or(0);
    let result = serde_json::json!({
        "shape": SHAPE,
        "points": part.cloud.len(),
        "spacing": summary.spacing,
        "sharp_points": sharp,
        "surfaces": part.surfaces.len(),
        "curves": part.curves.len(),
        "normals": {
            "method": "pca k=20, oriented (Hoppe)",
            "angle_error_degrees": { "median": pct(0.5), "p95": pct(0.95) },
        },
        "sharp_detection": {
            "method": "projected distance, k = 12..40, Otsu per scale (tran)",
            "detected": detected.num_sharp(),
            "exact": confusion.metrics(),
            "tolerant": tolerant,
            "mesh_vertices": { "detected": mesh_sharp.num_sharp(), "exact": mesh_confusion.metrics() },
        },
        "sharp_lines": {
            "polylines": net.polylines.len(),
            "closed_loops": net.closed_loops(),
            "junctions": net.junctions(),
            "endpoints": net.endpoints(),
        },
        "curve_network": {
            "noise": "5 % of the spacing",
            "sharp_polylines": network.polylines.len() - smooth_lines,
            "smooth_polylines": smooth_lines,
            "joined_smooth_ends": network.joined_ends,
            "open_smooth_ends": network.open_ends,
        },
        "segmentation": {
            "surfaces": seg.surfaces.len(),
            "types": surface_types,
            "groups": seg.groups.len(),
            "unassigned_faces": seg.face_surface.iter().filter(|&&s| s < 0).count(),
        },
        "brep": {
            "solid": rec.report.closed,
            "faces": rec.report.faces_by_type,
            "edges": rec.report.edges_by_curve,
            "vertices": rec.report.vertices,
            "max_gap": rec.report.max_gap,
        },
        "mesh_feature_edges": {
            "noise": "0.5 % of the bounding box's largest side (vidal 2011, section 6.1)",
            "edges": num_edges,
            "true_feature_edges": edge_truth.iter().filter(|&&t| t).count(),
            "methods": edge_scores,
        },
        "mesh": {
            "vertices": mesh_vertices,
            "faces": mesh_faces,
            "edges": topo.num_edges(),
            "closed_manifold": topo.is_closed_manifold(),
        },
        "files": ["part.ply", "part.curves.ply", "part.truth.json", "part-estimated.ply",
                  "part-mesh.ply", "part-sharp.png", "part-surfaces.png", "part-curvature.png",
                  "part-mesh.png", "part-detected-sharp.png", "part-lines.obj", "part-lines.png",
                  "part-network.obj", "part-network.png", "part-segments.ply",
                  "part-segments.png", "part.step", "part-edges.obj", "part-edges.png", "run/labels.ply",
                  "run/network.obj", "run/surfaces.json", "run/part.step", "run/summary.json",
                  "run/picture.png"],
        "seconds": timings,
    });
    crate::ui::write_text(
        &dir.join("summary.json"),
        &serde_json::to_string_pretty(&result)?,
    )?;
    if g.json {
        crate::ui::print_json(&result)?;
    } else if !g.quiet {
        crate::ui::outln(format_args!(
            "crease demo: {SHAPE} sampled with {} points (spacing {:.5}), {} of them within one spacing of a sharp edge;",
            part.cloud.len(),
            summary.spacing.unwrap_or(0.0),
            sharp
        ))?;
        crate::ui::outln(format_args!(
            "{} analytic surfaces, {} feature curves; mesh of {} vertices / {} triangles ({}).",
            part.surfaces.len(),
            part.curves.len(),
            mesh_vertices,
            mesh_faces,
            if topo.is_closed_manifold() {
                "closed manifold"
            } else {
                "open"
            }
        ))?;
        crate::ui::outln(format_args!(
            "estimated normals (PCA, k = 20, oriented): median error {:.2} deg, 95th percentile {:.2} deg against the exact normals.",
            pct(0.5).unwrap_or(f64::NAN),
            pct(0.95).unwrap_or(f64::NAN)
        ))?;
        crate::ui::outln(format_args!(
            "sharp points (projected distance, 8 scales): {} detected, F1 {:.3} exact / {:.3} within two spacings; mesh vertices F1 {:.3}.",
            detected.num_sharp(),
            confusion.f1(),
            tolerant.map_or(f64::NAN, |t| t.f1),
            mesh_confusion.f1()
        ))?;
        crate::ui::outln(format_args!(
            "closed sharp lines (Demarsin 2007): {} polylines, {} closed loops, {} junctions, {} endpoints.",
            net.polylines.len(),
            net.closed_loops(),
            net.junctions(),
            net.endpoints()
        ))?;
        crate::ui::outln(format_args!(
            "curve network (Demarsin 2007 + 2008, noise 5 % of the spacing): {} sharp and {} fillet polylines, {} of {} fillet ends joined to sharp lines.",
            network.polylines.len() - smooth_lines,
            smooth_lines,
            network.joined_ends,
            network.joined_ends + network.open_ends
        ))?;
        crate::ui::outln(format_args!(
            "segmentation of the mesh (Mizoguchi): {} analytic surfaces {}, {} recognised groups.",
            seg.surfaces.len(),
            serde_json::Value::Object(surface_types.clone()),
            seg.groups.len()
        ))?;
        let auc_of = |m: &str| result["mesh_feature_edges"]["methods"][m]["auc"].as_f64();
        let f1_of = |m: &str| result["mesh_feature_edges"]["methods"][m]["exact"]["f1"].as_f64();
        crate::ui::outln(format_args!(
            "mesh feature edges (Vidal 2011, noisy mesh): fused AUC {:.3}, F1 {:.3}; filtered {:.3}, {:.3}; dihedral thresholding {:.3}, {:.3}.",
            auc_of("fused").unwrap_or(f64::NAN),
            f1_of("fused").unwrap_or(f64::NAN),
            auc_of("filtered").unwrap_or(f64::NAN),
            f1_of("filtered").unwrap_or(f64::NAN),
            auc_of("dihedral").unwrap_or(f64::NAN),
            f1_of("dihedral").unwrap_or(f64::NAN)
        ))?;
        crate::ui::outln(format_args!(
            "results in {}/: {}",
            dir.display(),
            result["files"]
        ))?;
    }
    Ok(())
}
