//! An interactive 3D view of a [`Scene`] in one self-contained HTML file (`crease view`, the
//! `report.html` of `crease run`): orbit, pan, zoom; points or faces coloured by any attribute
//! with a legend or a colour bar; each polyline group a layer that toggles; a click on a point or
//! face shows its attributes and, when it belongs to a surface of the segmentation, the surface's
//! type, parameters, point count and RMS.
//!
//! * **Offline**: three.js r170 (MIT, its licence kept in the page) is vendored in
//!   `assets/three/` (`scripts/vendor-three.py` makes the bundle from the pinned npm package) and
//!   inlined with the viewer's own script (`assets/view/`); a Content-Security-Policy forbids
//!   every network request.
//! * **Compact**: positions quantised to 16 bits per axis over the bounding box (1/65,535 of its
//!   extent, far below a pixel), flags and small integers in 8 or 16 bits exactly, floats in 16
//!   bits over their range (a click shows them so rounded, to 1/65,534 of the range); all
//!   base64 in `<script type="application/octet-stream">` blocks: about 11 bytes per point with
//!   `crease run`'s six attributes (1M points: 15 MB), 33 bytes with a synthetic part's nine
//!   ground-truth attributes too (1M points: 32 MB). Normals are left out.
//! * **Large inputs**: above [`PageParams::max_points`] points an even subsample (every k-th
//!   point in Morton order) is embedded, and the page says so.
//! * Fragment options (for links and the browser tests): `#color=ATTR`, `#layer-NAME=off` (a
//!   polyline group), `#points=off`, `#click=X,Y` (a click at that pixel once drawn).

use base64::Engine;

use crate::geometry::{Aabb, Attribute, Point3, ScalarKind};
use crate::render::{Polyline, Scene};
use crate::spatial::morton_order;
use crate::spatial::spacing::average_spacing;
use crate::{Error, Result};

/// three.js r170 and OrbitControls as one classic script (`scripts/vendor-three.py`).
const THREE: &str = include_str!("../../assets/three/three.bundle.js");
/// three.js' licence, kept in the page.
const THREE_LICENSE: &str = include_str!("../../assets/three/LICENSE");
/// The viewer's script.
const APP: &str = include_str!("../../assets/view/view.js");
/// The viewer's style sheet.
const STYLE: &str = include_str!("../../assets/view/view.css");

/// Forbids every request: scripts and styles only inline, images only from data.
const CSP: &str = "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; \
                   img-src data: blob:; base-uri 'none'; form-action 'none'";

/// Options of [`page`].
#[derive(Debug, Clone, PartialEq)]
pub struct PageParams {
    /// Shown on top and as the page's title.
    pub title: String,
    /// The attribute the points (or faces) are first coloured by; `None`: `surface` when
    /// present, else the stored colours, else one colour.
    pub color_by: Option<String>,
    /// The segmentation's surfaces (`crease segment --primitives`, `surfaces.json`): a click on
    /// a point or face whose `surface` attribute names one shows it.
    pub surfaces: Option<serde_json::Value>,
    /// Above this many points, an even subsample of this size is embedded (default 2,000,000).
    pub max_points: usize,
    /// Further meshes shown as layers of their own, coloured by their faces' `surface_type`
    /// (`crease run`'s report: the B-rep's faces, tessellated).
    pub overlays: Vec<Overlay>,
}

/// A mesh shown as a layer of its own (see [`PageParams::overlays`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Overlay {
    /// The layer's name.
    pub name: String,
    /// The triangles, with face attributes (shown when clicked).
    pub mesh: crate::geometry::TriMesh,
    /// Shown when the page opens.
    pub visible: bool,
}

impl Default for PageParams {
    fn default() -> Self {
        PageParams {
            title: "crease".into(),
            color_by: None,
            surfaces: None,
            max_points: 2_000_000,
            overlays: Vec::new(),
        }
    }
}

/// Overlays with more triangles are left out (the page says so): a 1M-point view stays under
/// 40 MB with one of this size (12 bytes per triangle, 6 per vertex, 2 per attribute, base64).
pub const MAX_OVERLAY_TRIANGLES: usize = 600_000;

/// Attributes that are not worth their bytes in a view (normals: directions, not values).
const SKIPPED: [&str; 3] = ["nx", "ny", "nz"];

/// The page's data blocks and their description, built up by [`page`].
struct Blocks {
    html: String,
    count: usize,
}

impl Blocks {
    fn add(&mut self, bytes: &[u8]) -> String {
        let id = format!("b{}", self.count);
        self.count += 1;
        self.html.push_str(&format!(
            "<script type=\"application/octet-stream\" id=\"{id}\">"
        ));
        self.html
            .push_str(&base64::engine::general_purpose::STANDARD.encode(bytes));
        self.html.push_str("</script>\n");
        id
    }

    /// An attribute's values at `rows` in the smallest exact encoding (u8, i16, i32) for
    /// integers, floats in 16 bits over their range; returns its description for the script.
    fn attribute(&mut self, a: &Attribute, rows: Option<&[u32]>) -> serde_json::Value {
        let pick = |i: usize| rows.map_or(i, |r| r[i] as usize);
        let n = rows.map_or(a.values.len(), <[u32]>::len);
        let integer = a.kind.is_integer() && a.values.iter().all(|v| v.fract() == 0.0);
        let (lo, hi) = a
            .values
            .iter()
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
                (l.min(v), h.max(v))
            });
        let (ty, bytes): (&str, Vec<u8>) = if integer && lo >= 0.0 && hi <= 255.0 {
            ("u8", (0..n).map(|i| a.values[pick(i)] as u8).collect())
        } else if integer && lo >= -32768.0 && hi <= 32767.0 {
            (
                "i16",
                (0..n)
                    .flat_map(|i| (a.values[pick(i)] as i16).to_le_bytes())
                    .collect(),
            )
        } else if integer && lo >= f64::from(i32::MIN) && hi <= f64::from(i32::MAX) {
            (
                "i32",
                (0..n)
                    .flat_map(|i| (a.values[pick(i)] as i32).to_le_bytes())
                    .collect(),
            )
        } else {
            // Floats to 16 bits over their finite range (65,535: not finite).
            let span = if hi > lo { hi - lo } else { 1.0 };
            (
                "q16",
                (0..n)
                    .flat_map(|i| {
                        let v = a.values[pick(i)];
                        let q = if v.is_finite() {
                            ((v - lo) / span * 65534.0).round().clamp(0.0, 65534.0) as u16
                        } else {
                            u16::MAX
                        };
                        q.to_le_bytes()
                    })
                    .collect(),
            )
        };
        let kind = if a.kind == ScalarKind::U8 && lo >= 0.0 && hi <= 1.0 && integer {
            "flag"
        } else if integer {
            "int"
        } else {
            "float"
        };
        let id = self.add(&bytes);
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 0.0) };
        serde_json::json!({
            "name": a.name, "block": id, "type": ty, "kind": kind, "lo": lo, "hi": hi,
        })
    }
}

/// Positions quantised to u16 over `b` (little-endian, x y z per point).
fn quantised(points: &[Point3], rows: Option<&[u32]>, b: &Aabb) -> Vec<u8> {
    let ext = [0, 1, 2].map(|a| (b.max[a] - b.min[a]).max(f64::MIN_POSITIVE));
    let n = rows.map_or(points.len(), <[u32]>::len);
    let mut out = Vec::with_capacity(n * 6);
    for i in 0..n {
        let p = points[rows.map_or(i, |r| r[i] as usize)];
        for a in 0..3 {
            let q = ((p[a] - b.min[a]) / ext[a] * 65535.0)
                .round()
                .clamp(0.0, 65535.0) as u16;
            out.extend_from_slice(&q.to_le_bytes());
        }
    }
    out
}

/// Polylines grouped into layers by label (then colour), as line segments relative to the box's
/// centre (f32 pairs).
fn layers(polylines: &[Polyline], centre: Point3, blocks: &mut Blocks) -> Vec<serde_json::Value> {
    let mut groups: Vec<(String, [u8; 3], Vec<u8>, usize)> = Vec::new();
    for l in polylines {
        let name = l.label.clone().unwrap_or_else(|| "lines".into());
        let g = match groups.iter().position(|g| g.0 == name && g.1 == l.color) {
            Some(g) => g,
            None => {
                groups.push((name, l.color, Vec::new(), 0));
                groups.len() - 1
            }
        };
        let mut seg = |p: Point3, q: Point3| {
            for v in [p, q] {
                for a in 0..3 {
                    groups[g]
                        .2
                        .extend_from_slice(&((v[a] - centre[a]) as f32).to_le_bytes());
                }
            }
        };
        for w in l.points.windows(2) {
            seg(w[0], w[1]);
        }
        if l.closed && l.points.len() > 2 {
            seg(l.points[l.points.len() - 1], l.points[0]);
        }
        groups[g].3 += 1;
    }
    groups
        .into_iter()
        .map(|(name, color, bytes, count)| {
            let id = blocks.add(&bytes);
            serde_json::json!({ "name": name, "color": color, "block": id, "polylines": count })
        })
        .collect()
}

/// The page of `scene` (see the module documentation). Errors: an empty scene, non-finite
/// coordinates.
pub fn page(scene: &Scene<'_>, params: &PageParams) -> Result<String> {
    let cloud = scene.points.or(scene.mesh.map(|m| &m.vertices));
    let positions: &[Point3] = cloud.map_or(&[], |c| &c.positions);
    let all = || {
        positions
            .iter()
            .chain(scene.polylines.iter().flat_map(|l| l.points.iter()))
    };
    let b = Aabb::enclosing(all().copied())
        .ok_or_else(|| Error::InvalidInput("a view of nothing: no point, face or line".into()))?;
    if all().flatten().any(|v| !v.is_finite()) {
        return Err(Error::InvalidInput(
            "a view of non-finite coordinates".into(),
        ));
    }
    let centre = [0, 1, 2].map(|a| 0.5 * (b.min[a] + b.max[a]));
    let mut blocks = Blocks {
        html: String::new(),
        count: 0,
    };
    // The points embedded: all, or an even subsample (meshes keep every vertex).
    let total = positions.len();
    let rows: Option<Vec<u32>> =
        (scene.mesh.is_none() && total > params.max_points.max(1)).then(|| {
            let order = morton_order(positions);
            let step = total.div_ceil(params.max_points.max(1));
            let mut keep: Vec<u32> = order.into_iter().step_by(step).collect();
            keep.sort_unstable();
            keep
        });
    let shown = rows.as_ref().map_or(total, Vec::len);
    let mut meta = serde_json::json!({
        "title": params.title,
        "points": shown,
        "total_points": total,
        "mesh": scene.mesh.is_some(),
        "min": b.min,
        "max": b.max,
        "centre": centre,
        "color_by": params.color_by,
        "surfaces": params.surfaces,
    });
    if total > 0 {
        meta["positions"] =
            serde_json::json!(blocks.add(&quantised(positions, rows.as_deref(), &b)));
    }
    if scene.mesh.is_none() && total > 1 {
        // Points are drawn as squares about this wide, so that a sampled surface looks closed.
        let shown_points: Vec<Point3> = match &rows {
            Some(r) => r.iter().map(|&i| positions[i as usize]).collect(),
            None => positions.to_vec(),
        };
        meta["spacing"] = serde_json::json!(average_spacing(&shown_points));
    }
    if let Some(c) = cloud {
        let attrs: Vec<serde_json::Value> = c
            .attributes
            .iter()
            .filter(|a| !SKIPPED.contains(&a.name.as_str()) && a.values.len() == total)
            .map(|a| blocks.attribute(a, rows.as_deref()))
            .collect();
        meta["attributes"] = serde_json::json!(attrs);
        if let Some(rgb) = c.colors.as_ref().filter(|rgb| rgb.len() == total) {
            let bytes: Vec<u8> = match &rows {
                Some(r) => r.iter().flat_map(|&i| rgb[i as usize]).collect(),
                None => rgb.iter().flatten().copied().collect(),
            };
            meta["colors"] = serde_json::json!(blocks.add(&bytes));
        }
    }
    if let Some(m) = scene.mesh {
        let faces: Vec<u8> = m
            .faces
            .iter()
            .flatten()
            .flat_map(|i| i.to_le_bytes())
            .collect();
        meta["faces"] = serde_json::json!(blocks.add(&faces));
        meta["face_count"] = serde_json::json!(m.faces.len());
        let attrs: Vec<serde_json::Value> = m
            .face_attributes
            .iter()
            .filter(|a| a.values.len() == m.faces.len())
            .map(|a| blocks.attribute(a, None))
            .collect();
        meta["face_attributes"] = serde_json::json!(attrs);
    }
    meta["layers"] = serde_json::json!(layers(&scene.polylines, centre, &mut blocks));
    let mut left_out = Vec::new();
    let overlays: Vec<serde_json::Value> = params
        .overlays
        .iter()
        .filter(|o| {
            let fits = o.mesh.faces.len() <= MAX_OVERLAY_TRIANGLES;
            if !fits {
                left_out.push(format!(
                    "{} not shown: {} triangles (more than {MAX_OVERLAY_TRIANGLES})",
                    o.name,
                    o.mesh.faces.len()
                ));
            }
            fits
        })
        .map(|o| {
            let pos = quantised(&o.mesh.vertices.positions, None, &b);
            let faces: Vec<u8> = o
                .mesh
                .faces
                .iter()
                .flatten()
                .flat_map(|i| i.to_le_bytes())
                .collect();
            let attrs: Vec<serde_json::Value> = o
                .mesh
                .face_attributes
                .iter()
                .filter(|a| a.values.len() == o.mesh.faces.len())
                .map(|a| blocks.attribute(a, None))
                .collect();
            serde_json::json!({
                "name": o.name,
                "visible": o.visible,
                "positions": blocks.add(&pos),
                "faces": blocks.add(&faces),
                "face_count": o.mesh.faces.len(),
                "face_attributes": attrs,
            })
        })
        .collect();
    meta["overlays"] = serde_json::json!(overlays);
    meta["left_out"] = serde_json::json!(left_out);
    let meta = serde_json::to_string(&meta)
        .map_err(|e| Error::InvalidInput(format!("the view's description: {e}")))?
        // JSON inside <script>: no "</" can close the element early.
        .replace("</", "<\\/");
    let title = escape(&params.title);
    Ok(format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n\
         <meta http-equiv=\"Content-Security-Policy\" content=\"{CSP}\">\n\
         <meta name=\"viewport\" content=\"width=device-width,initial-scale=1\">\n\
         <title>{title}</title>\n<!-- Made by crease (https://github.com/crease-rs/crease). It \
         embeds three.js r170, whose licence follows.\n{licence}-->\n<style>{STYLE}</style>\n\
         </head><body>\n<div id=\"panel\"><div id=\"title\">{title}</div><div id=\"note\"></div>\
         <div id=\"controls\"></div><div id=\"legend\"></div></div>\n<div id=\"info\"></div>\n\
         <script type=\"application/json\" id=\"meta\">{meta}</script>\n{data}\
         <script>\n\"use strict\";\n{THREE}\n{{\n{APP}\n}}\n</script>\n</body></html>\n",
        licence = THREE_LICENSE.replace("--", "- -"),
        data = blocks.html,
    ))
}

/// `s` with the HTML special characters escaped.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
