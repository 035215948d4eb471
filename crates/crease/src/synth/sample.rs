//! Point sampling of the synthetic parts: uniform over the area, Gaussian noise, uniform
//! outliers, exact per-point ground truth.
//!
//! A point is drawn by choosing a patch with probability proportional to the area of its
//! untrimmed domain, drawing a uniform point of that domain (area-correct parametrisation) and
//! rejecting it if the patch's trim removes it; the accepted points are therefore uniform over
//! the whole trimmed surface. Points are generated in fixed chunks of 4096, each with its own
//! `Pcg64` seeded from (seed, chunk index), so the cloud does not depend on the thread count.

use rand::{Rng, SeedableRng};
use rand_distr::StandardNormal;
use rand_pcg::Pcg64;
use rayon::prelude::*;
use serde_json::json;

use super::shapes::Model;
use super::truth::{CurveIndex, CurveKind};
use super::{attr, FeatureCurve, Noise, NoiseScale, Shape, Surface};
use crate::geometry::vec3::{add, scale};
use crate::geometry::SurfaceType;
use crate::geometry::{Attribute, Point3, PointCloud, ScalarKind};
use crate::io::Geometry;
use crate::{Error, Result};

/// Parameters of [`sample_points`].
#[derive(Debug, Clone, PartialEq)]
pub struct SampleParams {
    /// Total number of points, outliers included (default 100 000).
    pub n: usize,
    /// Noise on the surface points (default none).
    pub noise: Noise,
    /// What the noise sigma is relative to (default the expected spacing).
    pub noise_scale: NoiseScale,
    /// Fraction of outliers in [0, 1): `round(outliers · n)` points uniform in the shape's
    /// bounding box enlarged by 10 % (5 % of each extent on every side). Default 0.
    pub outliers: f64,
    /// Random seed (default 1).
    pub seed: u64,
    /// Distance to a curve under which a point is labelled sharp / smooth. Default: 1 × the
    /// expected spacing.
    pub sharp_tolerance: Option<f64>,
}

impl Default for SampleParams {
    fn default() -> Self {
        SampleParams {
            n: 100_000,
            noise: Noise::None,
            noise_scale: NoiseScale::Spacing,
            outliers: 0.0,
            seed: 1,
            sharp_tolerance: None,
        }
    }
}

/// A sampled synthetic part with its exact ground truth.
#[derive(Debug, Clone)]
pub struct SyntheticPart {
    /// The points with exact normals and the `gt_*` attributes (see the module documentation).
    pub cloud: PointCloud,
    /// The patches; `gt_surface` indexes this list.
    pub surfaces: Vec<Surface>,
    /// The exact feature curves.
    pub curves: Vec<FeatureCurve>,
    /// Expected spacing `sqrt(total area / number of surface points)` (the side of the square
    /// each point would own on a regular grid; the mean nearest-neighbour distance of a uniform
    /// random sample is about half of it).
    pub spacing: f64,
    /// Tolerance of the `gt_sharp` / `gt_smooth` labels.
    pub sharp_tolerance: f64,
    /// The sampled shape.
    pub shape: Shape,
    /// Absolute standard deviation of the noise that was added.
    pub noise_sigma: f64,
}

/// Samples `p.n` points on `shape` with exact ground truth. Fails on invalid shape dimensions or
/// parameters (n = 0, outlier fraction outside [0, 1), negative or non-finite sigma / tolerance).
pub fn sample_points(shape: &Shape, p: &SampleParams) -> Result<SyntheticPart> {
    if p.n == 0 || p.n > u32::MAX as usize {
        return Err(Error::InvalidInput(format!(
            "synthetic sampling: the number of points must be in 1..=2^32-1, got {}",
            p.n
        )));
    }
    if !(0.0..1.0).contains(&p.outliers) {
        return Err(Error::InvalidInput(format!(
            "synthetic sampling: the outlier fraction must be in [0, 1), got {}",
            p.outliers
        )));
    }
    check_sigma(p.noise)?;
    check_tolerance(p.sharp_tolerance)?;
    let model = shape.model()?;
    let n_out = (p.outliers * p.n as f64).round() as usize;
    let n_surf = p.n - n_out;
    let total_area: f64 = model.patches.iter().map(|q| q.surface.area).sum();
    let spacing = (total_area / n_surf.max(1) as f64).sqrt();
    let tol = p.sharp_tolerance.unwrap_or(spacing);
    let sigma = p.noise.sigma()
        * match p.noise_scale {
            NoiseScale::Spacing => spacing,
            NoiseScale::BoundingBox => model.bbox.diagonal(),
        };

    // Patch choice by untrimmed domain area.
    let mut cumulative = Vec::with_capacity(model.patches.len());
    let mut acc = 0.0;
    for q in &model.patches {
        acc += q.domain.area();
        cumulative.push(acc);
    }
    const CHUNK: usize = 4096;
    let chunks = n_surf.div_ceil(CHUNK);
    let surface_points: Vec<(Point3, Point3, Point3, u32)> = (0..chunks)
        .into_par_iter()
        .flat_map_iter(|c| {
            let mut rng = Pcg64::seed_from_u64(mix(p.seed, c as u64));
            let count = CHUNK.min(n_surf - c * CHUNK);
            let model = &model;
            let cumulative = &cumulative;
            (0..count)
                .map(move |_| {
                    let (pos, normal, id) = draw(model, cumulative, acc, &mut rng);
                    let noisy = match p.noise {
                        Noise::None => pos,
                        Noise::AlongNormal(_) => {
                            let g: f64 = rng.sample(StandardNormal);
                            add(pos, scale(normal, g * sigma))
                        }
                        Noise::Isotropic(_) => {
                            let g: Point3 = [
                                rng.sample(StandardNormal),
                                rng.sample(StandardNormal),
                                rng.sample(StandardNormal),
                            ];
                            add(pos, scale(g, sigma))
                        }
                    };
                    (pos, noisy, normal, id)
                })
                .collect::<Vec<_>>()
        })
        .collect();

    // Outliers: uniform in the bounding box enlarged by 10 %.
    let ext = model.bbox.extent();
    let lo: Point3 = std::array::from_fn(|k| model.bbox.min[k] - 0.05 * ext[k]);
    let size: Point3 = std::array::from_fn(|k| 1.1 * ext[k]);
    let mut orng = Pcg64::seed_from_u64(mix(p.seed ^ 0x6f75_746c_6965_7273, u64::MAX));
    let outliers: Vec<Point3> = (0..n_out)
        .map(|_| std::array::from_fn(|k| lo[k] + orng.random::<f64>() * size[k]))
        .collect();

    // Order: surface points then outliers, then one seeded shuffle of everything.
    let n = p.n;
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut srng = Pcg64::seed_from_u64(mix(p.seed, u64::MAX - 1));
    for i in (1..n).rev() {
        let j = srng.random_range(0..=i);
        order.swap(i, j);
    }
    let sample = |i: u32| -> (Point3, Point3, Point3, i64) {
        let i = i as usize;
        if i < n_surf {
            let (t, q, nn, id) = surface_points[i];
            (t, q, nn, id as i64)
        } else {
            let o = outliers[i - n_surf];
            (o, o, [0.0; 3], -1)
        }
    };
    let rows: Vec<(Point3, Point3, Point3, i64)> = order.par_iter().map(|&i| sample(i)).collect();
    let truth: Vec<Point3> = rows.iter().map(|r| r.0).collect();
    let surface: Vec<i64> = rows.iter().map(|r| r.3).collect();
    let mut cloud = PointCloud::from_positions(rows.iter().map(|r| r.1).collect());
    cloud.set_normals(rows.iter().map(|r| r.2).collect())?;
    drop(rows);
    let kinds: Vec<SurfaceType> = model.patches.iter().map(|q| q.surface.kind).collect();
    for a in truth_attributes(&truth, &surface, &kinds, &model.curves, tol) {
        cloud.set_attribute(a)?;
    }
    Ok(SyntheticPart {
        cloud,
        surfaces: model.patches.iter().map(|q| q.surface.clone()).collect(),
        curves: model.curves,
        spacing,
        sharp_tolerance: tol,
        shape: *shape,
        noise_sigma: sigma,
    })
}

/// One uniform point of the trimmed surface: position, normal, patch id.
fn draw(model: &Model, cumulative: &[f64], total: f64, rng: &mut Pcg64) -> (Point3, Point3, u32) {
    loop {
        let x = rng.random::<f64>() * total;
        let i = cumulative
            .partition_point(|&c| c <= x)
            .min(cumulative.len() - 1);
        let patch = &model.patches[i];
        let (pos, normal, q) = patch.domain.sample(rng);
        if patch.trim.keeps(pos, q) {
            return (pos, normal, i as u32);
        }
    }
}

/// SplitMix64 of (seed, stream): independent seeds per chunk.
pub(crate) fn mix(seed: u64, stream: u64) -> u64 {
    let mut z = seed
        .wrapping_add(stream.wrapping_mul(0x9E37_79B9_7F4A_7C15))
        .wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

pub(crate) fn check_sigma(noise: Noise) -> Result<()> {
    let s = noise.sigma();
    if s.is_finite() && s >= 0.0 {
        Ok(())
    } else {
        Err(Error::InvalidInput(format!(
            "synthetic noise sigma must be finite and non-negative, got {s}"
        )))
    }
}

pub(crate) fn check_tolerance(t: Option<f64>) -> Result<()> {
    match t {
        Some(t) if !(t.is_finite() && t >= 0.0) => Err(Error::InvalidInput(format!(
            "synthetic sharp tolerance must be finite and non-negative, got {t}"
        ))),
        _ => Ok(()),
    }
}

/// The `gt_*` attributes for elements with true positions `truth` and surface ids `surface`
/// (-1 = outlier).
pub(crate) fn truth_attributes(
    truth: &[Point3],
    surface: &[i64],
    kinds: &[SurfaceType],
    curves: &[FeatureCurve],
    tol: f64,
) -> Vec<Attribute> {
    let sharp = CurveIndex::new(curves, CurveKind::Sharp);
    let smooth = CurveIndex::new(curves, CurveKind::Smooth);
    let far = f32::MAX as f64;
    let dists: Vec<(f64, i64, f64, i64)> = truth
        .par_iter()
        .map(|&p| {
            let (ds, cs) = sharp.nearest(p);
            let (dm, cm) = smooth.nearest(p);
            (
                if ds.is_finite() { ds } else { far },
                cs.map_or(-1, i64::from),
                if dm.is_finite() { dm } else { far },
                cm.map_or(-1, i64::from),
            )
        })
        .collect();
    let is_out = |i: usize| surface[i] < 0;
    let u8_attr = |name: &str, values: Vec<f64>| Attribute {
        name: name.into(),
        kind: ScalarKind::U8,
        values,
    };
    vec![
        Attribute::float(attr::EDGE_DISTANCE, dists.iter().map(|d| d.0).collect()),
        Attribute::flag(
            attr::SHARP,
            dists
                .iter()
                .enumerate()
                .map(|(i, d)| !is_out(i) && d.0 <= tol),
        ),
        Attribute::float(attr::SMOOTH_DISTANCE, dists.iter().map(|d| d.2).collect()),
        Attribute::flag(
            attr::SMOOTH,
            dists
                .iter()
                .enumerate()
                .map(|(i, d)| !is_out(i) && d.2 <= tol),
        ),
        Attribute::int(attr::SHARP_CURVE, dists.iter().map(|d| d.1)),
        Attribute::int(attr::SMOOTH_CURVE, dists.iter().map(|d| d.3)),
        Attribute::int(attr::SURFACE, surface.iter().copied()),
        u8_attr(
            attr::SURFACE_TYPE,
            surface
                .iter()
                .map(|&s| {
                    let k = usize::try_from(s)
                        .ok()
                        .and_then(|s| kinds.get(s))
                        .copied()
                        .unwrap_or(SurfaceType::Other);
                    f64::from(k.code())
                })
                .collect(),
        ),
        Attribute::flag(attr::OUTLIER, surface.iter().map(|&s| s < 0)),
    ]
}

/// The curves as a line set: every curve's polyline points, one edge per polyline segment
/// (closed curves get their closing edge), with the edge and point attributes `curve_kind`
/// (U8: 0 sharp, 1 smooth, 2 boundary) and `curve` (I32 index in `curves`). `polylines` is left
/// empty so that each segment appears once.
pub(crate) fn curves_geometry(curves: &[FeatureCurve]) -> Geometry {
    let mut positions = Vec::new();
    let mut pkind = Vec::new();
    let mut pcurve = Vec::new();
    let mut edges = Vec::new();
    let mut ekind = Vec::new();
    let mut ecurve = Vec::new();
    for (ci, c) in curves.iter().enumerate() {
        let base = positions.len() as u32;
        let m = c.points.len() as u32;
        positions.extend_from_slice(&c.points);
        pkind.extend(std::iter::repeat_n(c.kind as u8 as f64, c.points.len()));
        pcurve.extend(std::iter::repeat_n(ci as f64, c.points.len()));
        let mut add_edge = |a: u32, b: u32| {
            edges.push([base + a, base + b]);
            ekind.push(c.kind as u8 as f64);
            ecurve.push(ci as f64);
        };
        for i in 1..m {
            add_edge(i - 1, i);
        }
        if c.closed && m > 2 {
            add_edge(m - 1, 0);
        }
    }
    let mut g = Geometry::from_cloud(PointCloud::from_positions(positions));
    let kind_attr = |values| Attribute {
        name: "curve_kind".into(),
        kind: ScalarKind::U8,
        values,
    };
    let curve_attr = |values| Attribute {
        name: "curve".into(),
        kind: ScalarKind::I32,
        values,
    };
    let n = g.points.len();
    let ne = edges.len();
    // Lengths match by construction.
    let _ = g.points.attributes.insert(n, kind_attr(pkind));
    let _ = g.points.attributes.insert(n, curve_attr(pcurve));
    g.edges = edges;
    let _ = g.edge_attributes.insert(ne, kind_attr(ekind));
    let _ = g.edge_attributes.insert(ne, curve_attr(ecurve));
    g
}

/// Summary of the ground truth as JSON (surfaces, curves, counts).
pub(crate) fn ground_truth_json(
    shape: &Shape,
    cloud: &PointCloud,
    surfaces: &[Surface],
    curves: &[FeatureCurve],
    extra: serde_json::Value,
) -> serde_json::Value {
    let count_flag = |name: &str| {
        cloud
            .attribute(name)
            .map_or(0, |a| a.values.iter().filter(|&&v| v != 0.0).count())
    };
    let mut per_surface = vec![0usize; surfaces.len()];
    if let Some(a) = cloud.attribute(attr::SURFACE) {
        for &v in &a.values {
            if v >= 0.0 {
                if let Some(c) = per_surface.get_mut(v as usize) {
                    *c += 1;
                }
            }
        }
    }
    let surfaces_json: Vec<_> = surfaces
        .iter()
        .zip(&per_surface)
        .map(|(s, &count)| {
            json!({
                "id": s.id,
                "type": s.kind.name(),
                "type_code": s.kind.code(),
                "params": s.params,
                "area": s.area,
                "points": count,
            })
        })
        .collect();
    let curves_json: Vec<_> = curves
        .iter()
        .enumerate()
        .map(|(i, c)| {
            json!({
                "id": i,
                "kind": c.kind.name(),
                "closed": c.closed,
                "length": c.length,
                "polyline_points": c.points.len(),
                "geometry": c.geometry,
            })
        })
        .collect();
    let length_of = |k: CurveKind| -> f64 {
        curves
            .iter()
            .filter(|c| c.kind == k)
            .map(|c| c.length)
            .sum()
    };
    let bbox = shape.aabb();
    json!({
        "shape": shape.name(),
        "shape_params": format!("{shape:?}"),
        "bbox": bbox,
        "points": cloud.len(),
        "total_area": surfaces.iter().map(|s| s.area).sum::<f64>(),
        "surfaces": surfaces_json,
        "curves": curves_json,
        "sharp_curves": curves.iter().filter(|c| c.kind == CurveKind::Sharp).count(),
        "smooth_curves": curves.iter().filter(|c| c.kind == CurveKind::Smooth).count(),
        "boundary_curves": curves.iter().filter(|c| c.kind == CurveKind::Boundary).count(),
        "sharp_length": length_of(CurveKind::Sharp),
        "smooth_length": length_of(CurveKind::Smooth),
        "boundary_length": length_of(CurveKind::Boundary),
        "counts": {
            "sharp": count_flag(attr::SHARP),
            "smooth": count_flag(attr::SMOOTH),
            "outliers": count_flag(attr::OUTLIER),
        },
        "details": extra,
    })
}

impl SyntheticPart {
    /// The feature curves as a line set (see the module docs of `synth`): points on the
    /// curves, one edge per polyline segment, edge / point attributes `curve_kind` (U8: 0 sharp,
    /// 1 smooth, 2 boundary) and `curve` (I32 curve index).
    pub fn curves_geometry(&self) -> Geometry {
        curves_geometry(&self.curves)
    }

    /// A JSON summary: shape, surfaces with parameters, exact areas and point counts, curves
    /// (kind, exact geometry, length), spacing, tolerance, noise, label counts.
    pub fn ground_truth_json(&self) -> serde_json::Value {
        ground_truth_json(
            &self.shape,
            &self.cloud,
            &self.surfaces,
            &self.curves,
            json!({
                "spacing": self.spacing,
                "sharp_tolerance": self.sharp_tolerance,
                "noise_sigma": self.noise_sigma,
            }),
        )
    }
}

impl super::SyntheticMesh {
    /// A JSON summary like [`SyntheticPart::ground_truth_json`], for the mesh of `shape`:
    /// surfaces with parameters and vertex counts, curves, the numbers of exact sharp / smooth
    /// mesh edges, the mean edge length and the label tolerance.
    pub fn ground_truth_json(&self, shape: &Shape) -> serde_json::Value {
        ground_truth_json(
            shape,
            &self.mesh.vertices,
            &self.surfaces,
            &self.curves,
            json!({
                "faces": self.mesh.faces.len(),
                "sharp_edges": self.sharp_edges.len(),
                "smooth_edges": self.smooth_edges.len(),
                "mean_edge": self.mean_edge,
                "sharp_tolerance": self.sharp_tolerance,
            }),
        )
    }
}
