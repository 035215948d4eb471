//! Sharp points tile by tile (`crease::sharp::tiled`): a cloud cut into tiles with the halo of
//! `halo_width` gives the labels of one run over the whole cloud, exactly, for tran's detector
//! (clean and noisy clouds, repeated points included); the global quantities merge exactly.

use crate::common;

use crease::geometry::Point3;
use crease::sharp::tiled::{
    halo_width, label_tile, merge_ranges, ratio_of_samples, thresholds, tile_histograms,
    tile_measures, tile_noise_samples, Tile,
};
use crease::sharp::{detect_points, SharpParams, SharpResult};

/// Cuts `points` into `nx` slabs along x with a halo of `halo`: per slab its point indices
/// and core flags.
fn slabs(points: &[Point3], nx: usize, halo: f64) -> Vec<(Vec<usize>, Vec<bool>)> {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p[0]), b.max(p[0]))
        });
    let w = (hi - lo) / nx as f64;
    let slab = |x: f64| (((x - lo) / w) as usize).min(nx - 1);
    (0..nx)
        .map(|t| {
            let (a, b) = (lo + t as f64 * w, lo + (t + 1) as f64 * w);
            let mut idx = Vec::new();
            let mut core = Vec::new();
            for (i, p) in points.iter().enumerate() {
                if slab(p[0]) == t {
                    idx.push(i);
                    core.push(true);
                } else if p[0] >= a - halo && p[0] <= b + halo {
                    idx.push(i);
                    core.push(false);
                }
            }
            (idx, core)
        })
        .collect()
}

type Slab = (Vec<Point3>, Vec<bool>, Vec<usize>);

fn tile(t: &Slab) -> Tile<'_> {
    Tile {
        points: &t.0,
        core: &t.1,
    }
}

/// The four passes over the tiles, and each point's label from the tile whose core holds it.
fn tiled(points: &[Point3], nx: usize, halo: f64, params: &SharpParams) -> SharpResult {
    let tiles: Vec<Slab> = slabs(points, nx, halo)
        .into_iter()
        .map(|(idx, core)| (idx.iter().map(|&i| points[i]).collect(), core, idx))
        .collect();

    let mut samples: Vec<(f64, f64)> = tiles
        .iter()
        .flat_map(|t| tile_noise_samples(&tile(t), points.len()).expect("noise"))
        .collect();
    let ratio = ratio_of_samples(&mut samples);
    let measures: Vec<_> = tiles
        .iter()
        .map(|t| tile_measures(&tile(t), ratio, params).expect("measures"))
        .collect();
    let ranges = merge_ranges(measures.iter().map(|m| m.ranges.as_slice()));
    let hists: Vec<_> = tiles
        .iter()
        .zip(&measures)
        .map(|(t, m)| tile_histograms(&tile(t), &m.values, &ranges, params).expect("hist"))
        .collect();
    let th = thresholds(&hists, &ranges, params).expect("thresholds");
    let mut out = SharpResult {
        sharp: vec![false; points.len()],
        sharpness: vec![f64::NAN; points.len()],
        scales: Vec::new(),
        noise_ratio: Some(ratio),
        regularized: false,
        surfaces: None,
    };
    for (t, m) in tiles.iter().zip(&measures) {
        let r = label_tile(&tile(t), &m.values, &th, ratio, params).expect("labels");
        out.regularized = r.regularized;
        out.scales = r.scales.clone();
        for (j, &i) in t.2.iter().enumerate() {
            if t.1[j] {
                out.sharp[i] = r.sharp[j];
                out.sharpness[i] = r.sharpness[j];
            }
        }
    }
    out
}

fn check(name: &str, n: usize, noise: f64, repeat: bool) {
    let part = common::noisy_part(name, n, noise);
    let mut points = part.cloud.positions.clone();
    if repeat {
        // Every 7th point twice (the analysis counts a point once).
        let extra: Vec<Point3> = points.iter().step_by(7).copied().collect();
        points.extend(extra);
    }
    let params = SharpParams {
        surfaces: None,
        ..Default::default()
    };
    let whole = detect_points(&points, &params).expect("whole");
    let spacing = crease::spatial::spacing::average_spacing(&points).expect("spacing");
    let t = tiled(&points, 3, halo_width(spacing, &params), &params);
    assert_eq!(t.noise_ratio, whole.noise_ratio, "{name}: noise ratio");
    assert_eq!(t.regularized, whole.regularized);
    for (a, b) in t.scales.iter().zip(&whole.scales) {
        assert_eq!(
            (a.threshold, a.normalized_threshold),
            (b.threshold, b.normalized_threshold)
        );
    }
    let differ = (0..points.len())
        .filter(|&i| t.sharp[i] != whole.sharp[i])
        .count();
    let sharp = whole.sharp.iter().filter(|&&s| s).count();
    assert!(sharp > 100, "{name}: {sharp} sharp points");
    if whole.regularized {
        // The Potts labelling is a minimum cut per tile: not local, measured instead.
        assert!(differ * 100 <= sharp, "{name}: {differ} of {sharp} differ");
    } else {
        assert_eq!(
            differ, 0,
            "{name}: {differ} labels differ from the whole run's"
        );
        assert_eq!(t.sharpness, whole.sharpness);
    }
}

#[test]
fn tiles_give_the_whole_clouds_labels() {
    check("fillet-chamfer-cone", 60_000, 0.0, false);
    check("two-cylinders", 40_000, 0.0, true);
}

#[test]
fn tiles_on_a_noisy_cloud() {
    check("cube", 40_000, 0.5, false);
}

/// `crease::io::tiles::split` (PLY read whole, LAS streamed): every point in the core of exactly
/// one tile, and in the halo of every other tile whose cell lies within the halo along each axis.
#[test]
fn split_into_tile_files() {
    use crease::io::tiles::{split, TileSpec};
    use crease::io::{read, write, Geometry, ReadOptions, WriteOptions};
    let dir = common::tempdir();
    let part = common::noisy_part("fillet-chamfer-cone", 20_000, 0.0);
    for ext in ["ply", "las"] {
        let src = dir.path().join(format!("part.{ext}"));
        write(
            &src,
            &Geometry::from_cloud(crease::PointCloud::from_positions(
                part.cloud.positions.clone(),
            )),
            &WriteOptions::default(),
        )
        .expect("write");
        let points = read(&src, &ReadOptions::default())
            .expect("read")
            .0
            .points
            .positions;
        let spec = TileSpec {
            size: 0.4,
            halo: 0.05,
        };
        let t = split(&src, &dir.path().join(format!("tiles-{ext}")), spec).expect("split");
        assert_eq!(t.points, points.len());
        assert!(t.tiles.len() >= 8, "{ext}: {} tiles", t.tiles.len());
        let mut core_of = vec![0usize; points.len()];
        let mut held = 0;
        for tile in &t.tiles {
            let g = read(&tile.path, &ReadOptions::default())
                .expect("tile")
                .0
                .points;
            let index = &g.attribute("index").expect("index").values;
            let core = &g.attribute("core").expect("core").values;
            assert_eq!(
                (g.len(), core.iter().filter(|&&c| c > 0.0).count()),
                (tile.points, tile.core)
            );
            let lo = [0, 1, 2].map(|a| t.origin[a] + tile.cell[a] as f64 * spec.size);
            for ((p, &i), &c) in g.positions.iter().zip(index).zip(core) {
                assert_eq!(*p, points[i as usize], "{ext}: positions kept exactly");
                for a in 0..3 {
                    let within = p[a] >= lo[a] - spec.halo - 1e-12
                        && (p[a] <= lo[a] + spec.size + spec.halo + 1e-12
                            || tile.cell[a] + 1 == t.grid[a]);
                    assert!(
                        within || tile.cell[a] == 0,
                        "{ext}: point {i} outside the tile"
                    );
                }
                if c > 0.0 {
                    core_of[i as usize] += 1;
                }
            }
            held += g.len();
        }
        assert!(
            core_of.iter().all(|&c| c == 1),
            "{ext}: each point in one core"
        );
        assert!(held > points.len(), "{ext}: halos hold copies");
    }
}
