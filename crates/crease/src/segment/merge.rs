//! Regions that are one surface within the noise, made one (not in the paper; issue 29).
//!
//! Under noise of half a spacing and more, the seeds of a curved surface are small patches
//! whose curvature is lost in the noise: the model selection of the seeds takes the simpler
//! type that fits them about as well (a plane), and the widened tolerances of equation 4 let
//! that plane grow over a strip of the surface. A cylinder of the `two-cylinders` part at
//! σ = 0.5 spacings came out as a dozen planar strips, the fillet of `fillet-chamfer-cone` as
//! two planes. Two steps put such surfaces back together, and a third takes back what a
//! camera's warp made curved, judged against the measured noise σ of the points
//! (`noise_tolerance`'s σ_d):
//! 1. **a richer type** for a region whose points it explains clearly better: a plane becomes a
//!    sphere, cylinder or cone, a cylinder a cone or torus, a sphere a cylinder, cone or torus
//!    (a strip of a cylinder under noise of a spacing is often taken for a sphere), when that type's
//!    RMS distance is at most the current one divided by [`RICHER_GAIN`] (pure noise lowers
//!    it by a fraction of `Δparameters / n`, a curved strip fitted by a plane by far more)
//!    and it keeps 90 % of the points within equations 4 and 5 that the current one held (as
//!    step 2 asks of each part: the count is a noisy statistic at noise of a spacing);
//! 2. **merging** adjacent regions: for each pair sharing [`MIN_CONTACT`] graph edges or
//!    more, the union is fitted with the types of both and, when one is a plane, the curved
//!    types too (strips of one cylinder); the simplest type whose distances on each of the two
//!    parts stay within [`MERGE_SLACK`] times that part's own RMS error or the noise,
//!    whichever is larger, and which keeps 90 % of the points each part's own surface held
//!    within equations 4 and 5, joins them. The best-scoring pairs merge first, each region
//!    at most once per round, until no pair merges. The per-part test is what keeps a fillet
//!    strip out of the large plane beside it (the union's RMS alone hides a small part).
//!
//!    2b. Two planes that fail it still join as one plane where their **seam is smooth**
//!    ([`smooth_seam`]): one plane through the points of both near the seam explains them
//!    about as well as their own two planes. A scanner bends and terraces a flat face by
//!    several times its noise (a Kinect table's corners turn by 8°, its depth steps leave
//!    patches 3 mm off it; the CurvSurf backdrop came out as 8 planes), which the per-part
//!    test reads as different surfaces; a crease or a step, however slight, is a kink right
//!    at the seam, where the warp is spread over the face.
//!
//! 3. **a plainer type**, last: a curved region whose curvature a depth camera's warp can
//!    explain (its normal turning by less than [`MIN_TURN_DEGREES`], which step 1 would not have
//!    made curved, or a cone whose points reach its apex: a face bulged into a tent, which no
//!    B-rep face represents) becomes a plane when the plane keeps 90 % of the points within
//!    equations 4 and 5 that its surface held. The seeds' model selection and the refits make
//!    such regions: one face of the RealSense box `caixa2` came out as a cone of half angle 80°
//!    with its apex inside the face (RMS 0.0057 against the plane's 0.0086), which the B-rep could
//!    not meet with the two other faces, and refused the scan. A drill point (a cone of half
//!    angle 59° reaching its apex) keeps its cone: a plane holds far fewer of its points.
//!
//! Both tests allow `simpler_floor` mean edge lengths beyond the ratios (as the model
//! selection of the seeds does): on exact data every RMS error is round-off, and their ratios
//! say nothing.
//!
//! Fits read at most [`PART_SAMPLE`] points of each part, evenly strided, weighted by their
//! area times the stride so that each part counts for its area; the merged region is refitted
//! to all its points. Pairs are judged in parallel and merged in a fixed order, so the result
//! does not depend on the thread count.

use std::collections::HashMap;

use rayon::prelude::*;

use super::fit::{fit, refine, rms_distance, Fit};
use super::grow::{Ctx, Region};
use crate::geometry::surface::Prepared;
use crate::geometry::vec3::{add, dist, dist2, dot, norm, normalize};
use crate::geometry::{fit_plane, Point3, SurfaceParams, SurfaceType};
use crate::spatial::Adjacency;

/// A richer type replaces a region's when it divides its RMS distance by at least this.
pub(crate) const RICHER_GAIN: f64 = 1.15;

/// Each part's RMS distance to the union's surface may exceed the larger of its own RMS error
/// and the noise by this factor.
pub(crate) const MERGE_SLACK: f64 = 1.1;

/// Graph edges two regions must share to be tried as one.
pub(crate) const MIN_CONTACT: usize = 3;

/// Most points of each part a fit reads.
const PART_SAMPLE: usize = 512;

/// A curved type is taken for a region (richer, or the union of two planes) only when its
/// normal turns by at least this over the region, from the mean normal to the farthest
/// (degrees). A real scan's flat face is not flat: a depth camera warps it by a few noise
/// scales over its extent, and a sphere or cylinder of ten times its size then lowers the
/// RMS error by a fifth (the RealSense box `caixa` had two of its three faces turned into a
/// cylinder and a sphere, turning by 3–4°), while a fillet's strip turns by 15° and more.
const MIN_TURN_DEGREES: f64 = 15.0;

/// The quantile of [`turn`].
const TURN_QUANTILE: f64 = 0.99;

/// Half-width of the band about two planes' seam that [`smooth_seam`] reads, in mean edge
/// lengths (about 20 point spacings on the neighbour graphs of clouds): wide enough that a
/// crease of a few degrees leaves one plane through the band by more than the noise, narrow
/// enough that a camera's warp (a bend of under 15° over a whole face) hardly does.
const SEAM_BAND: f64 = 12.0;

/// A seam is smooth when one plane through its band leaves the band's points (RMS) at most
/// this many times as far as their own regions' planes do. Measured on the scans of
/// `../shared/data/scans` (band of 20 spacings): pieces of one warped or terraced face
/// 0.45–1.40 (the Kinect table, the CurvSurf backdrop), the box's edges 4.8–7.0.
const SEAM_SLACK: f64 = 1.5;

/// Fewest points of a region tried with a richer type.
const MIN_RICHER: usize = 50;

/// The order of simplicity (fewest parameters first).
const SIMPLE_FIRST: [SurfaceType; 5] = [
    SurfaceType::Plane,
    SurfaceType::Sphere,
    SurfaceType::Cylinder,
    SurfaceType::Cone,
    SurfaceType::Torus,
];

/// Points, normals and weights of up to [`PART_SAMPLE`] vertices of `vs`, evenly strided,
/// weights times the stride.
pub(crate) struct Part {
    pub pts: Vec<Point3>,
    nrm: Vec<Point3>,
    vnrm: Vec<Point3>,
    pub w: Vec<f64>,
}

impl Part {
    pub fn of<G: Adjacency>(ctx: &Ctx<G>, vs: &[u32]) -> Part {
        let step = vs.len().div_ceil(PART_SAMPLE).max(1);
        let mut p = Part {
            pts: Vec::new(),
            nrm: Vec::new(),
            vnrm: Vec::new(),
            w: Vec::new(),
        };
        for &v in vs.iter().step_by(step) {
            let v = v as usize;
            p.pts.push(ctx.pos[v]);
            p.nrm.push(ctx.fnormal[v]);
            p.vnrm.push(ctx.vnormal[v]);
            p.w.push(ctx.weight[v] * step as f64);
        }
        p
    }

    /// The weighted centroid of the sample (None when it weighs nothing).
    pub fn centroid(&self) -> Option<Point3> {
        super::fit::centroid(&self.pts, &self.w)
    }

    /// Weighted RMS distance to `s` and the number of points within equations 4 and 5.
    pub fn score<G: Adjacency>(&self, ctx: &Ctx<G>, s: &SurfaceParams) -> (f64, usize) {
        let s = Prepared::new(s);
        let (mut a, mut b, mut n) = (0.0, 0.0, 0);
        for ((&p, &vn), &w) in self.pts.iter().zip(&self.vnrm).zip(&self.w) {
            let d = s.signed_distance(p);
            a += w * d * d;
            b += w;
            n += usize::from(ctx.tol.ok(&s, p, vn));
        }
        (if b > 0.0 { (a / b).sqrt() } else { f64::NAN }, n)
    }
}

/// How far the normal of `s` turns over the points of `parts`: the [`TURN_QUANTILE`] quantile
/// of the angles between the normal at a point and the mean normal (90° when the normals cancel
/// out, a closed cylinder), not the largest: a few points of the neighbouring surface or of
/// clutter left in a region must not decide its extent.
fn turn(parts: &[&Part], s: &SurfaceParams) -> f64 {
    let s = Prepared::new(s);
    let ns: Vec<Point3> = parts
        .iter()
        .flat_map(|p| p.pts.iter().map(|&x| s.normal(x)))
        .collect();
    let m = ns.iter().fold([0.0; 3], |a, &n| add(a, n));
    let Some(m) = normalize(m).filter(|_| norm(m) > 0.5 * ns.len() as f64) else {
        return std::f64::consts::FRAC_PI_2;
    };
    let mut angles: Vec<f64> = ns
        .iter()
        .map(|&n| dot(n, m).clamp(-1.0, 1.0).acos())
        .collect();
    // The 99th percentile: the largest angle is that of a few stray points.
    let q = ((angles.len() - 1) as f64 * TURN_QUANTILE).round() as usize;
    let (_, v, _) = angles.select_nth_unstable_by(q, f64::total_cmp);
    *v
}

/// The fit of type `kind` to the points of `parts`; also refined from each of `starts` of that
/// type (the parts' own surfaces), the best kept: under noise of a spacing the normals that
/// start [`fit`] are poor, and two strips of one cylinder can fit apart from there while
/// either strip's own cylinder leads to their common one.
fn fit_parts(kind: SurfaceType, parts: &[&Part], starts: &[&SurfaceParams]) -> Option<Fit> {
    let cat = |f: fn(&Part) -> &Vec<Point3>| -> Vec<Point3> {
        parts.iter().flat_map(|p| f(p).iter().copied()).collect()
    };
    let pts = cat(|p| &p.pts);
    let nrm = cat(|p| &p.nrm);
    let w: Vec<f64> = parts.iter().flat_map(|p| p.w.iter().copied()).collect();
    let mut best = fit(kind, &pts, &nrm, &w);
    for &s in starts
        .iter()
        .filter(|s| s.kind() == kind && kind != SurfaceType::Plane)
    {
        let Some(params) = refine(s, &pts, &w) else {
            continue;
        };
        let rms = rms_distance(&params, &pts, &w);
        if rms.is_finite() && best.as_ref().is_none_or(|b| rms < b.rms) {
            best = Some(Fit { params, rms });
        }
    }
    best
}

fn cone_ok(f: &Fit, min_cone: f64) -> bool {
    match f.params {
        SurfaceParams::Cone { half_angle, .. } => half_angle >= min_cone,
        _ => true,
    }
}

/// The richer types a region of type `k` is tried with.
fn richer(k: SurfaceType) -> &'static [SurfaceType] {
    use SurfaceType as T;
    match k {
        T::Plane => &[T::Sphere, T::Cylinder, T::Cone],
        T::Cylinder => &[T::Cone, T::Torus],
        T::Sphere => &[T::Cylinder, T::Cone, T::Torus],
        T::Cone | T::Torus | T::Other => &[],
    }
}

/// Gives region `r` the type `k` with `f`, its fit to `part`; refitted to all the region's
/// points when `part` is a sample of them.
fn retype<G: Adjacency>(ctx: &Ctx<G>, r: &mut Region, part: &Part, k: SurfaceType, f: Fit) {
    r.kind = k;
    r.fit = if part.pts.len() < r.vertices.len() {
        ctx.fit(k, &r.vertices).unwrap_or(f)
    } else {
        f
    };
}

/// Step 1 of the module documentation on every region; returns whether any changed.
pub(crate) fn richer_types<G: Adjacency>(
    ctx: &Ctx<G>,
    regions: &mut [Region],
    floor: f64,
    min_cone: f64,
) -> bool {
    regions
        .par_iter_mut()
        .map(|r| {
            if r.vertices.len() < MIN_RICHER {
                return false;
            }
            let part = Part::of(ctx, &r.vertices);
            let (rms, held) = part.score(ctx, &r.fit.params);
            for &k in richer(r.kind) {
                let Some(f) = fit_parts(k, &[&part], &[]).filter(|f| cone_ok(f, min_cone)) else {
                    continue;
                };
                let (frms, fheld) = part.score(ctx, &f.params);
                if frms * RICHER_GAIN + floor <= rms
                    && 10 * fheld >= 9 * held
                    && turn(&[&part], &f.params) >= MIN_TURN_DEGREES.to_radians()
                {
                    retype(ctx, r, &part, k, f);
                    return true;
                }
            }
            false
        })
        .reduce(|| false, |a, b| a || b)
}

/// Step 3 of the module documentation: after the merges and the tangency, a curved region that
/// a camera's warp may have made (its normal turning by less than [`MIN_TURN_DEGREES`] over
/// its points, or a cone whose points reach its apex, within 2 `l` of it) becomes a plane
/// when the plane keeps 90 % of the points within equations 4 and 5 that its surface held.
/// Returns whether any changed.
pub(crate) fn plainer_types<G: Adjacency>(ctx: &Ctx<G>, regions: &mut [Region], l: f64) -> bool {
    regions
        .par_iter_mut()
        .map(|r| {
            if r.kind == SurfaceType::Plane || r.vertices.len() < MIN_RICHER {
                return false;
            }
            let part = Part::of(ctx, &r.vertices);
            let reaches_apex = match r.fit.params {
                SurfaceParams::Cone { apex, .. } => r
                    .vertices
                    .iter()
                    .any(|&v| dist(ctx.pos[v as usize], apex) <= 2.0 * l),
                _ => false,
            };
            if !reaches_apex && turn(&[&part], &r.fit.params) >= MIN_TURN_DEGREES.to_radians() {
                return false;
            }
            let (_, held) = part.score(ctx, &r.fit.params);
            let Some(f) = fit_parts(SurfaceType::Plane, &[&part], &[]) else {
                return false;
            };
            let (_, plane_held) = part.score(ctx, &f.params);
            if 10 * plane_held < 9 * held {
                return false;
            }
            retype(ctx, r, &part, SurfaceType::Plane, f);
            true
        })
        .reduce(|| false, |a, b| a || b)
}

/// The verdict on one pair: the union's type and fit, and its score (lower merges first).
type Verdict = Option<(SurfaceType, Fit, f64)>;

/// Whether planes `a` and `b` continue each other across their seam, one face that the scanner
/// bent or terraced (step 2b of the module documentation): one plane through the points of
/// both within [`SEAM_BAND`] of the seam explains them within [`SEAM_SLACK`] times their own
/// planes' RMS distance (plus `floor`). A crease, however flat, bends the band at its middle,
/// a step offsets it; a warp spreads its bend over the face. The regions' planes, the band's
/// and (in [`merge_smooth_seams`]) the union's must lie within [`MIN_TURN_DEGREES`] of each
/// other ([`along`]; a region of fewer than [`MIN_RICHER`] points does not determine its
/// plane's direction well enough to compare).
/// Returns the ratio of the two RMS distances.
fn smooth_seam<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &[i32],
    (a, ra): (u32, &Region),
    (b, rb): (u32, &Region),
    l: f64,
    floor: f64,
) -> Option<f64> {
    let (SurfaceParams::Plane { .. }, SurfaceParams::Plane { normal: nb, .. }) =
        (ra.fit.params, rb.fit.params)
    else {
        return None;
    };
    // Both planes determined: within MIN_TURN_DEGREES of each other.
    if ra.vertices.len().min(rb.vertices.len()) >= MIN_RICHER && !along(ra, nb) {
        return None;
    }
    // The seam: the smaller region's vertices beside the other, and those neighbours.
    let (small, other) = if ra.vertices.len() <= rb.vertices.len() {
        (ra, b as i32)
    } else {
        (rb, a as i32)
    };
    let mut seam: Vec<u32> = Vec::new();
    for &v in &small.vertices {
        let before = seam.len();
        ctx.topo.for_each_neighbor(v as usize, |w| {
            if owner[w as usize] == other {
                seam.push(w);
            }
        });
        if seam.len() > before {
            seam.push(v);
        }
    }
    seam.sort_unstable();
    seam.dedup();
    // The band: breadth-first from the seam through both regions, each vertex within
    // SEAM_BAND · l of the seam vertex it was reached from.
    let r2 = (SEAM_BAND * l).powi(2);
    let mut seen: std::collections::HashSet<u32> = seam.iter().copied().collect();
    let mut queue: Vec<(u32, Point3)> = seam.iter().map(|&v| (v, ctx.pos[v as usize])).collect();
    let mut head = 0;
    while head < queue.len() {
        let (v, src) = queue[head];
        head += 1;
        ctx.topo.for_each_neighbor(v as usize, |w| {
            let o = owner[w as usize];
            if (o == a as i32 || o == b as i32)
                && dist2(ctx.pos[w as usize], src) <= r2
                && seen.insert(w)
            {
                queue.push((w, src));
            }
        });
    }
    let (sa, sb) = (Prepared::new(&ra.fit.params), Prepared::new(&rb.fit.params));
    let (mut own, mut wsum, mut in_a, mut in_b) = (0.0, 0.0, 0usize, 0usize);
    for &(v, _) in &queue {
        let (p, w) = (ctx.pos[v as usize], ctx.weight[v as usize]);
        let d = if owner[v as usize] == a as i32 {
            in_a += 1;
            sa.signed_distance(p)
        } else {
            in_b += 1;
            sb.signed_distance(p)
        };
        own += w * d * d;
        wsum += w;
    }
    if in_a < 3 || in_b < 3 || wsum <= 0.0 {
        return None;
    }
    let own = (own / wsum).sqrt();
    let joint = fit_plane(
        queue
            .iter()
            .map(|&(v, _)| (ctx.pos[v as usize], ctx.weight[v as usize])),
    )?;
    // The band of two thin strips (a plate's rims) is nearly a line, about which one plane
    // turns freely: it must lie along the two planes it replaces.
    if !(along(ra, joint.normal) && along(rb, joint.normal)) {
        return None;
    }
    let joint = joint.eigenvalues[0].max(0.0).sqrt();
    (joint <= SEAM_SLACK * own + floor).then(|| joint / own.max(f64::MIN_POSITIVE))
}

/// Whether plane region `r` lies within [`MIN_TURN_DEGREES`] of direction `n` (either sense),
/// or holds too few points ([`MIN_RICHER`]) for its plane's direction to tell.
fn along(r: &Region, n: Point3) -> bool {
    match r.fit.params {
        SurfaceParams::Plane { normal, .. } => {
            r.vertices.len() < MIN_RICHER
                || dot(normal, n).abs() >= MIN_TURN_DEGREES.to_radians().cos()
        }
        _ => false,
    }
}

fn judge<G: Adjacency>(
    ctx: &Ctx<G>,
    (ra, pa): (&Region, &Part),
    (rb, pb): (&Region, &Part),
    sigma: f64,
    floor: f64,
    min_cone: f64,
) -> Verdict {
    use SurfaceType as T;
    let curved = ra.kind == T::Plane || rb.kind == T::Plane;
    let kinds = SIMPLE_FIRST.iter().copied().filter(|&k| {
        k == ra.kind || k == rb.kind || (curved && matches!(k, T::Sphere | T::Cylinder | T::Cone))
    });
    let (rms_a, held_a) = pa.score(ctx, &ra.fit.params);
    let (rms_b, held_b) = pb.score(ctx, &rb.fit.params);
    let bound_a = MERGE_SLACK * rms_a.max(sigma) + floor;
    let bound_b = MERGE_SLACK * rms_b.max(sigma) + floor;
    for k in kinds {
        let Some(f) = fit_parts(k, &[pa, pb], &[&ra.fit.params, &rb.fit.params])
            .filter(|f| cone_ok(f, min_cone))
        else {
            continue;
        };
        if k != T::Plane && turn(&[pa, pb], &f.params) < MIN_TURN_DEGREES.to_radians() {
            continue;
        }
        let (ua, ha) = pa.score(ctx, &f.params);
        let (ub, hb) = pb.score(ctx, &f.params);
        if ua <= bound_a && ub <= bound_b && 10 * ha >= 9 * held_a && 10 * hb >= 9 * held_b {
            return Some((k, f, (ua / bound_a).max(ub / bound_b)));
        }
    }
    None
}

/// Step 2 of the module documentation: merges adjacent regions of `regions` (owners in
/// `owner`) that are one surface within the noise `sigma` (score: the larger of the two parts'
/// RMS ratios to their bounds); regions are renumbered in order, merged ones taking the lower
/// id. Returns whether any merged.
pub(crate) fn merge_regions<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &mut [i32],
    regions: &mut Vec<Region>,
    sigma: f64,
    floor: f64,
    min_cone: f64,
) -> bool {
    merge_pairs(ctx, owner, regions, min_cone, |_, regions, todo| {
        let mut needed: Vec<u32> = todo.iter().flat_map(|&(a, b)| [a, b]).collect();
        needed.sort_unstable();
        needed.dedup();
        let parts: HashMap<u32, Part> = needed
            .par_iter()
            .map(|&r| (r, Part::of(ctx, &regions[r as usize].vertices)))
            .collect();
        todo.par_iter()
            .map(|&(a, b)| {
                judge(
                    ctx,
                    (&regions[a as usize], &parts[&a]),
                    (&regions[b as usize], &parts[&b]),
                    sigma,
                    floor,
                    min_cone,
                )
            })
            .collect()
    })
}

/// Step 2b of the module documentation, after step 2: merges adjacent planes whose seam is
/// smooth ([`smooth_seam`], which is also the score) into one plane, as [`merge_regions`]
/// does, when the union's plane also explains the two regions whole within [`SEAM_SLACK`]
/// times their own planes (pooled RMS distances): the band alone let the rims and faces of a
/// plate as thin as the noise (the noisy PCEDNet model 7034) become one "plane" of twice
/// their RMS distance. A pass of its own, as its verdicts cost no surface fit: in step 2's loop a large face
/// that takes one piece per round had every other pair beside it judged again each round (the
/// Kinect scene `learn33`: 1 → 6 s).
pub(crate) fn merge_smooth_seams<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &mut [i32],
    regions: &mut Vec<Region>,
    l: f64,
    floor: f64,
) -> bool {
    merge_pairs(ctx, owner, regions, 0.0, |owner, regions, todo| {
        todo.par_iter()
            .map(|&(a, b)| {
                let (ra, rb) = (&regions[a as usize], &regions[b as usize]);
                let ratio = smooth_seam(ctx, owner, (a, ra), (b, rb), l, floor)?;
                let (pa, pb) = (Part::of(ctx, &ra.vertices), Part::of(ctx, &rb.vertices));
                let f = fit_parts(SurfaceType::Plane, &[&pa, &pb], &[])?;
                let SurfaceParams::Plane { normal, .. } = f.params else {
                    return None;
                };
                // The whole union, too, within SEAM_SLACK of the two planes (pooled RMS).
                let pooled = |ua: f64, ub: f64| {
                    let (wa, wb) = (pa.w.iter().sum::<f64>(), pb.w.iter().sum::<f64>());
                    ((wa * ua * ua + wb * ub * ub) / (wa + wb)).sqrt()
                };
                let own = pooled(
                    pa.score(ctx, &ra.fit.params).0,
                    pb.score(ctx, &rb.fit.params).0,
                );
                let union = pooled(pa.score(ctx, &f.params).0, pb.score(ctx, &f.params).0);
                (along(ra, normal) && along(rb, normal) && union <= SEAM_SLACK * own + floor)
                    .then_some((SurfaceType::Plane, f, ratio))
            })
            .collect()
    })
}

/// The rounds of [`merge_regions`] and [`merge_smooth_seams`]: `judge(owner, regions, pairs)`
/// gives the verdicts on pairs of adjacent regions; the best-scoring pairs merge first, each
/// region at most once per round, and the union is refitted to all its points with the
/// verdict's type (cones slimmer than `min_cone` refused), until no pair merges.
fn merge_pairs<G: Adjacency>(
    ctx: &Ctx<G>,
    owner: &mut [i32],
    regions: &mut Vec<Region>,
    min_cone: f64,
    judge: impl Fn(&[i32], &[Region], &[(u32, u32)]) -> Vec<Verdict>,
) -> bool {
    // Verdicts stay valid while neither region changes: keyed by (a, b, version a, version b).
    let mut version = vec![0u32; regions.len()];
    let mut cache: HashMap<(u32, u32, u32, u32), Verdict> = HashMap::new();
    let mut alive = vec![true; regions.len()];
    let mut any = false;
    loop {
        let pairs = contacts(ctx, owner);
        let todo: Vec<(u32, u32)> = pairs
            .iter()
            .copied()
            .filter(|&(a, b)| {
                !cache.contains_key(&(a, b, version[a as usize], version[b as usize]))
            })
            .collect();
        let verdicts = judge(owner, regions, &todo);
        for (&(a, b), v) in todo.iter().zip(verdicts) {
            cache.insert((a, b, version[a as usize], version[b as usize]), v);
        }
        let mut ok: Vec<(f64, u32, u32, SurfaceType, Fit)> = pairs
            .iter()
            .filter_map(|&(a, b)| {
                let v = cache.get(&(a, b, version[a as usize], version[b as usize]))?;
                v.map(|(k, f, s)| (s, a, b, k, f))
            })
            .collect();
        ok.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)).then(x.2.cmp(&y.2)));
        let mut touched = vec![false; regions.len()];
        let mut merged: Vec<(u32, u32, SurfaceType, Fit)> = Vec::new();
        for (_, a, b, k, f) in ok {
            if touched[a as usize] || touched[b as usize] {
                continue;
            }
            touched[a as usize] = true;
            touched[b as usize] = true;
            merged.push((a, b, k, f));
        }
        if merged.is_empty() {
            break;
        }
        any = true;
        let mut into: Vec<i32> = (0..regions.len() as i32).collect();
        for &(a, b, _, _) in &merged {
            into[b as usize] = a as i32;
            alive[b as usize] = false;
        }
        for o in owner.iter_mut() {
            if *o >= 0 {
                *o = into[*o as usize];
            }
        }
        let refits: Vec<(u32, Region)> = merged
            .par_iter()
            .map(|&(a, b, k, f)| {
                let mut vs = regions[a as usize].vertices.clone();
                vs.extend_from_slice(&regions[b as usize].vertices);
                vs.sort_unstable();
                let f = ctx
                    .fit(k, &vs)
                    .filter(|g| cone_ok(g, min_cone))
                    .unwrap_or(f);
                (
                    a,
                    Region {
                        kind: k,
                        fit: f,
                        vertices: vs,
                    },
                )
            })
            .collect();
        for (a, r) in refits {
            version[a as usize] += 1;
            regions[a as usize] = r;
        }
        for &(_, b, _, _) in &merged {
            regions[b as usize].vertices.clear();
            version[b as usize] += 1;
        }
    }
    if any {
        renumber(owner, regions, &alive);
    }
    any
}

/// Pairs of regions (lower id first, sorted) sharing at least [`MIN_CONTACT`] graph edges.
pub(crate) fn contacts<G: Adjacency>(ctx: &Ctx<G>, owner: &[i32]) -> Vec<(u32, u32)> {
    let mut pairs: Vec<(u32, u32)> = (0..owner.len())
        .into_par_iter()
        .flat_map_iter(|v| {
            let o = owner[v];
            let mut out = Vec::new();
            if o >= 0 {
                ctx.topo.for_each_neighbor(v, |w| {
                    let p = owner[w as usize];
                    if p > o {
                        out.push((o as u32, p as u32));
                    }
                });
            }
            out
        })
        .collect();
    pairs.par_sort_unstable();
    let mut out = Vec::new();
    let mut i = 0;
    while i < pairs.len() {
        let mut j = i;
        while j < pairs.len() && pairs[j] == pairs[i] {
            j += 1;
        }
        if j - i >= MIN_CONTACT {
            out.push(pairs[i]);
        }
        i = j;
    }
    out
}

/// Drops the regions not `alive` and renumbers the rest in order.
pub(crate) fn renumber(owner: &mut [i32], regions: &mut Vec<Region>, alive: &[bool]) {
    let mut new_id = vec![-1i32; regions.len()];
    let mut next = 0;
    for (i, &a) in alive.iter().enumerate() {
        if a {
            new_id[i] = next;
            next += 1;
        }
    }
    for o in owner.iter_mut() {
        if *o >= 0 {
            *o = new_id[*o as usize];
        }
    }
    let mut i = 0;
    regions.retain(|_| {
        i += 1;
        alive[i - 1]
    });
}
