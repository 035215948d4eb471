//! Writing: the header and the rows of vertices, faces and edges (with the polylines), in any
//! of the three encodings.

use std::io::Write;
use std::path::Path;

use rayon::prelude::*;

use super::PlyEncoding;
use crate::geometry::{Attributes, ScalarKind};
use crate::io::Geometry;
use crate::{Error, Result};

/// Where a written property takes its values from.
#[derive(Clone, Copy)]
enum Source<'a> {
    Position(usize),
    Normal(usize),
    Color(usize),
    Values(&'a [f64]),
}

struct Field<'a> {
    name: &'a str,
    kind: ScalarKind,
    source: Source<'a>,
}

fn check_names(attrs: &Attributes, reserved: &[&str], element: &str) -> Result<()> {
    for a in attrs {
        let ok = !a.name.is_empty() && a.name.bytes().all(|b| b.is_ascii_graphic());
        if !ok {
            return Err(Error::InvalidArgument(format!(
                "{element} attribute {:?} cannot be written to PLY: a property name must be non-empty printable ascii without spaces",
                a.name
            )));
        }
        if reserved.contains(&a.name.as_str()) {
            return Err(Error::InvalidArgument(format!(
                "{element} attribute {:?} cannot be written to PLY: the name is used by a standard property",
                a.name
            )));
        }
    }
    Ok(())
}

fn int_value(v: f64, kind: ScalarKind) -> i64 {
    let (lo, hi) = match kind {
        ScalarKind::I8 => (i8::MIN as f64, i8::MAX as f64),
        ScalarKind::U8 => (0.0, u8::MAX as f64),
        ScalarKind::I16 => (i16::MIN as f64, i16::MAX as f64),
        ScalarKind::U16 => (0.0, u16::MAX as f64),
        ScalarKind::I32 => (i32::MIN as f64, i32::MAX as f64),
        _ => (0.0, u32::MAX as f64),
    };
    if v.is_nan() {
        0
    } else {
        v.round().clamp(lo, hi) as i64
    }
}

/// Appends one value of `kind` to `out` in `enc`.
fn put(out: &mut Vec<u8>, v: f64, kind: ScalarKind, enc: PlyEncoding) {
    macro_rules! bin {
        ($x:expr) => {{
            let x = $x;
            if enc == PlyEncoding::BinaryBigEndian {
                out.extend_from_slice(&x.to_be_bytes())
            } else {
                out.extend_from_slice(&x.to_le_bytes())
            }
        }};
    }
    if enc == PlyEncoding::Ascii {
        // Writing to a Vec cannot fail.
        let _ = match kind {
            ScalarKind::F32 => write!(out, "{}", v as f32),
            ScalarKind::F64 => write!(out, "{v}"),
            k => write!(out, "{}", int_value(v, k)),
        };
        return;
    }
    match kind {
        ScalarKind::I8 => bin!(int_value(v, kind) as i8),
        ScalarKind::U8 => bin!(int_value(v, kind) as u8),
        ScalarKind::I16 => bin!(int_value(v, kind) as i16),
        ScalarKind::U16 => bin!(int_value(v, kind) as u16),
        ScalarKind::I32 => bin!(int_value(v, kind) as i32),
        ScalarKind::U32 => bin!(int_value(v, kind) as u32),
        ScalarKind::F32 => bin!(v as f32),
        ScalarKind::F64 => bin!(v),
    }
}

fn end_row(out: &mut Vec<u8>, enc: PlyEncoding) {
    if enc == PlyEncoding::Ascii {
        if out.last() == Some(&b' ') {
            out.pop();
        }
        out.push(b'\n');
    }
}

fn sep(out: &mut Vec<u8>, enc: PlyEncoding) {
    if enc == PlyEncoding::Ascii {
        out.push(b' ');
    }
}

/// Encodes rows `0..n` in parallel chunks with `row` and writes them to `w` in order.
fn write_rows<W: Write, F>(w: &mut W, path: &Path, n: usize, row: F) -> Result<()>
where
    F: Fn(usize, &mut Vec<u8>) + Sync,
{
    const ROWS: usize = 64 * 1024;
    const GROUP: usize = 16;
    let nchunks = n.div_ceil(ROWS);
    let mut c0 = 0;
    while c0 < nchunks {
        let c1 = (c0 + GROUP).min(nchunks);
        let bufs: Vec<Vec<u8>> = (c0..c1)
            .into_par_iter()
            .map(|c| {
                let mut out = Vec::with_capacity(ROWS * 32);
                for i in c * ROWS..((c + 1) * ROWS).min(n) {
                    row(i, &mut out);
                }
                out
            })
            .collect();
        for b in bufs {
            w.write_all(&b).map_err(|e| Error::io(path, e))?;
        }
        c0 = c1;
    }
    Ok(())
}

pub(super) fn encode<W: Write>(
    geom: &Geometry,
    enc: PlyEncoding,
    w: &mut W,
    path: &Path,
) -> Result<()> {
    geom.validate()?;
    let pts = &geom.points;
    let n = pts.len();
    if n > i32::MAX as usize {
        return Err(Error::InvalidArgument(format!(
            "{n} points: PLY int vertex indices hold at most {}",
            i32::MAX
        )));
    }
    check_names(
        &pts.attributes,
        &["x", "y", "z", "nx", "ny", "nz", "red", "green", "blue"],
        "point",
    )?;
    check_names(
        &geom.face_attributes,
        &["vertex_indices", "vertex_index"],
        "face",
    )?;
    check_names(
        &geom.edge_attributes,
        &["vertex1", "vertex2", "polyline"],
        "edge",
    )?;

    let mut vfields: Vec<Field> = Vec::new();
    for (k, name) in ["x", "y", "z"].into_iter().enumerate() {
        vfields.push(Field {
            name,
            kind: ScalarKind::F64,
            source: Source::Position(k),
        });
    }
    if pts.normals.is_some() {
        for (k, name) in ["nx", "ny", "nz"].into_iter().enumerate() {
            vfields.push(Field {
                name,
                kind: ScalarKind::F32,
                source: Source::Normal(k),
            });
        }
    }
    if pts.colors.is_some() {
        for (k, name) in ["red", "green", "blue"].into_iter().enumerate() {
            vfields.push(Field {
                name,
                kind: ScalarKind::U8,
                source: Source::Color(k),
            });
        }
    }
    for a in &pts.attributes {
        vfields.push(Field {
            name: &a.name,
            kind: a.kind,
            source: Source::Values(&a.values),
        });
    }
    let segments: usize = geom
        .polylines
        .iter()
        .map(|l| l.len().saturating_sub(1))
        .sum();
    let n_edges = geom.edges.len() + segments;

    let mut h = String::new();
    h.push_str("ply\n");
    h.push_str(&format!("format {} 1.0\n", enc.header_name()));
    h.push_str("comment generated by crease\n");
    h.push_str(&format!("element vertex {n}\n"));
    for f in &vfields {
        h.push_str(&format!("property {} {}\n", f.kind.ply_name(), f.name));
    }
    if !geom.faces.is_empty() {
        h.push_str(&format!("element face {}\n", geom.faces.len()));
        h.push_str("property list uchar int vertex_indices\n");
        for a in &geom.face_attributes {
            h.push_str(&format!("property {} {}\n", a.kind.ply_name(), a.name));
        }
    }
    if n_edges > 0 {
        h.push_str(&format!("element edge {n_edges}\n"));
        h.push_str("property int vertex1\nproperty int vertex2\n");
        for a in &geom.edge_attributes {
            h.push_str(&format!("property {} {}\n", a.kind.ply_name(), a.name));
        }
        if !geom.polylines.is_empty() {
            h.push_str("property int polyline\n");
        }
    }
    h.push_str("end_header\n");
    w.write_all(h.as_bytes()).map_err(|e| Error::io(path, e))?;

    let normals = pts.normals.as_deref().unwrap_or(&[]);
    let colors = pts.colors.as_deref().unwrap_or(&[]);
    write_rows(w, path, n, |i, out| {
        for f in &vfields {
            let v = match f.source {
                Source::Position(k) => pts.positions.get(i).map_or(0.0, |p| p[k]),
                Source::Normal(k) => normals.get(i).map_or(0.0, |p| p[k]),
                Source::Color(k) => colors.get(i).map_or(0.0, |c| c[k] as f64),
                Source::Values(v) => v.get(i).copied().unwrap_or(0.0),
            };
            put(out, v, f.kind, enc);
            sep(out, enc);
        }
        end_row(out, enc);
    })?;

    if !geom.faces.is_empty() {
        write_rows(w, path, geom.faces.len(), |i, out| {
            put(out, 3.0, ScalarKind::U8, enc);
            sep(out, enc);
            if let Some(f) = geom.faces.get(i) {
                for &v in f {
                    put(out, v as f64, ScalarKind::I32, enc);
                    sep(out, enc);
                }
            }
            for a in &geom.face_attributes {
                put(out, a.values.get(i).copied().unwrap_or(0.0), a.kind, enc);
                sep(out, enc);
            }
            end_row(out, enc);
        })?;
    }

    if n_edges > 0 {
        // Row r < edges.len(): a plain edge; after that, polyline segments in order.
        let mut seg: Vec<([u32; 2], usize)> = Vec::with_capacity(segments);
        for (li, l) in geom.polylines.iter().enumerate() {
            seg.extend(l.windows(2).map(|w| ([w[0], w[1]], li)));
        }
        let ne = geom.edges.len();
        let has_lines = !geom.polylines.is_empty();
        write_rows(w, path, n_edges, |i, out| {
            let (e, line, plain) = match geom.edges.get(i) {
                Some(&e) => (e, -1.0, true),
                None => match seg.get(i - ne) {
                    Some(&(e, li)) => (e, li as f64, false),
                    None => ([0, 0], -1.0, true),
                },
            };
            put(out, e[0] as f64, ScalarKind::I32, enc);
            sep(out, enc);
            put(out, e[1] as f64, ScalarKind::I32, enc);
            sep(out, enc);
            for a in &geom.edge_attributes {
                let v = if plain {
                    a.values.get(i).copied().unwrap_or(0.0)
                } else {
                    0.0
                };
                put(out, v, a.kind, enc);
                sep(out, enc);
            }
            if has_lines {
                put(out, line, ScalarKind::I32, enc);
                sep(out, enc);
            }
            end_row(out, enc);
        })?;
    }
    Ok(())
}
