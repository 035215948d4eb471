//! ASPRS LAS and LAZ (LASzip-compressed LAS) reading and writing, through the `las` crate
//! (compiled with the cargo feature `las`, on by default).
//!
//! # Reading
//! Positions are the scaled coordinates as f64. Per-point data become attributes:
//! `intensity` (U16), `classification` (U8), `return_number` (U8), `number_of_returns` (U8) and,
//! when the point format has it, `gps_time` (F64). Colours are 16-bit in LAS: they are reduced to
//! 8 bits by keeping the high byte (which inverts both the `c × 257` and the `c × 256`
//! conventions exactly), except when no channel of any point exceeds 255: such a file stores
//! 8-bit values in the 16-bit fields, and they are kept as they are. The report's encoding names
//! the LAS version and the point format.
//!
//! For an uncompressed file the point count from the header is checked against the file size
//! before anything is read; points are read in batches, so memory follows the data actually
//! decoded, not the header's count (which matters for LAZ, whose size does not bound the count).
//!
//! # Writing
//! LAS or LAZ by extension (`.laz` is compressed). LAS 1.2 point format 0, 1 (GPS time), 2
//! (colour) or 3 (both); LAS 1.4 formats 6 / 7 when a classification exceeds 31 or a return
//! number exceeds 7 (the 1.2 formats store them in 5 and 3 bits). Attributes named `intensity`,
//! `classification`, `return_number`, `number_of_returns` and `gps_time` go to those fields
//! (class 12, "overlap", is the overlap flag in LAS 1.4 formats and reads back as 12); LAS
//! has no room for normals or other attributes, which are not written. Colours are written as
//! `c × 257` (full 16-bit range).
//!
//! Coordinates are stored as 32-bit integers `offset + n × scale` with offset = the bounding
//! box's minimum and scale the largest power of ten not above 2e-6 × the bounding-box diagonal,
//! so that the rounding error (at most half a step) is at most 1e-6 of the diagonal. The integer
//! range then spans at least 10^5 steps per diagonal and at most ~5 × 10^6, far inside i32.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use las::{Builder, Color, Point, PointData, Reader, Transform, Vector, Writer};

use super::{Geometry, ReadReport, WriteOptions};
use crate::geometry::{Attribute, PointCloud, ScalarKind};
use crate::{Error, Result};

/// Points decoded per batch.
const BATCH: u64 = 1 << 16;

fn las_err(path: &Path, what: &str, e: las::Error) -> Error {
    Error::format(path, format!("{what}: {e}"))
}

/// Checks a LAZ file's chunk table before the decoder allocates it: the `laz` crate reserves
/// 16 bytes per chunk the table announces, so a corrupt count of 2^31 chunks made it allocate
/// 32 GB and abort (found by mutation fuzzing). Every chunk holds at least one byte of the
/// compressed data between the point data's start and the table, which bounds the count.
fn check_chunk_table(path: &Path, data_start: u64, file_len: u64) -> Result<()> {
    use std::io::{Read, Seek, SeekFrom};
    let corrupt = |what: String| Error::format(path, format!("corrupt LAZ chunk table: {what}"));
    let mut f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut word = [0u8; 8];
    let read_at = |f: &mut std::fs::File, at: u64, buf: &mut [u8]| -> Result<()> {
        f.seek(SeekFrom::Start(at))
            .and_then(|_| f.read_exact(buf))
            .map_err(|_| corrupt(format!("cannot read {} bytes at byte {at}", buf.len())))
    };
    read_at(&mut f, data_start, &mut word)?;
    let mut table = i64::from_le_bytes(word);
    if table == -1 {
        // Written by a streaming encoder: the offset is in the file's last 8 bytes.
        read_at(&mut f, file_len.saturating_sub(8), &mut word)?;
        table = i64::from_le_bytes(word);
    }
    let table = u64::try_from(table).unwrap_or(u64::MAX);
    if table < data_start + 8 || table.saturating_add(8) > file_len {
        return Err(corrupt(format!(
            "its offset {table} lies outside the compressed data (bytes {} to {file_len})",
            data_start + 8
        )));
    }
    let mut head = [0u8; 8];
    read_at(&mut f, table, &mut head)?;
    let chunks = u64::from(u32::from_le_bytes([head[4], head[5], head[6], head[7]]));
    let room = table - (data_start + 8);
    if chunks > room {
        return Err(corrupt(format!(
            "it announces {chunks} chunks, but only {room} bytes of compressed data precede it"
        )));
    }
    Ok(())
}

/// Reads a LAS or LAZ file (see the module documentation).
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    // The decoder is a third-party crate: a panic inside it on a corrupt file becomes an error.
    catch_unwind(AssertUnwindSafe(|| read_inner(path))).unwrap_or_else(|_| {
        Err(Error::format(
            path,
            "the LAS/LAZ decoder failed on corrupt data",
        ))
    })
}

/// Opens a LAS / LAZ file for reading, after the checks that keep a corrupt header from
/// allocating or decoding garbage (chunk table, announced size against the file's).
fn open(path: &Path) -> Result<Reader> {
    let file_len = std::fs::metadata(path)
        .map_err(|e| Error::io(path, e))?
        .len();
    // The raw header gives the point data offset and record length for the size check.
    let raw = {
        let f = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
        las::raw::Header::read_from(std::io::BufReader::new(f)).map_err(|e| {
            las_err(
                path,
                "not a readable LAS header (the file is truncated or not LAS)",
                e,
            )
        })?
    };
    if raw.point_data_record_format & 0x80 != 0 {
        check_chunk_table(path, u64::from(raw.offset_to_point_data), file_len)?;
    }
    let reader =
        Reader::from_path(path).map_err(|e| las_err(path, "cannot open the LAS/LAZ file", e))?;
    let header = reader.header();
    let format = *header.point_format();
    let n = header.number_of_points();
    if !format.is_compressed {
        let need = n
            .checked_mul(u64::from(raw.point_data_record_length))
            .and_then(|b| b.checked_add(u64::from(raw.offset_to_point_data)))
            .unwrap_or(u64::MAX);
        if need > file_len {
            return Err(Error::format(
                path,
                format!(
                    "the header announces {n} points of {} bytes from byte {}, which needs {need} \
                     bytes, but the file has {file_len}: the file is truncated",
                    raw.point_data_record_length, raw.offset_to_point_data
                ),
            ));
        }
    }
    Ok(reader)
}

/// The point count and the bounding box a LAS / LAZ file's header announces.
pub fn header_bounds(path: &Path) -> Result<(u64, [f64; 3], [f64; 3])> {
    let reader = open(path)?;
    let header = reader.header();
    let b = header.bounds();
    Ok((
        header.number_of_points(),
        [b.min.x, b.min.y, b.min.z],
        [b.max.x, b.max.y, b.max.z],
    ))
}

/// The positions of a LAS / LAZ file, handed to `f` in batches in file order without holding
/// the file in memory (for clouds larger than memory, [`crate::io::tiles`]); returns the
/// header's point count and bounding box.
pub fn for_each_position(
    path: &Path,
    mut f: impl FnMut(&[[f64; 3]]) -> Result<()>,
) -> Result<(u64, [f64; 3], [f64; 3])> {
    catch_unwind(AssertUnwindSafe(|| {
        let mut reader = open(path)?;
        let header = reader.header().clone();
        let n = header.number_of_points();
        let b = header.bounds();
        let mut pd: PointData = las::PointDataBuilder::new().for_header(&header).build();
        let mut batch = Vec::new();
        let mut read = 0u64;
        loop {
            let got = reader.fill_points(BATCH, &mut pd).map_err(|e| {
                las_err(
                    path,
                    &format!("point {read}: cannot decode the point data"),
                    e,
                )
            })?;
            if got == 0 {
                break;
            }
            read += got;
            batch.clear();
            batch.extend(pd.x().zip(pd.y()).zip(pd.z()).map(|((x, y), z)| [x, y, z]));
            f(&batch)?;
        }
        if read < n {
            return Err(Error::format(
                path,
                format!(
                    "the header announces {n} points but only {read} could be read: the file is \
                     truncated"
                ),
            ));
        }
        Ok((n, [b.min.x, b.min.y, b.min.z], [b.max.x, b.max.y, b.max.z]))
    }))
    .unwrap_or_else(|_| {
        Err(Error::format(
            path,
            "the LAS/LAZ decoder failed on corrupt data",
        ))
    })
}

fn read_inner(path: &Path) -> Result<(Geometry, ReadReport)> {
    let mut reader = open(path)?;
    let header = reader.header().clone();
    let format = *header.point_format();
    let n = header.number_of_points();
    let mut positions = Vec::new();
    let mut intensity = Vec::new();
    let mut class = Vec::new();
    let mut ret = Vec::new();
    let mut nret = Vec::new();
    let mut gps = Vec::new();
    let mut rgb16: Vec<[u16; 3]> = Vec::new();
    let mut pd: PointData = las::PointDataBuilder::new().for_header(&header).build();
    loop {
        let got = reader.fill_points(BATCH, &mut pd).map_err(|e| {
            las_err(
                path,
                &format!("point {}: cannot decode the point data", positions.len()),
                e,
            )
        })?;
        if got == 0 {
            break;
        }
        positions.extend(pd.x().zip(pd.y()).zip(pd.z()).map(|((x, y), z)| [x, y, z]));
        intensity.extend(pd.intensity().map(f64::from));
        if format.is_extended {
            // Code 12 (overlap) is a flag in the extended formats: an unclassified overlap
            // point reads back as 12, as in the legacy formats (see `write`).
            let rl = pd.record_len();
            class.extend(pd.raw_bytes().chunks_exact(rl).map(|r| {
                match (r.get(15).map(|f| f & 0b1000 != 0), r.get(16).copied()) {
                    (Some(true), Some(1)) => 12.0,
                    (_, c) => f64::from(c.unwrap_or(0)),
                }
            }));
        } else {
            class.extend(pd.classification().map(f64::from));
        }
        ret.extend(pd.return_number().map(f64::from));
        nret.extend(pd.number_of_returns().map(f64::from));
        if let Some(g) = pd.gps_time() {
            gps.extend(g);
        }
        if let Some(c) = pd.rgb() {
            rgb16.extend(c.map(|(r, g, b)| [r, g, b]));
        }
    }
    if (positions.len() as u64) < n {
        return Err(Error::format(
            path,
            format!(
                "the header announces {n} points but only {} could be read: the file is truncated",
                positions.len()
            ),
        ));
    }
    let count = positions.len();
    let mut cloud = PointCloud::from_positions(positions);
    let mut report = ReadReport {
        encoding: format!(
            "{} {} point format {}",
            if format.is_compressed { "LAZ" } else { "LAS" },
            header.version(),
            format
                .to_u8()
                .map(|v| v.to_string())
                .unwrap_or_else(|_| "?".into())
        ),
        ..Default::default()
    };
    if format.has_color && rgb16.len() == count {
        let max = rgb16.iter().flatten().copied().max().unwrap_or(0);
        let colors = if max <= 255 {
            if count > 0 {
                report
                    .notes
                    .push("colours hold 8-bit values in 16-bit fields; kept as they are".into());
            }
            rgb16.iter().map(|c| c.map(|v| v as u8)).collect()
        } else {
            rgb16.iter().map(|c| c.map(|v| (v >> 8) as u8)).collect()
        };
        cloud.set_colors(colors)?;
    }
    let attr = |name: &str, kind, values| Attribute {
        name: name.into(),
        kind,
        values,
    };
    cloud.set_attribute(attr("intensity", ScalarKind::U16, intensity))?;
    cloud.set_attribute(attr("classification", ScalarKind::U8, class))?;
    cloud.set_attribute(attr("return_number", ScalarKind::U8, ret))?;
    cloud.set_attribute(attr("number_of_returns", ScalarKind::U8, nret))?;
    if format.has_gps_time && gps.len() == count {
        cloud.set_attribute(attr("gps_time", ScalarKind::F64, gps))?;
    }
    if count < n as usize {
        report
            .notes
            .push(format!("{n} points announced, {count} read"));
    }
    Ok((Geometry::from_cloud(cloud), report))
}

/// The quantisation step for a bounding-box diagonal `d`: the largest power of ten not above
/// `2e-6 × d` (so half a step is at most 1e-6 of the diagonal); 1e-3 for a single point.
pub fn scale_for_diagonal(d: f64) -> f64 {
    if !(d.is_finite() && d > 0.0) {
        return 1e-3;
    }
    let s = 10f64.powf((2e-6 * d).log10().floor());
    // Guard against log10 rounding up at exact powers of ten.
    if s > 2e-6 * d {
        s / 10.0
    } else {
        s
    }
}

/// Writes a LAS file, or LAZ when the extension is `.laz` (see the module documentation).
pub fn write(path: &Path, geom: &Geometry, _opts: &WriteOptions) -> Result<()> {
    geom.validate()?;
    let cloud = &geom.points;
    let n = cloud.len();
    let (min, max) = match cloud.aabb() {
        Some(b) => (b.min, b.max),
        None => ([0.0; 3], [0.0; 3]),
    };
    if min.iter().chain(&max).any(|c| !c.is_finite()) {
        return Err(Error::InvalidInput(format!(
            "{}: LAS cannot store NaN or infinite coordinates",
            path.display()
        )));
    }
    let d = (0..3)
        .map(|k| (max[k] - min[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let scale = scale_for_diagonal(d);
    let get = |name: &str| cloud.attribute(name).map(|a| &a.values);
    let intensity = get("intensity");
    let class = get("classification");
    let ret = get("return_number");
    let nret = get("number_of_returns");
    let gps = get("gps_time");
    let colors = cloud.colors.as_ref();
    let max_of = |v: Option<&Vec<f64>>| v.map_or(0.0, |v| v.iter().copied().fold(0.0, f64::max));
    let extended = max_of(class) > 31.0 || max_of(ret) > 7.0 || max_of(nret) > 7.0;
    let fmt = match (extended, colors.is_some(), gps.is_some()) {
        (true, true, _) => 7,
        (true, false, _) => 6,
        (false, false, false) => 0,
        (false, false, true) => 1,
        (false, true, false) => 2,
        (false, true, true) => 3,
    };
    let mut b = Builder::from(if extended { (1, 4) } else { (1, 2) });
    b.point_format = las::point::Format::new(fmt).map_err(|e| las_err(path, "point format", e))?;
    b.generating_software = "crease".into();
    b.transforms = Vector {
        x: Transform {
            scale,
            offset: min[0],
        },
        y: Transform {
            scale,
            offset: min[1],
        },
        z: Transform {
            scale,
            offset: min[2],
        },
    };
    let header = b
        .into_header()
        .map_err(|e| las_err(path, "cannot build the LAS header", e))?;
    let mut w = Writer::from_path(path, header).map_err(|e| las_err(path, "cannot create", e))?;
    let clamp = |v: f64, hi: f64| v.clamp(0.0, hi).round();
    for i in 0..n {
        let [x, y, z] = cloud.positions[i];
        let mut p = Point {
            x,
            y,
            z,
            ..Default::default()
        };
        if let Some(v) = intensity {
            p.intensity = clamp(v[i], 65535.0) as u16;
        }
        if let Some(v) = class {
            let c = clamp(v[i], if extended { 255.0 } else { 31.0 }) as u8;
            if c == 12 {
                // The las crate models code 12 (overlap) as a flag: legacy formats store it back
                // as class 12, extended ones as "unclassified + overlap bit" (read back as 12).
                p.is_overlap = true;
                p.classification = las::point::Classification::Unclassified;
            } else {
                p.classification = las::point::Classification::new(c)
                    .map_err(|e| las_err(path, &format!("point {i}: classification"), e))?;
            }
        }
        if let Some(v) = ret {
            p.return_number = clamp(v[i], if extended { 15.0 } else { 7.0 }) as u8;
        }
        if let Some(v) = nret {
            p.number_of_returns = clamp(v[i], if extended { 15.0 } else { 7.0 }) as u8;
        }
        if fmt == 1 || fmt == 3 || extended {
            p.gps_time = Some(gps.map_or(0.0, |v| v[i]));
        }
        if let Some(c) = colors {
            let [r, g, b] = c[i];
            p.color = Some(Color::new(
                u16::from(r) * 257,
                u16::from(g) * 257,
                u16::from(b) * 257,
            ));
        }
        w.write_point(p)
            .map_err(|e| las_err(path, &format!("point {i}: cannot write"), e))?;
    }
    w.close()
        .map_err(|e| las_err(path, "cannot finish the file", e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_bounds_the_error() {
        for d in [1e-4, 0.3, 1.0, 7.5, 10.0, 1234.5, 1e6] {
            let s = scale_for_diagonal(d);
            assert!(s / 2.0 <= 1e-6 * d, "d {d} s {s}");
            assert!(s * 10.0 > 2e-6 * d, "d {d} s {s}");
        }
    }
}
