//! Giving the decoded columns their meaning: vertices (positions, normals, colours,
//! attributes), faces (fan-triangulated) and edges (with the polylines they encode).

use std::path::Path;

use rayon::prelude::*;

use super::binary::read_scalar;
use super::columns::{Col, RawCol};
use super::header::{is_face_index_list, ElementDef, PropType};
use crate::geometry::{Attribute, Attributes, PointCloud, ScalarKind};
use crate::io::{Geometry, ReadReport};
use crate::{Error, Result};

fn scalar_col(el: &ElementDef, cols: &[Col], name: &str) -> Option<usize> {
    el.props
        .iter()
        .zip(cols)
        .position(|(p, c)| p.name == name && matches!(c, Col::Scalar(_) | Col::Raw(_)))
}

/// Takes column `i` out of `cols` as values (decoding a raw column in parallel).
fn take_scalar(cols: &mut [Col], i: usize) -> Vec<f64> {
    match cols.get_mut(i).map(|c| std::mem::replace(c, Col::Skipped)) {
        Some(Col::Scalar(v)) => v,
        Some(Col::Raw(r)) => r.decode(|row| r.get(row)),
        _ => Vec::new(),
    }
}

/// Takes three columns out of `cols` and maps each row's three values with `f`: decoded straight
/// from the rows when they are raw binary, zipped otherwise.
fn take_triple<'a, T: Send, F: Fn([f64; 3]) -> T + Sync + Send>(
    cols: &mut [Col<'a>],
    idx: [usize; 3],
    f: F,
) -> Vec<T> {
    fn raw<'a>(c: Option<&Col<'a>>) -> Option<RawCol<'a>> {
        match c {
            Some(Col::Raw(r)) => Some(*r),
            _ => None,
        }
    }
    if let (Some(a), Some(b), Some(c)) = (
        raw(cols.get(idx[0])),
        raw(cols.get(idx[1])),
        raw(cols.get(idx[2])),
    ) {
        for i in idx {
            if let Some(c) = cols.get_mut(i) {
                *c = Col::Skipped;
            }
        }
        return a.decode(|row| f([a.get(row), b.get(row), c.get(row)]));
    }
    let x = take_scalar(cols, idx[0]);
    let y = take_scalar(cols, idx[1]);
    let z = take_scalar(cols, idx[2]);
    let mut out = Vec::new();
    x.par_iter()
        .zip(&y)
        .zip(&z)
        .map(|((&a, &b), &c)| f([a, b, c]))
        .collect_into_vec(&mut out);
    out
}

fn kind_of(el: &ElementDef, i: usize) -> ScalarKind {
    match el.props.get(i).map(|p| p.ty) {
        Some(PropType::Scalar(k)) => k,
        _ => ScalarKind::F64,
    }
}

/// Every remaining scalar column as a named attribute, in header order.
fn remaining_attributes(el: &ElementDef, cols: &mut [Col], n: usize) -> Result<Attributes> {
    let mut found = Vec::new();
    for (i, p) in el.props.iter().enumerate() {
        if let Some(Col::Scalar(_) | Col::Raw(_)) = cols.get(i) {
            let values = take_scalar(cols, i);
            found.push(Attribute {
                name: p.name.clone(),
                kind: kind_of(el, i),
                values,
            });
        }
    }
    let mut attrs = Attributes::new();
    attrs.extend(n, found)?;
    Ok(attrs)
}

fn to_u8_color(v: f64, kind: ScalarKind) -> u8 {
    let x = match kind {
        ScalarKind::F32 | ScalarKind::F64 => v * 255.0,
        ScalarKind::U16 => v / 257.0,
        _ => v,
    };
    if x.is_nan() {
        0
    } else {
        x.round().clamp(0.0, 255.0) as u8
    }
}

pub(super) fn build_vertices(
    path: &Path,
    el: &ElementDef,
    mut cols: Vec<Col>,
) -> Result<PointCloud> {
    let n = el.count;
    let mut xyz = [0usize; 3];
    for (slot, name) in xyz.iter_mut().zip(["x", "y", "z"]) {
        *slot = scalar_col(el, &cols, name).ok_or_else(|| {
            Error::format(
                path,
                format!(
                    "header line {}: element `vertex` has no scalar property `{name}`; expected x, y and z",
                    el.line
                ),
            )
        })?;
    }
    let mut cloud = PointCloud::from_positions(take_triple(&mut cols, xyz, |p| p));
    let found = |cols: &[Col], names: [&str; 3]| -> Option<[usize; 3]> {
        let a = scalar_col(el, cols, names[0])?;
        let b = scalar_col(el, cols, names[1])?;
        let c = scalar_col(el, cols, names[2])?;
        Some([a, b, c])
    };
    let bad = |e: Error| Error::format(path, format!("element `vertex`: {e}"));
    if let Some(idx) = found(&cols, ["nx", "ny", "nz"]) {
        let normals = take_triple(&mut cols, idx, |p| p);
        cloud.set_normals(normals).map_err(bad)?;
    }
    if let Some(idx) = found(&cols, ["red", "green", "blue"]) {
        let k = idx.map(|i| kind_of(el, i));
        let colors = take_triple(&mut cols, idx, |c| {
            [
                to_u8_color(c[0], k[0]),
                to_u8_color(c[1], k[1]),
                to_u8_color(c[2], k[2]),
            ]
        });
        cloud.set_colors(colors).map_err(bad)?;
    }
    cloud.attributes = remaining_attributes(el, &mut cols, n).map_err(bad)?;
    Ok(cloud)
}

/// Checks a vertex index read from the file.
fn vertex_index(v: f64, vertex_count: usize) -> Option<u32> {
    if v >= 0.0 && v.fract() == 0.0 && v < vertex_count as f64 && v <= u32::MAX as f64 {
        Some(v as u32)
    } else {
        None
    }
}

pub(super) fn build_faces(
    path: &Path,
    el: &ElementDef,
    mut cols: Vec<Col>,
    vertex_count: usize,
    geom: &mut Geometry,
    report: &mut ReadReport,
) -> Result<()> {
    let li = el.props.iter().zip(&cols).position(|(p, c)| {
        is_face_index_list(&p.name) && matches!(c, Col::List { .. } | Col::RawList { .. })
    });
    let Some(li) = li else {
        if el.count == 0 {
            return Ok(());
        }
        return Err(Error::format(
            path,
            format!(
                "header line {}: element `face` has no list property `vertex_indices` (or `vertex_index`)",
                el.line
            ),
        ));
    };
    let corner = |f: usize, k: usize, v: f64| -> Result<u32> {
        vertex_index(v, vertex_count).ok_or_else(|| {
            Error::format(
                path,
                format!(
                    "element `face` row {f}: corner {k} refers to vertex {v}, but there are {vertex_count} vertices (expected an index in 0..{vertex_count})"
                ),
            )
        })
    };
    let (offsets, items) = match cols.get_mut(li).map(|c| std::mem::replace(c, Col::Skipped)) {
        Some(Col::List { offsets, items }) => (offsets, items),
        Some(Col::RawList { raw, len: 3 }) if vertex_count < u32::MAX as usize => {
            // Triangles with fixed-size rows: decoded and checked in parallel.
            let size = raw.kind.size();
            let values = |row: &[u8]| {
                [0, 1, 2].map(|k| read_scalar(row, raw.off + k * size, raw.kind, raw.be))
            };
            let faces = raw.decode(|row| {
                values(row).map(|v| {
                    v.and_then(|v| vertex_index(v, vertex_count))
                        .unwrap_or(u32::MAX)
                })
            });
            if let Some(f) = faces.iter().position(|t| t.contains(&u32::MAX)) {
                let row = raw.body.chunks_exact(raw.row_size).nth(f).unwrap_or(&[]);
                for (k, v) in values(row).into_iter().enumerate() {
                    corner(f, k, v.unwrap_or(f64::NAN))?;
                }
            }
            let n = faces.len();
            geom.face_attributes = remaining_attributes(el, &mut cols, n)
                .map_err(|e| Error::format(path, format!("element `face`: {e}")))?;
            geom.faces = faces;
            return Ok(());
        }
        Some(Col::RawList { raw, len }) => {
            let size = raw.kind.size();
            let mut items = vec![0.0; el.count * len];
            if len > 0 {
                items
                    .par_chunks_mut(len)
                    .zip(raw.body.par_chunks_exact(raw.row_size))
                    .for_each(|(out, row)| {
                        for (k, o) in out.iter_mut().enumerate() {
                            *o = read_scalar(row, raw.off + k * size, raw.kind, raw.be)
                                .unwrap_or(f64::NAN);
                        }
                    });
            }
            ((0..=el.count).map(|i| i * len).collect(), items)
        }
        _ => (vec![0], Vec::new()),
    };
    let mut faces = Vec::with_capacity(el.count);
    let mut source_row: Vec<usize> = Vec::with_capacity(el.count);
    let mut polygons = 0usize;
    for (f, w) in offsets.windows(2).enumerate() {
        let corners = items.get(w[0]..w[1]).unwrap_or(&[]);
        if corners.len() < 3 {
            return Err(Error::format(
                path,
                format!(
                    "element `face` row {f}: {} corners; expected at least 3",
                    corners.len()
                ),
            ));
        }
        let get = |k: usize| corner(f, k, corners.get(k).copied().unwrap_or(f64::NAN));
        let first = get(0)?;
        let mut prev = get(1)?;
        if corners.len() > 3 {
            polygons += 1;
        }
        for k in 2..corners.len() {
            let cur = get(k)?;
            faces.push([first, prev, cur]);
            source_row.push(f);
            prev = cur;
        }
    }
    let nrows = offsets.len().saturating_sub(1);
    let mut attrs = remaining_attributes(el, &mut cols, nrows)
        .map_err(|e| Error::format(path, format!("element `face`: {e}")))?;
    if polygons > 0 {
        attrs = attrs.select(&source_row);
    }
    report.polygons_triangulated += polygons;
    geom.faces = faces;
    geom.face_attributes = attrs;
    Ok(())
}

pub(super) fn build_edges(
    path: &Path,
    el: &ElementDef,
    mut cols: Vec<Col>,
    vertex_count: usize,
    geom: &mut Geometry,
    report: &mut ReadReport,
) -> Result<()> {
    let (Some(a), Some(b)) = (
        scalar_col(el, &cols, "vertex1"),
        scalar_col(el, &cols, "vertex2"),
    ) else {
        report.notes.push(format!(
            "skipped element `edge` ({} rows): it has no scalar properties vertex1 and vertex2",
            el.count
        ));
        return Ok(());
    };
    let v1 = take_scalar(&mut cols, a);
    let v2 = take_scalar(&mut cols, b);
    let mut edges = Vec::with_capacity(v1.len());
    for (e, (&p, &q)) in v1.iter().zip(&v2).enumerate() {
        let check = |v: f64, which: &str| {
            vertex_index(v, vertex_count).ok_or_else(|| {
                Error::format(
                    path,
                    format!(
                        "element `edge` row {e}: {which} refers to vertex {v}, but there are {vertex_count} vertices (expected an index in 0..{vertex_count})"
                    ),
                )
            })
        };
        edges.push([check(p, "vertex1")?, check(q, "vertex2")?]);
    }
    let n = edges.len();
    let mut attrs = remaining_attributes(el, &mut cols, n)
        .map_err(|e| Error::format(path, format!("element `edge`: {e}")))?;
    let Some(line_of_edge) = attrs.remove("polyline") else {
        geom.edges = edges;
        geom.edge_attributes = attrs;
        return Ok(());
    };
    // Segments marked with a polyline index >= 0 are chained back into polylines; a new polyline
    // starts when the index changes or the chain breaks.
    let mut plain = Vec::new();
    let mut polylines: Vec<Vec<u32>> = Vec::new();
    let mut current: Option<f64> = None;
    for (i, (&[p, q], &l)) in edges.iter().zip(&line_of_edge.values).enumerate() {
        if l.is_nan() || l < 0.0 {
            plain.push(i);
            current = None;
            continue;
        }
        let continues = current == Some(l) && polylines.last().and_then(|pl| pl.last()) == Some(&p);
        if continues {
            if let Some(pl) = polylines.last_mut() {
                pl.push(q);
            }
        } else {
            polylines.push(vec![p, q]);
        }
        current = Some(l);
    }
    geom.edges = plain
        .iter()
        .filter_map(|&i| edges.get(i).copied())
        .collect();
    geom.edge_attributes = attrs.select(&plain);
    geom.polylines = polylines;
    Ok(())
}
