//! Scoring a segmentation against per-face ground truth: area-weighted type accuracy, the
//! intersection over union (IoU) of every ground-truth surface with its best-matching
//! extracted surface, and parameter errors; plus the reader of the ABC dataset's surface
//! ground truth (`*_face_surface_labels.txt` and `*_primitives.json`, see
//! `../shared/data/README.md`).

use std::collections::HashMap;
use std::path::Path;

use serde::Serialize;

use crate::geometry::vec3::{cross, dot, norm, sub};
use crate::geometry::{SurfaceParams, SurfaceType};
use crate::{Error, Result};

/// How one ground-truth surface was recovered.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SurfaceMatch {
    /// Ground-truth surface index.
    pub truth: usize,
    /// Its type.
    pub truth_type: SurfaceType,
    /// Its area (sum of its faces').
    pub area: f64,
    /// The extracted surface with the largest IoU, -1 if none overlaps.
    pub best: i64,
    /// That surface's type (`Other` when none).
    pub best_type: SurfaceType,
    /// IoU (by area) of the two face sets.
    pub iou: f64,
}

/// Scores of a segmentation (see [`score_faces`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SegmentScore {
    /// Fraction of the (ground-truth-typed) area whose face got the right type.
    pub typed_area: f64,
    /// Fraction of that area left unassigned.
    pub unassigned_area: f64,
    /// Mean IoU over the ground-truth surfaces, weighted by area.
    pub mean_iou_area: f64,
    /// Plain mean IoU over the ground-truth surfaces.
    pub mean_iou: f64,
    /// Per ground-truth surface.
    pub matches: Vec<SurfaceMatch>,
}

/// Compares per-face predictions with per-face ground truth. Faces whose truth type is
/// `Other` (or with a negative truth id) are left out.
///
/// Inputs: per face: area, predicted surface id (-1 none), predicted type code, truth surface
/// id, truth type code (all of the same length).
/// Errors: lengths differ.
pub fn score_faces(
    area: &[f64],
    pred: &[i32],
    pred_type: &[u8],
    truth: &[i32],
    truth_type: &[u8],
) -> Result<SegmentScore> {
    let n = area.len();
    if [pred.len(), pred_type.len(), truth.len(), truth_type.len()]
        .iter()
        .any(|&l| l != n)
    {
        return Err(Error::InvalidArgument(
            "segmentation score: per-face arrays of different lengths".into(),
        ));
    }
    let other = SurfaceType::Other.code();
    let (mut total, mut right, mut unassigned) = (0.0, 0.0, 0.0);
    let mut truth_area: HashMap<i32, (f64, u8)> = HashMap::new();
    let mut pred_area: HashMap<i32, f64> = HashMap::new();
    let mut inter: HashMap<(i32, i32), f64> = HashMap::new();
    for f in 0..n {
        let a = if area[f].is_finite() { area[f] } else { 0.0 };
        if pred[f] >= 0 {
            *pred_area.entry(pred[f]).or_default() += a;
        }
        if truth[f] < 0 || truth_type[f] == other {
            continue;
        }
        total += a;
        if pred_type[f] == truth_type[f] {
            right += a;
        }
        if pred[f] < 0 {
            unassigned += a;
        }
        let e = truth_area.entry(truth[f]).or_insert((0.0, truth_type[f]));
        e.0 += a;
        if pred[f] >= 0 {
            *inter.entry((truth[f], pred[f])).or_default() += a;
        }
    }
    let mut pred_types: HashMap<i32, u8> = HashMap::new();
    for f in 0..n {
        if pred[f] >= 0 {
            pred_types.insert(pred[f], pred_type[f]);
        }
    }
    let mut ids: Vec<i32> = truth_area.keys().copied().collect();
    ids.sort_unstable();
    let mut pairs: Vec<((i32, i32), f64)> = inter.into_iter().collect();
    pairs.sort_by_key(|a| a.0);
    let matches: Vec<SurfaceMatch> = ids
        .iter()
        .map(|&t| {
            let (ta, tt) = truth_area[&t];
            let mut best = (-1i64, 0.0f64);
            for &((tt2, p), i) in &pairs {
                if tt2 != t {
                    continue;
                }
                let iou = i / (ta + pred_area[&p] - i);
                if iou > best.1 {
                    best = (p as i64, iou);
                }
            }
            SurfaceMatch {
                truth: t as usize,
                truth_type: SurfaceType::from_code(tt).unwrap_or(SurfaceType::Other),
                area: ta,
                best: best.0,
                best_type: if best.0 >= 0 {
                    SurfaceType::from_code(pred_types[&(best.0 as i32)])
                        .unwrap_or(SurfaceType::Other)
                } else {
                    SurfaceType::Other
                },
                iou: best.1,
            }
        })
        .collect();
    let tsum: f64 = matches.iter().map(|m| m.area).sum();
    Ok(SegmentScore {
        typed_area: if total > 0.0 { right / total } else { 0.0 },
        unassigned_area: if total > 0.0 { unassigned / total } else { 0.0 },
        mean_iou_area: if tsum > 0.0 {
            matches.iter().map(|m| m.iou * m.area).sum::<f64>() / tsum
        } else {
            0.0
        },
        mean_iou: if matches.is_empty() {
            0.0
        } else {
            matches.iter().map(|m| m.iou).sum::<f64>() / matches.len() as f64
        },
        matches,
    })
}

/// Parameter errors between an extracted surface and the true one of the same type.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ParamError {
    /// Relative error of the radius (cylinder, sphere; torus: the larger of the two).
    pub radius: Option<f64>,
    /// Angle between the axes / plane normals, degrees (orientation ignored).
    pub axis_degrees: Option<f64>,
    /// Distance between the axis lines at the centroid (cylinder), centres (sphere, torus),
    /// apexes (cone) or planes at the origin (plane offset difference).
    pub position: Option<f64>,
    /// Half-angle error of a cone, degrees.
    pub half_angle_degrees: Option<f64>,
}

fn axis_angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    dot(a, b).abs().min(1.0).acos().to_degrees()
}

/// Errors of `got` against `truth`; all `None` when the types differ.
pub fn param_error(got: &SurfaceParams, truth: &SurfaceParams) -> ParamError {
    use SurfaceParams as S;
    match (*got, *truth) {
        (
            S::Plane { normal, offset },
            S::Plane {
                normal: n2,
                offset: o2,
            },
        ) => ParamError {
            axis_degrees: Some(axis_angle(normal, n2)),
            position: Some(if dot(normal, n2) >= 0.0 {
                (offset - o2).abs()
            } else {
                (offset + o2).abs()
            }),
            ..Default::default()
        },
        (
            S::Cylinder {
                axis_point,
                axis_dir,
                radius,
            },
            S::Cylinder {
                axis_point: p2,
                axis_dir: d2,
                radius: r2,
            },
        ) => ParamError {
            radius: Some((radius - r2).abs() / r2),
            axis_degrees: Some(axis_angle(axis_dir, d2)),
            position: Some(norm(cross(sub(axis_point, p2), d2))),
            ..Default::default()
        },
        (
            S::Sphere { center, radius },
            S::Sphere {
                center: c2,
                radius: r2,
            },
        ) => ParamError {
            radius: Some((radius - r2).abs() / r2),
            position: Some(norm(sub(center, c2))),
            ..Default::default()
        },
        (
            S::Cone {
                apex,
                axis_dir,
                half_angle,
            },
            S::Cone {
                apex: a2,
                axis_dir: d2,
                half_angle: h2,
            },
        ) => ParamError {
            axis_degrees: Some(axis_angle(axis_dir, d2)),
            position: Some(norm(sub(apex, a2))),
            half_angle_degrees: Some((half_angle - h2).abs().to_degrees()),
            ..Default::default()
        },
        (
            S::Torus {
                center,
                axis_dir,
                major_radius,
                minor_radius,
            },
            S::Torus {
                center: c2,
                axis_dir: d2,
                major_radius: rr2,
                minor_radius: r2,
            },
        ) => ParamError {
            radius: Some(((major_radius - rr2).abs() / rr2).max((minor_radius - r2).abs() / r2)),
            axis_degrees: Some(axis_angle(axis_dir, d2)),
            position: Some(norm(sub(center, c2))),
            ..Default::default()
        },
        _ => ParamError::default(),
    }
}

/// Ground truth of an ABC model's surfaces.
#[derive(Debug, Clone)]
pub struct AbcTruth {
    /// Per face: surface index.
    pub face_surface: Vec<i32>,
    /// Per face: type code (`Other` for BSpline, Revolution, ...).
    pub face_type: Vec<u8>,
    /// Per surface: parameters (`None` for the types crease does not model).
    pub surfaces: Vec<Option<SurfaceParams>>,
}

fn abc_type(name: &str) -> SurfaceType {
    match name {
        "Plane" => SurfaceType::Plane,
        "Cylinder" => SurfaceType::Cylinder,
        "Cone" => SurfaceType::Cone,
        "Sphere" => SurfaceType::Sphere,
        "Torus" => SurfaceType::Torus,
        _ => SurfaceType::Other,
    }
}

/// Reads an ABC model's `*_face_surface_labels.txt` (one line per face: surface index and
/// type, `#` comments) and `*_primitives.json` (the features file's surfaces with their
/// parameters: plane `coefficients` a b c d of `ax + by + cz + d = 0`; cylinder `location`,
/// `z_axis`, `radius`; cone `apex`, `z_axis`, `angle`; sphere `location`, `radius`; torus
/// `location`, `z_axis`, `max_radius`, `min_radius`).
pub fn read_abc_truth(labels: &Path, primitives: &Path) -> Result<AbcTruth> {
    let text = std::fs::read_to_string(labels)
        .map_err(|e| Error::InvalidInput(format!("{}: {e}", labels.display())))?;
    let (mut face_surface, mut face_type) = (Vec::new(), Vec::new());
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let mut it = line.split_whitespace();
        let id: i32 = it.next().and_then(|s| s.parse().ok()).ok_or_else(|| {
            Error::InvalidInput(format!(
                "{} line {}: expected `surface_index type`, got `{line}`",
                labels.display(),
                i + 1
            ))
        })?;
        face_surface.push(id);
        face_type.push(abc_type(it.next().unwrap_or("")).code());
    }
    let json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(primitives)
            .map_err(|e| Error::InvalidInput(format!("{}: {e}", primitives.display())))?,
    )
    .map_err(|e| Error::InvalidInput(format!("{}: {e}", primitives.display())))?;
    let list = json["surfaces"].as_array().ok_or_else(|| {
        Error::InvalidInput(format!("{}: no `surfaces` array", primitives.display()))
    })?;
    let v3 = |v: &serde_json::Value| -> Option<[f64; 3]> {
        let a = v.as_array()?;
        Some([
            a.first()?.as_f64()?,
            a.get(1)?.as_f64()?,
            a.get(2)?.as_f64()?,
        ])
    };
    let unit = |v: [f64; 3]| crate::geometry::vec3::normalize(v);
    let surfaces = list
        .iter()
        .map(|s| {
            let t = s["type"].as_str().unwrap_or("");
            match abc_type(t) {
                SurfaceType::Plane => {
                    let c = s["coefficients"].as_array()?;
                    let n = [
                        c.first()?.as_f64()?,
                        c.get(1)?.as_f64()?,
                        c.get(2)?.as_f64()?,
                    ];
                    let len = norm(n);
                    Some(SurfaceParams::Plane {
                        normal: unit(n)?,
                        offset: -c.get(3)?.as_f64()? / len,
                    })
                }
                SurfaceType::Cylinder => Some(SurfaceParams::Cylinder {
                    axis_point: v3(&s["location"])?,
                    axis_dir: unit(v3(&s["z_axis"])?)?,
                    radius: s["radius"].as_f64()?,
                }),
                SurfaceType::Cone => Some(SurfaceParams::Cone {
                    apex: v3(&s["apex"])?,
                    axis_dir: unit(v3(&s["z_axis"])?)?,
                    half_angle: s["angle"].as_f64()?,
                }),
                SurfaceType::Sphere => Some(SurfaceParams::Sphere {
                    center: v3(&s["location"])?,
                    radius: s["radius"].as_f64()?,
                }),
                SurfaceType::Torus => Some(SurfaceParams::Torus {
                    center: v3(&s["location"])?,
                    axis_dir: unit(v3(&s["z_axis"])?)?,
                    major_radius: s["max_radius"].as_f64()?,
                    minor_radius: s["min_radius"].as_f64()?,
                }),
                SurfaceType::Other => None,
            }
        })
        .collect();
    Ok(AbcTruth {
        face_surface,
        face_type,
        surfaces,
    })
}
