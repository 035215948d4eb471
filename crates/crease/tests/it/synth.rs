//! Exactness tests of the synthetic parts: points on their surfaces, exact normals, exact
//! labels, areas, curve lengths, noise statistics, outliers, determinism, meshes.

use std::collections::HashMap;
use std::f64::consts::PI;

use crease::geometry::{SurfaceParams, SurfaceType};
use crease::synth::{
    mesh, sample_points, two_cylinders_curve_length, CurveKind, FeatureCurve, MeshParams, Noise,
    NoiseScale, SampleParams, Shape, SyntheticPart,
};

fn sample(name: &str, n: usize) -> SyntheticPart {
    let shape = Shape::from_name(name).unwrap();
    sample_points(
        &shape,
        &SampleParams {
            n,
            seed: 7,
            ..Default::default()
        },
    )
    .unwrap()
}

fn attr<'a>(part: &'a SyntheticPart, name: &str) -> &'a [f64] {
    &part.cloud.attribute(name).unwrap().values
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}
fn unit(a: [f64; 3]) -> [f64; 3] {
    let n = norm(a);
    [a[0] / n, a[1] / n, a[2] / n]
}

/// Independent implicit distance and unit gradient (up to sign) of each surface type.
fn implicit(params: &SurfaceParams, p: [f64; 3]) -> (f64, [f64; 3]) {
    match *params {
        SurfaceParams::Plane { normal, offset } => (dot(normal, p) - offset, normal),
        SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            radius,
        } => {
            let v = sub(p, axis_point);
            let a = dot(v, axis_dir);
            let r = sub(v, [axis_dir[0] * a, axis_dir[1] * a, axis_dir[2] * a]);
            (norm(r) - radius, unit(r))
        }
        SurfaceParams::Cone {
            apex,
            axis_dir,
            half_angle,
        } => {
            let v = sub(p, apex);
            let h = dot(v, axis_dir);
            let r = sub(v, [axis_dir[0] * h, axis_dir[1] * h, axis_dir[2] * h]);
            let rho = norm(r);
            let ru = unit(r);
            let (s, c) = half_angle.sin_cos();
            let n = [
                ru[0] * c - axis_dir[0] * s,
                ru[1] * c - axis_dir[1] * s,
                ru[2] * c - axis_dir[2] * s,
            ];
            (rho * c - h * s, n)
        }
        SurfaceParams::Sphere { center, radius } => {
            let v = sub(p, center);
            (norm(v) - radius, unit(v))
        }
        SurfaceParams::Torus {
            center,
            axis_dir,
            major_radius,
            minor_radius,
        } => {
            let v = sub(p, center);
            let h = dot(v, axis_dir);
            let r = sub(v, [axis_dir[0] * h, axis_dir[1] * h, axis_dir[2] * h]);
            let ru = unit(r);
            let q = [
                ru[0] * major_radius,
                ru[1] * major_radius,
                ru[2] * major_radius,
            ];
            let w = sub(v, q);
            (norm(w) - minor_radius, unit(w))
        }
    }
}

#[test]
fn points_lie_on_their_surfaces_with_exact_normals() {
    for &name in Shape::names() {
        let part = sample(name, 20_000);
        assert_eq!(part.cloud.len(), 20_000, "{name}");
        let normals = part.cloud.normals.as_ref().unwrap();
        let sid = attr(&part, "gt_surface");
        let stype = attr(&part, "gt_surface_type");
        let mut seen_types = std::collections::BTreeSet::new();
        for (i, &p) in part.cloud.positions.iter().enumerate() {
            let s = &part.surfaces[sid[i] as usize];
            assert_eq!(stype[i] as u8, s.kind.code(), "{name}");
            seen_types.insert(s.kind.code());
            let (d, g) = implicit(&s.params, p);
            assert!(
                d.abs() < 1e-9,
                "{name}: point {i} is {d} off surface {}",
                s.id
            );
            assert!((s.params.distance(p)).abs() < 1e-9);
            let n = normals[i];
            assert!((norm(n) - 1.0).abs() < 1e-12, "{name}: normal not unit");
            let c = dot(n, g).abs();
            assert!(
                c > 1.0 - 1e-12,
                "{name}: normal differs from the analytic one"
            );
        }
        // Every surface type of the shape is represented.
        let want: std::collections::BTreeSet<u8> =
            part.surfaces.iter().map(|s| s.kind.code()).collect();
        assert_eq!(seen_types, want, "{name}");
    }
}

#[test]
fn normals_point_outward() {
    // Convex solids: outward means away from the centre.
    for name in ["cube", "rounded-cube", "sphere"] {
        let part = sample(name, 5000);
        let normals = part.cloud.normals.as_ref().unwrap();
        for (p, n) in part.cloud.positions.iter().zip(normals) {
            assert!(dot(*p, *n) > 0.0, "{name}");
        }
    }
    // The hole of the box: normals point towards the axis.
    let part = sample("box-hole", 20_000);
    let normals = part.cloud.normals.as_ref().unwrap();
    let types = attr(&part, "gt_surface_type");
    let mut hole = 0;
    for (i, (p, n)) in part.cloud.positions.iter().zip(normals).enumerate() {
        if types[i] as u8 == SurfaceType::Cylinder.code() {
            hole += 1;
            assert!(p[0] * n[0] + p[1] * n[1] < 0.0);
        }
    }
    assert!(hole > 500);
    // The two cylinders: normals point away from the axis of their own cylinder.
    let part = sample("two-cylinders", 20_000);
    let normals = part.cloud.normals.as_ref().unwrap();
    let sid = attr(&part, "gt_surface");
    for (i, (p, n)) in part.cloud.positions.iter().zip(normals).enumerate() {
        let s = &part.surfaces[sid[i] as usize];
        match s.params {
            SurfaceParams::Cylinder { axis_dir, .. } => {
                let a = dot(*p, axis_dir);
                let r = sub(*p, [axis_dir[0] * a, axis_dir[1] * a, axis_dir[2] * a]);
                assert!(dot(r, *n) > 0.0);
            }
            SurfaceParams::Plane { normal, .. } => assert!(dot(*p, normal) > 0.0),
            _ => unreachable!(),
        }
    }
}

/// Distance from `p` to a curve's polyline (brute force).
fn polyline_distance(c: &FeatureCurve, p: [f64; 3]) -> f64 {
    let pts = &c.points;
    let mut best = f64::INFINITY;
    let m = pts.len();
    let last = if c.closed { m } else { m - 1 };
    for i in 0..last {
        let a = pts[i];
        let b = pts[(i + 1) % m];
        let ab = sub(b, a);
        let t = (dot(sub(p, a), ab) / dot(ab, ab)).clamp(0.0, 1.0);
        let q = [a[0] + ab[0] * t, a[1] + ab[1] * t, a[2] + ab[2] * t];
        best = best.min(norm(sub(p, q)));
    }
    best
}

fn brute(part: &SyntheticPart, kind: CurveKind, p: [f64; 3]) -> f64 {
    part.curves
        .iter()
        .filter(|c| c.kind == kind)
        .map(|c| polyline_distance(c, p))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn labels_match_brute_force_distances() {
    for (name, kind, dist_name, flag_name) in [
        ("cube", CurveKind::Sharp, "gt_edge_distance", "gt_sharp"),
        ("box-hole", CurveKind::Sharp, "gt_edge_distance", "gt_sharp"),
        (
            "two-cylinders",
            CurveKind::Sharp,
            "gt_edge_distance",
            "gt_sharp",
        ),
        (
            "fillet-chamfer-cone",
            CurveKind::Sharp,
            "gt_edge_distance",
            "gt_sharp",
        ),
        (
            "fillet-chamfer-cone",
            CurveKind::Smooth,
            "gt_smooth_distance",
            "gt_smooth",
        ),
        (
            "rounded-cube",
            CurveKind::Smooth,
            "gt_smooth_distance",
            "gt_smooth",
        ),
    ] {
        let part = sample(name, 40_000);
        let tol = part.sharp_tolerance;
        assert!((tol - part.spacing).abs() < 1e-15);
        let size = part.shape.aabb().max_side();
        let chord = 1e-4 * size;
        let d = attr(&part, dist_name);
        let f = attr(&part, flag_name);
        let mut labelled = 0;
        // A subsample plus every labelled point.
        for i in 0..part.cloud.len() {
            if i % 20 != 0 && f[i] == 0.0 {
                continue;
            }
            let p = part.cloud.positions[i];
            let b = brute(&part, kind, p);
            // The exact distance and the polyline distance differ by at most the chord error.
            assert!(
                (b - d[i]).abs() <= chord + 1e-12,
                "{name} {dist_name}: exact {} vs polyline {b}",
                d[i]
            );
            if f[i] != 0.0 {
                labelled += 1;
                assert!(b <= tol + chord, "{name}: labelled point at {b} > {tol}");
            }
            if b <= tol / 2.0 {
                assert!(f[i] != 0.0, "{name}: point at {b} <= tol/2 not labelled");
            }
            assert_eq!(f[i] != 0.0, d[i] <= tol);
        }
        // Expected share of labelled points ~ (curve length × 2 tol) / area.
        let area: f64 = part.surfaces.iter().map(|s| s.area).sum();
        let length: f64 = part
            .curves
            .iter()
            .filter(|c| c.kind == kind)
            .map(|c| c.length)
            .sum();
        let expect = part.cloud.len() as f64 * length * 2.0 * tol / area;
        let ratio = labelled as f64 / expect;
        assert!(
            (0.8..1.2).contains(&ratio),
            "{name}: {labelled} labelled vs ~{expect}"
        );
    }
}

#[test]
fn smooth_distance_is_max_without_smooth_curves() {
    let part = sample("cube", 1000);
    assert!(attr(&part, "gt_smooth_distance")
        .iter()
        .all(|&d| d == f32::MAX as f64));
    assert!(attr(&part, "gt_smooth").iter().all(|&v| v == 0.0));
    assert!(attr(&part, "gt_smooth_curve").iter().all(|&v| v == -1.0));
}

#[test]
fn areas_and_counts_per_surface() {
    let a = 0.5 - 0.1;
    let expected_total = [
        ("cube", 6.0),
        (
            "rounded-cube",
            6.0 * (2.0 * a) * (2.0 * a) + 12.0 * (PI * 0.1 / 2.0) * (2.0 * a) + 4.0 * PI * 0.01,
        ),
        (
            "box-hole",
            2.0 * (1.0 - PI * 0.04) + 4.0 * 0.5 + 2.0 * PI * 0.2 * 0.5,
        ),
        ("plane", 1.0),
        ("cylinder", PI),
        ("cone", PI * 0.75 * (0.25f64).hypot(0.5)),
        ("sphere", PI),
        ("torus", 4.0 * PI * PI * 0.5 * 0.2),
        (
            "fillet-chamfer-cone",
            // bottom + top - cone base + sides + ends + fillet + chamfer + cone + cone top
            1.2 * 0.8 + 1.2 * 0.6 - PI * 0.04
                + 1.2 * 0.3 * 2.0
                + 2.0 * (0.8 * 0.4 - 0.005 - 0.01 + PI * 0.01 / 4.0)
                + 1.2 * PI * 0.1 / 2.0
                + 1.2 * 0.1 * 2f64.sqrt()
                + PI * 0.3 * (0.1f64).hypot(0.25)
                + PI * 0.01,
        ),
    ];
    for (name, want) in expected_total {
        let part = sample(name, 1000);
        let got: f64 = part.surfaces.iter().map(|s| s.area).sum();
        assert!((got - want).abs() < 1e-12, "{name}: area {got} vs {want}");
    }
    // Counts per surface proportional to the exact (trimmed) areas: this checks the trimmed
    // area formulas (two-cylinder quadratures included) against the rejection sampler.
    for &name in Shape::names() {
        let n = 200_000;
        let part = sample(name, n);
        let total: f64 = part.surfaces.iter().map(|s| s.area).sum();
        let mut counts = vec![0usize; part.surfaces.len()];
        for &s in attr(&part, "gt_surface") {
            counts[s as usize] += 1;
        }
        let mut chi2 = 0.0;
        for (s, &c) in part.surfaces.iter().zip(&counts) {
            let p = s.area / total;
            let e = n as f64 * p;
            let sd = (e * (1.0 - p)).sqrt();
            assert!(
                (c as f64 - e).abs() <= 5.0 * sd + 1.0,
                "{name}: surface {} has {c} points, expected {e}",
                s.id
            );
            chi2 += (c as f64 - e).powi(2) / e;
        }
        // Chi-square with k-1 dof: mean k-1, sd sqrt(2(k-1)); generous bound.
        let k = part.surfaces.len() as f64;
        assert!(
            chi2 <= (k - 1.0) + 6.0 * (2.0 * (k - 1.0)).sqrt() + 1e-9,
            "{name}: chi2 {chi2}"
        );
    }
}

#[test]
fn curve_lengths_and_closure() {
    let cube = sample("cube", 100);
    assert_eq!(cube.curves.len(), 12);
    let l: f64 = cube.curves.iter().map(|c| c.length).sum();
    assert!((l - 12.0).abs() < 1e-12);

    let rc = sample("rounded-cube", 100);
    let a = 0.4;
    let r = 0.1;
    let smooth: Vec<_> = rc
        .curves
        .iter()
        .filter(|c| c.kind == CurveKind::Smooth)
        .collect();
    assert_eq!(smooth.len(), 48);
    assert_eq!(rc.curves.len(), 48);
    let l: f64 = smooth.iter().map(|c| c.length).sum();
    assert!((l - (24.0 * 2.0 * a + 24.0 * PI * r / 2.0)).abs() < 1e-12);

    // Two cylinders: each intersection curve's polyline length vs an independent integral
    // (Simpson's rule on |dP/dphi|).
    let tc = sample("two-cylinders", 100);
    let (ra, rb) = (0.5f64, 0.3f64);
    let m = 200_000;
    let h = 2.0 * PI / m as f64;
    let speed = |phi: f64| {
        let (s, c) = phi.sin_cos();
        let x = (ra * ra - rb * rb * c * c).sqrt();
        ((rb * rb * c * s / x).powi(2) + rb * rb).sqrt()
    };
    let simpson: f64 = (0..m)
        .map(|i| {
            let a = i as f64 * h;
            (speed(a) + 4.0 * speed(a + h / 2.0) + speed(a + h)) * h / 6.0
        })
        .sum();
    assert!((two_cylinders_curve_length(ra, rb) - simpson).abs() < 1e-10);
    let polys: Vec<_> = tc
        .curves
        .iter()
        .filter(|c| c.points.len() > 10_000)
        .collect();
    assert_eq!(polys.len(), 2);
    for c in polys {
        assert!(c.closed);
        assert!(
            (c.length - simpson).abs() < 1e-7,
            "{} vs {simpson}",
            c.length
        );
        // All vertices on both cylinders.
        for p in &c.points {
            assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - ra).abs() < 1e-12);
            assert!(((p[1] * p[1] + p[2] * p[2]).sqrt() - rb).abs() < 1e-12);
        }
    }
    // Closed curves: consecutive points (closing pair included) are close; open ones reach
    // their ends.
    for &name in Shape::names() {
        let part = sample(name, 100);
        let size = part.shape.aabb().max_side();
        for c in &part.curves {
            let m = c.points.len();
            let max_gap = (1..m)
                .map(|i| norm(sub(c.points[i], c.points[i - 1])))
                .fold(0.0, f64::max);
            assert!(max_gap <= size / 50.0, "{name}: gap {max_gap}");
            if c.closed {
                let gap = norm(sub(c.points[0], c.points[m - 1]));
                assert!(
                    gap > 0.0 && gap <= max_gap * 1.0001,
                    "{name}: closing gap {gap}"
                );
            }
            let poly_len: f64 = (1..m)
                .map(|i| norm(sub(c.points[i], c.points[i - 1])))
                .sum::<f64>()
                + if c.closed {
                    norm(sub(c.points[0], c.points[m - 1]))
                } else {
                    0.0
                };
            assert!(
                (poly_len - c.length).abs() <= 1e-3 * c.length,
                "{name}: polyline {poly_len} vs {}",
                c.length
            );
        }
    }
    // Open primitives have boundary curves only; sphere and torus none.
    for (name, count) in [("plane", 4), ("cylinder", 2), ("cone", 2)] {
        let part = sample(name, 100);
        assert_eq!(part.curves.len(), count);
        assert!(part.curves.iter().all(|c| c.kind == CurveKind::Boundary));
        assert!(attr(&part, "gt_sharp").iter().all(|&v| v == 0.0));
    }
    assert!(sample("sphere", 100).curves.is_empty());
    assert!(sample("torus", 100).curves.is_empty());
}

#[test]
fn noise_statistics_and_outliers() {
    let shape = Shape::from_name("plane").unwrap();
    for noise in [Noise::AlongNormal(0.05), Noise::Isotropic(0.05)] {
        let part = sample_points(
            &shape,
            &SampleParams {
                n: 100_000,
                noise,
                seed: 3,
                ..Default::default()
            },
        )
        .unwrap();
        let sigma = 0.05 * part.spacing;
        assert!((part.noise_sigma - sigma).abs() < 1e-15);
        let z: Vec<f64> = part.cloud.positions.iter().map(|p| p[2]).collect();
        let mean = z.iter().sum::<f64>() / z.len() as f64;
        let sd = (z.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / z.len() as f64).sqrt();
        assert!(
            (sd / sigma - 1.0).abs() < 0.05,
            "{noise:?}: sd {sd} vs {sigma}"
        );
        // Normals unchanged by noise.
        assert!(part
            .cloud
            .normals
            .as_ref()
            .unwrap()
            .iter()
            .all(|n| *n == [0.0, 0.0, 1.0]));
    }
    // Bounding-box relative noise.
    let part = sample_points(
        &shape,
        &SampleParams {
            n: 100_000,
            noise: Noise::AlongNormal(0.001),
            noise_scale: NoiseScale::BoundingBox,
            ..Default::default()
        },
    )
    .unwrap();
    assert!((part.noise_sigma - 0.001 * 2f64.sqrt()).abs() < 1e-15);

    // Outliers: exact fraction, inside the enlarged box, flagged, surface -1 / type 255.
    let cube = Shape::default_cube();
    let part = sample_points(
        &cube,
        &SampleParams {
            n: 10_001,
            outliers: 0.1,
            ..Default::default()
        },
    )
    .unwrap();
    let out = attr(&part, "gt_outlier");
    let n_out = out.iter().filter(|&&v| v != 0.0).count();
    assert_eq!(n_out, 1000);
    let sid = attr(&part, "gt_surface");
    let st = attr(&part, "gt_surface_type");
    let sharp = attr(&part, "gt_sharp");
    let normals = part.cloud.normals.as_ref().unwrap();
    for i in 0..part.cloud.len() {
        if out[i] != 0.0 {
            assert_eq!(sid[i], -1.0);
            assert_eq!(st[i], 255.0);
            assert_eq!(sharp[i], 0.0);
            assert_eq!(normals[i], [0.0; 3]);
            assert!(part.cloud.positions[i].iter().all(|c| c.abs() <= 0.55));
        } else {
            assert!(sid[i] >= 0.0);
        }
    }
    // Outliers are spread through the cloud, not appended.
    assert!(out[..5000].iter().filter(|&&v| v != 0.0).count() > 400);
    // The spacing counts surface points only.
    assert!((part.spacing - (6.0f64 / 9001.0).sqrt()).abs() < 1e-15);
}

#[test]
fn deterministic_whatever_the_thread_count() {
    let params = SampleParams {
        n: 30_000,
        noise: Noise::Isotropic(0.1),
        outliers: 0.02,
        seed: 42,
        ..Default::default()
    };
    for name in ["two-cylinders", "fillet-chamfer-cone"] {
        let shape = Shape::from_name(name).unwrap();
        let a = sample_points(&shape, &params).unwrap();
        let b = sample_points(&shape, &params).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let c = pool.install(|| sample_points(&shape, &params).unwrap());
        assert_eq!(a.cloud, b.cloud);
        assert_eq!(a.cloud, c.cloud);
        let d = sample_points(
            &shape,
            &SampleParams {
                seed: 43,
                ..params.clone()
            },
        )
        .unwrap();
        assert_ne!(a.cloud.positions, d.cloud.positions);
    }
}

#[test]
fn invalid_parameters_are_errors() {
    let cube = Shape::default_cube();
    for p in [
        SampleParams {
            n: 0,
            ..Default::default()
        },
        SampleParams {
            outliers: 1.0,
            ..Default::default()
        },
        SampleParams {
            noise: Noise::AlongNormal(f64::NAN),
            ..Default::default()
        },
        SampleParams {
            sharp_tolerance: Some(-1.0),
            ..Default::default()
        },
    ] {
        assert!(sample_points(&cube, &p).is_err());
    }
    for bad in [
        Shape::Cube { size: -1.0 },
        Shape::RoundedCube {
            size: 1.0,
            radius: 0.6,
        },
        Shape::TwoCylinders {
            radius_a: 0.3,
            half_length_a: 1.0,
            radius_b: 0.5,
            half_length_b: 1.0,
        },
        Shape::Torus {
            major_radius: 0.2,
            minor_radius: 0.5,
        },
        Shape::Sphere { radius: f64::NAN },
    ] {
        assert!(sample_points(&bad, &SampleParams::default()).is_err());
    }
    assert!(Shape::from_name("dodecahedron").is_none());
    for &name in Shape::names() {
        assert_eq!(Shape::from_name(name).unwrap().name(), name);
    }
}

#[test]
fn curves_geometry_and_json() {
    let part = sample("fillet-chamfer-cone", 5000);
    let g = part.curves_geometry();
    g.validate().unwrap();
    let kinds = &g.edge_attributes.get("curve_kind").unwrap().values;
    let sharp_edges = kinds.iter().filter(|&&k| k == 0.0).count();
    let smooth_edges = kinds.iter().filter(|&&k| k == 1.0).count();
    assert!(sharp_edges > 0 && smooth_edges > 0);
    let expect_edges: usize = part
        .curves
        .iter()
        .map(|c| c.points.len() - usize::from(!c.closed))
        .sum();
    assert_eq!(g.edges.len(), expect_edges);
    let j = part.ground_truth_json();
    assert_eq!(j["shape"], "fillet-chamfer-cone");
    assert_eq!(j["surfaces"].as_array().unwrap().len(), part.surfaces.len());
    assert_eq!(j["sharp_curves"], 18);
    assert_eq!(j["smooth_curves"], 2);
    let pts: u64 = j["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["points"].as_u64().unwrap())
        .sum();
    assert_eq!(pts, 5000);
    assert_eq!(
        j["counts"]["sharp"].as_u64().unwrap() as usize,
        attr(&part, "gt_sharp")
            .iter()
            .filter(|&&v| v != 0.0)
            .count()
    );
    assert_eq!(j["surfaces"][0]["params"]["type"], "plane");
}

// ---------------------------------------------------------------- meshes

fn edge_faces(faces: &[[u32; 3]]) -> HashMap<(u32, u32), usize> {
    let mut m = HashMap::new();
    for f in faces {
        for k in 0..3 {
            let (a, b) = (f[k], f[(k + 1) % 3]);
            *m.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    m
}

#[test]
fn meshes_are_closed_manifolds_with_exact_features() {
    for (name, euler) in [
        ("cube", 2),
        ("rounded-cube", 2),
        ("sphere", 2),
        ("torus", 0),
        ("box-hole", 0),
        ("two-cylinders", 2),
        ("fillet-chamfer-cone", 2),
    ] {
        let shape = Shape::from_name(name).unwrap();
        check_closed_mesh(name, &shape, &MeshParams::default(), euler);
    }
}

/// The closed-solid mesh guarantees: every edge in exactly 2 faces, consistent outward
/// orientation, Euler characteristic `euler`, vertices on their surfaces, feature edges on the
/// feature curves and covering them (total length within 1 %).
fn check_closed_mesh(name: &str, shape: &Shape, params: &MeshParams, euler: i64) {
    let m = mesh(shape, params).unwrap_or_else(|e| panic!("{name}: {e}"));
    let tm = &m.mesh;
    tm.check_indices().unwrap();
    let ef = edge_faces(&tm.faces);
    assert!(
        ef.values().all(|&c| c == 2),
        "{name}: edge not in exactly 2 faces"
    );
    // Consistent orientation: every directed edge appears once.
    let mut directed = std::collections::HashSet::new();
    for f in &tm.faces {
        for k in 0..3 {
            assert!(
                directed.insert((f[k], f[(k + 1) % 3])),
                "{name}: orientation"
            );
        }
    }
    let v = tm.num_vertices() as i64;
    let e = ef.len() as i64;
    let f = tm.num_faces() as i64;
    assert_eq!(v - e + f, euler, "{name}: Euler characteristic");
    // Outward orientation: positive signed volume.
    let vol: f64 = tm
        .faces
        .iter()
        .map(|&[a, b, c]| {
            let p = tm.positions();
            let (a, b, c) = (p[a as usize], p[b as usize], p[c as usize]);
            dot(
                a,
                [
                    b[1] * c[2] - b[2] * c[1],
                    b[2] * c[0] - b[0] * c[2],
                    b[0] * c[1] - b[1] * c[0],
                ],
            ) / 6.0
        })
        .sum();
    assert!(vol > 0.0, "{name}: volume {vol}");
    // Vertices on their surfaces.
    let sid = &tm.vertices.attribute("gt_surface").unwrap().values;
    for (i, &p) in tm.positions().iter().enumerate() {
        let s = &m.surfaces[sid[i] as usize];
        assert!(
            s.params.distance(p) < 1e-9,
            "{name}: vertex off its surface"
        );
    }
    let fsid = &tm.face_attributes.get("gt_surface").unwrap().values;
    assert_eq!(fsid.len(), tm.num_faces());
    // Sharp / smooth edges: mesh edges whose endpoints and midpoint lie on a curve.
    let size = shape.aabb().max_side();
    for (edges, kind) in [
        (&m.sharp_edges, CurveKind::Sharp),
        (&m.smooth_edges, CurveKind::Smooth),
    ] {
        for &[a, b] in edges.iter() {
            assert!(ef.contains_key(&(a.min(b), a.max(b))));
            let pa = tm.positions()[a as usize];
            let pb = tm.positions()[b as usize];
            let on = |p: [f64; 3]| {
                m.curves
                    .iter()
                    .filter(|c| c.kind == kind)
                    .map(|c| c.distance(p))
                    .fold(f64::INFINITY, f64::min)
            };
            assert!(
                on(pa) < 1e-9 && on(pb) < 1e-9,
                "{name}: feature edge off curve"
            );
            let mid = [
                (pa[0] + pb[0]) / 2.0,
                (pa[1] + pb[1]) / 2.0,
                (pa[2] + pb[2]) / 2.0,
            ];
            assert!(on(mid) < 1e-2 * size);
        }
    }
    // The feature edges cover the feature curves: their total length ~ the curve length.
    for (edges, kind) in [
        (&m.sharp_edges, CurveKind::Sharp),
        (&m.smooth_edges, CurveKind::Smooth),
    ] {
        let got: f64 = edges
            .iter()
            .map(|&[a, b]| norm(sub(tm.positions()[a as usize], tm.positions()[b as usize])))
            .sum();
        let want: f64 = m
            .curves
            .iter()
            .filter(|c| c.kind == kind)
            .map(|c| c.length)
            .sum();
        assert!(
            (got - want).abs() <= 0.01 * want + 1e-12,
            "{name} {kind:?}: feature edges {got} vs curves {want}"
        );
    }
}

#[test]
fn mesh_noise_and_open_primitives() {
    for name in ["plane", "cylinder", "cone"] {
        let shape = Shape::from_name(name).unwrap();
        let m = mesh(&shape, &MeshParams::default()).unwrap();
        let ef = edge_faces(&m.mesh.faces);
        assert!(ef.values().all(|&c| c == 1 || c == 2));
        let boundary = ef.values().filter(|&&c| c == 1).count();
        assert!(boundary > 0, "{name}: open surface has a boundary");
        let v = m.mesh.num_vertices() as i64;
        let e = ef.len() as i64;
        let f = m.mesh.num_faces() as i64;
        let euler = if name == "plane" { 1 } else { 0 };
        assert_eq!(v - e + f, euler, "{name}");
        // Vertices on the surface; the open boundary runs along the boundary curves.
        let p = m.mesh.positions();
        assert!(p.iter().all(|&q| m.surfaces[0].params.distance(q) < 1e-9));
        let on = |q: [f64; 3]| {
            m.curves
                .iter()
                .map(|c| c.distance(q))
                .fold(f64::INFINITY, f64::min)
        };
        let mut got = 0.0;
        for (&(a, b), &c) in &ef {
            if c == 1 {
                let (pa, pb) = (p[a as usize], p[b as usize]);
                assert!(
                    on(pa) < 1e-9 && on(pb) < 1e-9,
                    "{name}: boundary vertex off curve"
                );
                got += norm(sub(pa, pb));
            }
        }
        let want: f64 = m.curves.iter().map(|c| c.length).sum();
        assert!(
            (got - want).abs() <= 0.01 * want,
            "{name}: boundary {got} vs {want}"
        );
    }
    let shape = Shape::default_cube();
    let clean = mesh(&shape, &MeshParams::default()).unwrap();
    let noisy = mesh(
        &shape,
        &MeshParams {
            noise: Noise::AlongNormal(0.1),
            seed: 5,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(clean.mesh.faces, noisy.mesh.faces);
    let moved = clean
        .mesh
        .positions()
        .iter()
        .zip(noisy.mesh.positions())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(moved, clean.mesh.num_vertices());
    // Ground-truth attributes describe the noise-free positions: identical.
    assert_eq!(
        clean.mesh.vertices.attribute("gt_edge_distance"),
        noisy.mesh.vertices.attribute("gt_edge_distance")
    );
}

/// Timing of 1M points per shape:
/// `cargo test --release -p crease --test it synth:: -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_one_million_points() {
    for &name in Shape::names() {
        let shape = Shape::from_name(name).unwrap();
        let t = std::time::Instant::now();
        let part = sample_points(
            &shape,
            &SampleParams {
                n: 1_000_000,
                noise: Noise::AlongNormal(0.02),
                ..Default::default()
            },
        )
        .unwrap();
        let sharp = attr(&part, "gt_sharp")
            .iter()
            .filter(|&&v| v != 0.0)
            .count();
        eprintln!(
            "{name:>20}: {:.3} s ({} surfaces, {} curves, {sharp} sharp points)",
            t.elapsed().as_secs_f64(),
            part.surfaces.len(),
            part.curves.len()
        );
    }
}

/// Triangle quality of a mesh: (min angle in degrees per face, edge lengths).
fn quality(tm: &crease::geometry::TriMesh) -> (Vec<f64>, Vec<f64>) {
    let p = tm.positions();
    let mut angles = Vec::with_capacity(tm.num_faces());
    let mut lengths = Vec::new();
    for f in &tm.faces {
        let v = f.map(|i| p[i as usize]);
        let mut min = 180.0f64;
        for k in 0..3 {
            let a = sub(v[(k + 1) % 3], v[k]);
            let b = sub(v[(k + 2) % 3], v[k]);
            let c = (dot(a, b) / (norm(a) * norm(b))).clamp(-1.0, 1.0);
            min = min.min(c.acos().to_degrees());
            lengths.push(norm(a));
        }
        angles.push(min);
    }
    (angles, lengths)
}

/// Every vertex's faces form one closed fan (closed 2-manifold at the vertices too).
fn vertex_fans_are_single_cycles(faces: &[[u32; 3]], nv: usize) -> bool {
    let mut link: Vec<Vec<(u32, u32)>> = vec![Vec::new(); nv];
    for f in faces {
        for k in 0..3 {
            link[f[k] as usize].push((f[(k + 1) % 3], f[(k + 2) % 3]));
        }
    }
    link.iter().all(|l| {
        if l.len() < 3 {
            return false;
        }
        let next: HashMap<u32, u32> = l.iter().copied().collect();
        if next.len() != l.len() {
            return false;
        }
        let start = l[0].0;
        let mut v = start;
        for step in 1..=l.len() {
            v = match next.get(&v) {
                Some(&w) => w,
                None => return false,
            };
            if v == start {
                return step == l.len();
            }
        }
        false
    })
}

#[test]
fn trimmed_meshes_quality_areas_and_determinism() {
    for name in ["box-hole", "two-cylinders", "fillet-chamfer-cone"] {
        let shape = Shape::from_name(name).unwrap();
        let target = shape.aabb().max_side() / 40.0;
        let m = mesh(&shape, &MeshParams::default()).unwrap();
        let tm = &m.mesh;
        assert!(
            vertex_fans_are_single_cycles(&tm.faces, tm.num_vertices()),
            "{name}: non-manifold vertex"
        );
        // No two vertices at the same place (seams and borders share their vertices).
        let mut keys: Vec<[i64; 3]> = tm
            .positions()
            .iter()
            .map(|p| p.map(|c| (c * 1e9).round() as i64))
            .collect();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), tm.num_vertices(), "{name}: coincident vertices");
        // Triangle quality and edge lengths.
        let (angles, lengths) = quality(tm);
        let min_angle = angles.iter().copied().fold(180.0, f64::min);
        assert!(min_angle > 20.0, "{name}: min angle {min_angle}");
        let mean = lengths.iter().sum::<f64>() / lengths.len() as f64;
        assert!(
            (0.9 * target..1.15 * target).contains(&mean),
            "{name}: mean edge {mean} vs target {target}"
        );
        assert!((m.mean_edge - mean).abs() < 1e-3 * target);
        let longest = lengths.iter().copied().fold(0.0, f64::max);
        assert!(longest < 2.0 * target, "{name}: edge {longest}");
        // Faces: exact outward normal agrees with the winding; per-surface areas match the
        // exact trimmed areas (within the chord error of the curved borders).
        let p = tm.positions();
        let fsid = &tm.face_attributes.get("gt_surface").unwrap().values;
        let ftype = &tm.face_attributes.get("gt_surface_type").unwrap().values;
        let mut area = vec![0.0; m.surfaces.len()];
        for (fi, f) in tm.faces.iter().enumerate() {
            let s = &m.surfaces[fsid[fi] as usize];
            assert_eq!(ftype[fi] as u8, s.kind.code());
            let [a, b, c] = f.map(|i| p[i as usize]);
            let (ab, ac) = (sub(b, a), sub(c, a));
            let g = [
                ab[1] * ac[2] - ab[2] * ac[1],
                ab[2] * ac[0] - ab[0] * ac[2],
                ab[0] * ac[1] - ab[1] * ac[0],
            ];
            area[fsid[fi] as usize] += norm(g) / 2.0;
            let centre = [
                (a[0] + b[0] + c[0]) / 3.0,
                (a[1] + b[1] + c[1]) / 3.0,
                (a[2] + b[2] + c[2]) / 3.0,
            ];
            let (_, grad) = implicit(&s.params, centre);
            // implicit() gradients point outward (away from the axis for cylinders and cones,
            // along the outward plane normal), except in the hole of the box.
            let sign = match s.params {
                SurfaceParams::Cylinder { .. } if name == "box-hole" => -1.0,
                _ => 1.0,
            };
            assert!(
                sign * dot(g, grad) > 0.0,
                "{name}: face {fi} wound against its outward normal"
            );
        }
        for (s, a) in m.surfaces.iter().zip(&area) {
            assert!(
                (a - s.area).abs() <= 0.01 * s.area,
                "{name}: surface {} mesh area {a} vs {}",
                s.id,
                s.area
            );
        }
        // Vertex normals: unit, exact normal of the vertex's surface.
        let normals = tm.vertices.normals.as_ref().unwrap();
        let vsid = &tm.vertices.attribute("gt_surface").unwrap().values;
        for (i, (&q, &n)) in p.iter().zip(normals).enumerate() {
            let s = &m.surfaces[vsid[i] as usize];
            let (_, grad) = implicit(&s.params, q);
            assert!((norm(n) - 1.0).abs() < 1e-12);
            assert!(dot(n, grad).abs() > 1.0 - 1e-9, "{name}: vertex normal");
        }
        // Deterministic; noise moves the vertices only.
        let again = mesh(&shape, &MeshParams::default()).unwrap();
        assert_eq!(again.mesh, m.mesh, "{name}: not deterministic");
        assert_eq!(again.sharp_edges, m.sharp_edges);
        let noisy = mesh(
            &shape,
            &MeshParams {
                noise: Noise::Isotropic(0.05),
                seed: 9,
                ..Default::default()
            },
        )
        .unwrap();
        assert_eq!(noisy.mesh.faces, m.mesh.faces);
        let moved = noisy
            .mesh
            .positions()
            .iter()
            .zip(p)
            .map(|(a, b)| norm(sub(*a, *b)))
            .collect::<Vec<_>>();
        let rms = (moved.iter().map(|d| d * d).sum::<f64>() / moved.len() as f64).sqrt();
        let want = 0.05 * m.mean_edge * 3f64.sqrt();
        assert!(
            (rms / want - 1.0).abs() < 0.1,
            "{name}: noise rms {rms} vs {want}"
        );
        // A finer target gives proportionally more faces.
        let fine = mesh(
            &shape,
            &MeshParams {
                target_edge: Some(target / 2.0),
                ..Default::default()
            },
        )
        .unwrap();
        let ratio = fine.mesh.num_faces() as f64 / tm.num_faces() as f64;
        assert!((3.5..4.5).contains(&ratio), "{name}: face ratio {ratio}");
    }
}

#[test]
fn trimmed_meshes_are_closed_over_targets_and_dimensions() {
    let variants = [
        (Shape::from_name("box-hole").unwrap(), 0),
        (
            Shape::BoxWithHole {
                size: [2.0, 0.6, 0.3],
                hole_radius: 0.29,
            },
            0,
        ),
        (Shape::from_name("two-cylinders").unwrap(), 2),
        (
            Shape::TwoCylinders {
                radius_a: 0.5,
                half_length_a: 0.6,
                radius_b: 0.45,
                half_length_b: 0.8,
            },
            2,
        ),
        (Shape::from_name("fillet-chamfer-cone").unwrap(), 2),
        (
            Shape::FilletChamferCone {
                length: 1.0,
                width: 1.0,
                height: 0.3,
                fillet_radius: 0.25,
                chamfer: 0.05,
                cone_base_radius: 0.3,
                cone_top_radius: 0.02,
                cone_height: 0.6,
            },
            2,
        ),
    ];
    for (shape, euler) in variants {
        let size = shape.aabb().max_side();
        for div in [6.0, 13.0, 31.0, 90.0] {
            let params = MeshParams {
                target_edge: Some(size / div),
                ..Default::default()
            };
            let name = format!("{} ({shape:?}) at size/{div}", shape.name());
            check_closed_mesh(&name, &shape, &params, euler);
            let m = mesh(&shape, &params).unwrap();
            assert!(
                vertex_fans_are_single_cycles(&m.mesh.faces, m.mesh.num_vertices()),
                "{name}: non-manifold vertex"
            );
        }
    }
}

/// Mesh timings at the default target and at ~1M triangles:
/// `cargo test --release -p crease --test it synth::timing_meshes -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_meshes_one_million_triangles() {
    for &name in Shape::names() {
        let shape = Shape::from_name(name).unwrap();
        let t = std::time::Instant::now();
        let m = mesh(&shape, &MeshParams::default()).unwrap();
        let t0 = t.elapsed().as_secs_f64();
        let target = shape.aabb().max_side() / 40.0 * (m.mesh.num_faces() as f64 / 1e6).sqrt();
        let t = std::time::Instant::now();
        let big = mesh(
            &shape,
            &MeshParams {
                target_edge: Some(target),
                ..Default::default()
            },
        )
        .unwrap();
        let t1 = t.elapsed().as_secs_f64();
        let min_angle = quality(&big.mesh).0.into_iter().fold(180.0, f64::min);
        eprintln!(
            "{name:>20}: default {} faces {:.3} s; {} faces {:.3} s (min angle {min_angle:.1}°)",
            m.mesh.num_faces(),
            t0,
            big.mesh.num_faces(),
            t1
        );
    }
}
