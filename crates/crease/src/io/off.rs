//! Object File Format (OFF, Geomview) reading and writing.
//!
//! # Reading
//! The header keyword is `[ST][C][N]OFF` (`OFF`, `COFF`, `NOFF`, `CNOFF`, `NCOFF`, `STOFF`, ...);
//! the counts `vertices faces [edges]` follow on the same line or the next one. A file starting
//! directly with the counts is accepted with a note. `4OFF`, `nOFF` and `OFF BINARY` are refused
//! as unsupported. `#` starts a comment; blank lines are skipped.
//!
//! Each vertex is one line: `x y z [nx ny nz] [r g b [a]] [s t]` as the keyword announces.
//! Normals (`N`) become per-vertex normals; colours (`C`) become colours (values written with a
//! decimal point or exponent are 0..1 floats, scaled to 0..255; integers are 0..255); texture
//! coordinates are ignored. Extra values on a plain `OFF` vertex line are ignored with a note.
//! Each face is one line `n i1 .. in [colour]`; polygons are fan-triangulated, face colours
//! ignored with a note.
//!
//! The counts are checked against the file size before anything is allocated from them (a
//! vertex line takes at least 6 bytes, a face line at least 8). Errors name the file and line.
//!
//! # Writing
//! Plain `OFF`: the vertices and the triangles. Normals, colours, edges and polylines have no
//! place in plain OFF and are not written (use PLY or OBJ to keep them).

use std::io::Write;
use std::path::Path;

use super::xyz::{lossy, next_line, parse_f64, push_f64, to_u8, tokens, write_lines_parallel};
use super::{create, read_bytes, Geometry, ReadReport, WriteOptions};
use crate::geometry::PointCloud;
use crate::{Error, Result};

/// Reads an OFF file (see the module documentation for the variants).
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    let bytes = read_bytes(path)?;
    parse(path, &bytes)
}

/// Writes the points and triangles of `geom` as plain `OFF`.
pub fn write(path: &Path, geom: &Geometry, _opts: &WriteOptions) -> Result<()> {
    let io = |e| Error::io(path, e);
    let mut w = create(path)?;
    let pts = &geom.points;
    writeln!(w, "OFF\n{} {} 0", pts.len(), geom.faces.len()).map_err(io)?;
    write_lines_parallel(&mut w, pts.len(), |i, out| {
        let p = pts.positions[i];
        push_f64(out, p[0]);
        out.push(b' ');
        push_f64(out, p[1]);
        out.push(b' ');
        push_f64(out, p[2]);
        out.push(b'\n');
    })
    .map_err(io)?;
    write_lines_parallel(&mut w, geom.faces.len(), |i, out| {
        let [a, b, c] = geom.faces[i];
        let _ = writeln!(out, "3 {a} {b} {c}");
    })
    .map_err(io)?;
    w.flush().map_err(io)
}

/// Non-blank lines with comments removed, with their 1-based line numbers.
struct Lines<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lines<'a> {
    fn next(&mut self) -> Option<(usize, &'a [u8])> {
        while self.pos < self.bytes.len() {
            let (l, next) = next_line(self.bytes, self.pos);
            self.pos = next;
            self.line += 1;
            let l = match l.iter().position(|&b| b == b'#') {
                Some(i) => &l[..i],
                None => l,
            };
            let l = l.trim_ascii();
            if !l.is_empty() {
                return Some((self.line, l));
            }
        }
        None
    }
}

/// Parses the bytes of an OFF file; `path` is used in messages only.
pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(Geometry, ReadReport)> {
    let at = |line: usize, msg: String| Error::format(path, format!("line {line}: {msg}"));
    let mut report = ReadReport {
        encoding: "ascii".into(),
        ..Default::default()
    };
    let mut lines = Lines {
        bytes,
        pos: 0,
        line: 0,
    };
    let Some((hl, header)) = lines.next() else {
        return Err(Error::format(
            path,
            "no points: the file is empty (expected an 'OFF' header)",
        ));
    };
    let mut htoks = tokens(header);
    let key = htoks.next().unwrap_or(b"");
    let (st, color, normal, counts_line): (bool, bool, bool, Vec<&[u8]>);
    if let Some(prefix) = key.strip_suffix(b"OFF") {
        let (st_, p) = match prefix.strip_prefix(b"ST") {
            Some(p) => (true, p),
            None => (false, prefix),
        };
        let (c_, n_) = match p {
            b"" => (false, false),
            b"C" => (true, false),
            b"N" => (false, true),
            b"CN" | b"NC" => (true, true),
            _ => {
                return Err(Error::Unsupported {
                    path: path.to_path_buf(),
                    message: format!(
                        "line {hl}: '{}' files (4D, n-dimensional or unknown OFF variants) are not supported; expected OFF, COFF, NOFF, CNOFF or STOFF",
                        lossy(key)
                    ),
                })
            }
        };
        let rest: Vec<&[u8]> = htoks.collect();
        if rest
            .first()
            .is_some_and(|t| t.eq_ignore_ascii_case(b"BINARY"))
        {
            return Err(Error::Unsupported {
                path: path.to_path_buf(),
                message: format!(
                    "line {hl}: binary OFF is not supported; convert it to text OFF or PLY"
                ),
            });
        }
        (st, color, normal) = (st_, c_, n_);
        counts_line = if rest.is_empty() {
            match lines.next() {
                Some((_, l)) => tokens(l).collect(),
                None => Vec::new(),
            }
        } else {
            rest
        };
    } else if parse_count(key).is_some() {
        report
            .notes
            .push("the 'OFF' keyword is missing; the first line was read as the counts".into());
        (st, color, normal) = (false, false, false);
        counts_line = tokens(header).collect();
    } else {
        return Err(at(
            hl,
            format!(
                "expected 'OFF' (or COFF, NOFF, CNOFF, STOFF), found '{}'",
                lossy(key)
            ),
        ));
    }
    let cl = lines.line;
    let counts: Vec<Option<u64>> = counts_line.iter().map(|t| parse_count(t)).collect();
    let (nv, nf) = match counts.as_slice() {
        [Some(v), Some(f)] | [Some(v), Some(f), Some(_), ..] => (*v, *f),
        _ => {
            return Err(at(
                cl,
                format!(
                    "expected the counts 'vertices faces edges' after OFF, found '{}'",
                    lossy(&counts_line.join(&b' '))
                ),
            ))
        }
    };
    if nv == 0 {
        return Err(at(cl, "no points: the header announces 0 vertices".into()));
    }
    let remaining = bytes.len().saturating_sub(lines.pos) as u128;
    let needed = u128::from(nv) * 6 + u128::from(nf) * 8;
    if needed > remaining + 1 {
        return Err(at(
            cl,
            format!(
                "the header announces {nv} vertices and {nf} faces, which need at least {needed} bytes, but only {remaining} bytes follow; the file is truncated or the counts are wrong"
            ),
        ));
    }
    let (nv, nf) = (nv as usize, nf as usize);

    let base = 3 + if normal { 3 } else { 0 } + if st { 2 } else { 0 };
    let mut positions = Vec::with_capacity(nv);
    let mut normals = Vec::with_capacity(if normal { nv } else { 0 });
    let mut colors: Vec<[f64; 3]> = Vec::with_capacity(if color { nv } else { 0 });
    let mut float_colors = false;
    let mut extra_values = 0usize;
    let mut vals: Vec<f64> = Vec::with_capacity(12);
    let mut toks: Vec<&[u8]> = Vec::with_capacity(12);
    for i in 0..nv {
        let Some((ln, l)) = lines.next() else {
            return Err(Error::format(
                path,
                format!(
                    "unexpected end of file after {i} of {nv} vertices (line {})",
                    lines.line
                ),
            ));
        };
        vals.clear();
        toks.clear();
        toks.extend(tokens(l));
        for t in &toks {
            let v = parse_f64(t).ok_or_else(|| {
                at(
                    ln,
                    format!("vertex {i}: expected a number, found '{}'", lossy(t)),
                )
            })?;
            vals.push(v);
        }
        if color {
            let end = toks.len().saturating_sub(if st { 2 } else { 0 });
            float_colors |= toks
                .get(base - if st { 2 } else { 0 }..end)
                .unwrap_or(&[])
                .iter()
                .any(|t| t.iter().any(|&b| b == b'.' || b == b'e' || b == b'E'));
        }
        let min = base + if color { 3 } else { 0 };
        if vals.len() < min {
            return Err(at(
                ln,
                format!(
                    "vertex {i}: expected {min} values ({}), found {}",
                    describe(normal, color, st),
                    vals.len()
                ),
            ));
        }
        positions.push([vals[0], vals[1], vals[2]]);
        let mut k = 3;
        if normal {
            normals.push([vals[3], vals[4], vals[5]]);
            k = 6;
        }
        if color {
            let nc = vals.len() - base;
            if nc != 3 && nc != 4 {
                return Err(at(
                    ln,
                    format!(
                        "vertex {i}: expected 3 or 4 colour values ({}), found {nc}",
                        describe(normal, color, st)
                    ),
                ));
            }
            colors.push([vals[k], vals[k + 1], vals[k + 2]]);
        } else if vals.len() > base {
            extra_values += 1;
        }
    }
    if extra_values > 0 {
        report.notes.push(format!(
            "{extra_values} vertex lines have more values than '{}' announces; the extra values were ignored",
            lossy(key)
        ));
    }

    let mut faces = Vec::with_capacity(nf);
    let mut face_colors = 0usize;
    let mut triangulated = 0usize;
    let mut idx: Vec<u32> = Vec::with_capacity(8);
    for i in 0..nf {
        let Some((ln, l)) = lines.next() else {
            return Err(Error::format(
                path,
                format!(
                    "unexpected end of file after {i} of {nf} faces (line {})",
                    lines.line
                ),
            ));
        };
        let mut toks = tokens(l);
        let first = toks.next().unwrap_or(b"");
        let k = parse_count(first).ok_or_else(|| {
            at(
                ln,
                format!(
                    "face {i}: expected the number of vertices, found '{}'",
                    lossy(first)
                ),
            )
        })?;
        if k < 3 {
            return Err(at(
                ln,
                format!("face {i}: a face needs at least 3 vertices, found {k}"),
            ));
        }
        idx.clear();
        for _ in 0..k {
            let Some(t) = toks.next() else {
                return Err(at(
                    ln,
                    format!("face {i}: expected {k} vertex indices, found {}", idx.len()),
                ));
            };
            let v = parse_count(t).ok_or_else(|| {
                at(
                    ln,
                    format!("face {i}: expected a vertex index, found '{}'", lossy(t)),
                )
            })?;
            if v >= nv as u64 {
                return Err(at(
                    ln,
                    format!("face {i} refers to vertex {v}, but the file has {nv} vertices (indices start at 0)"),
                ));
            }
            idx.push(v as u32);
        }
        if toks.next().is_some() {
            face_colors += 1;
        }
        if k > 3 {
            triangulated += 1;
        }
        for j in 1..idx.len() - 1 {
            faces.push([idx[0], idx[j], idx[j + 1]]);
        }
    }
    if face_colors > 0 {
        report
            .notes
            .push(format!("{face_colors} per-face colours ignored"));
    }
    report.polygons_triangulated = triangulated;

    let mut cloud = PointCloud::from_positions(positions);
    if normal {
        cloud.normals = Some(normals);
    }
    if color {
        let scale = if float_colors { 255.0 } else { 1.0 };
        cloud.colors = Some(colors.iter().map(|c| c.map(|v| to_u8(v * scale))).collect());
    }
    if st {
        report.notes.push("texture coordinates ignored".into());
    }
    report.encoding = format!("ascii {}", lossy(key));
    Ok((
        Geometry {
            points: cloud,
            faces,
            ..Default::default()
        },
        report,
    ))
}

/// A non-negative integer (counts and indices).
fn parse_count(t: &[u8]) -> Option<u64> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

/// What a vertex line holds, for messages.
fn describe(normal: bool, color: bool, st: bool) -> String {
    let mut s = String::from("x y z");
    if normal {
        s.push_str(" nx ny nz");
    }
    if color {
        s.push_str(" r g b [a]");
    }
    if st {
        s.push_str(" s t");
    }
    s
}
