//! `PointCloud`: positions with optional normals and colours and any number of named attributes.

use super::{Aabb, Attribute, Attributes};
use crate::{Error, Result};

/// A point in 3D.
pub type Point3 = [f64; 3];

/// A set of points with optional per-point normals, colours and named attributes.
///
/// Invariant: every per-point array has `positions.len()` entries. The constructors and
/// setters check it; the fields are public for reading and for algorithms that keep it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointCloud {
    /// Point positions.
    pub positions: Vec<Point3>,
    /// Optional unit normals, one per point.
    pub normals: Option<Vec<Point3>>,
    /// Optional RGB colours, one per point.
    pub colors: Option<Vec<[u8; 3]>>,
    /// Named per-point attributes (`sharp`, `sharpness`, `label`, scanner intensity, ...).
    pub attributes: Attributes,
}

impl PointCloud {
    /// A cloud of bare positions.
    pub fn from_positions(positions: Vec<Point3>) -> Self {
        PointCloud {
            positions,
            ..Default::default()
        }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.positions.len()
    }

    /// True if the cloud has no points.
    pub fn is_empty(&self) -> bool {
        self.positions.is_empty()
    }

    /// Sets the normals; fails if their count differs from the point count.
    pub fn set_normals(&mut self, normals: Vec<Point3>) -> Result<()> {
        check_len("normals", normals.len(), self.len())?;
        self.normals = Some(normals);
        Ok(())
    }

    /// Sets the colours; fails if their count differs from the point count.
    pub fn set_colors(&mut self, colors: Vec<[u8; 3]>) -> Result<()> {
        check_len("colors", colors.len(), self.len())?;
        self.colors = Some(colors);
        Ok(())
    }

    /// Adds (or replaces) a named per-point attribute.
    pub fn set_attribute(&mut self, attr: Attribute) -> Result<()> {
        let n = self.len();
        self.attributes.insert(n, attr)
    }

    /// The attribute named `name`, if any.
    pub fn attribute(&self, name: &str) -> Option<&Attribute> {
        self.attributes.get(name)
    }

    /// Axis-aligned bounding box of the positions (`None` for an empty cloud).
    pub fn aabb(&self) -> Option<Aabb> {
        Aabb::from_points(&self.positions)
    }

    /// Keeps only the points whose flag in `keep` is true, with all their per-point data.
    pub fn retain(&mut self, keep: &[bool]) {
        debug_assert_eq!(keep.len(), self.len());
        retain_by(&mut self.positions, keep);
        if let Some(n) = &mut self.normals {
            retain_by(n, keep);
        }
        if let Some(c) = &mut self.colors {
            retain_by(c, keep);
        }
        self.attributes.retain_elements(keep);
    }

    /// A new cloud whose point `i` is point `index[i]` of self, with all per-point data.
    pub fn select(&self, index: &[usize]) -> PointCloud {
        PointCloud {
            positions: index.iter().map(|&i| self.positions[i]).collect(),
            normals: self
                .normals
                .as_ref()
                .map(|n| index.iter().map(|&i| n[i]).collect()),
            colors: self
                .colors
                .as_ref()
                .map(|c| index.iter().map(|&i| c[i]).collect()),
            attributes: self.attributes.select(index),
        }
    }

    /// Checks that every per-point array has one entry per point.
    pub fn validate(&self) -> Result<()> {
        let n = self.len();
        if let Some(v) = &self.normals {
            check_len("normals", v.len(), n)?;
        }
        if let Some(v) = &self.colors {
            check_len("colors", v.len(), n)?;
        }
        for a in &self.attributes {
            check_len(&a.name, a.values.len(), n)?;
        }
        Ok(())
    }
}

fn check_len(what: &str, got: usize, want: usize) -> Result<()> {
    if got != want {
        return Err(Error::InvalidArgument(format!(
            "{what}: {got} values for {want} points"
        )));
    }
    Ok(())
}

pub(crate) fn retain_by<T>(v: &mut Vec<T>, keep: &[bool]) {
    let mut i = 0;
    v.retain(|_| {
        let k = keep[i];
        i += 1;
        k
    });
}
