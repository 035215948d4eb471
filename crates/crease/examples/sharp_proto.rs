//! Prototype of one-face neighbourhoods for the projected distance (issue 3, thin plates).
//!
//! `cargo run --release -p crease --example sharp_proto -- [mode=plain|oracle|oraclen|side]
//! [K=40] [grow] [alpha=20] [beta=15] [ks=8] [sets=abc,abc-noisy]`

use std::path::PathBuf;

use crease::estimate::normals::smallest_eigen;
use crease::geometry::{vec3, Point3};
use crease::io::{read, ReadOptions};
use crease::sharp::{relabel_points, SharpParams, CLOUD_SCALES};
use crease::spatial::knn;
use crease::threshold::otsu;
use rayon::prelude::*;

fn mcc(pred: &[bool], truth: &[bool]) -> f64 {
    let (mut tp, mut fp, mut tn, mut fnn) = (0f64, 0f64, 0f64, 0f64);
    for (&p, &t) in pred.iter().zip(truth) {
        match (p, t) {
            (true, true) => tp += 1.0,
            (true, false) => fp += 1.0,
            (false, false) => tn += 1.0,
            (false, true) => fnn += 1.0,
        }
    }
    let d = ((tp + fp) * (tp + fnn) * (tn + fp) * (tn + fnn)).sqrt();
    if d > 0.0 {
        (tp * tn - fp * fnn) / d
    } else {
        0.0
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// PCA of p and the given points: (normal, eigenvalues, centroid offset c - p, rms radius).
fn pca(p: Point3, q: impl Iterator<Item = Point3>) -> (Point3, [f64; 3], Point3, f64) {
    let (mut s1, mut s2, mut m) = ([0.0f64; 3], [0.0f64; 6], 1usize);
    for x in q {
        let d = vec3::sub(x, p);
        s1 = vec3::add(s1, d);
        s2[0] += d[0] * d[0];
        s2[1] += d[0] * d[1];
        s2[2] += d[0] * d[2];
        s2[3] += d[1] * d[1];
        s2[4] += d[1] * d[2];
        s2[5] += d[2] * d[2];
        m += 1;
    }
    let inv = 1.0 / m as f64;
    let c = vec3::scale(s1, inv);
    let cov = [
        s2[0] * inv - c[0] * c[0],
        s2[1] * inv - c[0] * c[1],
        s2[2] * inv - c[0] * c[2],
        s2[3] * inv - c[1] * c[1],
        s2[4] * inv - c[1] * c[2],
        s2[5] * inv - c[2] * c[2],
    ];
    let (n, e) = smallest_eigen(cov);
    (n, e, c, (cov[0] + cov[3] + cov[5]).max(0.0).sqrt())
}

#[derive(Clone)]
struct Opt {
    mode: String,
    kcand: usize,
    grow: bool,
    alpha: f64,
    beta: f64,
    ks: usize,
    refine: usize,
    ransac: usize,
    tol: f64,
    iter: usize,
    k2: usize,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut o = Opt {
        mode: "plain".into(),
        kcand: 40,
        grow: false,
        alpha: 20.0,
        beta: 15.0,
        ks: 8,
        refine: 1,
        ransac: 0,
        tol: 0.0,
        iter: 0,
        k2: 12,
    };
    let mut sets: Vec<String> = vec!["abc".into(), "abc-noisy".into()];
    let mut verbose = false;
    let mut out: Option<PathBuf> = None;
    for a in &args {
        if let Some(v) = a.strip_prefix("mode=") {
            o.mode = v.into();
        } else if let Some(v) = a.strip_prefix("K=") {
            o.kcand = v.parse()?;
        } else if a == "grow" {
            o.grow = true;
        } else if let Some(v) = a.strip_prefix("out=") {
            out = Some(PathBuf::from(v));
        } else if a == "v" {
            verbose = true;
        } else if let Some(v) = a.strip_prefix("alpha=") {
            o.alpha = v.parse()?;
        } else if let Some(v) = a.strip_prefix("beta=") {
            o.beta = v.parse()?;
        } else if let Some(v) = a.strip_prefix("ks=") {
            o.ks = v.parse()?;
        } else if let Some(v) = a.strip_prefix("ransac=") {
            o.ransac = v.parse()?;
        } else if let Some(v) = a.strip_prefix("tol=") {
            o.tol = v.parse()?;
        } else if let Some(v) = a.strip_prefix("iter=") {
            o.iter = v.parse()?;
        } else if let Some(v) = a.strip_prefix("k2=") {
            o.k2 = v.parse()?;
        } else if let Some(v) = a.strip_prefix("refine=") {
            o.refine = v.parse()?;
        } else if let Some(s) = a.strip_prefix("sets=") {
            sets = s.split(',').map(String::from).collect();
        }
    }
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/points-gt");
    for set in &sets {
        let mut names: Vec<_> = std::fs::read_dir(root.join(set))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .collect();
        names.sort();
        let mut mccs = Vec::new();
        for path in names {
            let (g, _) = read(&path, &ReadOptions::default())?;
            let cloud = g.points;
            let colors = cloud.colors.clone().ok_or("no colours")?;
            let gt_n = cloud.normals.clone().ok_or("no normals")?;
            let truth: Vec<bool> = colors
                .iter()
                .map(|c| matches!(c, [168, 0, 0] | [255, 0, 0]))
                .collect();
            let pts = &cloud.positions;
            let t0 = std::time::Instant::now();
            let kmax = 40usize;
            let nb = knn(pts, o.kcand.max(kmax))?;
            // Small-scale normals.
            let mut small: Vec<Point3> = (0..pts.len())
                .into_par_iter()
                .map(|i| {
                    let p = pts[i];
                    let row = nb.prefix(i, o.ks);
                    let (mut n, ..) = pca(p, row.iter().map(|&j| pts[j as usize]));
                    if o.ransac > 0 {
                        let sb = o.beta.to_radians().sin();
                        let cand = nb.prefix(i, o.ransac);
                        let test = nb.prefix(i, 2 * o.ransac);
                        let mut best = (0usize, f64::INFINITY);
                        let d1 = vec3::dist(p, pts[cand[0] as usize]);
                        for a in 0..cand.len() {
                            for b in a + 1..cand.len() {
                                let da = vec3::sub(pts[cand[a] as usize], p);
                                let db = vec3::sub(pts[cand[b] as usize], p);
                                let Some(m) = vec3::normalize(vec3::cross(da, db)) else {
                                    continue;
                                };
                                // Reject near-collinear pairs.
                                if vec3::norm(vec3::cross(da, db))
                                    < 0.3 * vec3::norm(da) * vec3::norm(db)
                                {
                                    continue;
                                }
                                let mut inl = 0usize;
                                let mut res = 0.0;
                                for &j in test {
                                    let d = vec3::sub(pts[j as usize], p);
                                    let h = vec3::dot(d, m).abs();
                                    let lim = if o.tol > 0.0 {
                                        o.tol * d1
                                    } else {
                                        sb * vec3::norm(d)
                                    };
                                    if h <= lim {
                                        inl += 1;
                                        res += h;
                                    }
                                }
                                if inl > best.0 || (inl == best.0 && res < best.1) {
                                    best = (inl, res);
                                    n = m;
                                }
                            }
                        }
                    }
                    for _ in 0..o.refine {
                        // Keep the neighbours among 2 ks whose chord is within beta of the plane.
                        let sb = o.beta.to_radians().sin();
                        let row2 = nb.prefix(i, 2 * o.ks);
                        let keep: Vec<Point3> = row2
                            .iter()
                            .map(|&j| pts[j as usize])
                            .filter(|q| {
                                let d = vec3::sub(*q, p);
                                let d1 = vec3::dist(p, pts[row[0] as usize]);
                                let lim = if o.tol > 0.0 && o.ransac > 0 {
                                    o.tol * d1
                                } else {
                                    sb * vec3::norm(d)
                                };
                                vec3::dot(d, n).abs() <= lim
                            })
                            .collect();
                        if keep.len() >= 3 {
                            n = pca(p, keep.into_iter()).0;
                        }
                    }
                    n
                })
                .collect();
            let ca = o.alpha.to_radians().cos();
            let sb = o.beta.to_radians().sin();
            let side_keep = |small: &[Point3], i: usize, j: usize| -> bool {
                let d = vec3::sub(pts[j], pts[i]);
                let (ni, nj) = (small[i], small[j]);
                let len = vec3::norm(d);
                let par = vec3::dot(ni, nj).abs() >= ca;
                let off = vec3::dot(d, ni).abs() > sb * len && vec3::dot(d, nj).abs() > sb * len;
                !(par && off)
            };
            for _ in 0..o.iter {
                let next: Vec<Point3> = (0..pts.len())
                    .into_par_iter()
                    .map(|i| {
                        let row = nb.prefix(i, o.k2);
                        pca(
                            pts[i],
                            row.iter()
                                .filter(|&&j| side_keep(&small, i, j as usize))
                                .map(|&j| pts[j as usize]),
                        )
                        .0
                    })
                    .collect();
                small = next;
            }
            let keep = |i: usize, j: usize| -> bool {
                let d = vec3::sub(pts[j], pts[i]);
                match o.mode.as_str() {
                    "oracle" => {
                        let h = vec3::dist(pts[i], pts[nb.of(i)[0] as usize]);
                        !(vec3::dot(gt_n[i], gt_n[j]) < -0.5 && vec3::dot(d, gt_n[i]) < -0.5 * h)
                    }
                    "oraclen" | "side" => {
                        let (ni, nj) = if o.mode == "oraclen" {
                            (gt_n[i], gt_n[j])
                        } else {
                            (small[i], small[j])
                        };
                        let len = vec3::norm(d);
                        let par = vec3::dot(ni, nj).abs() >= ca;
                        let off =
                            vec3::dot(d, ni).abs() > sb * len && vec3::dot(d, nj).abs() > sb * len;
                        !(par && off)
                    }
                    _ => true,
                }
            };
            if verbose {
                // Filter accuracy against the stored normals over the 40 nearest.
                let (mut drop_opp, mut drop_other, mut keep_opp, mut opp_all) =
                    (0usize, 0usize, 0usize, 0usize);
                let mut nerr = 0usize;
                for i in 0..pts.len() {
                    if vec3::dot(small[i], gt_n[i]).abs() < 20f64.to_radians().cos() {
                        nerr += 1;
                    }
                    let h = vec3::dist(pts[i], pts[nb.of(i)[0] as usize]);
                    for &j in nb.prefix(i, 40) {
                        let j = j as usize;
                        let d = vec3::sub(pts[j], pts[i]);
                        let opp = vec3::dot(gt_n[i], gt_n[j]) < -0.5
                            && vec3::dot(d, gt_n[i]).abs() > 0.5 * h;
                        let k = keep(i, j);
                        opp_all += opp as usize;
                        match (opp, k) {
                            (true, false) => drop_opp += 1,
                            (false, false) => drop_other += 1,
                            (true, true) => keep_opp += 1,
                            _ => {}
                        }
                    }
                }
                let tot = (pts.len() * 40) as f64;
                println!("  normals >20deg off: {:.1}%  opposite {:.1}% of pairs: dropped {:.1}%, kept {:.1}%, wrongly dropped {:.1}%",
                    100.0 * nerr as f64 / pts.len() as f64, 100.0 * opp_all as f64 / tot,
                    100.0 * drop_opp as f64 / tot, 100.0 * keep_opp as f64 / tot, 100.0 * drop_other as f64 / tot);
            }
            let ns = CLOUD_SCALES.len();
            let flat: Vec<f64> = (0..pts.len())
                .into_par_iter()
                .flat_map_iter(|i| {
                    let p = pts[i];
                    let row = nb.of(i);
                    let kept: Vec<(usize, u32)> = row
                        .iter()
                        .enumerate()
                        .filter(|(_, &j)| keep(i, j as usize))
                        .map(|(r, &j)| (r, j))
                        .collect();
                    CLOUD_SCALES
                        .iter()
                        .map(|&k| {
                            let sel: Vec<Point3> = if o.grow {
                                kept.iter().take(k).map(|&(_, j)| pts[j as usize]).collect()
                            } else {
                                kept.iter()
                                    .filter(|&&(r, _)| r < k)
                                    .map(|&(_, j)| pts[j as usize])
                                    .collect()
                            };
                            let (n, _, c, rms) = pca(p, sel.into_iter());
                            let d = vec3::dot(c, n).abs();
                            if rms > 0.0 {
                                d / rms
                            } else {
                                0.0
                            }
                        })
                        .collect::<Vec<_>>()
                })
                .collect();
            let mut params = SharpParams::default();
            if crease::sharp::noise::noise_ratio(pts, &nb) > crease::sharp::noise::NOISY_RATIO {
                params.regularize = Some(crease::sharp::Regularize::noisy());
            }
            let mut th = Vec::new();
            for s in 0..ns {
                let v: Vec<f64> = flat.iter().skip(s).step_by(ns).copied().collect();
                th.push(otsu(&v, &params.otsu)?.threshold);
            }
            let sharpness: Vec<f64> = (0..pts.len())
                .map(|i| {
                    (0..ns)
                        .map(|s| flat[i * ns + s] / th[s])
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            let sharp: Vec<bool> = sharpness.iter().map(|&s| s >= 1.0).collect();
            let nb40 = if o.kcand > 40 {
                knn(pts, 40)?
            } else {
                nb.clone()
            };
            let lab = relabel_points(pts, &nb40, &sharp, &sharpness, &params)?;
            let m = mcc(&lab, &truth);
            let m_nothin = mcc(&sharp, &truth);
            {
                println!(
                    "{set}/{} pred={} mcc={m:.3} (no thin {m_nothin:.3}) {:.2}s",
                    path.file_stem().unwrap_or_default().to_string_lossy(),
                    lab.iter().filter(|&&x| x).count(),
                    t0.elapsed().as_secs_f64()
                );
            }
            if let Some(dir) = &out {
                std::fs::create_dir_all(dir)?;
                let cols: Vec<[u8; 3]> = (0..pts.len())
                    .map(|i| match (lab[i], truth[i]) {
                        (true, true) => [0, 160, 0],
                        (true, false) => [230, 0, 0],
                        (false, true) => [0, 60, 255],
                        (false, false) => [215, 215, 215],
                    })
                    .collect();
                let mut c = crease::geometry::PointCloud::from_positions(pts.clone());
                c.colors = Some(cols);
                let geom = crease::io::Geometry {
                    points: c,
                    ..Default::default()
                };
                let stem = path.file_stem().unwrap_or_default().to_string_lossy();
                crease::io::write(
                    dir.join(format!("{set}_{stem}.ply")),
                    &geom,
                    &crease::io::WriteOptions::default(),
                )?;
            }
            mccs.push(m);
        }
        println!("{set}: median MCC {:.3}", median(mccs));
    }
    Ok(())
}
