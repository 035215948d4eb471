//! ASTM E57 reading and writing, through the `e57` crate (compiled with the cargo feature
//! `e57`, on by default).
//!
//! # Reading
//! Every point cloud (scan) in the file is read and its pose (rotation quaternion + translation)
//! applied, giving one cloud in world coordinates; scans with spherical coordinates are converted
//! to cartesian first. Points whose coordinates are flagged invalid (or are a direction only, no
//! range) are dropped and counted in [`ReadReport::dropped_missing`]. Colours are normalised by
//! the scan's colour limits to 0..1 and stored as 0..255. Intensity is kept as stored (not
//! normalised) in the `intensity` attribute (F32). When only some scans (or points) carry colour
//! or intensity, the others get black / 0 and a note says so. The number of scans merged is noted.
//!
//! # Writing
//! One scan with f64 cartesian coordinates (so positions round-trip exactly), 8-bit colours when
//! present, and the `intensity` attribute as a 32-bit float when present. The scan's GUID is
//! derived from a hash of the data, so writing the same cloud gives the same file.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use e57::{
    CartesianCoordinate, E57Reader, E57Writer, Record, RecordDataType, RecordName, RecordValue,
};

use super::{Geometry, ReadReport, WriteOptions};
use crate::geometry::{Attribute, PointCloud, ScalarKind};
use crate::{Error, Result};

fn e57_err(path: &Path, what: &str, e: e57::Error) -> Error {
    Error::format(path, format!("{what}: {e}"))
}

/// Reads every scan of an E57 file into one cloud in world coordinates.
pub fn read(path: &Path) -> Result<(Geometry, ReadReport)> {
    // The decoder is a third-party crate: a panic inside it on a corrupt file becomes an error.
    catch_unwind(AssertUnwindSafe(|| read_inner(path))).unwrap_or_else(|_| {
        Err(Error::format(
            path,
            "the E57 decoder failed on corrupt data",
        ))
    })
}

fn read_inner(path: &Path) -> Result<(Geometry, ReadReport)> {
    // Open first so that a missing file is an I/O error, not a format error.
    std::fs::metadata(path).map_err(|e| Error::io(path, e))?;
    let mut reader = E57Reader::from_file(path).map_err(|e| {
        e57_err(
            path,
            "not a readable E57 file (bad header, checksum or XML section)",
            e,
        )
    })?;
    let scans = reader.pointclouds();
    let mut positions = Vec::new();
    let mut colors: Vec<[u8; 3]> = Vec::new();
    let mut intensity: Vec<f64> = Vec::new();
    let mut any_color = false;
    let mut any_intensity = false;
    let mut missing_color = 0usize;
    let mut missing_intensity = 0usize;
    let mut report = ReadReport {
        encoding: format!("e57 {}", reader.format_name()),
        ..Default::default()
    };
    for (si, pc) in scans.iter().enumerate() {
        let mut it = reader
            .pointcloud_simple(pc)
            .map_err(|e| e57_err(path, &format!("scan {si}: cannot read the point data"), e))?;
        it.apply_pose(true);
        it.spherical_to_cartesian(true);
        it.intensity_to_color(false);
        it.normalize_color(true);
        it.normalize_intensity(false);
        for (pi, p) in it.enumerate() {
            let p = p.map_err(|e| e57_err(path, &format!("scan {si}, point {pi}"), e))?;
            let CartesianCoordinate::Valid { x, y, z } = p.cartesian else {
                report.dropped_missing += 1;
                continue;
            };
            positions.push([x, y, z]);
            match p.color {
                Some(c) => {
                    any_color = true;
                    let q = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
                    colors.push([q(c.red), q(c.green), q(c.blue)]);
                }
                None => {
                    missing_color += 1;
                    colors.push([0, 0, 0]);
                }
            }
            match p.intensity {
                Some(v) => {
                    any_intensity = true;
                    intensity.push(f64::from(v));
                }
                None => {
                    missing_intensity += 1;
                    intensity.push(0.0);
                }
            }
        }
    }
    report.notes.push(format!(
        "{} scan(s) merged in world coordinates (each scan's pose applied)",
        scans.len()
    ));
    let mut cloud = PointCloud::from_positions(positions);
    if any_color {
        if missing_color > 0 {
            report.notes.push(format!(
                "{missing_color} points without colour set to black"
            ));
        }
        cloud.set_colors(colors)?;
    }
    if any_intensity {
        if missing_intensity > 0 {
            report.notes.push(format!(
                "{missing_intensity} points without intensity set to 0"
            ));
        }
        cloud.set_attribute(Attribute {
            name: "intensity".into(),
            kind: ScalarKind::F32,
            values: intensity,
        })?;
    }
    Ok((Geometry::from_cloud(cloud), report))
}

/// FNV-1a over the positions, for a reproducible GUID.
fn data_hash(cloud: &PointCloud) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for p in &cloud.positions {
        for c in p {
            for b in c.to_le_bytes() {
                h ^= u64::from(b);
                h = h.wrapping_mul(0x0000_0100_0000_01b3);
            }
        }
    }
    h ^ cloud.len() as u64
}

/// Writes one E57 scan with f64 cartesian coordinates, colours and intensity.
pub fn write(path: &Path, geom: &Geometry, _opts: &WriteOptions) -> Result<()> {
    geom.validate()?;
    let cloud = &geom.points;
    let h = data_hash(cloud);
    let file_guid = format!("crease-file-{h:016x}");
    let scan_guid = format!("crease-scan-{h:016x}");
    let mut w = E57Writer::from_file(path, &file_guid)
        .map_err(|e| e57_err(path, "cannot create the E57 file", e))?;
    let mut proto = vec![
        Record::CARTESIAN_X_F64,
        Record::CARTESIAN_Y_F64,
        Record::CARTESIAN_Z_F64,
    ];
    let colors = cloud.colors.as_ref();
    if colors.is_some() {
        proto.extend([
            Record::COLOR_RED_U8,
            Record::COLOR_GREEN_U8,
            Record::COLOR_BLUE_U8,
        ]);
    }
    let intensity = cloud.attribute("intensity").map(|a| &a.values);
    if let Some(v) = intensity {
        let (lo, hi) = v
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x as f32), hi.max(x as f32))
            });
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
        proto.push(Record {
            name: RecordName::Intensity,
            data_type: RecordDataType::Single {
                min: Some(lo),
                max: Some(hi),
            },
        });
    }
    {
        let mut pw = w
            .add_pointcloud(&scan_guid, proto)
            .map_err(|e| e57_err(path, "cannot start the scan", e))?;
        pw.set_name(Some("crease".into()));
        for (i, p) in cloud.positions.iter().enumerate() {
            let mut v = vec![
                RecordValue::Double(p[0]),
                RecordValue::Double(p[1]),
                RecordValue::Double(p[2]),
            ];
            if let Some(c) = colors {
                v.extend(c[i].iter().map(|&x| RecordValue::Integer(i64::from(x))));
            }
            if let Some(t) = intensity {
                v.push(RecordValue::Single(t[i] as f32));
            }
            pw.add_point(v)
                .map_err(|e| e57_err(path, &format!("point {i}: cannot write"), e))?;
        }
        pw.finalize()
            .map_err(|e| e57_err(path, "cannot finish the scan", e))?;
    }
    w.finalize()
        .map_err(|e| e57_err(path, "cannot finish the file", e))?;
    Ok(())
}
