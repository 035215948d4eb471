//! Reading and writing point clouds, meshes and polylines. One file per format; the format is
//! chosen by the file extension (`Format::from_path`), with a clear error for an unknown one.
//!
//! Every reader is hostile-input safe: it never panics, never allocates from a header count
//! before checking that count against the file size, and reports errors naming the file and the
//! line, element or byte where the content went wrong. Points with NaN or infinite coordinates
//! are dropped and counted in the [`ReadReport`] (or refused with [`ReadOptions::strict`]).

use std::path::Path;

use crate::geometry::{Attributes, PointCloud, TriMesh};
use crate::{Error, Result};

pub mod atomic;
#[cfg(feature = "e57")]
pub mod e57;
#[cfg(feature = "las")]
pub mod las;
pub mod obj;
pub mod off;
pub mod pcd;
pub mod ply;
pub mod stl;
pub mod summary;
pub mod tiles;
pub mod xyz;

/// Everything a file may hold: points (with per-point data), triangles, and line segments /
/// polylines over the points.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Geometry {
    /// The points (mesh vertices) with their normals, colours and attributes.
    pub points: PointCloud,
    /// Triangles (polygons are fan-triangulated on reading, and counted in the report).
    pub faces: Vec<[u32; 3]>,
    /// Per-face attributes.
    pub face_attributes: Attributes,
    /// Line segments between points (PLY `edge` element: `vertex1 vertex2`).
    pub edges: Vec<[u32; 2]>,
    /// Per-edge attributes (`sharp`, `sharpness`, ...).
    pub edge_attributes: Attributes,
    /// Polylines as point-index chains (OBJ `l`). A closed loop repeats its first index at the end.
    pub polylines: Vec<Vec<u32>>,
    /// Optional group name of every polyline (OBJ `g` before each run of equal names, e.g.
    /// `sharp` / `smooth` lines of a curve network); empty for none. Not stored in PLY.
    pub polyline_groups: Vec<String>,
}

impl Geometry {
    /// A geometry holding only a point cloud.
    pub fn from_cloud(points: PointCloud) -> Self {
        Geometry {
            points,
            ..Default::default()
        }
    }

    /// A geometry holding a mesh.
    pub fn from_mesh(mesh: TriMesh) -> Self {
        Geometry {
            points: mesh.vertices,
            faces: mesh.faces,
            face_attributes: mesh.face_attributes,
            ..Default::default()
        }
    }

    /// The triangle mesh, if the geometry has faces.
    pub fn into_mesh(self) -> Option<TriMesh> {
        if self.faces.is_empty() {
            return None;
        }
        Some(TriMesh {
            vertices: self.points,
            faces: self.faces,
            face_attributes: self.face_attributes,
        })
    }

    /// True if the geometry has triangles.
    pub fn is_mesh(&self) -> bool {
        !self.faces.is_empty()
    }

    /// Every polyline and edge as a list of segments.
    pub fn segments(&self) -> Vec<[u32; 2]> {
        let mut s = self.edges.clone();
        for l in &self.polylines {
            s.extend(l.windows(2).map(|w| [w[0], w[1]]));
        }
        s
    }

    /// Checks that faces, edges and polylines index existing points and that every per-element
    /// array has the right length.
    pub fn validate(&self) -> Result<()> {
        self.points.validate()?;
        let n = self.points.len();
        for (i, f) in self.faces.iter().enumerate() {
            if let Some(v) = f.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidInput(format!(
                    "face {i} refers to vertex {v}, but there are {n} vertices"
                )));
            }
        }
        for (i, e) in self.edges.iter().enumerate() {
            if let Some(v) = e.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidInput(format!(
                    "edge {i} refers to vertex {v}, but there are {n} vertices"
                )));
            }
        }
        for (i, l) in self.polylines.iter().enumerate() {
            if let Some(v) = l.iter().find(|&&v| v as usize >= n) {
                return Err(Error::InvalidInput(format!(
                    "polyline {i} refers to vertex {v}, but there are {n} vertices"
                )));
            }
        }
        for a in &self.face_attributes {
            if a.values.len() != self.faces.len() {
                return Err(Error::InvalidInput(format!(
                    "face attribute {:?} has {} values for {} faces",
                    a.name,
                    a.values.len(),
                    self.faces.len()
                )));
            }
        }
        for a in &self.edge_attributes {
            if a.values.len() != self.edges.len() {
                return Err(Error::InvalidInput(format!(
                    "edge attribute {:?} has {} values for {} edges",
                    a.name,
                    a.values.len(),
                    self.edges.len()
                )));
            }
        }
        Ok(())
    }
}

/// The file formats crease knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Format {
    /// Stanford PLY (ascii, binary little / big endian).
    Ply,
    /// Wavefront OBJ.
    Obj,
    /// Object File Format.
    Off,
    /// STL (ascii and binary).
    Stl,
    /// Plain text `x y z [nx ny nz]` (`.xyz`, `.txt`, `.csv`, `.pts`).
    Xyz,
    /// Point Cloud Library PCD.
    Pcd,
    /// ASPRS LAS / LAZ.
    Las,
    /// ASTM E57.
    E57,
}

/// The extensions crease recognises, for error messages.
pub const KNOWN_EXTENSIONS: &str = ".ply .obj .off .stl .xyz .txt .csv .pts .pcd .las .laz .e57";

impl Format {
    /// The format named by `path`'s extension (case-insensitive).
    pub fn from_path(path: &Path) -> Result<Format> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        Ok(match ext.as_str() {
            "ply" => Format::Ply,
            "obj" => Format::Obj,
            "off" => Format::Off,
            "stl" => Format::Stl,
            "xyz" | "txt" | "csv" | "pts" => Format::Xyz,
            "pcd" => Format::Pcd,
            "las" | "laz" => Format::Las,
            "e57" => Format::E57,
            _ => {
                return Err(Error::UnknownFormat {
                    path: path.to_path_buf(),
                    ext,
                    known: KNOWN_EXTENSIONS,
                })
            }
        })
    }

    /// A short lowercase name.
    pub fn name(self) -> &'static str {
        match self {
            Format::Ply => "ply",
            Format::Obj => "obj",
            Format::Off => "off",
            Format::Stl => "stl",
            Format::Xyz => "xyz",
            Format::Pcd => "pcd",
            Format::Las => "las",
            Format::E57 => "e57",
        }
    }
}

/// Options for reading.
#[derive(Debug, Clone, Default)]
pub struct ReadOptions {
    /// Refuse files with NaN or infinite coordinates instead of dropping those points.
    pub strict: bool,
}

/// Options for writing.
#[derive(Debug, Clone, Default)]
pub struct WriteOptions {
    /// Write text instead of binary where the format has both (PLY, STL, PCD).
    pub ascii: bool,
}

/// What a reader found and did, beyond the geometry itself.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct ReadReport {
    /// Encoding detail, e.g. `binary_little_endian 1.0` or `ascii`.
    pub encoding: String,
    /// Points dropped because a coordinate was NaN or infinite.
    pub dropped_nonfinite: usize,
    /// Faces dropped because they used a dropped point.
    pub dropped_faces: usize,
    /// Points the format marks as missing (NaN in organised PCD), dropped.
    pub dropped_missing: usize,
    /// Polygons with more than three corners, fan-triangulated.
    pub polygons_triangulated: usize,
    /// Anything else worth telling the user (ignored elements, unusual properties, ...).
    pub notes: Vec<String>,
}

/// Reads any supported file, choosing the format by extension.
pub fn read(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<(Geometry, ReadReport)> {
    let path = path.as_ref();
    let format = Format::from_path(path)?;
    // A FIFO or a device would be read forever (`/dev/urandom`), a folder cannot be read.
    let meta = std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    if !meta.is_file() {
        return Err(Error::InvalidInput(format!(
            "{}: not a regular file (a folder, a FIFO or a device); give a point cloud or mesh file",
            path.display()
        )));
    }
    let (mut geom, mut report) = match format {
        Format::Ply => ply::read(path)?,
        Format::Obj => obj::read(path)?,
        Format::Off => off::read(path)?,
        Format::Stl => stl::read(path)?,
        Format::Xyz => xyz::read(path)?,
        Format::Pcd => pcd::read(path)?,
        #[cfg(feature = "las")]
        Format::Las => las::read(path)?,
        #[cfg(feature = "e57")]
        Format::E57 => e57::read(path)?,
        #[allow(unreachable_patterns)]
        _ => return Err(disabled(path, format)),
    };
    drop_nonfinite(path, &mut geom, &mut report, opts.strict)?;
    geom.validate()
        .map_err(|e| Error::format(path, e.to_string()))?;
    Ok((geom, report))
}

/// Reads a file as a point cloud (a mesh's vertices are its points).
pub fn read_cloud(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<(PointCloud, ReadReport)> {
    let (g, r) = read(path, opts)?;
    Ok((g.points, r))
}

/// Reads a file that must hold a triangle mesh.
pub fn read_mesh(path: impl AsRef<Path>, opts: &ReadOptions) -> Result<(TriMesh, ReadReport)> {
    let path = path.as_ref();
    let (g, r) = read(path, opts)?;
    let mesh = g.into_mesh().ok_or_else(|| {
        Error::format(
            path,
            "the file holds no faces, but a triangle mesh is needed",
        )
    })?;
    Ok((mesh, r))
}

/// Writes `geom` in the format named by `path`'s extension.
///
/// Point formats (XYZ, PCD, LAS, E57) write the points of any geometry: a mesh's vertices,
/// without its faces, which is what converting a mesh to a point format means. Per-point data a
/// format has no room for (e.g. arbitrary attributes in XYZ) is left out; PLY keeps everything.
///
/// The file is replaced atomically ([`atomic`]): an interrupted run never leaves a truncated
/// output.
pub fn write(path: impl AsRef<Path>, geom: &Geometry, opts: &WriteOptions) -> Result<()> {
    let path = path.as_ref();
    geom.validate()?;
    let format = Format::from_path(path)?;
    atomic::replace(path, |tmp| write_format(tmp, format, geom, opts))
}

fn write_format(path: &Path, format: Format, geom: &Geometry, opts: &WriteOptions) -> Result<()> {
    match format {
        Format::Ply => ply::write(path, geom, opts),
        Format::Obj => obj::write(path, geom, opts),
        Format::Off => off::write(path, geom, opts),
        Format::Stl => stl::write(path, geom, opts),
        Format::Xyz => xyz::write(path, geom, opts),
        Format::Pcd => pcd::write(path, geom, opts),
        #[cfg(feature = "las")]
        Format::Las => las::write(path, geom, opts),
        #[cfg(feature = "e57")]
        Format::E57 => e57::write(path, geom, opts),
        #[allow(unreachable_patterns)]
        f => Err(disabled(path, f)),
    }
}

#[allow(dead_code)]
fn disabled(path: &Path, f: Format) -> Error {
    Error::Unsupported {
        path: path.to_path_buf(),
        message: format!(
            "{} support is not compiled in (enable the crate feature {:?})",
            f.name(),
            f.name()
        ),
    }
}

/// Drops points with a NaN or infinite coordinate (and faces / edges / polylines using them),
/// counting them in `report`; with `strict`, refuses the file instead.
fn drop_nonfinite(
    path: &Path,
    geom: &mut Geometry,
    report: &mut ReadReport,
    strict: bool,
) -> Result<()> {
    let keep: Vec<bool> = geom
        .points
        .positions
        .iter()
        .map(|p| p.iter().all(|c| c.is_finite()))
        .collect();
    let bad = keep.iter().filter(|k| !**k).count();
    if bad == 0 {
        return Ok(());
    }
    if strict {
        let first = keep.iter().position(|k| !k).unwrap_or(0);
        return Err(Error::format(
            path,
            format!("{bad} points have NaN or infinite coordinates (the first is point {first}); remove them or read without --strict to drop them"),
        ));
    }
    let faces_before = geom.faces.len();
    remove_points(geom, &keep);
    report.dropped_nonfinite += bad;
    report.dropped_faces += faces_before - geom.faces.len();
    Ok(())
}

/// Removes the points whose `keep` flag is false, renumbering faces, edges and polylines and
/// dropping the faces and edges that used a removed point (polylines are cut there).
pub fn remove_points(geom: &mut Geometry, keep: &[bool]) {
    let mut new_index = vec![u32::MAX; keep.len()];
    let mut next = 0u32;
    for (i, &k) in keep.iter().enumerate() {
        if k {
            new_index[i] = next;
            next += 1;
        }
    }
    geom.points.retain(keep);
    let face_keep: Vec<bool> = geom
        .faces
        .iter()
        .map(|f| f.iter().all(|&v| keep[v as usize]))
        .collect();
    crate::geometry::retain_by(&mut geom.faces, &face_keep);
    geom.face_attributes.retain_elements(&face_keep);
    for f in &mut geom.faces {
        for v in f.iter_mut() {
            *v = new_index[*v as usize];
        }
    }
    let edge_keep: Vec<bool> = geom
        .edges
        .iter()
        .map(|e| e.iter().all(|&v| keep[v as usize]))
        .collect();
    crate::geometry::retain_by(&mut geom.edges, &edge_keep);
    geom.edge_attributes.retain_elements(&edge_keep);
    for e in &mut geom.edges {
        for v in e.iter_mut() {
            *v = new_index[*v as usize];
        }
    }
    let mut lines = Vec::new();
    for l in std::mem::take(&mut geom.polylines) {
        let mut cur = Vec::new();
        for v in l {
            if keep[v as usize] {
                cur.push(new_index[v as usize]);
            } else if !cur.is_empty() {
                if cur.len() > 1 {
                    lines.push(std::mem::take(&mut cur));
                }
                cur.clear();
            }
        }
        if cur.len() > 1 {
            lines.push(cur);
        }
    }
    geom.polylines = lines;
}

/// Reads a whole file into memory, mapping the OS error to one naming the file.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::io(path, e))
}

/// Creates a buffered writer on `path`.
pub(crate) fn create(path: &Path) -> Result<std::io::BufWriter<std::fs::File>> {
    let f = std::fs::File::create(path).map_err(|e| Error::io(path, e))?;
    Ok(std::io::BufWriter::with_capacity(1 << 20, f))
}
