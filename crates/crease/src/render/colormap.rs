//! Colour maps and palettes: viridis for continuous values, a qualitative palette for labels,
//! fixed colours for the known labels (`sharp`, `surface_type`), hashed colours for cluster ids,
//! and the choice between them for an attribute.
//!
//! * viridis: the 256-entry matplotlib table (van der Walt, Smith & Firing, CC0), perceptually
//!   uniform and readable in grey scale and by colour-blind readers.
//! * Qualitative: matplotlib's `tab10` (Tableau 10) without its grey, then `tab20`'s light
//!   shades, 20 colours in all; grey is kept for "unassigned" (-1) and "other".
//! * Continuous ranges are robust: from the 1st to the 99th percentile of the finite values,
//!   so that a few outliers do not squash the colours of everything else; values outside are
//!   clamped to the end colours.

use std::collections::BTreeMap;

/// The viridis colour map, 256 RGB triples (index 0 = dark purple, 255 = yellow).
#[rustfmt::skip]
static VIRIDIS: [u8; 768] = [
68, 1, 84, 68, 2, 86, 69, 4, 87, 69, 5, 89, 70, 7, 90, 70, 8, 92, 70, 10, 93, 70, 11, 94, 71, 13, 96, 71, 14, 97, 71, 16, 99, 71, 17, 100, 71, 19, 101, 72, 20, 103, 72, 22, 104, 72, 23, 105, 72, 24, 106, 72, 26, 108, 72, 27, 109, 72, 28, 110, 72, 29, 111, 72, 31, 112, 72, 32, 113, 72, 33, 115, 72, 35, 116, 72, 36, 117, 72, 37, 118, 72, 38, 119, 72, 40, 120, 72, 41, 121, 71, 42, 122, 71, 44, 122, 71, 45, 123, 71, 46, 124, 71, 47, 125, 70, 48, 126, 70, 50, 126, 70, 51, 127, 70, 52, 128, 69, 53, 129, 69, 55, 129, 69, 56, 130, 68, 57, 131, 68, 58, 131, 68, 59, 132, 67, 61, 132, 67, 62, 133, 66, 63, 133, 66, 64, 134, 66, 65, 134, 65, 66, 135, 65, 68, 135, 64, 69, 136, 64, 70, 136, 63, 71, 136, 63, 72, 137, 62, 73, 137, 62, 74, 137, 62, 76, 138, 61, 77, 138, 61, 78, 138, 60, 79, 138, 60, 80, 139, 59, 81, 139, 59, 82, 139, 58, 83, 139, 58, 84, 140, 57, 85, 140, 57, 86, 140, 56, 88, 140, 56, 89, 140, 55, 90, 140, 55, 91, 141, 54, 92, 141, 54, 93, 141, 53, 94, 141, 53, 95, 141, 52, 96, 141, 52, 97, 141, 51, 98, 141, 51, 99, 141, 50, 100, 142, 50, 101, 142, 49, 102, 142, 49, 103, 142, 49, 104, 142, 48, 105, 142, 48, 106, 142, 47, 107, 142, 47, 108, 142, 46, 109, 142, 46, 110, 142, 46, 111, 142, 45, 112, 142, 45, 113, 142, 44, 113, 142, 44, 114, 142, 44, 115, 142, 43, 116, 142, 43, 117, 142, 42, 118, 142, 42, 119, 142, 42, 120, 142, 41, 121, 142, 41, 122, 142, 41, 123, 142, 40, 124, 142, 40, 125, 142, 39, 126, 142, 39, 127, 142, 39, 128, 142, 38, 129, 142, 38, 130, 142, 38, 130, 142, 37, 131, 142, 37, 132, 142, 37, 133, 142, 36, 134, 142, 36, 135, 142, 35, 136, 142, 35, 137, 142, 35, 138, 141, 34, 139, 141, 34, 140, 141, 34, 141, 141, 33, 142, 141, 33, 143, 141, 33, 144, 141, 33, 145, 140, 32, 146, 140, 32, 146, 140, 32, 147, 140, 31, 148, 140, 31, 149, 139, 31, 150, 139, 31, 151, 139, 31, 152, 139, 31, 153, 138, 31, 154, 138, 30, 155, 138, 30, 156, 137, 30, 157, 137, 31, 158, 137, 31, 159, 136, 31, 160, 136, 31, 161, 136, 31, 161, 135, 31, 162, 135, 32, 163, 134, 32, 164, 134, 33, 165, 133, 33, 166, 133, 34, 167, 133, 34, 168, 132, 35, 169, 131, 36, 170, 131, 37, 171, 130, 37, 172, 130, 38, 173, 129, 39, 173, 129, 40, 174, 128, 41, 175, 127, 42, 176, 127, 44, 177, 126, 45, 178, 125, 46, 179, 124, 47, 180, 124, 49, 181, 123, 50, 182, 122, 52, 182, 121, 53, 183, 121, 55, 184, 120, 56, 185, 119, 58, 186, 118, 59, 187, 117, 61, 188, 116, 63, 188, 115, 64, 189, 114, 66, 190, 113, 68, 191, 112, 70, 192, 111, 72, 193, 110, 74, 193, 109, 76, 194, 108, 78, 195, 107, 80, 196, 106, 82, 197, 105, 84, 197, 104, 86, 198, 103, 88, 199, 101, 90, 200, 100, 92, 200, 99, 94, 201, 98, 96, 202, 96, 99, 203, 95, 101, 203, 94, 103, 204, 92, 105, 205, 91, 108, 205, 90, 110, 206, 88, 112, 207, 87, 115, 208, 86, 117, 208, 84, 119, 209, 83, 122, 209, 81, 124, 210, 80, 127, 211, 78, 129, 211, 77, 132, 212, 75, 134, 213, 73, 137, 213, 72, 139, 214, 70, 142, 214, 69, 144, 215, 67, 147, 215, 65, 149, 216, 64, 152, 216, 62, 155, 217, 60, 157, 217, 59, 160, 218, 57, 162, 218, 55, 165, 219, 54, 168, 219, 52, 170, 220, 50, 173, 220, 48, 176, 221, 47, 178, 221, 45, 181, 222, 43, 184, 222, 41, 186, 222, 40, 189, 223, 38, 192, 223, 37, 194, 223, 35, 197, 224, 33, 200, 224, 32, 202, 225, 31, 205, 225, 29, 208, 225, 28, 210, 226, 27, 213, 226, 26, 216, 226, 25, 218, 227, 25, 221, 227, 24, 223, 227, 24, 226, 228, 24, 229, 228, 25, 231, 228, 25, 234, 229, 26, 236, 229, 27, 239, 229, 28, 241, 229, 29, 244, 230, 30, 246, 230, 32, 248, 230, 33, 251, 231, 35, 253, 231, 37
];

/// Viridis at `t` in [0, 1] (clamped; NaN gives the first colour).
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let i = (t * 255.0).round() as usize;
    let j = 3 * i.min(255);
    match VIRIDIS.get(j..j + 3) {
        Some(c) => [c[0], c[1], c[2]],
        None => [0, 0, 0],
    }
}

/// The 20-colour qualitative palette used for up to 20 labels, in order of use.
pub const QUALITATIVE: [[u8; 3]; 20] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [188, 189, 34],
    [23, 190, 207],
    [174, 199, 232],
    [255, 187, 120],
    [152, 223, 138],
    [255, 152, 150],
    [197, 176, 213],
    [196, 156, 148],
    [247, 182, 210],
    [219, 219, 141],
    [158, 218, 229],
    [127, 127, 127],
    [199, 199, 199],
];

/// Colour of value 0 of a 0/1 flag (`sharp` = 0): light grey.
pub const FLAG_OFF: [u8; 3] = [190, 190, 190];
/// Colour of value 1 of a 0/1 flag (`sharp` = 1): strong red.
pub const FLAG_ON: [u8; 3] = [214, 39, 40];
/// Colour of unassigned (-1) labels, `other` surfaces and NaN values.
pub const UNASSIGNED: [u8; 3] = [160, 160, 160];
/// Suggested colour for sharp feature polylines.
pub const SHARP_LINE: [u8; 3] = [214, 39, 40];
/// Suggested colour for smooth (fillet) feature polylines.
pub const SMOOTH_LINE: [u8; 3] = [31, 119, 180];

/// `surface_type` codes, names and colours (codes as written by crease's segmentation).
pub const SURFACE_TYPES: [(i64, &str, [u8; 3]); 6] = [
    (0, "plane", [31, 119, 180]),
    (1, "cylinder", [255, 127, 14]),
    (2, "cone", [44, 160, 44]),
    (3, "sphere", [148, 103, 189]),
    (4, "torus", [214, 39, 40]),
    (255, "other", UNASSIGNED),
];

/// Largest number of distinct integer values drawn with a legend entry per value.
pub const MAX_CATEGORIES: usize = 20;

/// True for attribute names holding a 0/1 sharp flag.
pub fn is_sharp_name(name: &str) -> bool {
    matches!(name, "sharp" | "gt_sharp" | "is_sharp")
}

/// True for attribute names holding surface type codes.
pub fn is_surface_type_name(name: &str) -> bool {
    matches!(name, "surface_type" | "gt_surface_type")
}

/// True for attribute names that hold labels even when stored as floats.
pub fn is_label_name(name: &str) -> bool {
    is_sharp_name(name)
        || is_surface_type_name(name)
        || matches!(
            name,
            "label"
                | "labels"
                | "cluster"
                | "segment"
                | "surface"
                | "gt_label"
                | "gt_surface"
                | "class"
        )
}

/// A colour from the hash of `v`: a well-spread hue at medium saturation and lightness, the
/// same for the same id in every image.
pub fn hashed_color(v: i64) -> [u8; 3] {
    // splitmix64 finaliser
    let mut z = (v as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    let hue = (z & 0xFFFF) as f64 / 65536.0;
    let sat = 0.45 + 0.3 * ((z >> 16) & 0xFF) as f64 / 255.0;
    let light = 0.42 + 0.2 * ((z >> 24) & 0xFF) as f64 / 255.0;
    hsl(hue, sat, light)
}

/// HSL (all in [0, 1]) to RGB.
fn hsl(h: f64, s: f64, l: f64) -> [u8; 3] {
    let c = (1.0 - (2.0 * l - 1.0).abs()) * s;
    let hp = (h.fract() * 6.0).max(0.0);
    let x = c * (1.0 - ((hp % 2.0) - 1.0).abs());
    let (r, g, b) = match hp as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = l - c * 0.5;
    let f = |v: f64| ((v + m) * 255.0).round().clamp(0.0, 255.0) as u8;
    [f(r), f(g), f(b)]
}

/// One legend entry of a categorical colouring.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Category {
    /// The attribute value.
    pub value: i64,
    /// Its colour.
    pub color: [u8; 3],
    /// Its name (`sharp`, `plane`, or the number).
    pub label: String,
    /// How many elements carry it.
    pub count: usize,
}

/// How an attribute's values become colours.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Scheme {
    /// Few distinct integer values: one colour and one legend entry each.
    Categorical(Vec<Category>),
    /// Many distinct integer values (cluster ids): hashed colours; `count` distinct ids
    /// (not counting -1), `unassigned` elements with -1.
    Hashed {
        /// Number of distinct ids other than -1.
        count: usize,
        /// Number of elements labelled -1.
        unassigned: usize,
    },
    /// Floats: viridis from `lo` (1st percentile) to `hi` (99th percentile).
    Continuous {
        /// Value mapped to the first colour.
        lo: f64,
        /// Value mapped to the last colour.
        hi: f64,
        /// Smallest finite value.
        min: f64,
        /// Largest finite value.
        max: f64,
        /// Number of NaN / infinite values (drawn grey).
        non_finite: usize,
    },
}

impl Scheme {
    /// Chooses the scheme for attribute `name` from all its `values` (over every element set
    /// that carries it). Integer kinds, and label names whose values are all integral, are
    /// categorical; the rest is continuous.
    pub fn choose(name: &str, integer_kind: bool, values: &[f64]) -> Scheme {
        let integral = values
            .iter()
            .all(|v| !v.is_finite() || (v.fract() == 0.0 && v.abs() < 9.0e15));
        if integer_kind || (is_label_name(name) && integral) {
            categorical(name, values)
        } else {
            continuous(values)
        }
    }

    /// The colour of `v`.
    pub fn color(&self, v: f64) -> [u8; 3] {
        if !v.is_finite() {
            return UNASSIGNED;
        }
        match self {
            Scheme::Categorical(cats) => {
                let k = v as i64;
                match cats.binary_search_by_key(&k, |c| c.value) {
                    Ok(i) => cats.get(i).map_or(UNASSIGNED, |c| c.color),
                    Err(_) => UNASSIGNED,
                }
            }
            Scheme::Hashed { .. } => {
                let k = v as i64;
                if k == -1 {
                    UNASSIGNED
                } else {
                    hashed_color(k)
                }
            }
            Scheme::Continuous { lo, hi, .. } => viridis(t_of(*lo, *hi, v)),
        }
    }

    /// For a continuous scheme, `v` mapped to [0, 1] (clamped); `None` for other schemes or NaN.
    pub fn unit(&self, v: f64) -> Option<f64> {
        match self {
            Scheme::Continuous { lo, hi, .. } if v.is_finite() => Some(t_of(*lo, *hi, v)),
            _ => None,
        }
    }
}

/// `v` between `lo` and `hi` mapped to [0, 1], clamped; 0.5 for an empty range.
fn t_of(lo: f64, hi: f64, v: f64) -> f64 {
    if hi > lo {
        ((v - lo) / (hi - lo)).clamp(0.0, 1.0)
    } else {
        0.5
    }
}

fn categorical(name: &str, values: &[f64]) -> Scheme {
    let mut counts: BTreeMap<i64, usize> = BTreeMap::new();
    let mut distinct_overflow = false;
    for &v in values {
        if !v.is_finite() {
            continue;
        }
        let k = v as i64;
        if let Some(c) = counts.get_mut(&k) {
            *c += 1;
        } else if counts.len() <= MAX_CATEGORIES {
            counts.insert(k, 1);
        } else {
            distinct_overflow = true;
            break;
        }
    }
    if distinct_overflow || counts.len() > MAX_CATEGORIES {
        let mut ids: Vec<i64> = values
            .iter()
            .filter(|v| v.is_finite())
            .map(|&v| v as i64)
            .collect();
        let unassigned = ids.iter().filter(|&&k| k == -1).count();
        ids.sort_unstable();
        ids.dedup();
        let count = ids.iter().filter(|&&k| k != -1).count();
        return Scheme::Hashed { count, unassigned };
    }
    let flag = counts.keys().all(|&k| k == 0 || k == 1);
    let sharp = is_sharp_name(name);
    let surface = is_surface_type_name(name);
    let mut next = 0usize;
    let mut cats = Vec::with_capacity(counts.len());
    for (&value, &count) in &counts {
        let known_surface = if surface {
            SURFACE_TYPES.iter().find(|s| s.0 == value)
        } else {
            None
        };
        let (color, label) = if let Some(s) = known_surface {
            (s.2, s.1.to_string())
        } else if flag || sharp {
            let label = if sharp {
                match value {
                    0 => "not sharp".to_string(),
                    1 => "sharp".to_string(),
                    v => v.to_string(),
                }
            } else {
                value.to_string()
            };
            let color = match value {
                0 => FLAG_OFF,
                1 => FLAG_ON,
                _ => UNASSIGNED,
            };
            (color, label)
        } else if value == -1 {
            (UNASSIGNED, "unassigned".to_string())
        } else {
            // Surface codes outside the table take palette colours after the reserved ones.
            let mut c = QUALITATIVE[next % QUALITATIVE.len()];
            if surface {
                while SURFACE_TYPES.iter().any(|s| s.2 == c) && next < QUALITATIVE.len() {
                    next += 1;
                    c = QUALITATIVE[next % QUALITATIVE.len()];
                }
            }
            next += 1;
            (c, value.to_string())
        };
        cats.push(Category {
            value,
            color,
            label,
            count,
        });
    }
    Scheme::Categorical(cats)
}

fn continuous(values: &[f64]) -> Scheme {
    let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    let non_finite = values.len() - finite.len();
    if finite.is_empty() {
        return Scheme::Continuous {
            lo: 0.0,
            hi: 0.0,
            min: f64::NAN,
            max: f64::NAN,
            non_finite,
        };
    }
    let min = finite.iter().copied().fold(f64::INFINITY, f64::min);
    let max = finite.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let n = finite.len();
    let k_lo = ((n - 1) as f64 * 0.01).round() as usize;
    let k_hi = ((n - 1) as f64 * 0.99).round() as usize;
    let mut pick = |k: usize| -> f64 {
        let (_, v, _) = finite.select_nth_unstable_by(k.min(n - 1), f64::total_cmp);
        *v
    };
    let mut lo = pick(k_lo);
    let mut hi = pick(k_hi);
    if hi <= lo {
        // Almost all values equal: fall back to the full range.
        lo = min;
        hi = max;
    }
    Scheme::Continuous {
        lo,
        hi,
        min,
        max,
        non_finite,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends() {
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(-3.0), viridis(0.0));
    }

    #[test]
    fn flags_and_surface_types() {
        let s = Scheme::choose("sharp", true, &[0.0, 1.0, 1.0]);
        assert_eq!(s.color(0.0), FLAG_OFF);
        assert_eq!(s.color(1.0), FLAG_ON);
        let Scheme::Categorical(c) = &s else {
            panic!("categorical expected")
        };
        assert_eq!(c[1].label, "sharp");
        assert_eq!(c[1].count, 2);
        let s = Scheme::choose("surface_type", true, &[0.0, 3.0, 255.0, 7.0]);
        assert_eq!(s.color(0.0), [31, 119, 180]);
        assert_eq!(s.color(255.0), UNASSIGNED);
        let c7 = s.color(7.0);
        assert!(SURFACE_TYPES.iter().all(|t| t.2 != c7));
    }

    #[test]
    fn many_ids_are_hashed() {
        let v: Vec<f64> = (0..100).map(|i| (i % 50) as f64 - 1.0).collect();
        match Scheme::choose("cluster", true, &v) {
            Scheme::Hashed { count, unassigned } => {
                assert_eq!(count, 49);
                assert_eq!(unassigned, 2);
            }
            s => panic!("{s:?}"),
        }
    }

    #[test]
    fn robust_range_ignores_outliers() {
        let mut v: Vec<f64> = (0..1000).map(|i| i as f64 / 999.0).collect();
        v.push(1e9);
        let s = Scheme::choose("sharpness", false, &v);
        let Scheme::Continuous { hi, max, .. } = s else {
            panic!()
        };
        assert!(hi < 1.0 && max == 1e9);
    }
}
