//! PNG quick-looks of points, meshes, labels, scores and feature polylines, drawn on the CPU
//! (no display, no GPU) into a `tiny_skia::Pixmap`.
//!
//! The default image shows the scene from four directions in a 2 × 2 grid (isometric, front,
//! top, side), each with its name and a small axis triad, all at the same scale so that sizes
//! compare, plus a legend on the right and an optional title on top.
//!
//! * Cameras are orthographic, fitted to the scene's bounding box (module `camera`).
//! * Each view is rasterised into its own z-buffer (module `raster`); views are drawn in parallel.
//!   Points are discs facing the camera (size chosen from the point count and the image size
//!   unless given), triangles are flat-shaded (Gouraud when the mesh has vertex normals) with a
//!   camera-mounted light (Lambert + ambient).
//! * Polylines are drawn on top, 2–3 px wide and anti-aliased. They are depth-tested against the
//!   surface with a bias of 1 % of the scene diagonal (plus the point radius): the parts hidden
//!   behind the surface stay visible but faint (25 % opacity), like hidden lines in a drawing.
//! * Colours ([`ColorBy`]): uniform, stored RGB, normal directions, or an attribute — few
//!   distinct integers get a qualitative palette with one legend entry each (0/1 flags grey /
//!   red, `sharp` and `surface_type` named), many integers (cluster ids) hashed colours, floats
//!   viridis between the 1st and 99th percentiles with a colour bar ([`colormap`]).
//! * Text uses a built-in 5 × 9 bitmap font ([`font`]).
//!
//! ```
//! use crease::render::{render, Polyline, RenderParams, Scene, ColorBy};
//! use crease::{Attribute, PointCloud};
//!
//! let mut cloud = PointCloud::from_positions(
//!     (0..400).map(|i| [(i % 20) as f64, (i / 20) as f64, 0.0]).collect(),
//! );
//! let flag = (0..400).map(|i| i % 20 == 0);
//! cloud.set_attribute(Attribute::flag("sharp", flag)).unwrap();
//! let scene = Scene {
//!     points: Some(&cloud),
//!     mesh: None,
//!     polylines: vec![Polyline {
//!         points: vec![[0.0, 0.0, 0.0], [19.0, 19.0, 0.0]],
//!         closed: false,
//!         color: [31, 119, 180],
//!         label: Some("diagonal".into()),
//!     }],
//! };
//! let params = RenderParams {
//!     width: 800,
//!     height: 600,
//!     color_by: ColorBy::Attribute("sharp".into()),
//!     ..Default::default()
//! };
//! let image = render(&scene, &params).unwrap();
//! assert_eq!((image.width(), image.height()), (800, 600));
//! ```

mod camera;
pub mod colormap;
pub mod font;
pub mod html;
mod legend;
mod raster;
mod style;

use std::io::Write;
use std::path::Path;

use rayon::prelude::*;

use crate::geometry::vec3::{cross, dot, normalize, sub};
use crate::geometry::{Aabb, PointCloud, TriMesh};
use crate::{Error, Result};
use camera::Camera;
use raster::{disc_stamp, shade, Canvas, ViewBuffer};
use style::{MeshStyle, PointStyle, Style};

pub use crate::geometry::Point3;
pub use colormap::{SHARP_LINE, SMOOTH_LINE};

/// What decides the colour of points and mesh faces.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum ColorBy {
    /// One colour; lit by the headlight when normals are available.
    #[default]
    Uniform,
    /// The cloud's (or mesh vertices') stored colours.
    Rgb,
    /// Normal direction mapped to RGB: `(n + 1) / 2`.
    Normal,
    /// A named attribute: looked up on the points, then the mesh vertices, then the mesh faces.
    Attribute(String),
}

/// How the image is divided into views.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ViewLayout {
    /// Isometric plus the three axis views (front, top, side) in a 2 × 2 grid, each labelled.
    #[default]
    Four,
    /// One view filling the image.
    Single(View),
}

/// A viewing direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum View {
    /// From the (+1, −1, +1) diagonal: front, right side and top visible, Z up.
    Iso,
    /// From −Y looking toward +Y, Z up, X to the right.
    Front,
    /// From above looking down −Z, Y up, X to the right.
    Top,
    /// From +X looking toward −X, Z up, Y to the right.
    Side,
}

impl View {
    /// The label drawn on the view.
    pub fn label(self) -> &'static str {
        match self {
            View::Iso => "Isometric",
            View::Front => "Front (from -Y)",
            View::Top => "Top (from +Z)",
            View::Side => "Side (from +X)",
        }
    }
}

/// Rendering options.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderParams {
    /// Width of the whole image in pixels (default 1600).
    pub width: u32,
    /// Height of the whole image in pixels (default 1200).
    pub height: u32,
    /// Views to draw (default: four).
    pub layout: ViewLayout,
    /// Colouring (default: uniform).
    pub color_by: ColorBy,
    /// Point diameter in pixels; `None` chooses it from the point count and the view size
    /// (larger for fewer points, so that a sampled surface looks closed).
    pub point_size: Option<f32>,
    /// Background colour (default white).
    pub background: [u8; 3],
    /// Title drawn above the views.
    pub title: Option<String>,
    /// Draw the legend panel on the right (default true).
    pub legend: bool,
}

impl Default for RenderParams {
    fn default() -> Self {
        RenderParams {
            width: 1600,
            height: 1200,
            layout: ViewLayout::Four,
            color_by: ColorBy::Uniform,
            point_size: None,
            background: [255, 255, 255],
            title: None,
            legend: true,
        }
    }
}

/// A polyline to draw over the scene (a feature curve).
#[derive(Debug, Clone, PartialEq)]
pub struct Polyline {
    /// Vertices in order.
    pub points: Vec<Point3>,
    /// Whether the last vertex joins the first.
    pub closed: bool,
    /// Stroke colour.
    pub color: [u8; 3],
    /// Legend entry (e.g. `sharp`, `smooth`); polylines with the same label and colour share one.
    pub label: Option<String>,
}

/// What to draw.
#[derive(Debug, Clone, Default)]
pub struct Scene<'a> {
    /// A point cloud.
    pub points: Option<&'a PointCloud>,
    /// A triangle mesh.
    pub mesh: Option<&'a TriMesh>,
    /// Polylines drawn on top.
    pub polylines: Vec<Polyline>,
}

/// Smallest image side accepted.
const MIN_SIDE: u32 = 32;
/// Largest image side accepted.
const MAX_SIDE: u32 = 16384;
/// Ambient light.
const AMBIENT: f32 = 0.38;
/// Diffuse light.
const DIFFUSE: f32 = 0.62;
/// Opacity factor of polyline parts hidden behind the surface.
const HIDDEN_ALPHA: f32 = 0.25;

/// Bounding box of everything finite in the scene (points, mesh vertices, polyline vertices).
pub(crate) fn scene_bbox(scene: &Scene) -> Option<Aabb> {
    let mut b: Option<Aabb> = None;
    let mut add = |p: &Point3| {
        if p.iter().all(|v| v.is_finite()) {
            match &mut b {
                Some(b) => b.grow(*p),
                None => b = Some(Aabb { min: *p, max: *p }),
            }
        }
    };
    if let Some(pc) = scene.points {
        pc.positions.iter().for_each(&mut add);
    }
    if let Some(m) = scene.mesh {
        if !m.faces.is_empty() {
            m.positions().iter().for_each(&mut add);
        }
    }
    for pl in &scene.polylines {
        pl.points.iter().for_each(&mut add);
    }
    b
}

/// A pixel rectangle.
#[derive(Debug, Clone, Copy)]
struct Rect {
    x: i64,
    y: i64,
    w: u32,
    h: u32,
}

/// Everything a view needs besides its camera.
struct Job<'s, 'a> {
    scene: &'s Scene<'a>,
    style: &'s Style<'a>,
    /// Point diameter in pixels, `None` for automatic (per view).
    point_size: Option<f32>,
    /// Largest automatic point diameter.
    max_point: f32,
    line_hw: f32,
    /// Depth bias of polylines before the point radius is added, in world units.
    bias: f64,
}

/// Side in pixels of the cells used to measure the on-screen point density.
const DENSITY_CELL: f32 = 16.0;

/// Automatic point diameter for one view: the points are binned into 16-pixel cells; in each
/// cell only the points within three cells' depth of the nearest one count (the visible
/// layer, not the far side of a closed surface). With `k` the median count over occupied
/// cells, the on-screen spacing is `s = 16 / sqrt(k)` px and the diameter `1.5 s + 1` (enough
/// to close the gaps of a regular or moderately irregular sampling once disc centres are
/// snapped to pixels), clamped to [1, `max_d`].
fn auto_point_size(points: &[Point3], cam: &Camera, w: u32, h: u32, max_d: f32) -> f32 {
    let gw = (w as f32 / DENSITY_CELL).ceil().max(1.0) as usize;
    let gh = (h as f32 / DENSITY_CELL).ceil().max(1.0) as usize;
    let cell = |x: f32, y: f32| -> Option<usize> {
        if x < 0.0 || y < 0.0 {
            return None;
        }
        let (cx, cy) = ((x / DENSITY_CELL) as usize, (y / DENSITY_CELL) as usize);
        (cx < gw && cy < gh).then_some(cy * gw + cx)
    };
    let mut zmin = vec![f32::INFINITY; gw * gh];
    for &p in points {
        if let Some((x, y, z)) = cam.project(p) {
            if let Some(slot) = cell(x, y).and_then(|c| zmin.get_mut(c)) {
                *slot = slot.min(z);
            }
        }
    }
    let slab = (3.0 * f64::from(DENSITY_CELL) / cam.scale) as f32;
    let mut count = vec![0u32; gw * gh];
    for &p in points {
        if let Some((x, y, z)) = cam.project(p) {
            if let Some(c) = cell(x, y) {
                if let (Some(&zm), Some(n)) = (zmin.get(c), count.get_mut(c)) {
                    if z <= zm + slab {
                        *n += 1;
                    }
                }
            }
        }
    }
    let mut occupied: Vec<u32> = count.into_iter().filter(|&n| n > 0).collect();
    if occupied.is_empty() {
        return max_d;
    }
    let mid = occupied.len() / 2;
    let (_, k, _) = occupied.select_nth_unstable(mid);
    let spacing = DENSITY_CELL / (*k as f32).sqrt();
    (1.5 * spacing + 1.0).clamp(1.0, max_d)
}

/// Draws one view: mesh, then points, then polylines.
fn draw_view(job: &Job, cam: &Camera, w: u32, h: u32) -> ViewBuffer {
    let mut vb = ViewBuffer::new(w, h);
    let light = cam.light_dir();
    let lit = |n: Point3| -> f32 {
        // Two-sided: turn the normal toward the eye first.
        let s = if dot(n, cam.forward) > 0.0 { -1.0 } else { 1.0 };
        AMBIENT + DIFFUSE * (s * dot(n, light)).max(0.0) as f32
    };
    if let (Some(mesh), Some(ms)) = (job.scene.mesh, &job.style.mesh) {
        let pos = mesh.positions();
        let proj: Vec<Option<(f32, f32, f32)>> = pos.iter().map(|&p| cam.project(p)).collect();
        let vlight: Option<Vec<f32>> = mesh
            .vertices
            .normals
            .as_ref()
            .filter(|n| n.len() == pos.len())
            .map(|n| {
                n.iter()
                    .map(|&v| {
                        if v.iter().all(|c| c.is_finite()) {
                            lit(v)
                        } else {
                            AMBIENT
                        }
                    })
                    .collect()
            });
        for (fi, f) in mesh.faces.iter().enumerate() {
            let idx = [f[0] as usize, f[1] as usize, f[2] as usize];
            let (Some(Some(a)), Some(Some(b)), Some(Some(c))) =
                (proj.get(idx[0]), proj.get(idx[1]), proj.get(idx[2]))
            else {
                continue;
            };
            let (Some(&pa), Some(&pb), Some(&pc)) =
                (pos.get(idx[0]), pos.get(idx[1]), pos.get(idx[2]))
            else {
                continue;
            };
            let flat = normalize(cross(sub(pb, pa), sub(pc, pa))).map_or(AMBIENT, lit);
            let inten = |bary: [f32; 3]| -> f32 {
                match &vlight {
                    Some(l) => {
                        let g = |i: usize| l.get(i).copied().unwrap_or(AMBIENT);
                        bary[0] * g(idx[0]) + bary[1] * g(idx[1]) + bary[2] * g(idx[2])
                    }
                    None => flat,
                }
            };
            let nearest = |bary: [f32; 3]| -> usize {
                if bary[0] >= bary[1] && bary[0] >= bary[2] {
                    idx[0]
                } else if bary[1] >= bary[2] {
                    idx[1]
                } else {
                    idx[2]
                }
            };
            vb.triangle([*a, *b, *c], |bary| {
                let base = match ms {
                    MeshStyle::Uniform(c) => *c,
                    MeshStyle::Face(cols) => cols.get(fi).copied().unwrap_or(colormap::UNASSIGNED),
                    MeshStyle::VertexNearest(cols) => cols
                        .get(nearest(bary))
                        .copied()
                        .unwrap_or(colormap::UNASSIGNED),
                    MeshStyle::VertexInterp(cols) => {
                        let g = |i: usize| cols.get(i).copied().unwrap_or(colormap::UNASSIGNED);
                        let (c0, c1, c2) = (g(idx[0]), g(idx[1]), g(idx[2]));
                        let f = |k: usize| {
                            (bary[0] * f32::from(c0[k])
                                + bary[1] * f32::from(c1[k])
                                + bary[2] * f32::from(c2[k]))
                            .round()
                            .clamp(0.0, 255.0) as u8
                        };
                        [f(0), f(1), f(2)]
                    }
                    MeshStyle::VertexScalar(t) => {
                        let g = |i: usize| t.get(i).copied().unwrap_or(f32::NAN);
                        let v = bary[0] * g(idx[0]) + bary[1] * g(idx[1]) + bary[2] * g(idx[2]);
                        if v.is_finite() {
                            colormap::viridis(f64::from(v))
                        } else {
                            let tn = g(nearest(bary));
                            if tn.is_finite() {
                                colormap::viridis(f64::from(tn))
                            } else {
                                colormap::UNASSIGNED
                            }
                        }
                    }
                };
                shade(base, inten(bary))
            });
        }
    }
    let point_d = match (job.point_size, job.scene.points) {
        (Some(d), _) => d,
        (None, Some(pc)) => auto_point_size(&pc.positions, cam, w, h, job.max_point),
        (None, None) => 1.0,
    };
    if let (Some(pc), Some(ps)) = (job.scene.points, &job.style.points) {
        let stamp = disc_stamp(point_d);
        let (fw, fh) = (w as f32, h as f32);
        let r = point_d;
        for (i, &p) in pc.positions.iter().enumerate() {
            let Some((x, y, z)) = cam.project(p) else {
                continue;
            };
            if x < -r || y < -r || x > fw + r || y > fh + r {
                continue;
            }
            let c = match ps {
                PointStyle::Fixed(cols) => cols.get(i).copied().unwrap_or(colormap::UNASSIGNED),
                PointStyle::Flat(c) => *c,
                PointStyle::Lit(c, normals) => match normals.get(i) {
                    Some(&n) if n.iter().all(|v| v.is_finite()) => shade(*c, lit(n)),
                    _ => *c,
                },
            };
            vb.splat(x, y, z, c, &stamp);
        }
    }
    let bias = (job.bias + f64::from(point_d * 0.5) / cam.scale) as f32;
    for pl in &job.scene.polylines {
        let proj: Vec<Option<(f32, f32, f32)>> =
            pl.points.iter().map(|&p| cam.project(p)).collect();
        let n = proj.len();
        let segs = if pl.closed && n > 2 {
            n
        } else {
            n.saturating_sub(1)
        };
        for s in 0..segs {
            let (Some(Some(a)), Some(Some(b))) = (proj.get(s), proj.get((s + 1) % n)) else {
                continue;
            };
            vb.stroke(*a, *b, job.line_hw, pl.color, bias, HIDDEN_ALPHA);
        }
    }
    vb
}

/// Draws a small axis triad (x red, y green, z blue) with its origin at (`ox`, `oy`).
fn draw_triad(canvas: &mut Canvas, cam: &Camera, ox: f32, oy: f32, len: f32, ts: u32) {
    let axes = [
        ([1.0, 0.0, 0.0], "x", [214, 39, 40]),
        ([0.0, 1.0, 0.0], "y", [44, 160, 44]),
        ([0.0, 0.0, 1.0], "z", [31, 119, 180]),
    ];
    for (dir, name, color) in axes {
        let (dx, dy) = cam.screen_dir(dir);
        let l = (dx * dx + dy * dy).sqrt();
        if l < 0.2 {
            continue; // pointing at the viewer
        }
        let (tx, ty) = (ox + (dx as f32) * len, oy + (dy as f32) * len);
        canvas.line(ox, oy, tx, ty, 1.5 * ts as f32 / 2.0 + 0.5, color);
        let off = (font::CAP_H * ts) as f32 * 0.9 + 2.0;
        let lx = tx + (dx / l) as f32 * off - (font::GLYPH_W * ts) as f32 * 0.5;
        let ly = ty + (dy / l) as f32 * off - (font::CAP_H * ts) as f32 * 0.5;
        font::draw_text(
            canvas,
            lx.round() as i64,
            ly.round() as i64,
            name,
            ts,
            color,
            false,
        );
    }
}

/// Renders `scene` into an image of `params.width` × `params.height` pixels.
///
/// Fails if the scene holds nothing with finite coordinates, if the image size is outside
/// 32..=16384 pixels per side, if a mesh face refers to a missing vertex, or if the colouring
/// asks for data that is absent (the error lists the attributes that exist). Points with
/// non-finite coordinates are skipped (and counted in the legend).
pub fn render(scene: &Scene, params: &RenderParams) -> Result<tiny_skia::Pixmap> {
    let (w, h) = (params.width, params.height);
    if !(MIN_SIDE..=MAX_SIDE).contains(&w) || !(MIN_SIDE..=MAX_SIDE).contains(&h) {
        return Err(Error::InvalidArgument(format!(
            "image size {w} x {h}: each side must be between {MIN_SIDE} and {MAX_SIDE} pixels"
        )));
    }
    if let Some(m) = scene.mesh {
        m.check_indices()?;
    }
    let bbox = scene_bbox(scene).ok_or_else(|| {
        Error::InvalidInput(
            "nothing to render: the scene has no points, triangles or polylines with finite coordinates".into(),
        )
    })?;
    let style = style::resolve(scene, &params.color_by)?;
    let views: Vec<View> = match params.layout {
        ViewLayout::Four => vec![View::Iso, View::Front, View::Top, View::Side],
        ViewLayout::Single(v) => vec![v],
    };

    // Sizes that follow the image size.
    let ts: u32 = if w.min(h) >= 700 { 2 } else { 1 };
    let bg = params.background;
    let lum = 0.299 * f32::from(bg[0]) + 0.587 * f32::from(bg[1]) + 0.114 * f32::from(bg[2]);
    let ink = if lum > 128.0 {
        legend::Ink {
            text: [40, 40, 40],
            dim: [118, 118, 118],
            frame: [214, 214, 214],
        }
    } else {
        legend::Ink {
            text: [232, 232, 232],
            dim: [165, 165, 165],
            frame: [84, 84, 84],
        }
    };
    let line_w = (w.min(h) as f32 / 480.0).clamp(2.0, 3.0);
    let margin = i64::from(10 * ts);
    let gap = i64::from(8 * ts);
    let pad = i64::from(6 * ts);

    let skipped = scene.points.map_or(0, |p| {
        p.positions
            .iter()
            .filter(|q| !q.iter().all(|v| v.is_finite()))
            .count()
    });

    // Title bar.
    let title_scale = ts + 1;
    let mut top = margin;
    if params.title.is_some() {
        top += i64::from(font::line_height(title_scale)) + gap;
    }

    // Legend panel (never wider than a third of the image).
    let legend = params
        .legend
        .then(|| legend::Legend::build(scene, &style.legend, skipped, ts, line_w));
    let legend_w = legend
        .as_ref()
        .map_or(0, |l| i64::from(l.width().min(w / 3)));
    let views_right = i64::from(w) - margin - if legend_w > 0 { legend_w + gap } else { 0 };
    let area = Rect {
        x: margin,
        y: top,
        w: (views_right - margin).max(8) as u32,
        h: (i64::from(h) - margin - top).max(8) as u32,
    };
    let (cols, rows) = if views.len() == 4 { (2, 2) } else { (1, 1) };
    let cell_w = ((i64::from(area.w) - gap * (cols - 1)) / cols).max(4);
    let cell_h = ((i64::from(area.h) - gap * (rows - 1)) / rows).max(4);
    let label_h = i64::from(font::CAP_H * ts) + 2 * pad;
    let content_w = (cell_w - 2).max(2) as u32;
    let content_h = (cell_h - label_h - 1).max(2) as u32;
    let cells: Vec<Rect> = (0..views.len() as i64)
        .map(|k| Rect {
            x: area.x + (k % cols) * (cell_w + gap),
            y: area.y + (k / cols) * (cell_h + gap),
            w: cell_w as u32,
            h: cell_h as u32,
        })
        .collect();

    // One scale for all views, with room around the shape for point discs and strokes.
    let fit_margin = f64::from(8 * ts) + 6.0;
    let scale = camera::common_scale(
        &views,
        &bbox,
        f64::from(content_w) - 2.0 * fit_margin,
        f64::from(content_h) - 2.0 * fit_margin,
    );
    let diag = bbox.diagonal();
    let job = Job {
        scene,
        style: &style,
        point_size: params
            .point_size
            .filter(|d| d.is_finite() && *d > 0.0)
            .map(|d| d.min(64.0)),
        max_point: (8 * ts + 2) as f32,
        line_hw: line_w * 0.5,
        bias: 0.01 * diag + f64::from(line_w) / scale,
    };
    let cams: Vec<Camera> = views
        .iter()
        .map(|&v| Camera::fitted(v, &bbox, scale, content_w, content_h))
        .collect();
    let buffers: Vec<ViewBuffer> = cams
        .par_iter()
        .map(|cam| draw_view(&job, cam, content_w, content_h))
        .collect();

    let mut canvas = Canvas::new(w, h, bg);
    if let Some(t) = &params.title {
        font::draw_text(&mut canvas, margin, margin, t, title_scale, ink.text, true);
    }
    for (((cell, view), cam), vb) in cells.iter().zip(&views).zip(&cams).zip(&buffers) {
        canvas.stroke_rect(
            cell.x,
            cell.y,
            i64::from(cell.w),
            i64::from(cell.h),
            ink.frame,
        );
        font::draw_text(
            &mut canvas,
            cell.x + pad,
            cell.y + pad,
            view.label(),
            ts,
            ink.text,
            false,
        );
        let cx = cell.x + 1;
        let cy = cell.y + label_h;
        if content_w >= 120 && content_h >= 90 {
            // The triad goes in the corner of the view least covered by the drawing (bottom
            // left when free), behind the geometry.
            let len = (14 * ts + 4) as f32;
            let inset = pad as f32 + len + 2.0;
            let reach = (len + (font::CAP_H * ts) as f32 * 1.5 + 2.0).ceil() as i64;
            let (fw, fh) = (content_w as f32, content_h as f32);
            let corners = [
                (inset, fh - inset),
                (fw - inset, fh - inset),
                (fw - inset, inset),
                (inset, inset),
            ];
            let mut best = corners[0];
            let mut best_n = usize::MAX;
            for c in corners {
                let (x, y) = (c.0.round() as i64, c.1.round() as i64);
                let n = vb.drawn_in(x - reach, y - reach, x + reach, y + reach);
                if n < best_n {
                    best_n = n;
                    best = c;
                }
            }
            draw_triad(
                &mut canvas,
                cam,
                cx as f32 + best.0,
                cy as f32 + best.1,
                len,
                ts,
            );
        }
        vb.composite(&mut canvas, cx, cy);
    }
    if let Some(l) = &legend {
        if legend_w > 0 {
            let lx = i64::from(w) - margin - legend_w;
            let lh = i64::from(l.height()).min(i64::from(area.h));
            canvas.stroke_rect(lx, area.y, legend_w, lh, ink.frame);
            l.draw(&mut canvas, lx, area.y, legend_w as u32, ink);
        }
    }
    canvas
        .into_pixmap()
        .ok_or_else(|| Error::InvalidArgument(format!("cannot allocate a {w} x {h} image")))
}

/// Renders `scene` and writes it as a PNG file at `path`. Errors name the file.
pub fn render_png(scene: &Scene, params: &RenderParams, path: &Path) -> Result<()> {
    let pixmap = render(scene, params)?;
    let bytes = pixmap
        .encode_png()
        .map_err(|e| Error::format(path, format!("cannot encode PNG: {e}")))?;
    crate::io::atomic::replace(path, |tmp| {
        let mut out = crate::io::create(tmp)?;
        out.write_all(&bytes)
            .and_then(|()| out.flush())
            .map_err(|e| Error::io(tmp, e))
    })
}
