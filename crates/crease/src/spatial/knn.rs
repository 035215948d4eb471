//! k nearest neighbours of every point of a cloud, as CSR lists.
//!
//! Multi-scale users query the largest k once and take prefixes ([`Neighborhoods::prefix`]):
//! rows are sorted nearest first (ties by index), so the first k' entries of a row are exactly
//! the k' nearest neighbours.
//!
//! # Algorithm
//! The points are sorted along a Morton curve (21 bits per axis over the bounding box, parallel
//! sort). The typical k-th neighbour distance r_k is estimated from windows of that order (the
//! k-th nearest point within a window of the sorted order bounds the true one from above; the
//! median over 1024 samples is used). The points are then sorted again on a quantiser whose
//! unit makes a Morton prefix a cell of side exactly 1.2 r_k, and bucketed into that uniform
//! grid (cells are contiguous runs of the order, found through a hash table). Queries run in
//! Morton order (neighbouring queries share cells, which stay in cache), in parallel tasks of
//! consecutive ranks, and each result is written straight to its input position.
//!
//! **Block search** (`block_query`, almost every query). The points of the 3 x 3 x 3 cells
//! around the query's cell are copied once per cell into a structure of arrays of f32
//! coordinates relative to the cell's centre. Per query: the squared distances to all of them
//! (eight lanes at a time); a threshold θ with at least k of them below it, narrowed from the
//! bound the previous query gives (the largest distance from q to the previous query's
//! neighbourhood) by interpolating vectorised counts (squared distances on a surface are spread
//! about uniformly, so two or three counts leave k to k + 3 candidates); those candidates
//! bucket-sorted by their f32 distance; exact f64 distances for them and an insertion pass on
//! (distance, index). The f32 error of a squared distance within the block is bounded (2^-16
//! cell², see `build_block`), so every true neighbour is among the candidates, and the answer
//! is accepted only when θ plus that error lies inside the distance from q to the block's faces:
//! the result is exact. Otherwise (≈ 0.1 % of the queries on surfaces) the shell search below
//! answers.
//!
//! **Crowded blocks.** Where candidates are many more than k (points within the f32 error of
//! each other: duplicates, or a cube whose cells an outlier 1e9 away made far wider than its
//! spacing), the k nearest are selected exactly in linear time instead of sorted
//! (`crowded_query`); a cloud whose points are all at one place is answered directly. Before,
//! such 3,000-point clouds took 5 to 40 s.
//!
//! **Shell search** (`grid_query`). Shells of cells of growing Chebyshev radius around the
//! query's cell, nearest shells first, keeping the k best candidates, skipping cells farther
//! than the current k-th candidate, until the next shell cannot hold anything nearer. Points
//! whose search would need more than a few shells (outliers, very uneven density) are finished
//! by a k-d tree (kiddo) built only when such points exist. Ties are broken by input index
//! everywhere, so the result equals brute force and does not depend on the thread count or the
//! input order.
//!
//! [`knn_map`] runs the same search but hands each neighbourhood (indices, coordinates, squared
//! distances) to a closure while it is in cache, and returns the closure's results in input
//! order, with no n·k lists at all; [`knn`] is the same query loop writing rows.
//!
//! **Why these choices.** Cells of 1.2 r_k let almost every query finish in its block, where
//! the power-of-two cells of the bounding box's unit (a side anywhere in 0.7 to 1.4 r_k) left
//! most of them to the shell search; the block search takes fewer instructions per query than
//! the shell search, and the unranked set ([`knn_map_set`]) fewer than the ranked rows. An
//! AVX2 build, a comparison sort or a full selection of the candidates and other cell sides
//! were slower, a cache of cell lookups gained nothing. Figures (callgrind, perf, timings
//! against PCL and Open3D): `docs/experiments/knn-and-normals.md`; speed tables:
//! `docs/benchmarks.md`.
//!
//! **Memory**: the points in Morton order (24 B/point), input indices (4 B/point), the cell
//! table (≤ 32 B/point), two (code, index) sorts (16 B/point each, one at a time), plus for
//! [`knn`] two n·k u32 buffers (160 MB at 1M, k = 20) and for [`knn_map`] only the n results.

use std::sync::OnceLock;

use rayon::prelude::*;

use wide::bytemuck::cast;
use wide::{f32x8, i32x8};

use super::grid::{dist2, CellGrid};
use super::morton::{cell_sorted, morton_sorted, Quantizer};
use super::KdIndex;
use crate::geometry::{Csr, Point3};
use crate::{Error, Result};

/// The k nearest neighbours of every point (the point itself excluded), nearest first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Neighborhoods {
    k: usize,
    lists: Csr,
}

impl Neighborhoods {
    /// Wraps CSR lists whose rows hold at most `k` neighbours, nearest first.
    pub fn from_csr(k: usize, lists: Csr) -> Self {
        Neighborhoods { k, lists }
    }

    /// The k the lists were built for (rows are shorter only when the cloud has ≤ k points).
    pub fn k(&self) -> usize {
        self.k
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.lists.num_rows()
    }

    /// True for an empty cloud.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The neighbours of point `i`, nearest first.
    #[inline]
    pub fn of(&self, i: usize) -> &[u32] {
        self.lists.row(i)
    }

    /// The `k` nearest neighbours of point `i` (all of them if the row is shorter).
    #[inline]
    pub fn prefix(&self, i: usize, k: usize) -> &[u32] {
        let row = self.lists.row(i);
        &row[..k.min(row.len())]
    }

    /// The underlying CSR lists.
    pub fn csr(&self) -> &Csr {
        &self.lists
    }

    /// The CSR lists, by value.
    pub fn into_csr(self) -> Csr {
        self.lists
    }
}

/// How [`knn_with`] searches; all methods give the same (exact) result.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum KnnMethod {
    /// Uniform grid over Morton-sorted points, queries in Morton order (the default: fastest).
    #[default]
    Grid,
    /// One kiddo k-d tree query per point, in input order (the baseline).
    KdTree,
    /// kiddo k-d tree over Morton-sorted points, queries in Morton order.
    KdTreeMorton,
}

/// Ratio of the grid cell side to the estimated k-th neighbour distance.
const CELL_RATIO: f64 = 1.2;
/// Shells searched by the grid before a query is handed to the k-d tree.
const MAX_SHELLS: i64 = 3;

/// The `k` nearest neighbours of every point of `points`, in parallel (see the module doc).
///
/// Errors when `k` is 0, when the cloud has fewer than `k + 1` points (a neighbourhood of k
/// other points is impossible), or when a coordinate is not finite.
pub fn knn(points: &[Point3], k: usize) -> Result<Neighborhoods> {
    knn_with(points, k, KnnMethod::Grid)
}

/// Checks the arguments shared by the kNN queries.
fn check_knn_args(points: &[Point3], k: usize) -> Result<()> {
    if k == 0 {
        return Err(Error::InvalidArgument(
            "k nearest neighbours with k = 0".into(),
        ));
    }
    if points.len() < k + 1 {
        return Err(Error::InvalidInput(format!(
            "{} points: k-nearest-neighbour neighbourhoods with k = {k} need at least {} points",
            points.len(),
            k + 1
        )));
    }
    if points.len() > u32::MAX as usize || (points.len() as u64) * (k as u64) > u32::MAX as u64 {
        return Err(Error::InvalidInput(format!(
            "{} points with k = {k}: more than 2^32 - 1 neighbour entries",
            points.len()
        )));
    }
    check_finite(points)?;
    check_extent(points)
}

/// Extents of a cloud whose squared distances stay normal f64 values: below, distances between
/// neighbours underflow to 0 (every point ties with every other, and a neighbour search turns
/// quadratic); above, they overflow to infinity. Either way no neighbourhood means anything.
const EXTENT_RANGE: (f64, f64) = (1e-140, 1e150);

/// Errors when the points span so little (but not nothing) or so much that squared distances
/// leave f64's normal range (spans from 1e-140 to 1e150 pass; zero passes too).
pub fn check_extent(points: &[Point3]) -> Result<()> {
    let (lo, hi) = points
        .par_iter()
        .fold(
            || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(mut lo, mut hi), p| {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
                (lo, hi)
            },
        )
        .reduce(
            || ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
            |(l1, h1), (l2, h2)| {
                (
                    [l1[0].min(l2[0]), l1[1].min(l2[1]), l1[2].min(l2[2])],
                    [h1[0].max(h2[0]), h1[1].max(h2[1]), h1[2].max(h2[2])],
                )
            },
        );
    let extent = (0..3).map(|a| hi[a] - lo[a]).fold(0.0f64, f64::max);
    // (All points at one place are a valid, if useless, input: see `GridSearch::same`.)
    if extent > 0.0 && extent < EXTENT_RANGE.0 {
        return Err(Error::InvalidInput(format!(
            "the points span only {extent:.1e}: squared distances between them underflow; \
             scale the coordinates up"
        )));
    }
    if extent > EXTENT_RANGE.1 {
        return Err(Error::InvalidInput(format!(
            "the points span {extent:.1e}: squared distances between them overflow; remove \
             the far outliers or scale the coordinates down"
        )));
    }
    Ok(())
}

/// Errors when the points all coincide (no neighbourhood, normal or surface is theirs) or
/// span outside [`check_extent`]'s range: the check every command of the CLI (and every
/// function of the Python package) that analyses a shape makes on its input first.
pub fn check_shape(points: &[Point3]) -> Result<()> {
    if let Some(first) = points.first() {
        if points.len() > 1 && points.iter().all(|q| q == first) {
            return Err(Error::InvalidInput(format!(
                "all {} points coincide (at {first:?}): no neighbourhood, normal or surface is \
                 theirs",
                points.len()
            )));
        }
    }
    check_extent(points)
}

/// Errors on the first point with a non-finite coordinate.
pub(crate) fn check_finite(points: &[Point3]) -> Result<()> {
    if let Some(i) = points
        .par_iter()
        .position_first(|p| !p.iter().all(|v| v.is_finite()))
    {
        return Err(Error::InvalidInput(format!(
            "point {i} has a non-finite coordinate: {:?}",
            points[i]
        )));
    }
    Ok(())
}

/// [`knn`] with a chosen search method (for comparisons; the result is the same).
pub fn knn_with(points: &[Point3], k: usize, method: KnnMethod) -> Result<Neighborhoods> {
    check_knn_args(points, k)?;
    let n = points.len();
    let indices = match method {
        KnnMethod::KdTree => {
            let index = KdIndex::new(points).ok_or_else(|| {
                Error::InvalidInput("cannot build a k-d tree over the points".into())
            })?;
            let ids: Vec<u32> = (0..n as u32).collect();
            let mut out = vec![0u32; n * k];
            out.par_chunks_mut(k)
                .enumerate()
                .for_each_init(Best::default, |best, (i, row)| {
                    best.reset(k);
                    kd_query(&index, points, &ids, i, best);
                    row.copy_from_slice(&best.id);
                });
            out
        }
        KnnMethod::KdTreeMorton => {
            let quant =
                Quantizer::new(points).ok_or_else(|| Error::InvalidInput("empty".into()))?;
            let sorted = morton_sorted(points, &quant);
            let sp: Vec<Point3> = sorted.iter().map(|&(_, i)| points[i as usize]).collect();
            let ids: Vec<u32> = sorted.iter().map(|&(_, i)| i).collect();
            drop(sorted);
            let index = KdIndex::new(&sp).ok_or_else(|| {
                Error::InvalidInput("cannot build a k-d tree over the points".into())
            })?;
            let mut buf = vec![0u32; n * k];
            buf.par_chunks_mut(k)
                .enumerate()
                .for_each_init(Best::default, |best, (r, row)| {
                    best.reset(k);
                    kd_query(&index, &sp, &ids, r, best);
                    row.copy_from_slice(&best.id);
                });
            gather_fixed(&buf, &ids, k)
        }
        KnnMethod::Grid => {
            let search = GridSearch::new(points, k)?;
            let mut buf = vec![0u32; n * k];
            buf.par_chunks_mut(k * TASK).enumerate().for_each_init(
                Scratch::default,
                |scratch, (t, rows)| {
                    for (j, row) in rows.chunks_exact_mut(k).enumerate() {
                        search.query(t * TASK + j, scratch);
                        row.copy_from_slice(&scratch.ids);
                    }
                },
            );
            gather_fixed(&buf, &search.grid.ids, k)
        }
    };
    Ok(Neighborhoods::from_csr(
        k,
        Csr::from_fixed_width(n, k, indices),
    ))
}

/// Queries per parallel task: consecutive queries in Morton order share cells and most of their
/// neighbours, so each task walks a long run of them with one scratch.
const TASK: usize = 1024;

/// One query's neighbourhood, handed to the closure of [`knn_map`].
///
/// The slices are the query's k nearest other points, nearest first, ties by input index:
/// exactly the row [`knn`] returns for `index`, with the coordinates and squared distances
/// alongside.
#[derive(Debug, Clone, Copy)]
pub struct KnnQuery<'a> {
    /// Input index of the query point.
    pub index: usize,
    /// The query point.
    pub point: Point3,
    /// Coordinates of its k nearest neighbours, nearest first (the point itself excluded).
    pub neighbors: &'a [Point3],
    /// Input indices of the neighbours, same order.
    pub ids: &'a [u32],
    /// Squared distances from the query to the neighbours, same order (non-decreasing).
    pub dist2: &'a [f64],
}

/// Calls `f` on the k-nearest-neighbour neighbourhood of every point and returns its results in
/// input order, without storing the n·k neighbour lists.
///
/// The queries run in parallel in Morton order (see the module doc), so each neighbourhood is
/// handed to `f` while its points are in cache; `init` makes one scratch value per parallel task
/// (reused across that task's queries, e.g. buffers for a local fit). The neighbourhoods are the
/// rows of [`knn`] (exact, nearest first, ties by input index), and the result does not depend on
/// the thread count as long as `f`'s result depends only on its [`KnnQuery`] (not on the
/// scratch's history).
///
/// Errors as [`knn`]: k = 0, fewer than k + 1 points, a non-finite coordinate.
pub fn knn_map<T, S, I, F>(points: &[Point3], k: usize, init: I, f: F) -> Result<Vec<T>>
where
    T: Send,
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, &KnnQuery) -> T + Sync + Send,
{
    map_queries::<Vec<T>, _, _, _>(points, k, true, init, f)
}

/// [`knn_map`] for consumers of the neighbour *set* (a local fit whose result does not depend
/// on the order of its points, up to rounding): the same k neighbours, but the slices of
/// [`KnnQuery`] hold them in an unspecified order, and `dist2` is not sorted. The order is
/// deterministic (it depends only on the points, not on the thread count), so results are
/// still reproducible.
///
/// Skipping the ranking (a bucket sort of the candidates and an exact insertion pass) saves
/// about a fifth of the search's instructions (callgrind: `docs/experiments/knn-and-normals.md`).
///
/// Errors as [`knn`].
pub fn knn_map_set<T, S, I, F>(points: &[Point3], k: usize, init: I, f: F) -> Result<Vec<T>>
where
    T: Send,
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, &KnnQuery) -> T + Sync + Send,
{
    map_queries::<Vec<T>, _, _, _>(points, k, false, init, f)
}

/// [`knn_map_set`] for an `f` that returns two values per point, returned as two vectors in
/// input order, each written in place (unzipping a vector of pairs afterwards cost a third
/// n-item buffer of fresh pages).
///
/// Errors as [`knn`].
pub fn knn_map_set_unzip<A, B, S, I, F>(
    points: &[Point3],
    k: usize,
    init: I,
    f: F,
) -> Result<(Vec<A>, Vec<B>)>
where
    A: Send,
    B: Send,
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, &KnnQuery) -> (A, B) + Sync + Send,
{
    map_queries::<(Vec<A>, Vec<B>), _, _, _>(points, k, false, init, f)
}

/// [`knn_map`] (`ordered`) or [`knn_map_set`].
fn map_queries<O, S, I, F>(points: &[Point3], k: usize, ordered: bool, init: I, f: F) -> Result<O>
where
    O: Outputs,
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, &KnnQuery) -> O::Item + Sync + Send,
{
    check_knn_args(points, k)?;
    let mut search = GridSearch::new(points, k)?;
    search.ordered = ordered;
    let search = search;
    let grid = &search.grid;
    map_to_input_order(
        &grid.ids,
        || (Scratch::default(), init()),
        |(scratch, state), r| {
            search.query(r, scratch);
            let query = KnnQuery {
                index: grid.ids[r] as usize,
                point: grid.points[r],
                neighbors: &scratch.pts,
                ids: &scratch.ids,
                dist2: &scratch.d2,
            };
            f(state, &query)
        },
    )
}

/// A raw pointer to an output buffer that may cross threads: each thread writes distinct
/// slots.
struct Dest<T>(*mut T);
// SAFETY: only used to write distinct slots of one allocation from several threads.
unsafe impl<T: Send> Send for Dest<T> {}
unsafe impl<T: Send> Sync for Dest<T> {}
impl<T> Dest<T> {
    /// Writes slot `i`.
    ///
    /// # Safety
    /// `i` is within the allocation's capacity, and no other write or read of slot `i`
    /// happens concurrently.
    unsafe fn put(&self, i: usize, item: T) {
        // SAFETY: as the caller guarantees.
        unsafe { self.0.add(i).write(item) }
    }
}

/// The result buffers of [`map_to_input_order`]: one vector, or two filled from the two halves
/// of each item.
trait Outputs: Sized {
    /// What one query returns.
    type Item: Send;
    /// Pointers through which the threads write.
    type Sink: Sync;
    /// Empty buffers with room for `n` items, and their sink.
    fn with_capacity(n: usize) -> (Self, Self::Sink);
    /// Writes item `i`.
    ///
    /// # Safety
    /// As [`Dest::put`], for every buffer.
    unsafe fn put(sink: &Self::Sink, i: usize, item: Self::Item);
    /// The buffers holding `n` items.
    ///
    /// # Safety
    /// All `n` slots of every buffer were written.
    unsafe fn assume_init(self, n: usize) -> Self;
}

impl<T: Send> Outputs for Vec<T> {
    type Item = T;
    type Sink = Dest<T>;
    fn with_capacity(n: usize) -> (Self, Dest<T>) {
        let mut v = Vec::with_capacity(n);
        let d = Dest(v.as_mut_ptr());
        (v, d)
    }
    unsafe fn put(sink: &Dest<T>, i: usize, item: T) {
        // SAFETY: as the caller guarantees.
        unsafe { sink.put(i, item) }
    }
    unsafe fn assume_init(mut self, n: usize) -> Self {
        // SAFETY: as the caller guarantees (n ≤ capacity, all written).
        unsafe { self.set_len(n) };
        self
    }
}

impl<A: Send, B: Send> Outputs for (Vec<A>, Vec<B>) {
    type Item = (A, B);
    type Sink = (Dest<A>, Dest<B>);
    fn with_capacity(n: usize) -> (Self, Self::Sink) {
        let (a, da) = <Vec<A> as Outputs>::with_capacity(n);
        let (b, db) = <Vec<B> as Outputs>::with_capacity(n);
        ((a, b), (da, db))
    }
    unsafe fn put(sink: &Self::Sink, i: usize, (a, b): (A, B)) {
        // SAFETY: as the caller guarantees, for both buffers.
        unsafe {
            sink.0.put(i, a);
            sink.1.put(i, b);
        }
    }
    unsafe fn assume_init(self, n: usize) -> Self {
        // SAFETY: as the caller guarantees, for both buffers.
        unsafe { (self.0.assume_init(n), self.1.assume_init(n)) }
    }
}

/// `f(state, r)` for every sorted rank r in `0..ids.len()`, in parallel in rank order (runs of
/// at least [`TASK`] consecutive ranks per task, one `init()` state per task), returned in
/// input order: the result of rank r at position `ids[r]`.
///
/// Each result is written straight to its input position (a parallel scatter into one
/// buffer) instead of being collected in rank order and permuted afterwards, which saves a
/// second n-item buffer and its time (`docs/experiments/knn-and-normals.md`). `ids` always is
/// a permutation (it comes from sorting `0..n`); this is verified first, so the unsafe writes
/// only ever run on a checked permutation, and an error is returned otherwise.
fn map_to_input_order<O, S, I, F>(ids: &[u32], init: I, f: F) -> Result<O>
where
    O: Outputs,
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, usize) -> O::Item + Sync + Send,
{
    let n = ids.len();
    let mut seen = vec![false; n];
    let valid = ids.iter().all(|&i| {
        seen.get_mut(i as usize)
            .is_some_and(|s| !std::mem::replace(s, true))
    });
    drop(seen);
    if !valid {
        return Err(Error::InvalidInput(
            "internal error: the spatial order is not a permutation of the points".into(),
        ));
    }
    let (out, sink) = O::with_capacity(n);
    (0..n)
        .into_par_iter()
        .with_min_len(TASK)
        .for_each_init(init, |state, r| {
            let item = f(state, r);
            // SAFETY: `ids` is a permutation of 0..n (checked above) and every rank r is
            // visited exactly once, so each slot of the capacity-n buffers is written exactly
            // once, by one thread.
            unsafe { O::put(&sink, ids[r] as usize, item) }
        });
    // SAFETY: all n slots were initialised above (a panic in `f` unwinds past this line,
    // leaking the written items but never exposing an unwritten slot).
    Ok(unsafe { out.assume_init(n) })
}
/// The grid search over one cloud: the points bucketed in cells in Morton order ([`cell_sorted`]), and the k-d tree
/// fallback for queries the grid cannot finish in a few shells, built on first use.
struct GridSearch<'a> {
    points: &'a [Point3],
    grid: CellGrid,
    k: usize,
    /// Whether the neighbours must come nearest first (false: the set in an unspecified but
    /// deterministic order, see [`knn_map_set`]).
    ordered: bool,
    /// Whether the f32 block search is safe at this cell size (see [`BLOCK_CELL_RANGE`]).
    blocks: bool,
    fallback: OnceLock<Option<KdIndex>>,
    /// Whether every point is at the same place: each query's answer is then the k smallest
    /// other input indices, given directly (the search would compare every pair).
    same: bool,
}

/// Cell sides for which the f32 block search of [`block_query`] holds: its squared distances
/// (up to about 27 cell² within a block) must neither overflow f32 nor fall into its subnormal
/// range. Outside (a cloud spaced 1e19 apart, or 1e-30), the shell search in f64 answers every
/// query: slower, exact. Seen by a fuzzer: a 25-point grid spaced 1e19 overflowed to infinite
/// distances and indexed out of bounds.
const BLOCK_CELL_RANGE: (f64, f64) = (1e-15, 1e17);

impl<'a> GridSearch<'a> {
    /// Sorts and buckets `points` (arguments already checked).
    fn new(points: &'a [Point3], k: usize) -> Result<Self> {
        let quant = Quantizer::new(points).ok_or_else(|| Error::InvalidInput("empty".into()))?;
        let r = kth_distance_subsampled(points, &quant, k);
        // Cells of side CELL_RATIO x the k-th distance exactly: the Morton sort on a quantiser
        // fitted to that side. Measured: cells of a power of two of the bounding box's unit
        // have any side in 0.7x to 1.4x of the target, and below 1x the block search of
        // [`block_query`] fails on most queries (76 % at 100k cube points).
        let (quant, level) = quant
            .with_cell(r * CELL_RATIO)
            .unwrap_or_else(|| (quant, level_for(&quant, r * CELL_RATIO)));
        let grid = CellGrid::new(points, quant, &cell_sorted(points, &quant, level), level);
        let blocks = (BLOCK_CELL_RANGE.0..=BLOCK_CELL_RANGE.1).contains(&grid.cell_size);
        let same = points.iter().all(|p| p == &points[0]);
        Ok(GridSearch {
            points,
            grid,
            k,
            ordered: true,
            blocks,
            fallback: OnceLock::new(),
            same,
        })
    }

    /// The k nearest neighbours of sorted point `r`, left in `scratch.ids`, `scratch.d2` and
    /// `scratch.pts`, nearest first, ties by input index.
    fn query(&self, r: usize, scratch: &mut Scratch) {
        let k = self.k;
        scratch.ids.clear();
        scratch.d2.clear();
        scratch.pts.clear();
        if self.same {
            // Sorted positions of equal codes follow the input order (`cell_sorted` sorts
            // (code, index) pairs): the first k + 1 positions other than r.
            scratch.sel.clear();
            scratch.sel.extend(
                (0..=k)
                    .filter(|&j| j != r)
                    .take(k)
                    .map(|j| (0, self.grid.ids[j], j as u32)),
            );
            scratch.prev.clear();
            self.copy_sel(scratch);
            return;
        }
        if self.blocks && block_query(&self.grid, r, k, self.ordered, scratch) {
            if self.ordered {
                self.copy_sel(scratch);
            }
            return;
        }
        // (The block may have left a partial result.)
        scratch.ids.clear();
        scratch.d2.clear();
        scratch.pts.clear();
        if grid_query(&self.grid, r, k, MAX_SHELLS, scratch) {
            self.copy_sel(scratch);
            return;
        }
        // Outlier or very uneven density: exact k-d tree search (or an unbounded grid search
        // if no tree can be built).
        let tree = self
            .fallback
            .get_or_init(|| KdIndex::new(&self.grid.points));
        match tree {
            Some(tree) => {
                let best = &mut scratch.best;
                best.reset(k);
                kd_query(tree, &self.grid.points, &self.grid.ids, r, best);
                for (&d, &id) in best.d2.iter().zip(&best.id) {
                    scratch.ids.push(id);
                    scratch.d2.push(d);
                    scratch.pts.push(self.points[id as usize]);
                }
                // The previous-query bound needs sorted positions: start afresh.
                scratch.prev.clear();
            }
            None => {
                grid_query(&self.grid, r, k, i64::MAX, scratch);
                self.copy_sel(scratch);
            }
        }
    }

    /// The selection `scratch.sel` into the result slices.
    #[inline]
    fn copy_sel(&self, scratch: &mut Scratch) {
        let sel = &scratch.sel;
        scratch.prev_dk = sel.last().map_or(0.0, |c| f64::from_bits(c.0) as f32);
        scratch.ids.extend(sel.iter().map(|c| c.1));
        scratch.d2.extend(sel.iter().map(|c| f64::from_bits(c.0)));
        let pts = &self.grid.points;
        scratch.pts.extend(
            sel.iter()
                .map(|c| pts.get(c.2 as usize).copied().unwrap_or_default()),
        );
    }
}

/// Rows of width `k` in sorted order (`ids[r]` = input index of rank r) back to input order.
fn gather_fixed(buf: &[u32], ids: &[u32], k: usize) -> Vec<u32> {
    let n = ids.len();
    let mut rank = vec![0u32; n];
    for (r, &i) in ids.iter().enumerate() {
        rank[i as usize] = r as u32;
    }
    let mut out = vec![0u32; n * k];
    out.par_chunks_mut(k).enumerate().for_each(|(i, row)| {
        let r = rank[i] as usize;
        row.copy_from_slice(&buf[r * k..(r + 1) * k]);
    });
    out
}

/// Estimates the typical distance to the k-th neighbour of `points` ([`estimate_kth_distance`])
/// without sorting the whole cloud: on a pseudo-random subsample of one point in s (s a power
/// of two up to 8, about k / 5), the (k / s)-th neighbour distance. The count of points in a
/// ball is proportional to the density whatever the dimension of the sampled set (a surface, a
/// curve, a volume), so thinning the cloud by s and the count by s leaves the radius unchanged.
/// The subsample is chosen by a hash of the index, not by stride, so that structured input
/// orders (scan lines, grids) are thinned evenly. Only the speed of a grid search depends on
/// this estimate (its answers are exact for any cell size), and sorting a quarter of the
/// points instead of all of them for it is a few times cheaper while the estimate stays
/// within a few percent (`docs/experiments/knn-and-normals.md`).
pub(crate) fn kth_distance_subsampled(points: &[Point3], quant: &Quantizer, k: usize) -> f64 {
    let n = points.len();
    let mut s = 1usize;
    while s < 8 && 5 * 2 * s <= k && n / (2 * s) >= 1 << 16 {
        s *= 2;
    }
    if s == 1 {
        return estimate_kth_distance(points, &morton_sorted(points, quant), k);
    }
    let bits = s.trailing_zeros();
    let sub: Vec<Point3> = points
        .par_iter()
        .enumerate()
        .filter(|&(i, _)| (i as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - bits) == 0)
        .map(|(_, p)| *p)
        .collect();
    estimate_kth_distance(&sub, &morton_sorted(&sub, quant), k.div_ceil(s))
}

/// Estimates the typical distance to the k-th neighbour: the median, over up to 1024 points
/// spread along the Morton order, of the k-th smallest distance to the points within a window of
/// the sorted order (an upper bound of the true k-th neighbour distance of each sample).
pub(crate) fn estimate_kth_distance(points: &[Point3], sorted: &[(u64, u32)], k: usize) -> f64 {
    let n = sorted.len();
    if n < 2 {
        return 0.0;
    }
    let k = k.clamp(1, n - 1);
    let half = (4 * k).max(32);
    let samples = n.min(1024);
    let mut est: Vec<f64> = (0..samples)
        .into_par_iter()
        .map(|s| {
            let r = s * n / samples;
            let q = &points[sorted[r].1 as usize];
            let lo = r.saturating_sub(half);
            let hi = (r + half + 1).min(n);
            let mut d: Vec<f64> = (lo..hi)
                .filter(|&j| j != r)
                .map(|j| dist2(q, &points[sorted[j].1 as usize]))
                .collect();
            let kk = (k - 1).min(d.len() - 1);
            let (_, v, _) = d.select_nth_unstable_by(kk, f64::total_cmp);
            *v
        })
        .collect();
    let mid = est.len() / 2;
    let (_, m, _) = est.select_nth_unstable_by(mid, f64::total_cmp);
    m.sqrt()
}

/// The grid level (cell side 2^level units) closest to `cell` in log scale.
pub(crate) fn level_for(quant: &Quantizer, cell: f64) -> u32 {
    if cell.is_nan() || cell <= 0.0 || cell.is_infinite() {
        return 0;
    }
    let l = (cell / quant.unit).log2().round();
    l.clamp(0.0, super::morton::MORTON_BITS as f64) as u32
}

/// The k best candidates so far, nearest first: (squared distance, input index).
#[derive(Default)]
pub(crate) struct Best {
    k: usize,
    pub d2: Vec<f64>,
    pub id: Vec<u32>,
}

impl Best {
    fn reset(&mut self, k: usize) {
        self.k = k;
        self.d2.clear();
        self.id.clear();
    }

    #[inline]
    fn full(&self) -> bool {
        self.d2.len() == self.k
    }

    /// The squared distance to beat (infinity while not full).
    #[inline]
    fn worst(&self) -> f64 {
        if self.full() {
            self.d2[self.k - 1]
        } else {
            f64::INFINITY
        }
    }

    /// Offers a candidate; keeps the k smallest by (distance, index).
    #[inline]
    fn offer(&mut self, d2: f64, id: u32) {
        let len = self.d2.len();
        if len == self.k {
            let wd = self.d2[len - 1];
            if d2 > wd || (d2 == wd && id > self.id[len - 1]) {
                return;
            }
            self.d2.pop();
            self.id.pop();
        }
        let mut pos = self.d2.len();
        while pos > 0 {
            let pd = self.d2[pos - 1];
            if pd < d2 || (pd == d2 && self.id[pos - 1] < id) {
                break;
            }
            pos -= 1;
        }
        self.d2.insert(pos, d2);
        self.id.insert(pos, id);
    }
}

/// Per-thread state of the grid search.
#[derive(Default)]
struct Scratch {
    /// Candidates as (squared distance bits, input index): for non-negative floats the bit
    /// patterns order like the values, so tuples sort by distance then index.
    /// (The third field is the candidate's sorted position.)
    cands: Vec<(u64, u32, u32)>,
    /// Sorted positions of the previous query of this thread and of its k neighbours, when
    /// [`grid_query`] answered it (empty after a block answer).
    prev: Vec<u32>,
    /// The previous query's k-th squared distance (0: none), where [`block_query`] starts.
    prev_dk: f32,
    /// Selection keys: truncated squared distance bits with the candidate's slot below.
    keys: Vec<u64>,
    /// The k selected candidates.
    sel: Vec<(u64, u32, u32)>,
    /// The cell whose 3 x 3 x 3 block is in `near`.
    cell: Option<[i64; 3]>,
    /// Non-empty cells of that block: (cell, first, end) sorted positions.
    near: Vec<([i64; 3], usize, usize)>,
    /// Result of the last query: input indices, squared distances and coordinates.
    ids: Vec<u32>,
    d2: Vec<f64>,
    pts: Vec<Point3>,
    /// Candidates of the k-d tree fallback.
    best: Best,
    /// The 3 x 3 x 3 block of cells of the current query's cell, in f32 (see [`block_query`]).
    block: Block,
}

/// The points of the 3 x 3 x 3 block of cells around one cell, as f32 coordinates relative to
/// that cell's centre (structure of arrays, padded to a multiple of [`LANES`] with far points),
/// for [`block_query`].
struct Block {
    /// The cell whose block this is, packed by [`pack_cell`] (`u64::MAX`: none yet).
    cell: u64,
    /// Centre of the cell (the origin of the f32 coordinates).
    centre: Point3,
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    /// Sorted position of each block point.
    pos: Vec<u32>,
    /// Number of real (non-padding) points.
    len: usize,
    /// Sorted range of the central cell and its first slot in the block.
    own_start: usize,
    own_end: usize,
    own_slot: usize,
    /// Absolute bound on |f32 squared distance − exact squared distance| within the block.
    slack: f64,
    /// Squared f32 distances of the current query, [`LANES`] slots per vector.
    d: Vec<f32x8>,
    /// Selection keys (the f32 bit patterns, which order like the non-negative values).
    keys: Vec<u32>,
    /// The candidates of the current query (f32 distance bits << 32 | slot), and sorted.
    cand_keys: Vec<u64>,
    sorted_keys: Vec<u64>,
    /// Sorted positions of the candidates (set mode of [`block_query`]).
    cand_pos: Vec<u32>,
}

impl Default for Block {
    fn default() -> Self {
        Block {
            cell: u64::MAX,
            centre: Point3::default(),
            x: Vec::new(),
            y: Vec::new(),
            z: Vec::new(),
            pos: Vec::new(),
            len: 0,
            own_start: 0,
            own_end: 0,
            own_slot: 0,
            slack: 0.0,
            d: Vec::new(),
            keys: Vec::new(),
            cand_keys: Vec::new(),
            sorted_keys: Vec::new(),
            cand_pos: Vec::new(),
        }
    }
}

/// Cell coordinates (each in 0..2^21, as [`CellGrid::cell_of`] gives them) as one integer:
/// comparing it costs one instruction, where comparing `[i64; 3]` values read back right
/// after the three stores that wrote them stalled on store forwarding (seen with perf).
#[inline]
fn pack_cell(c: [i64; 3]) -> u64 {
    (c[0] as u64) | ((c[1] as u64) << 21) | ((c[2] as u64) << 42)
}

/// Appends the points of sorted range `lo..hi` within squared distance `t2_bits` of `q`
/// (except sorted point `r`) to `cands`, without data-dependent branches.
#[inline]
fn scan(
    grid: &CellGrid,
    q: &Point3,
    r: usize,
    lo: usize,
    hi: usize,
    t2_bits: u64,
    cands: &mut Vec<(u64, u32, u32)>,
) {
    let base = cands.len();
    cands.resize(base + (hi - lo), (0, 0, 0));
    let mut w = base;
    let pts = &grid.points[lo..hi];
    let ids = &grid.ids[lo..hi];
    for (j, (p, &id)) in pts.iter().zip(ids).enumerate() {
        let d = dist2(q, p).to_bits();
        if let Some(slot) = cands.get_mut(w) {
            *slot = (d, id, (lo + j) as u32);
        }
        w += usize::from(d <= t2_bits && lo + j != r);
    }
    cands.truncate(w);
}

/// SIMD width of the block arrays (f32 lanes).
const LANES: usize = 8;

/// Squared f32 distances from `q` (block coordinates) to every slot of `block`, into `block.d`
/// (padding slots included), [`LANES`] at a time.
#[inline]
fn sq_dists(block: &mut Block, q: [f32; 3]) {
    let (qx, qy, qz) = (f32x8::splat(q[0]), f32x8::splat(q[1]), f32x8::splat(q[2]));
    let (x, _) = block.x.as_chunks::<LANES>();
    let (y, _) = block.y.as_chunks::<LANES>();
    let (z, _) = block.z.as_chunks::<LANES>();
    block.d.clear();
    block.d.extend(x.iter().zip(y).zip(z).map(|((x, y), z)| {
        let (dx, dy, dz) = (
            f32x8::new(*x) - qx,
            f32x8::new(*y) - qy,
            f32x8::new(*z) - qz,
        );
        dx * dx + dy * dy + dz * dz
    }));
}

/// Number of lanes of `d` that are ≤ `t`: the comparison masks (−1 per true lane) summed as
/// integers, two instructions per vector (baseline x86-64 has no `popcnt`, and counting the
/// bits of `to_bitmask` took a dozen).
#[inline]
fn count_le(d: &[f32x8], t: f32) -> usize {
    let t = f32x8::splat(t);
    let mut acc = i32x8::splat(0);
    for v in d {
        acc -= cast::<f32x8, i32x8>(v.simd_le(t));
    }
    acc.to_array().iter().sum::<i32>() as usize
}

/// Sorts a short, nearly sorted slice in place (elements move only past their out-of-order
/// neighbours).
#[inline]
fn insertion_sort<T: Ord>(v: &mut [T]) {
    for i in 1..v.len() {
        let mut j = i;
        while j > 0 && v[j] < v[j - 1] {
            v.swap(j, j - 1);
            j -= 1;
        }
    }
}

/// Buckets of [`bucket_sort`].
const BUCKETS: usize = 32;

/// Sorts `keys` (f32 distance bits ≤ `top` in the high half) into `out`: a counting sort on
/// [`BUCKETS`] equal buckets of [0, top], then an insertion pass (a bucket holds few keys).
fn bucket_sort(keys: &[u64], top: f32, out: &mut Vec<u64>) {
    out.clear();
    out.resize(keys.len(), 0);
    let scale = if top > 0.0 { BUCKETS as f32 / top } else { 0.0 };
    // Distances are ≥ 0, so the clamped product converts with one `cvttss2si` (a conversion to
    // usize takes a dozen instructions per key on x86-64 without AVX-512).
    let bucket = |key: u64| -> usize {
        let d = f32::from_bits((key >> 32) as u32);
        (d * scale).min((BUCKETS - 1) as f32) as i32 as usize
    };
    let mut start = [0u32; BUCKETS + 1];
    for &key in keys {
        start[bucket(key) + 1] += 1;
    }
    for b in 1..=BUCKETS {
        start[b] += start[b - 1];
    }
    for &key in keys {
        let b = bucket(key);
        if let Some(slot) = out.get_mut(start[b] as usize) {
            *slot = key;
        }
        start[b] += 1;
    }
    insertion_sort(out);
}

/// Fills `block` with the points of the cells within Chebyshev distance 1 of cell `c`.
fn build_block(grid: &CellGrid, c: [i64; 3], block: &mut Block) {
    block.cell = pack_cell(c);
    block.x.clear();
    block.y.clear();
    block.z.clear();
    block.pos.clear();
    let centre = grid.cell_centre(c);
    block.centre = centre;
    for dz in -1..=1 {
        for dy in -1..=1 {
            for dx in -1..=1 {
                let cell = [c[0] + dx, c[1] + dy, c[2] + dz];
                let range = grid.cell_range(cell);
                if cell == c {
                    block.own_start = range.start;
                    block.own_end = range.end;
                    block.own_slot = block.pos.len();
                }
                for j in range {
                    let p = &grid.points[j];
                    block.x.push((p[0] - centre[0]) as f32);
                    block.y.push((p[1] - centre[1]) as f32);
                    block.z.push((p[2] - centre[2]) as f32);
                    block.pos.push(j as u32);
                }
            }
        }
    }
    block.len = block.pos.len();
    // Padding: points far outside the block (their squared distances stay finite in f32
    // for any cell size, and they are never candidates).
    let far = (2.0 * grid.cell_size).max(1.0) as f32 * 1e6;
    while !block.x.len().is_multiple_of(LANES) {
        block.x.push(far);
        block.y.push(far);
        block.z.push(far);
    }
    // Coordinates within the block are at most 1.5 cells (plus rounding slack) from the centre,
    // so each f32 coordinate is off by ≤ 1.5·cell·2^-24 and a coordinate difference by
    // ≤ 3·cell·2^-24; with differences ≤ 2 cells per axis and the f32 rounding of the squares
    // and sums (≤ 3·2^-24 of d² ≤ 12 cell²), |d²_f32 − d²| < 80·cell²·2^-24. 2^-16·cell² is a
    // generous bound.
    block.slack = grid.cell_size * grid.cell_size * (2.0f64).powi(-16);
}

/// The k nearest neighbours of sorted point `r` from the f32 block of its cell: all distances
/// to the block's points in f32 (vectorised), a threshold θ with at least k others below it,
/// then exact f64 distances for the candidates within the f32 error of θ. `ordered`: ranked by
/// (distance, index) and left in `scratch.sel` as [`grid_query`] does; otherwise the set, in
/// block order, straight in `scratch.ids` / `d2` / `pts` (see [`knn_map_set`]). Returns true,
/// or false when the block cannot prove the answer (the k-th distance reaches beyond the
/// block, or the block holds ≤ k points): then [`grid_query`] answers.
///
/// Exactness: with s the block's slack (|f32 − exact| ≤ s for every squared distance), at
/// least k other points have f32 distances ≤ θ, so the k-th distance within the block D_k ≤
/// θ + s; every nearer block point j then has d_f32(j) ≤ D_k + s ≤ θ + 2s, so it is among the
/// candidates measured exactly; and the exact D_k < b² (b the distance from q to the block's
/// faces, [`within_block`]) means no point outside the block is nearer.
fn block_query(grid: &CellGrid, r: usize, k: usize, ordered: bool, scratch: &mut Scratch) -> bool {
    let q = grid.points[r];
    let c = grid.cell_of(&q);
    let block = &mut scratch.block;
    if block.cell != pack_cell(c) || !(block.own_start..block.own_end).contains(&r) {
        build_block(grid, c, block);
    }
    if block.len <= k {
        return false;
    }
    let qx = (q[0] - block.centre[0]) as f32;
    let qy = (q[1] - block.centre[1]) as f32;
    let qz = (q[2] - block.centre[2]) as f32;
    sq_dists(block, [qx, qy, qz]);
    // The query's own slot stays in (its f32 distance is exactly 0): counts are of k + 1
    // points, and the slot is dropped from the candidates. (Overwriting its lane with +inf
    // cost a store-forwarding stall per query.)
    let own = (block.own_slot + (r - block.own_start)) as u64;
    let k1 = k + 1;
    let d_all = &block.d[..];
    let slack = block.slack;
    // θ: a value with at least k others' f32 distances ≤ θ, as small as cheaply found. The
    // previous query's neighbourhood bounds the k-th distance from above (as in
    // [`grid_query`]); squared distances on a surface are spread about uniformly below it, so
    // interpolating the count narrows θ in a few vectorised counting passes.
    let count = |t: f32| count_le(d_all, t);
    let mut theta = f32::NAN;
    let start = scratch.prev_dk;
    if start > 0.0 && start.is_finite() {
        // Start from the previous query's k-th squared distance (its neighbourhood is next to
        // this one: the count there is k ± 2 on a surface), then narrow with the counts: a
        // proportional model (the count grows like θ, the area of a disc on a surface) until
        // θ is bracketed, interpolation inside the bracket. Aim between the k-th and the
        // (k + 1)-th distance until exactly k others are ≤ θ: a count pass (two instructions
        // per vector) is cheaper than a spare candidate's exact distance and removal.
        // Measured (callgrind, 100k cube points, k = 20, set mode): starting from the largest
        // distance to the previous query's neighbours (an upper bound) and stopping at ≤ k + 3
        // others cost 5260 instructions per query; stopping at exactly k, 4500; this start,
        // 3810 (the previous neighbourhood no longer needs re-measuring, and two to three
        // counts suffice).
        let (mut lo, mut c_lo) = (0.0f32, 0usize);
        let (mut hi, mut c_hi) = (f32::INFINITY, usize::MAX);
        let mut t = start;
        for _ in 0..8 {
            let c = count(t);
            if c >= k1 {
                (hi, c_hi) = (t, c);
                if c == k1 {
                    break;
                }
            } else {
                (lo, c_lo) = (t, c);
            }
            let next = if c_hi == usize::MAX {
                if c == 0 {
                    4.0 * t
                } else {
                    t * ((k1 as f32 + 0.5) / c as f32).max(1.05)
                }
            } else {
                let f = ((k1 as f32 + 0.5 - c_lo as f32) / (c_hi - c_lo) as f32).clamp(0.05, 0.95);
                lo + (hi - lo) * f
            };
            if !(next > lo && next < hi) {
                break;
            }
            t = next;
        }
        if c_hi != usize::MAX {
            theta = hi;
        }
    }
    let tk = if theta.is_nan() {
        // No usable bound (first query of a task): the k-th smallest f32 distance to the
        // others, the (k + 1)-th with the query's own 0.
        block.keys.clear();
        block.keys.extend(
            d_all
                .iter()
                .flat_map(|v| v.to_array())
                .take(block.len)
                .map(f32::to_bits),
        );
        let (_, kth, _) = block.keys.select_nth_unstable(k);
        f64::from(f32::from_bits(*kth))
    } else {
        f64::from(theta)
    };
    let limit = tk + 2.0 * slack;
    // The largest f32 ≤ limit: for an f32 value v, v ≤ lim32 exactly when v ≤ limit.
    let mut lim32 = limit as f32;
    if f64::from(lim32) > limit {
        lim32 = f32::from_bits(lim32.to_bits() - 1);
    }
    // Candidates as u64 keys (f32 distance bits above the slot), bucket-sorted by distance:
    // squared distances below θ spread about uniformly, so most buckets hold one candidate and
    // the insertion pass that completes the sort rarely moves anything (no data-dependent
    // branches to mispredict, unlike a comparison sort).
    let keys = &mut block.cand_keys;
    keys.clear();
    let lim = f32x8::splat(lim32);
    for (ci, v) in d_all.iter().enumerate() {
        let mut mask = v.simd_le(lim).to_bitmask();
        if mask == 0 {
            continue;
        }
        let lanes = v.to_array();
        while mask != 0 {
            let j = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            keys.push((u64::from(lanes[j].to_bits()) << 32) | (ci * LANES + j) as u64);
        }
    }
    let exact = |key: &u64| {
        let pos = block.pos[(key & 0xffff_ffff) as usize] as usize;
        (
            dist2(&q, &grid.points[pos]).to_bits(),
            grid.ids[pos],
            pos as u32,
        )
    };
    let sel = &mut scratch.sel;
    sel.clear();
    if keys.len() > crowded(k) {
        return crowded_query(grid, r, k, ordered, scratch);
    }
    if ordered {
        bucket_sort(keys, lim32, &mut block.sorted_keys);
        // Exact (distance, index) order: f32 order is exact except between candidates within
        // the slack of each other, which the insertion pass puts right.
        sel.extend(
            block
                .sorted_keys
                .iter()
                .filter(|&&key| key & 0xffff_ffff != own)
                .map(exact),
        );
        insertion_sort(sel);
        sel.truncate(k);
        let dk = sel.last().map_or(f64::INFINITY, |c| f64::from_bits(c.0));
        if !within_block(grid, &q, c, dk) {
            return false;
        }
    } else {
        // The set only, in block order, straight into the result slices: the candidates
        // beyond k (one or two, see θ above) are the largest by (exact distance, index),
        // removed one at a time.
        // Positions first: every pass below is a map over a slice, so each `extend` reserves
        // once (pushing candidate by candidate, with a capacity check each, cost twice the
        // instructions).
        let cpos = &mut block.cand_pos;
        cpos.clear();
        cpos.extend(
            keys.iter()
                .map(|&key| block.pos[(key & 0xffff_ffff) as usize]),
        );
        let (ids, d2, pts) = (&mut scratch.ids, &mut scratch.d2, &mut scratch.pts);
        ids.extend(cpos.iter().map(|&j| grid.ids[j as usize]));
        pts.extend(cpos.iter().map(|&j| grid.points[j as usize]));
        d2.extend(pts.iter().map(|p| dist2(&q, p)));
        // Order-preserving removal: which spare candidates there are depends on θ, hence on
        // the previous query, and so on the thread count; the order of the others must not.
        let remove = |j: usize,
                      cpos: &mut Vec<u32>,
                      ids: &mut Vec<u32>,
                      d2: &mut Vec<f64>,
                      pts: &mut Vec<Point3>| {
            cpos.remove(j);
            ids.remove(j);
            d2.remove(j);
            pts.remove(j);
        };
        if let Some(j) = cpos.iter().position(|&j| j as usize == r) {
            remove(j, cpos, ids, d2, pts);
        }
        while ids.len() > k {
            let (mut worst, mut worst_key) = (0, 0u128);
            for (j, (&d, &id)) in d2.iter().zip(ids.iter()).enumerate() {
                let key = (u128::from(d.to_bits()) << 32) | u128::from(id);
                if key > worst_key {
                    (worst, worst_key) = (j, key);
                }
            }
            remove(worst, cpos, ids, d2, pts);
        }
        // (Non-negative floats order like their bits: an integer max, no NaN handling.)
        let dk = f64::from_bits(d2.iter().map(|d| d.to_bits()).max().unwrap_or(0));
        if !within_block(grid, &q, c, dk) {
            return false;
        }
        scratch.prev.clear();
        scratch.prev_dk = dk as f32;
        return true;
    }
    scratch.prev.clear();
    scratch.prev_dk = sel.last().map_or(0.0, |c| f64::from_bits(c.0) as f32);
    true
}

/// More candidates than this for k neighbours make [`block_query`] select instead of sort.
#[inline]
fn crowded(k: usize) -> usize {
    4 * k + 32
}

/// [`block_query`]'s ending when its candidates are many more than k: points that coincide
/// or lie within the f32 slack of each other (duplicates, or cells far wider than the spacing
/// because an outlier stretched the quantiser's unit). Sorting them all is quadratic there (all
/// keys in one bucket): a 3,000-point cloud of one repeated point took 5 s, one with a point
/// 1e9 away 7 s. Here the k nearest by exact (distance, index) are selected in linear time.
/// The result is the one the sorting path gives (nearest first, or the set in block order),
/// so which path a query takes, which depends on the previous query, changes nothing.
#[cold]
fn crowded_query(
    grid: &CellGrid,
    r: usize,
    k: usize,
    ordered: bool,
    scratch: &mut Scratch,
) -> bool {
    let q = grid.points[r];
    let c = grid.cell_of(&q);
    let block = &scratch.block;
    let own = (block.own_slot + (r - block.own_start)) as u64;
    // (exact squared distance bits, input index, block slot): tuples unique by index.
    let sel = &mut scratch.sel;
    sel.clear();
    sel.extend(
        block
            .cand_keys
            .iter()
            .map(|&key| key & 0xffff_ffff)
            .filter(|&slot| slot != own)
            .map(|slot| {
                let pos = block.pos[slot as usize] as usize;
                (
                    dist2(&q, &grid.points[pos]).to_bits(),
                    grid.ids[pos],
                    slot as u32,
                )
            }),
    );
    if sel.len() > k {
        sel.select_nth_unstable(k);
        sel.truncate(k);
    }
    let dk = f64::from_bits(sel.iter().map(|s| s.0).max().unwrap_or(0));
    if !within_block(grid, &q, c, dk) {
        return false;
    }
    scratch.prev.clear();
    scratch.prev_dk = dk as f32;
    if ordered {
        sel.sort_unstable();
        for s in sel.iter_mut() {
            s.2 = block.pos[s.2 as usize];
        }
    } else {
        // The set in block order, as the removal of the spare candidates leaves it.
        sel.sort_unstable_by_key(|s| s.2);
        for &(d, id, slot) in sel.iter() {
            let pos = block.pos[slot as usize] as usize;
            scratch.ids.push(id);
            scratch.d2.push(f64::from_bits(d));
            scratch.pts.push(grid.points[pos]);
        }
    }
    true
}

/// Whether the k nearest neighbours found in the 3 x 3 x 3 block of cell `c`, the k-th at
/// squared distance `dk`, are the true ones: no point outside the block is that near. Decided
/// on the exact `dk` (not on the search's threshold θ, which depends on the previous query), so
/// whether the block answers does not depend on the thread count either.
#[inline]
fn within_block(grid: &CellGrid, q: &Point3, c: [i64; 3], dk: f64) -> bool {
    if grid.covers_all(c, 1) {
        return true;
    }
    let b = grid.shell_bound(q, c, 1);
    b > 0.0 && dk < b * b
}

/// Grid search for sorted point `r`, at most `max_shells` shells; leaves the k nearest in
/// `scratch.sel` (sorted by distance then input index) and returns true, or false when
/// unfinished.
///
/// The previous query p of the same thread bounds the search: among p and its k neighbours
/// (k + 1 points) at least k differ from q, so the k-th smallest of their distances to q bounds
/// q's k-th neighbour distance from above; farther candidates and cells are skipped from the
/// start. Consecutive queries (Morton order) share most neighbours, so the bound is tight. Consecutive queries (Morton order)
/// mostly share a cell, so the cell's 3 x 3 x 3 block is looked up once for all of them.
fn grid_query(grid: &CellGrid, r: usize, k: usize, max_shells: i64, scratch: &mut Scratch) -> bool {
    let q = grid.points[r];
    let c = grid.cell_of(&q);
    let mut t2_bits = f64::INFINITY.to_bits();
    if scratch.prev.len() == k + 1 {
        // The k-th smallest distance from q to the k + 1 points of `prev` other than q itself:
        // their largest distance if q is one of them, else the second largest.
        let (mut first, mut second) = (0u64, 0u64);
        let mut has_q = false;
        for &j in &scratch.prev {
            if j as usize == r {
                has_q = true;
                continue;
            }
            let d = dist2(&q, &grid.points[j as usize]).to_bits();
            if d > first {
                second = first;
                first = d;
            } else if d > second {
                second = d;
            }
        }
        t2_bits = if has_q { first } else { second };
    }
    let mut t2 = f64::from_bits(t2_bits);
    if scratch.cell != Some(c) {
        scratch.near.clear();
        for s in 0..=1 {
            grid.for_each_shell_cell(c, s, |cell| {
                let range = grid.cell_range(cell);
                if !range.is_empty() {
                    scratch.near.push((cell, range.start, range.end));
                }
            });
        }
        scratch.cell = Some(c);
    }
    let cands = &mut scratch.cands;
    cands.clear();
    for &(cell, lo, hi) in &scratch.near {
        if grid.cell_min_dist2(&q, cell) <= t2 {
            scan(grid, &q, r, lo, hi, t2_bits, cands);
        }
    }
    let mut s = 1i64;
    loop {
        if cands.len() >= k {
            select_sorted(cands, k, &mut scratch.keys, &mut scratch.sel);
            let kth = scratch.sel.last().map_or(0, |c| c.0);
            t2_bits = kth;
            t2 = f64::from_bits(kth);
            let b = grid.shell_bound(&q, c, s);
            if !(grid.covers_all(c, s) || (b > 0.0 && t2 < b * b)) {
                // Some points within the k-th distance may lie beyond the scanned cube: scan
                // the cells of the ball's bounding box outside it (usually a few face cells of
                // the next shell), which makes the search exact.
                let (lo, hi) = grid.cell_box(&q, t2.sqrt());
                if (0..3).any(|a| c[a] - lo[a] > max_shells || hi[a] - c[a] > max_shells) {
                    return false;
                }
                for z in lo[2]..=hi[2] {
                    for y in lo[1]..=hi[1] {
                        let inside_yz = (z - c[2]).abs() <= s && (y - c[1]).abs() <= s;
                        for x in lo[0]..=hi[0] {
                            if inside_yz && (x - c[0]).abs() <= s {
                                continue;
                            }
                            let cell = [x, y, z];
                            if grid.cell_min_dist2(&q, cell) > t2 {
                                continue;
                            }
                            let range = grid.cell_range(cell);
                            scan(grid, &q, r, range.start, range.end, t2_bits, cands);
                        }
                    }
                }
                select_sorted(cands, k, &mut scratch.keys, &mut scratch.sel);
            }
            scratch.prev.clear();
            scratch.prev.push(r as u32);
            scratch.prev.extend(scratch.sel.iter().map(|c| c.2));
            return true;
        } else if grid.covers_all(c, s) {
            // Unreachable for n > k (every point was a candidate); keep the search sound anyway.
            return false;
        }
        if s >= max_shells {
            return false;
        }
        s += 1;
        grid.for_each_shell_cell(c, s, |cell| {
            if grid.cell_min_dist2(&q, cell) > t2 {
                return;
            }
            let range = grid.cell_range(cell);
            scan(grid, &q, r, range.start, range.end, t2_bits, cands);
        });
    }
}

/// Low bits of a selection key that hold the candidate's slot (the distance bits they replace
/// are 2^-40 of its value: keys order candidates by distance except among near-equal ones, which
/// [`select_sorted`] puts in exact order afterwards).
const SLOT_BITS: u32 = 12;
const SLOT_MASK: u64 = (1 << SLOT_BITS) - 1;
/// Up to this many candidates are sorted whole rather than selected first.
const FULL_SORT: usize = 64;

/// The k candidates smallest by (squared distance, input index), sorted, into `sel`.
///
/// Candidates are ranked by u64 keys (distance bits with the slot in the low [`SLOT_BITS`]):
/// quick selection and sorting of plain integers, then an insertion pass with the exact
/// comparison, which only moves near-equal neighbours. When the k-th key's truncated distance is
/// shared with candidates beyond it, those are ranked exactly too.
fn select_sorted(
    cands: &[(u64, u32, u32)],
    k: usize,
    keys: &mut Vec<u64>,
    sel: &mut Vec<(u64, u32, u32)>,
) {
    sel.clear();
    if cands.len() > SLOT_MASK as usize {
        sel.extend_from_slice(cands);
        sel.select_nth_unstable(k - 1);
        sel.truncate(k);
        sel.sort_unstable();
        return;
    }
    keys.clear();
    keys.extend(
        cands
            .iter()
            .enumerate()
            .map(|(i, c)| (c.0 & !SLOT_MASK) | i as u64),
    );
    let mut m = keys.len();
    if m > k && m > FULL_SORT {
        keys.select_nth_unstable(k - 1);
        let tk = keys[k - 1] & !SLOT_MASK;
        // Candidates beyond the k-th whose truncated distance equals it may rank before it.
        m = k;
        for i in k..keys.len() {
            if keys[i] & !SLOT_MASK == tk {
                keys.swap(m, i);
                m += 1;
            }
        }
    }
    let keys = &mut keys[..m];
    keys.sort_unstable();
    // Only candidates whose truncated distances are equal can be out of place: take the k
    // first, plus those tied with the k-th, and order them exactly.
    let mut end = m.min(k);
    if let Some(&kth) = keys.get(end.wrapping_sub(1)) {
        while end < m && keys[end] & !SLOT_MASK == kth & !SLOT_MASK {
            end += 1;
        }
    }
    sel.extend(
        keys[..end]
            .iter()
            .map(|&key| cands[(key & SLOT_MASK) as usize]),
    );
    if sel.len() > k + FULL_SORT {
        // Many ties with the k-th (coincident points, or distances that underflow to 0): an
        // exact selection, as the insertion pass would be quadratic.
        sel.select_nth_unstable(k - 1);
        sel.truncate(k);
        sel.sort_unstable();
        return;
    }
    insertion_sort(sel);
    sel.truncate(k);
}

/// Exact k-d tree search for point `r` of `pts` (input indices `ids`), ties by input index: asks
/// the tree for more points until the farthest returned is strictly beyond the k-th kept.
fn kd_query(index: &KdIndex, pts: &[Point3], ids: &[u32], r: usize, best: &mut Best) {
    let n = pts.len();
    let q = pts[r];
    let k = best.k;
    let mut want = (k + 1).min(n);
    loop {
        best.reset(k);
        let nn = index.nearest(&q, want);
        let mut far = 0.0f64;
        for &(j, dk) in &nn {
            far = far.max(dk);
            if j as usize != r {
                best.offer(dist2(&q, &pts[j as usize]), ids[j as usize]);
            }
        }
        if nn.len() >= n || want >= n || far > best.worst() {
            return;
        }
        want = (want * 2).min(n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_land_in_input_order() {
        let ids: Vec<u32> = vec![3, 0, 4, 1, 2];
        let out: Vec<String> = map_to_input_order(&ids, || (), |_, r| format!("rank {r}")).unwrap();
        for (r, &i) in ids.iter().enumerate() {
            assert_eq!(out[i as usize], format!("rank {r}"));
        }
        let (a, b): (Vec<usize>, Vec<String>) =
            map_to_input_order(&ids, || (), |_, r| (r, format!("rank {r}"))).unwrap();
        for (r, &i) in ids.iter().enumerate() {
            assert_eq!((a[i as usize], &b[i as usize]), (r, &format!("rank {r}")));
        }
        // Not a permutation: an error, never a panic.
        assert!(map_to_input_order::<Vec<_>, _, _, _>(&[1, 1, 7, 0, 2], || (), |_, r| r).is_err());
        assert!(map_to_input_order::<Vec<_>, _, _, _>(&[0, 2], || (), |_, r| r).is_err());
    }
}
