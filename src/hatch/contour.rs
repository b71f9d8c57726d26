//! Contour-parallel fill: rings at inward offsets `0, s, 2s, …` of the offset region, plus gap
//! strokes where the rings leave something unmarked.
//!
//! With `Q_k` the region offset by `k·s` (ring `k` is its boundary) every point whose depth below
//! the offset boundary lies within `s/2` of a multiple of `s` is within `s/2` of a ring, except
//! where the next region `Q_{k+1}` has retreated (near the corners and ends of the medial axis,
//! and where a part is narrower than one spacing). Those gaps are the points of the half-step
//! region `H_k = Q_k ⊖ s/2` farther than `s/2` from `Q_{k+1}`; every such point is within `s/2` of
//! the boundary of `H_k`, so the pieces of that boundary farther than `s/2` from ring `k + 1` are
//! marked as gap strokes.

use super::region::{ArcGeom, Elem, Region};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use cavalier_contours::static_aabb2d_index::{StaticAABB2DIndex, StaticAABB2DIndexBuilder};
use rustc_hash::FxHashMap as HashMap;
use std::cell::OnceCell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// A boundary-of-`H_k` point counts as reached by ring `k + 1` within `s/2 · (1 + this)`.
const GAP_MARGIN: f64 = 0.004;

/// The rings and gap strokes of one offset level.
#[derive(Debug, Clone, Default)]
pub(crate) struct Level {
    /// Closed rings (boundary loops of `Q_k`).
    pub rings: Vec<Vec<Pt>>,
    /// Gap strokes between ring `k` and ring `k + 1`: (points, closed).
    pub gaps: Vec<(Vec<Pt>, bool)>,
}

/// Rings and gaps of `region` offset inward by `edge_mm`, `spacing` apart.
///
/// Two chains of offsets run side by side, `Q_0 → Q_2 → Q_4 …` and `Q_1 → Q_3 → …` (steps of
/// `2s`: erosions by discs compose, so `Q_{k+2} = Q_k ⊖ 2s`; `Q_0` and `Q_1` are both offsets of
/// `region` itself), which halves the longest chain of dependent offsets; as soon as `Q_k` and
/// `Q_{k+1}` exist a task flattens ring `k + 1` and finds the gaps of level `k`.
pub(crate) fn contour_levels(
    region: &Region,
    edge_mm: f64,
    spacing: f64,
    tol_mm: f64,
    max_levels: usize,
    ctx: &JobCtx,
) -> Result<Vec<Level>, Cancelled> {
    if region.is_empty() {
        return Ok(Vec::new());
    }
    let st = LevelState {
        regions: Mutex::new(Vec::new()),
        rings: Mutex::new(Vec::new()),
        gaps: Mutex::new(Vec::new()),
        first_empty: AtomicUsize::new(max_levels.saturating_add(1)),
        cancelled: AtomicBool::new(false),
        spacing,
        tol_mm,
    };
    rayon::scope(|sc| {
        let st = &st;
        sc.spawn(move |sc| {
            let q1 = region.offset(edge_mm + spacing);
            let q1 = (!q1.is_empty()).then(|| Arc::new(q1));
            if let Some(q1) = st.publish(sc, 1, q1) {
                st.chain(sc, 1, q1, ctx);
            }
        });
        let q0 = region.offset(edge_mm);
        let q0 = (!q0.is_empty()).then(|| Arc::new(q0));
        if let Some(q0) = st.publish(sc, 0, q0) {
            let level0 = q0.clone();
            sc.spawn(move |_| store(&st.rings, 0, level0.flatten(tol_mm)));
            st.chain(sc, 0, q0, ctx);
        }
    });
    if st.cancelled.load(Ordering::Relaxed) {
        return Err(Cancelled);
    }
    // levels 0 .. first empty region
    let n = st.first_empty.load(Ordering::Relaxed);
    let mut rings = st.rings.into_inner().unwrap_or_default().into_iter();
    let mut gaps = st.gaps.into_inner().unwrap_or_default().into_iter();
    let mut levels: Vec<Level> = (0..n)
        .map(|_| Level {
            rings: rings.next().flatten().unwrap_or_default(),
            gaps: gaps.next().flatten().unwrap_or_default(),
        })
        .collect();
    while levels
        .last()
        .is_some_and(|l| l.rings.is_empty() && l.gaps.is_empty())
    {
        levels.pop();
    }
    Ok(levels)
}

/// What the chains and tasks of [`contour_levels`] share.
struct LevelState {
    /// `Q_k` by level once known: `Some(None)` when empty.
    regions: Slots<Option<Arc<Region>>>,
    rings: Slots<Vec<Vec<Pt>>>,
    gaps: Slots<Vec<(Vec<Pt>, bool)>>,
    /// The lowest level known to be empty (or beyond the level limit).
    first_empty: AtomicUsize,
    cancelled: AtomicBool,
    spacing: f64,
    tol_mm: f64,
}

impl LevelState {
    /// Offsets by `2s` from `q` (level `k`) while the regions last.
    fn chain<'s>(&'s self, sc: &rayon::Scope<'s>, mut k: usize, mut q: Arc<Region>, ctx: &JobCtx) {
        loop {
            if ctx.check().is_err() {
                self.cancelled.store(true, Ordering::Relaxed);
                return;
            }
            if self.cancelled.load(Ordering::Relaxed) {
                return;
            }
            k += 2;
            let next = if k >= self.first_empty.load(Ordering::Relaxed) {
                None
            } else {
                let n = q.offset(2.0 * self.spacing);
                (!n.is_empty()).then(|| Arc::new(n))
            };
            match self.publish(sc, k, next) {
                Some(n) => q = n,
                None => return,
            }
        }
    }

    /// Records `Q_k` and starts the level tasks it completes; returns it back.
    fn publish<'s>(
        &'s self,
        sc: &rayon::Scope<'s>,
        k: usize,
        q: Option<Arc<Region>>,
    ) -> Option<Arc<Region>> {
        if q.is_none() {
            self.first_empty.fetch_min(k, Ordering::Relaxed);
        }
        let Ok(mut regions) = self.regions.lock() else {
            return None;
        };
        if regions.len() <= k + 1 {
            regions.resize_with(k + 2, || None);
        }
        regions[k] = Some(q.clone());
        // level j needs Q_j (not empty) and Q_{j+1}
        for j in [k.checked_sub(1), Some(k)].into_iter().flatten() {
            if let (Some(Some(lo)), Some(hi)) = (&regions[j], &regions[j + 1]) {
                let (lo, hi) = (lo.clone(), hi.clone());
                sc.spawn(move |_| self.level(j, &lo, hi.as_deref()));
            }
        }
        q
    }

    /// Ring `k + 1` and the gaps of level `k`.
    fn level(&self, k: usize, q: &Region, next: Option<&Region>) {
        let (s, tol_mm) = (self.spacing, self.tol_mm);
        let next_rings = next.map(|n| n.flatten(tol_mm));
        let g = match (next, &next_rings) {
            (Some(n), Some(nr)) if !nr.is_empty() => {
                let elems = ElemTable::new(n, q.frame.len_units(s / 2.0));
                let loops = q.offset_flattened_marked(s / 2.0, tol_mm, |e| elems.covers(e));
                gap_strokes(&loops, nr, s)
            }
            _ => q
                .offset_flattened_marked(s / 2.0, tol_mm, |_| false)
                .into_iter()
                .map(|(l, _)| (l, true))
                .collect(),
        };
        store(&self.gaps, k, g);
        if let Some(nr) = next_rings {
            store(&self.rings, k + 1, nr);
        }
    }
}

/// Results of parallel tasks by level.
type Slots<T> = Mutex<Vec<Option<T>>>;

/// Puts `v` into slot `k`.
fn store<T>(slots: &Slots<T>, k: usize, v: T) {
    if let Ok(mut s) = slots.lock() {
        if s.len() <= k {
            s.resize_with(k + 1, || None);
        }
        s[k] = Some(v);
    }
}

/// Segments of closed loops with a spatial index and their neighbours along the loops.
struct SegIndex {
    segs: Vec<(Pt, Pt)>,
    /// Next and previous segment of the same loop.
    next: Vec<u32>,
    prev: Vec<u32>,
    /// Built on first use (most segments are covered by their neighbours' hits).
    index: OnceCell<Option<StaticAABB2DIndex<f64>>>,
}

impl SegIndex {
    fn new(loops: &[Vec<Pt>]) -> Self {
        let mut segs = Vec::new();
        let (mut next, mut prev) = (Vec::new(), Vec::new());
        for l in loops {
            let (base, m) = (segs.len() as u32, l.len() as u32);
            for i in 0..l.len() {
                segs.push((l[i], l[(i + 1) % l.len()]));
                let i = i as u32;
                next.push(base + (i + 1) % m);
                prev.push(base + (i + m - 1) % m);
            }
        }
        Self {
            index: OnceCell::new(),
            segs,
            next,
            prev,
        }
    }

    fn index(&self) -> Option<&StaticAABB2DIndex<f64>> {
        self.index
            .get_or_init(|| {
                let mut b = StaticAABB2DIndexBuilder::new(self.segs.len());
                for (a, q) in &self.segs {
                    b.add(a.x.min(q.x), a.y.min(q.y), a.x.max(q.x), a.y.max(q.y));
                }
                b.build().ok()
            })
            .as_ref()
    }

    /// The parts of the segment `a`–`b` (parameter intervals in 0..=1) farther than `r` from
    /// every indexed segment, into `sc.far`. `near` holds the segments that reached the previous
    /// segment of the same loop: along parallel loops they and the next ones usually cover this
    /// one too, which saves the index query; they are tried first, then their neighbours, then
    /// the index.
    fn far_parts(&self, a: Pt, b: Pt, r: f64, near: &mut Vec<u32>, sc: &mut Scratch) {
        let Scratch {
            tried,
            hit,
            buf,
            far,
        } = sc;
        tried.clear();
        hit.clear();
        buf.clear();
        let mut try_seg = |t: u32, buf: &mut Vec<(f64, f64)>| {
            if tried.contains(&t) {
                return;
            }
            tried.push(t);
            let (q0, q1) = self.segs[t as usize];
            if let Some(iv) = capsule_interval(a, b, q0, q1, r) {
                buf.push(iv);
                hit.push(t);
            }
        };
        // 1. the previous hits and the segment after the last of them
        for &c in near.iter() {
            try_seg(c, buf);
        }
        if let Some(&c) = near.last() {
            try_seg(self.next[c as usize], buf);
        }
        gaps_of(buf, far);
        // 2. their neighbours on both sides
        if !far.is_empty() && !near.is_empty() {
            for &c in near.iter() {
                try_seg(self.prev[c as usize], buf);
                try_seg(self.next[c as usize], buf);
            }
            gaps_of(buf, far);
        }
        // 3. the index
        if !far.is_empty() {
            if let Some(index) = self.index() {
                for i in index.query_iter(
                    a.x.min(b.x) - r,
                    a.y.min(b.y) - r,
                    a.x.max(b.x) + r,
                    a.y.max(b.y) + r,
                ) {
                    try_seg(i as u32, buf);
                }
            }
            gaps_of(buf, far);
        }
        let len = a.dist2(b).sqrt();
        far.retain(|(lo, hi)| (hi - lo) * len > 1e-9);
        near.clear();
        near.extend_from_slice(hit);
    }
}

/// Scratch space of [`SegIndex::far_parts`], reused from segment to segment.
#[derive(Default)]
struct Scratch {
    /// Segments tried for the current segment.
    tried: Vec<u32>,
    /// Those within reach.
    hit: Vec<u32>,
    /// Their parameter intervals.
    buf: Vec<(f64, f64)>,
    /// The result: parameter intervals farther than `r` from every segment.
    far: Vec<(f64, f64)>,
}

/// The complement in 0..=1 of the union of `cover` (sorted here), into `far`.
fn gaps_of(cover: &mut [(f64, f64)], far: &mut Vec<(f64, f64)>) {
    far.clear();
    cover.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut t = 0.0;
    for &(lo, hi) in cover.iter() {
        if lo > t {
            far.push((t, lo));
        }
        t = t.max(hi);
    }
    if t < 1.0 {
        far.push((t, 1.0));
    }
}

/// The parameter interval (clipped to 0..=1) of the segment `a`–`b` within `r` of the segment
/// `q0`–`q1` (a capsule, convex, so the set is one interval).
fn capsule_interval(a: Pt, b: Pt, q0: Pt, q1: Pt, r: f64) -> Option<(f64, f64)> {
    let e = b.minus(a);
    let ee = e.dot(e);
    if ee <= 0.0 {
        return None;
    }
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    // the end discs
    for c in [q0, q1] {
        let w = a.minus(c);
        let (bq, cq) = (e.dot(w), w.dot(w) - r * r);
        let disc = bq * bq - ee * cq;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            lo = lo.min((-bq - sq) / ee);
            hi = hi.max((-bq + sq) / ee);
        }
    }
    // the rectangle: 0 ≤ (p − q0)·d ≤ L and |(p − q0)·n| ≤ r, each linear in t
    let dq = q1.minus(q0);
    let l = dq.dot(dq).sqrt();
    if l > 0.0 {
        let d = dq.scale(1.0 / l);
        let n = Pt::new(-d.y, d.x);
        let w = a.minus(q0);
        let mut t0 = f64::NEG_INFINITY;
        let mut t1 = f64::INFINITY;
        for (f0, f1, min, max) in [(w.dot(d), e.dot(d), 0.0, l), (w.dot(n), e.dot(n), -r, r)] {
            if f1.abs() < 1e-300 {
                if f0 < min || f0 > max {
                    t0 = f64::INFINITY;
                }
            } else {
                let (u, v) = ((min - f0) / f1, (max - f0) / f1);
                t0 = t0.max(u.min(v));
                t1 = t1.min(u.max(v));
            }
        }
        if t0 <= t1 {
            lo = lo.min(t0);
            hi = hi.max(t1);
        }
    }
    let (lo, hi) = (lo.max(0.0), hi.min(1.0));
    (lo <= hi).then_some((lo, hi))
}

/// The boundary elements of ring `k + 1`, to recognise the elements of the half-step loop that
/// lie exactly `s/2` from one of them: an arc concentric with an arc of ring `k + 1` at `s/2`
/// radius difference and within its angular span, or a line segment parallel to one of ring
/// `k + 1` at `s/2` and within its extent. Offsets move line segments parallel and keep the
/// centres of arcs, so most of the half-step loop is recognised and skipped by the distance
/// check; what is left are the corners and the parts that vanish in ring `k + 1`.
struct ElemTable {
    arcs: HashMap<(i64, i64), Vec<ArcGeom>>,
    /// Line segments by (direction angle, signed distance of the line from the origin).
    lines: HashMap<(i64, i64), Vec<LineKey>>,
    /// `s/2` in frame units.
    half_units: f64,
}

/// A line segment of ring `k + 1` as a key: direction angle, unit direction, signed distance of
/// its line from the origin along the left normal, and its extent along the direction.
#[derive(Debug, Clone, Copy)]
struct LineKey {
    angle: f64,
    dist: f64,
    lo: f64,
    hi: f64,
}

impl LineKey {
    fn of(a: Pt, b: Pt) -> Option<Self> {
        let d = b.minus(a);
        let len = d.dot(d).sqrt();
        if len <= 0.0 {
            return None;
        }
        let u = d.scale(1.0 / len);
        let n = Pt::new(-u.y, u.x);
        let (ta, tb) = (u.dot(a), u.dot(b));
        Some(Self {
            angle: u.y.atan2(u.x),
            dist: n.dot(a),
            lo: ta.min(tb),
            hi: ta.max(tb),
        })
    }
}

/// Centres and line distances closer than this (frame units; one spacing is 64 units) are the
/// same.
const SAME_POS_UNITS: f64 = 1e-4;
/// Radii or line distances that differ from `s/2` by less than this (frame units) are `s/2`
/// apart.
const SAME_DIST_UNITS: f64 = 1e-4;
/// Directions closer than this (radians) are the same.
const SAME_ANGLE: f64 = 1e-9;
/// Slack at the element ends, as a fraction of `s/2` of length.
const END_SLACK: f64 = 1e-3;
/// Hash cells (much larger than the tolerances above, so a lookup usually probes one cell):
/// arc centres, frame units.
const ARC_CELL: f64 = 1.0;
/// Line directions, radians.
const LINE_CELL_ANGLE: f64 = 1e-6;
/// Line distances from the origin, frame units.
const LINE_CELL_DIST: f64 = 1.0;

impl ElemTable {
    fn new(next: &Region, half_units: f64) -> Self {
        let mut arcs: HashMap<(i64, i64), Vec<ArcGeom>> = HashMap::default();
        let mut lines: HashMap<(i64, i64), Vec<LineKey>> = HashMap::default();
        for e in next.elems() {
            match e {
                Elem::Arc(a) => arcs.entry(Self::arc_cell(a.center)).or_default().push(a),
                Elem::Line(a, b) => {
                    if let Some(k) = LineKey::of(a, b) {
                        lines
                            .entry(Self::line_cell(k.angle, k.dist))
                            .or_default()
                            .push(k);
                    }
                }
            }
        }
        Self {
            arcs,
            lines,
            half_units,
        }
    }

    fn arc_cell(c: Pt) -> (i64, i64) {
        (
            (c.x / ARC_CELL).floor() as i64,
            (c.y / ARC_CELL).floor() as i64,
        )
    }

    fn line_cell(angle: f64, dist: f64) -> (i64, i64) {
        (
            (angle / LINE_CELL_ANGLE).floor() as i64,
            (dist / LINE_CELL_DIST).floor() as i64,
        )
    }

    /// True when `e` (an element of the half-step loop) lies exactly `s/2` from ring `k + 1`.
    fn covers(&self, e: &Elem) -> bool {
        match e {
            Elem::Arc(a) => {
                let (c, t) = (a.center, SAME_POS_UNITS);
                cells(
                    Self::arc_cell(Pt::new(c.x - t, c.y - t)),
                    Self::arc_cell(Pt::new(c.x + t, c.y + t)),
                )
                .any(|k| {
                    self.arcs
                        .get(&k)
                        .is_some_and(|l| l.iter().any(|b| self.arc_covers(b, a)))
                })
            }
            Elem::Line(p, q) => {
                let Some(h) = LineKey::of(*p, *q) else {
                    return true;
                };
                // the matching line of ring k + 1 lies s/2 further to the left
                let d = h.dist + self.half_units;
                let (ta, td) = (SAME_ANGLE, SAME_DIST_UNITS);
                cells(
                    Self::line_cell(h.angle - ta, d - td),
                    Self::line_cell(h.angle + ta, d + td),
                )
                .any(|k| {
                    self.lines
                        .get(&k)
                        .is_some_and(|l| l.iter().any(|b| self.line_covers(b, &h)))
                })
            }
        }
    }

    fn line_covers(&self, b: &LineKey, h: &LineKey) -> bool {
        let slack = END_SLACK * self.half_units;
        (b.angle - h.angle).abs() <= SAME_ANGLE
            && (b.dist - h.dist - self.half_units).abs() <= SAME_DIST_UNITS
            && h.lo >= b.lo - slack
            && h.hi <= b.hi + slack
    }

    fn arc_covers(&self, b: &ArcGeom, a: &ArcGeom) -> bool {
        if b.center.dist2(a.center) > SAME_POS_UNITS * SAME_POS_UNITS
            || ((b.radius - a.radius).abs() - self.half_units).abs() > SAME_DIST_UNITS
            || (a.sweep > 0.0) != (b.sweep > 0.0)
        {
            return false;
        }
        // both spans counter-clockwise: [start, start + len]
        let span = |g: &ArcGeom| {
            if g.sweep >= 0.0 {
                (g.start, g.sweep)
            } else {
                (g.start + g.sweep, -g.sweep)
            }
        };
        let ((a0, al), (b0, bl)) = (span(a), span(b));
        let slack = END_SLACK * self.half_units / b.radius.max(a.radius);
        let d = (a0 - b0 + slack).rem_euclid(std::f64::consts::TAU) - slack;
        d + al <= bl + slack
    }
}

/// The cells from `lo` to `hi` (inclusive; usually one).
fn cells(lo: (i64, i64), hi: (i64, i64)) -> impl Iterator<Item = (i64, i64)> {
    (lo.0..=hi.0).flat_map(move |x| (lo.1..=hi.1).map(move |y| (x, y)))
}

/// The pieces of the half-step loops farther than `s/2` (plus the margin) from the next rings.
///
/// `half` holds the half-step loops with a flag per segment: flagged segments lie exactly `s/2`
/// from ring `k + 1` (see [`ElemTable`]) and are not checked.
fn gap_strokes(
    half: &[(Vec<Pt>, Vec<bool>)],
    next: &[Vec<Pt>],
    spacing: f64,
) -> Vec<(Vec<Pt>, bool)> {
    let index = SegIndex::new(next);
    let r = spacing / 2.0 * (1.0 + GAP_MARGIN);
    let mut out = Vec::new();
    let mut near: Vec<u32> = Vec::new();
    let mut sc = Scratch::default();
    for (l, covered) in half {
        let m = l.len();
        // polylines of far parts; `open` says whether the last one reaches its edge's end
        let mut runs: Vec<Vec<Pt>> = Vec::new();
        let mut open = false;
        let mut first_from_start = false;
        let mut all_far = true;
        for i in 0..m {
            let (a, b) = (l[i], l[(i + 1) % m]);
            if covered.get(i).copied().unwrap_or(false) {
                sc.far.clear();
                near.clear();
            } else {
                index.far_parts(a, b, r, &mut near, &mut sc);
            }
            let parts = &sc.far;
            if !(parts.len() == 1 && parts[0].0 == 0.0 && parts[0].1 == 1.0) {
                all_far = false;
            }
            // a part from the edge's start continues the run that reached the edge's end
            let mut joins = open;
            open = false;
            for &(lo, hi) in parts {
                let p = a.plus(b.minus(a).scale(lo));
                let q = a.plus(b.minus(a).scale(hi));
                match runs.last_mut() {
                    Some(run) if joins && lo == 0.0 => run.push(q),
                    _ => {
                        if i == 0 && lo == 0.0 {
                            first_from_start = true;
                        }
                        runs.push(vec![p, q]);
                    }
                }
                joins = false;
                open = hi == 1.0;
            }
        }
        if all_far {
            out.push((l.clone(), true));
            continue;
        }
        // the last run reaches the loop's start and the first run starts there: one run
        if open && first_from_start && runs.len() > 1 {
            let first = runs.remove(0);
            if let Some(last) = runs.last_mut() {
                last.extend(first.into_iter().skip(1));
            }
        }
        out.extend(runs.into_iter().map(|r| (r, false)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::region::{resolve, Frame};
    use super::super::settings::FillRule;
    use super::*;
    use crate::geom::polyline_length;

    fn disc(r: f64, n: usize) -> Vec<Pt> {
        (0..n)
            .map(|i| {
                let a = i as f64 / n as f64 * std::f64::consts::TAU;
                Pt::new(r * a.cos(), r * a.sin())
            })
            .collect()
    }

    #[test]
    fn square_rings_and_centre_gap() {
        // 10 × 10 square: rings at 0, 1, .., 4 mm in, half-sizes 5, 4, .., 1; the centre is
        // reached by the last ring (1 mm half-size: corners at √2 > 0.5 but the centre is 1 away)
        let sq = vec![
            Pt::new(0.0, 0.0),
            Pt::new(10.0, 0.0),
            Pt::new(10.0, 10.0),
            Pt::new(0.0, 10.0),
        ];
        let loops = resolve(&[sq], FillRule::EvenOdd);
        let r = Region::new(&loops, Frame::new(&loops, 1.0));
        let levels = contour_levels(&r, 0.0, 1.0, 1e-4, 100, &JobCtx::default()).unwrap();
        assert_eq!(levels.len(), 5);
        let ring_len: f64 = levels
            .iter()
            .flat_map(|l| &l.rings)
            .map(|p| polyline_length(p, true))
            .sum();
        assert!((ring_len - 4.0 * (10.0 + 8.0 + 6.0 + 4.0 + 2.0)).abs() < 1e-6);
        // corners of every ring leave wedges: gap strokes exist around the corners
        assert!(levels.iter().any(|l| !l.gaps.is_empty()));
        // the innermost level (2 × 2) has a 1 × 1 half-step square and no next ring: a closed gap
        let last = levels.last().unwrap();
        assert_eq!(last.gaps.len(), 1);
        assert!(last.gaps[0].1);
    }

    #[test]
    fn disc_rings_have_no_gaps_until_the_centre() {
        let loops = resolve(&[disc(5.3, 720)], FillRule::EvenOdd);
        let r = Region::new(&loops, Frame::new(&loops, 1.0));
        let levels = contour_levels(&r, 0.0, 1.0, 1e-4, 100, &JobCtx::default()).unwrap();
        // radii 5.3, 4.3, .., 0.3: six rings
        assert_eq!(levels.len(), 6);
        assert!(levels.iter().all(|l| l.gaps.is_empty()));
    }
}
