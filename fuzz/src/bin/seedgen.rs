//! Seed corpora of the fuzz targets, made by `scripts/fuzz.sh`:
//!
//! ```text
//! seedgen DATA_DIR BAD_INPUT_DIR OUT_DIR
//! ```
//!
//! writes `OUT_DIR/<target>/` for every target:
//!
//! * readers: every file of DATA_DIR (recursively) and BAD_INPUT_DIR with the target's
//!   extension, the first [`CUT`] bytes of the big ones; plus a small cloud and a small mesh
//!   written by crease's own writers in every encoding (PLY ascii / binary LE / BE with faces,
//!   edges and attributes, OBJ with polylines, OFF, STL ascii / binary, XYZ, PCD ascii / binary
//!   and a hand-made binary_compressed, LAS, LAZ, E57);
//! * point targets: a subsample and a dense patch of chosen real clouds and meshes, and
//!   synthetic parts (`crease_fuzz::encode`);
//! * mesh targets: a connected patch of every real mesh, and synthetic tessellated parts.
//!
//! It is built with the targets (instrumented like them, so it links libFuzzer's runtime but
//! runs its own `main`).

use std::path::{Path, PathBuf};

use crease::geometry::{Attribute, Point3, PointCloud, TriMesh};
use crease::io::{Geometry, ReadOptions, WriteOptions};
use crease_fuzz::encode;

// The instrumented crates call into libFuzzer's runtime, which needs a test function; this one
// never runs (libFuzzer's own `main` is not linked: this binary has its own).
libfuzzer_sys::fuzz_target!(|_data: &[u8]| {});

/// Files above this size are cut to their first `CUT` bytes (the headers and the start of the
/// data are what a reader's branches depend on).
const CUT: usize = 64 * 1024;

/// Reader targets and the extensions whose files seed them.
const READERS: &[(&str, &[&str])] = &[
    ("read_ply", &["ply"]),
    ("read_obj", &["obj"]),
    ("read_off", &["off"]),
    ("read_stl", &["stl"]),
    ("read_xyz", &["xyz", "txt", "csv", "pts"]),
    ("read_pcd", &["pcd"]),
    ("read_las", &["las", "laz"]),
    ("read_e57", &["e57"]),
];

const POINT_TARGETS: &[&str] = &[
    "points_normals",
    "points_sharp",
    "points_lines",
    "points_fillets",
    "points_segment",
    "points_reconstruct",
];

const MESH_TARGETS: &[&str] = &["mesh_edges", "mesh_segment", "mesh_sharp"];

/// Real clouds and meshes (relative to DATA_DIR) whose points seed the point targets: one of
/// each kind (CAD sample, noisy CAD, fractal, scan-like, depth scans, text scan, a mesh).
const POINT_SOURCES: &[&str] = &[
    "points-gt/abc/7034.ply",
    "points-gt/abc-noisy/7031.ply",
    "points-gt/default/TwoPlane90.ply",
    "points-gt/shrec/12.ply",
    "scans/realsense-box/caixa3.ply",
    "scans/curvsurf/sample.xyz",
    "scans/kinect-mosd/test0.pcd",
    "meshes/fandisk.off",
];

/// Points per real seed of the point targets.
const SEED_POINTS: usize = 1000;

fn main() {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [data, bad, out] = args.as_slice() else {
        eprintln!("usage: seedgen DATA_DIR BAD_INPUT_DIR OUT_DIR");
        std::process::exit(2);
    };
    if let Err(e) = run(data, bad, out) {
        eprintln!("seedgen: {e}");
        std::process::exit(1);
    }
}

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn run(data: &Path, bad: &Path, out: &Path) -> Res<()> {
    let mut files = Vec::new();
    list_files(data, &mut files)?;
    list_files(bad, &mut files)?;
    files.sort();
    let written = out.join("written");
    std::fs::create_dir_all(&written)?;
    write_samples(&written)?;
    list_files(&written, &mut files)?;

    for (target, exts) in READERS {
        let dir = out.join(target);
        std::fs::create_dir_all(&dir)?;
        let mut n = 0;
        for f in &files {
            let ext = f
                .extension()
                .and_then(|e| e.to_str())
                .unwrap_or("")
                .to_ascii_lowercase();
            if !exts.contains(&ext.as_str()) {
                continue;
            }
            let mut bytes = std::fs::read(f)?;
            bytes.truncate(CUT);
            n += 1;
            std::fs::write(dir.join(seed_name(n, f)), bytes)?;
        }
        eprintln!("seedgen: {target}: {n} seeds");
    }

    let mut point_seeds: Vec<Vec<Point3>> = Vec::new();
    for rel in POINT_SOURCES {
        let path = data.join(rel);
        let Ok((geom, _)) = crease::io::read(&path, &ReadOptions::default()) else {
            eprintln!(
                "seedgen: skipping {} (missing or unreadable)",
                path.display()
            );
            continue;
        };
        let pts = &geom.points.positions;
        point_seeds.push(subsample(pts, SEED_POINTS));
        point_seeds.push(patch(pts, SEED_POINTS));
    }
    for target in POINT_TARGETS {
        let dir = out.join(target);
        std::fs::create_dir_all(&dir)?;
        let mut n = 0;
        let mut put = |bytes: Vec<u8>| -> Res<()> {
            n += 1;
            std::fs::write(dir.join(format!("seed-{n:03}")), bytes)?;
            Ok(())
        };
        for (i, pts) in point_seeds.iter().enumerate() {
            // Variant 0 is the CLI's default; every other seed also tries a second variant.
            let variant = if i % 2 == 0 { 0 } else { 0x25 };
            put(encode::points(variant, pts))?;
        }
        for shape in 0..10u8 {
            put(encode::synthetic_points(0, shape, 600, 0, shape))?;
        }
        put(encode::synthetic_points(0x31, 3, 1500, 0x42, 7))?;
        put(encode::synthetic_points(0x10, 4, 1500, 0x05, 8))?;
        eprintln!("seedgen: {target}: {n} seeds");
    }

    let mut mesh_seeds: Vec<(Vec<Point3>, Vec<[u32; 3]>)> = Vec::new();
    for f in &files {
        let ext = f.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !f.starts_with(data) || !matches!(ext, "obj" | "off" | "stl") {
            continue;
        }
        if let Ok((mesh, _)) = crease::io::read_mesh(f, &ReadOptions::default()) {
            mesh_seeds.push(mesh_patch(&mesh, 600, 1200));
        }
    }
    for target in MESH_TARGETS {
        let dir = out.join(target);
        std::fs::create_dir_all(&dir)?;
        let mut n = 0;
        let mut put = |bytes: Vec<u8>| -> Res<()> {
            n += 1;
            std::fs::write(dir.join(format!("seed-{n:03}")), bytes)?;
            Ok(())
        };
        for (pos, faces) in &mesh_seeds {
            if let Some(bytes) = encode::mesh(0, pos, faces) {
                put(bytes)?;
            }
        }
        for shape in 0..10u8 {
            put(encode::synthetic_mesh(0, shape, 8, 0, shape))?;
        }
        put(encode::synthetic_mesh(1, 3, 10, 0x43, 3))?;
        eprintln!("seedgen: {target}: {n} seeds");
    }
    Ok(())
}

/// Every regular file under `dir`, recursively (nothing when `dir` is missing).
fn list_files(dir: &Path, out: &mut Vec<PathBuf>) -> Res<()> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    for e in entries {
        let path = e?.path();
        if path.is_dir() {
            list_files(&path, out)?;
        } else if path.is_file() {
            out.push(path);
        }
    }
    Ok(())
}

/// A readable, unique seed file name for source `f`.
fn seed_name(n: usize, f: &Path) -> String {
    let stem: String = f
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    format!("seed-{n:03}-{stem}")
}

/// `n` points spread over the whole cloud (every k-th point).
fn subsample(points: &[Point3], n: usize) -> Vec<Point3> {
    let step = points.len().div_ceil(n.max(1)).max(1);
    points.iter().step_by(step).copied().collect()
}

/// The `n` points nearest to the cloud's first point: a patch at the real density.
fn patch(points: &[Point3], n: usize) -> Vec<Point3> {
    let Some(&c) = points.first() else {
        return Vec::new();
    };
    let d2 = |p: &Point3| (0..3).map(|i| (p[i] - c[i]).powi(2)).sum::<f64>();
    let mut sorted: Vec<&Point3> = points.iter().collect();
    sorted.sort_by(|a, b| d2(a).total_cmp(&d2(b)));
    sorted.into_iter().take(n).copied().collect()
}

/// A connected patch of `mesh` grown face by face from face 0 (breadth first over shared
/// vertices) until it has `max_vertices` vertices or `max_faces` faces, renumbered.
fn mesh_patch(
    mesh: &TriMesh,
    max_vertices: usize,
    max_faces: usize,
) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let nv = mesh.vertices.positions.len();
    let mut vertex_faces: Vec<Vec<usize>> = vec![Vec::new(); nv];
    for (i, f) in mesh.faces.iter().enumerate() {
        for &v in f {
            vertex_faces[v as usize].push(i);
        }
    }
    let mut new_index = vec![u32::MAX; nv];
    let mut positions = Vec::new();
    let mut faces = Vec::new();
    let mut taken = vec![false; mesh.faces.len()];
    let mut queue = std::collections::VecDeque::from([0usize]);
    if let Some(t) = taken.first_mut() {
        *t = true;
    }
    while let Some(fi) = queue.pop_front() {
        if positions.len() + 3 > max_vertices || faces.len() >= max_faces {
            break;
        }
        let f = mesh.faces[fi];
        let mut out = [0u32; 3];
        for (k, &v) in f.iter().enumerate() {
            let v = v as usize;
            if new_index[v] == u32::MAX {
                new_index[v] = positions.len() as u32;
                positions.push(mesh.vertices.positions[v]);
            }
            out[k] = new_index[v];
            for &g in &vertex_faces[v] {
                if !taken[g] {
                    taken[g] = true;
                    queue.push_back(g);
                }
            }
        }
        faces.push(out);
    }
    (positions, faces)
}

/// Small files written by crease's writers in every format and encoding.
fn write_samples(dir: &Path) -> Res<()> {
    let part = crease::synth::sample_points(
        &crease::synth::Shape::default_cube(),
        &crease::synth::SampleParams {
            n: 60,
            ..Default::default()
        },
    )?;
    let cloud = part.cloud;
    let m = crease::synth::mesh(
        &crease::synth::Shape::default_cube(),
        &crease::synth::MeshParams {
            target_edge: Some(0.5),
            ..Default::default()
        },
    )?;
    let mut mesh = Geometry::from_mesh(m.mesh);
    // An edge element with attributes and a closed polyline, as `crease edges` / `lines` write.
    mesh.edges = vec![[0, 1], [1, 2]];
    mesh.edge_attributes
        .insert(2, Attribute::flag("sharp", [true, false]))?;
    mesh.edge_attributes
        .insert(2, Attribute::float("sharpness", vec![30.0, 2.5]))?;
    let mut lines = Geometry::from_cloud(PointCloud::from_positions(
        mesh.points.positions.iter().take(6).copied().collect(),
    ));
    lines.polylines = vec![vec![0, 1, 2, 0], vec![3, 4, 5]];
    lines.polyline_groups = vec!["sharp".into(), "smooth".into()];

    let cloud = Geometry::from_cloud(cloud);
    let binary = WriteOptions { ascii: false };
    let ascii = WriteOptions { ascii: true };
    let jobs: &[(&str, &Geometry, &WriteOptions)] = &[
        ("cloud-binary.ply", &cloud, &binary),
        ("cloud-ascii.ply", &cloud, &ascii),
        ("mesh-binary.ply", &mesh, &binary),
        ("mesh-ascii.ply", &mesh, &ascii),
        ("lines.ply", &lines, &ascii),
        ("mesh.obj", &mesh, &ascii),
        ("lines.obj", &lines, &ascii),
        ("mesh.off", &mesh, &ascii),
        ("mesh-binary.stl", &mesh, &binary),
        ("mesh-ascii.stl", &mesh, &ascii),
        ("cloud.xyz", &cloud, &ascii),
        ("cloud.csv", &cloud, &ascii),
        ("cloud-binary.pcd", &cloud, &binary),
        ("cloud-ascii.pcd", &cloud, &ascii),
        ("cloud.las", &cloud, &binary),
        ("cloud.laz", &cloud, &binary),
        ("cloud.e57", &cloud, &binary),
    ];
    for (name, geom, opts) in jobs {
        crease::io::write(dir.join(name), geom, opts)?;
    }
    let be = crease::io::ply::to_bytes(&mesh, crease::io::ply::PlyEncoding::BinaryBigEndian)?;
    std::fs::write(dir.join("mesh-be.ply"), be)?;
    if let Some(bytes) = pcd_compressed(&cloud.points.positions) {
        std::fs::write(dir.join("cloud-compressed.pcd"), bytes)?;
    }
    Ok(())
}

/// An organised `binary_compressed` PCD of `points` (x y z as F4, field after field, LZF),
/// with every fifth point missing (NaN), as depth cameras write; `None` if LZF cannot shrink it.
fn pcd_compressed(points: &[Point3]) -> Option<Vec<u8>> {
    let width = 10;
    let height = points.len() / width;
    let n = width * height;
    let mut raw = Vec::with_capacity(n * 12);
    for k in 0..3 {
        for (i, p) in points.iter().take(n).enumerate() {
            let v = if i % 5 == 0 { f32::NAN } else { p[k] as f32 };
            raw.extend_from_slice(&v.to_le_bytes());
        }
    }
    let packed = lzf::compress(&raw).ok()?;
    let mut out = format!(
        "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n\
         TYPE F F F\nCOUNT 1 1 1\nWIDTH {width}\nHEIGHT {height}\nVIEWPOINT 0 0 0 1 0 0 0\n\
         POINTS {n}\nDATA binary_compressed\n"
    )
    .into_bytes();
    out.extend_from_slice(&(packed.len() as u32).to_le_bytes());
    out.extend_from_slice(&(raw.len() as u32).to_le_bytes());
    out.extend_from_slice(&packed);
    Some(out)
}
