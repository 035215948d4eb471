//! A point cloud cut into tiles with halos, one file per tile, for clouds whose analysis
//! outgrows one machine's memory (the Python package's `crease.tiled_sharp`, which processes the
//! tiles as tasks and merges their labels, see [`crate::sharp::tiled`]).
//!
//! The tiles are the cells of a grid of cubes of side [`TileSpec::size`] over the cloud's bounding
//! box. A tile's file holds the points of its cell (its core) and, as its halo, every point
//! within [`TileSpec::halo`] of the cell along each axis; each point carries its `index` in the
//! input (a double, exact up to 2^53) and a `core` flag. A LAS / LAZ input is streamed (its
//! header gives the box; the points are read in batches and appended to one temporary file per
//! tile, so memory holds one tile at a time); the other formats are read whole (the positions
//! then take 24 bytes per point). Cells without a core point are left out.

use std::collections::BTreeMap;
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use crate::geometry::{Attribute, Point3, PointCloud, ScalarKind};
use crate::io::{self, Format, Geometry, ReadOptions, WriteOptions};
use crate::{Error, Result};

/// The most tiles one split makes (each is an open file while the input is read).
pub const MAX_TILES: usize = 512;

/// Bytes per point in a tile's temporary file: x, y, z (f64), index (u64), core (u8).
const RECORD: usize = 33;

/// How to cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TileSpec {
    /// The side of a tile's cell (the cloud's units).
    pub size: f64,
    /// How far around its cell a tile also holds points (the cloud's units).
    pub halo: f64,
}

/// One tile's file.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TileFile {
    /// The binary PLY with `index` and `core` per point.
    pub path: PathBuf,
    /// The cell (x, y, z) in the grid.
    pub cell: [usize; 3],
    /// Points in the file, core and halo.
    pub points: usize,
    /// Points of its core.
    pub core: usize,
}

/// What [`split`] wrote.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Tiling {
    /// The tiles with a core point, in cell order.
    pub tiles: Vec<TileFile>,
    /// Points in the input.
    pub points: usize,
    /// Cells of the grid along x, y, z.
    pub grid: [usize; 3],
    /// The grid's origin (the lowest corner of the input's box).
    pub origin: Point3,
    /// The cut.
    pub spec: TileSpec,
}

impl serde::Serialize for TileSpec {
    fn serialize<S: serde::Serializer>(&self, s: S) -> std::result::Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("TileSpec", 2)?;
        st.serialize_field("size", &self.size)?;
        st.serialize_field("halo", &self.halo)?;
        st.end()
    }
}

/// The grid over a box, and the cells a point belongs to.
struct Grid {
    origin: Point3,
    size: f64,
    halo: f64,
    cells: [usize; 3],
}

impl Grid {
    fn cell_along(&self, axis: usize, x: f64) -> usize {
        let c = ((x - self.origin[axis]) / self.size).floor();
        if c.is_nan() || c < 0.0 {
            0
        } else {
            (c as usize).min(self.cells[axis] - 1)
        }
    }

    /// `f(cell id, core)` for the point's own cell and every cell whose halo holds it.
    fn visit(&self, p: Point3, mut f: impl FnMut(usize, bool)) {
        let own = [0, 1, 2].map(|a| self.cell_along(a, p[a]));
        let lo = [0, 1, 2].map(|a| self.cell_along(a, p[a] - self.halo));
        let hi = [0, 1, 2].map(|a| self.cell_along(a, p[a] + self.halo));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let id = (z * self.cells[1] + y) * self.cells[0] + x;
                    f(id, [x, y, z] == own);
                }
            }
        }
    }

    fn cell_of(&self, id: usize) -> [usize; 3] {
        [
            id % self.cells[0],
            (id / self.cells[0]) % self.cells[1],
            id / (self.cells[0] * self.cells[1]),
        ]
    }
}

/// Cuts the cloud of `input` into tiles written into the folder `dir` (created if missing) as
/// `tile-X-Y-Z.ply`. Errors: the input's (unreadable, not a point file), a size or halo that is
/// not a positive finite length (halo ≥ 0), more than [`MAX_TILES`] cells, an empty cloud.
pub fn split(input: &Path, dir: &Path, spec: TileSpec) -> Result<Tiling> {
    if !(spec.size.is_finite() && spec.size > 0.0) {
        return Err(Error::InvalidArgument(format!(
            "tile size must be a positive length, got {}",
            spec.size
        )));
    }
    if !(spec.halo.is_finite() && spec.halo >= 0.0) {
        return Err(Error::InvalidArgument(format!(
            "tile halo must be a length >= 0, got {}",
            spec.halo
        )));
    }
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let streamed = cfg!(feature = "las") && matches!(Format::from_path(input), Ok(Format::Las));
    // The box first: from a LAS header, or from the points read whole.
    let (positions, lo, hi) = if streamed {
        let (lo, hi) = las_bounds(input)?;
        (None, lo, hi)
    } else {
        let (geom, _) = io::read(input, &ReadOptions::default())?;
        let pts = geom.points.positions;
        let b = crate::Aabb::from_points(&pts)
            .ok_or_else(|| Error::InvalidInput(format!("{}: no points", input.display())))?;
        (Some(pts), b.min, b.max)
    };
    let cells = [0, 1, 2].map(|a| (((hi[a] - lo[a]) / spec.size).floor() as usize + 1).max(1));
    let total_cells = cells.iter().try_fold(1usize, |acc, &c| acc.checked_mul(c));
    if total_cells.is_none_or(|t| t > MAX_TILES) {
        return Err(Error::InvalidArgument(format!(
            "{}: tiles of size {} make a grid of {} x {} x {} cells over the cloud's box, more \
             than {MAX_TILES}: use larger tiles",
            input.display(),
            spec.size,
            cells[0],
            cells[1],
            cells[2]
        )));
    }
    let grid = Grid {
        origin: lo,
        size: spec.size,
        halo: spec.halo,
        cells,
    };
    let raw_path = |id: usize| {
        let c = grid.cell_of(id);
        dir.join(format!("tile-{}-{}-{}.raw", c[0], c[1], c[2]))
    };
    // Per cell: its temporary file, points and core points.
    let mut open: BTreeMap<usize, (BufWriter<std::fs::File>, usize, usize)> = BTreeMap::new();
    let mut index = 0u64;
    let mut write = |batch: &[Point3]| -> Result<()> {
        for &p in batch {
            let mut failed = None;
            grid.visit(p, |id, core| {
                if failed.is_some() {
                    return;
                }
                let entry = match open.entry(id) {
                    std::collections::btree_map::Entry::Occupied(e) => e.into_mut(),
                    std::collections::btree_map::Entry::Vacant(v) => {
                        let path = raw_path(id);
                        match std::fs::File::create(&path) {
                            Ok(f) => v.insert((BufWriter::with_capacity(1 << 16, f), 0, 0)),
                            Err(e) => {
                                failed = Some(Error::io(&path, e));
                                return;
                            }
                        }
                    }
                };
                let mut rec = [0u8; RECORD];
                for (a, c) in p.iter().enumerate() {
                    rec[a * 8..a * 8 + 8].copy_from_slice(&c.to_le_bytes());
                }
                rec[24..32].copy_from_slice(&index.to_le_bytes());
                rec[32] = u8::from(core);
                if let Err(e) = entry.0.write_all(&rec) {
                    failed = Some(Error::io(raw_path(id), e));
                }
                entry.1 += 1;
                entry.2 += usize::from(core);
            });
            if let Some(e) = failed {
                return Err(e);
            }
            index += 1;
        }
        Ok(())
    };
    match &positions {
        Some(p) => write(p)?,
        None => las_stream(input, &mut write)?,
    }
    let points = index as usize;
    if points == 0 {
        return Err(Error::InvalidInput(format!(
            "{}: no points",
            input.display()
        )));
    }
    drop(positions);
    // Each temporary file becomes a PLY (one tile in memory at a time).
    let mut tiles = Vec::new();
    for (id, (w, n, core)) in open {
        let raw = raw_path(id);
        w.into_inner()
            .map_err(|e| Error::io(&raw, e.into_error()))?
            .sync_all()
            .map_err(|e| Error::io(&raw, e))?;
        if core > 0 {
            let cell = grid.cell_of(id);
            let path = dir.join(format!("tile-{}-{}-{}.ply", cell[0], cell[1], cell[2]));
            write_tile(&raw, &path, n)?;
            tiles.push(TileFile {
                path,
                cell,
                points: n,
                core,
            });
        }
        std::fs::remove_file(&raw).map_err(|e| Error::io(&raw, e))?;
    }
    Ok(Tiling {
        tiles,
        points,
        grid: cells,
        origin: lo,
        spec,
    })
}

/// A tile's temporary records as a binary PLY with `index` and `core`.
fn write_tile(raw: &Path, path: &Path, n: usize) -> Result<()> {
    let mut bytes = Vec::with_capacity(n * RECORD);
    std::fs::File::open(raw)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .map_err(|e| Error::io(raw, e))?;
    let f64_at = |r: &[u8], at: usize| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&r[at..at + 8]);
        b
    };
    let mut positions = Vec::with_capacity(n);
    let mut index = Vec::with_capacity(n);
    let mut core = Vec::with_capacity(n);
    for r in bytes.chunks_exact(RECORD) {
        positions.push([0, 8, 16].map(|a| f64::from_le_bytes(f64_at(r, a))));
        index.push(u64::from_le_bytes(f64_at(r, 24)) as f64);
        core.push(f64::from(r[32]));
    }
    let mut cloud = PointCloud::from_positions(positions);
    cloud.set_attribute(Attribute {
        name: "index".into(),
        kind: ScalarKind::F64,
        values: index,
    })?;
    cloud.set_attribute(Attribute {
        name: "core".into(),
        kind: ScalarKind::U8,
        values: core,
    })?;
    io::write(path, &Geometry::from_cloud(cloud), &WriteOptions::default())
}

#[cfg(feature = "las")]
fn las_bounds(input: &Path) -> Result<(Point3, Point3)> {
    io::las::header_bounds(input).map(|(_, lo, hi)| (lo, hi))
}

#[cfg(feature = "las")]
fn las_stream(input: &Path, f: impl FnMut(&[Point3]) -> Result<()>) -> Result<()> {
    io::las::for_each_position(input, f).map(|_| ())
}

#[cfg(not(feature = "las"))]
fn las_bounds(input: &Path) -> Result<(Point3, Point3)> {
    Err(Error::Unsupported {
        path: input.to_path_buf(),
        message: "LAS (crease was built without the `las` feature)".into(),
    })
}

#[cfg(not(feature = "las"))]
fn las_stream(input: &Path, _f: impl FnMut(&[Point3]) -> Result<()>) -> Result<()> {
    las_bounds(input).map(|_| ())
}
