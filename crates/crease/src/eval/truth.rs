//! Ground-truth readers: per-point "sharp" labels (and, where the source has them, a class per
//! point: flat / sharp / smooth) from a point cloud's named property or from the colour-coded
//! classes of the PCEDNet benchmark (Himeur et al., ACM TOG 2021, supplementary data).
//!
//! Sources, tried in this order by [`TruthSource::Auto`]:
//! 1. a numeric property, value > 0 meaning sharp, looked up under [`DEFAULT_PROPERTIES`]
//!    (`gt_sharp` is what [`crate::synth`] writes; with it, `gt_smooth` gives the smooth class);
//! 2. the PCEDNet colours ([`class_of_color`]): white flat, red sharp, black / orange / gold
//!    smooth. Any other colour is an error naming the file, the colour and how many points have it.

use std::path::Path;

use serde::Serialize;

use crate::geometry::names::{self, gt as attr};
use crate::geometry::PointCloud;
use crate::{Error, Result};

/// Properties tried, in order, when no ground-truth property is named.
pub const DEFAULT_PROPERTIES: [&str; 4] = [attr::SHARP, names::SHARP, "label", "class"];

/// The class of a point in a labelled benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointClass {
    /// On a smooth surface, away from any feature.
    Flat,
    /// On a sharp edge (a crease: the normal jumps).
    Sharp,
    /// On a smooth edge (a fillet border: the curvature jumps, the normal does not).
    Smooth,
}

impl PointClass {
    /// The three classes in order.
    pub const ALL: [PointClass; 3] = [PointClass::Flat, PointClass::Sharp, PointClass::Smooth];

    /// Lower-case name (`flat`, `sharp`, `smooth`).
    pub fn name(self) -> &'static str {
        match self {
            PointClass::Flat => "flat",
            PointClass::Sharp => "sharp",
            PointClass::Smooth => "smooth",
        }
    }
}

/// Where the ground truth is read from.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum TruthSource {
    /// A property of [`DEFAULT_PROPERTIES`] if present, else the colour classes if the cloud
    /// has colours.
    #[default]
    Auto,
    /// The named numeric property (> 0 = sharp).
    Property(String),
    /// The PCEDNet colour classes.
    Colors,
}

/// Per-point ground truth.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundTruth {
    /// True for the points of the positive (sharp) class.
    pub sharp: Vec<bool>,
    /// The class of every point, when the source distinguishes smooth edges from flat areas.
    pub classes: Option<Vec<PointClass>>,
    /// What was read: `property gt_sharp`, `colour classes`, ...
    pub source: String,
}

/// Number of points of each class.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
pub struct ClassCounts {
    /// Flat points.
    pub flat: u64,
    /// Sharp-edge points.
    pub sharp: u64,
    /// Smooth-edge points.
    pub smooth: u64,
}

impl ClassCounts {
    /// Counts `classes`.
    pub fn of(classes: &[PointClass]) -> ClassCounts {
        let mut c = ClassCounts::default();
        for k in classes {
            *c.get_mut(*k) += 1;
        }
        c
    }

    /// The count of class `k`.
    pub fn get(&self, k: PointClass) -> u64 {
        match k {
            PointClass::Flat => self.flat,
            PointClass::Sharp => self.sharp,
            PointClass::Smooth => self.smooth,
        }
    }

    fn get_mut(&mut self, k: PointClass) -> &mut u64 {
        match k {
            PointClass::Flat => &mut self.flat,
            PointClass::Sharp => &mut self.sharp,
            PointClass::Smooth => &mut self.smooth,
        }
    }

    /// All points.
    pub fn total(&self) -> u64 {
        self.flat + self.sharp + self.smooth
    }
}

impl GroundTruth {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.sharp.len()
    }

    /// True when there are no points.
    pub fn is_empty(&self) -> bool {
        self.sharp.is_empty()
    }

    /// Points per class (without classes: sharp and flat from the labels).
    pub fn class_counts(&self) -> ClassCounts {
        match &self.classes {
            Some(c) => ClassCounts::of(c),
            None => {
                let sharp = self.sharp.iter().filter(|&&s| s).count() as u64;
                ClassCounts {
                    flat: self.sharp.len() as u64 - sharp,
                    sharp,
                    smooth: 0,
                }
            }
        }
    }
}

/// The PCEDNet class of an RGB colour: (255,255,255) flat; (168,0,0) or (255,0,0) sharp;
/// (0,0,0), (255,196,93) or (255,215,0) smooth; anything else `None`.
pub fn class_of_color(c: [u8; 3]) -> Option<PointClass> {
    match c {
        [255, 255, 255] => Some(PointClass::Flat),
        [168, 0, 0] | [255, 0, 0] => Some(PointClass::Sharp),
        [0, 0, 0] | [255, 196, 93] | [255, 215, 0] => Some(PointClass::Smooth),
        _ => None,
    }
}

/// Ground truth from the per-point colours of `cloud` (read from `path`, named in errors).
/// Fails if the cloud has no colours, or lists every unknown colour with its point count and
/// the first point having it.
pub fn truth_from_colors(cloud: &PointCloud, path: &Path) -> Result<GroundTruth> {
    let Some(colors) = &cloud.colors else {
        return Err(Error::format(
            path,
            "no per-point colours (red green blue), so no PCEDNet colour classes",
        ));
    };
    let classes: Vec<Option<PointClass>> = colors.iter().map(|&c| class_of_color(c)).collect();
    if classes.iter().any(|c| c.is_none()) {
        // (colour, count, first point), in order of first appearance.
        let mut unknown: Vec<([u8; 3], usize, usize)> = Vec::new();
        for (i, (&c, k)) in colors.iter().zip(&classes).enumerate() {
            if k.is_some() {
                continue;
            }
            match unknown.iter_mut().find(|u| u.0 == c) {
                Some(u) => u.1 += 1,
                None => unknown.push((c, 1, i)),
            }
        }
        let total: usize = unknown.iter().map(|u| u.1).sum();
        let listed: Vec<String> = unknown
            .iter()
            .take(8)
            .map(|(c, n, i)| {
                format!(
                    "({},{},{}) on {n} points, first point {i}",
                    c[0], c[1], c[2]
                )
            })
            .collect();
        return Err(Error::format(
            path,
            format!(
                "{total} points have a colour that is no PCEDNet class: {}{}; expected (255,255,255) flat, (168,0,0) or (255,0,0) sharp, (0,0,0), (255,196,93) or (255,215,0) smooth",
                listed.join("; "),
                if unknown.len() > 8 { format!("; and {} more colours", unknown.len() - 8) } else { String::new() }
            ),
        ));
    }
    let classes: Vec<PointClass> = classes.into_iter().flatten().collect();
    Ok(GroundTruth {
        sharp: classes.iter().map(|&c| c == PointClass::Sharp).collect(),
        classes: Some(classes),
        source: "colour classes".into(),
    })
}

/// Boolean labels (value > 0) of the numeric property `name` of `cloud`; errors (naming `path`)
/// if it is missing or a value is NaN. `what` says whose labels these are, for messages.
pub fn labels_from_property(
    cloud: &PointCloud,
    name: &str,
    path: &Path,
    what: &str,
) -> Result<Vec<bool>> {
    let Some(a) = cloud.attribute(name) else {
        return Err(Error::format(
            path,
            format!(
                "no per-point property {name:?} for the {what}; properties present: {}",
                property_list(cloud)
            ),
        ));
    };
    if let Some(i) = a.values.iter().position(|v| v.is_nan()) {
        return Err(Error::format(
            path,
            format!("property {name:?} is NaN at point {i}; expected a number (> 0 = positive)"),
        ));
    }
    Ok(a.values.iter().map(|&v| v > 0.0).collect())
}

/// The values of the numeric property `name` of `cloud` as scores (e.g. a detector's
/// `sharpness`); errors (naming `path`) if it is missing or a value is NaN.
pub fn scores_from_property(cloud: &PointCloud, name: &str, path: &Path) -> Result<Vec<f64>> {
    let Some(a) = cloud.attribute(name) else {
        return Err(Error::format(
            path,
            format!(
                "no per-point property {name:?} for the scores; properties present: {}",
                property_list(cloud)
            ),
        ));
    };
    if let Some(i) = a.values.iter().position(|v| v.is_nan()) {
        return Err(Error::format(
            path,
            format!("score property {name:?} is NaN at point {i}; every score must be a number"),
        ));
    }
    Ok(a.values.clone())
}

/// Ground truth from the numeric property `name` (> 0 = sharp). When `name` is `gt_sharp` and
/// the cloud also has `gt_smooth` (a [`crate::synth`] part), classes are given too: sharp if
/// `gt_sharp`, else smooth if `gt_smooth`, else flat.
pub fn truth_from_property(cloud: &PointCloud, name: &str, path: &Path) -> Result<GroundTruth> {
    let sharp = labels_from_property(cloud, name, path, "ground truth")?;
    let classes = match (name == attr::SHARP, cloud.attribute(attr::SMOOTH)) {
        (true, Some(sm)) => Some(
            sharp
                .iter()
                .zip(&sm.values)
                .map(|(&s, &m)| {
                    if s {
                        PointClass::Sharp
                    } else if m > 0.0 {
                        PointClass::Smooth
                    } else {
                        PointClass::Flat
                    }
                })
                .collect(),
        ),
        _ => None,
    };
    Ok(GroundTruth {
        sharp,
        classes,
        source: format!("property {name}"),
    })
}

/// Ground truth of `cloud` (read from `path`) from `source`. With [`TruthSource::Auto`] the
/// error, when nothing fits, lists what was looked for and what the file has.
pub fn read_truth(cloud: &PointCloud, source: &TruthSource, path: &Path) -> Result<GroundTruth> {
    match source {
        TruthSource::Property(name) => truth_from_property(cloud, name, path),
        TruthSource::Colors => truth_from_colors(cloud, path),
        TruthSource::Auto => {
            if let Some(name) = DEFAULT_PROPERTIES
                .iter()
                .find(|n| cloud.attribute(n).is_some())
            {
                return truth_from_property(cloud, name, path);
            }
            if cloud.colors.is_some() {
                return truth_from_colors(cloud, path);
            }
            Err(Error::format(
                path,
                format!(
                    "no ground truth found: looked for a property named {} and for per-point colours (PCEDNet classes); properties present: {}",
                    DEFAULT_PROPERTIES.join(", "),
                    property_list(cloud)
                ),
            ))
        }
    }
}

fn property_list(cloud: &PointCloud) -> String {
    let names: Vec<&str> = cloud.attributes.iter().map(|a| a.name.as_str()).collect();
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Attribute;

    fn cloud(n: usize) -> PointCloud {
        PointCloud::from_positions((0..n).map(|i| [i as f64, 0.0, 0.0]).collect())
    }

    #[test]
    fn colours_give_classes() {
        let mut c = cloud(6);
        c.set_colors(vec![
            [255, 255, 255],
            [168, 0, 0],
            [255, 0, 0],
            [0, 0, 0],
            [255, 196, 93],
            [255, 215, 0],
        ])
        .unwrap();
        let t = read_truth(&c, &TruthSource::Auto, Path::new("x.ply")).unwrap();
        assert_eq!(t.sharp, vec![false, true, true, false, false, false]);
        assert_eq!(
            t.class_counts(),
            ClassCounts {
                flat: 1,
                sharp: 2,
                smooth: 3
            }
        );
        assert_eq!(t.source, "colour classes");
    }

    #[test]
    fn unknown_colours_are_named_with_their_count() {
        let mut c = cloud(4);
        c.set_colors(vec![[255, 255, 255], [1, 2, 3], [1, 2, 3], [9, 9, 9]])
            .unwrap();
        let e = truth_from_colors(&c, Path::new("bad.ply"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("bad.ply: 3 points"), "{e}");
        assert!(e.contains("(1,2,3) on 2 points, first point 1"), "{e}");
        assert!(e.contains("(9,9,9) on 1 points, first point 3"), "{e}");
    }

    #[test]
    fn properties_in_order_then_colours_then_a_clear_error() {
        let mut c = cloud(3);
        c.set_attribute(Attribute::int("label", [0, 2, -1]))
            .unwrap();
        c.set_colors(vec![[255, 0, 0]; 3]).unwrap();
        let t = read_truth(&c, &TruthSource::Auto, Path::new("a.ply")).unwrap();
        assert_eq!(t.sharp, vec![false, true, false]);
        assert_eq!(t.source, "property label");
        assert_eq!(t.classes, None);
        c.set_attribute(Attribute::flag("gt_sharp", [true, false, false]))
            .unwrap();
        c.set_attribute(Attribute::flag("gt_smooth", [true, true, false]))
            .unwrap();
        let t = read_truth(&c, &TruthSource::Auto, Path::new("a.ply")).unwrap();
        assert_eq!(t.sharp, vec![true, false, false]);
        assert_eq!(
            t.classes,
            Some(vec![
                PointClass::Sharp,
                PointClass::Smooth,
                PointClass::Flat
            ])
        );
        let t = read_truth(&c, &TruthSource::Colors, Path::new("a.ply")).unwrap();
        assert_eq!(t.sharp, vec![true; 3]);
        let e = read_truth(
            &c,
            &TruthSource::Property("nope".into()),
            Path::new("a.ply"),
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("a.ply") && e.contains("\"nope\"") && e.contains("gt_sharp"),
            "{e}"
        );
        let e = read_truth(&cloud(2), &TruthSource::Auto, Path::new("b.ply"))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("b.ply: no ground truth found"), "{e}");
        assert!(e.contains("gt_sharp, sharp, label, class"), "{e}");
        let mut c = cloud(2);
        c.set_attribute(Attribute::float("sharp", vec![0.0, f64::NAN]))
            .unwrap();
        let e = read_truth(&c, &TruthSource::Auto, Path::new("c.ply")).unwrap_err();
        assert!(e.to_string().contains("NaN at point 1"), "{e}");
    }
}
