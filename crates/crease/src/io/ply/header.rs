//! The PLY header: element and property definitions, parsed and checked against the file.

use std::path::Path;

use super::PlyEncoding;
use crate::geometry::ScalarKind;
use crate::{Error, Result};

#[derive(Debug, Clone, Copy)]
pub(super) enum PropType {
    Scalar(ScalarKind),
    List { count: ScalarKind, item: ScalarKind },
}

#[derive(Debug, Clone)]
pub(super) struct PropDef {
    pub(super) name: String,
    pub(super) ty: PropType,
}

#[derive(Debug, Clone)]
pub(super) struct ElementDef {
    pub(super) name: String,
    pub(super) count: usize,
    pub(super) props: Vec<PropDef>,
    /// Header line of the `element` line, for messages.
    pub(super) line: usize,
}

#[derive(Debug)]
pub(super) struct Header {
    pub(super) encoding: PlyEncoding,
    pub(super) version: String,
    pub(super) elements: Vec<ElementDef>,
    pub(super) body_start: usize,
}

pub(super) fn is_face_index_list(name: &str) -> bool {
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

pub(super) fn parse_header(path: &Path, bytes: &[u8]) -> Result<Header> {
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
