//! Axis-aligned bounding boxes.

use super::Point3;

/// An axis-aligned bounding box.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Aabb {
    /// Smallest coordinates.
    pub min: Point3,
    /// Largest coordinates.
    pub max: Point3,
}

impl Aabb {
    /// The box of `points`, `None` if there are none.
    pub fn from_points(points: &[Point3]) -> Option<Aabb> {
        Aabb::enclosing(points.iter().copied())
    }

    /// The box of the points of an iterator, `None` if there are none.
    pub fn enclosing(points: impl IntoIterator<Item = Point3>) -> Option<Aabb> {
        let mut points = points.into_iter();
        let first = points.next()?;
        let mut b = Aabb {
            min: first,
            max: first,
        };
        for p in points {
            b.grow(p);
        }
        Some(b)
    }

    /// Enlarges the box to hold `p`.
    pub fn grow(&mut self, p: Point3) {
        for ((lo, hi), c) in self.min.iter_mut().zip(self.max.iter_mut()).zip(p) {
            *lo = lo.min(c);
            *hi = hi.max(c);
        }
    }

    /// Side lengths.
    pub fn extent(&self) -> Point3 {
        [
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        ]
    }

    /// Length of the diagonal.
    pub fn diagonal(&self) -> f64 {
        let e = self.extent();
        (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt()
    }

    /// Centre point.
    pub fn center(&self) -> Point3 {
        [
            0.5 * (self.min[0] + self.max[0]),
            0.5 * (self.min[1] + self.max[1]),
            0.5 * (self.min[2] + self.max[2]),
        ]
    }

    /// Longest side.
    pub fn max_side(&self) -> f64 {
        let e = self.extent();
        e[0].max(e[1]).max(e[2])
    }

    /// Shortest side.
    pub fn min_side(&self) -> f64 {
        let e = self.extent();
        e[0].min(e[1]).min(e[2])
    }
}
