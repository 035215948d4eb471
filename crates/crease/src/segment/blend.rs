//! Rounded edges recovered from the planes they round, on noisy clouds (not in the paper;
//! issue 29).
//!
//! Under noise of half a spacing and more the region growing may not see a fillet: its points
//! leave the planes beside it by `r (1 − cos θ)`, within the widened tolerances for tens of
//! degrees, so the planes take its flanks and whatever fit takes the rest is no fillet (the
//! fillet-chamfer-cone part at a whole spacing: a cone of half angle 1.2°, which no tangency
//! test takes). A designer's fillet is fixed by the two planes it rounds and one radius, so it
//! is fitted as such, on all the points about it instead of on a region the noise drew:
//! - every pair of non-parallel planes that touch (directly, through regions that are not
//!   planes, or across a set of unassigned vertices) and that no tangent cylinder joins yet
//!   is given the **rounded edge** of radius `r` that fits their points and those between
//!   best: a geometric grid in `r`, then a golden-section search, of a truncated
//!   least-squares cost in which each point is measured to the part of the rounded edge whose
//!   *zone* holds it (the cylinder inside the wedge its two tangent lines subtend from the
//!   axis, else the plane on its side);
//! - the edge is kept when, over its zone, it beats the sharp edge by [`ROUNDED_GAIN`] noise
//!   scales in quadrature, its cylinder's robust residual scale is within [`ROUND_SLACK`]
//!   times the noise, and the zone holds at least [`MIN_BLEND_POINTS`];
//! - a new edge that closes a triangle of rounded edges (a rounded corner, where a ball would
//!   meet three cylinders) is left to the region growing: the B-rep does not yet build the
//!   vertices where four tangent surfaces meet (with corner balls the noisy rounded cube's
//!   segmentation came out exact but its B-rep an open shell; the trial and its patch are in
//!   `docs/experiments/noisy-segmentation.md`);
//! - the points go to the zones, not to the nearest surface: within about `√(2 r σ)` of a
//!   tangent border the noise, not the geometry, decides which surface is nearer. A point
//!   moves only when its zone's surface lies within [`GATE_SIGMAS`] noise scales of where its
//!   own does (a face that runs on past the end of a rounded edge keeps its points).
//!
//! The planes are then refitted on what is left to them, the radii on their zones (tangent to
//! the planes, as in [`super::tangent`]), and the zones drawn again once. The noise is the
//! points' own (`estimate::noise::noise_sigma`): the seeds' overstates it where they straddle
//! surfaces (0.0134 for 0.0015 on the rounded cube at a fifth of a spacing).

use rayon::prelude::*;

use super::fit::Fit;
use super::grow::{Ctx, Region};
use super::merge::{contacts, renumber, Part, MIN_CONTACT};
use super::tangent::{fit_radius, solve3, Tangent};
use crate::geometry::vec3::{cross, dot, norm, normalize, scale, sub};
use crate::geometry::{Point3, SurfaceParams, SurfaceType};
use crate::spatial::Adjacency;

/// The rounded edge must explain the points of its zone better than the sharp edge by this many
/// noise scales, in quadrature (the mean over the zone of the difference of their squared
/// distances, each capped at [`GATE_SIGMAS`] noise scales).
const ROUNDED_GAIN: f64 = 0.5;

/// A rounded edge's cylinder explains its zone within this many times the noise (robust
/// scale): a depth camera blurs a box's sharp edges over a few spacings into profiles that a
/// cylinder fits 3–4 times worse than the noise (`caixa.ply`: 0.0044–0.0057 against 0.0015).
const ROUND_SLACK: f64 = 1.25;

/// Fewest points in a blend's zone: a radius fitted to fewer is the noise's.
const MIN_BLEND_POINTS: usize = 30;

/// A point moves to a zone's surface only if it lies at most this many noise scales farther
/// from it than from its own region's surface.
const GATE_SIGMAS: f64 = 3.0;

/// Planes whose normals are this close (degrees) to parallel bound no blend between them.
const PARALLEL_DEGREES: f64 = 10.0;

/// A cylinder's axis this close (degrees) to an edge's direction, at its radius from both
/// planes (within [`TANGENT_TOLERANCE`] of it), already rounds the edge.
const AXIS_DEGREES: f64 = 10.0;
const TANGENT_TOLERANCE: f64 = 0.2;

/// Most points of a pair's neighbourhood the radius search reads (evenly strided).
const SEARCH_SAMPLE: usize = 30_000;

/// A plane `n · x = o` and the sign `s` with which the depth `s (n · x − o)` is positive on the
/// blend's side (towards the centre of its arcs).
#[derive(Clone, Copy, Debug)]
struct Side {
    region: usize,
    n: Point3,
    o: f64,
    s: f64,
}

impl Side {
    fn depth(&self, p: Point3) -> f64 {
        self.s * (dot(self.n, p) - self.o)
    }
    /// From the centre towards the plane.
    fn towards(&self) -> Point3 {
        scale(self.n, -self.s)
    }
    fn tangent(&self) -> Tangent {
        (self.n, self.o, -self.s)
    }
}

/// A rounded edge between planes `a` and `b`.
#[derive(Clone, Debug)]
struct Edge {
    a: Side,
    b: Side,
    r: f64,
    /// The axis direction and a point of the axis.
    dir: Point3,
    centre: Point3,
    /// The cylinder's region (made for it).
    region: usize,
    /// Regions whose points the edge may take: its planes, its cylinder, those between.
    from: Vec<usize>,
}

/// The axis point of the edge of radius `r` nearest `near`.
fn edge_axis(a: &Side, b: &Side, r: f64, near: Point3) -> Option<(Point3, Point3)> {
    let d = normalize(cross(a.n, b.n))?;
    let c = solve3([a.n, b.n, d], [a.o + a.s * r, b.o + b.s * r, dot(d, near)])?;
    Some((d, c))
}

/// Whether `p` lies in the edge's cylinder zone, and its distance to the cylinder.
fn edge_zone(e: &Edge, p: Point3) -> (bool, f64) {
    let q = sub(p, e.centre);
    let q = sub(q, scale(e.dir, dot(q, e.dir)));
    let (ma, mb) = (e.a.towards(), e.b.towards());
    let g = dot(ma, mb);
    let (qa, qb) = (dot(q, ma), dot(q, mb));
    // q = α m_a + β m_b (m_a, m_b across the axis): inside the wedge when both are ≥ 0.
    let inside = qa - g * qb >= 0.0 && qb - g * qa >= 0.0;
    (inside, norm(q) - e.r)
}

/// The distance from `p` to the rounded edge of radius `r` (planes `a`, `b`, axis through
/// `c` along `d`), each point measured to the part whose zone holds it.
fn rounded_distance(a: &Side, b: &Side, d: Point3, c: Point3, r: f64, p: Point3) -> f64 {
    let q = sub(p, c);
    let q = sub(q, scale(d, dot(q, d)));
    let (ma, mb) = (a.towards(), b.towards());
    let g = dot(ma, mb);
    let (qa, qb) = (dot(q, ma), dot(q, mb));
    let (alpha, beta) = (qa - g * qb, qb - g * qa);
    if alpha >= 0.0 && beta >= 0.0 {
        norm(q) - r
    } else if beta < 0.0 && alpha >= 0.0 {
        a.depth(p)
    } else if alpha < 0.0 && beta >= 0.0 {
        b.depth(p)
    } else {
        a.depth(p).abs().min(b.depth(p).abs())
    }
}

/// The plane of region `i`, if it is one.
fn plane(regions: &[Region], i: usize) -> Option<(Point3, f64)> {
    match regions[i].fit.params {
        SurfaceParams::Plane { normal, offset } => Some((normal, offset)),
        _ => None,
    }
}

/// Whether the surface of region `j` already rounds the edge of planes `a`, `b` (a cylinder
/// along it, or a sphere, at its radius from both).
fn rounds(regions: &[Region], j: usize, a: (Point3, f64), b: (Point3, f64)) -> bool {
    let (c, r) = match regions[j].fit.params {
        SurfaceParams::Cylinder {
            axis_point,
            axis_dir,
            radius,
        } => {
            let Some(d) = normalize(cross(a.0, b.0)) else {
                return false;
            };
            if dot(d, axis_dir).abs() < AXIS_DEGREES.to_radians().cos() {
                return false;
            }
            (axis_point, radius)
        }
        SurfaceParams::Sphere { center, radius } => (center, radius),
        _ => return false,
    };
    let off = |(n, o): (Point3, f64)| ((dot(n, c) - o).abs() - r).abs();
    off(a) <= TANGENT_TOLERANCE * r && off(b) <= TANGENT_TOLERANCE * r
}

/// The vertices of regions `from`, concatenated.
fn vertices_of(regions: &[Region], from: &[usize]) -> Vec<u32> {
    from.iter()
        .flat_map(|&i| regions[i].vertices.iter().copied())
        .collect()
}

/// The connected sets of unassigned vertices (graph components): each vertex's set
/// (`u32::MAX` when assigned) and each set's bordering regions with their counts of graph
/// edges into it.
fn free_sets<G: Adjacency>(ctx: &Ctx<G>, owner: &[i32]) -> (Vec<u32>, Vec<Vec<(usize, usize)>>) {
    let mut set = vec![u32::MAX; owner.len()];
    let mut borders = Vec::new();
    let mut stack = Vec::new();
    for s in 0..owner.len() {
        if owner[s] >= 0 || set[s] != u32::MAX {
            continue;
        }
        let id = borders.len() as u32;
        let mut around: Vec<usize> = Vec::new();
        set[s] = id;
        stack.push(s as u32);
        while let Some(v) = stack.pop() {
            ctx.topo.for_each_neighbor(v as usize, |w| {
                let o = owner[w as usize];
                if o >= 0 {
                    around.push(o as usize);
                } else if set[w as usize] == u32::MAX {
                    set[w as usize] = id;
                    stack.push(w);
                }
            });
        }
        around.sort_unstable();
        let mut counts = Vec::new();
        let mut i = 0;
        while i < around.len() {
            let j = i + around[i..].iter().take_while(|&&r| r == around[i]).count();
            counts.push((around[i], j - i));
            i = j;
        }
        borders.push(counts);
    }
    (set, borders)
}

/// Pairs of regions that share graph edges or border one set of unassigned vertices (the
/// noisiest fillets leave bands of them between their planes), lower id first, sorted.
fn touching<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &[i32],
    borders: &[Vec<(usize, usize)>],
) -> Vec<(u32, u32)> {
    let mut out = contacts(ctx, owner);
    for b in borders {
        let near: Vec<usize> = b
            .iter()
            .filter(|x| x.1 >= MIN_CONTACT)
            .map(|x| x.0)
            .collect();
        for (i, &a) in near.iter().enumerate() {
            for &c in &near[i + 1..] {
                out.push((a as u32, c as u32));
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// The rounded edge between planes `pa` and `pb` that fits the points of regions `from` best
/// (see the module documentation), if it explains them better than the sharp edge.
fn fit_edge<G: Adjacency>(
    ctx: &Ctx<G>,
    regions: &[Region],
    (pa, pb, from): (usize, usize, Vec<usize>),
    sigma: f64,
    floor: f64,
    l: f64,
) -> Option<Edge> {
    let (na, oa) = plane(regions, pa)?;
    let (nb, ob) = plane(regions, pb)?;
    // Each plane's blend side is where the other face lies.
    let side_of = |n: Point3, o: f64, other: usize| {
        let vs = &regions[other].vertices;
        let mut d: Vec<f64> = vs
            .iter()
            .map(|&v| dot(n, ctx.pos[v as usize]) - o)
            .collect();
        if d.is_empty() {
            return 1.0;
        }
        let mid = d.len() / 2;
        let (_, m, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
        if *m >= 0.0 {
            1.0
        } else {
            -1.0
        }
    };
    let a = Side {
        region: pa,
        n: na,
        o: oa,
        s: side_of(na, oa, pb),
    };
    let b = Side {
        region: pb,
        n: nb,
        o: ob,
        s: side_of(nb, ob, pa),
    };
    // The largest radius searched: half the narrower face's extent from the edge.
    let extent = |plane: &Side, face: usize| {
        let mut d: Vec<f64> = regions[face]
            .vertices
            .iter()
            .map(|&v| plane.depth(ctx.pos[v as usize]))
            .collect();
        if d.is_empty() {
            return 0.0;
        }
        let k = ((d.len() * 9) / 10).min(d.len() - 1);
        let (_, m, _) = d.select_nth_unstable_by(k, f64::total_cmp);
        *m
    };
    let r_max = 0.5 * extent(&b, pa).min(extent(&a, pb));
    let r_min = 2.0 * l;
    if r_max.is_nan() || r_max <= r_min {
        return None;
    }
    let vs = vertices_of(regions, &from);
    let band: Vec<Point3> = vs
        .iter()
        .map(|&v| ctx.pos[v as usize])
        .filter(|&p| a.depth(p) < 2.0 * r_max && b.depth(p) < 2.0 * r_max)
        .collect();
    if band.len() < MIN_BLEND_POINTS {
        return None;
    }
    let step = band.len().div_ceil(SEARCH_SAMPLE).max(1);
    let sample: Vec<Point3> = band.iter().step_by(step).copied().collect();
    let near = sample
        .iter()
        .fold([0.0; 3], |s, &p| crate::geometry::vec3::add(s, p));
    let near = scale(near, 1.0 / sample.len() as f64);
    let cap = (GATE_SIGMAS * sigma).powi(2);
    let cost = |r: f64| -> f64 {
        match edge_axis(&a, &b, r, near) {
            Some((d, c)) => sample
                .iter()
                .map(|&p| rounded_distance(&a, &b, d, c, r, p).powi(2).min(cap))
                .sum(),
            None => f64::INFINITY,
        }
    };
    // A geometric grid in r, then a golden-section search about its best.
    let mut grid = Vec::new();
    let mut r = r_min;
    while r <= r_max {
        grid.push(r);
        r *= 1.05;
    }
    let costs: Vec<f64> = grid.iter().map(|&r| cost(r)).collect();
    let best = (0..grid.len()).min_by(|&i, &j| costs[i].total_cmp(&costs[j]))?;
    let (mut lo, mut hi) = (
        grid[best.saturating_sub(1)],
        grid[(best + 1).min(grid.len() - 1)],
    );
    let phi = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..20 {
        let (x1, x2) = (hi - phi * (hi - lo), lo + phi * (hi - lo));
        if cost(x1) <= cost(x2) {
            hi = x2;
        } else {
            lo = x1;
        }
    }
    let r = 0.5 * (lo + hi);
    let (dir, centre) = edge_axis(&a, &b, r, near)?;
    let e = Edge {
        a,
        b,
        r,
        dir,
        centre,
        region: usize::MAX,
        from,
    };
    // The zone's points, measured to the cylinder and to the sharp edge.
    let (mut round, mut gain) = (Vec::new(), 0.0);
    for &p in &band {
        let (inside, d) = edge_zone(&e, p);
        let sharp = a.depth(p).abs().min(b.depth(p).abs());
        if inside && d.abs() <= GATE_SIGMAS * sigma + sharp {
            round.push(d.abs());
            gain += sharp.powi(2).min(cap) - d.powi(2).min(cap);
        }
    }
    let n = round.len();
    if n < MIN_BLEND_POINTS {
        return None;
    }
    // Robust: the zone still holds the corners' points, which no cylinder explains.
    let (_, mid, _) = round.select_nth_unstable_by(n / 2, f64::total_cmp);
    let scale_round = 1.4826 * *mid;
    (gain >= ROUNDED_GAIN.powi(2) * sigma * sigma * n as f64
        && scale_round <= ROUND_SLACK * sigma + floor)
        .then_some(e)
}

/// Gives the points of the regions the blends may take, and the unassigned vertices bordering
/// them, to their zones (see the module documentation).
fn relabel<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &mut [i32],
    regions: &[Region],
    edges: &[Edge],
    sigma: f64,
) {
    let mut touched: Vec<usize> = edges.iter().flat_map(|e| e.from.iter().copied()).collect();
    touched.sort_unstable();
    touched.dedup();
    // Each vertex with the regions whose blends it may join: its own, or for an unassigned
    // vertex those its set borders.
    let (free, borders) = free_sets(ctx, owner);
    let near: Vec<Vec<usize>> = borders
        .iter()
        .map(|b| {
            b.iter()
                .map(|x| x.0)
                .filter(|r| touched.binary_search(r).is_ok())
                .collect()
        })
        .collect();
    let mut vs: Vec<u32> = touched
        .iter()
        .flat_map(|&i| regions[i].vertices.iter().copied())
        .collect();
    vs.extend(
        (0..owner.len() as u32).filter(|&v| {
            free[v as usize] != u32::MAX && !near[free[v as usize] as usize].is_empty()
        }),
    );
    let gate = GATE_SIGMAS * sigma;
    let moves: Vec<(u32, i32)> = vs
        .par_iter()
        .filter_map(|&v| {
            let p = ctx.pos[v as usize];
            let o = owner[v as usize];
            let assigned = o >= 0;
            let mine: &[usize] = if assigned {
                std::slice::from_ref(&touched[touched.binary_search(&(o as usize)).ok()?])
            } else {
                &near[free[v as usize] as usize]
            };
            let eligible = |from: &[usize]| mine.iter().any(|r| from.binary_search(r).is_ok());
            let own = if assigned {
                crate::geometry::surface::signed_distance(&regions[o as usize].fit.params, p).abs()
            } else {
                0.0
            };
            let changes = |r: usize| (!assigned || r != o as usize).then_some((v, r as i32));
            let mut best: Option<(f64, usize)> = None;
            for e in edges.iter().filter(|e| eligible(&e.from)) {
                let (inside, d) = edge_zone(e, p);
                if inside && d.abs() <= own + gate && best.is_none_or(|(bd, _)| d.abs() < bd) {
                    best = Some((d.abs(), e.region));
                }
            }
            if let Some((_, r)) = best {
                return changes(r);
            }
            // A blend's point outside every zone goes back to the nearer of its planes.
            let o = o as usize;
            let blend = assigned && edges.iter().any(|e| e.region == o);
            if !blend {
                return None;
            }
            edges
                .iter()
                .filter(|e| e.from.binary_search(&o).is_ok())
                .flat_map(|e| [e.a, e.b])
                .map(|s| (s.depth(p).abs(), s.region))
                .min_by(|x, y| x.0.total_cmp(&y.0))
                .and_then(|(_, r)| changes(r))
        })
        .collect();
    for (v, r) in moves {
        owner[v as usize] = r;
    }
}

/// Rounded edges from the planes (see the module documentation); returns whether any was
/// made. `owner` and `regions` are rebuilt: new regions appended, emptied
/// ones removed.
pub(crate) fn blends<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &mut [i32],
    regions: &mut Vec<Region>,
    sigma: f64,
    floor: f64,
    l: f64,
) -> bool {
    let nreg = regions.len();
    let mut neighbours: Vec<Vec<usize>> = vec![Vec::new(); nreg];
    let (_, borders) = free_sets(ctx, owner);
    for (a, b) in touching(ctx, owner, &borders) {
        neighbours[a as usize].push(b as usize);
        neighbours[b as usize].push(a as usize);
    }
    let parallel = PARALLEL_DEGREES.to_radians().cos();
    // Pairs of planes that touch, directly or through regions that are not planes.
    let mut pairs: Vec<(usize, usize, Vec<usize>)> = Vec::new();
    let mut existing: Vec<(usize, usize)> = Vec::new();
    for pa in 0..nreg {
        let Some(a) = plane(regions, pa) else {
            continue;
        };
        let mut candidates: Vec<usize> = neighbours[pa].clone();
        for &j in &neighbours[pa] {
            if plane(regions, j).is_none() {
                candidates.extend(neighbours[j].iter().copied());
            }
        }
        candidates.sort_unstable();
        candidates.dedup();
        for &pb in candidates.iter().filter(|&&pb| pb > pa) {
            let Some(b) = plane(regions, pb) else {
                continue;
            };
            if dot(a.0, b.0).abs() >= parallel {
                continue;
            }
            let common: Vec<usize> = neighbours[pa]
                .iter()
                .copied()
                .filter(|j| neighbours[pb].contains(j) && plane(regions, *j).is_none())
                .collect();
            // A tangent cylinder rounds the edge already: recorded, for the corners.
            if common
                .iter()
                .any(|&j| regions[j].kind == SurfaceType::Cylinder && rounds(regions, j, a, b))
            {
                existing.push((pa, pb));
                continue;
            }
            // Regions between that already round something else stay out.
            let between = common
                .into_iter()
                .filter(|&j| {
                    !neighbours[j].iter().any(|&x| {
                        x != pa
                            && x != pb
                            && plane(regions, x).is_some_and(|xp| {
                                rounds(regions, j, a, xp) || rounds(regions, j, b, xp)
                            })
                    })
                })
                .collect::<Vec<_>>();
            let mut from = vec![pa, pb];
            from.extend(between);
            from.sort_unstable();
            pairs.push((pa, pb, from));
        }
    }
    let new: Vec<Edge> = pairs
        .into_par_iter()
        .filter_map(|pair| fit_edge(ctx, regions, pair, sigma, floor, l))
        .collect();
    // A new edge that closes a triangle of rounded edges rounds a corner: left out (see the
    // module documentation).
    let key = |e: &Edge| (e.a.region.min(e.b.region), e.a.region.max(e.b.region));
    let mut rounded: Vec<(usize, usize)> =
        existing.into_iter().chain(new.iter().map(key)).collect();
    rounded.sort_unstable();
    let is_rounded = |a: usize, b: usize| rounded.binary_search(&(a.min(b), a.max(b))).is_ok();
    let mut edges: Vec<Edge> = new
        .into_iter()
        .filter(|e| {
            let (a, b) = key(e);
            !(0..nreg).any(|c| c != a && c != b && is_rounded(a, c) && is_rounded(b, c))
        })
        .collect();
    if edges.is_empty() {
        return false;
    }
    for e in &mut edges {
        e.region = regions.len();
        e.from.push(e.region);
        e.from.sort_unstable();
        regions.push(Region {
            kind: SurfaceType::Cylinder,
            fit: Fit {
                params: SurfaceParams::Cylinder {
                    axis_point: e.centre,
                    axis_dir: e.dir,
                    radius: e.r,
                },
                rms: 0.0,
            },
            vertices: Vec::new(),
        });
    }
    for round in 0..2 {
        relabel(ctx, owner, regions, &edges, sigma);
        rebuild(owner, regions);
        if round == 0 {
            refit(ctx, regions, &mut edges);
        }
    }
    // What the zones left of a region between planes goes to the nearest of the edges'
    // surfaces.
    let leftover: Vec<(u32, i32)> = (0..nreg)
        .filter(|&i| {
            let n = regions[i].vertices.len();
            n > 0 && n < MIN_BLEND_POINTS && plane(regions, i).is_none()
        })
        .flat_map(|i| {
            let near: Vec<usize> = edges
                .iter()
                .filter(|e| e.from.binary_search(&i).is_ok())
                .flat_map(|e| [e.region, e.a.region, e.b.region])
                .collect();
            let regions = &*regions;
            regions[i].vertices.iter().filter_map(move |&v| {
                let p = ctx.pos[v as usize];
                near.iter()
                    .map(|&r| {
                        let d =
                            crate::geometry::surface::signed_distance(&regions[r].fit.params, p);
                        (d.abs(), r)
                    })
                    .min_by(|x, y| x.0.total_cmp(&y.0))
                    .map(|(_, r)| (v, r as i32))
            })
        })
        .collect();
    if !leftover.is_empty() {
        for (v, r) in leftover {
            owner[v as usize] = r;
        }
        rebuild(owner, regions);
    }
    refit(ctx, regions, &mut edges);
    // Regions emptied (a cone that held a corner and its fillets) are removed.
    let alive: Vec<bool> = regions.iter().map(|r| !r.vertices.is_empty()).collect();
    if alive.iter().any(|a| !a) {
        renumber(owner, regions, &alive);
    }
    true
}

/// Each region's vertices from `owner`, in ascending order.
fn rebuild(owner: &[i32], regions: &mut [Region]) {
    for r in regions.iter_mut() {
        r.vertices.clear();
    }
    for (v, &o) in owner.iter().enumerate() {
        if o >= 0 {
            regions[o as usize].vertices.push(v as u32);
        }
    }
}

/// The planes refitted on their points, then each blend's radius on its zone, tangent to them.
fn refit<G: Adjacency>(ctx: &Ctx<G>, regions: &mut [Region], edges: &mut [Edge]) {
    let mut planes: Vec<usize> = edges
        .iter()
        .flat_map(|e| [e.a.region, e.b.region])
        .collect();
    planes.sort_unstable();
    planes.dedup();
    for &p in &planes {
        if regions[p].vertices.len() >= MIN_BLEND_POINTS {
            if let Some(f) = ctx.fit(SurfaceType::Plane, &regions[p].vertices) {
                regions[p].fit = f;
            }
        }
    }
    let update = |s: &mut Side, regions: &[Region]| {
        if let Some((n, o)) = plane(regions, s.region) {
            // Keep the side: the refitted normal may have flipped.
            let flip = if dot(n, s.n) < 0.0 { -1.0 } else { 1.0 };
            s.n = scale(n, flip);
            s.o = o * flip;
        }
    };
    for e in edges.iter_mut() {
        update(&mut e.a, regions);
        update(&mut e.b, regions);
        let part = Part::of(ctx, &regions[e.region].vertices);
        let Some((d, _)) = edge_axis(&e.a, &e.b, e.r, e.centre) else {
            continue;
        };
        let d = if dot(d, e.dir) < 0.0 {
            scale(d, -1.0)
        } else {
            d
        };
        if let Some((
            SurfaceParams::Cylinder {
                axis_point, radius, ..
            },
            rms,
        )) = (part.pts.len() >= MIN_BLEND_POINTS)
            .then(|| {
                fit_radius(
                    &part,
                    &[e.a.tangent(), e.b.tangent()],
                    Some((d, dot(d, e.centre))),
                    e.r,
                )
            })
            .flatten()
        {
            e.r = radius;
            e.dir = d;
            e.centre = axis_point;
            regions[e.region].fit = Fit {
                params: SurfaceParams::Cylinder {
                    axis_point,
                    axis_dir: d,
                    radius,
                },
                rms,
            };
            regions[e.region].kind = SurfaceType::Cylinder;
        }
    }
}
