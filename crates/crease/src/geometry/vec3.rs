//! Small vector helpers on `[f64; 3]`, inlined; used in hot loops where a matrix library's
//! generality costs more than it brings.

use super::Point3;

/// a + b
#[inline]
pub fn add(a: Point3, b: Point3) -> Point3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a - b
#[inline]
pub fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// s * a
#[inline]
pub fn scale(a: Point3, s: f64) -> Point3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// a . b
#[inline]
pub fn dot(a: Point3, b: Point3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a x b
#[inline]
pub fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// |a|
#[inline]
pub fn norm(a: Point3) -> f64 {
    dot(a, a).sqrt()
}

/// |a - b|^2
#[inline]
pub fn dist2(a: Point3, b: Point3) -> f64 {
    let d = sub(a, b);
    dot(d, d)
}

/// |a - b|
#[inline]
pub fn dist(a: Point3, b: Point3) -> f64 {
    dist2(a, b).sqrt()
}

/// a / |a|, or `None` if |a| is zero or not finite.
#[inline]
pub fn normalize(a: Point3) -> Option<Point3> {
    let n = norm(a);
    if n > 0.0 && n.is_finite() {
        Some(scale(a, 1.0 / n))
    } else {
        None
    }
}

/// Linear interpolation a + t (b - a).
#[inline]
pub fn lerp(a: Point3, b: Point3, t: f64) -> Point3 {
    add(a, scale(sub(b, a), t))
}

/// Distance from `p` to the segment `a`–`b`.
#[inline]
pub fn segment_distance(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = sub(b, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(sub(p, a), ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist(p, add(a, scale(ab, t)))
}

/// Distance from `p` to the line through `q` along the unit direction `d`.
#[inline]
pub fn line_distance(p: Point3, q: Point3, d: Point3) -> f64 {
    norm(cross(sub(p, q), d))
}

/// Angle in radians between a and b (0 if either is zero).
#[inline]
pub fn angle(a: Point3, b: Point3) -> f64 {
    let c = cross(a, b);
    norm(c).atan2(dot(a, b))
}
