//! Shared code of the crease fuzz targets (`fuzz_targets/*.rs`) and of the seed generator
//! (`src/bin/seedgen.rs`): how a target turns its input bytes into a file for a reader, a point
//! set or a triangle mesh, and the inverse encodings the seed generator writes.
//!
//! Input layouts (every target reads a leading "variant" byte first, which picks CLI options):
//!
//! * points: a mode byte, then
//!   - 0: raw `f32` LE triples (a point with a non-finite coordinate is skipped),
//!   - 1: raw `f64` LE triples (same),
//!   - 2: a grid: `f32` scale, 3 × `f32` offset, then `i8` triples: coordinates `q · scale +
//!     offset` (duplicates, collinear and coplanar sets, any scale),
//!   - 3: a synthetic part (`crease::synth::sample_points`): shape, count, noise, outliers,
//!     seed, then scale and offset, then raw `f32` triples appended as stray points;
//! * meshes: a mode byte, then
//!   - 0: vertex count `u16`, coordinate kind byte (0 raw `f32`, else `f32` scale + `i8`
//!     triples), vertices, then `u16` LE face index triples taken modulo the vertex count
//!     (degenerate, duplicate, flipped and non-manifold faces all happen),
//!   - 1: a synthetic tessellated part (`crease::synth::mesh`), then edits from the rest of
//!     the bytes (flip, drop or duplicate a face, move or merge a vertex, add a face).
//!
//! At most [`MAX_POINTS`] points, [`MAX_VERTICES`] mesh vertices and [`MAX_FACES`] faces are
//! made (meshes are smaller: every mesh path is slower per vertex than the cloud paths).
//!
//! Every target runs its body in [`guarded`]: crease turns a panic of a third-party decoder
//! (the `las` / `laz` and `e57` crates) into an error with `catch_unwind`, which libFuzzer's
//! panic hook would report as a crash all the same.

use std::backtrace::Backtrace;
use std::panic::{self, AssertUnwindSafe, PanicHookInfo};
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

use crease::geometry::{Point3, TriMesh};
use crease::synth::{Noise, NoiseScale, Shape};

/// The largest point set a point target builds.
pub const MAX_POINTS: usize = 2000;
/// The largest vertex count a mesh target builds.
pub const MAX_VERTICES: usize = 1000;
/// The largest face count a mesh target builds.
pub const MAX_FACES: usize = 2000;

/// A cursor over the fuzz input; reading past the end gives zeros.
#[derive(Debug, Clone)]
pub struct Bytes<'a> {
    data: &'a [u8],
}

impl<'a> Bytes<'a> {
    /// A cursor at the start of `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Bytes { data }
    }

    /// Bytes left.
    pub fn len(&self) -> usize {
        self.data.len()
    }

    /// True when no byte is left.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The next `N` bytes, zero-padded at the end of the input.
    pub fn array<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        let n = N.min(self.data.len());
        out[..n].copy_from_slice(&self.data[..n]);
        self.data = &self.data[n..];
        out
    }

    /// The next byte.
    pub fn u8(&mut self) -> u8 {
        self.array::<1>()[0]
    }

    /// The next little-endian `u16`.
    pub fn u16(&mut self) -> u16 {
        u16::from_le_bytes(self.array())
    }

    /// The next little-endian `f32`, widened.
    pub fn f32(&mut self) -> f64 {
        f64::from(f32::from_le_bytes(self.array()))
    }

    /// The next little-endian `f64`.
    pub fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.array())
    }

    /// The next `f32`, or `default` where it is not finite.
    pub fn finite_f32_or(&mut self, default: f64) -> f64 {
        let v = self.f32();
        if v.is_finite() {
            v
        } else {
            default
        }
    }
}

/// The last panic raised outside crease's and the harness' own code, kept until it is known
/// whether crease caught it.
static FOREIGN_PANIC: Mutex<Option<(String, Backtrace)>> = Mutex::new(None);

/// True when the panic was raised in crease or in this harness (a bug, caught or not).
fn is_ours(info: &PanicHookInfo) -> bool {
    info.location().is_some_and(|l| {
        let f = l.file().replace('\\', "/");
        f.contains("crates/crease/src/") || f.contains("fuzz/src/") || f.contains("fuzz_targets/")
    })
}

/// Runs a target's body. A panic in crease's (or the harness') code is a crash at once, even
/// where crease would catch it; a panic elsewhere (a dependency, the standard library) is a
/// crash only when it escapes `body`, and is then reported with its message and backtrace.
pub fn guarded(body: impl FnOnce()) {
    static HOOK: OnceLock<()> = OnceLock::new();
    HOOK.get_or_init(|| {
        // libFuzzer's hook (set before the first input): print, then abort.
        let crash = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            if is_ours(info) {
                crash(info);
            } else {
                let mut last = FOREIGN_PANIC.lock().unwrap_or_else(|e| e.into_inner());
                *last = Some((info.to_string(), Backtrace::force_capture()));
            }
        }));
    });
    *FOREIGN_PANIC.lock().unwrap_or_else(|e| e.into_inner()) = None;
    if panic::catch_unwind(AssertUnwindSafe(body)).is_err() {
        let last = FOREIGN_PANIC
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take();
        match last {
            Some((message, backtrace)) => eprintln!("{message}\nstack backtrace:\n{backtrace}"),
            None => eprintln!("a panic escaped the target (no message recorded)"),
        }
        std::process::abort();
    }
}

/// Where the reader targets write their input: `$CREASE_FUZZ_TMP` (set by `scripts/fuzz.sh`),
/// else `/dev/shm` when it exists (no disk writes), else the system temp folder; one folder per
/// process, made once and reused by every run.
fn scratch_dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let base = std::env::var_os("CREASE_FUZZ_TMP")
            .map(PathBuf::from)
            .or_else(|| {
                let shm = PathBuf::from("/dev/shm");
                shm.is_dir().then_some(shm)
            })
            .unwrap_or_else(std::env::temp_dir);
        let dir = base.join(format!("crease-fuzz-{}", std::process::id()));
        if let Err(e) = std::fs::create_dir_all(&dir) {
            panic!("harness: cannot create {}: {e}", dir.display());
        }
        dir
    })
}

/// Writes `data` to this process' scratch file with extension `ext` and reads it with
/// `crease::io::read`, then runs what `crease info` and `crease convert` do with the result:
/// the summaries and a PLY encoding. `--strict` only changes what happens to points with
/// non-finite coordinates, so the file is read strictly too when it has some.
pub fn read_as(ext: &str, data: &[u8]) {
    let path = scratch_dir().join(format!("input.{ext}"));
    if let Err(e) = std::fs::write(&path, data) {
        panic!("harness: cannot write {}: {e}", path.display());
    }
    let lenient = crease::io::ReadOptions { strict: false };
    let Ok((geom, report)) = crease::io::read(&path, &lenient) else {
        return;
    };
    if report.dropped_nonfinite > 0 {
        let _ = crease::io::read(&path, &crease::io::ReadOptions { strict: true });
    }
    let _ = crease::io::summary::summarize(&geom, &report);
    let _ = crease::io::ply::to_bytes(&geom, crease::io::ply::PlyEncoding::BinaryLittleEndian);
    if let Some(mesh) = geom.into_mesh() {
        let _ = crease::io::summary::summarize_mesh(&mesh);
    }
}

/// Pushes `p` if every coordinate is finite and there is room.
fn push_finite(out: &mut Vec<Point3>, p: Point3) {
    if out.len() < MAX_POINTS && p.iter().all(|c| c.is_finite()) {
        out.push(p);
    }
}

/// The shapes `crease::synth` knows, in a fixed order.
fn shape(b: &mut Bytes) -> Shape {
    let names = Shape::names();
    let name = names[usize::from(b.u8()) % names.len()];
    Shape::from_name(name).unwrap_or_else(Shape::default_cube)
}

/// Noise from one byte: none, along the normal or isotropic, up to 0.5 spacing.
fn noise(byte: u8) -> Noise {
    let sigma = f64::from(byte & 0x3f) / 126.0;
    match byte >> 6 {
        0 => Noise::None,
        1 | 2 => Noise::Isotropic(sigma),
        _ => Noise::AlongNormal(sigma),
    }
}

/// A scale (finite, non-zero) and an offset (finite) from the input.
fn transform(b: &mut Bytes) -> (f64, Point3) {
    let mut scale = b.finite_f32_or(1.0);
    if scale == 0.0 {
        scale = 1.0;
    }
    let offset = [
        b.finite_f32_or(0.0),
        b.finite_f32_or(0.0),
        b.finite_f32_or(0.0),
    ];
    (scale, offset)
}

/// A finite point set of at most [`MAX_POINTS`] points (see the module documentation).
pub fn points(b: &mut Bytes) -> Vec<Point3> {
    let mut out = Vec::new();
    match b.u8() % 4 {
        0 => {
            while b.len() >= 12 && out.len() < MAX_POINTS {
                let p = [b.f32(), b.f32(), b.f32()];
                push_finite(&mut out, p);
            }
        }
        1 => {
            while b.len() >= 24 && out.len() < MAX_POINTS {
                let p = [b.f64(), b.f64(), b.f64()];
                push_finite(&mut out, p);
            }
        }
        2 => {
            let (scale, o) = transform(b);
            while b.len() >= 3 && out.len() < MAX_POINTS {
                let q = b.array::<3>().map(|v| f64::from(v as i8));
                push_finite(
                    &mut out,
                    [
                        q[0] * scale + o[0],
                        q[1] * scale + o[1],
                        q[2] * scale + o[2],
                    ],
                );
            }
        }
        _ => {
            let shape = shape(b);
            let n = 1 + usize::from(b.u16()) % MAX_POINTS;
            let params = crease::synth::SampleParams {
                n,
                noise: noise(b.u8()),
                noise_scale: NoiseScale::Spacing,
                outliers: f64::from(b.u8() % 64) / 256.0,
                seed: u64::from(b.u8()),
                sharp_tolerance: None,
            };
            let (scale, o) = transform(b);
            if let Ok(part) = crease::synth::sample_points(&shape, &params) {
                for p in part.cloud.positions {
                    push_finite(
                        &mut out,
                        [
                            p[0] * scale + o[0],
                            p[1] * scale + o[1],
                            p[2] * scale + o[2],
                        ],
                    );
                }
            }
            while b.len() >= 12 && out.len() < MAX_POINTS {
                let p = [b.f32(), b.f32(), b.f32()];
                push_finite(&mut out, p);
            }
        }
    }
    out
}

/// Stored normals for a cloud, as a file may hold them, chosen by bits 5 and 6 of `variant`:
/// none; unit vectors; raw vectors (some zero); raw vectors with every seventh NaN (readers
/// drop points with non-finite positions, not normals). Made from the coordinates, permuted.
pub fn stored_normals(variant: u8, points: &[Point3]) -> Option<Vec<Point3>> {
    let kind = (variant >> 5) % 4;
    if kind == 0 {
        return None;
    }
    let normals = points
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let v = [p[1], p[2], p[0]];
            match kind {
                1 => {
                    let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                    if len > 0.0 && len.is_finite() {
                        v.map(|c| c / len)
                    } else {
                        [0.0, 0.0, 1.0]
                    }
                }
                3 if i % 7 == 0 => [f64::NAN; 3],
                _ => v,
            }
        })
        .collect();
    Some(normals)
}

/// A triangle mesh with finite vertices and in-range indices, of at most [`MAX_VERTICES`]
/// vertices and [`MAX_FACES`] faces (see the module documentation); `None` when the input
/// makes no vertex.
pub fn mesh(b: &mut Bytes) -> Option<TriMesh> {
    let (positions, faces) = match b.u8() % 2 {
        0 => raw_mesh(b),
        _ => synthetic_mesh(b)?,
    };
    if positions.is_empty() {
        return None;
    }
    TriMesh::new(positions, faces).ok()
}

/// Mode 0 of [`mesh`].
fn raw_mesh(b: &mut Bytes) -> (Vec<Point3>, Vec<[u32; 3]>) {
    let wanted = usize::from(b.u16()) % (MAX_VERTICES + 1);
    let mut positions = Vec::with_capacity(wanted);
    if b.u8() & 1 == 0 {
        while positions.len() < wanted && b.len() >= 12 {
            let p = [b.f32(), b.f32(), b.f32()];
            positions.push(p.map(|c| if c.is_finite() { c } else { 0.0 }));
        }
    } else {
        let (scale, o) = transform(b);
        while positions.len() < wanted && b.len() >= 3 {
            let q = b.array::<3>().map(|v| f64::from(v as i8));
            let p = [
                q[0] * scale + o[0],
                q[1] * scale + o[1],
                q[2] * scale + o[2],
            ];
            positions.push(p.map(|c| if c.is_finite() { c } else { 0.0 }));
        }
    }
    let n = positions.len() as u32;
    let mut faces = Vec::new();
    if n > 0 {
        while b.len() >= 6 && faces.len() < MAX_FACES {
            faces.push([
                u32::from(b.u16()) % n,
                u32::from(b.u16()) % n,
                u32::from(b.u16()) % n,
            ]);
        }
    }
    (positions, faces)
}

/// Mode 1 of [`mesh`].
fn synthetic_mesh(b: &mut Bytes) -> Option<(Vec<Point3>, Vec<[u32; 3]>)> {
    let shape = shape(b);
    let aabb = shape.aabb();
    let extent = (0..3)
        .map(|i| aabb.max[i] - aabb.min[i])
        .fold(0.0f64, f64::max);
    let divisions = 3.0 + f64::from(b.u8() % 10);
    let params = crease::synth::MeshParams {
        target_edge: Some(extent / divisions),
        noise: noise(b.u8()),
        noise_scale: NoiseScale::Spacing,
        seed: u64::from(b.u8()),
        sharp_tolerance: None,
    };
    let (scale, o) = transform(b);
    let m = crease::synth::mesh(&shape, &params).ok()?;
    let mut positions: Vec<Point3> = m
        .mesh
        .vertices
        .positions
        .iter()
        .map(|p| {
            [
                p[0] * scale + o[0],
                p[1] * scale + o[1],
                p[2] * scale + o[2],
            ]
            .map(|c| if c.is_finite() { c } else { 0.0 })
        })
        .collect();
    let mut faces = m.mesh.faces;
    if positions.len() > MAX_VERTICES || faces.len() > MAX_FACES || positions.is_empty() {
        return None;
    }
    // Edits, 5 bytes each: kind, then two u16 operands.
    while b.len() >= 5 {
        let kind = b.u8();
        let (x, y) = (usize::from(b.u16()), usize::from(b.u16()));
        let nv = positions.len();
        let nf = faces.len();
        match kind % 6 {
            0 if nf > 0 => faces[x % nf].swap(1, 2),
            1 if nf > 0 => {
                faces.swap_remove(x % nf);
            }
            2 if nf > 0 && nf < MAX_FACES => faces.push(faces[x % nf]),
            3 => {
                // Move a vertex by up to ±1 (in the part's size, before the transform) × scale.
                let d = f64::from(y as u16 as i16) / 32768.0 * scale;
                positions[x % nv][y % 3] += d;
            }
            4 => {
                // Merge vertex y into x: every face corner on y now uses x.
                let (keep, gone) = ((x % nv) as u32, (y % nv) as u32);
                for f in faces.iter_mut() {
                    for v in f.iter_mut() {
                        if *v == gone {
                            *v = keep;
                        }
                    }
                }
            }
            5 if nf < MAX_FACES => {
                let c = b.u16();
                faces.push([
                    (x % nv) as u32,
                    (y % nv) as u32,
                    (usize::from(c) % nv) as u32,
                ]);
            }
            _ => {}
        }
    }
    Some((positions, faces))
}

/// Seed encodings: the inverse of [`points`] and [`mesh`] for real data, used by the seed
/// generator.
pub mod encode {
    use super::{Point3, MAX_FACES, MAX_POINTS, MAX_VERTICES};

    /// `variant`, mode 0 (raw `f32`), then the points (at most [`MAX_POINTS`]).
    pub fn points(variant: u8, points: &[Point3]) -> Vec<u8> {
        let mut out = vec![variant, 0];
        for p in points.iter().take(MAX_POINTS) {
            for c in p {
                out.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        }
        out
    }

    /// `variant`, mode 3 (synthetic part): shape index, count, noise byte, outlier byte, seed;
    /// unit scale and zero offset.
    pub fn synthetic_points(variant: u8, shape: u8, n: u16, noise: u8, seed: u8) -> Vec<u8> {
        let mut out = vec![variant, 3, shape];
        out.extend_from_slice(&n.to_le_bytes());
        out.extend_from_slice(&[noise, 0, seed]);
        out.extend_from_slice(&1f32.to_le_bytes());
        out.extend_from_slice(&[0u8; 12]);
        out
    }

    /// `variant`, mode 0 (raw mesh), `f32` vertices, `u16` faces; `None` when the mesh is too
    /// big for the layout.
    pub fn mesh(variant: u8, positions: &[Point3], faces: &[[u32; 3]]) -> Option<Vec<u8>> {
        if positions.len() > MAX_VERTICES || faces.len() > MAX_FACES {
            return None;
        }
        let mut out = vec![variant, 0];
        out.extend_from_slice(&(positions.len() as u16).to_le_bytes());
        out.push(0);
        for p in positions {
            for c in p {
                out.extend_from_slice(&(*c as f32).to_le_bytes());
            }
        }
        for f in faces {
            for &v in f {
                out.extend_from_slice(&(v as u16).to_le_bytes());
            }
        }
        Some(out)
    }

    /// `variant`, mode 1 (synthetic mesh): shape index, divisions byte, noise byte, seed; unit
    /// scale and zero offset; no edits.
    pub fn synthetic_mesh(variant: u8, shape: u8, divisions: u8, noise: u8, seed: u8) -> Vec<u8> {
        let mut out = vec![variant, 1, shape, divisions, noise, seed];
        out.extend_from_slice(&1f32.to_le_bytes());
        out.extend_from_slice(&[0u8; 12]);
        out
    }
}
