//! Orthographic cameras for the four standard views, fitted to the scene's bounding box.
//!
//! A camera is an orthonormal frame (`right`, `up`, `forward`) and a centre. A point `p` goes to
//! image pixel `(ox + s (p − c)·right, oy − s (p − c)·up)` with depth `(p − c)·forward`
//! (smaller is nearer). One scale `s` is shared by all views of an image, so that sizes compare.

use super::View;
use crate::geometry::vec3::{cross, dot, normalize, sub};
use crate::geometry::{Aabb, Point3};

/// An orthographic camera placed in a pixel rectangle.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Camera {
    /// Screen x direction in world coordinates.
    pub right: Point3,
    /// Screen up direction in world coordinates.
    pub up: Point3,
    /// Viewing direction (from the eye into the scene).
    pub forward: Point3,
    /// World point mapped to the pixel (`ox`, `oy`).
    pub center: Point3,
    /// Pixels per world unit.
    pub scale: f64,
    /// Pixel x of the centre (buffer coordinates).
    pub ox: f64,
    /// Pixel y of the centre (buffer coordinates).
    pub oy: f64,
}

/// The (right, up, forward) frame of a standard view.
///
/// * `Front`: the eye on −Y looking toward +Y, Z up, X to the right.
/// * `Top`: the eye above looking down −Z, Y up, X to the right.
/// * `Side`: the eye on +X looking toward −X, Z up, Y to the right.
/// * `Iso`: the eye on the (+1, −1, +1) diagonal (front, right side and top visible), Z up.
pub(crate) fn frame(view: View) -> (Point3, Point3, Point3) {
    match view {
        View::Front => ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        View::Top => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]),
        View::Side => ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]),
        View::Iso => {
            let s3 = 1.0 / 3f64.sqrt();
            let forward = [-s3, s3, -s3];
            // Up: +Z made orthogonal to the viewing direction.
            let z = [0.0, 0.0, 1.0];
            let d = dot(z, forward);
            let up = normalize(sub(z, [d * forward[0], d * forward[1], d * forward[2]]))
                .unwrap_or([0.0, 0.0, 1.0]);
            let right = cross(forward, up);
            (right, up, forward)
        }
    }
}

/// Width and height of the box's projection in `view`, in world units.
pub(crate) fn projected_extent(view: View, bbox: &Aabb) -> (f64, f64) {
    let (right, up, _) = frame(view);
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for i in 0..8 {
        let corner = [
            if i & 1 == 0 { bbox.min[0] } else { bbox.max[0] },
            if i & 2 == 0 { bbox.min[1] } else { bbox.max[1] },
            if i & 4 == 0 { bbox.min[2] } else { bbox.max[2] },
        ];
        let u = dot(corner, right);
        let v = dot(corner, up);
        lo[0] = lo[0].min(u);
        hi[0] = hi[0].max(u);
        lo[1] = lo[1].min(v);
        hi[1] = hi[1].max(v);
    }
    (hi[0] - lo[0], hi[1] - lo[1])
}

/// The largest scale (pixels per world unit) at which the box fits a `w` × `h` pixel area in
/// every one of `views`. Zero extents (a single point, a plane seen edge-on) are replaced by a
/// small fraction of the box diagonal (or by 1 if the diagonal is zero), so the result is finite.
pub(crate) fn common_scale(views: &[View], bbox: &Aabb, w: f64, h: f64) -> f64 {
    let diag = bbox.diagonal();
    let floor = if diag > 0.0 && diag.is_finite() {
        diag * 1e-3
    } else {
        1.0
    };
    let mut scale = f64::INFINITY;
    for &v in views {
        let (ew, eh) = projected_extent(v, bbox);
        scale = scale.min(w.max(1.0) / ew.max(floor));
        scale = scale.min(h.max(1.0) / eh.max(floor));
    }
    if scale.is_finite() && scale > 0.0 {
        scale
    } else {
        1.0
    }
}

impl Camera {
    /// A camera for `view` at `scale`, with the centre of the box's projection at the centre of
    /// a `w` × `h` pixel buffer.
    pub fn fitted(view: View, bbox: &Aabb, scale: f64, w: u32, h: u32) -> Camera {
        let (right, up, forward) = frame(view);
        Camera {
            right,
            up,
            forward,
            center: bbox.center(),
            scale,
            ox: f64::from(w) * 0.5,
            oy: f64::from(h) * 0.5,
        }
    }

    /// Buffer pixel coordinates (x, y) and depth of `p`; `None` if `p` is not finite.
    #[inline]
    pub fn project(&self, p: Point3) -> Option<(f32, f32, f32)> {
        let d = sub(p, self.center);
        let x = self.ox + self.scale * dot(d, self.right);
        let y = self.oy - self.scale * dot(d, self.up);
        let z = dot(d, self.forward);
        if x.is_finite() && y.is_finite() && z.is_finite() {
            Some((x as f32, y as f32, z as f32))
        } else {
            None
        }
    }

    /// Screen-space direction (dx, dy), in pixels per world unit, of the world direction `dir`.
    pub fn screen_dir(&self, dir: Point3) -> (f64, f64) {
        (dot(dir, self.right), -dot(dir, self.up))
    }

    /// Direction toward the light, in world coordinates: a headlight mounted on the camera,
    /// tilted up and slightly to the left so that faces meeting the view direction at equal
    /// angles (a cube seen isometrically) still get different shades.
    pub fn light_dir(&self) -> Point3 {
        let l = [
            -self.forward[0] + 0.5 * self.up[0] - 0.2 * self.right[0],
            -self.forward[1] + 0.5 * self.up[1] - 0.2 * self.right[1],
            -self.forward[2] + 0.5 * self.up[2] - 0.2 * self.right[2],
        ];
        normalize(l).unwrap_or([0.0, 0.0, 1.0])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_right_handed_orthonormal() {
        for v in [View::Iso, View::Front, View::Top, View::Side] {
            let (r, u, f) = frame(v);
            assert!((dot(r, r) - 1.0).abs() < 1e-12);
            assert!((dot(u, u) - 1.0).abs() < 1e-12);
            assert!(dot(r, u).abs() < 1e-12 && dot(u, f).abs() < 1e-12);
            // right = forward × up
            let c = cross(f, u);
            assert!(dot(c, r) > 1.0 - 1e-12, "{v:?}");
        }
    }

    #[test]
    fn zero_extent_gives_finite_scale() {
        let b = Aabb {
            min: [1.0, 2.0, 3.0],
            max: [1.0, 2.0, 3.0],
        };
        let s = common_scale(&[View::Iso, View::Top], &b, 100.0, 80.0);
        assert!(s.is_finite() && s > 0.0);
    }
}
