//! Software rasterisation: an RGB canvas for the whole image and a z-buffered view buffer.
//!
//! A [`ViewBuffer`] holds one view: a depth buffer (`f32`, smaller is nearer, `+inf` empty), a
//! colour buffer, and a line overlay. Points are splatted as discs facing the camera,
//! triangles are scan-converted with edge functions (both windings, barycentric depth and
//! colour), and polylines are drawn as anti-aliased round-capped strokes whose coverage is kept
//! per pixel as a maximum (so joints do not darken) and blended over the surface at the end.
//! Strokes are depth-tested against the surface with a bias; the parts that fail the test
//! (hidden behind the surface) are kept but faint, like hidden lines in a technical drawing.

/// An RGB image being composed (opaque; converted to a `tiny_skia::Pixmap` at the end).
pub(crate) struct Canvas {
    /// Width in pixels.
    pub w: u32,
    /// Height in pixels.
    pub h: u32,
    /// Row-major pixels.
    pub px: Vec<[u8; 3]>,
}

/// `a` blended toward `b` by `t` in [0, 1].
#[inline]
pub(crate) fn mix(a: [u8; 3], b: [u8; 3], t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let f = |x: u8, y: u8| (f32::from(x) + (f32::from(y) - f32::from(x)) * t).round() as u8;
    [f(a[0], b[0]), f(a[1], b[1]), f(a[2], b[2])]
}

/// `c` multiplied by the intensity `s` (clamped to [0, 1]).
#[inline]
pub(crate) fn shade(c: [u8; 3], s: f32) -> [u8; 3] {
    let s = s.clamp(0.0, 1.0);
    [
        (f32::from(c[0]) * s).round() as u8,
        (f32::from(c[1]) * s).round() as u8,
        (f32::from(c[2]) * s).round() as u8,
    ]
}

impl Canvas {
    /// A `w` × `h` canvas filled with `bg`.
    pub fn new(w: u32, h: u32, bg: [u8; 3]) -> Canvas {
        Canvas {
            w,
            h,
            px: vec![bg; w as usize * h as usize],
        }
    }

    #[inline]
    fn index(&self, x: i64, y: i64) -> Option<usize> {
        if x < 0 || y < 0 || x >= i64::from(self.w) || y >= i64::from(self.h) {
            None
        } else {
            Some(y as usize * self.w as usize + x as usize)
        }
    }

    /// Sets pixel (`x`, `y`) if inside.
    #[inline]
    pub fn set(&mut self, x: i64, y: i64, c: [u8; 3]) {
        if let Some(i) = self.index(x, y) {
            if let Some(p) = self.px.get_mut(i) {
                *p = c;
            }
        }
    }

    /// Blends `c` over pixel (`x`, `y`) with opacity `a`.
    #[inline]
    pub fn blend(&mut self, x: i64, y: i64, c: [u8; 3], a: f32) {
        if let Some(i) = self.index(x, y) {
            if let Some(p) = self.px.get_mut(i) {
                *p = mix(*p, c, a);
            }
        }
    }

    /// Fills the rectangle with top-left (`x`, `y`) and size `w` × `h` (clipped).
    pub fn fill_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: [u8; 3]) {
        let x0 = x.max(0);
        let y0 = y.max(0);
        let x1 = (x + w).min(i64::from(self.w));
        let y1 = (y + h).min(i64::from(self.h));
        for yy in y0..y1 {
            for xx in x0..x1 {
                self.set(xx, yy, c);
            }
        }
    }

    /// Draws the one-pixel outline of a rectangle.
    pub fn stroke_rect(&mut self, x: i64, y: i64, w: i64, h: i64, c: [u8; 3]) {
        self.fill_rect(x, y, w, 1, c);
        self.fill_rect(x, y + h - 1, w, 1, c);
        self.fill_rect(x, y, 1, h, c);
        self.fill_rect(x + w - 1, y, 1, h, c);
    }

    /// An anti-aliased stroke of width `width` from (`x0`, `y0`) to (`x1`, `y1`), round caps.
    pub fn line(&mut self, x0: f32, y0: f32, x1: f32, y1: f32, width: f32, c: [u8; 3]) {
        let hw = width * 0.5;
        stroke_pixels(x0, y0, x1, y1, hw, self.w, self.h, |x, y, cov, _t| {
            self.blend(i64::from(x), i64::from(y), c, cov);
        });
    }

    /// The canvas as an opaque `tiny_skia::Pixmap`.
    pub fn into_pixmap(self) -> Option<tiny_skia::Pixmap> {
        let size = tiny_skia::IntSize::from_wh(self.w, self.h)?;
        let mut data = Vec::with_capacity(self.px.len() * 4);
        for p in &self.px {
            data.extend_from_slice(&[p[0], p[1], p[2], 255]);
        }
        tiny_skia::Pixmap::from_vec(data, size)
    }
}

/// Calls `f(x, y, coverage, t)` for every pixel of a `w` × `h` grid touched by a round-capped
/// stroke of half-width `hw` around the segment (`x0`, `y0`)–(`x1`, `y1`); `t` in [0, 1] is the
/// parameter of the closest point on the segment. Walks the segment's major axis, so the cost
/// is proportional to the stroke's area, not its bounding box.
#[allow(clippy::too_many_arguments)]
pub(crate) fn stroke_pixels(
    x0: f32,
    y0: f32,
    x1: f32,
    y1: f32,
    hw: f32,
    w: u32,
    h: u32,
    mut f: impl FnMut(u32, u32, f32, f32),
) {
    if !(x0.is_finite() && y0.is_finite() && x1.is_finite() && y1.is_finite()) {
        return;
    }
    let (dx, dy) = (x1 - x0, y1 - y0);
    let len2 = dx * dx + dy * dy;
    let reach = hw + 1.0;
    // Pixel coverage of a point at distance d from the segment.
    let mut visit = |x: i64, y: i64| {
        if x < 0 || y < 0 || x >= i64::from(w) || y >= i64::from(h) {
            return;
        }
        let px = x as f32 + 0.5;
        let py = y as f32 + 0.5;
        let t = if len2 > 0.0 {
            (((px - x0) * dx + (py - y0) * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let ex = px - (x0 + t * dx);
        let ey = py - (y0 + t * dy);
        let d = (ex * ex + ey * ey).sqrt();
        let cov = (hw + 0.5 - d).clamp(0.0, 1.0);
        if cov > 0.0 {
            f(x as u32, y as u32, cov, t);
        }
    };
    let steep = dy.abs() > dx.abs();
    // Clip the walk to the grid (plus the stroke's reach) so huge coordinates cost nothing.
    let (lo_lim, hi_lim) = if steep {
        (-reach - 1.0, h as f32 + reach + 1.0)
    } else {
        (-reach - 1.0, w as f32 + reach + 1.0)
    };
    let (a0, a1, b0, slope) = if steep {
        let (lo, hi) = if y0 <= y1 { (y0, y1) } else { (y1, y0) };
        (lo, hi, (x0, y0), if dy != 0.0 { dx / dy } else { 0.0 })
    } else {
        let (lo, hi) = if x0 <= x1 { (x0, x1) } else { (x1, x0) };
        (lo, hi, (x0, y0), if dx != 0.0 { dy / dx } else { 0.0 })
    };
    let start = (a0 - reach).max(lo_lim).floor() as i64;
    let end = (a1 + reach).min(hi_lim).ceil() as i64;
    if start > end {
        return;
    }
    let span = reach * (1.0 + slope * slope).sqrt() + 1.0;
    for a in start..=end {
        let ac = a as f32 + 0.5;
        // Minor-axis coordinate of the infinite line at this major coordinate, clamped to the
        // segment's extent so the caps are covered.
        let ac_clamped = ac.clamp(a0, a1);
        let bc = if steep {
            b0.0 + (ac_clamped - b0.1) * slope
        } else {
            b0.1 + (ac_clamped - b0.0) * slope
        };
        let lim = if steep { w as f32 } else { h as f32 };
        let lo = (bc - span).max(-1.0).floor() as i64;
        let hi = (bc + span).min(lim + 1.0).ceil() as i64;
        for b in lo..=hi {
            if steep {
                visit(b, a);
            } else {
                visit(a, b);
            }
        }
    }
}

/// One view being rendered: depth, colour and a polyline overlay.
pub(crate) struct ViewBuffer {
    /// Width in pixels.
    pub w: u32,
    /// Height in pixels.
    pub h: u32,
    /// Depth per pixel, `+inf` where nothing was drawn.
    pub depth: Vec<f32>,
    /// Surface colour per pixel (meaningful where depth is finite).
    pub color: Vec<[u8; 3]>,
    /// Polyline overlay opacity per pixel.
    pub line_a: Vec<f32>,
    /// Polyline overlay colour per pixel.
    pub line_c: Vec<[u8; 3]>,
}

/// Pixel offsets of a disc splat of diameter `d` around the pixel holding the point.
pub(crate) fn disc_stamp(d: f32) -> Vec<(i32, i32)> {
    let r = (d * 0.5).max(0.5);
    let ri = r.ceil() as i32;
    let mut out = Vec::new();
    for dy in -ri..=ri {
        for dx in -ri..=ri {
            let (fx, fy) = (dx as f32, dy as f32);
            if fx * fx + fy * fy <= r * r + 0.25 {
                out.push((dx, dy));
            }
        }
    }
    if out.is_empty() {
        out.push((0, 0));
    }
    out
}

impl ViewBuffer {
    /// An empty `w` × `h` view.
    pub fn new(w: u32, h: u32) -> ViewBuffer {
        let n = w as usize * h as usize;
        ViewBuffer {
            w,
            h,
            depth: vec![f32::INFINITY; n],
            color: vec![[0, 0, 0]; n],
            line_a: vec![0.0; n],
            line_c: vec![[0, 0, 0]; n],
        }
    }

    /// Splats a point at pixel position (`x`, `y`) and depth `z` with the stamp's pixels.
    /// Ties keep the earlier point, so the result does not depend on anything but input order.
    #[inline]
    pub fn splat(&mut self, x: f32, y: f32, z: f32, c: [u8; 3], stamp: &[(i32, i32)]) {
        let cx = x.floor() as i64;
        let cy = y.floor() as i64;
        let (w, h) = (i64::from(self.w), i64::from(self.h));
        for &(dx, dy) in stamp {
            let px = cx + i64::from(dx);
            let py = cy + i64::from(dy);
            if px < 0 || py < 0 || px >= w || py >= h {
                continue;
            }
            let i = py as usize * self.w as usize + px as usize;
            if let (Some(d), Some(col)) = (self.depth.get_mut(i), self.color.get_mut(i)) {
                if z < *d {
                    *d = z;
                    *col = c;
                }
            }
        }
    }

    /// Scan-converts a triangle given as (x, y, depth) corners. `shader(b)` gives the colour at
    /// barycentric coordinates `b`; it is called only for pixels that pass the depth test.
    /// Degenerate (zero-area or edge-on) triangles draw nothing.
    pub fn triangle(
        &mut self,
        v: [(f32, f32, f32); 3],
        mut shader: impl FnMut([f32; 3]) -> [u8; 3],
    ) {
        let [(x0, y0, z0), (x1, y1, z1), (x2, y2, z2)] = v;
        let area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0);
        if !area.is_finite() || area.abs() < 1e-9 {
            return;
        }
        let inv = 1.0 / area;
        let min_x = x0.min(x1).min(x2).floor().max(0.0);
        let max_x = x0.max(x1).max(x2).ceil().min(self.w as f32 - 1.0);
        let min_y = y0.min(y1).min(y2).floor().max(0.0);
        let max_y = y0.max(y1).max(y2).ceil().min(self.h as f32 - 1.0);
        if min_x > max_x || min_y > max_y {
            return;
        }
        let (min_x, max_x, min_y, max_y) = (min_x as u32, max_x as u32, min_y as u32, max_y as u32);
        let eps = -1e-5;
        for py in min_y..=max_y {
            let fy = py as f32 + 0.5;
            let row = py as usize * self.w as usize;
            for px in min_x..=max_x {
                let fx = px as f32 + 0.5;
                let b0 = ((x1 - fx) * (y2 - fy) - (x2 - fx) * (y1 - fy)) * inv;
                let b1 = ((x2 - fx) * (y0 - fy) - (x0 - fx) * (y2 - fy)) * inv;
                let b2 = 1.0 - b0 - b1;
                if b0 < eps || b1 < eps || b2 < eps {
                    continue;
                }
                let z = b0 * z0 + b1 * z1 + b2 * z2;
                let i = row + px as usize;
                let Some(d) = self.depth.get_mut(i) else {
                    continue;
                };
                if z < *d {
                    *d = z;
                    if let Some(col) = self.color.get_mut(i) {
                        *col = shader([b0, b1, b2]);
                    }
                }
            }
        }
    }

    /// Draws a polyline segment into the overlay: an anti-aliased stroke of half-width `hw`
    /// between (x, y, depth) ends. A pixel is visible if the stroke's depth there is at most the
    /// surface depth plus `bias`; hidden pixels get their opacity multiplied by `hidden_alpha`.
    /// Each overlay pixel keeps the most opaque stroke that reached it.
    pub fn stroke(
        &mut self,
        a: (f32, f32, f32),
        b: (f32, f32, f32),
        hw: f32,
        c: [u8; 3],
        bias: f32,
        hidden_alpha: f32,
    ) {
        let (w, h) = (self.w, self.h);
        let depth = &self.depth;
        let line_a = &mut self.line_a;
        let line_c = &mut self.line_c;
        stroke_pixels(a.0, a.1, b.0, b.1, hw, w, h, |x, y, cov, t| {
            let i = y as usize * w as usize + x as usize;
            let z = a.2 + t * (b.2 - a.2);
            let surf = depth.get(i).copied().unwrap_or(f32::INFINITY);
            let alpha = if z <= surf + bias {
                cov
            } else {
                cov * hidden_alpha
            };
            if let (Some(la), Some(lc)) = (line_a.get_mut(i), line_c.get_mut(i)) {
                if alpha > *la {
                    *la = alpha;
                    *lc = c;
                }
            }
        });
    }

    /// Number of pixels in the rectangle [x0, x1] × [y0, y1] (clipped) where something was
    /// drawn.
    pub fn drawn_in(&self, x0: i64, y0: i64, x1: i64, y1: i64) -> usize {
        let mut n = 0;
        for y in y0.max(0)..=y1.min(i64::from(self.h) - 1) {
            for x in x0.max(0)..=x1.min(i64::from(self.w) - 1) {
                let i = y as usize * self.w as usize + x as usize;
                let d = self.depth.get(i).copied().unwrap_or(f32::INFINITY);
                let a = self.line_a.get(i).copied().unwrap_or(0.0);
                if d.is_finite() || a > 0.0 {
                    n += 1;
                }
            }
        }
        n
    }

    /// Copies the view onto `canvas` with its top-left at (`ox`, `oy`): surface colour where
    /// something was drawn, the polyline overlay blended on top; empty pixels are left as they
    /// are (so decorations drawn beforehand stay behind the geometry).
    pub fn composite(&self, canvas: &mut Canvas, ox: i64, oy: i64) {
        for y in 0..self.h {
            for x in 0..self.w {
                let i = y as usize * self.w as usize + x as usize;
                let d = self.depth.get(i).copied().unwrap_or(f32::INFINITY);
                let a = self.line_a.get(i).copied().unwrap_or(0.0);
                if !d.is_finite() && a <= 0.0 {
                    continue;
                }
                let (px, py) = (ox + i64::from(x), oy + i64::from(y));
                if d.is_finite() {
                    canvas.set(px, py, self.color.get(i).copied().unwrap_or([0, 0, 0]));
                }
                if a > 0.0 {
                    canvas.blend(px, py, self.line_c.get(i).copied().unwrap_or([0, 0, 0]), a);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn triangle_covers_its_interior_and_respects_depth() {
        let mut vb = ViewBuffer::new(20, 20);
        vb.triangle(
            [(0.0, 0.0, 1.0), (20.0, 0.0, 1.0), (0.0, 20.0, 1.0)],
            |_| [255, 0, 0],
        );
        // Nearer triangle, opposite winding.
        vb.triangle(
            [(0.0, 0.0, 0.0), (0.0, 20.0, 0.0), (20.0, 0.0, 0.0)],
            |_| [0, 0, 255],
        );
        // Farther one drawn last loses.
        vb.triangle(
            [(0.0, 0.0, 5.0), (20.0, 0.0, 5.0), (0.0, 20.0, 5.0)],
            |_| [0, 255, 0],
        );
        assert_eq!(vb.color[2 * 20 + 2], [0, 0, 255]);
        assert!(vb.depth[19 * 20 + 19].is_infinite());
    }

    #[test]
    fn stroke_covers_its_path_only() {
        let mut hits = vec![0f32; 100 * 50];
        stroke_pixels(5.0, 25.0, 95.0, 25.0, 1.25, 100, 50, |x, y, c, _| {
            hits[y as usize * 100 + x as usize] = c;
        });
        assert!(hits[25 * 100 + 50] > 0.99);
        assert_eq!(hits[10 * 100 + 50], 0.0);
        // Steep and reversed.
        let mut n = 0;
        stroke_pixels(50.0, 49.0, 48.0, 1.0, 1.0, 100, 50, |_, _, _, _| n += 1);
        assert!(n > 48 * 2);
    }

    #[test]
    fn stamps_grow_with_size() {
        assert_eq!(disc_stamp(1.0).len(), 1);
        assert!(disc_stamp(4.0).len() > disc_stamp(2.0).len());
    }
}
