//! Stanford PLY reading and writing: ascii, binary little endian and binary big endian.
//!
//! # Reading
//! The whole file is read with one `std::fs::read`; the header is parsed into element and
//! property definitions, then each element's rows are decoded into columns (one `f64` column per
//! scalar property, offsets + items per list property), and finally the columns are given their
//! meaning:
//! - `vertex`: `x y z` → positions, `nx ny nz` → normals, `red green blue` → colours (uchar, or
//!   float in [0, 1] scaled to 0..255); every other scalar property becomes a named
//!   [`Attribute`] keeping its [`ScalarKind`]. List properties of vertices are skipped (noted).
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

use std::io::Write;
use std::path::Path;

use rayon::prelude::*;

use super::{Geometry, ReadReport, WriteOptions};
use crate::geometry::{Attribute, Attributes, PointCloud, ScalarKind};
use crate::{Error, Result};

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

// ---------------------------------------------------------------------------------------------
// Header

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    Vertex,
    Face,
    Edge,
    Skip,
}

#[derive(Debug, Clone, Copy)]
enum PropType {
    Scalar(ScalarKind),
    List { count: ScalarKind, item: ScalarKind },
}

#[derive(Debug, Clone)]
struct PropDef {
    name: String,
    ty: PropType,
}

#[derive(Debug, Clone)]
struct ElementDef {
    name: String,
    count: usize,
    props: Vec<PropDef>,
    /// Header line of the `element` line, for messages.
    line: usize,
}

#[derive(Debug)]
struct Header {
    encoding: PlyEncoding,
    version: String,
    elements: Vec<ElementDef>,
    body_start: usize,
}

fn is_face_index_list(name: &str) -> bool {
    name == "vertex_indices" || name == "vertex_index"
}

const TYPE_NAMES: &str =
    "char uchar short ushort int uint float double (or int8 uint8 int16 uint16 int32 uint32 float32 float64)";

fn parse_type(path: &Path, line: usize, tok: Option<&str>) -> Result<ScalarKind> {
    let Some(t) = tok else {
        return Err(Error::format(
            path,
            format!("header line {line}: the property has no type; expected one of {TYPE_NAMES}"),
        ));
    };
    ScalarKind::from_ply_name(t).ok_or_else(|| {
        Error::format(
            path,
            format!(
                "header line {line}: unknown property type {}; expected one of {TYPE_NAMES}",
                crate::error::excerpt(t)
            ),
        )
    })
}

fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    if bytes.is_empty() {
        return Err(Error::format(
            path,
            "the file is empty; expected a PLY header starting with the line `ply`",
        ));
    }
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut format: Option<(PlyEncoding, String)> = None;
    let mut elements: Vec<ElementDef> = Vec::new();
    loop {
        let Some(rest) = bytes.get(pos..).filter(|r| !r.is_empty()) else {
            return Err(Error::format(
                path,
                format!(
                    "the header has no `end_header` line (the file ends after {line_no} header lines)"
                ),
            ));
        };
        let (raw, next) = match rest.iter().position(|&b| b == b'\n') {
            Some(i) => (rest.get(..i).unwrap_or(rest), pos + i + 1),
            None => (rest, bytes.len()),
        };
        line_no += 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        let text = std::str::from_utf8(raw).map_err(|_| {
            Error::format(
                path,
                format!(
                    "header line {line_no} is not text; expected a header line or `end_header` (is the header cut short or the file not PLY?)"
                ),
            )
        })?;
        pos = next;
        if line_no == 1 {
            if text.trim() != "ply" {
                return Err(Error::format(
                    path,
                    "the file does not start with the line `ply`: not a PLY file",
                ));
            }
            continue;
        }
        let mut toks = text.split_ascii_whitespace();
        match toks.next() {
            None | Some("comment") | Some("obj_info") => {}
            Some("format") => {
                let name = toks.next().unwrap_or("");
                let enc = PlyEncoding::from_header_name(name).ok_or_else(|| {
                    Error::format(
                        path,
                        format!("header line {line_no}: unknown format {}; expected ascii, binary_little_endian or binary_big_endian", crate::error::excerpt(name)),
                    )
                })?;
                let version = toks.next().unwrap_or("1.0").to_string();
                format = Some((enc, version));
            }
            Some("element") => {
                let (Some(name), Some(count)) = (toks.next(), toks.next()) else {
                    return Err(Error::format(
                        path,
                        format!("header line {line_no}: expected `element NAME COUNT`"),
                    ));
                };
                let count = count
                    .parse::<u64>()
                    .ok()
                    .and_then(|c| usize::try_from(c).ok())
                    .ok_or_else(|| {
                        Error::format(
                            path,
                            format!("header line {line_no}: element `{}` has count {}; expected a non-negative integer", crate::error::excerpt(name), crate::error::excerpt(count)),
                        )
                    })?;
                elements.push(ElementDef {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line: line_no,
                });
            }
            Some("property") => {
                let Some(el) = elements.last_mut() else {
                    return Err(Error::format(
                        path,
                        format!("header line {line_no}: a property before any `element` line"),
                    ));
                };
                let first = toks.next();
                let ty = if first == Some("list") {
                    let count = parse_type(path, line_no, toks.next())?;
                    if !count.is_integer() {
                        return Err(Error::format(
                            path,
                            format!("header line {line_no}: list count type {:?} is not an integer type", count.ply_name()),
                        ));
                    }
                    let item = parse_type(path, line_no, toks.next())?;
                    PropType::List { count, item }
                } else {
                    PropType::Scalar(parse_type(path, line_no, first)?)
                };
                let Some(name) = toks.next() else {
                    return Err(Error::format(
                        path,
                        format!("header line {line_no}: the property has no name"),
                    ));
                };
                if el.props.iter().any(|p| p.name == name) {
                    return Err(Error::format(
                        path,
                        format!(
                            "header line {line_no}: property `{name}` appears twice in element `{}`",
                            el.name
                        ),
                    ));
                }
                el.props.push(PropDef {
                    name: name.to_string(),
                    ty,
                });
            }
            Some("end_header") => break,
            Some(other) => {
                return Err(Error::format(
                    path,
                    format!("header line {line_no}: unknown keyword {}; expected format, comment, obj_info, element, property or end_header", crate::error::excerpt(other)),
                ))
            }
        }
    }
    let Some((encoding, version)) = format else {
        return Err(Error::format(
            path,
            "the header has no `format` line; expected `format ascii|binary_little_endian|binary_big_endian 1.0`",
        ));
    };
    for el in &elements {
        if el.count > 0 && el.props.is_empty() {
            return Err(Error::format(
                path,
                format!(
                    "header line {}: element `{}` has {} rows but no properties",
                    el.line, el.name, el.count
                ),
            ));
        }
    }
    Ok(Header {
        encoding,
        version,
        elements,
        body_start: pos,
    })
}

// ---------------------------------------------------------------------------------------------
// Body decoding into columns

/// The decoded values of one property of an element.
#[derive(Debug, Clone)]
enum Col<'a> {
    /// Not kept (skipped list, or an element crease does not read).
    Skipped,
    /// One value per row.
    Scalar(Vec<f64>),
    /// A property of fixed-size binary rows, not decoded yet: the value of row `i` is at byte
    /// `i * row_size + off` of `body`. Decoded straight into its final array when it is used.
    Raw(RawCol<'a>),
    /// Row `i` holds `items[offsets[i]..offsets[i + 1]]`.
    List {
        offsets: Vec<usize>,
        items: Vec<f64>,
    },
    /// A list property of binary rows whose lists all have `len` items (so the rows have a fixed
    /// size): item `k` of row `i` is at byte `i * row_size + off + k * kind.size()`.
    RawList { raw: RawCol<'a>, len: usize },
}

/// One property of the fixed-size rows of a binary element (see [`Col::Raw`]).
#[derive(Debug, Clone, Copy)]
struct RawCol<'a> {
    body: &'a [u8],
    row_size: usize,
    off: usize,
    kind: ScalarKind,
    be: bool,
}

impl RawCol<'_> {
    #[inline(always)]
    fn get(&self, row: &[u8]) -> f64 {
        read_scalar(row, self.off, self.kind, self.be).unwrap_or(0.0)
    }

    /// Decodes every row with `f` in parallel.
    fn decode<T: Send, F: Fn(&[u8]) -> T + Sync + Send>(&self, f: F) -> Vec<T> {
        let mut out = Vec::new();
        if self.row_size > 0 {
            self.body
                .par_chunks_exact(self.row_size)
                .map(f)
                .collect_into_vec(&mut out);
        }
        out
    }
}

impl Col<'_> {
    fn new(want: bool, ty: PropType, rows: usize) -> Self {
        match (want, ty) {
            (false, _) => Col::Skipped,
            (true, PropType::Scalar(_)) => Col::Scalar(Vec::with_capacity(rows)),
            (true, PropType::List { .. }) => {
                let mut offsets = Vec::with_capacity(rows + 1);
                offsets.push(0);
                Col::List {
                    offsets,
                    items: Vec::with_capacity(rows.saturating_mul(3)),
                }
            }
        }
    }

    /// Appends `other`'s rows after self's.
    fn append(&mut self, other: Self) {
        match (self, other) {
            (Col::Scalar(a), Col::Scalar(b)) => a.extend_from_slice(&b),
            (
                Col::List { offsets, items },
                Col::List {
                    offsets: o2,
                    items: i2,
                },
            ) => {
                let base = items.len();
                offsets.extend(o2.iter().skip(1).map(|o| o + base));
                items.extend_from_slice(&i2);
            }
            _ => {}
        }
    }
}

/// Rows per parallel chunk.
const CHUNK: usize = 16 * 1024;

fn binary_size_error(
    path: &Path,
    el: &ElementDef,
    row_bytes: usize,
    pos: usize,
    remaining: usize,
    at_least: bool,
) -> Error {
    Error::format(
        path,
        format!(
            "element `{}` declares {} rows of {}{} bytes, but only {} bytes remain after byte offset {}: the file is truncated or the count is wrong",
            el.name,
            el.count,
            if at_least { "at least " } else { "" },
            row_bytes,
            remaining,
            pos
        ),
    )
}

fn decode_binary<'a>(
    path: &Path,
    bytes: &'a [u8],
    pos: &mut usize,
    el: &ElementDef,
    want: &[bool],
    be: bool,
) -> Result<Vec<Col<'a>>> {
    let remaining = bytes.len().saturating_sub(*pos);
    let fixed = el.props.iter().all(|p| matches!(p.ty, PropType::Scalar(_)));
    let min_row: usize = el
        .props
        .iter()
        .map(|p| match p.ty {
            PropType::Scalar(k) => k.size(),
            PropType::List { count, .. } => count.size(),
        })
        .sum();
    let enough = el
        .count
        .checked_mul(min_row)
        .is_some_and(|need| need <= remaining);
    if !enough {
        return Err(binary_size_error(
            path, el, min_row, *pos, remaining, !fixed,
        ));
    }
    if fixed {
        Ok(decode_binary_fixed(bytes, pos, el, want, be, min_row))
    } else if let Some(cols) = decode_binary_uniform(bytes, pos, el, want, be) {
        Ok(cols)
    } else {
        decode_binary_rows(path, bytes, pos, el, want, be)
    }
}

/// The common case of one list property whose lists all have the same length (a triangle mesh's
/// faces): the rows then have a fixed size, checked in parallel, and the element is decoded like
/// fixed rows. `None` when the element does not have that shape (then it is decoded row by row,
/// which also finds and reports any error).
fn decode_binary_uniform<'a>(
    bytes: &'a [u8],
    pos: &mut usize,
    el: &ElementDef,
    want: &[bool],
    be: bool,
) -> Option<Vec<Col<'a>>> {
    let mut lists = el.props.iter().enumerate().filter_map(|(i, p)| match p.ty {
        PropType::List { count, item } => Some((i, count, item)),
        PropType::Scalar(_) => None,
    });
    let (li, ck, ik) = lists.next()?;
    if lists.next().is_some() || el.count == 0 {
        return None;
    }
    let scalar_size = |props: &[PropDef]| -> usize {
        props
            .iter()
            .map(|p| match p.ty {
                PropType::Scalar(k) => k.size(),
                PropType::List { .. } => 0,
            })
            .sum()
    };
    let list_off = scalar_size(el.props.get(..li)?);
    let c0 = read_scalar(bytes, pos.checked_add(list_off)?, ck, be)?;
    if c0 < 0.0 {
        return None;
    }
    let len = c0 as usize;
    let list_bytes = ck.size().checked_add(len.checked_mul(ik.size())?)?;
    let rs = scalar_size(&el.props).checked_add(list_bytes)?;
    let total = el.count.checked_mul(rs)?;
    let body = bytes.get(*pos..pos.checked_add(total)?)?;
    let uniform = body
        .par_chunks_exact(rs)
        .all(|row| read_scalar(row, list_off, ck, be) == Some(c0));
    if !uniform {
        return None;
    }
    let mut off = 0;
    let mut cols = Vec::with_capacity(el.props.len());
    for (p, &w) in el.props.iter().zip(want) {
        let (kind, size, item_off) = match p.ty {
            PropType::Scalar(k) => (k, k.size(), off),
            PropType::List { .. } => (ik, list_bytes, off + ck.size()),
        };
        let raw = RawCol {
            body,
            row_size: rs,
            off: item_off,
            kind,
            be,
        };
        cols.push(match (w, p.ty) {
            (false, _) => Col::Skipped,
            (true, PropType::Scalar(_)) => Col::Raw(raw),
            (true, PropType::List { .. }) => Col::RawList { raw, len },
        });
        off += size;
    }
    *pos += total;
    Some(cols)
}

/// Fixed-size rows: nothing is decoded here; each wanted property becomes a [`Col::Raw`] over
/// the element's bytes (an offset plan), decoded in parallel when its meaning is known.
fn decode_binary_fixed<'a>(
    bytes: &'a [u8],
    pos: &mut usize,
    el: &ElementDef,
    want: &[bool],
    be: bool,
    row_size: usize,
) -> Vec<Col<'a>> {
    let total = el.count * row_size; // checked by the caller
    let body = bytes.get(*pos..*pos + total).unwrap_or(&[]);
    *pos += total;
    let mut off = 0;
    let mut cols = Vec::with_capacity(el.props.len());
    for (p, &w) in el.props.iter().zip(want) {
        let PropType::Scalar(kind) = p.ty else {
            cols.push(Col::Skipped);
            continue;
        };
        cols.push(if w {
            Col::Raw(RawCol {
                body,
                row_size,
                off,
                kind,
                be,
            })
        } else {
            Col::Skipped
        });
        off += kind.size();
    }
    cols
}

/// Reads one scalar of `kind` at `pos`, or `None` past the end.
fn read_scalar(bytes: &[u8], pos: usize, kind: ScalarKind, be: bool) -> Option<f64> {
    macro_rules! go {
        ($t:ty, $n:expr) => {{
            let b: [u8; $n] = bytes.get(pos..pos.checked_add($n)?)?.try_into().ok()?;
            Some(if be {
                <$t>::from_be_bytes(b)
            } else {
                <$t>::from_le_bytes(b)
            } as f64)
        }};
    }
    match kind {
        ScalarKind::I8 => go!(i8, 1),
        ScalarKind::U8 => go!(u8, 1),
        ScalarKind::I16 => go!(i16, 2),
        ScalarKind::U16 => go!(u16, 2),
        ScalarKind::I32 => go!(i32, 4),
        ScalarKind::U32 => go!(u32, 4),
        ScalarKind::F32 => go!(f32, 4),
        ScalarKind::F64 => go!(f64, 8),
    }
}

/// Rows with list properties: decoded one after the other.
fn decode_binary_rows(
    path: &Path,
    bytes: &[u8],
    pos: &mut usize,
    el: &ElementDef,
    want: &[bool],
    be: bool,
) -> Result<Vec<Col<'static>>> {
    let mut cols: Vec<Col<'static>> = el
        .props
        .iter()
        .zip(want)
        .map(|(p, &w)| Col::new(w, p.ty, el.count))
        .collect();
    let mut p = *pos;
    let short = |row: usize, prop: &str, what: &str, at: usize| {
        Error::format(
            path,
            format!(
                "element `{}` row {row}, property `{prop}`: the file ends at byte {at}, expected {what}: the file is truncated",
                el.name
            ),
        )
    };
    for row in 0..el.count {
        for (prop, col) in el.props.iter().zip(cols.iter_mut()) {
            match prop.ty {
                PropType::Scalar(k) => {
                    let v = read_scalar(bytes, p, k, be)
                        .ok_or_else(|| short(row, &prop.name, k.ply_name(), p))?;
                    if let Col::Scalar(c) = col {
                        c.push(v);
                    }
                    p += k.size();
                }
                PropType::List { count, item } => {
                    let c = read_scalar(bytes, p, count, be).ok_or_else(|| {
                        short(
                            row,
                            &prop.name,
                            &format!("a {} list count", count.ply_name()),
                            p,
                        )
                    })?;
                    let at = p;
                    p += count.size();
                    let rest = bytes.len().saturating_sub(p);
                    if c < 0.0 {
                        return Err(Error::format(
                            path,
                            format!(
                                "element `{}` row {row}, property `{}`: negative list count {c} at byte {at}; expected a count >= 0",
                                el.name, prop.name
                            ),
                        ));
                    }
                    let len = c as usize;
                    let need = len.checked_mul(item.size()).filter(|&b| b <= rest);
                    let Some(need) = need else {
                        return Err(Error::format(
                            path,
                            format!(
                                "element `{}` row {row}, property `{}`: list count {len} at byte {at} needs {} bytes, but only {rest} remain: the count overruns the file",
                                el.name, prop.name, len.saturating_mul(item.size())
                            ),
                        ));
                    };
                    if let Col::List { offsets, items } = col {
                        for i in 0..len {
                            items.push(
                                read_scalar(bytes, p + i * item.size(), item, be).unwrap_or(0.0),
                            );
                        }
                        offsets.push(items.len());
                    }
                    p += need;
                }
            }
        }
    }
    *pos = p;
    Ok(cols)
}

/// Line number (1-based) of byte offset `at`.
fn line_of(bytes: &[u8], at: usize) -> usize {
    bytes
        .get(..at)
        .unwrap_or(bytes)
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

fn decode_ascii(
    path: &Path,
    bytes: &[u8],
    pos: &mut usize,
    el: &ElementDef,
    want: &[bool],
) -> Result<Vec<Col<'static>>> {
    let remaining = bytes.len().saturating_sub(*pos);
    // Every value takes at least one character and one separator (the very last value of the
    // file may lack its newline).
    let min_row = 2 * el.props.len();
    if el
        .count
        .checked_mul(min_row)
        .is_none_or(|need| need > remaining + 1)
    {
        return Err(Error::format(
            path,
            format!(
                "element `{}` declares {} rows of {} values, but only {} bytes remain after line {}: the file is truncated or the count is wrong",
                el.name,
                el.count,
                el.props.len(),
                remaining,
                line_of(bytes, *pos)
            ),
        ));
    }
    // Find the rows: one non-blank line each.
    let mut lines: Vec<(usize, usize)> = Vec::with_capacity(el.count);
    let mut p = *pos;
    while lines.len() < el.count {
        let Some(rest) = bytes.get(p..).filter(|r| !r.is_empty()) else {
            return Err(Error::format(
                path,
                format!(
                    "element `{}` ends after {} of {} rows (line {}): the file is truncated",
                    el.name,
                    lines.len(),
                    el.count,
                    line_of(bytes, bytes.len())
                ),
            ));
        };
        let end = rest
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| p + i);
        if rest
            .get(..end - p)
            .is_some_and(|l| l.iter().any(|b| !b.is_ascii_whitespace()))
        {
            lines.push((p, end));
        }
        p = end + 1;
    }
    *pos = p.min(bytes.len());
    let chunks: Vec<Result<Vec<Col<'static>>>> = lines
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(ci, chunk)| {
            let mut cols: Vec<Col<'static>> = el
                .props
                .iter()
                .zip(want)
                .map(|(p, &w)| Col::new(w, p.ty, chunk.len()))
                .collect();
            for (i, &(s, e)) in chunk.iter().enumerate() {
                let line = bytes.get(s..e).unwrap_or(&[]);
                parse_ascii_row(line, el, &mut cols).map_err(|msg| {
                    Error::format(
                        path,
                        format!(
                            "line {}: element `{}` row {}: {msg}",
                            line_of(bytes, s),
                            el.name,
                            ci * CHUNK + i
                        ),
                    )
                })?;
            }
            Ok(cols)
        })
        .collect();
    let mut out: Option<Vec<Col<'static>>> = None;
    for c in chunks {
        let c = c?;
        match &mut out {
            None => out = Some(c),
            Some(o) => {
                for (a, b) in o.iter_mut().zip(c) {
                    a.append(b);
                }
            }
        }
    }
    Ok(out.unwrap_or_else(|| {
        el.props
            .iter()
            .zip(want)
            .map(|(p, &w)| Col::new(w, p.ty, 0))
            .collect()
    }))
}

/// Parses an ascii value of `kind`: a `float` is parsed as f32 (then widened), so that the
/// value is the one a binary file would hold; every other kind as f64, which holds them exactly.
fn parse_number(tok: &[u8], kind: ScalarKind) -> Option<f64> {
    let s = std::str::from_utf8(tok).ok()?;
    if kind == ScalarKind::F32 {
        s.parse::<f32>().ok().map(f64::from)
    } else {
        s.parse::<f64>().ok()
    }
}

fn parse_ascii_row(line: &[u8], el: &ElementDef, cols: &mut [Col]) -> Result<(), String> {
    let mut toks = line
        .split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty());
    let show = |t: &[u8]| {
        String::from_utf8_lossy(t)
            .chars()
            .take(40)
            .collect::<String>()
    };
    for (prop, col) in el.props.iter().zip(cols.iter_mut()) {
        match prop.ty {
            PropType::Scalar(k) => {
                let Some(t) = toks.next() else {
                    return Err(format!(
                        "the line ends before property `{}`; expected {} values",
                        prop.name,
                        el.props.len()
                    ));
                };
                let v = parse_number(t, k).ok_or_else(|| {
                    format!(
                        "property `{}`: {:?} is not a number; expected a {} value",
                        prop.name,
                        show(t),
                        k.ply_name()
                    )
                })?;
                if let Col::Scalar(c) = col {
                    c.push(v);
                }
            }
            PropType::List { item, .. } => {
                let Some(t) = toks.next() else {
                    return Err(format!(
                        "the line ends before the count of list `{}`",
                        prop.name
                    ));
                };
                let c = parse_number(t, ScalarKind::F64).ok_or_else(|| {
                    format!(
                        "list `{}`: count {:?} is not a number; expected an integer >= 0",
                        prop.name,
                        show(t)
                    )
                })?;
                if c < 0.0 || c.fract() != 0.0 {
                    return Err(format!(
                        "list `{}`: count {c} is negative or fractional; expected an integer >= 0",
                        prop.name
                    ));
                }
                // A count larger than the line can hold is caught when the values run out, so
                // nothing is allocated from it.
                let len = c as usize;
                for i in 0..len {
                    let Some(t) = toks.next() else {
                        return Err(format!(
                            "list `{}` announces {len} values but the line ends after {i}: the count overruns the line",
                            prop.name
                        ));
                    };
                    let v = parse_number(t, item).ok_or_else(|| {
                        format!(
                            "list `{}` value {i}: {:?} is not a number",
                            prop.name,
                            show(t)
                        )
                    })?;
                    if let Col::List { items, .. } = col {
                        items.push(v);
                    }
                }
                if let Col::List { offsets, items } = col {
                    offsets.push(items.len());
                }
            }
        }
    }
    if let Some(t) = toks.next() {
        return Err(format!(
            "unexpected extra value {:?} after the {} properties of the element",
            show(t),
            el.props.len()
        ));
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// Giving the columns their meaning

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

fn build_vertices(path: &Path, el: &ElementDef, mut cols: Vec<Col>) -> Result<PointCloud> {
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

fn build_faces(
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

fn build_edges(
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

// ---------------------------------------------------------------------------------------------
// Writing

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

fn encode<W: Write>(geom: &Geometry, enc: PlyEncoding, w: &mut W, path: &Path) -> Result<()> {
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
