//! The legend panel: what the colours mean (categories with counts, a colour bar with its
//! range, cluster counts), the polyline kinds, and a few numbers about the scene.
//!
//! The legend is a list of rows measured first (so the panel is exactly as wide as its widest
//! row) and then drawn top to bottom with the bitmap font.

use super::colormap::{viridis, Scheme, UNASSIGNED};
use super::font::{draw_text, line_height, text_width, CAP_H};
use super::raster::Canvas;
use super::style::LegendBody;
use super::Scene;

/// Text colours of the panel.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ink {
    /// Main text.
    pub text: [u8; 3],
    /// Secondary text (counts, notes).
    pub dim: [u8; 3],
    /// Frames and ticks.
    pub frame: [u8; 3],
}

enum Row {
    Heading(String),
    Swatch {
        color: [u8; 3],
        text: String,
        note: Option<String>,
    },
    Line {
        color: [u8; 3],
        text: String,
        note: Option<String>,
    },
    ColorBar {
        lo: f64,
        hi: f64,
    },
    Text(String),
    Dim(String),
    Gap,
}

/// A measured legend.
pub(crate) struct Legend {
    rows: Vec<Row>,
    /// Text scale.
    ts: u32,
    /// Polyline width in pixels.
    line_w: f32,
}

/// `n` with thousands separators (`1,234,567`).
pub(crate) fn fmt_count(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::with_capacity(s.len() + s.len() / 3);
    for (i, ch) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(ch);
    }
    out
}

/// A short, readable form of `v`: about four significant digits, scientific notation for very
/// large or small magnitudes, trailing zeros removed.
pub(crate) fn fmt_num(v: f64) -> String {
    if !v.is_finite() {
        return "nan".to_string();
    }
    let a = v.abs();
    if a == 0.0 {
        return "0".to_string();
    }
    if !(1e-3..1e5).contains(&a) {
        return format!("{v:.2e}");
    }
    let decimals = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
    let mut s = format!("{v:.decimals$}");
    if s.contains('.') {
        while s.ends_with('0') {
            s.pop();
        }
        if s.ends_with('.') {
            s.pop();
        }
    }
    if s == "-0" {
        s = "0".to_string();
    }
    s
}

impl Legend {
    /// The legend for `scene` coloured as `body`; `skipped` is the number of points with
    /// non-finite coordinates that were not drawn.
    pub fn build(scene: &Scene, body: &LegendBody, skipped: usize, ts: u32, line_w: f32) -> Legend {
        let mut rows = Vec::new();
        match body {
            LegendBody::None => {}
            LegendBody::Rgb => {
                rows.push(Row::Heading("colour".into()));
                rows.push(Row::Dim("stored RGB".into()));
            }
            LegendBody::Normal => {
                rows.push(Row::Heading("normal".into()));
                for (c, t) in [
                    ([255, 128, 128], "+x"),
                    ([128, 255, 128], "+y"),
                    ([128, 128, 255], "+z"),
                ] {
                    rows.push(Row::Swatch {
                        color: c,
                        text: t.into(),
                        note: None,
                    });
                }
            }
            LegendBody::Attribute { name, scheme } => {
                rows.push(Row::Heading(name.clone()));
                match scheme {
                    Scheme::Categorical(cats) => {
                        for c in cats {
                            rows.push(Row::Swatch {
                                color: c.color,
                                text: c.label.clone(),
                                note: Some(fmt_count(c.count)),
                            });
                        }
                    }
                    Scheme::Hashed { count, unassigned } => {
                        rows.push(Row::Text(format!("{} clusters", fmt_count(*count))));
                        if *unassigned > 0 {
                            rows.push(Row::Swatch {
                                color: UNASSIGNED,
                                text: "unassigned".into(),
                                note: Some(fmt_count(*unassigned)),
                            });
                        }
                    }
                    Scheme::Continuous {
                        lo,
                        hi,
                        min,
                        max,
                        non_finite,
                    } => {
                        rows.push(Row::ColorBar { lo: *lo, hi: *hi });
                        rows.push(Row::Dim("1st-99th percentile".into()));
                        if min.is_finite() && (min < lo || max > hi) {
                            rows.push(Row::Dim(format!(
                                "data {} .. {}",
                                fmt_num(*min),
                                fmt_num(*max)
                            )));
                        }
                        if *non_finite > 0 {
                            rows.push(Row::Swatch {
                                color: UNASSIGNED,
                                text: "NaN".into(),
                                note: Some(fmt_count(*non_finite)),
                            });
                        }
                    }
                }
            }
        }
        // Polyline kinds, in order of first appearance.
        let mut kinds: Vec<([u8; 3], String, usize)> = Vec::new();
        for p in &scene.polylines {
            if let Some(label) = &p.label {
                match kinds.iter_mut().find(|k| k.0 == p.color && &k.1 == label) {
                    Some(k) => k.2 += 1,
                    None => kinds.push((p.color, label.clone(), 1)),
                }
            }
        }
        if !kinds.is_empty() {
            if !rows.is_empty() {
                rows.push(Row::Gap);
            }
            rows.push(Row::Heading("lines".into()));
            for (color, text, n) in kinds {
                rows.push(Row::Line {
                    color,
                    text,
                    note: Some(fmt_count(n)),
                });
            }
        }
        // Scene numbers.
        if !rows.is_empty() {
            rows.push(Row::Gap);
        }
        if let Some(p) = scene.points.filter(|p| !p.is_empty()) {
            rows.push(Row::Dim(format!("{} points", fmt_count(p.len()))));
        }
        if let Some(m) = scene.mesh.filter(|m| !m.faces.is_empty()) {
            rows.push(Row::Dim(format!("{} triangles", fmt_count(m.num_faces()))));
        }
        if !scene.polylines.is_empty() {
            rows.push(Row::Dim(format!(
                "{} polylines",
                fmt_count(scene.polylines.len())
            )));
        }
        if skipped > 0 {
            rows.push(Row::Dim(format!(
                "{} non-finite skipped",
                fmt_count(skipped)
            )));
        }
        if let Some(b) = super::scene_bbox(scene) {
            let e = b.extent();
            rows.push(Row::Dim(format!(
                "size {} x {} x {}",
                fmt_num(e[0]),
                fmt_num(e[1]),
                fmt_num(e[2])
            )));
        }
        Legend { rows, ts, line_w }
    }

    fn swatch(&self) -> u32 {
        CAP_H * self.ts + 2
    }

    fn gap(&self) -> u32 {
        4 * self.ts
    }

    fn bar_h(&self) -> u32 {
        100 * self.ts
    }

    fn row_height(&self, r: &Row) -> u32 {
        let lh = line_height(self.ts);
        match r {
            Row::Heading(_) => lh + 3 * self.ts,
            Row::Swatch { .. } | Row::Line { .. } | Row::Text(_) | Row::Dim(_) => lh + 2 * self.ts,
            Row::ColorBar { .. } => self.bar_h() + lh + 2 * self.ts,
            Row::Gap => 6 * self.ts,
        }
    }

    fn row_width(&self, r: &Row) -> u32 {
        let ts = self.ts;
        let note_w =
            |n: &Option<String>| n.as_ref().map_or(0, |n| 4 * self.gap() + text_width(n, ts));
        match r {
            Row::Heading(t) => text_width(t, ts) + 1,
            Row::Swatch { text, note, .. } => {
                self.swatch() + 2 * self.gap() + text_width(text, ts) + note_w(note)
            }
            Row::Line { text, note, .. } => {
                3 * self.swatch() + 2 * self.gap() + text_width(text, ts) + note_w(note)
            }
            Row::ColorBar { lo, hi } => {
                let lw = [*lo, 0.5 * (lo + hi), *hi]
                    .iter()
                    .map(|v| text_width(&fmt_num(*v), ts))
                    .max()
                    .unwrap_or(0);
                3 * self.swatch() + 3 * self.gap() + lw
            }
            Row::Text(t) | Row::Dim(t) => text_width(t, ts),
            Row::Gap => 0,
        }
    }

    /// Inner padding of the panel.
    pub fn pad(&self) -> u32 {
        8 * self.ts
    }

    /// Panel width: the widest row plus padding (0 if the legend is empty).
    pub fn width(&self) -> u32 {
        if self.rows.is_empty() {
            return 0;
        }
        let w = self
            .rows
            .iter()
            .map(|r| self.row_width(r))
            .max()
            .unwrap_or(0);
        w + 2 * self.pad()
    }

    /// Panel height: all rows plus padding.
    pub fn height(&self) -> u32 {
        self.rows.iter().map(|r| self.row_height(r)).sum::<u32>() + 2 * self.pad()
    }

    /// Draws the legend in the panel whose top-left corner is (`x`, `y`) and width `w`.
    pub fn draw(&self, canvas: &mut Canvas, x: i64, y: i64, w: u32, ink: Ink) {
        let ts = self.ts;
        let pad = i64::from(self.pad());
        let sw = i64::from(self.swatch());
        let gap = i64::from(self.gap());
        let right = x + i64::from(w) - pad;
        let mut cy = y + pad;
        let x0 = x + pad;
        // Text baseline offset so that a swatch and its text are centred on each other.
        let text_dy = (sw - i64::from(CAP_H * ts)) / 2;
        let note_at = |canvas: &mut Canvas, cy: i64, note: &Option<String>| {
            if let Some(n) = note {
                let nw = i64::from(text_width(n, ts));
                draw_text(canvas, right - nw, cy + text_dy, n, ts, ink.dim, false);
            }
        };
        for r in &self.rows {
            match r {
                Row::Heading(t) => draw_text(canvas, x0, cy, t, ts, ink.text, true),
                Row::Swatch { color, text, note } => {
                    canvas.fill_rect(x0, cy, sw, sw, *color);
                    draw_text(
                        canvas,
                        x0 + sw + 2 * gap,
                        cy + text_dy,
                        text,
                        ts,
                        ink.text,
                        false,
                    );
                    note_at(canvas, cy, note);
                }
                Row::Line { color, text, note } => {
                    let my = cy as f32 + sw as f32 * 0.5;
                    canvas.line(
                        x0 as f32 + 1.0,
                        my,
                        (x0 + 3 * sw) as f32 - 1.0,
                        my,
                        self.line_w,
                        *color,
                    );
                    draw_text(
                        canvas,
                        x0 + 3 * sw + 2 * gap,
                        cy + text_dy,
                        text,
                        ts,
                        ink.text,
                        false,
                    );
                    note_at(canvas, cy, note);
                }
                Row::ColorBar { lo, hi } => {
                    let bh = i64::from(self.bar_h());
                    let bw = 2 * sw;
                    let top = cy + i64::from(CAP_H * ts) / 2;
                    for k in 0..bh {
                        let t = 1.0 - k as f64 / (bh - 1).max(1) as f64;
                        canvas.fill_rect(x0, top + k, bw, 1, viridis(t));
                    }
                    canvas.stroke_rect(x0 - 1, top - 1, bw + 2, bh + 2, ink.frame);
                    for (frac, v) in [(0.0, *hi), (0.5, 0.5 * (lo + hi)), (1.0, *lo)] {
                        let ty = top + ((bh - 1) as f64 * frac).round() as i64;
                        canvas.fill_rect(x0 + bw, ty, gap, 1, ink.text);
                        draw_text(
                            canvas,
                            x0 + bw + 2 * gap,
                            ty - i64::from(CAP_H * ts) / 2,
                            &fmt_num(v),
                            ts,
                            ink.text,
                            false,
                        );
                    }
                }
                Row::Text(t) => draw_text(canvas, x0, cy + text_dy, t, ts, ink.text, false),
                Row::Dim(t) => draw_text(canvas, x0, cy + text_dy, t, ts, ink.dim, false),
                Row::Gap => {}
            }
            cy += i64::from(self.row_height(r));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers() {
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_num(1.0), "1");
        assert_eq!(fmt_num(0.0123), "0.0123");
        assert_eq!(fmt_num(123.456), "123.5");
        assert_eq!(fmt_num(-2.5), "-2.5");
        assert_eq!(fmt_num(1.5e7), "1.50e7");
        assert_eq!(fmt_count(1234567), "1,234,567");
        assert_eq!(fmt_count(12), "12");
    }
}
