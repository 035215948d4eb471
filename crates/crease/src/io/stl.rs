//! STL reading (ASCII and binary) and writing.
//!
//! Our own reader rather than `stl_io` 0.11: stl_io decides ASCII vs binary by the `solid `
//! prefix alone, so binary files whose 80-byte header starts with `solid` (several CAD
//! exporters write that) fail to load; its ASCII errors carry no line number; it refuses
//! NaN coordinates instead of letting the caller drop them; it stores `f32` even for ASCII
//! input. (Its binary reader does not allocate from the header count, and it does not panic on
//! garbage.) The format is simple enough that a direct reader is shorter than the adaptation.
//!
//! # Reading
//! - Binary when the size is exactly `84 + 50·n` bytes for the count `n` in bytes 80..84
//!   (checked first, whatever the header text says). A file starting with `solid` and with no
//!   NUL byte in its first kilobyte is otherwise read as ASCII; anything else of 84 bytes or more is binary whose size does not match its
//!   count: too short is an error (truncated), longer is read with a note about the trailing
//!   bytes.
//! - ASCII: `solid [name]`, then `facet normal nx ny nz` / `outer loop` / `vertex x y z` ... /
//!   `endloop` / `endfacet` blocks, `endsolid`; keywords case-insensitive; several solids in
//!   one file are concatenated; a loop of more than 3 vertices is fan-triangulated. Errors name
//!   the line.
//! - Facet normals and the binary attribute bytes are ignored (crease recomputes normals).
//! - STL is a triangle soup: corners with exactly the same coordinates are merged into one
//!   vertex (`-0.0` equals `0.0`), numbered in order of first appearance; the report says how
//!   many corners were merged. Faces with NaN coordinates are dropped by [`crate::io::read`].
//!
//! # Writing
//! Binary by default (coordinates rounded to `f32`, as binary STL stores them), ASCII with
//! [`WriteOptions::ascii`] (coordinates exact). Facet normals are computed from the corners.
//! A geometry without triangles is refused.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};
use std::io::Write;
use std::path::Path;

use rayon::prelude::*;

use super::xyz::{lossy, next_line, parse_f64, push_f64, tokens};
use super::{create, read_bytes, Geometry, ReadReport, WriteOptions};
use crate::geometry::PointCloud;
use crate::{Error, Result};

/// Reads an ASCII or binary STL file and merges coincident corners into an indexed mesh.
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    let bytes = read_bytes(path)?;
    parse(path, &bytes)
}

/// Writes the triangles of `geom` as binary STL, or ASCII STL with `opts.ascii`.
pub fn write(path: &Path, geom: &Geometry, opts: &WriteOptions) -> Result<()> {
    if geom.faces.is_empty() {
        return Err(Error::Unsupported {
            path: path.to_path_buf(),
            message: "STL holds triangles; this geometry has none".into(),
        });
    }
    let n = u32::try_from(geom.faces.len()).map_err(|_| Error::Unsupported {
        path: path.to_path_buf(),
        message: format!(
            "binary STL holds at most {} triangles; this mesh has {}",
            u32::MAX,
            geom.faces.len()
        ),
    })?;
    let io = |e| Error::io(path, e);
    let p = &geom.points.positions;
    let mut w = create(path)?;
    if opts.ascii {
        writeln!(w, "solid crease").map_err(io)?;
        super::xyz::write_lines_parallel(&mut w, geom.faces.len(), |i, out| {
            let t = geom.faces[i].map(|v| p[v as usize]);
            out.extend_from_slice(b"facet normal");
            for c in facet_normal(&t) {
                out.push(b' ');
                push_f64(out, c);
            }
            out.extend_from_slice(b"\n  outer loop\n");
            for v in t {
                out.extend_from_slice(b"    vertex");
                for c in v {
                    out.push(b' ');
                    push_f64(out, c);
                }
                out.push(b'\n');
            }
            out.extend_from_slice(b"  endloop\nendfacet\n");
        })
        .map_err(io)?;
        writeln!(w, "endsolid crease").map_err(io)?;
    } else {
        let mut header = [b' '; 80];
        let text = b"binary STL written by crease";
        header[..text.len()].copy_from_slice(text);
        w.write_all(&header).map_err(io)?;
        w.write_all(&n.to_le_bytes()).map_err(io)?;
        super::xyz::write_lines_parallel(&mut w, geom.faces.len(), |i, out| {
            let t = geom.faces[i].map(|v| p[v as usize]);
            for c in facet_normal(&t) {
                out.extend_from_slice(&(c as f32).to_le_bytes());
            }
            for v in t {
                for c in v {
                    out.extend_from_slice(&(c as f32).to_le_bytes());
                }
            }
            out.extend_from_slice(&[0, 0]);
        })
        .map_err(io)?;
    }
    w.flush().map_err(io)
}

/// The unit normal of a triangle (zero for a degenerate one).
fn facet_normal(t: &[[f64; 3]; 3]) -> [f64; 3] {
    let u = [t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]];
    let v = [t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]];
    let n = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 && l.is_finite() {
        n.map(|c| c / l)
    } else {
        [0.0; 3]
    }
}

/// Parses the bytes of an STL file; `path` is used in messages only.
pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(Geometry, ReadReport)> {
    if bytes.is_empty() {
        return Err(Error::format(
            path,
            "no triangles: the file is empty (expected ASCII STL starting with 'solid' or binary STL)",
        ));
    }
    let mut report = ReadReport::default();
    let count = bytes
        .get(80..84)
        .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as u64);
    let expected = count.map(|n| 84 + 50 * n);
    let corners = if expected == Some(bytes.len() as u64) {
        report.encoding = "binary".into();
        binary_corners(bytes, count.unwrap_or(0) as usize)
    } else if starts_with_solid(bytes) && !bytes[..bytes.len().min(1024)].contains(&0) {
        report.encoding = "ascii".into();
        ascii_corners(path, bytes, &mut report)?
    } else {
        let (Some(n), Some(expected)) = (count, expected) else {
            return Err(Error::format(
                path,
                format!(
                    "not an STL file: {} bytes, too short for binary STL (84-byte header) and not ASCII STL (does not start with 'solid')",
                    bytes.len()
                ),
            ));
        };
        let len = bytes.len() as u64;
        if expected > len {
            return Err(Error::format(
                path,
                format!(
                    "binary STL: the header announces {n} triangles ({expected} bytes) but the file has only {len} bytes; the file is truncated or not an STL file"
                ),
            ));
        }
        report.encoding = "binary".into();
        report.notes.push(format!(
            "{} bytes after the {n} announced triangles were ignored",
            len - expected
        ));
        binary_corners(bytes, n as usize)
    };
    if corners.is_empty() {
        return Err(Error::format(
            path,
            format!(
                "no triangles: the {} STL file holds no facets",
                report.encoding
            ),
        ));
    }
    if corners.len() / 3 > u32::MAX as usize {
        return Err(Error::format(
            path,
            "too many triangles for crease (over 2^32 corners)",
        ));
    }
    let (positions, faces) = merge_corners(&corners);
    report.notes.push(format!(
        "STL is a triangle soup: {} corners merged into {} vertices ({} corners shared a position with an earlier one)",
        corners.len(),
        positions.len(),
        corners.len() - positions.len()
    ));
    Ok((
        Geometry {
            points: PointCloud::from_positions(positions),
            faces,
            ..Default::default()
        },
        report,
    ))
}

/// True if the file starts (after blanks) with the keyword `solid`.
fn starts_with_solid(bytes: &[u8]) -> bool {
    let t = bytes.trim_ascii_start();
    t.len() >= 5
        && t[..5].eq_ignore_ascii_case(b"solid")
        && t.get(5).is_none_or(|b| b.is_ascii_whitespace())
}

/// The corners of the first `n` triangles of a binary STL whose size was checked to hold them.
fn binary_corners(bytes: &[u8], n: usize) -> Vec<[f64; 3]> {
    let body = bytes.get(84..84 + 50 * n).unwrap_or(&[]);
    let mut corners = vec![[0.0f64; 3]; 3 * n];
    corners
        .par_chunks_mut(3)
        .zip(body.par_chunks_exact(50))
        .for_each(|(out, r)| {
            let f = |o: usize| f64::from(f32::from_le_bytes([r[o], r[o + 1], r[o + 2], r[o + 3]]));
            out[0] = [f(12), f(16), f(20)];
            out[1] = [f(24), f(28), f(32)];
            out[2] = [f(36), f(40), f(44)];
        });
    corners
}

/// The corners of an ASCII STL (fan-triangulating loops of more than 3 vertices).
fn ascii_corners(path: &Path, bytes: &[u8], report: &mut ReadReport) -> Result<Vec<[f64; 3]>> {
    let at = |line: usize, msg: String| Error::format(path, format!("line {line}: {msg}"));
    let mut corners = Vec::new();
    let mut pos = 0;
    let mut line_no = 0;
    let mut next = || -> Option<(usize, &[u8])> {
        while pos < bytes.len() {
            let (l, n) = next_line(bytes, pos);
            pos = n;
            line_no += 1;
            let l = l.trim_ascii();
            if !l.is_empty() {
                return Some((line_no, l));
            }
        }
        None
    };
    let kw = |l: &[u8], k: &[u8]| -> bool {
        tokens(l).next().is_some_and(|t| t.eq_ignore_ascii_case(k))
    };
    let mut in_solid = false;
    let mut polygons = 0usize;
    let mut loop_pts: Vec<[f64; 3]> = Vec::with_capacity(4);
    loop {
        let Some((ln, l)) = next() else {
            if in_solid {
                report.notes.push("the file ends without 'endsolid'".into());
            }
            break;
        };
        if !in_solid {
            if kw(l, b"solid") {
                in_solid = true;
                continue;
            }
            return Err(at(
                ln,
                format!(
                    "expected 'solid' or the end of the file, found '{}'",
                    lossy(l)
                ),
            ));
        }
        if kw(l, b"endsolid") {
            in_solid = false;
            continue;
        }
        if !kw(l, b"facet") {
            return Err(at(
                ln,
                format!(
                    "expected 'facet normal nx ny nz' or 'endsolid', found '{}'",
                    lossy(l)
                ),
            ));
        }
        match next() {
            Some((_, l)) if kw(l, b"outer") => {}
            Some((ln, l)) => {
                return Err(at(
                    ln,
                    format!("expected 'outer loop', found '{}'", lossy(l)),
                ))
            }
            None => return Err(at(ln, "the file ends inside a facet".into())),
        }
        loop_pts.clear();
        loop {
            let Some((ln, l)) = next() else {
                return Err(at(
                    ln,
                    "the file ends inside a facet (expected 'vertex x y z' or 'endloop')".into(),
                ));
            };
            if kw(l, b"endloop") {
                if loop_pts.len() < 3 {
                    return Err(at(
                        ln,
                        format!("a facet needs 3 vertices, found {}", loop_pts.len()),
                    ));
                }
                break;
            }
            let mut t = tokens(l);
            if !t.next().is_some_and(|k| k.eq_ignore_ascii_case(b"vertex")) {
                return Err(at(
                    ln,
                    format!("expected 'vertex x y z' or 'endloop', found '{}'", lossy(l)),
                ));
            }
            let mut v = [0.0; 3];
            let mut k = 0;
            for tok in t {
                let x = parse_f64(tok).ok_or_else(|| {
                    at(
                        ln,
                        format!(
                            "expected 3 coordinates after 'vertex', found '{}'",
                            lossy(tok)
                        ),
                    )
                })?;
                if k < 3 {
                    v[k] = x;
                }
                k += 1;
            }
            if k != 3 {
                return Err(at(
                    ln,
                    format!("expected 3 coordinates after 'vertex', found {k}"),
                ));
            }
            loop_pts.push(v);
        }
        match next() {
            Some((_, l)) if kw(l, b"endfacet") => {}
            Some((ln, l)) => {
                return Err(at(ln, format!("expected 'endfacet', found '{}'", lossy(l))))
            }
            None => {
                return Err(at(
                    ln,
                    "the file ends inside a facet (expected 'endfacet')".into(),
                ))
            }
        }
        if loop_pts.len() > 3 {
            polygons += 1;
        }
        for j in 1..loop_pts.len() - 1 {
            corners.extend_from_slice(&[loop_pts[0], loop_pts[j], loop_pts[j + 1]]);
        }
    }
    report.polygons_triangulated += polygons;
    Ok(corners)
}

/// Merges corners with identical coordinates (bit patterns, `-0.0` folded into `0.0`).
/// Returns the vertices in order of first appearance and one triangle per three corners.
fn merge_corners(corners: &[[f64; 3]]) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut index: HashMap<Key, u32, BuildHasherDefault<Mix>> =
        HashMap::with_capacity_and_hasher(corners.len() / 6 + 16, Default::default());
    let mut positions = Vec::with_capacity(corners.len() / 6 + 16);
    let mut ids = Vec::with_capacity(corners.len());
    for c in corners {
        let key = Key(c.map(|x| if x == 0.0 { 0 } else { x.to_bits() }));
        let next = positions.len() as u32;
        let id = *index.entry(key).or_insert(next);
        if id == next {
            positions.push(*c);
        }
        ids.push(id);
    }
    let faces = ids.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    (positions, faces)
}

/// A corner's coordinates as bit patterns, hashed as three words.
#[derive(PartialEq, Eq)]
struct Key([u64; 3]);

impl Hash for Key {
    fn hash<H: Hasher>(&self, h: &mut H) {
        for w in self.0 {
            h.write_u64(w);
        }
    }
}

/// A small fast hasher for [`Key`]: multiply-rotate mixing, splitmix64 finaliser (so that keys
/// differing only in exponent bits still spread over the table).
#[derive(Default)]
struct Mix(u64);

impl Hasher for Mix {
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.write_u64(u64::from(*b));
        }
    }
    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(23) ^ x).wrapping_mul(0x9e37_79b9_7f4a_7c15);
    }
    fn finish(&self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}
