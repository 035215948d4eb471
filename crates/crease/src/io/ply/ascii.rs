//! ASCII bodies: rows found line by line and parsed in parallel chunks.

use std::path::Path;

use rayon::prelude::*;

use super::columns::Col;
use super::header::{ElementDef, PropType};
use crate::geometry::ScalarKind;
use crate::{Error, Result};

/// Rows per parallel chunk.
const CHUNK: usize = 16 * 1024;

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

pub(super) fn decode_ascii(
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
