//! I/O benchmarks: reading and writing point clouds and triangle meshes, per format.
//!
//! Each case is a geometry (a cloud of N points with normals and colours, or a grid mesh of about
//! N triangles) and each format is an extension plus write options; every (case, format) pair
//! gets a write and a read benchmark through `crease::io::write` / `crease::io::read`, so adding a
//! format (OBJ, STL, ...) is one line in `FORMATS`. One more case reads a PLY written the way most
//! tools write scans (float x y z nx ny nz, uchar red green blue), the reader's speed target.
//!
//! Run with `cargo bench -p crease --bench io`.

use std::hint::black_box;
use std::io::Write;
use std::path::{Path, PathBuf};

use crease::io::{Geometry, ReadOptions, WriteOptions};
use crease::PointCloud;
use criterion::{criterion_group, criterion_main, Criterion};

/// The formats benchmarked: (label, extension, write options, holds meshes).
const FORMATS: &[(&str, &str, bool, bool)] = &[
    ("ply-binary", "ply", false, true),
    ("ply-ascii", "ply", true, true),
];

/// Deterministic pseudo-random numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// `n` points on the unit sphere with normals and colours.
fn cloud(n: usize) -> Geometry {
    let mut rng = Lcg(7);
    let mut pos = Vec::with_capacity(n);
    let mut nor = Vec::with_capacity(n);
    let mut col = Vec::with_capacity(n);
    for i in 0..n {
        let z = 2.0 * rng.next() - 1.0;
        let t = std::f64::consts::TAU * rng.next();
        let r = (1.0 - z * z).sqrt();
        let p = [r * t.cos(), r * t.sin(), z];
        pos.push(p);
        nor.push(p);
        col.push([(i % 256) as u8, 128, 255]);
    }
    let mut pc = PointCloud::from_positions(pos);
    pc.set_normals(nor).expect("normals");
    pc.set_colors(col).expect("colours");
    Geometry::from_cloud(pc)
}

/// A height-field grid mesh with about `triangles` triangles.
fn grid_mesh(triangles: usize) -> Geometry {
    let side = ((triangles as f64 / 2.0).sqrt().ceil() as usize).max(1);
    let v = side + 1;
    let mut pos = Vec::with_capacity(v * v);
    for j in 0..v {
        for i in 0..v {
            let (x, y) = (i as f64 / side as f64, j as f64 / side as f64);
            pos.push([x, y, 0.1 * (6.0 * x).sin() * (4.0 * y).cos()]);
        }
    }
    let mut faces = Vec::with_capacity(2 * side * side);
    for j in 0..side {
        for i in 0..side {
            let a = (j * v + i) as u32;
            let b = a + 1;
            let c = a + v as u32;
            let d = c + 1;
            faces.push([a, b, d]);
            faces.push([a, d, c]);
        }
    }
    Geometry {
        points: PointCloud::from_positions(pos),
        faces,
        ..Default::default()
    }
}

/// A binary little-endian PLY of `n` points with float x y z nx ny nz and uchar red green blue,
/// written byte by byte (not by crease), as scanners and Open3D-like tools write them.
fn write_float_ply(path: &Path, n: usize) {
    let mut b = Vec::with_capacity(n * 27 + 300);
    write!(
        b,
        "ply\nformat binary_little_endian 1.0\nelement vertex {n}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n"
    )
    .expect("header");
    let mut rng = Lcg(11);
    for i in 0..n {
        for _ in 0..6 {
            b.extend_from_slice(&(rng.next() as f32).to_le_bytes());
        }
        b.extend_from_slice(&[(i % 256) as u8, 7, 9]);
    }
    std::fs::write(path, b).expect("write the float PLY");
}

fn file(dir: &Path, name: &str, ext: &str) -> PathBuf {
    dir.join(format!("{name}.{ext}"))
}

/// Write and read benchmarks of `geom` in every format of `FORMATS`.
fn bench_case(c: &mut Criterion, dir: &Path, name: &str, geom: &Geometry) {
    let mut group = c.benchmark_group(name);
    group.sample_size(10);
    for &(label, ext, ascii, meshes) in FORMATS {
        if geom.is_mesh() && !meshes {
            continue;
        }
        let path = file(dir, &format!("{name}-{label}"), ext);
        let opts = WriteOptions { ascii };
        group.bench_function(format!("write {label}"), |b| {
            b.iter(|| crease::io::write(&path, black_box(geom), &opts).expect("write"))
        });
        crease::io::write(&path, geom, &opts).expect("write");
        group.bench_function(format!("read {label}"), |b| {
            b.iter(|| {
                let (g, _) = crease::io::read(&path, &ReadOptions::default()).expect("read");
                assert_eq!(g.points.len(), geom.points.len());
                black_box(g)
            })
        });
    }
    group.finish();
}

fn benches(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary directory");
    for (label, n) in [("100k", 100_000), ("1M", 1_000_000)] {
        let path = file(dir.path(), &format!("float-{label}"), "ply");
        write_float_ply(&path, n);
        let mut group = c.benchmark_group(format!("points-{label}"));
        group.sample_size(10);
        group.bench_function("read ply-binary float xyz+normals+rgb", |b| {
            b.iter(|| {
                let (g, _) = crease::io::read(&path, &ReadOptions::default()).expect("read");
                assert_eq!(g.points.len(), n);
                black_box(g)
            })
        });
        group.finish();
        bench_case(c, dir.path(), &format!("points-{label}"), &cloud(n));
        bench_case(
            c,
            dir.path(),
            &format!("mesh-{label}-triangles"),
            &grid_mesh(n),
        );
    }
}

criterion_group!(io, benches);
criterion_main!(io);
