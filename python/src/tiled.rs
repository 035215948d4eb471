//! The native passes of `crease.tiled_sharp` (`crease/_tiled.py`): the cut into tile files
//! (`crease::io::tiles`) and the four passes of `crease::sharp::tiled` on one tile file each,
//! so that a process pool or a dask cluster runs them as tasks. What a pass keeps for a later
//! one (the measures) goes to a cache file beside the tile; what merges across tiles (noise
//! samples, ranges, histograms) comes back to Python, which is small.

use std::path::{Path, PathBuf};

use numpy::{PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crease::geometry::{Attribute, Point3, PointCloud, ScalarKind};
use crease::io::tiles::{split, TileSpec};
use crease::io::{Geometry, ReadOptions, WriteOptions};
use crease::sharp::tiled::{self, Tile};
use crease::sharp::SharpParams;

use crate::convert::{compute, to_py, value_error};

/// The detector's settings of a tiled run: the CLI's defaults, `surfaces` false for
/// `--no-surfaces`.
fn params(surfaces: bool) -> SharpParams {
    SharpParams {
        surfaces: if surfaces {
            SharpParams::default().surfaces
        } else {
            None
        },
        ..Default::default()
    }
}

/// A tile file's points and core flags.
fn read_tile(path: &Path) -> crease::Result<(Vec<Point3>, Vec<bool>, Vec<f64>)> {
    let (geom, _) = crease::io::read(path, &ReadOptions::default())?;
    let attr = |name: &str| {
        geom.points
            .attribute(name)
            .map(|a| a.values.clone())
            .ok_or_else(|| {
                crease::Error::InvalidInput(format!(
                    "{}: not a tile (no `{name}` attribute)",
                    path.display()
                ))
            })
    };
    let core = attr("core")?.iter().map(|&c| c != 0.0).collect();
    let index = attr("index")?;
    Ok((geom.points.positions, core, index))
}

/// Cuts the cloud of `path` into tiles in `dir` (see `crease::io::tiles`).
#[pyfunction]
pub fn split_tiles<'py>(
    py: Python<'py>,
    path: PathBuf,
    dir: PathBuf,
    size: f64,
    halo: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let t = compute(py, move || split(&path, &dir, TileSpec { size, halo }))?;
    to_py(py, &t)
}

/// The average spacing of the first `limit` points of a file (LAS streamed; other formats are
/// read whole): what sizes the halo and the tiles.
#[pyfunction]
#[pyo3(signature = (path, limit = 1_000_000))]
pub fn sample_spacing(py: Python<'_>, path: PathBuf, limit: usize) -> PyResult<f64> {
    compute(py, move || {
        let mut pts: Vec<Point3> = Vec::new();
        let las = matches!(
            crease::io::Format::from_path(&path),
            Ok(crease::io::Format::Las)
        );
        if las {
            let stop = "enough points";
            let r = crease::io::las::for_each_position(&path, |b| {
                pts.extend(b.iter().take(limit - pts.len().min(limit)));
                if pts.len() >= limit {
                    Err(crease::Error::InvalidInput(stop.into()))
                } else {
                    Ok(())
                }
            });
            match r {
                Err(crease::Error::InvalidInput(m)) if m == stop => {}
                r => {
                    r?;
                }
            }
        } else {
            let (g, _) = crease::io::read(&path, &ReadOptions::default())?;
            pts = g.points.positions;
            pts.truncate(limit);
        }
        crease::spatial::spacing::average_spacing(&pts).ok_or_else(|| {
            crease::Error::InvalidInput(format!(
                "{}: too few distinct points to measure a spacing",
                path.display()
            ))
        })
    })
}

/// The halo a tiled run needs on a cloud of this spacing (`crease::sharp::tiled::halo_width`).
#[pyfunction]
pub fn halo_width(spacing: f64, surfaces: bool) -> f64 {
    tiled::halo_width(spacing, &params(surfaces))
}

/// Pass 1: the noise samples of a tile's core points, (m, 2).
#[pyfunction]
pub fn tile_noise<'py>(
    py: Python<'py>,
    tile: PathBuf,
    total: usize,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let s = compute(py, move || {
        let (p, core, _) = read_tile(&tile)?;
        tiled::tile_noise_samples(
            &Tile {
                points: &p,
                core: &core,
            },
            total,
        )
    })?;
    let flat: Vec<f64> = s.iter().flat_map(|&(a, b)| [a, b]).collect();
    numpy::PyArray1::from_vec(py, flat).reshape([s.len(), 2])
}

/// The cloud's noise ratio from all tiles' samples.
#[pyfunction]
pub fn noise_ratio_of(samples: PyReadonlyArray2<'_, f64>) -> PyResult<f64> {
    if samples.shape()[1] != 2 {
        return Err(value_error("noise samples must be an (m, 2) array"));
    }
    let a = samples.as_array();
    let mut s: Vec<(f64, f64)> = a.rows().into_iter().map(|r| (r[0], r[1])).collect();
    Ok(tiled::ratio_of_samples(&mut s))
}

/// Pass 2: the measures of a tile's points, kept in `cache` (little-endian f64, scale after
/// scale); returns each scale's range over the core points.
#[pyfunction]
pub fn tile_measures(
    py: Python<'_>,
    tile: PathBuf,
    cache: PathBuf,
    ratio: f64,
    surfaces: bool,
) -> PyResult<Vec<(f64, f64)>> {
    compute(py, move || {
        let (p, core, _) = read_tile(&tile)?;
        let m = tiled::tile_measures(
            &Tile {
                points: &p,
                core: &core,
            },
            ratio,
            &params(surfaces),
        )?;
        let bytes: Vec<u8> = m
            .values
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        crease::io::atomic::replace(&cache, |tmp| {
            std::fs::write(tmp, &bytes).map_err(|e| crease::Error::io(tmp, e))
        })?;
        Ok(m.ranges)
    })
}

/// The measures of pass 2 back from `cache`, for a tile of `n` points.
fn read_cache(cache: &Path, n: usize) -> crease::Result<Vec<Vec<f64>>> {
    let bytes = std::fs::read(cache).map_err(|e| crease::Error::io(cache, e))?;
    if n == 0 || bytes.len() % (8 * n) != 0 {
        return Err(crease::Error::format(
            cache,
            format!("{} bytes of measures for {n} points", bytes.len()),
        ));
    }
    let values: Vec<f64> = bytes
        .chunks_exact(8)
        .map(|b| {
            let mut a = [0u8; 8];
            a.copy_from_slice(b);
            f64::from_le_bytes(a)
        })
        .collect();
    Ok(values.chunks(n).map(<[f64]>::to_vec).collect())
}

/// Pass 3: per scale, the histogram of a tile's core values over the merged ranges.
#[pyfunction]
pub fn tile_histograms(
    py: Python<'_>,
    tile: PathBuf,
    cache: PathBuf,
    ranges: Vec<(f64, f64)>,
    surfaces: bool,
) -> PyResult<Vec<Vec<u64>>> {
    compute(py, move || {
        let (p, core, _) = read_tile(&tile)?;
        let values = read_cache(&cache, p.len())?;
        tiled::tile_histograms(
            &Tile {
                points: &p,
                core: &core,
            },
            &values,
            &ranges,
            &params(surfaces),
        )
    })
}

/// Each scale's threshold (T_s, normalised T_s) from the summed histograms and merged ranges.
#[pyfunction]
pub fn sharp_thresholds(
    py: Python<'_>,
    histograms: Vec<Vec<u64>>,
    ranges: Vec<(f64, f64)>,
    surfaces: bool,
) -> PyResult<Vec<(f64, f64)>> {
    compute(py, move || {
        tiled::thresholds(&[histograms], &ranges, &params(surfaces))
    })
}

/// Pass 4: the labels of a tile's core points, written to `out` (a PLY with `index`, `sharp`,
/// `sharpness` per core point); returns the tile's report.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn tile_labels<'py>(
    py: Python<'py>,
    tile: PathBuf,
    cache: PathBuf,
    thresholds: Vec<(f64, f64)>,
    ratio: f64,
    surfaces: bool,
    out: PathBuf,
) -> PyResult<Bound<'py, PyDict>> {
    let (core_count, regularized, sharp_count) = compute(py, move || {
        let (p, core, index) = read_tile(&tile)?;
        let values = read_cache(&cache, p.len())?;
        let r = tiled::label_tile(
            &Tile {
                points: &p,
                core: &core,
            },
            &values,
            &thresholds,
            ratio,
            &params(surfaces),
        )?;
        let keep: Vec<usize> = (0..p.len()).filter(|&i| core[i]).collect();
        let mut cloud = PointCloud::from_positions(keep.iter().map(|&i| p[i]).collect());
        cloud.set_attribute(Attribute {
            name: "index".into(),
            kind: ScalarKind::F64,
            values: keep.iter().map(|&i| index[i]).collect(),
        })?;
        cloud.set_attribute(Attribute::flag("sharp", keep.iter().map(|&i| r.sharp[i])))?;
        cloud.set_attribute(Attribute::float(
            "sharpness",
            keep.iter().map(|&i| r.sharpness[i]).collect::<Vec<f64>>(),
        ))?;
        crease::io::write(&out, &Geometry::from_cloud(cloud), &WriteOptions::default())?;
        let sharp_count = keep.iter().filter(|&&i| r.sharp[i]).count();
        Ok((keep.len(), r.regularized, sharp_count))
    })?;
    let d = PyDict::new(py);
    d.set_item("core", core_count)?;
    d.set_item("sharp", sharp_count)?;
    d.set_item("regularized", regularized)?;
    Ok(d)
}
