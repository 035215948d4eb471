//! `crease._crease`: the native part of the `crease` Python package.
//!
//! Each function mirrors one CLI command (`crates/crease-cli/src/commands/*.rs`): the same
//! library calls with the same parameters and defaults, so that it gives the same answers bit
//! for bit, on numpy arrays instead of files. The arrays are checked and copied into the
//! library's types while the GIL is held; the computation runs with the GIL released
//! (`Python::detach`); results come back as numpy arrays (the library's vectors handed over
//! without a copy where their layout allows) and dicts (the structures the CLI prints with
//! `--json`, through their serde form). Errors become Python exceptions (see
//! [`convert::to_py_err`]); a panic becomes a `RuntimeError`, never an unwind into Python.
//!
//! The Python layer (`crease/__init__.py`) accepts Open3D / trimesh objects, coerces arrays to
//! float64 / int64, wraps the dicts in result classes and documents the functions.

mod convert;
mod tiled;

use std::path::PathBuf;
use std::time::Instant;

use numpy::{PyArrayMethods, PyReadonlyArray1, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crease::analysis::{AnalysisParams, CloudAnalysis};
use crease::estimate::bezier::{bezier_curvature, BezierParams};
use crease::estimate::curvature::{quadric_curvature_of, QuadricParams};
use crease::estimate::{self, PcaParams, Weighting};
use crease::fillets::{
    curve_network, extract_fillets, FilletParams, Label, Search, ThresholdCount,
};
use crease::geometry::{names, MeshTopology, PointCloud, TriMesh};
use crease::io::{Geometry, ReadOptions, WriteOptions};
use crease::lines::{extract_lines, LinesParams};
use crease::meshfeat::{detect_edges, feature_polylines, EdgeMethod, EdgeParams};
use crease::network::{network_of_points, NetworkSummary};
use crease::segment::{segment_mesh, segment_points, PointParams, SegmentParams};
use crease::sharp::{detect, detect_mesh, Measure, SharpParams, ThresholdRule};

use convert::{
    attribute_of, attributes_dict, check_shape, compute, faces_of, index_array, json_to_py,
    opt_points, points_array, points_of, polylines, to_py, to_py_err, value_error, vec_array,
    Faces, Points,
};

/// Positions and, when given, triangles, in the library's types.
type Shape = (Vec<[f64; 3]>, Option<Vec<[u32; 3]>>);

/// Points (and triangles, when given) checked as the CLI's `load_shape` checks a file.
fn shape_input(points: &Points<'_>, faces: Option<&Faces<'_>>) -> PyResult<Shape> {
    let p = points_of("points", points)?;
    let f = faces.map(|f| faces_of(f, p.len())).transpose()?;
    check_shape(&p)?;
    Ok((p, f))
}

/// Reads a point cloud or mesh file: a dict of numpy arrays (see `crease.read`).
#[pyfunction]
#[pyo3(signature = (path, strict = false))]
fn read<'py>(py: Python<'py>, path: PathBuf, strict: bool) -> PyResult<Bound<'py, PyDict>> {
    let (geom, report) = compute(py, || crease::io::read(&path, &ReadOptions { strict }))?;
    let d = PyDict::new(py);
    let Geometry {
        points,
        faces,
        face_attributes,
        edges,
        edge_attributes,
        polylines,
        polyline_groups,
    } = geom;
    let PointCloud {
        positions,
        normals,
        colors,
        attributes,
    } = points;
    d.set_item("attributes", attributes_dict(py, &attributes)?)?;
    d.set_item("points", points_array(py, positions)?)?;
    d.set_item("normals", normals.map(|n| points_array(py, n)).transpose()?)?;
    d.set_item(
        "colors",
        colors
            .map(|c| {
                let n = c.len();
                numpy::PyArray1::from_vec(py, c.into_flattened()).reshape([n, 3])
            })
            .transpose()?,
    )?;
    d.set_item(
        "faces",
        (!faces.is_empty())
            .then(|| index_array(py, &faces))
            .transpose()?,
    )?;
    d.set_item("face_attributes", attributes_dict(py, &face_attributes)?)?;
    d.set_item(
        "edges",
        (!edges.is_empty())
            .then(|| index_array(py, &edges))
            .transpose()?,
    )?;
    d.set_item("edge_attributes", attributes_dict(py, &edge_attributes)?)?;
    let lines = PyList::empty(py);
    for l in polylines {
        lines.append(vec_array(
            py,
            l.into_iter().map(i64::from).collect::<Vec<i64>>(),
        ))?;
    }
    d.set_item("polylines", lines)?;
    d.set_item("polyline_groups", polyline_groups)?;
    d.set_item("report", to_py(py, &report)?)?;
    Ok(d)
}

/// One attribute given to `write`: name, PLY kind name, values as float64.
type AttrArg<'py> = (String, String, PyReadonlyArray1<'py, f64>);

/// Writes points (and faces, normals, colours, attributes) to a file, the format chosen by its
/// extension, replacing it atomically as the CLI does.
#[pyfunction]
#[pyo3(signature = (path, points, normals = None, colors = None, faces = None, attributes = Vec::new(), face_attributes = Vec::new(), ascii = false))]
#[allow(clippy::too_many_arguments)]
fn write(
    py: Python<'_>,
    path: PathBuf,
    points: Points<'_>,
    normals: Option<Points<'_>>,
    colors: Option<numpy::PyReadonlyArray2<'_, u8>>,
    faces: Option<Faces<'_>>,
    attributes: Vec<AttrArg<'_>>,
    face_attributes: Vec<AttrArg<'_>>,
    ascii: bool,
) -> PyResult<()> {
    let positions = points_of("points", &points)?;
    let n = positions.len();
    let mut cloud = PointCloud::from_positions(positions);
    if let Some(nr) = opt_points("normals", normals.as_ref())? {
        cloud.set_normals(nr).map_err(|e| to_py_err(py, e))?;
    }
    if let Some(c) = colors {
        let shape = c.shape();
        if shape[1] != 3 {
            return Err(value_error(format!(
                "colors: expected an (n, 3) uint8 array, got shape ({}, {})",
                shape[0], shape[1]
            )));
        }
        let rows: Vec<[u8; 3]> = c
            .as_array()
            .rows()
            .into_iter()
            .map(|r| [r[0], r[1], r[2]])
            .collect();
        cloud.set_colors(rows).map_err(|e| to_py_err(py, e))?;
    }
    for (name, kind, values) in &attributes {
        let a = attribute_of(name.clone(), kind, values)?;
        cloud.set_attribute(a).map_err(|e| to_py_err(py, e))?;
    }
    let mut geom = Geometry::from_cloud(cloud);
    if let Some(f) = faces {
        geom.faces = faces_of(&f, n)?;
    }
    for (name, kind, values) in &face_attributes {
        let a = attribute_of(name.clone(), kind, values)?;
        geom.face_attributes
            .insert(geom.faces.len(), a)
            .map_err(|e| to_py_err(py, e))?;
    }
    compute(py, || {
        crease::io::write(&path, &geom, &WriteOptions { ascii })
    })
}

/// `crease normals`: normals per point (pca, ring) or mesh vertex (mesh), optionally oriented.
#[pyfunction]
#[pyo3(signature = (points, k = 20, method = "pca", orient = false, faces = None, weighting = "uniform"))]
fn normals<'py>(
    py: Python<'py>,
    points: Points<'py>,
    k: usize,
    method: &str,
    orient: bool,
    faces: Option<Faces<'py>>,
    weighting: &str,
) -> PyResult<Bound<'py, PyDict>> {
    #[derive(PartialEq, Clone, Copy)]
    enum M {
        Pca,
        Ring,
        Mesh,
    }
    let m = match method {
        "pca" => M::Pca,
        "ring" => M::Ring,
        "mesh" => M::Mesh,
        _ => {
            return Err(value_error(format!(
                "method must be one of pca, ring, mesh; got {method:?}"
            )))
        }
    };
    let weighting = match weighting {
        "uniform" => Weighting::Uniform,
        "area" => Weighting::Area,
        "angle" => Weighting::Angle,
        _ => {
            return Err(value_error(format!(
                "weighting must be one of uniform, area, angle; got {weighting:?}"
            )))
        }
    };
    if k == 0 && (m != M::Mesh || orient) {
        return Err(value_error("k must be at least 1"));
    }
    let (pos, faces) = shape_input(&points, faces.as_ref())?;
    if m == M::Mesh && faces.as_ref().is_none_or(|f| f.is_empty()) {
        return Err(value_error(
            "method 'mesh' needs a triangle mesh (faces), and none were given (use method 'pca')",
        ));
    }
    let needs_knn = m != M::Mesh || orient;
    let fused = m == M::Pca && !orient;
    let (normals, t_knn, t_normals, t_orient) = compute(py, move || {
        // As the CLI: exact duplicates estimated once, each copy given its original's normal.
        let distinct = if m == M::Mesh {
            None
        } else {
            crease::spatial::distinct_in_input_order(&pos)
        };
        let pts = distinct
            .as_ref()
            .map_or(pos.as_slice(), |d| d.points.as_slice());
        let t = Instant::now();
        let nbrs = if needs_knn && !fused {
            Some(crease::spatial::knn(pts, k)?)
        } else {
            None
        };
        let t_knn = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut normals = match (m, &nbrs) {
            (M::Pca, None) => {
                estimate::normals::pca_normals_direct(
                    pts,
                    &PcaParams {
                        k,
                        ..Default::default()
                    },
                )?
                .normals
            }
            (M::Pca, Some(nbrs)) => {
                estimate::pca_normals(
                    pts,
                    nbrs,
                    &PcaParams {
                        k,
                        ..Default::default()
                    },
                )?
                .normals
            }
            (M::Ring, Some(nbrs)) => {
                let rings =
                    crease::spatial::delaunay_rings(pts, nbrs, &crease::spatial::RingParams { k })?;
                estimate::ring_normals(pts, &rings)
            }
            (M::Ring, None) => {
                return Err(crease::Error::InvalidArgument(
                    "internal: no neighbourhoods for method ring".into(),
                ))
            }
            (M::Mesh, _) => {
                let mesh = TriMesh::new(pos.clone(), faces.unwrap_or_default())?;
                estimate::mesh_vertex_normals(&mesh, weighting)?
            }
        };
        let t_normals = t.elapsed().as_secs_f64();
        let t = Instant::now();
        if orient {
            if let Some(nbrs) = &nbrs {
                normals = estimate::orient_normals(pts, &normals, nbrs)?;
            }
        }
        if let Some(d) = &distinct {
            normals = d.expand(&normals);
        }
        Ok((normals, t_knn, t_normals, t.elapsed().as_secs_f64()))
    })?;
    let d = PyDict::new(py);
    d.set_item("normals", points_array(py, normals)?)?;
    let t = PyDict::new(py);
    t.set_item("knn", t_knn)?;
    t.set_item("normals", t_normals)?;
    t.set_item("orient", t_orient)?;
    d.set_item("timings", t)?;
    Ok(d)
}

/// `crease curvature`: principal curvatures per point by the quadric fit over the k nearest
/// neighbours (oriented by `normals` when given), or per mesh vertex by the two-pass Bézier fit
/// (`method = "bezier"`, with its sharp vertices).
#[pyfunction]
#[pyo3(signature = (points, k = 20, method = "quadric", normals = None, faces = None, sharp_threshold = None))]
fn curvature<'py>(
    py: Python<'py>,
    points: Points<'py>,
    k: usize,
    method: &str,
    normals: Option<Points<'py>>,
    faces: Option<Faces<'py>>,
    sharp_threshold: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let bezier = match method {
        "quadric" => false,
        "bezier" => true,
        _ => {
            return Err(value_error(format!(
                "method must be one of quadric, bezier; got {method:?}"
            )))
        }
    };
    if !bezier && k < 5 {
        return Err(value_error(format!(
            "k must be at least 5 for the quadric fit, got {k}"
        )));
    }
    let mut bp = BezierParams::default();
    if let Some(t) = sharp_threshold {
        if !(t > 0.0 && t.is_finite()) {
            return Err(value_error(format!(
                "sharp_threshold must be a positive number, got {t}"
            )));
        }
        bp.sharp_threshold = t;
    }
    let (pos, faces) = shape_input(&points, faces.as_ref())?;
    let given = opt_points("normals", normals.as_ref())?;
    if bezier && faces.as_ref().is_none_or(|f| f.is_empty()) {
        return Err(value_error(
            "the Bézier method needs a triangle mesh (faces), and none were given (use method \
             'quadric' for point clouds)",
        ));
    }
    if !bezier && pos.len() < k + 1 {
        return Err(value_error(format!(
            "{} points, the quadric fit with k = {k} needs at least {}",
            pos.len(),
            k + 1
        )));
    }
    let (c, sharp) = compute(py, move || {
        if bezier {
            let mesh = TriMesh::new(pos, faces.unwrap_or_default())?;
            let topo = MeshTopology::new(&mesh)?;
            let b = bezier_curvature(&mesh, &topo, &bp)?;
            Ok((b.curvature, Some(b.sharp)))
        } else {
            let c = quadric_curvature_of(&pos, given.as_deref(), &QuadricParams { k })?;
            Ok((c, None))
        }
    })?;
    let d = PyDict::new(py);
    d.set_item("failed", c.num_failed())?;
    d.set_item("k1", vec_array(py, c.k1))?;
    d.set_item("k2", vec_array(py, c.k2))?;
    d.set_item("mean_curvature", vec_array(py, c.mean))?;
    d.set_item("gaussian_curvature", vec_array(py, c.gaussian))?;
    d.set_item("sharp", sharp.map(|s| vec_array(py, s)))?;
    Ok(d)
}

/// `crease sharp`: sharp feature points of a cloud (or of a mesh's vertices when faces are
/// given).
#[pyfunction]
#[pyo3(signature = (points, faces = None, method = "projected-distance", scales = None, threshold = None, upper_quantile = None, raw = false, regularize = None, surfaces = true))]
#[allow(clippy::too_many_arguments)]
fn sharp<'py>(
    py: Python<'py>,
    points: Points<'py>,
    faces: Option<Faces<'py>>,
    method: &str,
    scales: Option<Vec<usize>>,
    threshold: Option<f64>,
    upper_quantile: Option<f64>,
    raw: bool,
    regularize: Option<f64>,
    surfaces: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let measure = match method {
        "projected-distance" => Measure::ProjectedDistance,
        "normal-variation" => Measure::NormalVariation,
        "mean-curvature" => Measure::MeanCurvature,
        "surface-variation" => Measure::SurfaceVariation,
        _ => {
            return Err(value_error(format!(
                "method must be one of projected-distance, normal-variation, mean-curvature, \
                 surface-variation; got {method:?}"
            )))
        }
    };
    let mut params = SharpParams {
        measure,
        scales: scales.filter(|s| !s.is_empty()),
        threshold: threshold.map_or(ThresholdRule::Otsu, ThresholdRule::Manual),
        density_invariant: !raw,
        ..Default::default()
    };
    if !surfaces {
        params.surfaces = None;
    }
    params.otsu.upper_quantile =
        upper_quantile.unwrap_or(SharpParams::default().otsu.upper_quantile);
    if let Some(lambda) = regularize {
        params.regularize = Some(crease::sharp::Regularize {
            lambda,
            ..Default::default()
        });
    }
    params.validate().map_err(|e| to_py_err(py, e))?;
    let (pos, faces) = shape_input(&points, faces.as_ref())?;
    let n = pos.len();
    let on_mesh = faces.as_ref().is_some_and(|f| !f.is_empty());
    let ap = crease::sharp::analysis_params(&params).map_err(|e| to_py_err(py, e))?;
    let kmax = ap.max_k;
    if !on_mesh && n < kmax + 1 {
        return Err(value_error(format!(
            "{n} points, sharp features at k = {kmax} need at least {}",
            kmax + 1
        )));
    }
    let (result, seconds, knn_seconds) = compute(py, move || {
        let start = Instant::now();
        let mut knn_seconds = None;
        let result = if on_mesh {
            let mesh = TriMesh::new(pos, faces.unwrap_or_default())?;
            detect_mesh(&mesh, &params)?
        } else {
            // As the CLI: the analysis (distinct points in Morton order), its neighbour
            // lists timed apart, then the detection.
            let t = Instant::now();
            let analysis = CloudAnalysis::new(&pos, ap)?;
            analysis.neighbours()?;
            knn_seconds = Some(t.elapsed().as_secs_f64());
            detect(&analysis, &params)?
        };
        Ok((result, start.elapsed().as_secs_f64(), knn_seconds))
    })?;
    let d = PyDict::new(py);
    d.set_item("mesh", on_mesh)?;
    d.set_item("method", measure.name())?;
    d.set_item("scales", to_py(py, &result.scales)?)?;
    d.set_item("noise_ratio", result.noise_ratio)?;
    d.set_item("regularized", result.regularized)?;
    d.set_item("surfaces", to_py(py, &result.surfaces)?)?;
    d.set_item("seconds", seconds)?;
    let t = PyDict::new(py);
    t.set_item("knn", knn_seconds)?;
    t.set_item("detection", seconds - knn_seconds.unwrap_or(0.0))?;
    d.set_item("timings", t)?;
    d.set_item("sharp", vec_array(py, result.sharp))?;
    d.set_item("sharpness", vec_array(py, result.sharpness))?;
    Ok(d)
}

/// `crease segment`: planes, cylinders, cones, spheres and tori of a cloud (per point) or a
/// mesh (per face).
#[pyfunction]
#[pyo3(signature = (points, normals = None, faces = None, distance_tolerance = 0.5, angle_tolerance = 8.0, k = 8))]
fn segment<'py>(
    py: Python<'py>,
    points: Points<'py>,
    normals: Option<Points<'py>>,
    faces: Option<Faces<'py>>,
    distance_tolerance: f64,
    angle_tolerance: f64,
    k: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let params = SegmentParams {
        th_pos: distance_tolerance,
        th_norm_degrees: angle_tolerance,
        ..Default::default()
    };
    params.validate().map_err(|e| to_py_err(py, e))?;
    let pp = PointParams {
        k,
        ..Default::default()
    };
    pp.validate().map_err(|e| to_py_err(py, e))?;
    let (pos, faces) = shape_input(&points, faces.as_ref())?;
    let given = opt_points("normals", normals.as_ref())?;
    if let Some(g) = &given {
        if g.len() != pos.len() {
            return Err(value_error(format!(
                "normals: {} rows for {} points",
                g.len(),
                pos.len()
            )));
        }
    }
    let on_mesh = faces.as_ref().is_some_and(|f| !f.is_empty());
    let d = PyDict::new(py);
    d.set_item("mesh", on_mesh)?;
    if on_mesh {
        let (seg, seconds) = compute(py, move || {
            let start = Instant::now();
            let mesh = TriMesh::new(pos, faces.unwrap_or_default())?;
            let topo = MeshTopology::new(&mesh)?;
            let seg = segment_mesh(&mesh, &topo, &params)?;
            Ok((seg, start.elapsed().as_secs_f64()))
        })?;
        d.set_item("labels", vec_array(py, seg.face_surface.clone()))?;
        d.set_item("types", vec_array(py, seg.face_types()))?;
        d.set_item("vertex_labels", vec_array(py, seg.vertex_surface.clone()))?;
        d.set_item("surfaces", to_py(py, &seg.surfaces)?)?;
        d.set_item("groups", to_py(py, &seg.groups)?)?;
        d.set_item("mean_edge", seg.mean_edge)?;
        d.set_item("epsilon", seg.epsilon)?;
        d.set_item("seeds", seg.seeds)?;
        d.set_item("timings", to_py(py, &timings_map(&seg.timings))?)?;
        d.set_item("seconds", seconds)?;
    } else {
        let (seg, seconds) = compute(py, move || {
            let start = Instant::now();
            let seg = segment_points(&pos, given.as_deref(), &params, &pp)?;
            Ok((seg, start.elapsed().as_secs_f64()))
        })?;
        d.set_item("labels", vec_array(py, seg.point_surface.clone()))?;
        d.set_item("types", vec_array(py, seg.point_types()))?;
        d.set_item("surfaces", to_py(py, &seg.surfaces)?)?;
        d.set_item("groups", to_py(py, &seg.groups)?)?;
        d.set_item("mean_edge", seg.mean_edge)?;
        d.set_item("epsilon", seg.epsilon)?;
        d.set_item("seeds", seg.seeds)?;
        d.set_item(
            "normals_source",
            if seg.normals_given {
                "given"
            } else {
                "estimated"
            },
        )?;
        d.set_item("timings", to_py(py, &timings_map(&seg.timings))?)?;
        d.set_item("seconds", seconds)?;
    }
    Ok(d)
}

/// Stage timings as a name -> seconds map (as the CLI's `--json`).
fn timings_map(t: &[(&'static str, f64)]) -> serde_json::Map<String, serde_json::Value> {
    t.iter()
        .map(|(k, v)| (k.to_string(), serde_json::Value::from(*v)))
        .collect()
}

/// `crease lines`: closed sharp feature lines of a cloud.
#[pyfunction]
#[pyo3(signature = (points, k = 20, region_angle = 8.0, spur_length = 5, denoise = true, close_candidates = None, close_path = None, boundary = true, smooth = true))]
#[allow(clippy::too_many_arguments)]
fn lines<'py>(
    py: Python<'py>,
    points: Points<'py>,
    k: usize,
    region_angle: f64,
    spur_length: usize,
    denoise: bool,
    close_candidates: Option<usize>,
    close_path: Option<usize>,
    boundary: bool,
    smooth: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let params = LinesParams {
        k,
        alpha_max_degrees: region_angle,
        d_max: spur_length,
        n: close_candidates,
        d: close_path,
        smooth,
        boundary,
        denoise_normals: denoise,
    };
    params.validate().map_err(|e| to_py_err(py, e))?;
    let (pos, _) = shape_input(&points, None)?;
    let n_points = pos.len();
    if n_points < k + 1 {
        return Err(value_error(format!(
            "{n_points} points, sharp lines with -k {k} need at least {}",
            k + 1
        )));
    }
    let (net, seconds) = compute(py, move || {
        let start = Instant::now();
        let net = extract_lines(&pos, &params)?;
        Ok((net, start.elapsed().as_secs_f64()))
    })?;
    let d = PyDict::new(py);
    let (lines, idx) = polylines(py, &net.vertices, &net.polylines)?;
    d.set_item("polylines", lines)?;
    d.set_item("indices", idx)?;
    d.set_item("groups", net.groups())?;
    d.set_item("clusters", vec_array(py, net.segmentation.labels.clone()))?;
    let s = serde_json::json!({
        "clusters": net.segmentation.num_clusters(),
        "small_clusters": net.small_clusters,
        "boundary_points": net.boundary_points,
        "stages": net.stages,
        "close": net.close,
        "n": net.n, "d": net.d,
        "polylines": net.polylines.len(),
        "closed_loops": net.closed_loops(),
        "junctions": net.junctions(),
        "endpoints": net.endpoints(),
        "seconds": seconds,
    });
    d.set_item("summary", json_to_py(py, &s)?)?;
    d.set_item("vertices", points_array(py, net.vertices)?)?;
    Ok(d)
}

/// `crease fillets` (`network` false) and `crease network` (`network` true).
#[pyfunction]
#[pyo3(signature = (points, network, k = 20, region_angle = 8.0, spur_length = 5, curvature_k = 20, smoothing = 0, median = 1, trim = 0.005, bins = 50, one_run = false, thresholds = None, max_thresholds = 4, tau = None, coarse_retry = false, boundary = true, lines_from = "surfaces"))]
#[allow(clippy::too_many_arguments)]
fn fillets<'py>(
    py: Python<'py>,
    points: Points<'py>,
    network: bool,
    k: usize,
    region_angle: f64,
    spur_length: usize,
    curvature_k: usize,
    smoothing: usize,
    median: usize,
    trim: f64,
    bins: usize,
    one_run: bool,
    thresholds: Option<usize>,
    max_thresholds: usize,
    tau: Option<Vec<f64>>,
    coarse_retry: bool,
    boundary: bool,
    lines_from: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let anchored = match lines_from {
        "surfaces" => network,
        "points" => false,
        other => {
            return Err(value_error(format!(
                "lines_from must be 'surfaces' or 'points', got {other:?}"
            )))
        }
    };
    let thresholds = match (tau, thresholds) {
        (Some(t), _) if !t.is_empty() => {
            if t.iter().any(|t| *t < 0.0) {
                return Err(value_error("tau values must be non-negative"));
            }
            ThresholdCount::Manual(t)
        }
        (_, Some(n)) => ThresholdCount::Exactly(n),
        _ => ThresholdCount::Auto {
            max: max_thresholds,
        },
    };
    let params = FilletParams {
        lines: LinesParams {
            k,
            alpha_max_degrees: region_angle,
            d_max: spur_length,
            boundary,
            ..Default::default()
        },
        curvature_k,
        smoothing_iterations: smoothing,
        median_iterations: median,
        trim,
        bins,
        search: if one_run {
            Search::OneRun
        } else {
            Search::Full
        },
        thresholds,
        coarse_retry,
        ..Default::default()
    };
    params.validate().map_err(|e| to_py_err(py, e))?;
    let (pos, _) = shape_input(&points, None)?;
    let n_points = pos.len();
    let need = k.max(curvature_k) + 1;
    if n_points < need {
        return Err(value_error(format!(
            "{n_points} points, fillet lines need at least {need}"
        )));
    }
    let (f, net, seconds) = compute(py, move || {
        let start = Instant::now();
        if anchored {
            // As `crease network` (with `--labels`): the lines anchored on the surfaces.
            let r = network_of_points(&pos, &params, true)?;
            let seconds = start.elapsed().as_secs_f64();
            let f = r.fillets.ok_or_else(|| {
                crease::Error::InvalidArgument(
                    "network: the fillet labels were not computed".into(),
                )
            })?;
            return Ok((f, Some((r.network, r.summary)), seconds));
        }
        let f = extract_fillets(&pos, &params, network)?;
        let seconds = start.elapsed().as_secs_f64();
        let net = network.then(|| {
            let net = curve_network(&f);
            let s = NetworkSummary::new(&net, 0, Some("asked for lines from points".into()));
            (net, s)
        });
        Ok((f, net, seconds))
    })?;
    let d = PyDict::new(py);
    let mut summary = serde_json::json!({
        "smooth_regions": f.regions.len(),
        "regions": f.regions,
        "border_points": f.label.iter().filter(|l| **l == Some(Label::Border)).count(),
        "polylines": f.lines.polylines.len(),
        "closed_loops": f.lines.closed_loops(),
        "junctions": f.lines.junctions(),
        "endpoints": f.lines.endpoints(),
        "sharp_stages": f.sharp.as_ref().map(|s| &s.stages),
        "timing": f.seconds,
        "seconds": seconds,
    });
    if let Some((net, counts)) = net {
        let (lines, idx) = polylines(py, &net.vertices, &net.polylines)?;
        d.set_item("polylines", lines)?;
        d.set_item("indices", idx)?;
        d.set_item("groups", net.groups())?;
        summary["network"] =
            serde_json::to_value(&counts).map_err(|e| value_error(e.to_string()))?;
        d.set_item("vertices", points_array(py, net.vertices)?)?;
    } else {
        let (lines, idx) = polylines(py, &f.lines.vertices, &f.lines.polylines)?;
        d.set_item("polylines", lines)?;
        d.set_item("indices", idx)?;
        d.set_item("groups", vec!["smooth"; f.lines.polylines.len()])?;
        d.set_item("vertices", points_array(py, f.lines.vertices.clone())?)?;
    }
    // The per-point labels of `--labels`.
    let code = |l: Option<Label>| l.map_or(255u8, |l| l as u8);
    d.set_item(
        "fillet_label",
        vec_array(py, f.label.iter().map(|&l| code(l)).collect::<Vec<u8>>()),
    )?;
    d.set_item(
        "smooth_edge",
        vec_array(
            py,
            f.label
                .iter()
                .map(|&l| l == Some(Label::Border))
                .collect::<Vec<bool>>(),
        ),
    )?;
    d.set_item("patch", vec_array(py, f.patch.clone()))?;
    d.set_item(
        "region",
        vec_array(
            py,
            f.region
                .iter()
                .map(|&r| if r == u32::MAX { -1 } else { i64::from(r) })
                .collect::<Vec<i64>>(),
        ),
    )?;
    d.set_item("mean_curvature", vec_array(py, f.curvature.clone()))?;
    d.set_item("summary", json_to_py(py, &summary)?)?;
    Ok(d)
}

/// The `--method` names of `crease edges`.
fn edge_method(name: &str) -> PyResult<EdgeMethod> {
    Ok(match name {
        "dihedral" => EdgeMethod::Dihedral,
        "hysteresis" => EdgeMethod::Hysteresis,
        "tangent" => EdgeMethod::Tangent,
        "potts-dihedral" => EdgeMethod::PottsDihedral,
        "potts-tangent" => EdgeMethod::PottsTangent,
        "learned" => EdgeMethod::Learned,
        "potts-learned" => EdgeMethod::PottsLearned,
        "filtered" => EdgeMethod::Filtered,
        "potts-filtered" => EdgeMethod::PottsFiltered,
        "fused" => EdgeMethod::Fused,
        _ => {
            return Err(value_error(format!(
                "method must be one of dihedral, hysteresis, tangent, potts-dihedral, \
                 potts-tangent, learned, potts-learned, filtered, potts-filtered, fused; got \
                 {name:?}"
            )))
        }
    })
}

/// `crease edges`: feature edges of a triangle mesh.
#[pyfunction]
#[pyo3(signature = (vertices, faces, method = "fused", threshold = None, scales = None, mu = None, model = None, bias = None))]
#[allow(clippy::too_many_arguments)]
fn edges<'py>(
    py: Python<'py>,
    vertices: Points<'py>,
    faces: Faces<'py>,
    method: &str,
    threshold: Option<f64>,
    scales: Option<Vec<f64>>,
    mu: Option<f64>,
    model: Option<PathBuf>,
    bias: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut params = EdgeParams {
        method: edge_method(method)?,
        ..EdgeParams::default()
    };
    if let Some(t) = threshold {
        if !(t.is_finite() && t > 0.0 && t < 180.0) {
            return Err(value_error(format!(
                "threshold must be in (0, 180) degrees, got {t}"
            )));
        }
        params.threshold_degrees = t;
        params.potts.theta_true = t.to_radians();
        params.filtered_degrees = t;
    }
    if let Some(scales) = scales.filter(|s| !s.is_empty()) {
        if let Some(s) = scales.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
            return Err(value_error(format!("scales must be positive, got {s}")));
        }
        params.tangent.scales = scales;
    }
    if let Some(mu) = mu {
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(value_error(format!("mu must be finite and >= 0, got {mu}")));
        }
        params.potts.mu = mu;
    }
    if let Some(b) = bias {
        if !b.is_finite() {
            return Err(value_error(format!("bias must be finite, got {b}")));
        }
        params.decision_bias = b;
    }
    if let Some(path) = &model {
        if !params.method.uses_model() {
            return Err(value_error(format!(
                "model is used by the learned methods, not by method {}",
                params.method.name()
            )));
        }
        let m = compute(py, || crease::meshfeat::SvmModel::read(path))?;
        params.model = Some(std::sync::Arc::new(m));
    }
    let (pos, faces) = shape_input(&vertices, Some(&faces))?;
    let faces = faces.unwrap_or_default();
    if faces.is_empty() {
        return Err(value_error("no faces; feature edges need a triangle mesh"));
    }
    let method_name = params.method.name();
    let (edges, sharp, sharpness, lines, flipped, boundary, timings, seconds) =
        compute(py, move || {
            let start = Instant::now();
            let mesh = TriMesh::new(pos, faces)?;
            let (em, det) = detect_edges(&mesh, &params)?;
            let seconds = start.elapsed().as_secs_f64();
            let lines = feature_polylines(&em.topo, &det.sharp);
            Ok((
                em.topo.edges().to_vec(),
                det.sharp,
                det.sharpness,
                lines,
                em.flipped_faces,
                em.topo.boundary_edges().len(),
                det.timings,
                seconds,
            ))
        })?;
    let d = PyDict::new(py);
    d.set_item("method", method_name)?;
    d.set_item("edges", index_array(py, &edges)?)?;
    d.set_item("sharp", vec_array(py, sharp))?;
    d.set_item("sharpness", vec_array(py, sharpness))?;
    let line_list = PyList::empty(py);
    for l in lines {
        line_list.append(vec_array(
            py,
            l.into_iter().map(i64::from).collect::<Vec<i64>>(),
        ))?;
    }
    d.set_item("lines", line_list)?;
    d.set_item("flipped_faces", flipped)?;
    d.set_item("boundary_edges", boundary)?;
    d.set_item("timings", to_py(py, &timings)?)?;
    d.set_item("seconds", seconds)?;
    Ok(d)
}

/// `crease reconstruct`: the part as a B-rep, its STEP text (written to `out` when given).
#[pyfunction]
#[pyo3(signature = (points, faces = None, normals = None, out = None, name = "part", units = "mm", distance_tolerance = 0.5, angle_tolerance = 8.0, topology = None, mesh = None))]
#[allow(clippy::too_many_arguments)]
fn reconstruct<'py>(
    py: Python<'py>,
    points: Points<'py>,
    faces: Option<Faces<'py>>,
    normals: Option<Points<'py>>,
    out: Option<PathBuf>,
    name: &str,
    units: &str,
    distance_tolerance: f64,
    angle_tolerance: f64,
    topology: Option<PathBuf>,
    mesh: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let unit: crease::brep::LengthUnit = units.parse().map_err(value_error)?;
    let params = SegmentParams {
        th_pos: distance_tolerance,
        th_norm_degrees: angle_tolerance,
        ..Default::default()
    };
    params.validate().map_err(|e| to_py_err(py, e))?;
    let (pos, faces) = shape_input(&points, faces.as_ref())?;
    let given = opt_points("normals", normals.as_ref())?;
    if let Some(ext) = out.as_ref().map(|o| {
        o.extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
    }) {
        if !matches!(ext.as_deref(), Some("step" | "stp")) {
            return Err(value_error(format!(
                "{}: the output must be a STEP file (.step or .stp)",
                out.as_ref()
                    .map(|o| o.display().to_string())
                    .unwrap_or_default()
            )));
        }
    }
    let name = name.to_string();
    let (text, topo_json, report, solid, nfaces, nedges, uncertainty, seconds) =
        compute(py, move || {
            let start = Instant::now();
            let on_mesh = faces.as_ref().is_some_and(|f| !f.is_empty());
            let rec = if on_mesh {
                let m = TriMesh::new(pos, faces.unwrap_or_default())?;
                crease::brep::reconstruct_mesh(&m, &params)?
            } else {
                let analysis = AnalysisParams {
                    segment: params,
                    ..Default::default()
                };
                crease::brep::reconstruct_points(&pos, given.as_deref(), analysis)?
            };
            let uncertainty = rec.uncertainty();
            let text = rec.to_step(&name, unit);
            if let Some(o) = &out {
                write_text(o, &text)?;
            }
            let topo_json = serde_json::to_string_pretty(&rec.brep)
                .map_err(|e| crease::Error::InvalidInput(format!("B-rep as JSON: {e}")))?
                + "\n";
            if let Some(p) = &topology {
                write_text(p, &topo_json)?;
            }
            if let Some(p) = &mesh {
                let g = Geometry::from_mesh(rec.tessellate()?);
                crease::io::write(p, &g, &WriteOptions::default())?;
            }
            let report = serde_json::to_value(&rec.report)
                .map_err(|e| crease::Error::InvalidInput(format!("report as JSON: {e}")))?;
            Ok((
                text,
                topo_json,
                report,
                rec.report.closed,
                rec.brep.faces.len(),
                rec.brep.edges.len(),
                uncertainty,
                start.elapsed().as_secs_f64(),
            ))
        })?;
    let d = PyDict::new(py);
    d.set_item("step", text)?;
    d.set_item("solid", solid)?;
    d.set_item("faces", nfaces)?;
    d.set_item("edges", nedges)?;
    d.set_item("report", json_to_py(py, &report)?)?;
    d.set_item("topology", topo_json)?;
    d.set_item("uncertainty", uncertainty)?;
    d.set_item("seconds", seconds)?;
    Ok(d)
}

/// `crease run` on arrays: the whole job from one shared analysis (`crease::pipeline`).
#[pyfunction]
#[pyo3(signature = (points, faces = None, name = "part", units = "mm"))]
fn run<'py>(
    py: Python<'py>,
    points: Points<'py>,
    faces: Option<Faces<'py>>,
    name: &str,
    units: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let unit: crease::brep::LengthUnit = units.parse().map_err(value_error)?;
    let (pos, faces) = shape_input(&points, faces.as_ref())?;
    let on_mesh = faces.as_ref().is_some_and(|f| !f.is_empty());
    let d = PyDict::new(py);
    d.set_item("mesh", on_mesh)?;
    let name = name.to_string();
    // The B-rep as the CLI writes it (its STEP text), or why there is none.
    let step = move |rec: &crease::Result<crease::brep::Reconstruction>| {
        rec.as_ref().map_err(|e| e.to_string()).map(|rec| {
            let report = serde_json::to_value(&rec.report).unwrap_or_default();
            (
                rec.to_step(&name, unit),
                report,
                rec.brep.faces.len(),
                rec.brep.edges.len(),
            )
        })
    };
    let start = Instant::now();
    let brep = if on_mesh {
        let (r, brep, positions) = compute(py, move || {
            let mesh = TriMesh::new(pos, faces.unwrap_or_default())?;
            let r = crease::pipeline::run_mesh(&mesh, |_| {})?;
            let brep = step(&r.brep);
            Ok((r, brep, mesh.vertices.positions))
        })?;
        let seg = &r.segmentation;
        d.set_item("edges", index_array(py, &r.edges)?)?;
        d.set_item("sharp", vec_array(py, r.detection.sharp.clone()))?;
        d.set_item("sharpness", vec_array(py, r.detection.sharpness.clone()))?;
        d.set_item("labels", vec_array(py, seg.face_surface.clone()))?;
        d.set_item("types", vec_array(py, seg.face_types()))?;
        d.set_item("surfaces", to_py(py, &seg.surfaces)?)?;
        d.set_item("surface_groups", to_py(py, &seg.groups)?)?;
        let (lines, idx) = polylines(py, &positions, &r.polylines)?;
        d.set_item("polylines", lines)?;
        d.set_item("polyline_indices", idx)?;
        d.set_item("polyline_groups", vec![names::SHARP; r.polylines.len()])?;
        d.set_item("polyline_vertices", points_array(py, positions)?)?;
        d.set_item("timings", to_py(py, &timings_map(&r.timings))?)?;
        brep
    } else {
        let (r, brep) = compute(py, move || {
            let analysis = CloudAnalysis::new(&pos, AnalysisParams::default())?;
            let r = crease::pipeline::run_cloud(&analysis, |_| {})?;
            let brep = step(&r.brep);
            Ok((r, brep))
        })?;
        let net = &r.network;
        let code = |l: Option<Label>| l.map_or(255u8, |l| l as u8);
        d.set_item("sharp", vec_array(py, r.sharp.sharp.clone()))?;
        d.set_item("sharpness", vec_array(py, r.sharp.sharpness.clone()))?;
        d.set_item("noise_ratio", r.sharp.noise_ratio)?;
        d.set_item("regularized", r.sharp.regularized)?;
        d.set_item("labels", vec_array(py, r.surface.clone()))?;
        d.set_item("types", vec_array(py, r.surface_type.clone()))?;
        d.set_item(
            "fillet_label",
            vec_array(
                py,
                r.fillet_label.iter().map(|&l| code(l)).collect::<Vec<u8>>(),
            ),
        )?;
        d.set_item(
            "smooth_edge",
            vec_array(
                py,
                r.fillet_label
                    .iter()
                    .map(|&l| l == Some(Label::Border))
                    .collect::<Vec<bool>>(),
            ),
        )?;
        d.set_item("surfaces", to_py(py, &r.surfaces)?)?;
        d.set_item("surface_groups", to_py(py, &r.groups)?)?;
        let (lines, idx) = polylines(py, &net.vertices, &net.polylines)?;
        d.set_item("polylines", lines)?;
        d.set_item("polyline_indices", idx)?;
        d.set_item("polyline_groups", net.groups())?;
        d.set_item("polyline_vertices", points_array(py, net.vertices.clone())?)?;
        d.set_item("analysis", to_py(py, &r.counts)?)?;
        d.set_item("timings", to_py(py, &timings_map(&r.timings))?)?;
        brep
    };
    d.set_item("seconds", start.elapsed().as_secs_f64())?;
    match brep {
        Ok((text, report, faces, edges)) => {
            d.set_item("step", text)?;
            let b = serde_json::json!({
                "solid": report.get("closed").cloned().unwrap_or_default(),
                "faces": faces,
                "edges": edges,
                "report": report,
            });
            d.set_item("brep", json_to_py(py, &b)?)?;
        }
        Err(e) => {
            d.set_item("step", py.None())?;
            d.set_item("brep", json_to_py(py, &serde_json::json!({ "error": e }))?)?;
        }
    }
    Ok(d)
}

/// Runs one `crease` command line in this process (the CLI's own code, `crease_cli`), the GIL
/// released. `args` without the program name. Returns the exit code having printed what the
/// binary prints when `check` is false (the console command); raises `crease.CommandError`
/// with the CLI's message and exit code when `check` is true and the command fails.
#[pyfunction]
#[pyo3(signature = (args, check = true))]
fn command(py: Python<'_>, args: Vec<std::ffi::OsString>, check: bool) -> PyResult<u8> {
    let argv = std::iter::once(std::ffi::OsString::from("crease")).chain(args);
    let r = py.detach(|| {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(move || {
            if check {
                crease_cli::try_main_with_args(argv).map(|()| 0)
            } else {
                Ok(crease_cli::main_with_args(argv))
            }
        }))
    });
    match r {
        Ok(Ok(code)) => Ok(code),
        Ok(Err(f)) => Err(convert::command_error(py, f.code, f.message)),
        Err(_) => Err(pyo3::exceptions::PyRuntimeError::new_err(
            "internal error in crease (please report it): a panic in the command",
        )),
    }
}

/// Writes `text` to `path` atomically (the CLI's `ui::write_text`).
fn write_text(path: &std::path::Path, text: &str) -> crease::Result<()> {
    crease::io::atomic::replace(path, |tmp| {
        std::fs::write(tmp, text).map_err(|e| crease::Error::io(tmp, e))
    })
}

/// Sets the number of worker threads of every later call (the CLI's `--threads`); only before
/// the first computation.
#[pyfunction]
fn set_num_threads(n: usize) -> PyResult<()> {
    if n == 0 {
        return Err(value_error("the number of threads must be at least 1"));
    }
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    rayon::ThreadPoolBuilder::new()
        .num_threads(n.min(cores))
        .build_global()
        .map_err(|e| {
            pyo3::exceptions::PyRuntimeError::new_err(format!(
                "cannot set the number of threads (only before the first computation): {e}"
            ))
        })
}

/// The native module.
#[pymodule]
fn _crease(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(normals, m)?)?;
    m.add_function(wrap_pyfunction!(curvature, m)?)?;
    m.add_function(wrap_pyfunction!(sharp, m)?)?;
    m.add_function(wrap_pyfunction!(segment, m)?)?;
    m.add_function(wrap_pyfunction!(lines, m)?)?;
    m.add_function(wrap_pyfunction!(fillets, m)?)?;
    m.add_function(wrap_pyfunction!(edges, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct, m)?)?;
    m.add_function(wrap_pyfunction!(set_num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(run, m)?)?;
    m.add_function(wrap_pyfunction!(command, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::split_tiles, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::sample_spacing, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::halo_width, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::tile_noise, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::noise_ratio_of, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::tile_measures, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::tile_histograms, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::sharp_thresholds, m)?)?;
    m.add_function(wrap_pyfunction!(tiled::tile_labels, m)?)?;
    Ok(())
}
