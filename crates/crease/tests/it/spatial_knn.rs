//! All-points k nearest neighbours and radius search: exactness against brute force (ties by
//! index), prefixes, input order, thread-count independence, argument errors.

use crease::geometry::Point3;
use crease::spatial::knn::{knn_map, knn_map_set, KnnQuery};
use crease::spatial::{knn, knn_with, knn_within, radius_neighbors, KnnMethod};
use crease::synth::{sample_points, Noise, SampleParams, Shape};

/// Deterministic pseudo-random numbers in [0, 1).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn below(&mut self, n: usize) -> usize {
        ((self.next() * n as f64) as usize).min(n - 1)
    }
}

fn d2(a: &Point3, b: &Point3) -> f64 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    dx * dx + dy * dy + dz * dz
}

/// Brute-force k nearest neighbours, self excluded, ties by index.
fn brute_knn(p: &[Point3], i: usize, k: usize) -> Vec<u32> {
    let mut v: Vec<(f64, u32)> = (0..p.len())
        .filter(|&j| j != i)
        .map(|j| (d2(&p[i], &p[j]), j as u32))
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    v.truncate(k);
    v.into_iter().map(|x| x.1).collect()
}

fn surface(name: &str, n: usize, seed: u64) -> Vec<Point3> {
    let shape = Shape::from_name(name).unwrap();
    sample_points(
        &shape,
        &SampleParams {
            n,
            noise: Noise::AlongNormal(0.1),
            seed,
            ..Default::default()
        },
    )
    .unwrap()
    .cloud
    .positions
}

fn random_cube(n: usize, seed: u64) -> Vec<Point3> {
    let mut r = Lcg(seed);
    (0..n).map(|_| [r.next(), r.next(), r.next()]).collect()
}

/// A 12 x 12 x 3 integer grid with every fifth point duplicated: many exact ties.
fn tie_grid() -> Vec<Point3> {
    let mut p = Vec::new();
    for z in 0..3 {
        for y in 0..12 {
            for x in 0..12 {
                p.push([x as f64, y as f64, z as f64 * 2.0]);
            }
        }
    }
    let dups: Vec<Point3> = p.iter().step_by(5).copied().collect();
    // Interleave the duplicates so they do not all have the largest indices.
    let mut out = Vec::new();
    for (i, q) in p.iter().enumerate() {
        out.push(*q);
        if i % 7 == 3 {
            out.push(dups[(i / 7) % dups.len()]);
        }
    }
    out
}

fn shuffle(p: &[Point3], seed: u64) -> (Vec<Point3>, Vec<usize>) {
    let mut perm: Vec<usize> = (0..p.len()).collect();
    let mut r = Lcg(seed);
    for i in (1..perm.len()).rev() {
        perm.swap(i, r.below(i + 1));
    }
    (perm.iter().map(|&i| p[i]).collect(), perm)
}

/// Everything [`knn_map`] hands to its closure, owned.
#[derive(Debug, Clone, PartialEq)]
struct Seen {
    index: usize,
    point: Point3,
    neighbors: Vec<Point3>,
    ids: Vec<u32>,
    dist2: Vec<f64>,
    /// How many queries this task's scratch had seen before (must not leak into results).
    calls: usize,
}

fn map_all(p: &[Point3], k: usize) -> Vec<Seen> {
    map_with(p, k, true)
}

/// [`knn_map`] (`ordered`) or [`knn_map_set`], each neighbourhood recorded.
fn map_with(p: &[Point3], k: usize, ordered: bool) -> Vec<Seen> {
    let map = if ordered {
        knn_map::<Seen, usize, fn() -> usize, fn(&mut usize, &KnnQuery) -> Seen>
    } else {
        knn_map_set::<Seen, usize, fn() -> usize, fn(&mut usize, &KnnQuery) -> Seen>
    };
    map(
        p,
        k,
        || 0usize,
        |calls: &mut usize, q: &KnnQuery| -> Seen {
            *calls += 1;
            Seen {
                index: q.index,
                point: q.point,
                neighbors: q.neighbors.to_vec(),
                ids: q.ids.to_vec(),
                dist2: q.dist2.to_vec(),
                calls: 0,
            }
        },
    )
    .unwrap()
}

fn assert_knn_map_exact(p: &[Point3], k: usize, what: &str) {
    let seen = map_all(p, k);
    assert_eq!(seen.len(), p.len());
    for (i, s) in seen.iter().enumerate() {
        let expect = brute_knn(p, i, k);
        assert_eq!(s.index, i, "{what}: k = {k}, point {i}");
        assert_eq!(s.point, p[i]);
        assert_eq!(s.ids, expect, "{what}: k = {k}, knn_map, point {i}");
        let pts: Vec<Point3> = expect.iter().map(|&j| p[j as usize]).collect();
        assert_eq!(s.neighbors, pts);
        let d: Vec<f64> = pts.iter().map(|q| d2(&p[i], q)).collect();
        assert_eq!(s.dist2, d);
    }
    // The set variant: the same neighbours in some order, the slices consistent.
    for (i, s) in map_with(p, k, false).iter().enumerate() {
        assert_eq!(s.index, i);
        assert_eq!(s.point, p[i]);
        let mut got = s.ids.clone();
        got.sort_unstable();
        let mut expect = brute_knn(p, i, k);
        expect.sort_unstable();
        assert_eq!(got, expect, "{what}: k = {k}, knn_map_set, point {i}");
        for ((&id, q), &d) in s.ids.iter().zip(&s.neighbors).zip(&s.dist2) {
            assert_eq!(*q, p[id as usize]);
            assert_eq!(d, d2(&p[i], q));
        }
    }
}

fn assert_knn_exact(p: &[Point3], k: usize, what: &str) {
    assert_knn_map_exact(p, k, what);
    for method in [KnnMethod::Grid, KnnMethod::KdTree, KnnMethod::KdTreeMorton] {
        let nb = knn_with(p, k, method).unwrap();
        assert_eq!(nb.len(), p.len());
        assert_eq!(nb.k(), k);
        for i in 0..p.len() {
            assert_eq!(
                nb.of(i),
                brute_knn(p, i, k).as_slice(),
                "{what}: k = {k}, {method:?}, point {i}"
            );
        }
    }
}

#[test]
fn knn_equals_brute_force_on_random_points() {
    let p = random_cube(1500, 3);
    for k in [1, 6, 20] {
        assert_knn_exact(&p, k, "random cube");
    }
}

#[test]
fn knn_equals_brute_force_on_surfaces() {
    for (name, seed) in [("cube", 1), ("cylinder", 2), ("box-hole", 3)] {
        let p = surface(name, 2500, seed);
        for k in [4, 20, 31] {
            assert_knn_exact(&p, k, name);
        }
    }
}

#[test]
fn knn_equals_brute_force_with_duplicates_and_ties() {
    let p = tie_grid();
    for k in [1, 4, 6, 9, 26, 40] {
        assert_knn_exact(&p, k, "tie grid");
    }
    // All points equal: the k smallest other indices.
    let same = vec![[0.5, -2.0, 3.0]; 30];
    let nb = knn(&same, 5).unwrap();
    assert_eq!(nb.of(0), &[1, 2, 3, 4, 5]);
    assert_eq!(nb.of(3), &[0, 1, 2, 4, 5]);
}

#[test]
fn crowded_blocks_and_repeated_points_stay_exact() {
    // One point 1e9 away stretches the quantiser: the cube's points share one cell and every
    // query's candidates are the whole cube (selected, not sorted: was quadratic).
    let mut p = surface("cube", 2000, 5);
    p.push([1e9, 0.1, 0.2]);
    for k in [1, 8, 20] {
        assert_knn_exact(&p, k, "cube and a far outlier");
    }
    // Half the points repeated at one place, the others spread.
    let mut p = surface("sphere", 600, 6);
    p.extend(std::iter::repeat_n([0.3, 0.1, -0.2], 600));
    assert_knn_exact(&p, 12, "half at one place");
    // Every point at one place: the k smallest other indices, answered without a search.
    let same = vec![[1.5, 2.5, 3.5]; 200_000];
    let nb = knn(&same, 8).unwrap();
    for i in [0usize, 3, 8, 9, 123_456, 199_999] {
        let expect: Vec<u32> = (0..=8u32).filter(|&j| j as usize != i).take(8).collect();
        assert_eq!(nb.of(i), &expect[..], "point {i}");
    }
}

#[test]
fn knn_handles_outliers_and_uneven_density() {
    // A dense surface plus far outliers: the outliers' searches leave the grid's shells.
    let mut p = surface("sphere", 3000, 4);
    let mut r = Lcg(9);
    for _ in 0..40 {
        p.push([
            1e3 * (r.next() - 0.5),
            1e3 * (r.next() - 0.5),
            1e3 * (r.next() - 0.5),
        ]);
    }
    // and a tight cluster
    for _ in 0..200 {
        p.push([1e-4 * r.next(), 1e-4 * r.next(), 1e-4 * r.next()]);
    }
    assert_knn_exact(&p, 12, "outliers");
}

#[test]
fn prefixes_equal_smaller_k_queries() {
    let p = surface("fillet-chamfer-cone", 4000, 5);
    let big = knn(&p, 30).unwrap();
    for k in [1, 5, 12, 29] {
        let small = knn(&p, k).unwrap();
        for i in 0..p.len() {
            assert_eq!(big.prefix(i, k), small.of(i), "k = {k}, point {i}");
        }
    }
    let t = tie_grid();
    let big = knn(&t, 30).unwrap();
    let small = knn(&t, 7).unwrap();
    for i in 0..t.len() {
        assert_eq!(big.prefix(i, 7), small.of(i));
    }
}

#[test]
fn input_order_is_restored() {
    for p in [surface("torus", 5000, 6), tie_grid()] {
        let k = 10;
        let (q, perm) = shuffle(&p, 11);
        let a = knn(&p, k).unwrap();
        let b = knn(&q, k).unwrap();
        // Row i of the shuffled cloud is row perm[i] of the original, with indices mapped
        // (ties are by index, so compare neighbour sets with equal distances).
        let mut inv = vec![0u32; p.len()];
        for (i, &j) in perm.iter().enumerate() {
            inv[j] = i as u32;
        }
        for i in 0..q.len() {
            let expect: Vec<u32> = brute_knn(&q, i, k);
            assert_eq!(b.of(i), expect.as_slice());
            let mapped: Vec<f64> = a
                .of(perm[i])
                .iter()
                .map(|&j| d2(&p[perm[i]], &p[j as usize]))
                .collect();
            let got: Vec<f64> = b.of(i).iter().map(|&j| d2(&q[i], &q[j as usize])).collect();
            assert_eq!(mapped, got);
        }
        // Without ties (a jittered surface) the rows map exactly.
        if p.len() == 5000 {
            for (i, &pi) in perm.iter().enumerate() {
                let mapped: Vec<u32> = a.of(pi).iter().map(|&j| inv[j as usize]).collect();
                assert_eq!(b.of(i), mapped.as_slice());
            }
        }
    }
}

#[test]
fn thread_count_does_not_change_the_result() {
    let p = surface("two-cylinders", 20000, 7);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| knn(&p, 16).unwrap())
    };
    assert_eq!(run(1), run(2));
    assert_eq!(run(1), run(3));
    let map = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| map_all(&p, 16))
    };
    let one = map(1);
    assert_eq!(one, map(2));
    assert_eq!(one, map(3));
    let set = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| map_with(&p, 16, false))
    };
    let set1 = set(1);
    assert_eq!(set1, set(2));
    assert_eq!(set1, set(3));
    let nb = knn(&p, 16).unwrap();
    for (i, s) in one.iter().enumerate() {
        assert_eq!(s.ids.as_slice(), nb.of(i));
    }
}

#[test]
fn argument_errors() {
    let p = random_cube(10, 1);
    assert!(knn(&p, 0).is_err());
    assert!(knn(&p, 10).is_err());
    assert!(knn(&p, 9).is_ok());
    assert!(knn(&[], 1).is_err());
    let mut bad = p.clone();
    bad[4][1] = f64::NAN;
    assert!(knn(&bad, 3).is_err());
    bad[4][1] = f64::INFINITY;
    assert!(knn(&bad, 3).is_err());
    let unit = |_: &mut (), _: &KnnQuery| ();
    assert!(knn_map(&p, 0, || (), unit).is_err());
    assert!(knn_map(&p, 10, || (), unit).is_err());
    assert_eq!(knn_map(&p, 9, || (), unit).unwrap().len(), 10);
    assert!(knn_map(&[], 1, || (), unit).is_err());
    assert!(knn_map(&bad, 3, || (), unit).is_err());
}

/// Brute-force neighbours within r (d² ≤ r²), self excluded, sorted by distance then index.
fn brute_radius(p: &[Point3], i: usize, r: f64) -> Vec<u32> {
    let mut v: Vec<(f64, u32)> = (0..p.len())
        .filter(|&j| j != i)
        .map(|j| (d2(&p[i], &p[j]), j as u32))
        .filter(|x| x.0 <= r * r)
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    v.into_iter().map(|x| x.1).collect()
}

#[test]
fn radius_search_equals_brute_force() {
    let clouds = [
        (
            "cube surface",
            surface("cube", 3000, 12),
            vec![0.0, 0.01, 0.05, 0.2],
        ),
        ("random", random_cube(1500, 13), vec![0.03, 0.1, 2.0]),
        // Radii equal to grid distances: points exactly on the sphere are included.
        (
            "tie grid",
            tie_grid(),
            vec![0.0, 1.0, 2.0, 2f64.sqrt(), 3.0],
        ),
    ];
    for (what, p, radii) in clouds {
        for r in radii {
            let csr = radius_neighbors(&p, r).unwrap();
            assert_eq!(csr.num_rows(), p.len());
            let mut total = 0;
            for i in 0..p.len() {
                let expect = brute_radius(&p, i, r);
                total += expect.len();
                assert_eq!(csr.row(i), expect.as_slice(), "{what}: r = {r}, point {i}");
            }
            if r > 0.0 {
                assert!(total > 0, "{what}: r = {r} finds nothing");
            }
        }
    }
    assert!(radius_neighbors(&tie_grid(), -1.0).is_err());
    assert!(radius_neighbors(&tie_grid(), f64::NAN).is_err());
    assert_eq!(radius_neighbors(&[], 1.0).unwrap().num_rows(), 0);
}

#[test]
fn knn_within_equals_brute_force() {
    let p = surface("cylinder", 3000, 14);
    let t = tie_grid();
    for (cloud, r) in [(&p, 0.005), (&p, 0.02), (&p, 1.0), (&t, 1.0), (&t, 2.5)] {
        for k in [1, 8, 20] {
            let nb = knn_within(cloud, k, r).unwrap();
            for i in 0..cloud.len() {
                let mut expect = brute_radius(cloud, i, r);
                expect.truncate(k);
                assert_eq!(nb.of(i), expect.as_slice(), "r = {r}, k = {k}, point {i}");
            }
        }
    }
    // Fewer points than k: shorter rows, no error.
    let few = random_cube(5, 2);
    let nb = knn_within(&few, 10, 10.0).unwrap();
    assert_eq!(nb.of(0).len(), 4);
    assert!(knn_within(&few, 0, 1.0).is_err());
}

/// Timing of the methods on 1M points of a cube's faces (run with `--release -- --ignored`).
#[test]
#[ignore]
fn timing_1m_cube_faces() {
    let n: usize = std::env::var("KNN_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1_000_000);
    let p = surface("cube", n, 1);
    let order = crease::spatial::morton_order(&p);
    let sorted: Vec<Point3> = order.iter().map(|&i| p[i as usize]).collect();
    let methods: Vec<KnnMethod> = match std::env::var("KNN_METHODS").as_deref() {
        Ok("grid") => vec![KnnMethod::Grid],
        _ => vec![KnnMethod::Grid, KnnMethod::KdTreeMorton, KnnMethod::KdTree],
    };
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        for (label, cloud) in [("random", &p), ("sorted", &sorted)] {
            for &m in &methods {
                let t = std::time::Instant::now();
                let c = cpu_seconds();
                let nb = pool.install(|| knn_with(cloud, 20, m).unwrap());
                eprintln!(
                    "{threads} thr {label:6} {m:?}: {:.3} s wall, {:.2} s cpu",
                    t.elapsed().as_secs_f64(),
                    cpu_seconds() - c
                );
                std::hint::black_box(nb);
            }
        }
    }
}

/// User + system CPU time of this process (Linux), for timings on a loaded machine.
fn cpu_seconds() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = s.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after.split_whitespace().collect();
    let t = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    (t(11) + t(12)) / 100.0
}

/// Clouds spaced far beyond or below the f32 range of the block search: exact answers, no
/// panic (a 25-point grid spaced 1e19 indexed out of bounds).
#[test]
fn extreme_spacings_are_exact() {
    for spacing in [1e19, 1e30, 1e-20, 1e-40] {
        let p: Vec<Point3> = (0..25)
            .map(|i| {
                [
                    (i % 5) as f64 * spacing,
                    (i / 5) as f64 * spacing * 1.01,
                    0.0,
                ]
            })
            .collect();
        for k in [4, 8] {
            let nb = knn(&p, k).expect("knn");
            for i in 0..p.len() {
                assert_eq!(
                    nb.of(i),
                    brute_knn(&p, i, k).as_slice(),
                    "spacing {spacing}"
                );
            }
            let sets = knn_map_set(
                &p,
                k,
                || (),
                |_, q: &KnnQuery| {
                    let mut ids = q.ids.to_vec();
                    ids.sort_unstable();
                    ids
                },
            )
            .expect("knn_map_set");
            for (i, ids) in sets.iter().enumerate() {
                let mut want = brute_knn(&p, i, k);
                want.sort_unstable();
                assert_eq!(ids, &want, "spacing {spacing}");
            }
        }
    }
}
