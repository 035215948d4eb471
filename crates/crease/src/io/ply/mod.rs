//! Stanford PLY reading and writing: ascii, binary little endian and binary big endian.
//!
//! # Reading
//! The whole file is read with one `std::fs::read`; the header is parsed into element and
//! property definitions, then each element's rows are decoded into columns (one `f64` column per
//! scalar property, offsets + items per list property), and finally the columns are given their
//! meaning:
//! - `vertex`: `x y z` → positions, `nx ny nz` → normals, `red green blue` → colours (uchar, or
//!   float in [0, 1] scaled to 0..255); every other scalar property becomes a named
//!   [`Attribute`](crate::geometry::Attribute) keeping its
//!   [`ScalarKind`](crate::geometry::ScalarKind). List properties of vertices are skipped (noted).
//! - `face`: the list `vertex_indices` (or `vertex_index`), fan-triangulated when a polygon has more
//!   than three corners (each triangle gets the polygon's face attributes); other scalars become
//!   face attributes.
//! - `edge`: `vertex1 vertex2` → edges; other scalars become edge attributes. An int edge
//!   attribute `polyline` (written by [`write()`]) rebuilds [`Geometry::polylines`].
//! - any other element is skipped and noted in the [`ReadReport`].
//!
//! Binary elements without list properties have fixed-size rows, decoded in parallel chunks with
//! a precomputed per-property offset plan. ASCII rows are found line by line and parsed in
//! parallel chunks. Every count read from the header is checked against the bytes left in the
//! file (count × smallest possible row) before anything is allocated from it, and every error
//! names the file, the element and row (and the line for ascii) and what was expected.
//!
//! # Why not a crate
//! `ply-rs-bw` 4.0.1 (the maintained fork of `ply-rs`) handles hostile counts well, but its
//! generic element (a hash map per row), or any element that can carry the arbitrary named
//! attributes of a file, reads a 1M-point scan many times slower than this reader; only a
//! fixed struct for one set of properties is as fast. Its binary errors do not name the row.
//! Figures: `docs/experiments/io-readers.md`.
//!
//! # Writing
//! Binary little endian by default, ascii with [`WriteOptions::ascii`] (big endian through
//! [`write_with_encoding`]). Positions are written as `double` (exact round trip), normals as
//! `float`, colours as `uchar`, attributes with their own kind. Faces as
//! `property list uchar int vertex_indices`; edges as `vertex1 vertex2` followed by the segments of
//! the polylines, marked by an int `polyline` edge attribute (-1 for plain edges; the other edge
//! attributes are 0 on polyline segments). A polyline of fewer than two points has no segment and
//! is not written. ASCII floats are written in the shortest form that reads back to the same
//! value (a `float` property is read back as f32, as in binary).
//!
//! # Layout
//! This file reads and writes a whole file; `header` parses the element and property
//! definitions, `binary` and `ascii` decode the bodies into the columns of `columns`,
//! `elements` gives the columns their meaning, and `writer` encodes.

use std::io::Write;
use std::path::Path;

use super::{Geometry, ReadReport, WriteOptions};
use crate::{Error, Result};

mod ascii;
mod binary;
mod columns;
mod elements;
mod header;
mod writer;

use ascii::decode_ascii;
use binary::decode_binary;
use elements::{build_edges, build_faces, build_vertices};
use header::{is_face_index_list, parse_header, PropType};
use writer::encode;

/// The three PLY encodings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    /// `format ascii 1.0`.
    Ascii,
    /// `format binary_little_endian 1.0`.
    BinaryLittleEndian,
    /// `format binary_big_endian 1.0`.
    BinaryBigEndian,
}

impl PlyEncoding {
    /// The name used on the `format` line.
    pub fn header_name(self) -> &'static str {
        match self {
            PlyEncoding::Ascii => "ascii",
            PlyEncoding::BinaryLittleEndian => "binary_little_endian",
            PlyEncoding::BinaryBigEndian => "binary_big_endian",
        }
    }

    fn from_header_name(s: &str) -> Option<Self> {
        Some(match s {
            "ascii" => PlyEncoding::Ascii,
            "binary_little_endian" => PlyEncoding::BinaryLittleEndian,
            "binary_big_endian" => PlyEncoding::BinaryBigEndian,
            _ => return None,
        })
    }
}

/// Reads a PLY file.
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    let bytes = super::read_bytes(path)?;
    read_bytes_ply(path, &bytes)
}

/// Decodes PLY content held in memory; `path_for_messages` is only used in error messages.
pub fn read_bytes_ply(path_for_messages: &Path, bytes: &[u8]) -> Result<(Geometry, ReadReport)> {
    let path = path_for_messages;
    let header = parse_header(path, bytes)?;
    let mut report = ReadReport {
        encoding: format!("{} {}", header.encoding.header_name(), header.version),
        ..Default::default()
    };
    let vertex_count = header
        .elements
        .iter()
        .find(|e| e.name == "vertex")
        .map_or(0, |e| e.count);
    let mut geom = Geometry::default();
    let mut seen = Vec::<&str>::new();
    let mut pos = header.body_start;
    for el in &header.elements {
        let role = match el.name.as_str() {
            "vertex" | "face" | "edge" if seen.contains(&el.name.as_str()) => {
                return Err(Error::format(
                    path,
                    format!(
                        "header line {}: a second `{}` element; expected at most one",
                        el.line, el.name
                    ),
                ))
            }
            "vertex" => Role::Vertex,
            "face" => Role::Face,
            "edge" => Role::Edge,
            _ => Role::Skip,
        };
        seen.push(el.name.as_str());
        let want: Vec<bool> = el
            .props
            .iter()
            .map(|p| match (role, &p.ty) {
                (Role::Skip, _) => false,
                (Role::Face, PropType::List { .. }) => is_face_index_list(&p.name),
                (_, PropType::List { .. }) => false,
                (_, PropType::Scalar(_)) => true,
            })
            .collect();
        let cols = match header.encoding {
            PlyEncoding::Ascii => decode_ascii(path, bytes, &mut pos, el, &want)?,
            PlyEncoding::BinaryLittleEndian => {
                decode_binary(path, bytes, &mut pos, el, &want, false)?
            }
            PlyEncoding::BinaryBigEndian => decode_binary(path, bytes, &mut pos, el, &want, true)?,
        };
        for (p, w) in el.props.iter().zip(&want) {
            if !w && role != Role::Skip {
                report.notes.push(format!(
                    "skipped the list property `{}` of element `{}`",
                    p.name, el.name
                ));
            }
        }
        match role {
            Role::Vertex => geom.points = build_vertices(path, el, cols)?,
            Role::Face => build_faces(path, el, cols, vertex_count, &mut geom, &mut report)?,
            Role::Edge => build_edges(path, el, cols, vertex_count, &mut geom, &mut report)?,
            Role::Skip => report.notes.push(format!(
                "skipped element `{}` ({} rows): crease reads vertex, face and edge",
                el.name, el.count
            )),
        }
    }
    Ok((geom, report))
}

/// Writes a PLY file: binary little endian, or ascii when `opts.ascii`.
pub fn write(path: &Path, geom: &Geometry, opts: &WriteOptions) -> Result<()> {
    let enc = if opts.ascii {
        PlyEncoding::Ascii
    } else {
        PlyEncoding::BinaryLittleEndian
    };
    write_with_encoding(path, geom, enc)
}

/// Writes a PLY file in the given encoding.
pub fn write_with_encoding(path: &Path, geom: &Geometry, encoding: PlyEncoding) -> Result<()> {
    let mut w = super::create(path)?;
    encode(geom, encoding, &mut w, path)?;
    w.flush().map_err(|e| Error::io(path, e))
}

/// Encodes `geom` as PLY content in memory.
pub fn to_bytes(geom: &Geometry, encoding: PlyEncoding) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    encode(geom, encoding, &mut out, Path::new("<memory>"))?;
    Ok(out)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    Vertex,
    Face,
    Edge,
    Skip,
}
