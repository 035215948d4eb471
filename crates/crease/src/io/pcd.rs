//! Point Cloud Library PCD files (format versions 0.7, and the older .6 / .5 headers):
//! `DATA ascii`, `binary` and `binary_compressed` (LZF) reading; `binary` and `ascii` writing.
//!
//! # Why our own parser and not `pcd-rs`
//! `pcd-rs` 0.13 reads `binary_compressed` and has a dynamic-schema reader, but it allocates
//! the compressed and decompressed buffers straight from the 32-bit sizes in the file, and its
//! structure-of-arrays transpose slices the decompressed block with offsets computed from
//! `POINTS` without checking that the block is `POINTS × record size` bytes long, so a
//! truncated or hostile file panics or asks for gigabytes. This parser checks every count
//! against the bytes actually present before allocating, and decodes all three data kinds
//! through one column accessor (no transposed copy of the data).
//!
//! # Mapping
//! - `x y z` → positions (any numeric type, converted to f64).
//! - `normal_x normal_y normal_z` → normals.
//! - `rgb` / `rgba` (SIZE 4, TYPE F or U: the same 32 bits, bytes B G R A little-endian) → colours
//!   (alpha is not kept).
//! - `_` → padding, skipped.
//! - any other field → a per-point attribute with the matching [`ScalarKind`] (`I`/`U` SIZE 1, 2, 4
//!   and `F` SIZE 4, 8 map exactly; 8-byte integers are stored as `F64` with a note, exact up to
//!   2^53). A field with COUNT k > 1 becomes attributes `name_0 .. name_{k-1}` when k ≤ 64;
//!   longer ones (descriptors such as `fpfh`, `vfh`) are skipped with a note.
//! - In an organised cloud (HEIGHT > 1) a point with a NaN coordinate is the sensor's "no return":
//!   it is dropped and counted in [`ReadReport::dropped_missing`]. In an unorganised cloud
//!   non-finite points are left to the generic non-finite check of [`super::read`].
//!
//! # Writing
//! `DATA binary` by default, `DATA ascii` with [`WriteOptions::ascii`]. Fields: `x y z`, then
//! `normal_x normal_y normal_z` and `rgb` when present, then every attribute with its kind.
//! Positions are written as `F 4` (what PCL point types expect) when rounding every coordinate to
//! f32 moves it by at most 1e-6 of the bounding-box diagonal, and as `F 8` otherwise (e.g.
//! georeferenced coordinates far from the origin), so the file never loses more than that.
//! `rgb` is written as `F 4` holding the packed bytes B G R 255 (PCL's `PointXYZRGB` layout); in
//! ascii files its value is written as the unsigned 32-bit integer, as PCL does.

use std::io::Write;
use std::path::Path;

use rayon::prelude::*;

use super::{Geometry, ReadReport, WriteOptions};
use crate::geometry::{Attribute, PointCloud, ScalarKind};
use crate::{Error, Result};

/// Largest COUNT for which a field is expanded into `name_0 ..` attributes.
const MAX_EXPANDED_COUNT: usize = 64;

/// The largest ratio between LZF output and input: a 3-byte back reference emits at most
/// 264 bytes, so a valid block never decompresses to more than 88 × its size.
const LZF_MAX_RATIO: usize = 88;

/// Scalar class of a PCD field (`TYPE`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Ty {
    I,
    U,
    F,
}

/// One `FIELDS` entry with its `SIZE`, `TYPE` and `COUNT`.
#[derive(Debug, Clone)]
struct Field {
    name: String,
    size: usize,
    ty: Ty,
    count: usize,
}

impl Field {
    fn is_packed_color(&self) -> bool {
        (self.name == "rgb" || self.name == "rgba") && self.size == 4 && self.count >= 1
    }

    fn kind(&self) -> (ScalarKind, bool) {
        match (self.ty, self.size) {
            (Ty::I, 1) => (ScalarKind::I8, false),
            (Ty::U, 1) => (ScalarKind::U8, false),
            (Ty::I, 2) => (ScalarKind::I16, false),
            (Ty::U, 2) => (ScalarKind::U16, false),
            (Ty::I, 4) => (ScalarKind::I32, false),
            (Ty::U, 4) => (ScalarKind::U32, false),
            (Ty::F, 4) => (ScalarKind::F32, false),
            // F 8, and I 8 / U 8 which have no exact kind.
            (Ty::F, _) => (ScalarKind::F64, false),
            _ => (ScalarKind::F64, true),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum DataKind {
    Ascii,
    Binary,
    BinaryCompressed,
}

/// A parsed header.
#[derive(Debug)]
struct Header {
    version: String,
    fields: Vec<Field>,
    width: usize,
    height: usize,
    viewpoint: [f64; 7],
    points: usize,
    data: DataKind,
    /// Byte offset of the first byte after the DATA line.
    data_start: usize,
    /// 1-based line number of the DATA line.
    data_line: usize,
    notes: Vec<String>,
}

impl Header {
    fn record_size(&self) -> usize {
        // Checked for overflow in `parse_header`.
        self.fields.iter().map(|f| f.size * f.count).sum()
    }
    fn total_count(&self) -> usize {
        self.fields.iter().map(|f| f.count).sum()
    }
}

fn parse_usize(path: &Path, line: usize, key: &str, tok: &str) -> Result<usize> {
    tok.parse::<usize>().map_err(|_| {
        Error::format(
            path,
            format!("header line {line} ({key}): expected a non-negative integer, found {tok:?}"),
        )
    })
}

fn one_value<'a>(path: &Path, line: usize, key: &str, toks: &[&'a str]) -> Result<&'a str> {
    match toks {
        [t] => Ok(t),
        _ => Err(Error::format(
            path,
            format!(
                "header line {line} ({key}): expected one value, found {}",
                toks.len()
            ),
        )),
    }
}

/// Parses the header lines up to and including `DATA`.
fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let mut version = String::new();
    let mut names: Option<(usize, Vec<String>)> = None;
    let mut sizes: Option<(usize, Vec<usize>)> = None;
    let mut types: Option<(usize, Vec<Ty>)> = None;
    let mut counts: Option<(usize, Vec<usize>)> = None;
    let mut width: Option<usize> = None;
    let mut height: Option<usize> = None;
    let mut points: Option<(usize, usize)> = None;
    let mut viewpoint = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let mut notes = Vec::new();
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let (data, data_line) = loop {
        if pos >= bytes.len() {
            return Err(Error::format(
                path,
                format!(
                    "the header ends after {line_no} lines without a DATA line; expected \
                     `DATA ascii`, `DATA binary` or `DATA binary_compressed` (is this a PCD file?)"
                ),
            ));
        }
        let rest = bytes.get(pos..).unwrap_or_default();
        let len = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let raw = rest.get(..len).unwrap_or_default();
        pos += len + 1;
        line_no += 1;
        let text = std::str::from_utf8(raw).map_err(|_| {
            Error::format(
                path,
                format!(
                    "header line {line_no} is not text; expected a PCD header \
                     (VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA)"
                ),
            )
        })?;
        let line = text.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut it = line.split_ascii_whitespace();
        let key = it.next().unwrap_or_default();
        let toks: Vec<&str> = it.collect();
        match key {
            "VERSION" => {
                version = one_value(path, line_no, key, &toks)?.to_string();
            }
            "FIELDS" | "COLUMNS" => {
                if toks.is_empty() {
                    return Err(Error::format(
                        path,
                        format!("header line {line_no} ({key}): expected at least one field name"),
                    ));
                }
                names = Some((line_no, toks.iter().map(|s| s.to_string()).collect()));
            }
            "SIZE" => {
                let v = toks
                    .iter()
                    .map(|t| {
                        let s = parse_usize(path, line_no, key, t)?;
                        if matches!(s, 1 | 2 | 4 | 8) {
                            Ok(s)
                        } else {
                            Err(Error::format(
                                path,
                                format!("header line {line_no} (SIZE): size {s} is not 1, 2, 4 or 8 bytes"),
                            ))
                        }
                    })
                    .collect::<Result<Vec<_>>>()?;
                sizes = Some((line_no, v));
            }
            "TYPE" => {
                let v = toks
                    .iter()
                    .map(|t| match *t {
                        "I" | "i" => Ok(Ty::I),
                        "U" | "u" => Ok(Ty::U),
                        "F" | "f" => Ok(Ty::F),
                        other => Err(Error::format(
                            path,
                            format!(
                                "header line {line_no} (TYPE): expected I, U or F, found {other:?}"
                            ),
                        )),
                    })
                    .collect::<Result<Vec<_>>>()?;
                types = Some((line_no, v));
            }
            "COUNT" => {
                let v = toks
                    .iter()
                    .map(|t| {
                        let c = parse_usize(path, line_no, key, t)?;
                        if c == 0 {
                            Err(Error::format(
                                path,
                                format!("header line {line_no} (COUNT): counts must be at least 1"),
                            ))
                        } else {
                            Ok(c)
                        }
                    })
                    .collect::<Result<Vec<_>>>()?;
                counts = Some((line_no, v));
            }
            "WIDTH" => {
                width = Some(parse_usize(
                    path,
                    line_no,
                    key,
                    one_value(path, line_no, key, &toks)?,
                )?)
            }
            "HEIGHT" => {
                height = Some(parse_usize(
                    path,
                    line_no,
                    key,
                    one_value(path, line_no, key, &toks)?,
                )?)
            }
            "POINTS" => {
                points = Some((
                    line_no,
                    parse_usize(path, line_no, key, one_value(path, line_no, key, &toks)?)?,
                ))
            }
            "VIEWPOINT" => {
                if toks.len() != 7 {
                    return Err(Error::format(
                        path,
                        format!(
                            "header line {line_no} (VIEWPOINT): expected 7 numbers (tx ty tz qw qx qy qz), found {}",
                            toks.len()
                        ),
                    ));
                }
                for (v, t) in viewpoint.iter_mut().zip(&toks) {
                    *v = t.parse::<f64>().map_err(|_| {
                        Error::format(
                            path,
                            format!(
                                "header line {line_no} (VIEWPOINT): expected a number, found {t:?}"
                            ),
                        )
                    })?;
                }
            }
            "DATA" => {
                let kind = match one_value(path, line_no, key, &toks)? {
                    "ascii" => DataKind::Ascii,
                    "binary" => DataKind::Binary,
                    "binary_compressed" => DataKind::BinaryCompressed,
                    other => {
                        return Err(Error::format(
                            path,
                            format!(
                            "header line {line_no} (DATA): unknown data kind {other:?}; expected \
                                 ascii, binary or binary_compressed"
                        ),
                        ))
                    }
                };
                break (kind, line_no);
            }
            other => notes.push(format!("ignored unknown header line {line_no} ({other})")),
        }
    };
    let data_start = pos.min(bytes.len());

    let Some((names_line, names)) = names else {
        return Err(Error::format(
            path,
            "the header has no FIELDS line; expected e.g. `FIELDS x y z`",
        ));
    };
    let n = names.len();
    let Some((sizes_line, sizes)) = sizes else {
        return Err(Error::format(
            path,
            "the header has no SIZE line; expected one size per field",
        ));
    };
    let Some((types_line, types)) = types else {
        return Err(Error::format(
            path,
            "the header has no TYPE line; expected one type per field",
        ));
    };
    let check = |what: &str, line: usize, got: usize| -> Result<()> {
        if got != n {
            return Err(Error::format(
                path,
                format!(
                    "header line {line} ({what}): {got} entries, but FIELDS (line {names_line}) names \
                     {n} fields; expected one {what} per field (mismatched FIELDS / {what} count)"
                ),
            ));
        }
        Ok(())
    };
    check("SIZE", sizes_line, sizes.len())?;
    check("TYPE", types_line, types.len())?;
    let counts = match counts {
        Some((l, c)) => {
            check("COUNT", l, c.len())?;
            c
        }
        None => vec![1; n],
    };
    let mut fields = Vec::with_capacity(n);
    let mut record = 0usize;
    for (i, name) in names.into_iter().enumerate() {
        let (size, ty, count) = (sizes[i], types[i], counts[i]);
        if ty == Ty::F && size < 4 {
            return Err(Error::format(
                path,
                format!(
                    "header line {types_line}: field {name:?} has TYPE F with SIZE {size}; \
                     floats must have SIZE 4 or 8"
                ),
            ));
        }
        record = size
            .checked_mul(count)
            .and_then(|b| record.checked_add(b))
            .ok_or_else(|| {
                Error::format(
                    path,
                    format!("header line {sizes_line}: the record size overflows"),
                )
            })?;
        fields.push(Field {
            name,
            size,
            ty,
            count,
        });
    }

    let points = match (points, width, height) {
        (Some((line, p)), w, h) => {
            let w = w.unwrap_or(p);
            let h = h.unwrap_or(1);
            if w.checked_mul(h) != Some(p) {
                return Err(Error::format(
                    path,
                    format!(
                        "header line {line} (POINTS): POINTS {p} differs from WIDTH {w} × HEIGHT {h}; \
                         expected them to agree"
                    ),
                ));
            }
            p
        }
        (None, Some(w), h) => w
            .checked_mul(h.unwrap_or(1))
            .ok_or_else(|| Error::format(path, "WIDTH × HEIGHT overflows"))?,
        (None, None, _) => {
            return Err(Error::format(
                path,
                "the header has neither POINTS nor WIDTH; expected the number of points",
            ))
        }
    };
    let width = width.unwrap_or(points);
    let height = height.unwrap_or(1);
    if !version.is_empty()
        && !matches!(version.as_str(), "0.7" | ".7" | "0.6" | ".6" | "0.5" | ".5")
    {
        notes.push(format!("unrecognised PCD VERSION {version}; read as 0.7"));
    }
    Ok(Header {
        version,
        fields,
        width,
        height,
        viewpoint,
        points,
        data,
        data_start,
        data_line,
        notes,
    })
}

/// Random access to the value of component `c` of field `f` of point `i`.
trait Source: Sync {
    fn get(&self, f: usize, c: usize, i: usize) -> f64;
    /// The 32 raw bits of a packed colour field.
    fn bits(&self, f: usize, c: usize, i: usize) -> u32;
}

/// Binary data, either array-of-structures (`binary`) or structure-of-arrays
/// (`binary_compressed`): value (f, c, i) starts at `base[f] + i * stride[f] + c * size[f]`.
/// `data` has been checked to hold every point.
struct BinarySource<'a> {
    data: &'a [u8],
    base: Vec<usize>,
    stride: Vec<usize>,
    size: Vec<usize>,
    ty: Vec<Ty>,
}

impl BinarySource<'_> {
    #[inline]
    fn bytes(&self, f: usize, c: usize, i: usize) -> &[u8] {
        let s = self.size[f];
        let o = self.base[f] + i * self.stride[f] + c * s;
        self.data.get(o..o + s).unwrap_or(&[])
    }
}

#[inline]
fn arr<const N: usize>(b: &[u8]) -> [u8; N] {
    let mut a = [0u8; N];
    if b.len() == N {
        a.copy_from_slice(b);
    }
    a
}

#[inline]
fn scalar(b: &[u8], ty: Ty) -> f64 {
    match (ty, b.len()) {
        (Ty::I, 1) => i8::from_le_bytes(arr(b)) as f64,
        (Ty::U, 1) => u8::from_le_bytes(arr(b)) as f64,
        (Ty::I, 2) => i16::from_le_bytes(arr(b)) as f64,
        (Ty::U, 2) => u16::from_le_bytes(arr(b)) as f64,
        (Ty::I, 4) => i32::from_le_bytes(arr(b)) as f64,
        (Ty::U, 4) => u32::from_le_bytes(arr(b)) as f64,
        (Ty::F, 4) => f32::from_le_bytes(arr(b)) as f64,
        (Ty::I, 8) => i64::from_le_bytes(arr(b)) as f64,
        (Ty::U, 8) => u64::from_le_bytes(arr(b)) as f64,
        (Ty::F, 8) => f64::from_le_bytes(arr(b)),
        _ => f64::NAN,
    }
}

impl Source for BinarySource<'_> {
    fn get(&self, f: usize, c: usize, i: usize) -> f64 {
        scalar(self.bytes(f, c, i), self.ty[f])
    }
    fn bits(&self, f: usize, c: usize, i: usize) -> u32 {
        u32::from_le_bytes(arr(self.bytes(f, c, i)))
    }
}

/// Ascii data parsed into a table of `total` values per point (packed colours hold their bits).
struct AsciiSource {
    table: Vec<f64>,
    total: usize,
    col: Vec<usize>,
}

impl Source for AsciiSource {
    fn get(&self, f: usize, c: usize, i: usize) -> f64 {
        self.table
            .get(i * self.total + self.col[f] + c)
            .copied()
            .unwrap_or(f64::NAN)
    }
    fn bits(&self, f: usize, c: usize, i: usize) -> u32 {
        self.get(f, c, i) as u32
    }
}

/// Parses one ascii token of `field`.
fn parse_token(tok: &str, field: &Field) -> Option<f64> {
    if field.is_packed_color() {
        // PCL writes packed colours as unsigned integers; older files hold the float.
        if let Ok(u) = tok.parse::<u32>() {
            return Some(u as f64);
        }
        return tok.parse::<f32>().ok().map(|v| v.to_bits() as f64);
    }
    match field.ty {
        Ty::F if field.size == 4 => tok.parse::<f32>().ok().map(|v| v as f64),
        Ty::F => tok.parse::<f64>().ok(),
        Ty::I => tok.parse::<i64>().ok().map(|v| v as f64).or_else(|| {
            tok.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && v.fract() == 0.0)
        }),
        Ty::U => tok.parse::<u64>().ok().map(|v| v as f64).or_else(|| {
            tok.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && v.fract() == 0.0 && *v >= 0.0)
        }),
    }
}

fn ascii_source(path: &Path, bytes: &[u8], h: &Header) -> Result<(AsciiSource, Vec<String>)> {
    let total = h.total_count();
    let mut col = Vec::with_capacity(h.fields.len());
    let mut acc = 0;
    for f in &h.fields {
        col.push(acc);
        acc += f.count;
    }
    let data = bytes.get(h.data_start..).unwrap_or_default();
    if h.points == 0 {
        return Ok((
            AsciiSource {
                table: Vec::new(),
                total,
                col,
            },
            Vec::new(),
        ));
    }
    // Every point needs at least `total` one-character tokens and separators.
    let min_bytes = h.points.saturating_mul(2 * total).saturating_sub(1);
    if min_bytes > data.len() {
        return Err(Error::format(
            path,
            format!(
                "POINTS {} with {total} values each cannot fit in the {} bytes of ascii data after \
                 the DATA line (line {}); the file is truncated or POINTS is larger than the data",
                h.points,
                data.len(),
                h.data_line
            ),
        ));
    }
    // `total` is now bounded by the data size (at least one point of `total` values fits).
    let mut owner = Vec::with_capacity(total);
    for (fi, f) in h.fields.iter().enumerate() {
        owner.extend(std::iter::repeat_n(fi, f.count));
    }
    let text = std::str::from_utf8(data).map_err(|e| {
        Error::format(
            path,
            format!(
                "the ascii data is not text (byte {} after the header); expected numbers",
                e.valid_up_to()
            ),
        )
    })?;
    let mut table = Vec::with_capacity(h.points * total);
    let mut notes = Vec::new();
    let mut point = 0usize;
    for (li, line) in text.lines().enumerate() {
        let line_no = h.data_line + 1 + li;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if point == h.points {
            notes.push(format!(
                "ignored text after the {} points announced by POINTS (from line {line_no})",
                h.points
            ));
            break;
        }
        let mut n = 0usize;
        for tok in line.split_ascii_whitespace() {
            let Some(&fi) = owner.get(n) else {
                return Err(Error::format(
                    path,
                    format!(
                        "point {point} (line {line_no}): more than the {total} values the fields \
                         declare"
                    ),
                ));
            };
            let field = &h.fields[fi];
            let v = parse_token(tok, field).ok_or_else(|| {
                Error::format(
                    path,
                    format!(
                        "point {point} (line {line_no}), field {:?}: expected a number of TYPE {:?} \
                         SIZE {}, found non-numeric value {tok:?}",
                        field.name, field.ty, field.size
                    ),
                )
            })?;
            table.push(v);
            n += 1;
        }
        if n != total {
            return Err(Error::format(
                path,
                format!("point {point} (line {line_no}): {n} values, expected {total}"),
            ));
        }
        point += 1;
    }
    if point < h.points {
        return Err(Error::format(
            path,
            format!(
                "POINTS is {} but the ascii data holds only {point} points; the file is truncated \
                 or POINTS is larger than the data",
                h.points
            ),
        ));
    }
    Ok((AsciiSource { table, total, col }, notes))
}

/// Reads a PCD file (see the module documentation for the mapping).
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    let bytes = super::read_bytes(path)?;
    read_from_bytes(path, &bytes)
}

fn read_from_bytes(path: &Path, bytes: &[u8]) -> Result<(Geometry, ReadReport)> {
    let h = parse_header(path, bytes)?;
    let mut report = ReadReport {
        encoding: format!(
            "{} {}",
            match h.data {
                DataKind::Ascii => "ascii",
                DataKind::Binary => "binary",
                DataKind::BinaryCompressed => "binary_compressed",
            },
            if h.version.is_empty() {
                "?"
            } else {
                &h.version
            }
        ),
        notes: h.notes.clone(),
        ..Default::default()
    };
    let record = h.record_size();
    let nf = h.fields.len();
    let mut decompressed = Vec::new();
    let ascii;
    let binary;
    let src: &dyn Source = match h.data {
        DataKind::Ascii => {
            let (s, notes) = ascii_source(path, bytes, &h)?;
            report.notes.extend(notes);
            ascii = s;
            &ascii
        }
        DataKind::Binary => {
            let data = bytes.get(h.data_start..).unwrap_or_default();
            let need = h.points.saturating_mul(record);
            if need > data.len() {
                return Err(Error::format(
                    path,
                    format!(
                        "POINTS {} × {record}-byte records need {need} bytes of binary data, but only \
                         {} bytes follow the DATA line (line {}); the file is truncated or POINTS is \
                         larger than the data",
                        h.points,
                        data.len(),
                        h.data_line
                    ),
                ));
            }
            if data.len() > need {
                report.notes.push(format!(
                    "ignored {} bytes after the binary point data",
                    data.len() - need
                ));
            }
            let mut base = Vec::with_capacity(nf);
            let mut off = 0;
            for f in &h.fields {
                base.push(off);
                off += f.size * f.count;
            }
            binary = BinarySource {
                data: data.get(..need).unwrap_or_default(),
                base,
                stride: vec![record; nf],
                size: h.fields.iter().map(|f| f.size).collect(),
                ty: h.fields.iter().map(|f| f.ty).collect(),
            };
            &binary
        }
        DataKind::BinaryCompressed => {
            decompressed = decompress(path, bytes, &h, record)?;
            let mut base = Vec::with_capacity(nf);
            let mut off = 0;
            for f in &h.fields {
                base.push(off);
                off += f.size * f.count * h.points;
            }
            binary = BinarySource {
                data: &decompressed,
                base,
                stride: h.fields.iter().map(|f| f.size * f.count).collect(),
                size: h.fields.iter().map(|f| f.size).collect(),
                ty: h.fields.iter().map(|f| f.ty).collect(),
            };
            &binary
        }
    };
    let cloud = decode(path, &h, src, &mut report)?;
    drop(decompressed);
    Ok((Geometry::from_cloud(cloud), report))
}

/// Reads and checks the `binary_compressed` block: `compressed_size uncompressed_size` (u32 LE)
/// then the LZF stream of the structure-of-arrays data.
fn decompress(path: &Path, bytes: &[u8], h: &Header, record: usize) -> Result<Vec<u8>> {
    let data = bytes.get(h.data_start..).unwrap_or_default();
    let (Some(cs), Some(us)) = (data.get(0..4), data.get(4..8)) else {
        return Err(Error::format(
            path,
            format!(
                "truncated binary_compressed data: expected the 8-byte size header after the DATA \
                 line (line {}), found {} bytes",
                h.data_line,
                data.len()
            ),
        ));
    };
    let compressed = u32::from_le_bytes(arr(cs)) as usize;
    let uncompressed = u32::from_le_bytes(arr(us)) as usize;
    let need = h.points.saturating_mul(record);
    if uncompressed != need {
        return Err(Error::format(
            path,
            format!(
                "binary_compressed: the uncompressed size is {uncompressed} bytes, but POINTS {} × \
                 {record}-byte records need {need}; expected them to agree",
                h.points
            ),
        ));
    }
    let stream = &data[8..];
    if compressed > stream.len() {
        return Err(Error::format(
            path,
            format!(
                "truncated binary_compressed data: the header announces {compressed} compressed \
                 bytes, but only {} follow (byte offset {})",
                stream.len(),
                h.data_start + 8
            ),
        ));
    }
    if need == 0 {
        return Ok(Vec::new());
    }
    if compressed == 0 || uncompressed > compressed.saturating_mul(LZF_MAX_RATIO) {
        return Err(Error::format(
            path,
            format!(
                "binary_compressed: {compressed} compressed bytes cannot expand to {uncompressed} \
                 (LZF expands at most {LZF_MAX_RATIO}×); the size header is corrupt"
            ),
        ));
    }
    let out = lzf::decompress(&stream[..compressed], uncompressed).map_err(|e| {
        Error::format(
            path,
            format!(
                "binary_compressed: the LZF data (byte offset {}) is corrupt or truncated: {e:?}",
                h.data_start + 8
            ),
        )
    })?;
    if out.len() != uncompressed {
        return Err(Error::format(
            path,
            format!(
                "binary_compressed: the LZF data expands to {} bytes, expected {uncompressed}; the \
                 file is truncated or corrupt",
                out.len()
            ),
        ));
    }
    Ok(out)
}

fn find(h: &Header, name: &str) -> Option<usize> {
    h.fields.iter().position(|f| f.name == name)
}

/// Builds the cloud from any source.
fn decode(
    path: &Path,
    h: &Header,
    src: &dyn Source,
    report: &mut ReadReport,
) -> Result<PointCloud> {
    let n = h.points;
    let (Some(fx), Some(fy), Some(fz)) = (find(h, "x"), find(h, "y"), find(h, "z")) else {
        return Err(Error::format(
            path,
            "the FIELDS line has no x y z fields; expected point positions",
        ));
    };
    let positions_all: Vec<[f64; 3]> = (0..n)
        .into_par_iter()
        .map(|i| [src.get(fx, 0, i), src.get(fy, 0, i), src.get(fz, 0, i)])
        .collect();
    let organised = h.height > 1;
    let (positions, kept): (Vec<[f64; 3]>, Option<Vec<usize>>) = if organised {
        let kept: Vec<usize> = positions_all
            .iter()
            .enumerate()
            .filter(|(_, p)| !p.iter().any(|c| c.is_nan()))
            .map(|(i, _)| i)
            .collect();
        report.dropped_missing = n - kept.len();
        report.notes.push(format!(
            "organised cloud {} × {}; {} points without a return (NaN) dropped",
            h.width, h.height, report.dropped_missing
        ));
        if kept.len() == n {
            (positions_all, None)
        } else {
            (kept.iter().map(|&i| positions_all[i]).collect(), Some(kept))
        }
    } else {
        (positions_all, None)
    };
    let m = positions.len();
    let column = |f: usize, c: usize| -> Vec<f64> {
        match &kept {
            Some(k) => k.par_iter().map(|&i| src.get(f, c, i)).collect(),
            None => (0..m).into_par_iter().map(|i| src.get(f, c, i)).collect(),
        }
    };
    let mut cloud = PointCloud::from_positions(positions);
    let mut used = vec![false; h.fields.len()];
    used[fx] = true;
    used[fy] = true;
    used[fz] = true;
    if let (Some(a), Some(b), Some(c)) = (
        find(h, "normal_x"),
        find(h, "normal_y"),
        find(h, "normal_z"),
    ) {
        let (x, y, z) = (column(a, 0), column(b, 0), column(c, 0));
        let normals = x
            .into_iter()
            .zip(y)
            .zip(z)
            .map(|((x, y), z)| [x, y, z])
            .collect();
        cloud.set_normals(normals)?;
        used[a] = true;
        used[b] = true;
        used[c] = true;
    }
    if let Some(fc) = h.fields.iter().position(|f| f.is_packed_color()) {
        let to_rgb = |bits: u32| {
            let b = bits.to_le_bytes();
            [b[2], b[1], b[0]]
        };
        let colors: Vec<[u8; 3]> = match &kept {
            Some(k) => k.par_iter().map(|&i| to_rgb(src.bits(fc, 0, i))).collect(),
            None => (0..m)
                .into_par_iter()
                .map(|i| to_rgb(src.bits(fc, 0, i)))
                .collect(),
        };
        cloud.set_colors(colors)?;
        used[fc] = true;
    }
    let mut wide = false;
    let mut fields = Vec::new();
    for (fi, f) in h.fields.iter().enumerate() {
        if used[fi] || f.name == "_" {
            continue;
        }
        if f.count > MAX_EXPANDED_COUNT {
            report.notes.push(format!(
                "skipped field {:?} with COUNT {} (more than {MAX_EXPANDED_COUNT} values per point)",
                f.name, f.count
            ));
            continue;
        }
        let (kind, lossy) = f.kind();
        if lossy {
            wide = true;
        }
        for c in 0..f.count {
            let name = if f.count == 1 {
                f.name.clone()
            } else {
                format!("{}_{c}", f.name)
            };
            fields.push(Attribute {
                name,
                kind,
                values: column(fi, c),
            });
        }
    }
    let n = cloud.len();
    cloud.attributes.extend(n, fields)?;
    if wide {
        report.notes.push(
            "8-byte integer fields are stored as F64 attributes (exact up to 2^53)".to_string(),
        );
    }
    if h.viewpoint != [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0] {
        report.notes.push(format!(
            "VIEWPOINT {:?} (sensor pose) not applied to the points",
            h.viewpoint
        ));
    }
    Ok(cloud)
}

/// What a written field holds.
enum Col<'a> {
    Pos(usize),
    Normal(usize),
    Rgb,
    Attr(&'a Attribute),
}

struct OutField<'a> {
    name: String,
    ty: char,
    size: usize,
    col: Col<'a>,
}

fn kind_type(k: ScalarKind) -> (char, usize) {
    match k {
        ScalarKind::I8 => ('I', 1),
        ScalarKind::U8 => ('U', 1),
        ScalarKind::I16 => ('I', 2),
        ScalarKind::U16 => ('U', 2),
        ScalarKind::I32 => ('I', 4),
        ScalarKind::U32 => ('U', 4),
        ScalarKind::F32 => ('F', 4),
        ScalarKind::F64 => ('F', 8),
    }
}

/// True if rounding every coordinate to f32 moves it by at most 1e-6 of the bounding-box
/// diagonal (the rule for writing positions as `F 4`).
pub(crate) fn f32_positions_suffice(cloud: &PointCloud) -> bool {
    let Some(bb) = cloud.aabb() else {
        return true;
    };
    let d = (0..3)
        .map(|k| (bb.max[k] - bb.min[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let tol = 1e-6 * d;
    cloud.positions.par_iter().all(|p| {
        p.iter()
            .all(|&c| !c.is_finite() || ((c as f32) as f64 - c).abs() <= tol)
    })
}

fn out_fields(cloud: &PointCloud) -> Vec<OutField<'_>> {
    let pos_size = if f32_positions_suffice(cloud) { 4 } else { 8 };
    let mut fields: Vec<OutField> = ["x", "y", "z"]
        .iter()
        .enumerate()
        .map(|(k, n)| OutField {
            name: n.to_string(),
            ty: 'F',
            size: pos_size,
            col: Col::Pos(k),
        })
        .collect();
    if cloud.normals.is_some() {
        for (k, n) in ["normal_x", "normal_y", "normal_z"].iter().enumerate() {
            fields.push(OutField {
                name: n.to_string(),
                ty: 'F',
                size: 4,
                col: Col::Normal(k),
            });
        }
    }
    if cloud.colors.is_some() {
        fields.push(OutField {
            name: "rgb".into(),
            ty: 'F',
            size: 4,
            col: Col::Rgb,
        });
    }
    for a in &cloud.attributes {
        let mut name: String = a
            .name
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        if name.is_empty() {
            name = "attribute".into();
        }
        while fields.iter().any(|f| f.name == name) {
            name.push('_');
        }
        let (ty, size) = kind_type(a.kind);
        fields.push(OutField {
            name,
            ty,
            size,
            col: Col::Attr(a),
        });
    }
    fields
}

fn packed_rgb(c: [u8; 3]) -> u32 {
    u32::from_le_bytes([c[2], c[1], c[0], 255])
}

/// Writes a PCD file: `DATA binary`, or `DATA ascii` with `opts.ascii`.
pub fn write(path: &Path, geom: &Geometry, opts: &WriteOptions) -> Result<()> {
    geom.validate()?;
    let cloud = &geom.points;
    let n = cloud.len();
    let fields = out_fields(cloud);
    let mut header = String::from("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n");
    let join = |f: &dyn Fn(&OutField) -> String| fields.iter().map(f).collect::<Vec<_>>().join(" ");
    header.push_str(&format!("FIELDS {}\n", join(&|f| f.name.clone())));
    header.push_str(&format!("SIZE {}\n", join(&|f| f.size.to_string())));
    header.push_str(&format!("TYPE {}\n", join(&|f| f.ty.to_string())));
    header.push_str(&format!("COUNT {}\n", join(&|_| "1".to_string())));
    header.push_str(&format!(
        "WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {}\n",
        if opts.ascii { "ascii" } else { "binary" }
    ));
    let value = |f: &OutField, i: usize| -> f64 {
        match f.col {
            Col::Pos(k) => cloud.positions[i][k],
            Col::Normal(k) => cloud.normals.as_ref().map_or(0.0, |v| v[i][k]),
            Col::Rgb => cloud
                .colors
                .as_ref()
                .map_or(0.0, |v| packed_rgb(v[i]) as f64),
            Col::Attr(a) => a.values[i],
        }
    };
    let mut out = super::create(path)?;
    let io = |e| Error::io(path, e);
    out.write_all(header.as_bytes()).map_err(io)?;
    if opts.ascii {
        const CHUNK: usize = 8192;
        let chunks: Vec<String> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let mut s = String::new();
                for i in c * CHUNK..((c + 1) * CHUNK).min(n) {
                    for (j, f) in fields.iter().enumerate() {
                        if j > 0 {
                            s.push(' ');
                        }
                        let v = value(f, i);
                        use std::fmt::Write as _;
                        let _ = match (f.ty, f.size, &f.col) {
                            (_, _, Col::Rgb) => write!(s, "{}", v as u32),
                            ('F', 4, _) => write!(s, "{}", v as f32),
                            ('F', _, _) => write!(s, "{v}"),
                            _ => write!(s, "{}", v as i64),
                        };
                    }
                    s.push('\n');
                }
                s
            })
            .collect();
        for c in chunks {
            out.write_all(c.as_bytes()).map_err(io)?;
        }
    } else {
        let record: usize = fields.iter().map(|f| f.size).sum();
        let mut buf = vec![0u8; n * record];
        buf.par_chunks_mut(record).enumerate().for_each(|(i, r)| {
            let mut o = 0;
            for f in &fields {
                let v = value(f, i);
                let dst = &mut r[o..o + f.size];
                match (f.ty, f.size, &f.col) {
                    (_, _, Col::Rgb) => dst.copy_from_slice(&(v as u32).to_le_bytes()),
                    ('F', 4, _) => dst.copy_from_slice(&(v as f32).to_le_bytes()),
                    ('F', _, _) => dst.copy_from_slice(&v.to_le_bytes()),
                    ('I', 1, _) => dst.copy_from_slice(&(v as i8).to_le_bytes()),
                    ('U', 1, _) => dst.copy_from_slice(&(v as u8).to_le_bytes()),
                    ('I', 2, _) => dst.copy_from_slice(&(v as i16).to_le_bytes()),
                    ('U', 2, _) => dst.copy_from_slice(&(v as u16).to_le_bytes()),
                    ('I', _, _) => dst.copy_from_slice(&(v as i32).to_le_bytes()),
                    _ => dst.copy_from_slice(&(v as u32).to_le_bytes()),
                }
                o += f.size;
            }
        });
        out.write_all(&buf).map_err(io)?;
    }
    out.flush().map_err(io)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<(Geometry, ReadReport)> {
        read_from_bytes(Path::new("t.pcd"), text.as_bytes())
    }

    #[test]
    fn ascii_with_count_padding_and_rgb() {
        let t = "VERSION .7\nFIELDS x y z _ rgb h\nSIZE 4 4 4 1 4 2\nTYPE F F F U U U\n\
                 COUNT 1 1 1 1 1 2\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n\
                 1 2 3 0 16711680 7 8\n4 5 6 0 255 9 10\n";
        let (g, r) = parse(t).unwrap();
        assert_eq!(g.points.positions, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
        assert_eq!(g.points.colors, Some(vec![[255, 0, 0], [0, 0, 255]]));
        let h1 = g.points.attribute("h_1").unwrap();
        assert_eq!(h1.values, vec![8.0, 10.0]);
        assert_eq!(h1.kind, ScalarKind::U16);
        assert!(g.points.attribute("_").is_none());
        assert_eq!(r.encoding, "ascii .7");
    }

    #[test]
    fn v05_columns_without_width() {
        let t = "VERSION .5\nCOLUMNS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 1\nDATA ascii\n1 2 3\n";
        let (g, _) = parse(t).unwrap();
        assert_eq!(g.points.positions, vec![[1.0, 2.0, 3.0]]);
    }

    #[test]
    fn hostile_sizes_do_not_allocate() {
        let mut t =
            b"FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 100000000\nHEIGHT 1\nPOINTS 100000000\nDATA binary_compressed\n"
                .to_vec();
        t.extend_from_slice(&10u32.to_le_bytes());
        t.extend_from_slice(&1_200_000_000u32.to_le_bytes());
        t.extend_from_slice(&[0u8; 10]);
        assert!(read_from_bytes(Path::new("t.pcd"), &t).is_err());
        let t = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 4000000000000000000\nPOINTS 5\nDATA binary\n";
        assert!(parse(t).is_err());
    }
}
