//! PCD, LAS / LAZ and E57: the real Kinect PCDs, round trips, and the bad-input corpus.

use crate::common;

use std::path::{Path, PathBuf};

use crease::geometry::{Attribute, PointCloud, ScalarKind};
use crease::io::{self, Geometry, ReadOptions, WriteOptions};

fn bad(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/bad_input")
        .join(name)
}

/// A deterministic test cloud: a slanted grid with normals, colours and assorted attributes.
fn sample_cloud(n: usize, offset: f64) -> PointCloud {
    let positions: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let u = (i % 37) as f64 / 37.0;
            let v = (i / 37) as f64 / 11.0;
            [
                offset + u * 1.7,
                offset - v * 0.9,
                offset + 0.3 * u * v + 0.123456789,
            ]
        })
        .collect();
    let mut c = PointCloud::from_positions(positions);
    c.set_normals(
        (0..n)
            .map(|i| {
                let a = i as f64 * 0.1;
                [a.cos() * 0.6, a.sin() * 0.6, 0.8]
            })
            .collect(),
    )
    .unwrap();
    c.set_colors(
        (0..n)
            .map(|i| {
                [
                    (i * 7 % 256) as u8,
                    (i * 13 % 256) as u8,
                    (255 - i % 256) as u8,
                ]
            })
            .collect(),
    )
    .unwrap();
    c.set_attribute(Attribute::float(
        "curvature",
        (0..n).map(|i| i as f64 * 0.25).collect(),
    ))
    .unwrap();
    c.set_attribute(Attribute::flag("sharp", (0..n).map(|i| i % 3 == 0)))
        .unwrap();
    c.set_attribute(Attribute::int("label", (0..n).map(|i| i as i64 - 50)))
        .unwrap();
    c.set_attribute(Attribute {
        name: "distance".into(),
        kind: ScalarKind::F64,
        values: (0..n).map(|i| (i as f64).sqrt()).collect(),
    })
    .unwrap();
    c.set_attribute(Attribute {
        name: "intensity".into(),
        kind: ScalarKind::U16,
        values: (0..n).map(|i| (i * 97 % 65536) as f64).collect(),
    })
    .unwrap();
    c.set_attribute(Attribute {
        name: "classification".into(),
        kind: ScalarKind::U8,
        values: (0..n).map(|i| (i % 20) as f64).collect(),
    })
    .unwrap();
    c
}

fn diag(c: &PointCloud) -> f64 {
    let b = c.aabb().unwrap();
    (0..3)
        .map(|k| (b.max[k] - b.min[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn f32r(v: f64) -> f64 {
    v as f32 as f64
}

#[test]
fn kinect_pcds_load_with_missing_points_dropped() {
    let Some(dir) = common::data_dir() else {
        return;
    };
    for name in ["learn33.pcd", "test0.pcd", "test1.pcd", "test16.pcd"] {
        let path = dir.join("scans/kinect-mosd").join(name);
        let t = std::time::Instant::now();
        let (g, r) = io::read(&path, &ReadOptions::default()).unwrap();
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let n = g.points.len();
        eprintln!(
            "{name}: {n} points, {} missing, {ms:.1} ms, encoding {}, notes {:?}",
            r.dropped_missing, r.encoding, r.notes
        );
        assert!(n > 100_000 && n < 307_200, "{name}: {n} points");
        assert_eq!(n + r.dropped_missing, 640 * 480, "{name}");
        assert_eq!(r.dropped_nonfinite, 0, "{name}");
        assert!(
            r.encoding.starts_with("binary_compressed"),
            "{}",
            r.encoding
        );
        assert!(g
            .points
            .positions
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite())));
        let colors = g.points.colors.as_ref().expect("colours");
        assert_eq!(colors.len(), n);
        // A real RGB scene: not all one colour.
        assert!(colors.iter().any(|c| *c != colors[0]), "{name}");
        let label = g.points.attribute("label").expect("label field");
        assert_eq!(label.kind, ScalarKind::U32);
        // Kinect depth: points lie in front of the sensor, within a few metres.
        assert!(g.points.positions.iter().all(|p| p[2] > 0.2 && p[2] < 10.0));
    }
}

fn check_pcd_roundtrip(c: &PointCloud, back: &PointCloud, f32_pos: bool) {
    assert_eq!(back.len(), c.len());
    for (a, b) in c.positions.iter().zip(&back.positions) {
        for k in 0..3 {
            let want = if f32_pos { f32r(a[k]) } else { a[k] };
            assert_eq!(b[k], want);
        }
    }
    if f32_pos {
        let tol = 1e-6 * diag(c);
        for (a, b) in c.positions.iter().zip(&back.positions) {
            assert!((0..3).all(|k| (a[k] - b[k]).abs() <= tol));
        }
    }
    let (na, nb) = (c.normals.as_ref().unwrap(), back.normals.as_ref().unwrap());
    for (a, b) in na.iter().zip(nb) {
        assert_eq!(*b, a.map(f32r));
    }
    assert_eq!(back.colors, c.colors);
    for a in &c.attributes {
        let b = back.attribute(&a.name).expect(&a.name);
        assert_eq!(b.kind, a.kind, "{}", a.name);
        let want: Vec<f64> = match a.kind {
            ScalarKind::F32 => a.values.iter().map(|&v| f32r(v)).collect(),
            _ => a.values.clone(),
        };
        assert_eq!(b.values, want, "{}", a.name);
    }
}

#[test]
fn pcd_binary_and_ascii_round_trip() {
    let dir = common::tempdir();
    let c = sample_cloud(1000, 0.0);
    let g = Geometry::from_cloud(c.clone());
    for ascii in [false, true] {
        let p = dir.path().join(if ascii { "a.pcd" } else { "b.pcd" });
        io::write(&p, &g, &WriteOptions { ascii }).unwrap();
        let text = std::fs::read(&p).unwrap();
        let head = String::from_utf8_lossy(&text[..400.min(text.len())]);
        assert!(head.contains(if ascii { "DATA ascii" } else { "DATA binary" }));
        assert!(head.contains("SIZE 4 4 4 4 4 4 4 4 1 4 8 2 1"), "{head}");
        let (back, r) = io::read_cloud(&p, &ReadOptions::default()).unwrap();
        assert_eq!(r.dropped_missing + r.dropped_nonfinite, 0);
        check_pcd_roundtrip(&c, &back, true);
    }
}

#[test]
fn pcd_far_from_origin_uses_doubles() {
    let dir = common::tempdir();
    // At 5e5 an f32 step is 0.03, far more than 1e-6 of the 2-unit diagonal.
    let c = sample_cloud(300, 5.0e5);
    for ascii in [false, true] {
        let p = dir.path().join("far.pcd");
        io::write(
            &p,
            &Geometry::from_cloud(c.clone()),
            &WriteOptions { ascii },
        )
        .unwrap();
        let text = std::fs::read(&p).unwrap();
        assert!(String::from_utf8_lossy(&text[..400]).contains("SIZE 8 8 8 4"));
        let (back, _) = io::read_cloud(&p, &ReadOptions::default()).unwrap();
        check_pcd_roundtrip(&c, &back, false);
    }
}

/// Encodes a PCD `binary_compressed` file by hand: fields laid out one after the other
/// (structure of arrays), LZF-compressed, with the two u32 sizes in front.
fn write_compressed(path: &Path, pts: &[[f32; 3]], rgb: &[u32], label: &[u16], w: usize, h: usize) {
    let n = pts.len();
    let mut soa = Vec::new();
    for k in 0..3 {
        for p in pts {
            soa.extend_from_slice(&p[k].to_le_bytes());
        }
    }
    for c in rgb {
        soa.extend_from_slice(&c.to_le_bytes());
    }
    for l in label {
        soa.extend_from_slice(&l.to_le_bytes());
    }
    let z = lzf::compress(&soa).unwrap();
    let mut f = format!(
        "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgba label\nSIZE 4 4 4 4 2\nTYPE F F F U U\n\
         COUNT 1 1 1 1 1\nWIDTH {w}\nHEIGHT {h}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\n\
         DATA binary_compressed\n"
    )
    .into_bytes();
    f.extend_from_slice(&(z.len() as u32).to_le_bytes());
    f.extend_from_slice(&(soa.len() as u32).to_le_bytes());
    f.extend_from_slice(&z);
    std::fs::write(path, f).unwrap();
}

#[test]
fn pcd_binary_compressed_hand_encoded() {
    let dir = common::tempdir();
    let (w, h) = (40usize, 25usize);
    let n = w * h;
    let pts: Vec<[f32; 3]> = (0..n)
        .map(|i| {
            if i % 7 == 3 {
                [f32::NAN; 3]
            } else {
                [
                    (i % w) as f32 * 0.01,
                    (i / w) as f32 * 0.01,
                    1.0 + (i % 5) as f32 * 0.001,
                ]
            }
        })
        .collect();
    // Bytes B G R A, as PCL packs them.
    let rgb: Vec<u32> = (0..n)
        .map(|i| {
            u32::from_le_bytes([
                (i % 256) as u8,
                (i * 3 % 256) as u8,
                (i * 5 % 256) as u8,
                255,
            ])
        })
        .collect();
    let label: Vec<u16> = (0..n).map(|i| (i * 11 % 65536) as u16).collect();
    let p = dir.path().join("c.pcd");
    write_compressed(&p, &pts, &rgb, &label, w, h);
    let (g, r) = io::read(&p, &ReadOptions::default()).unwrap();
    let keep: Vec<usize> = (0..n).filter(|i| i % 7 != 3).collect();
    assert_eq!(r.dropped_missing, n - keep.len());
    assert_eq!(r.dropped_nonfinite, 0);
    assert_eq!(g.points.len(), keep.len());
    for (j, &i) in keep.iter().enumerate() {
        assert_eq!(g.points.positions[j], pts[i].map(f64::from));
        assert_eq!(
            g.points.colors.as_ref().unwrap()[j],
            [(i * 5 % 256) as u8, (i * 3 % 256) as u8, (i % 256) as u8]
        );
        assert_eq!(
            g.points.attribute("label").unwrap().values[j],
            label[i] as f64
        );
    }
    assert_eq!(g.points.attribute("label").unwrap().kind, ScalarKind::U16);

    // Unorganised (HEIGHT 1): NaN points are not "missing" but non-finite.
    let p1 = dir.path().join("c1.pcd");
    write_compressed(&p1, &pts, &rgb, &label, n, 1);
    let (g1, r1) = io::read(&p1, &ReadOptions::default()).unwrap();
    assert_eq!(r1.dropped_missing, 0);
    assert_eq!(r1.dropped_nonfinite, n - keep.len());
    assert_eq!(g1.points.positions, g.points.positions);
}

#[cfg(feature = "las")]
#[test]
fn las_and_laz_round_trip() {
    let dir = common::tempdir();
    let c = sample_cloud(2000, 1234.5);
    let g = Geometry::from_cloud(c.clone());
    let step = crease::io::las::scale_for_diagonal(diag(&c));
    assert!(step / 2.0 <= 1e-6 * diag(&c));
    for name in ["r.las", "r.laz"] {
        let p = dir.path().join(name);
        io::write(&p, &g, &WriteOptions::default()).unwrap();
        let (back, r) = io::read_cloud(&p, &ReadOptions::default()).unwrap();
        assert!(r.encoding.contains("point format 2"), "{}", r.encoding);
        assert_eq!(r.encoding.starts_with("LAZ"), name.ends_with(".laz"));
        assert_eq!(back.len(), c.len());
        for (a, b) in c.positions.iter().zip(&back.positions) {
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() <= step * 0.5 + 1e-9, "{a:?} {b:?}");
            }
        }
        assert_eq!(back.colors, c.colors);
        for name in ["classification", "intensity"] {
            assert_eq!(
                back.attribute(name).unwrap().values,
                c.attribute(name).unwrap().values,
                "{name}"
            );
        }
        assert_eq!(
            back.attribute("classification").unwrap().kind,
            ScalarKind::U8
        );
        assert_eq!(back.attribute("intensity").unwrap().kind, ScalarKind::U16);
        assert!(back.attribute("gps_time").is_none());
    }
}

#[cfg(feature = "las")]
#[test]
fn las_extended_classes_and_gps_time() {
    let dir = common::tempdir();
    let mut c = PointCloud::from_positions((0..100).map(|i| [i as f64, 0.5, -2.0]).collect());
    c.set_attribute(Attribute {
        name: "classification".into(),
        kind: ScalarKind::U8,
        values: (0..100).map(|i| (i * 3 % 256) as f64).collect(),
    })
    .unwrap();
    c.set_attribute(Attribute {
        name: "gps_time".into(),
        kind: ScalarKind::F64,
        values: (0..100).map(|i| 1000.0 + i as f64 * 0.5).collect(),
    })
    .unwrap();
    let p = dir.path().join("x.laz");
    io::write(
        &p,
        &Geometry::from_cloud(c.clone()),
        &WriteOptions::default(),
    )
    .unwrap();
    let (back, r) = io::read_cloud(&p, &ReadOptions::default()).unwrap();
    assert!(r.encoding.contains("point format 6"), "{}", r.encoding);
    assert_eq!(back.colors, None);
    for name in ["classification", "gps_time"] {
        assert_eq!(
            back.attribute(name).unwrap().values,
            c.attribute(name).unwrap().values
        );
    }
}

#[cfg(feature = "e57")]
#[test]
fn e57_round_trip() {
    let dir = common::tempdir();
    let c = sample_cloud(1500, -3.25);
    let p = dir.path().join("r.e57");
    io::write(
        &p,
        &Geometry::from_cloud(c.clone()),
        &WriteOptions::default(),
    )
    .unwrap();
    let (back, r) = io::read_cloud(&p, &ReadOptions::default()).unwrap();
    assert_eq!(back.positions, c.positions);
    assert_eq!(back.colors, c.colors);
    let want: Vec<f64> = c
        .attribute("intensity")
        .unwrap()
        .values
        .iter()
        .map(|&v| f32r(v))
        .collect();
    assert_eq!(back.attribute("intensity").unwrap().values, want);
    assert_eq!(r.dropped_missing, 0);
    assert!(
        r.notes.iter().any(|n| n.starts_with("1 scan")),
        "{:?}",
        r.notes
    );
    // The same cloud gives the same file.
    let p2 = dir.path().join("r2.e57");
    io::write(&p2, &Geometry::from_cloud(c), &WriteOptions::default()).unwrap();
    assert_eq!(std::fs::read(&p).unwrap(), std::fs::read(&p2).unwrap());
}

/// Reading `path` fails with a message naming the file and containing every word of `words`.
fn assert_bad(path: &Path, words: &[&str]) {
    let err = io::read(path, &ReadOptions::default())
        .err()
        .unwrap_or_else(|| panic!("{} was accepted", path.display()));
    let msg = err.to_string();
    let file = path.file_name().unwrap().to_str().unwrap();
    assert!(msg.contains(file), "message does not name the file: {msg}");
    for w in words {
        assert!(msg.contains(w), "message lacks {w:?}: {msg}");
    }
}

#[test]
fn bad_pcd_points_larger_than_data() {
    assert_bad(
        &bad("pcd-points-larger-than-data.pcd"),
        &["POINTS 1000", "truncated"],
    );
}

#[test]
fn bad_pcd_truncated_compressed() {
    assert_bad(
        &bad("pcd-truncated-compressed.pcd"),
        &["truncated binary_compressed"],
    );
}

#[test]
fn bad_pcd_unknown_data_kind() {
    assert_bad(
        &bad("pcd-unknown-data-kind.pcd"),
        &["unknown data kind", "binary_lzma"],
    );
}

#[test]
fn bad_pcd_fields_size_mismatch() {
    assert_bad(
        &bad("pcd-fields-size-mismatch.pcd"),
        &["line 4 (SIZE)", "mismatched"],
    );
}

#[test]
fn bad_pcd_non_numeric_ascii() {
    assert_bad(
        &bad("pcd-non-numeric-ascii.pcd"),
        &["point 1", "non-numeric", "\"abc\""],
    );
}

#[cfg(feature = "las")]
#[test]
fn bad_las_truncated() {
    assert_bad(&bad("las-truncated.las"), &["1000 points", "truncated"]);
}

#[cfg(feature = "e57")]
#[test]
fn bad_e57_garbage() {
    assert_bad(&bad("e57-garbage.e57"), &["not a readable E57"]);
}

/// Files cut short at many lengths: always an error naming the file, never a panic.
#[test]
fn truncated_files_fail_cleanly() {
    let dir = common::tempdir();
    let g = Geometry::from_cloud(sample_cloud(500, 0.0));
    let mut names = vec!["t.pcd"];
    if cfg!(feature = "las") {
        names.extend(["t.las", "t.laz"]);
    }
    if cfg!(feature = "e57") {
        names.push("t.e57");
    }
    for name in names {
        let p = dir.path().join(name);
        io::write(&p, &g, &WriteOptions::default()).unwrap();
        let full = std::fs::read(&p).unwrap();
        let cut = dir.path().join(format!("cut-{name}"));
        for frac in [0.0, 0.01, 0.1, 0.3, 0.5, 0.9, 0.99] {
            let len = (full.len() as f64 * frac) as usize;
            std::fs::write(&cut, &full[..len]).unwrap();
            let err = io::read(&cut, &ReadOptions::default())
                .err()
                .unwrap_or_else(|| panic!("{name} cut to {len} bytes was accepted"));
            assert!(err.to_string().contains("cut-"), "{err}");
        }
    }
}

/// Bytes overwritten at many places (header and data, all three PCD data kinds): reading may
/// succeed or fail, but never panics.
#[test]
fn corrupted_pcds_never_panic() {
    let dir = common::tempdir();
    let c = sample_cloud(300, 0.0);
    let mut files = Vec::new();
    for ascii in [false, true] {
        let p = dir.path().join(format!("k{ascii}.pcd"));
        io::write(
            &p,
            &Geometry::from_cloud(c.clone()),
            &WriteOptions { ascii },
        )
        .unwrap();
        files.push(std::fs::read(&p).unwrap());
    }
    let p = dir.path().join("kc.pcd");
    let pts: Vec<[f32; 3]> = (0..300).map(|i| [i as f32, 0.5, -1.0]).collect();
    write_compressed(&p, &pts, &[7u32; 300], &[3u16; 300], 20, 15);
    files.push(std::fs::read(&p).unwrap());
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let cut = dir.path().join("mut.pcd");
    for full in &files {
        for _ in 0..150 {
            let mut f = full.clone();
            for _ in 0..1 + next() % 4 {
                // Half the hits in the header, where counts and sizes live.
                let at = if next() % 2 == 0 {
                    next() as usize % 300
                } else {
                    next() as usize
                };
                let at = at % f.len();
                f[at] = match next() % 4 {
                    0 => b'9',
                    1 => 0xff,
                    2 => b' ',
                    _ => next() as u8,
                };
            }
            std::fs::write(&cut, &f).unwrap();
            let _ = io::read(&cut, &ReadOptions::default());
        }
    }
}
