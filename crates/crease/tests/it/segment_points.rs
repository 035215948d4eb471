//! Segmentation of point clouds into analytic surfaces (mizoguchi over the kNN graph): the
//! synthetic parts sampled as clouds with estimated normals, scored against their exact
//! per-point truth, and the ABC model's vertices as a cloud.

use crate::common;

use crease::geometry::MeshTopology;
use crease::geometry::SurfaceType;
use crease::segment::recognize::GroupKind;
use crease::segment::score::{param_error, read_abc_truth, score_faces};
use crease::segment::{segment_points, PointParams, PointSegmentation, SegmentParams};
use crease::synth::{self, Noise, SampleParams, Shape};

fn sample(name: &str, n: usize, noise: f64) -> synth::SyntheticPart {
    synth::sample_points(
        &Shape::from_name(name).unwrap(),
        &SampleParams {
            n,
            noise: if noise > 0.0 {
                Noise::AlongNormal(noise)
            } else {
                Noise::None
            },
            ..Default::default()
        },
    )
    .unwrap()
}

/// Segmentation with estimated normals and the default parameters.
fn segment_default(points: &[crease::geometry::Point3]) -> PointSegmentation {
    segment_points(
        points,
        None,
        &SegmentParams::default(),
        &PointParams::default(),
    )
    .unwrap()
}

fn attr(part: &synth::SyntheticPart, name: &str) -> Vec<i64> {
    part.cloud.attributes.get(name).unwrap().as_i64()
}

/// Segments a sampled part (normals estimated, not the exact ones) and checks it like the mesh
/// tests do: every true surface of at least 1 % of the points found with its type, an IoU of
/// at least `min_iou`, the radius within `radius_tol` and the axis within 1°; the smaller ones
/// (the rounded cube's corner spheres, about 55 points each at 20k points) need an IoU of 0.3
/// and three quarters of them the right type, and those of the right type the same radius
/// tolerance (measured at 20k points: all 8 corners spheres with radii exact at noise 0, 7 of
/// 8 at noise 0.01 within 0.35 %; before the border refinement they were up to 1.4 % off).
/// Returns the segmentation.
fn check_part(
    name: &str,
    n: usize,
    noise: f64,
    min_iou: f64,
    radius_tol: f64,
) -> PointSegmentation {
    let part = sample(name, n, noise);
    let seg = segment_default(&part.cloud.positions);
    let truth: Vec<i32> = attr(&part, synth::attr::SURFACE)
        .iter()
        .map(|&v| v as i32)
        .collect();
    let ttype: Vec<u8> = attr(&part, synth::attr::SURFACE_TYPE)
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
    )
    .unwrap();
    eprintln!(
        "{name} n {n} noise {noise}: {} surfaces, typed {:.4}, unassigned {:.4}, IoU {:.3}",
        seg.surfaces.len(),
        score.typed_area,
        score.unassigned_area,
        score.mean_iou_area
    );
    assert!(
        score.typed_area > 0.96,
        "{name}: typed {}",
        score.typed_area
    );
    let total: f64 = score.matches.iter().map(|m| m.area).sum();
    let (mut small_n, mut small_ok) = (0, 0);
    for mt in &score.matches {
        let small = mt.area < 0.01 * total;
        assert!(mt.best >= 0, "{name}: true surface {} not found", mt.truth);
        let got = &seg.surfaces[mt.best as usize];
        let e = param_error(&got.params, &part.surfaces[mt.truth].params);
        eprintln!(
            "  true {} {:?} {} pts: got #{} {:?} IoU {:.3} err {:?}",
            mt.truth, mt.truth_type, mt.area, mt.best, mt.best_type, mt.iou, e
        );
        if small {
            small_n += 1;
            small_ok += (mt.best_type == mt.truth_type) as usize;
            assert!(mt.iou >= 0.3, "{name}: surface {} IoU {}", mt.truth, mt.iou);
            if let (true, Some(r)) = (mt.best_type == mt.truth_type, e.radius) {
                assert!(
                    r < radius_tol,
                    "{name}: small surface {} radius error {r}",
                    mt.truth
                );
            }
            continue;
        }
        assert_eq!(mt.best_type, mt.truth_type, "{name}: surface {}", mt.truth);
        assert!(
            mt.iou >= min_iou,
            "{name}: surface {} IoU {}",
            mt.truth,
            mt.iou
        );
        if let Some(r) = e.radius {
            assert!(
                r < radius_tol,
                "{name}: surface {} radius error {r}",
                mt.truth
            );
        }
        if let Some(a) = e.axis_degrees {
            assert!(a < 1.0, "{name}: surface {} axis error {a}°", mt.truth);
        }
    }
    assert!(
        4 * small_ok >= 3 * small_n,
        "{name}: {small_ok} of {small_n} small surfaces typed right"
    );
    seg
}

#[test]
fn cloud_primitives_are_found_with_accurate_parameters() {
    for name in ["plane", "cylinder", "cone", "sphere", "torus"] {
        check_part(name, 10_000, 0.0, 0.98, 0.005);
        check_part(name, 10_000, 0.01, 0.98, 0.02);
    }
}

#[test]
fn cloud_parts_every_surface_found() {
    for name in ["cube", "box-hole", "rounded-cube", "two-cylinders"] {
        check_part(name, 20_000, 0.0, 0.6, 0.005);
        check_part(name, 20_000, 0.01, 0.6, 0.02);
    }
    // Fillets lose the points within th_norm of their tangent planes to the planes, which grow
    // first (IoU down to 0.66 with noise at 20k points).
    // The 45° chamfer is 8 spacings wide at 20k points: PCA normals (20 neighbours) bend
    // over most of it and it comes out as a cylinder; at 40k points it is a plane.
    let seg = check_part("fillet-chamfer-cone", 40_000, 0.0, 0.75, 0.005);
    // The fillet (radius 0.1) between the top and the side is recognised as a fillet.
    let fillet = seg.groups.iter().any(|g| {
        g.kind == GroupKind::Fillet
            && match seg.surfaces[g.surfaces[0] as usize].params {
                crease::geometry::SurfaceParams::Cylinder { radius, .. } => {
                    (radius - 0.1).abs() < 1e-3
                }
                _ => false,
            }
    });
    assert!(fillet, "groups {:?}", seg.groups);
    // No spurious surfaces along the creases (`crease_band`): 10 true surfaces, 10 found.
    assert_eq!(seg.surfaces.len(), 10);
    let seg = check_part("fillet-chamfer-cone", 40_000, 0.01, 0.75, 0.02);
    assert_eq!(seg.surfaces.len(), 10);
}

#[test]
fn cloud_given_normals_and_determinism() {
    let part = sample("box-hole", 20_000, 0.01);
    let normals = part.cloud.normals.clone().unwrap();
    let run = |t: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
            .install(|| {
                segment_points(
                    &part.cloud.positions,
                    Some(&normals),
                    &SegmentParams::default(),
                    &PointParams::default(),
                )
                .unwrap()
            })
    };
    let (a, b) = (run(1), run(2));
    assert_eq!(a.point_surface, b.point_surface);
    assert_eq!(a.surfaces, b.surfaces);
    assert!(a.normals_given);
    // With the exact normals every point of the box with a hole gets its true type.
    let ttype = attr(&part, synth::attr::SURFACE_TYPE);
    let right = a
        .point_types()
        .iter()
        .zip(&ttype)
        .filter(|(x, y)| **x as i64 == **y)
        .count();
    assert!(right as f64 > 0.999 * ttype.len() as f64, "{right}");
    let cyl: Vec<_> = a
        .surfaces
        .iter()
        .filter(|s| s.kind == SurfaceType::Cylinder)
        .collect();
    assert_eq!(cyl.len(), 1);
    assert_eq!(cyl[0].neighbours.len(), 2, "the hole meets top and bottom");
    // Areas: the points' areas add up to the part's area within 5 %.
    let area: f64 = a.point_area.iter().sum();
    let truth: f64 = part.surfaces.iter().map(|s| s.area).sum();
    assert!((area / truth - 1.0).abs() < 0.05, "{area} vs {truth}");
    // Bad input.
    assert!(segment_points(
        &part.cloud.positions,
        Some(&normals[1..]),
        &SegmentParams::default(),
        &PointParams::default()
    )
    .is_err());
    assert!(segment_points(
        &part.cloud.positions[..5],
        None,
        &SegmentParams::default(),
        &PointParams::default()
    )
    .is_err());
}

/// The ABC model's 16332 vertices as a cloud (normals estimated). A vertex counts as right
/// when its type is that of one of its incident faces; weights are the points' areas.
#[test]
fn abc_vertices_as_a_cloud() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    let abc = dir.join("abc");
    let (mesh, _) = crease::io::read_mesh(
        abc.join("00000006_d4fe04f0f5f84b52bd4f10e4_trimesh_001.obj"),
        &Default::default(),
    )
    .unwrap();
    let truth = read_abc_truth(
        &abc.join("00000006_face_surface_labels.txt"),
        &abc.join("00000006_primitives.json"),
    )
    .unwrap();
    let topo = MeshTopology::new(&mesh).unwrap();
    let seg = segment_points(
        mesh.positions(),
        None,
        &SegmentParams::default(),
        &PointParams::default(),
    )
    .unwrap();
    let types = seg.point_types();
    let (mut right, mut total) = (0.0, 0.0);
    for (v, &ty) in types.iter().enumerate() {
        let fs = topo.vertex_faces(v);
        if fs.is_empty() {
            continue;
        }
        total += seg.point_area[v];
        if fs.iter().any(|&f| truth.face_type[f as usize] == ty) {
            right += seg.point_area[v];
        }
    }
    let typed = right / total;
    eprintln!(
        "ABC vertices as a cloud: {} surfaces, typed {typed:.4}",
        seg.surfaces.len()
    );
    assert!(typed > 0.97, "typed {typed}");
    // No small surfaces along the creases: 15 true surfaces, 15 found (24, typed 0.967, before
    // regions of crease bands that their neighbours explain were dissolved).
    assert!(seg.surfaces.len() <= 16, "{} surfaces", seg.surfaces.len());
    // The large surfaces (planes, the cylinder) are recovered with their parameters.
    for (i, t) in truth.surfaces.iter().enumerate() {
        let Some(t) = t else { continue };
        if !matches!(t.kind(), SurfaceType::Plane | SurfaceType::Cylinder) {
            continue;
        }
        let best = seg
            .surfaces
            .iter()
            .filter(|s| s.kind == t.kind())
            .map(|s| param_error(&s.params, t))
            .filter(|e| e.axis_degrees.is_some_and(|a| a < 1.0))
            .any(|e| e.position.is_some_and(|p| p < 1e-3) && e.radius.is_none_or(|r| r < 0.005));
        assert!(best, "true surface {i} ({:?}) not recovered", t.kind());
    }
}

/// Real depth-sensor scans (`../shared/data/scans`, no labels): the noise-adapted tolerances
/// (`noise_tolerance`) and the hand-over of explained regions keep them segmented. Measured:
/// RealSense box 99 % of the points assigned (17 % with the paper's tolerances), its three
/// visible faces the three largest surfaces, one plane each, 86–96° apart (the third was three
/// planes 5° apart before the merge of `segment::merge`); Kinect test0 the table one plane of 80 % of the points
/// (a 56 % "cone" of half angle 89° before, 64 % assigned); CurvSurf sample: the plane and one
/// each of the torus, cylinder, sphere and cone of its objects.
#[test]
fn real_scans_are_segmented() {
    use crease::io::{read, ReadOptions};
    let Some(dir) = common::data_dir() else {
        return;
    };
    let run = |rel: &str| {
        let (g, _) = read(dir.join(rel), &ReadOptions::default()).unwrap();
        let seg = segment_default(&g.points.positions);
        let n = seg.point_surface.len();
        let assigned = seg.point_surface.iter().filter(|&&s| s >= 0).count() as f64 / n as f64;
        let mut by_size: Vec<&crease::segment::SegmentSurface> = seg.surfaces.iter().collect();
        by_size.sort_by_key(|s| std::cmp::Reverse(s.vertices));
        eprintln!(
            "{rel}: {n} points, {} surfaces, assigned {assigned:.4}, largest {:?}",
            seg.surfaces.len(),
            by_size
                .iter()
                .take(6)
                .map(|s| (s.kind, s.vertices))
                .collect::<Vec<_>>()
        );
        (n, assigned, seg)
    };
    let normal = |s: &crease::segment::SegmentSurface| match s.params {
        crease::geometry::SurfaceParams::Plane { normal, .. } => normal,
        _ => panic!("not a plane: {:?}", s.kind),
    };
    // RealSense box.
    let (_, assigned, seg) = run("scans/realsense-box/caixa.ply");
    assert!(assigned > 0.95, "assigned {assigned}");
    let mut big: Vec<_> = seg.surfaces.iter().collect();
    big.sort_by_key(|s| std::cmp::Reverse(s.vertices));
    // Its three visible faces: the three largest surfaces, planes, each one (the depth camera
    // warps them by a few degrees).
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let (a, b) = (normal(big[i]), normal(big[j]));
        let c = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]).abs();
        assert!(
            c < 0.15,
            "box faces {i} and {j} are {}° apart",
            c.acos().to_degrees()
        );
    }
    // Kinect: the table is one plane.
    let (n, assigned, seg) = run("scans/kinect-mosd/test0.pcd");
    assert!(assigned > 0.95, "assigned {assigned}");
    let table = seg.surfaces.iter().max_by_key(|s| s.vertices).unwrap();
    assert_eq!(table.kind, SurfaceType::Plane);
    assert!(
        table.vertices as f64 > 0.75 * n as f64,
        "table {}",
        table.vertices
    );
    // CurvSurf: the objects on the plane.
    let (n, assigned, seg) = run("scans/curvsurf/sample.xyz");
    assert!(assigned > 0.95, "assigned {assigned}");
    let plane = seg.surfaces.iter().max_by_key(|s| s.vertices).unwrap();
    assert_eq!(plane.kind, SurfaceType::Plane);
    assert!(plane.vertices as f64 > 0.45 * n as f64);
    for k in [
        SurfaceType::Torus,
        SurfaceType::Cylinder,
        SurfaceType::Sphere,
        SurfaceType::Cone,
    ] {
        assert!(
            seg.surfaces
                .iter()
                .any(|s| s.kind == k && s.vertices >= 300),
            "no {k:?} of 300 points"
        );
    }
}

/// A scanner bends and terraces a flat face by several times its noise; the pieces join the
/// face they continue (`segment::merge`, step 2b: their seam is smooth). The Kinect table came
/// out as the table and nine pieces within a few of its RMS distances (its corners turned by
/// 8°, patches of 14 to 2691 points one depth step off it), the CurvSurf backdrop as 8 planes.
#[test]
fn scanner_warps_and_terraces_join_the_face_they_bend() {
    use crease::geometry::vec3::dot;
    use crease::io::{read, ReadOptions};
    let Some(dir) = common::data_dir() else {
        return;
    };
    let load = |rel: &str| read(dir.join(rel), &ReadOptions::default()).unwrap().0;
    let g = load("scans/kinect-mosd/test0.pcd");
    let pts = &g.points.positions;
    let seg = segment_default(pts);
    let n = pts.len();
    let table = seg.surfaces.iter().max_by_key(|s| s.vertices).unwrap();
    let crease::geometry::SurfaceParams::Plane { normal, offset } = table.params else {
        panic!("the table is a {:?}", table.kind);
    };
    let frac = table.vertices as f64 / n as f64;
    // Other regions whose points lie (median) within five of the table's RMS distances of it.
    let mut near = Vec::new();
    for s in &seg.surfaces {
        if s.id == table.id {
            continue;
        }
        let mut d: Vec<f64> = (0..n)
            .filter(|&i| seg.point_surface[i] == s.id as i32)
            .map(|i| (dot(pts[i], normal) - offset).abs())
            .collect();
        d.sort_by(f64::total_cmp);
        if !d.is_empty() && d[d.len() / 2] < 5.0 * table.rms {
            near.push((s.kind, s.vertices));
        }
    }
    eprintln!("table {frac:.3} of the points; pieces near it {near:?}");
    assert!(frac > 0.83, "table {frac}");
    assert!(near.len() <= 2, "pieces of the table left apart: {near:?}");
    // The table is a plane still: its RMS distance within 3 of the noise's.
    let sigma = crease::estimate::noise::noise_sigma(pts).unwrap();
    assert!(
        table.rms < 3.0 * sigma,
        "table rms {} noise {sigma}",
        table.rms
    );

    // CurvSurf: the backdrop one plane where its pieces touch (a part of it lies apart,
    // beyond a gap of the scan).
    let g = load("scans/curvsurf/sample.xyz");
    let seg = segment_default(&g.points.positions);
    let n = g.points.positions.len();
    let backdrop = seg.surfaces.iter().max_by_key(|s| s.vertices).unwrap();
    assert_eq!(backdrop.kind, SurfaceType::Plane);
    assert!(
        backdrop.vertices as f64 > 0.6 * n as f64,
        "backdrop {} of {n}",
        backdrop.vertices
    );
    let planes = seg
        .surfaces
        .iter()
        .filter(|s| s.kind == SurfaceType::Plane)
        .count();
    assert!(planes <= 7, "{planes} planes");
}

/// The cloud path does not depend on the units either: a noisy cloud (4000 points, noise 0.2
/// of the spacing, normals estimated) scaled by 1000 and 1/1000 gets the same point labels,
/// sharp points and surfaces, its areas and RMS errors scaled; scaled by 2^10 and 2^-10 (exact
/// in floating point) the same numbers bit for bit. Until the damping floor of the fits'
/// Levenberg–Marquardt refinement was made relative (`fit::damping_floor`), 20 points changed
/// at 1/1000 and 15 at 2^-10; until the algebraic circle, sphere and quadric fits were solved
/// in units of the data's RMS radius (`fit::unit_scale`), their last bits changed at 2^±10.
#[test]
fn cloud_segmentation_is_independent_of_the_units() {
    let part = sample("fillet-chamfer-cone", 4000, 0.2);
    let p0 = &part.cloud.positions;
    let reference = segment_default(p0);
    assert!(
        reference.surfaces.len() >= 9,
        "{}",
        reference.surfaces.len()
    );
    for k in [1e3, 1e-3, 1024.0, 1.0 / 1024.0f64] {
        let exact = k.log2().fract() == 0.0;
        let p: Vec<[f64; 3]> = p0.iter().map(|q| q.map(|x| x * k)).collect();
        let seg = segment_default(&p);
        let differ = reference
            .point_surface
            .iter()
            .zip(&seg.point_surface)
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(differ, 0, "scale {k}: point labels");
        assert_eq!(reference.point_labels, seg.point_labels, "scale {k}");
        assert_eq!(reference.sharp, seg.sharp, "scale {k}");
        assert_eq!(reference.surfaces.len(), seg.surfaces.len(), "scale {k}");
        for (a, b) in reference.surfaces.iter().zip(&seg.surfaces) {
            assert_eq!(
                (a.kind, a.vertices, &a.neighbours),
                (b.kind, b.vertices, &b.neighbours),
                "scale {k}: surface {}",
                a.id
            );
            if exact {
                assert_eq!((b.area, b.rms), (a.area * k * k, a.rms * k), "scale {k}");
                continue;
            }
            assert!(
                (b.area / (k * k) - a.area).abs() <= 1e-9 * a.area,
                "scale {k}: area {} vs {}",
                b.area,
                a.area
            );
            assert!(
                (b.rms / k - a.rms).abs() <= 1e-6 * a.rms + 1e-12 * reference.mean_edge,
                "scale {k}: rms {} vs {}",
                b.rms,
                a.rms
            );
        }
    }
}

/// Under noise of half a spacing the rounded cube's planes take the first part of each fillet's
/// arc (within the widened tolerances) and the middle of the arc, a 45° strip, passes for a
/// plane; `segment::tangent` makes such a strip the cylinder tangent to its two planes, and
/// the border refinement gives it back its flanks. Measured (50k points, normals estimated): 7
/// cylinders and 11 planes before, the 12 fillets and 6 faces after, radii 0.102–0.105 (the 8
/// corner spheres are not found yet).
#[test]
fn noisy_rounded_cube_fillet_strips_become_cylinders_tangent_to_their_planes() {
    let part = common::noisy_part("rounded-cube", 50_000, 0.5);
    let seg = segment_default(&part.cloud.positions);
    let count = |k: SurfaceType| seg.surfaces.iter().filter(|s| s.kind == k).count();
    let radii: Vec<f64> = seg
        .surfaces
        .iter()
        .filter_map(|s| match s.params {
            crease::geometry::SurfaceParams::Cylinder { radius, .. } => Some(radius),
            _ => None,
        })
        .collect();
    eprintln!("rounded cube at 0.5 spacings: cylinder radii {radii:?}");
    assert_eq!(count(SurfaceType::Plane), 6, "{:?}", seg.surfaces);
    assert_eq!(count(SurfaceType::Cylinder), 12, "{:?}", seg.surfaces);
    for r in radii {
        assert!((r - 0.1).abs() < 0.007, "fillet radius {r} for 0.1");
    }
}

/// The rounded cube at noise of a fifth of a spacing (100k points, normals estimated): its
/// curvature labels mix faces, fillets and corners into seeds of thousands of points, whose
/// fits (cones of half angle 45° tangent to two faces, cones around a corner's diagonal) grew
/// over faces and fillets alike: 15 surfaces of 26, one a cone over two faces and two fillets.
/// Seeds that their fits do not explain within three times the points' noise are now split
/// into local patches (`segment::split_unexplained`): 18 surfaces, the 6 faces, 10 of the 12
/// fillets with their radius, no cone.
#[test]
fn noisy_rounded_cube_seeds_that_straddle_surfaces_are_split() {
    let part = common::noisy_part("rounded-cube", 100_000, 0.2);
    let seg = segment_default(&part.cloud.positions);
    let count = |k: SurfaceType| seg.surfaces.iter().filter(|s| s.kind == k).count();
    let kinds: Vec<(SurfaceType, usize)> =
        seg.surfaces.iter().map(|s| (s.kind, s.vertices)).collect();
    eprintln!("rounded cube at 0.2 spacings: {kinds:?}");
    assert_eq!(count(SurfaceType::Plane), 6, "{kinds:?}");
    assert_eq!(
        count(SurfaceType::Cone) + count(SurfaceType::Torus),
        0,
        "{kinds:?}"
    );
    let fillets = seg
        .surfaces
        .iter()
        .filter(|s| match s.params {
            crease::geometry::SurfaceParams::Cylinder { radius, .. } => {
                (radius - 0.1).abs() < 0.007
            }
            _ => false,
        })
        .count();
    assert!(fillets >= 10, "{fillets} fillets of radius 0.1: {kinds:?}");
}
