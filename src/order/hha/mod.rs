//! The hierarchical heuristic algorithm (seed 000 §3.2) and its improvements.
//!
//! 1. Fields: an open path over the field centres from the field nearest the work area's top-left
//!    corner, free end (a virtual end node at zero cost) — exact (Held–Karp) up to 12 fields,
//!    cheapest arc plus 2-opt/Or-opt beyond. Beyond the seed, up to 16 fields also try the exact
//!    path over the gaps between the fields' nearest geometries; both go through steps 2–4 and
//!    the lower idle is kept.
//! 2. Per field, a start and an end geometry: nearest the previous / next field's geometries; the
//!    first field starts with the geometry farthest from where the line to the second field leaves
//!    it, the last ends with the one farthest from where the line from the previous field enters
//!    it; a lone field runs from its top-left to its bottom-right geometry.
//! 3. Per field (in parallel), the geometries' centroids are ordered from the start to the end
//!    geometry by path-cheapest-arc on the penalised cost of Eq. 7,
//!    `D = d + w·(|AB|max − |AB|)`, which prefers geometries far from the exit first, so the path
//!    sweeps towards the next field (w = 0.5; 0.1 with one field).
//! 4. Start vertices by the vertex enhancement algorithm (VEA, §3.2.3).
//!
//! Beyond the seed (`SolverSettings::hha_improve`, on by default): the per-field order is improved
//! by 2-opt/Or-opt under `d + λ·(backward travel along the sweep)` (λ = w), which keeps the
//! sweep; the start vertices are then chosen exactly (layered-graph DP, `VertexMode::Exact`); then
//! local search on the real stroke ends (open geometries may flip) and the exact vertex choice
//! alternate while the idle travel falls.
//!
//! A lone field has nothing to sweep towards: under the distance objective its path is the
//! engine's free open path (no direction weight, free ends, the full kick budget, exact
//! vertices) from a Hilbert-curve start; under the time objective the time search does the
//! same. HHA's own steps only give it a start.

use super::tsp::{
    cheapest_arc, exact_path, local_search, space_filling_order, IlsBudget, LocalSearch, LsOptions,
    Node, PathProblem, Tour,
};
use super::vertex::{optimal_vertices, vea};
use super::{OrderError, Ordering};
use crate::document::{
    Cylinder, Geometry, MachineProfile, ScanField, SolverSettings, Step, VertexMode,
};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use crate::order::cost::TravelCost;
use rayon::prelude::*;
use std::time::{Duration, Instant};

/// Fields up to this count are ordered exactly.
pub const EXACT_FIELDS: usize = 12;

/// Fields with more geometries than this start from a Hilbert-curve order instead of the seed's
/// cheapest arc (quadratic: 0.3 s at 10⁴ geometries) when the local search follows.
pub const CHEAPEST_ARC_MAX: usize = 2000;

/// Shares of `--time-limit` (from the start of the ordering) at which HHA's per-field searches,
/// its refinement rounds (when the time objective follows) and the time objective's searches
/// stop. The last search gets the most: its result is the plan.
const FIELD_PATHS_SHARE: f64 = 0.25;
const REFINE_SHARE: f64 = 0.5;
/// The rest is left for lowering the plan and comparing it.
pub const LAST_SEARCH_SHARE: f64 = 0.95;

/// Kick budgets of searches whose result a later search of the same nodes improves again (the
/// per-field paths before the refinement, refinement rounds after the first) are divided by
/// this: the later search starts from their tour, so their last kicks gain little.
const PRELIMINARY_KICK_DIVISOR: usize = 8;

/// A lone field's free open path under the distance objective is searched once per seed
/// (the settings' seed xor each of these), in parallel, and the shortest kept (the first of
/// equals: the same plan on any thread count). Two searches take the wall time of one on two
/// cores; on 1,000 uniform dots (10 sets) the worst gap to LKH fell from +1.36 to +1.00 %
/// (BENCHMARKS, issue 24).
const LONE_FREE_SEEDS: [u64; 2] = [0, 0x9e37_79b9_7f4a_7c15];

/// Most refinement rounds (each: every field's path between its neighbours' ends, then the exact
/// vertices); they stop earlier once a round gains less than 0.1 %.
const REFINE_ROUNDS: usize = 6;

/// Refinement rounds when the time objective follows: it searches every field's path again
/// (free ends, full budget) and keeps the faster plan, so one round gives it its start.
const REFINE_ROUNDS_BEFORE_TIME: usize = 1;

/// The instant `share` of the settings' time limit after `t0` (none without a limit).
pub fn deadline(settings: &SolverSettings, t0: Instant, share: f64) -> Option<Instant> {
    let limit = settings.time_limit_s?;
    Some(t0 + Duration::from_secs_f64((limit * share).max(0.0)))
}

fn unit(v: Pt) -> Option<Pt> {
    let n = v.norm();
    (n > 1e-12).then(|| v.scale(1.0 / n))
}

/// Where the ray from `c` along `u` leaves the field of size `f` centred at `c`.
fn exit_point(c: Pt, u: Pt, f: [f64; 2]) -> Pt {
    let tx = if u.x.abs() > 1e-12 {
        f[0] / 2.0 / u.x.abs()
    } else {
        f64::INFINITY
    };
    let ty = if u.y.abs() > 1e-12 {
        f[1] / 2.0 / u.y.abs()
    } else {
        f64::INFINITY
    };
    c.plus(u.scale(tx.min(ty)))
}

/// Fields up to this count also try the exact field path over the gaps between the fields'
/// nearest geometries (see `field_order_candidates`): Held–Karp over 15 free fields is
/// 2¹⁵ · 15² ≈ 7 · 10⁶ steps (tens of ms); beyond it a field path is a sweep over many fields,
/// where the centre distance decides well.
pub const GAP_PATH_MAX_FIELDS: usize = 16;

/// The field nearest the work area's top-left corner: where every field path starts.
fn top_left_field(fields: &[ScanField], profile: &MachineProfile) -> usize {
    let corner = Pt::new(-profile.field_mm[0] / 2.0, -profile.field_mm[1] / 2.0);
    (0..fields.len())
        .min_by(|&a, &b| {
            fields[a]
                .center
                .dist2(corner)
                .total_cmp(&fields[b].center.dist2(corner))
                .then(a.cmp(&b))
        })
        .unwrap_or(0)
}

/// Field visiting order (field slots): open path over the field centres from the field nearest
/// the work area's top-left (seed 000 §3.2.1).
pub fn field_order(
    fields: &[ScanField],
    profile: &MachineProfile,
    cylinder: Option<Cylinder>,
    ctx: &JobCtx,
) -> Result<Vec<usize>, Cancelled> {
    let n = fields.len();
    if n == 0 {
        return Ok(Vec::new());
    }
    let first = top_left_field(fields, profile);
    let c: Vec<Pt> = fields.iter().map(|f| f.center).collect();
    // around a cylinder: the distance between strip centres on its surface
    let metric = TravelCost::distance(cylinder);
    let dist = |i: usize, j: usize| metric.between(c[i], c[j]);
    if n <= EXACT_FIELDS {
        return Ok(exact_path(&dist, n, first, None));
    }
    let order = cheapest_arc(n, first, None, &dist);
    let mut prob = PathProblem::points(&c, &vec![0.0; n], 0.0);
    prob.fixed_first = true;
    prob.metric = metric;
    let mut tour = Tour {
        order,
        flipped: vec![false; n],
    };
    local_search(&prob, &mut tour, LsOptions::default(), ctx)?;
    Ok(tour.order)
}

/// The field paths HHA carries through its per-field stages: the seed's path over the field
/// centres, and (up to [`GAP_PATH_MAX_FIELDS`] fields, when it differs) the exact path over the
/// gaps between the fields' nearest geometries. The centre distance is what the
/// laser jumps when fields are full and even; when they are sparse or uneven (mix-120: 16 fields
/// of 1–30 geometries), the shortest centre path can cross between fields far from where their
/// geometries meet, and the gap path follows the geometries instead.
fn field_order_candidates(
    fields: &[ScanField],
    cent: &[Pt],
    profile: &MachineProfile,
    cylinder: Option<Cylinder>,
    ctx: &JobCtx,
) -> Result<(Vec<usize>, Option<Vec<usize>>), Cancelled> {
    let by_centre = field_order(fields, profile, cylinder, ctx)?;
    let n = fields.len();
    if !(3..=GAP_PATH_MAX_FIELDS).contains(&n) {
        return Ok((by_centre, None));
    }
    let mut gap = vec![0.0; n * n];
    for a in 0..n {
        for b in a + 1..n {
            let (fa, fb) = (&fields[a], &fields[b]);
            let (x, y) = closest_pair(&fa.geometries, &fb.geometries, cent, fa.center, fb.center);
            gap[a * n + b] = cent[x].dist(cent[y]);
            gap[b * n + a] = gap[a * n + b];
        }
    }
    let by_gap = exact_path(
        &|i, j| gap[i * n + j],
        n,
        top_left_field(fields, profile),
        None,
    );
    let differs = by_gap != by_centre;
    Ok((by_centre, differs.then_some(by_gap)))
}

/// The sweep direction of each field in visiting order: towards the next field (the last field:
/// away from the previous one; a lone field: towards its bottom-right).
fn sweep_dirs(centers: &[Pt]) -> Vec<Pt> {
    let n = centers.len();
    let diag = Pt::new(
        std::f64::consts::FRAC_1_SQRT_2,
        std::f64::consts::FRAC_1_SQRT_2,
    );
    (0..n)
        .map(|j| {
            let d = if j + 1 < n {
                centers[j + 1].minus(centers[j])
            } else if j > 0 {
                centers[j].minus(centers[j - 1])
            } else {
                diag
            };
            unit(d).unwrap_or(diag)
        })
        .collect()
}

/// The member of `a` and of `b` closest to each other (centroids; each side pruned to the 64
/// members nearest the other field's centre).
fn closest_pair(a: &[usize], b: &[usize], cent: &[Pt], ca: Pt, cb: Pt) -> (usize, usize) {
    let prune = |v: &[usize], towards: Pt| -> Vec<usize> {
        let mut w: Vec<(f64, usize)> = v.iter().map(|&g| (cent[g].dist2(towards), g)).collect();
        w.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        w.truncate(64);
        w.into_iter().map(|x| x.1).collect()
    };
    let (pa, pb) = (prune(a, cb), prune(b, ca));
    let mut best = (f64::INFINITY, a[0], b[0]);
    for &x in &pa {
        for &y in &pb {
            let d = cent[x].dist2(cent[y]);
            if d < best.0 {
                best = (d, x, y);
            }
        }
    }
    (best.1, best.2)
}

/// Start and end geometry of every field (in visiting order), seed 000 §3.2.2.
fn start_end(fields: &[&ScanField], cent: &[Pt], profile: &MachineProfile) -> Vec<(usize, usize)> {
    let n = fields.len();
    let f = profile.field_mm;
    let mut se: Vec<(Option<usize>, Option<usize>)> = vec![(None, None); n];
    if n == 1 {
        let b = fields[0].bbox();
        let (tl, br) = (Pt::new(b.min_x, b.min_y), Pt::new(b.max_x, b.max_y));
        let g = &fields[0].geometries;
        let near = |p: Pt, skip: Option<usize>| {
            g.iter()
                .copied()
                .filter(|&x| Some(x) != skip || g.len() == 1)
                .min_by(|&x, &y| {
                    cent[x]
                        .dist2(p)
                        .total_cmp(&cent[y].dist2(p))
                        .then(x.cmp(&y))
                })
        };
        let s = near(tl, None);
        return vec![(s.unwrap_or(0), near(br, s).unwrap_or(0))];
    }
    for j in 0..n - 1 {
        let (a, b) = closest_pair(
            &fields[j].geometries,
            &fields[j + 1].geometries,
            cent,
            fields[j].center,
            fields[j + 1].center,
        );
        se[j].1 = Some(a);
        se[j + 1].0 = Some(b);
    }
    let farthest = |g: &[usize], p: Pt, skip: Option<usize>| {
        g.iter()
            .copied()
            .filter(|&x| Some(x) != skip || g.len() == 1)
            .max_by(|&x, &y| {
                cent[x]
                    .dist2(p)
                    .total_cmp(&cent[y].dist2(p))
                    .then(y.cmp(&x))
            })
    };
    // first field: farthest from where the line to the second field leaves it
    let u = unit(fields[1].center.minus(fields[0].center)).unwrap_or(Pt::new(1.0, 0.0));
    let exit = exit_point(fields[0].center, u, f);
    se[0].0 = farthest(&fields[0].geometries, exit, se[0].1);
    // last field: farthest from where the line from the previous field enters it
    let u = unit(fields[n - 2].center.minus(fields[n - 1].center)).unwrap_or(Pt::new(-1.0, 0.0));
    let entry = exit_point(fields[n - 1].center, u, f);
    se[n - 1].1 = farthest(&fields[n - 1].geometries, entry, se[n - 1].0);
    // a start that equals the end in a field with more members: the end takes the next nearest
    for j in 0..n {
        let g = &fields[j].geometries;
        if g.len() > 1 && se[j].0 == se[j].1 {
            let target = if j + 1 < n {
                fields[j + 1].center
            } else {
                entry
            };
            let s = se[j].0;
            let alt = g
                .iter()
                .copied()
                .filter(|&x| Some(x) != s)
                .min_by(|&x, &y| {
                    cent[x]
                        .dist2(target)
                        .total_cmp(&cent[y].dist2(target))
                        .then(x.cmp(&y))
                });
            se[j].1 = alt;
        }
    }
    se.into_iter()
        .zip(fields)
        .map(|((s, e), fl)| {
            let g0 = fl.geometries.first().copied().unwrap_or(0);
            (s.unwrap_or(g0), e.unwrap_or(g0))
        })
        .collect()
}

/// Orders one field's geometries from `start` to `end`: cheapest arc on Eq. 7's cost, then (when
/// `improve`) local search under the directional cost.
#[allow(clippy::too_many_arguments)]
fn order_field(
    members: &[usize],
    start: usize,
    end: usize,
    cent: &[Pt],
    exit: Pt,
    dir: Pt,
    weight: f64,
    diag: f64,
    improve: bool,
    seed: u64,
    budget: IlsBudget,
    ctx: &JobCtx,
) -> Result<Vec<usize>, Cancelled> {
    // parallel callers run every field's closure even after a cancel: stop before the set-up
    ctx.check()?;
    let m = members.len();
    if m <= 2 {
        let mut v = vec![start];
        v.extend(members.iter().copied().filter(|&g| g != start));
        return Ok(v);
    }
    let pts: Vec<Pt> = members.iter().map(|&g| cent[g]).collect();
    let local = |g: usize| members.iter().position(|&x| x == g).unwrap_or(0);
    let (s, e) = (local(start), local(end));
    // Eq. 7: |AB| = distance from the exit point B to the projection A of the next centroid on the
    // line through the field along the sweep direction
    let ab: Vec<f64> = pts.iter().map(|p| p.minus(exit).dot(dir).abs()).collect();
    let arc = |i: usize, j: usize| pts[i].dist(pts[j]) + weight * (diag - ab[j]);
    let order = if improve && m > CHEAPEST_ARC_MAX {
        // the start first, the end last, the rest along a Hilbert curve
        let mut order = vec![s];
        order.extend(
            space_filling_order(&pts)
                .into_iter()
                .filter(|&k| k != s && k != e),
        );
        if e != s {
            order.push(e);
        }
        order
    } else {
        cheapest_arc(m, s, (e != s).then_some(e), &arc)
    };
    let order = if improve {
        let proj: Vec<f64> = pts.iter().map(|p| p.dot(dir)).collect();
        let mut prob = PathProblem::points(&pts, &proj, weight);
        prob.fixed_first = true;
        prob.fixed_last = e != s;
        let mut tour = Tour {
            order,
            flipped: vec![false; m],
        };
        LocalSearch::new(&prob, LsOptions::default(), ctx)?
            .iterated_within(&mut tour, budget, seed, ctx)?;
        tour.order
    } else {
        order
    };
    Ok(order.into_iter().map(|k| members[k]).collect())
}

/// Largest lone field that HHA still descends before the time objective searches it: below
/// it the descent costs under a millisecond and gives the time objective's few kicks a better
/// basin than a Hilbert curve (rnd-32: job time 0.4939 s against 0.4949, with a
/// nearest-neighbour start 0.4951); above it the descent only costs time (BENCHMARKS, issue
/// 16: 1,000 dots 0.175 → 0.142 s of ordering, 10⁵ dots 9.45 → 3.43 s).
const LONE_DESCENT_MAX: usize = 200;

/// A field's geometries along a Hilbert curve through their centroids: the start a later
/// search takes over (it descends with its own cost and free ends).
fn hilbert_start(members: &[usize], cent: &[Pt], ctx: &JobCtx) -> Result<Vec<usize>, Cancelled> {
    ctx.check()?;
    let pts: Vec<Pt> = members.iter().map(|&g| cent[g]).collect();
    Ok(space_filling_order(&pts)
        .into_iter()
        .map(|k| members[k])
        .collect())
}

/// Local search of one field's strokes on their real ends, between fixed anchor points.
#[allow(clippy::too_many_arguments)]
pub(crate) fn refine_field(
    geometries: &[Geometry],
    run: &[Step],
    before: Option<Pt>,
    after: Option<Pt>,
    dir: Pt,
    lambda: f64,
    seed: u64,
    budget: IlsBudget,
    ctx: &JobCtx,
) -> Result<Vec<Step>, Cancelled> {
    ctx.check()?;
    let mut nodes = Vec::with_capacity(run.len() + 2);
    let mut flippable = Vec::with_capacity(run.len() + 2);
    if let Some(a) = before {
        nodes.push(Node::point(a, f64::NEG_INFINITY));
        flippable.push(false);
    }
    for s in run {
        let g = &geometries[s.geometry];
        let (a, b) = g.ends(s.choice(g));
        // open geometries are stored forwards so that flipping means reversing
        let (ns, ne) = if g.closed || !s.reversed {
            (a, b)
        } else {
            (b, a)
        };
        let p = g.centroid().dot(dir);
        let (node, flips) = if g.closed {
            (Node::point(ns, p), false)
        } else {
            Node::open_stroke(ns, ne, p)
        };
        nodes.push(node);
        flippable.push(flips);
    }
    if let Some(z) = after {
        nodes.push(Node::point(z, f64::INFINITY));
        flippable.push(false);
    }
    // anchors must not add penalties: give them the projections of their neighbours
    let k0 = usize::from(before.is_some());
    if before.is_some() {
        nodes[0].p = nodes.get(k0).map_or(0.0, |q| q.p);
    }
    if after.is_some() {
        let last = nodes.len() - 1;
        nodes[last].p = nodes[last - 1].p;
    }
    let n = nodes.len();
    let prob = PathProblem {
        nodes,
        lambda,
        fixed_first: before.is_some(),
        fixed_last: after.is_some(),
        flippable,
        cluster: Vec::new(),
        cluster_penalty: 0.0,
        metric: TravelCost::Distance,
    };
    let mut flipped = vec![false; n];
    for (k, s) in run.iter().enumerate() {
        flipped[k0 + k] = !geometries[s.geometry].closed && s.reversed;
    }
    let mut tour = Tour {
        order: (0..n).collect(),
        flipped,
    };
    LocalSearch::new(&prob, LsOptions::default(), ctx)?
        .iterated_within(&mut tour, budget, seed, ctx)?;
    Ok(tour
        .order
        .iter()
        .filter(|&&v| v >= k0 && v < k0 + run.len())
        .map(|&v| {
            let s = run[v - k0];
            let g = &geometries[s.geometry];
            if g.closed {
                s
            } else {
                Step::from_choice(s.geometry, s.field, g, usize::from(tour.flipped[v]))
            }
        })
        .collect())
}

/// One field path carried through HHA's per-field stages.
struct Routed<'f> {
    /// The fields in visiting order.
    ordered: Vec<&'f ScanField>,
    /// Each field's sweep direction.
    dirs: Vec<Pt>,
    /// The strokes with their start vertices.
    steps: Vec<Step>,
    /// Their idle travel, mm.
    idle_mm: f64,
    /// Time spent on the per-field paths and on the vertices, s.
    paths_s: f64,
    vertices_s: f64,
}

/// What HHA's per-field stages (seed 000 §3.2.2–3.2.3) share.
struct Stages<'a> {
    geometries: &'a [Geometry],
    cent: &'a [Pt],
    profile: &'a MachineProfile,
    settings: &'a SolverSettings,
    /// When the per-field searches stop (a share of `--time-limit`).
    until: Option<Instant>,
    /// A later search redoes the field's path with its full budget and free ends (a lone
    /// field: the time objective's search, or the free open path under the distance
    /// objective): the path is only a start, a descent up to
    /// [`LONE_DESCENT_MAX`] geometries and a Hilbert curve beyond.
    start_only: bool,
}

impl Stages<'_> {
    /// Eq. 7's direction weight: the settings' for several fields, 0.1 for a lone field.
    fn weight(&self, single: bool) -> f64 {
        if single {
            0.1
        } else {
            self.settings.direction_weight
        }
    }

    /// Start and end geometries, each field's path (in parallel) and the start vertices of the
    /// fields in `ordered`.
    fn route<'f>(
        &self,
        ordered: Vec<&'f ScanField>,
        ctx: &JobCtx,
    ) -> Result<Routed<'f>, Cancelled> {
        let (geometries, cent, profile) = (self.geometries, self.cent, self.profile);
        let t = Instant::now();
        let centers: Vec<Pt> = ordered.iter().map(|f| f.center).collect();
        let dirs = sweep_dirs(&centers);
        let se = start_end(&ordered, cent, profile);
        let single = ordered.len() == 1;
        let weight = self.weight(single);
        let diag = profile.field_mm[0].hypot(profile.field_mm[1]);
        let improve = self.settings.hha_improve || single;
        let per_field: Vec<Result<Vec<usize>, Cancelled>> = ordered
            .par_iter()
            .enumerate()
            .map(|(j, f)| {
                let exit = if single {
                    cent[se[0].1]
                } else {
                    exit_point(f.center, dirs[j], profile.field_mm)
                };
                let m = f.geometries.len();
                if self.start_only && m > LONE_DESCENT_MAX {
                    return hilbert_start(&f.geometries, cent, ctx);
                }
                let seed = self.settings.seed ^ ((j as u64) << 32);
                // the refinement rounds or the time objective go on from here: a fraction of
                // the kicks, or none
                let budget = if self.start_only {
                    IlsBudget::kicks(0)
                } else {
                    IlsBudget::until(m, self.until).divided(PRELIMINARY_KICK_DIVISOR)
                };
                order_field(
                    &f.geometries,
                    se[j].0,
                    se[j].1,
                    cent,
                    exit,
                    dirs[j],
                    weight,
                    diag,
                    improve,
                    seed,
                    budget,
                    ctx,
                )
            })
            .collect();
        let mut steps = Vec::with_capacity(geometries.len());
        for (j, r) in per_field.into_iter().enumerate() {
            for g in r? {
                steps.push(Step::from_choice(g, ordered[j].id, &geometries[g], 0));
            }
        }
        let paths_s = t.elapsed().as_secs_f64();
        ctx.progress("order", 2, 4, "HHA: vertices");
        let t = Instant::now();
        vea(geometries, &mut steps, ctx)?;
        let idle_mm = if self.settings.vertex == VertexMode::Exact {
            optimal_vertices(geometries, &mut steps, ctx)?
        } else {
            super::metrics::idle_mm(geometries, &steps)
        };
        Ok(Routed {
            ordered,
            dirs,
            steps,
            idle_mm,
            paths_s,
            vertices_s: t.elapsed().as_secs_f64(),
        })
    }
}

/// Refinement rounds: none for a lone field (its path is searched freely afterwards), one
/// before the time objective's own search, else up to [`REFINE_ROUNDS`].
fn refine_rounds(lone: bool, time_follows: bool) -> usize {
    match (lone, time_follows) {
        (true, _) => 0,
        (false, true) => REFINE_ROUNDS_BEFORE_TIME,
        (false, false) => REFINE_ROUNDS,
    }
}

/// HHA's time budgets: a time limit is HHA's own only when HHA is the algorithm (HGA spends
/// it on generations); under the time objective the refinement is preliminary too (the time
/// objective's search of each field's path comes last and gets the full budget).
struct Budgets<'a> {
    settings: &'a SolverSettings,
    t0: Instant,
    time_follows: bool,
}

impl Budgets<'_> {
    /// The deadline of a stage given `share` of the time limit, when HHA has one.
    fn limited(&self, share: f64) -> Option<Instant> {
        (self.settings.algo == crate::document::Algo::Hha)
            .then(|| deadline(self.settings, self.t0, share))
            .flatten()
    }
    /// The search budget of a field of `m` geometries in refinement round `round`.
    fn refine(&self, m: usize, round: usize) -> IlsBudget {
        let share = if self.time_follows {
            REFINE_SHARE
        } else {
            LAST_SEARCH_SHARE
        };
        let budget = IlsBudget::until(m, self.limited(share));
        if round > 0 || self.time_follows {
            budget.divided(PRELIMINARY_KICK_DIVISOR)
        } else {
            budget
        }
    }
}

/// Runs HHA on allocated fields. `stage_s` receives the time of each sub-stage.
pub fn hha_order(
    geometries: &[Geometry],
    fields: &[ScanField],
    profile: &MachineProfile,
    settings: &SolverSettings,
    ctx: &JobCtx,
    stage_s: &mut Vec<(String, f64)>,
) -> Result<Ordering, OrderError> {
    let t = Instant::now();
    let time_follows = settings.cost_model == crate::document::CostModel::Time;
    let budgets = Budgets {
        settings,
        t0: t,
        time_follows,
    };
    let live: Vec<&ScanField> = fields.iter().filter(|f| !f.geometries.is_empty()).collect();
    let live_owned: Vec<ScanField> = live.iter().map(|f| (*f).clone()).collect();
    // a lone field under the time objective: HHA's sweep direction and start/end rules mean
    // nothing once the time objective frees both ends and searches the path with its full
    // budget, so HHA only gives it a start along a Hilbert curve (BENCHMARKS)
    // (on the fly no time search follows: `order_plan` runs it for step-and-scan only)
    let lone_before_time =
        time_follows && settings.motion != crate::document::MotionMode::OnTheFly && live.len() == 1;
    // a lone field under the distance objective: its idle travel is the whole objective, so its
    // path is the free open path (no direction weight, free ends, the full budget), as the
    // engine alone finds it; HHA gives it only its start
    let lone_free = !time_follows && live.len() == 1;
    let cent: Vec<Pt> = geometries.iter().map(Geometry::centroid).collect();
    let (by_centre, by_gap) =
        field_order_candidates(&live_owned, &cent, profile, settings.cylinder, ctx)?;
    stage_s.push(("field_order".into(), t.elapsed().as_secs_f64()));
    ctx.progress("order", 1, 4, "HHA: field order");

    // every candidate field path through the per-field paths and vertices; the lowest idle wins
    let stages = Stages {
        geometries,
        cent: &cent,
        profile,
        settings,
        until: budgets.limited(FIELD_PATHS_SHARE),
        start_only: lone_before_time || lone_free,
    };
    let (best, paths_s, vertices_s) = stages.best_route(&live, &by_centre, by_gap, ctx)?;
    stage_s.push(("field_paths".into(), paths_s));
    stage_s.push(("vertices".into(), vertices_s));
    let Routed {
        ordered,
        dirs,
        mut steps,
        ..
    } = best;
    ctx.progress("order", 3, 4, "HHA: refine");
    if settings.hha_improve {
        let t = Instant::now();
        let rounds = refine_rounds(lone_before_time || lone_free, time_follows);
        let refine = Refine {
            geometries,
            cent: &cent,
            dirs: &dirs,
            lambda: stages.weight(ordered.len() == 1) * 2.0,
            budgets: &budgets,
        };
        steps = refine.rounds(steps, rounds, ctx)?;
        stage_s.push(("refine".into(), t.elapsed().as_secs_f64()));
    }
    if lone_free {
        let t = Instant::now();
        let until = budgets.limited(LAST_SEARCH_SHARE);
        let seeds = LONE_FREE_SEEDS.map(|s| settings.seed ^ s);
        steps = super::time::best_free_field_path(geometries, &steps, &seeds, until, ctx)?;
        stage_s.push(("free path".into(), t.elapsed().as_secs_f64()));
    }
    ctx.progress("order", 4, 4, "HHA: order made");
    Ok(Ordering {
        field_order: ordered.iter().map(|f| f.id).collect(),
        steps,
    })
}

impl Stages<'_> {
    /// The field order by centres and, when there is one, by gaps, each routed through its
    /// fields' paths and vertices; the one of lower idle travel, with the time both took in
    /// the path and vertex stages, s.
    fn best_route<'f>(
        &self,
        live: &[&'f ScanField],
        by_centre: &[usize],
        by_gap: Option<Vec<usize>>,
        ctx: &JobCtx,
    ) -> Result<(Routed<'f>, f64, f64), Cancelled> {
        let slots = |fo: &[usize]| -> Vec<&'f ScanField> { fo.iter().map(|&k| live[k]).collect() };
        let mut best = self.route(slots(by_centre), ctx)?;
        let (mut paths_s, mut vertices_s) = (best.paths_s, best.vertices_s);
        if let Some(fo) = by_gap {
            let routed = self.route(slots(&fo), ctx)?;
            paths_s += routed.paths_s;
            vertices_s += routed.vertices_s;
            if routed.idle_mm < best.idle_mm - 1e-9 {
                best = routed;
            }
        }
        Ok((best, paths_s, vertices_s))
    }
}

/// HHA's refinement: every field's path searched again between its neighbours' ends, on the
/// directional objective (idle travel plus `lambda` times the backward steps along each
/// field's sweep direction), alternate fields in parallel.
struct Refine<'a> {
    geometries: &'a [Geometry],
    cent: &'a [Pt],
    /// Each field's sweep direction, in visiting order.
    dirs: &'a [Pt],
    lambda: f64,
    budgets: &'a Budgets<'a>,
}

impl Refine<'_> {
    /// Up to `rounds` rounds, each kept while it gains (another only while it gains at least
    /// 0.1 %).
    fn rounds(
        &self,
        mut steps: Vec<Step>,
        rounds: usize,
        ctx: &JobCtx,
    ) -> Result<Vec<Step>, OrderError> {
        let g = self.geometries;
        // rounds are judged by the same directional objective the local search optimises
        let cent_dir = self.sweep_positions(&steps);
        let objective = |st: &[Step], idle: f64| -> f64 {
            idle + self.lambda
                * st.windows(2)
                    .filter(|w| w[0].field == w[1].field)
                    .map(|w| (cent_dir[w[0].geometry] - cent_dir[w[1].geometry]).max(0.0))
                    .sum::<f64>()
        };
        let mut best = objective(&steps, super::metrics::idle_mm(g, &steps));
        let vertex = self.budgets.settings.vertex;
        for round in 0..rounds {
            let mut next = steps.clone();
            self.round(&mut next, round, ctx)?;
            let idle = if vertex == VertexMode::Exact {
                optimal_vertices(g, &mut next, ctx)?
            } else {
                vea(g, &mut next, ctx)?;
                super::metrics::idle_mm(g, &next)
            };
            let idle = objective(&next, idle);
            if idle >= best - 1e-9 {
                break;
            }
            // keep the gain; another round only while it gains at least 0.1 %
            let small = idle > best * (1.0 - 1e-3);
            best = idle;
            steps = next;
            if small {
                break;
            }
        }
        Ok(steps)
    }

    /// Each geometry's centroid along its field's sweep direction.
    fn sweep_positions(&self, steps: &[Step]) -> Vec<f64> {
        let mut p = vec![0.0; self.geometries.len()];
        for (j, &(a, b)) in field_runs(steps).iter().enumerate() {
            for s in &steps[a..b] {
                p[s.geometry] = self.cent[s.geometry].dot(self.dirs[j]);
            }
        }
        p
    }

    /// One round: the even fields, then the odd ones (each between its neighbours as they
    /// are then), searched in parallel.
    fn round(&self, next: &mut [Step], round: usize, ctx: &JobCtx) -> Result<(), OrderError> {
        let g = self.geometries;
        let seed0 = self.budgets.settings.seed;
        for parity in 0..2 {
            let runs = field_runs(next);
            let updates: Vec<Result<(usize, Vec<Step>), Cancelled>> = runs
                .par_iter()
                .enumerate()
                .filter(|(j, _)| j % 2 == parity)
                .map(|(j, &(a, b))| {
                    let before = (a > 0).then(|| super::metrics::step_ends(g, &next[a - 1]).1);
                    let after = (b < next.len()).then(|| super::metrics::step_ends(g, &next[b]).0);
                    let seed = seed0 ^ ((j as u64) << 32) ^ ((round as u64) << 16);
                    refine_field(
                        g,
                        &next[a..b],
                        before,
                        after,
                        self.dirs[j],
                        self.lambda,
                        seed,
                        self.budgets.refine(b - a, round),
                        ctx,
                    )
                    .map(|r| (a, r))
                })
                .collect();
            for u in updates {
                let (a, r) = u?;
                next[a..a + r.len()].copy_from_slice(&r);
            }
        }
        Ok(())
    }
}

/// Position ranges `[a, b)` of each field's run in a step list (in order).
pub fn field_runs(steps: &[Step]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut a = 0;
    for k in 1..=steps.len() {
        if k == steps.len() || steps[k].field != steps[a].field {
            out.push((a, k));
            a = k;
        }
    }
    out
}

#[cfg(test)]
mod tests;
