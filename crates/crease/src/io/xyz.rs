//! Plain-text point clouds: `.xyz`, `.txt`, `.csv`, `.pts` — one point per row.
//!
//! # Reading
//! Values in a row are separated by whitespace, commas or semicolons (any mix, runs count as
//! one separator). Blank lines and comment lines (starting with `#` or `//`) are skipped
//! anywhere. Before the first data row the reader accepts:
//! - a line holding a single integer: a point count (Leica `.pts`); it is skipped, and a
//!   mismatch with the number of rows is noted;
//! - a line with no numeric value: a header naming the columns (e.g. `x,y,z,nx,ny,nz`).
//!   A comment line whose words name exactly as many columns as the data has (CloudCompare's
//!   `//X Y Z R G B`) serves as a header too.
//!
//! Every data row must have the same number of values (at least 3), all numbers; otherwise the
//! read fails naming the line. The first three columns are always `x y z`. The other columns:
//! - with a header: `nx ny nz` (also `normal_x`..) become normals, `r g b` / `red green blue`
//!   become colours (both only when all three are present); any other column becomes a float
//!   attribute under its header name;
//! - without a header, by the number of columns:
//!   - 4: `x y z intensity`;
//!   - 6: `x y z nx ny nz`, except when the last three columns are integers in 0..=255 with
//!     at least one above 1 (they cannot be unit normals): then `x y z r g b`;
//!   - 7: `x y z intensity r g b` (Leica PTS) when the last three are integers in 0..=255,
//!     otherwise attributes `c3`..`c6`;
//!   - any other count: attributes `c3`, `c4`, ... named by their 0-based column.
//!
//! Colours written as floats in 0..1 (all values in [0, 1], at least one not an integer) are
//! scaled to 0..255; other colour values are rounded and clamped to 0..=255. The report's notes
//! say how the columns were read.
//!
//! Big files are parsed in parallel: the text is cut at line ends into chunks, each parsed by a
//! rayon task, and the chunks are concatenated in file order, so the result (and the first error
//! reported) does not depend on the thread count.
//!
//! # Writing
//! `x y z`, or `x y z nx ny nz` when the points have normals, one point per line, with the
//! shortest decimal form that reads back to the same `f64`. A mesh's vertices are written as its
//! points; faces, colours and attributes are not written (use PLY to keep them).
//!
//! This module also holds the small text helpers (line splitting, float formatting, chunked
//! parallel writing) shared with the OBJ, OFF and STL modules.

use std::io::Write;
use std::path::Path;

use rayon::prelude::*;

use super::{create, read_bytes, Geometry, ReadReport, WriteOptions};
use crate::geometry::{Attribute, PointCloud};
use crate::{Error, Result};

/// Reads a text point cloud (see the module documentation for the column rules).
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    let bytes = read_bytes(path)?;
    parse(path, &bytes)
}

/// Writes the points of `geom` as `x y z` or `x y z nx ny nz` rows.
pub fn write(path: &Path, geom: &Geometry, _opts: &WriteOptions) -> Result<()> {
    let mut w = create(path)?;
    let pts = &geom.points;
    let normals = pts.normals.as_deref();
    write_lines_parallel(&mut w, pts.len(), |i, out| {
        let p = pts.positions[i];
        push_f64(out, p[0]);
        out.push(b' ');
        push_f64(out, p[1]);
        out.push(b' ');
        push_f64(out, p[2]);
        if let Some(n) = normals {
            for c in n[i] {
                out.push(b' ');
                push_f64(out, c);
            }
        }
        out.push(b'\n');
    })
    .and_then(|()| w.flush())
    .map_err(|e| Error::io(path, e))
}

/// Parses the bytes of a text point cloud; `path` is used in messages only.
pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(Geometry, ReadReport)> {
    let err = |line: usize, msg: String| Error::format(path, format!("line {line}: {msg}"));
    let mut report = ReadReport {
        encoding: "ascii".into(),
        ..Default::default()
    };

    // The preamble: comments, an optional point count and an optional header, serially.
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut count_line: Option<(usize, u64)> = None;
    let mut header: Option<(usize, Vec<String>)> = None;
    let mut last_comment: Option<Vec<String>> = None;
    let (data_start, data_line, ncols) = loop {
        if pos >= bytes.len() {
            return Err(Error::format(
                path,
                "no points: the file holds no data rows (expected rows of 'x y z' values)",
            ));
        }
        let (line, next) = next_line(bytes, pos);
        line_no += 1;
        let t = trim(line);
        if t.is_empty() {
            pos = next;
            continue;
        }
        if let Some(rest) = comment_body(t) {
            last_comment = Some(split_fields(rest).map(lossy).collect());
            pos = next;
            continue;
        }
        let fields: Vec<&[u8]> = split_fields(t).collect();
        let any_numeric = fields.iter().any(|f| parse_f64(f).is_some());
        if fields.len() == 1 && count_line.is_none() && header.is_none() {
            if let Some(n) = std::str::from_utf8(fields[0])
                .ok()
                .and_then(|s| s.parse::<u64>().ok())
            {
                count_line = Some((line_no, n));
                pos = next;
                continue;
            }
        }
        if !any_numeric && header.is_none() {
            header = Some((line_no, fields.iter().map(|f| lossy(f)).collect()));
            pos = next;
            continue;
        }
        if fields.len() < 3 {
            return Err(err(
                line_no,
                format!(
                    "expected at least 3 values (x y z), found {} ('{}')",
                    fields.len(),
                    lossy(t)
                ),
            ));
        }
        break (pos, line_no, fields.len());
    };

    // The data rows, in parallel chunks cut at line ends.
    let data = &bytes[data_start..];
    let chunks = split_chunks(data, 1 << 20);
    let newlines: Vec<usize> = chunks
        .par_iter()
        .map(|c| c.iter().filter(|&&b| b == b'\n').count())
        .collect();
    let mut first_lines = Vec::with_capacity(chunks.len());
    let mut l = data_line;
    for n in &newlines {
        first_lines.push(l);
        l += n;
    }
    let parsed: Vec<std::result::Result<Vec<f64>, (usize, String)>> = chunks
        .par_iter()
        .zip(first_lines.par_iter())
        .map(|(c, &first)| parse_rows(c, first, ncols, data_line))
        .collect();
    let mut values = Vec::new();
    for p in parsed {
        match p {
            Ok(v) => {
                if values.is_empty() {
                    values = v;
                } else {
                    values.extend_from_slice(&v);
                }
            }
            Err((line, msg)) => return Err(err(line, msg)),
        }
    }
    let n = values.len() / ncols;
    if let Some((cl, count)) = count_line {
        if count != n as u64 {
            report.notes.push(format!(
                "line {cl} gives a point count of {count}, but the file has {n} rows"
            ));
        }
    }

    // Column names: a header line, or a comment line just before the data naming every column.
    let mut names: Option<Vec<String>> = None;
    if let Some((hl, h)) = header {
        if h.len() == ncols {
            names = Some(h);
        } else {
            report.notes.push(format!(
                "the header on line {hl} names {} columns but the rows have {ncols}; header ignored",
                h.len()
            ));
        }
    } else if let Some(c) = last_comment {
        if c.len() == ncols && c.iter().all(|s| parse_f64(s.as_bytes()).is_none()) {
            names = Some(c);
        }
    }

    // One column (in parallel only for long files: a file of many columns and few rows spent
    // its time starting rayon tasks, one per column).
    let column = |j: usize| -> Vec<f64> {
        if values.len() / ncols.max(1) < 1 << 16 {
            values.chunks_exact(ncols).map(|r| r[j]).collect()
        } else {
            values.par_chunks_exact(ncols).map(|r| r[j]).collect()
        }
    };
    let positions: Vec<[f64; 3]> = values
        .par_chunks_exact(ncols)
        .map(|r| [r[0], r[1], r[2]])
        .collect();
    let mut cloud = PointCloud::from_positions(positions);
    let mut roles: Vec<String> = vec!["x".into(), "y".into(), "z".into()];
    let mut attrs: Vec<(usize, String)> = Vec::new();
    let mut normal_cols: Option<[usize; 3]> = None;
    let mut color_cols: Option<[usize; 3]> = None;
    match &names {
        Some(names) => {
            let lower: Vec<String> = names.iter().map(|s| s.to_ascii_lowercase()).collect();
            let find = |alts: &[&str]| -> Option<usize> {
                (3..ncols).find(|&j| alts.contains(&lower[j].as_str()))
            };
            let nx = find(&["nx", "normal_x", "normalx", "n_x"]);
            let ny = find(&["ny", "normal_y", "normaly", "n_y"]);
            let nz = find(&["nz", "normal_z", "normalz", "n_z"]);
            if let (Some(a), Some(b), Some(c)) = (nx, ny, nz) {
                normal_cols = Some([a, b, c]);
            }
            let r = find(&["r", "red"]);
            let g = find(&["g", "green"]);
            let b = find(&["b", "blue"]);
            if let (Some(r), Some(g), Some(b)) = (r, g, b) {
                color_cols = Some([r, g, b]);
            }
            for (j, raw) in names.iter().enumerate().skip(3) {
                let used = normal_cols.is_some_and(|c| c.contains(&j))
                    || color_cols.is_some_and(|c| c.contains(&j));
                if !used {
                    let name = raw.trim();
                    let taken = name.is_empty()
                        || attrs.iter().any(|(_, a)| a == name)
                        || ["x", "y", "z"].contains(&name);
                    let name = if taken {
                        format!("c{j}")
                    } else {
                        name.to_string()
                    };
                    attrs.push((j, name));
                }
            }
        }
        None => {
            let bytes_like = |j: usize| {
                values.par_chunks_exact(ncols).all(|r| {
                    let v = r[j];
                    v.fract() == 0.0 && (0.0..=255.0).contains(&v)
                })
            };
            let any_above_one = |j: usize| values.par_chunks_exact(ncols).any(|r| r[j] > 1.0);
            match ncols {
                3 => {}
                4 => attrs.push((3, "intensity".into())),
                6 => {
                    if (3..6).all(bytes_like) && (3..6).any(any_above_one) {
                        color_cols = Some([3, 4, 5]);
                    } else {
                        normal_cols = Some([3, 4, 5]);
                    }
                }
                7 if (4..7).all(bytes_like) => {
                    attrs.push((3, "intensity".into()));
                    color_cols = Some([4, 5, 6]);
                }
                _ => attrs.extend((3..ncols).map(|j| (j, format!("c{j}")))),
            }
        }
    }
    if let Some([a, b, c]) = normal_cols {
        let normals: Vec<[f64; 3]> = values
            .par_chunks_exact(ncols)
            .map(|r| [r[a], r[b], r[c]])
            .collect();
        cloud.normals = Some(normals);
        roles.extend(["nx", "ny", "nz"].map(String::from));
    }
    if let Some([a, b, c]) = color_cols {
        let unit = values
            .par_chunks_exact(ncols)
            .all(|r| [r[a], r[b], r[c]].iter().all(|v| (0.0..=1.0).contains(v)))
            && values
                .par_chunks_exact(ncols)
                .any(|r| [r[a], r[b], r[c]].iter().any(|v| v.fract() != 0.0));
        let scale = if unit { 255.0 } else { 1.0 };
        let colors: Vec<[u8; 3]> = values
            .par_chunks_exact(ncols)
            .map(|r| [r[a], r[b], r[c]].map(|v| to_u8(v * scale)))
            .collect();
        cloud.colors = Some(colors);
        roles.push(if unit {
            "r g b (0..1)".into()
        } else {
            "r g b (0..255)".into()
        });
    }
    let mut columns = Vec::with_capacity(attrs.len());
    for (j, name) in &attrs {
        roles.push(name.clone());
        columns.push(Attribute::float(name.clone(), column(*j)));
    }
    let n = cloud.len();
    cloud
        .attributes
        .extend(n, columns)
        .map_err(|e| Error::format(path, e.to_string()))?;
    report.encoding = format!("ascii, {ncols} columns");
    if ncols > 3 {
        report.notes.push(format!(
            "columns read as: {}{}",
            roles.join(" "),
            if names.is_some() {
                " (from the header)"
            } else {
                ""
            }
        ));
    }
    Ok((Geometry::from_cloud(cloud), report))
}

/// Parses the data rows of one chunk into a flat array (`ncols` values per row).
/// `first` is the 1-based line number of the chunk's first line.
fn parse_rows(
    chunk: &[u8],
    first: usize,
    ncols: usize,
    ref_line: usize,
) -> std::result::Result<Vec<f64>, (usize, String)> {
    let mut out = Vec::with_capacity(chunk.len() / 8 + ncols);
    let mut pos = 0;
    let mut line = first;
    while pos < chunk.len() {
        let (l, next) = next_line(chunk, pos);
        pos = next;
        let t = trim(l);
        if !t.is_empty() && comment_body(t).is_none() {
            let mut k = 0;
            for f in split_fields(t) {
                if k < ncols {
                    match parse_f64(f) {
                        Some(v) => out.push(v),
                        None => {
                            return Err((
                                line,
                                format!(
                                    "column {}: expected a number, found '{}'",
                                    k + 1,
                                    lossy(f)
                                ),
                            ))
                        }
                    }
                }
                k += 1;
            }
            if k != ncols {
                return Err((
                    line,
                    format!(
                        "expected {ncols} values (as on line {ref_line}), found {k}: '{}'",
                        lossy(t)
                    ),
                ));
            }
        }
        line += 1;
    }
    Ok(out)
}

/// Cuts `data` into chunks of about `target` bytes, each ending just after a newline (the last
/// one at the end of the data).
pub(super) fn split_chunks(data: &[u8], target: usize) -> Vec<&[u8]> {
    let mut chunks = Vec::new();
    let mut start = 0;
    while start < data.len() {
        let mut end = (start + target).min(data.len());
        while end < data.len() && data[end - 1] != b'\n' {
            end += 1;
        }
        chunks.push(&data[start..end]);
        start = end;
    }
    chunks
}

/// The line starting at `pos` (without its `\n` and a trailing `\r`) and the start of the next.
pub(super) fn next_line(bytes: &[u8], pos: usize) -> (&[u8], usize) {
    let rest = &bytes[pos.min(bytes.len())..];
    let (line, next) = match rest.iter().position(|&b| b == b'\n') {
        Some(i) => (&rest[..i], pos + i + 1),
        None => (rest, bytes.len()),
    };
    (line.strip_suffix(b"\r").unwrap_or(line), next)
}

/// `s` without leading and trailing ASCII whitespace.
pub(super) fn trim(s: &[u8]) -> &[u8] {
    s.trim_ascii()
}

/// If `t` (trimmed) is a `#` or `//` comment, the text after the marker.
fn comment_body(t: &[u8]) -> Option<&[u8]> {
    t.strip_prefix(b"#").or_else(|| t.strip_prefix(b"//"))
}

/// The values of a row separated by whitespace, commas or semicolons.
fn split_fields(t: &[u8]) -> Fields<'_> {
    Fields {
        s: t,
        pos: 0,
        punct: true,
    }
}

/// Iterator over the values of a row (see [`split_fields`] and [`tokens`]).
pub(super) struct Fields<'a> {
    s: &'a [u8],
    pos: usize,
    /// Commas and semicolons separate too.
    punct: bool,
}

impl<'a> Iterator for Fields<'a> {
    type Item = &'a [u8];
    #[inline]
    fn next(&mut self) -> Option<&'a [u8]> {
        let punct = self.punct;
        let sep = |b: u8| {
            matches!(b, b' ' | b'\t' | b'\r' | b'\n' | 0x0b | 0x0c)
                || (punct && (b == b',' || b == b';'))
        };
        let s = self.s;
        let mut i = self.pos;
        while i < s.len() && sep(s[i]) {
            i += 1;
        }
        if i >= s.len() {
            self.pos = i;
            return None;
        }
        let start = i;
        while i < s.len() && !sep(s[i]) {
            i += 1;
        }
        self.pos = i;
        Some(&s[start..i])
    }
}

/// Whitespace-separated tokens.
pub(super) fn tokens(t: &[u8]) -> impl Iterator<Item = &[u8]> {
    t.split(|b| b.is_ascii_whitespace())
        .filter(|f| !f.is_empty())
}

/// Parses a decimal number (also exponents, `nan`, `inf`), correctly rounded.
///
/// Plain decimals `[-+]digits[.digits]` whose digits form an integer below 2^53 take Clinger's
/// fast path (an exact integer divided by an exact power of ten is correctly rounded); anything
/// else goes to the standard library's parser.
#[inline]
pub(super) fn parse_f64(tok: &[u8]) -> Option<f64> {
    const POW10: [f64; 23] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
        1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
    ];
    let (neg, body) = match tok.first() {
        Some(b'-') => (true, &tok[1..]),
        Some(b'+') => (false, &tok[1..]),
        _ => (false, tok),
    };
    let mut mant: u64 = 0;
    let mut digits = 0usize;
    let mut frac: Option<usize> = None;
    let mut simple = !body.is_empty() && body.len() <= 40;
    if simple {
        for (i, &b) in body.iter().enumerate() {
            match b {
                b'0'..=b'9' => {
                    if digits == 19 {
                        simple = false;
                        break;
                    }
                    mant = mant * 10 + u64::from(b - b'0');
                    digits += 1;
                }
                b'.' if frac.is_none() => frac = Some(i),
                _ => {
                    simple = false;
                    break;
                }
            }
        }
    }
    if simple && digits > 0 && mant <= 1 << 53 {
        let scale = frac.map_or(0, |i| body.len() - i - 1);
        if let Some(&p) = POW10.get(scale) {
            let v = mant as f64 / p;
            return Some(if neg { -v } else { v });
        }
    }
    std::str::from_utf8(tok).ok()?.parse::<f64>().ok()
}

/// A token as text for an error message (shortened when long).
pub(super) fn lossy(tok: &[u8]) -> String {
    let s = String::from_utf8_lossy(tok);
    if s.chars().count() > 60 {
        let short: String = s.chars().take(60).collect();
        format!("{short}...")
    } else {
        s.into_owned()
    }
}

/// A colour component rounded and clamped to 0..=255.
pub(super) fn to_u8(v: f64) -> u8 {
    if v.is_nan() {
        0
    } else {
        v.round().clamp(0.0, 255.0) as u8
    }
}

/// Appends the shortest decimal text that reads back as exactly `x` (plain notation for
/// ordinary magnitudes, exponent notation for very large or small ones).
pub(super) fn push_f64(out: &mut Vec<u8>, x: f64) {
    let a = x.abs();
    if x == 0.0 || (1e-5..1e16).contains(&a) || !x.is_finite() {
        let _ = write!(out, "{x}");
    } else {
        let _ = write!(out, "{x:e}");
    }
}

/// Writes `n` records to `w`, formatting blocks of records in parallel with `fmt(i, buf)` and
/// writing the blocks in order.
pub(super) fn write_lines_parallel<W: Write, F>(w: &mut W, n: usize, fmt: F) -> std::io::Result<()>
where
    F: Fn(usize, &mut Vec<u8>) + Sync,
{
    const BLOCK: usize = 16_384;
    const BATCH: usize = 64;
    let blocks = n.div_ceil(BLOCK);
    let mut b = 0;
    while b < blocks {
        let end = (b + BATCH).min(blocks);
        let bufs: Vec<Vec<u8>> = (b..end)
            .into_par_iter()
            .map(|k| {
                let mut buf = Vec::with_capacity(BLOCK * 32);
                for i in k * BLOCK..((k + 1) * BLOCK).min(n) {
                    fmt(i, &mut buf);
                }
                buf
            })
            .collect();
        for buf in bufs {
            w.write_all(&buf)?;
        }
        b = end;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_float_path_matches_std() {
        let mut rng = 0x1234_5678_9abc_def0u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        let mut texts: Vec<String> = [
            "0",
            "-0",
            "+1",
            "1.",
            ".5",
            "-.5",
            "0.1",
            "9007199254740993",
            "9007199254740992",
            "12345678901234567890",
            "1e5",
            "1E-5",
            "nan",
            "-inf",
            "0.30000000000000004",
            "123456789.12345679",
            "1.7976931348623157",
            "",
            "-",
            ".",
            "1.2.3",
            "1,5",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        for _ in 0..200_000 {
            let x = f64::from_bits(next());
            if x.is_finite() {
                texts.push(format!("{x}"));
                texts.push(format!("{x:e}"));
            }
            let m = next() % 10_000_000_000_000_000;
            let d = (next() % 20) as usize;
            let s = format!("{m}");
            let cut = s.len().saturating_sub(d);
            texts.push(format!("-{}.{}", &s[..cut], &s[cut..]));
        }
        for t in &texts {
            let want = t.parse::<f64>().ok().map(f64::to_bits);
            let got = parse_f64(t.as_bytes()).map(f64::to_bits);
            assert_eq!(got, want, "{t:?}");
        }
    }
}
