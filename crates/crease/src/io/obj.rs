//! Wavefront OBJ reading and writing (geometry only: `v`, `vn`, `f`, `l`).
//!
//! Our own parser rather than `tobj` 4: tobj splits the file into models at `o`/`g` and renumbers
//! each model's vertices (breaking the vertex numbering that ground-truth files such as ABC's
//! feature YAML index into), stores `f32` by default, has no `l` polylines, and reports errors
//! without a line number. What crease needs from OBJ is small enough to parse directly.
//!
//! # Reading
//! - `v x y z [w]` (`w` ignored) and the colour extension `v x y z r g b [a]` (floats in 0..1,
//!   or 0..255 if any value is above 1; `a` ignored). Colours are kept when every vertex has one.
//! - `vn x y z`; `vt` is ignored (noted).
//! - `f` with corners `v`, `v/vt`, `v/vt/vn` or `v//vn`; indices are 1-based, negative indices
//!   count back from the latest element. Polygons are fan-triangulated (`(c0, ci, ci+1)`) and
//!   counted in [`ReadReport::polygons_triangulated`].
//! - OBJ attaches normals to face corners. When every vertex gets one normal (equal values at
//!   all its corners — the usual `f v//vn` export of a smooth mesh), they become per-vertex
//!   normals; when a vertex has different normals on different faces (a sharp edge) or no
//!   normal, normals are left unset and a note says why. A file with `vn` lines but no face
//!   using them and as many `vn` as `v` lines (a point cloud export) pairs them by order.
//! - `l` polylines (`v` or `v/vt` indices) go to [`Geometry::polylines`].
//! - `p`, `o`, `g`, `s`, `usemtl`, `mtllib` and unknown statements (`vc`, `vp`, curves...)
//!   are ignored with one note per kind.
//! - `#` comments, `\` line continuation, `\r\n` line ends.
//!
//! Errors name the file and the 1-based line (the first line of a continued statement).
//!
//! # Writing
//! `v x y z [r g b]` (colours as `c / 255`), `vn` and `f a//a b//b c//c` when the points have
//! normals, `f a b c` otherwise, `l` for each polyline and each edge. Floats use the shortest
//! text that reads back to the same `f64`.

use std::io::Write;
use std::path::Path;

use super::xyz::{lossy, parse_f64, push_f64, to_u8, tokens, trim, write_lines_parallel};
use super::{create, read_bytes, Geometry, ReadReport, WriteOptions};
use crate::geometry::PointCloud;
use crate::{Error, Result};

const NONE: u32 = u32::MAX;

/// Reads an OBJ file (see the module documentation for what is read).
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    let bytes = read_bytes(path)?;
    parse(path, &bytes)
}

/// Writes `geom` as OBJ: vertices (with colours), normals, triangles, polylines and edges.
pub fn write(path: &Path, geom: &Geometry, _opts: &WriteOptions) -> Result<()> {
    let io = |e| Error::io(path, e);
    let mut w = create(path)?;
    let pts = &geom.points;
    writeln!(
        w,
        "# written by crease: {} vertices, {} triangles, {} polylines, {} edges",
        pts.len(),
        geom.faces.len(),
        geom.polylines.len(),
        geom.edges.len()
    )
    .map_err(io)?;
    let colors = pts.colors.as_deref();
    write_lines_parallel(&mut w, pts.len(), |i, out| {
        out.extend_from_slice(b"v");
        for c in pts.positions[i] {
            out.push(b' ');
            push_f64(out, c);
        }
        if let Some(col) = colors {
            for c in col[i] {
                out.push(b' ');
                push_f64(out, f64::from(c) / 255.0);
            }
        }
        out.push(b'\n');
    })
    .map_err(io)?;
    let normals = pts.normals.as_deref();
    if let Some(n) = normals {
        write_lines_parallel(&mut w, n.len(), |i, out| {
            out.extend_from_slice(b"vn");
            for c in n[i] {
                out.push(b' ');
                push_f64(out, c);
            }
            out.push(b'\n');
        })
        .map_err(io)?;
    }
    let with_n = normals.is_some();
    write_lines_parallel(&mut w, geom.faces.len(), |i, out| {
        out.push(b'f');
        for v in geom.faces[i] {
            let k = u64::from(v) + 1;
            if with_n {
                let _ = write!(out, " {k}//{k}");
            } else {
                let _ = write!(out, " {k}");
            }
        }
        out.push(b'\n');
    })
    .map_err(io)?;
    let mut buf = Vec::new();
    let grouped = geom.polyline_groups.len() == geom.polylines.len();
    let mut group: Option<&str> = None;
    for (i, l) in geom.polylines.iter().enumerate() {
        if grouped && group != Some(geom.polyline_groups[i].as_str()) {
            group = Some(geom.polyline_groups[i].as_str());
            writeln!(w, "g {}", geom.polyline_groups[i]).map_err(io)?;
        }
        buf.clear();
        buf.push(b'l');
        for &v in l {
            let _ = write!(buf, " {}", u64::from(v) + 1);
        }
        buf.push(b'\n');
        w.write_all(&buf).map_err(io)?;
    }
    write_lines_parallel(&mut w, geom.edges.len(), |i, out| {
        let [a, b] = geom.edges[i];
        let _ = writeln!(out, "l {} {}", u64::from(a) + 1, u64::from(b) + 1);
    })
    .map_err(io)?;
    w.flush().map_err(io)
}

/// The parser's state.
#[derive(Default)]
struct Parser {
    positions: Vec<[f64; 3]>,
    colors: Vec<[f64; 3]>,
    normals: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
    polylines: Vec<Vec<u32>>,
    /// The group (`g`) each polyline was read in, and the current one.
    polyline_groups: Vec<String>,
    group: String,
    triangulated: usize,
    /// Normal index per vertex from the face corners (`NONE` if none yet).
    vertex_normal: Vec<u32>,
    /// (vertex, normal) corners to check at the end: forward references and conflicts.
    pending: Vec<(u32, u32)>,
    /// Face corners seen with and without a normal.
    corners_with_normal: usize,
    corners_without_normal: usize,
    /// Largest positive vertex / normal index used, with its line, checked at the end.
    max_v: Option<(u32, usize, &'static str)>,
    max_vn: Option<(u32, usize)>,
    /// Ignored statements: keyword and count, in order of first appearance.
    ignored: Vec<(String, usize)>,
    /// Scratch: the corners of the current face / line.
    corners: Vec<(u32, u32)>,
}

/// Parses the bytes of an OBJ file; `path` is used in messages only.
pub(crate) fn parse(path: &Path, bytes: &[u8]) -> Result<(Geometry, ReadReport)> {
    let mut p = Parser::default();
    let mut pos = 0;
    let mut line_no = 0usize;
    let mut joined: Vec<u8> = Vec::new();
    while pos < bytes.len() {
        let (line, next) = super::xyz::next_line(bytes, pos);
        pos = next;
        line_no += 1;
        let start = line_no;
        let body = trim(line);
        if let Some(head) = body.strip_suffix(b"\\") {
            joined.clear();
            joined.extend_from_slice(head);
            joined.push(b' ');
            while pos < bytes.len() {
                let (l, next) = super::xyz::next_line(bytes, pos);
                pos = next;
                line_no += 1;
                let t = trim(l);
                match t.strip_suffix(b"\\") {
                    Some(h) => {
                        joined.extend_from_slice(h);
                        joined.push(b' ');
                    }
                    None => {
                        joined.extend_from_slice(t);
                        break;
                    }
                }
            }
            p.statement(&joined, start)
                .map_err(|m| Error::format(path, format!("line {start}: {m}")))?;
        } else {
            p.statement(body, start)
                .map_err(|m| Error::format(path, format!("line {start}: {m}")))?;
        }
    }
    p.finish(path)
}

impl Parser {
    /// Handles one logical line.
    fn statement(&mut self, line: &[u8], ln: usize) -> std::result::Result<(), String> {
        let line = match line.iter().position(|&b| b == b'#') {
            Some(i) => &line[..i],
            None => line,
        };
        let mut toks = tokens(line);
        let Some(key) = toks.next() else {
            return Ok(());
        };
        match key {
            b"v" => {
                let mut vals = [0.0f64; 8];
                let mut k = 0;
                for t in toks {
                    let v = parse_f64(t).ok_or_else(|| {
                        format!(
                            "expected 3 coordinates after 'v', found '{}'",
                            lossy(trim(line))
                        )
                    })?;
                    if k < vals.len() {
                        vals[k] = v;
                    }
                    k += 1;
                }
                match k {
                    3 | 4 => {}
                    6 | 7 => self.colors.push([vals[3], vals[4], vals[5]]),
                    _ => {
                        return Err(format!(
                            "expected 'v x y z', 'v x y z w' or 'v x y z r g b', found {k} values"
                        ))
                    }
                }
                self.positions.push([vals[0], vals[1], vals[2]]);
            }
            b"vn" => {
                let mut n = [0.0; 3];
                let mut k = 0;
                for t in toks {
                    let v = parse_f64(t).ok_or_else(|| {
                        format!(
                            "expected 3 numbers after 'vn', found '{}'",
                            lossy(trim(line))
                        )
                    })?;
                    if k < 3 {
                        n[k] = v;
                    }
                    k += 1;
                }
                if k != 3 {
                    return Err(format!("expected 3 numbers after 'vn', found {k}"));
                }
                self.normals.push(n);
            }
            b"f" => {
                self.corners.clear();
                for t in toks {
                    let c = self.corner(t, ln, "face")?;
                    self.corners.push(c);
                }
                let k = self.corners.len();
                if k < 3 {
                    return Err(format!("a face needs at least 3 vertices, found {k}"));
                }
                if k > 3 {
                    self.triangulated += 1;
                }
                for i in 0..k {
                    let (v, n) = self.corners[i];
                    self.corner_normal(v, n);
                }
                let c0 = self.corners[0].0;
                for i in 1..k - 1 {
                    self.faces
                        .push([c0, self.corners[i].0, self.corners[i + 1].0]);
                }
            }
            b"l" => {
                self.corners.clear();
                for t in toks {
                    let c = self.corner(t, ln, "polyline")?;
                    self.corners.push(c);
                }
                if self.corners.len() < 2 {
                    return Err(format!(
                        "a polyline ('l') needs at least 2 vertices, found {}",
                        self.corners.len()
                    ));
                }
                self.polylines
                    .push(self.corners.iter().map(|c| c.0).collect());
                self.polyline_groups.push(self.group.clone());
            }
            // Groups name the polylines that follow (crease writes its curve network's kinds so:
            // `sharp`, `smooth`, `boundary`); other uses of groups are not kept.
            b"g" => {
                self.group = toks.map(lossy).collect::<Vec<_>>().join(" ");
            }
            _ => {
                let k = String::from_utf8_lossy(key);
                match self.ignored.iter_mut().find(|(name, _)| *name == k) {
                    Some((_, n)) => *n += 1,
                    None => self.ignored.push((lossy(key), 1)),
                }
            }
        }
        Ok(())
    }

    /// Parses a corner `v`, `v/vt`, `v/vt/vn` or `v//vn` into 0-based (vertex, normal or NONE).
    fn corner(
        &mut self,
        tok: &[u8],
        ln: usize,
        what: &'static str,
    ) -> std::result::Result<(u32, u32), String> {
        let mut parts = tok.split(|&b| b == b'/');
        let vpart = parts.next().unwrap_or(b"");
        if let Some(vt) = parts.next().filter(|p| !p.is_empty()) {
            let ok = std::str::from_utf8(vt)
                .ok()
                .and_then(|s| s.parse::<i64>().ok())
                .is_some_and(|i| i != 0);
            if !ok {
                return Err(format!(
                    "expected a texture index in {what} corner '{}', found '{}'",
                    lossy(tok),
                    lossy(vt)
                ));
            }
        }
        let npart = parts.next().filter(|p| !p.is_empty());
        if parts.next().is_some() {
            return Err(format!(
                "expected a {what} corner 'v', 'v/vt', 'v/vt/vn' or 'v//vn', found '{}'",
                lossy(tok)
            ));
        }
        let v = resolve(vpart, self.positions.len(), "vertex", what, tok)?;
        if v.1 && self.max_v.is_none_or(|(m, _, _)| v.0 > m) {
            self.max_v = Some((v.0, ln, what));
        }
        let n = match npart {
            Some(np) => {
                let n = resolve(np, self.normals.len(), "normal", what, tok)?;
                if n.1 && self.max_vn.is_none_or(|(m, _)| n.0 > m) {
                    self.max_vn = Some((n.0, ln));
                }
                n.0
            }
            None => NONE,
        };
        Ok((v.0, n))
    }

    /// Records the normal a face corner gives its vertex.
    fn corner_normal(&mut self, v: u32, n: u32) {
        if n == NONE {
            self.corners_without_normal += 1;
            return;
        }
        self.corners_with_normal += 1;
        let vi = v as usize;
        if vi >= self.positions.len() {
            self.pending.push((v, n));
            return;
        }
        if self.vertex_normal.len() < self.positions.len() {
            self.vertex_normal.resize(self.positions.len(), NONE);
        }
        let slot = &mut self.vertex_normal[vi];
        if *slot == NONE {
            *slot = n;
        } else if *slot != n {
            self.pending.push((v, n));
        }
    }

    fn finish(mut self, path: &Path) -> Result<(Geometry, ReadReport)> {
        let nv = self.positions.len();
        if nv == 0 {
            return Err(Error::format(
                path,
                "no vertices: the file has no 'v' lines (empty or not an OBJ file)",
            ));
        }
        if let Some((m, ln, what)) = self.max_v {
            if m as usize >= nv {
                return Err(Error::format(
                    path,
                    format!(
                        "line {ln}: {what} refers to vertex {}, but the file has {nv} vertices",
                        u64::from(m) + 1
                    ),
                ));
            }
        }
        let nn = self.normals.len();
        if let Some((m, ln)) = self.max_vn {
            if m as usize >= nn {
                return Err(Error::format(
                    path,
                    format!(
                        "line {ln}: face refers to normal {}, but the file has {nn} 'vn' lines",
                        u64::from(m) + 1
                    ),
                ));
            }
        }
        let mut report = ReadReport {
            encoding: "ascii".into(),
            polygons_triangulated: self.triangulated,
            ..Default::default()
        };
        let mut cloud = PointCloud::from_positions(std::mem::take(&mut self.positions));

        // Colours.
        if !self.colors.is_empty() {
            if self.colors.len() == nv {
                let unit = self
                    .colors
                    .iter()
                    .all(|c| c.iter().all(|v| (0.0..=1.0).contains(v)));
                let scale = if unit { 255.0 } else { 1.0 };
                cloud.colors = Some(
                    self.colors
                        .iter()
                        .map(|c| c.map(|v| to_u8(v * scale)))
                        .collect(),
                );
                if !unit {
                    report
                        .notes
                        .push("vertex colours above 1 read as 0..255 values".into());
                }
            } else {
                report.notes.push(format!(
                    "only {} of {nv} vertices have colours; colours ignored",
                    self.colors.len()
                ));
            }
        }

        // Normals.
        if nn > 0 {
            if self.corners_with_normal == 0 {
                if nn == nv {
                    cloud.normals = Some(std::mem::take(&mut self.normals));
                    report.notes.push(
                        "no face uses the 'vn' normals; they were paired with the vertices by order"
                            .into(),
                    );
                } else {
                    report.notes.push(format!(
                        "{nn} 'vn' normals are used by no face and do not pair with the {nv} vertices; ignored"
                    ));
                }
            } else {
                self.vertex_normal.resize(nv, NONE);
                let mut conflict = vec![false; nv];
                for &(v, n) in &self.pending {
                    let slot = &mut self.vertex_normal[v as usize];
                    if *slot == NONE {
                        *slot = n;
                    } else if *slot != n && self.normals[*slot as usize] != self.normals[n as usize]
                    {
                        conflict[v as usize] = true;
                    }
                }
                let conflicting = conflict.iter().filter(|&&c| c).count();
                let missing = self.vertex_normal.iter().filter(|&&n| n == NONE).count();
                if conflicting > 0 {
                    report.notes.push(format!(
                        "normals not set: {conflicting} vertices have different normals on different faces (OBJ per-corner normals, e.g. at sharp edges)"
                    ));
                } else if missing > 0 {
                    report.notes.push(format!(
                        "normals not set: {missing} vertices get no normal from any face"
                    ));
                } else {
                    cloud.normals = Some(
                        self.vertex_normal
                            .iter()
                            .map(|&n| self.normals[n as usize])
                            .collect(),
                    );
                    if self.corners_without_normal > 0 {
                        report.notes.push(format!(
                            "{} face corners have no normal; their vertices' normals come from other faces",
                            self.corners_without_normal
                        ));
                    }
                }
            }
        }

        for (k, n) in &self.ignored {
            let what = match k.as_str() {
                "vt" => " (texture coordinates)",
                "p" => " (points)",
                "o" => " (object names)",
                "s" => " (smoothing groups)",
                "usemtl" | "mtllib" => " (materials)",
                _ => "",
            };
            report
                .notes
                .push(format!("ignored {n} '{k}' statement(s){what}"));
        }
        let named = self.polyline_groups.iter().any(|g| !g.is_empty());
        let geom = Geometry {
            points: cloud,
            faces: self.faces,
            polylines: self.polylines,
            polyline_groups: if named {
                self.polyline_groups
            } else {
                Vec::new()
            },
            ..Default::default()
        };
        Ok((geom, report))
    }
}

/// Resolves a 1-based or negative OBJ index against `count` elements defined so far.
/// Returns the 0-based index and whether it was positive (then checked at the end of the file,
/// since it may refer to an element defined later).
fn resolve(
    part: &[u8],
    count: usize,
    elem: &str,
    what: &str,
    tok: &[u8],
) -> std::result::Result<(u32, bool), String> {
    let i: i64 = std::str::from_utf8(part)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| {
            format!(
                "expected a {elem} index in {what} corner '{}', found '{}'",
                lossy(tok),
                lossy(part)
            )
        })?;
    if i == 0 {
        return Err(format!(
            "{elem} index 0 in {what} corner '{}' is invalid (OBJ indices start at 1)",
            lossy(tok)
        ));
    }
    if i > 0 {
        if i > i64::from(u32::MAX) {
            return Err(format!("{elem} index {i} is out of range"));
        }
        return Ok(((i - 1) as u32, true));
    }
    let k = count as i64 + i;
    if k < 0 {
        return Err(format!(
            "relative {elem} index {i} reaches before the first {elem} (only {count} defined so far)"
        ));
    }
    Ok((k as u32, false))
}
