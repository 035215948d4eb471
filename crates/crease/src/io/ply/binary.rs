//! Binary bodies (little and big endian): fixed-size rows decoded in parallel, rows with lists
//! one after the other.

use std::path::Path;

use rayon::prelude::*;

use super::columns::{Col, RawCol};
use super::header::{ElementDef, PropDef, PropType};
use crate::geometry::ScalarKind;
use crate::{Error, Result};

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

pub(super) fn decode_binary<'a>(
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
pub(super) fn read_scalar(bytes: &[u8], pos: usize, kind: ScalarKind, be: bool) -> Option<f64> {
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
