//! Gap strokes of the contour-parallel fill: the pieces of a half-step boundary farther than
//! `s/2` (plus a margin) from the next ring.

use crate::geom::{polyline_length, BBox, Pt};
use cavalier_contours::static_aabb2d_index::{StaticAABB2DIndex, StaticAABB2DIndexBuilder};
use std::cell::OnceCell;

/// A boundary-of-`H_k` point counts as reached by ring `k + 1` within `s/2 · (1 + this)`.
pub(crate) const GAP_MARGIN: f64 = 0.004;
/// Gap strokes shorter than this many spacings are dropped. They mark slivers that reach less
/// than about 0.6 % beyond `s/2` from the rings: a sharp corner of turn θ leaves a far piece of
/// `s · (tan(θ/2) − 0.0895)` on the half-step boundary whose corner lies `s/2 · (1/cos(θ/2) − 1)`
/// beyond `s/2`, and a closed piece of this perimeter has an inradius under `0.0032 s`. Such
/// micro-strokes (a few µm) cost a jump and a laser switch each and say nothing at any spot size.
pub(crate) const MIN_GAP_LEN_SPACING: f64 = 0.02;

/// Ring `k + 1` of a level, flattened, as segments with a spatial index: what the half-step
/// boundary is measured against.
pub(crate) struct NextRing {
    index: SegIndex,
    /// The reach `s/2 · (1 + GAP_MARGIN)`, mm.
    reach_mm: f64,
    /// Shorter gap strokes are dropped, mm.
    min_len_mm: f64,
}

impl NextRing {
    /// Ring `k + 1` (closed loops, mm) for spacing `spacing` mm.
    pub(crate) fn new(rings: &[Vec<Pt>], spacing: f64) -> Self {
        Self::of_index(SegIndex::new(rings), spacing)
    }

    fn of_index(index: SegIndex, spacing: f64) -> Self {
        Self {
            index,
            reach_mm: spacing / 2.0 * (1.0 + GAP_MARGIN),
            min_len_mm: spacing * MIN_GAP_LEN_SPACING,
        }
    }

    /// Like [`Self::new`], keeping only the segments within reach of `boxes` (mm): for points
    /// inside the boxes the answer is the same.
    pub(crate) fn near(rings: &[Vec<Pt>], spacing: f64, boxes: &[BBox]) -> Self {
        // (a little more than the reach: the test is on segment boxes)
        let grow = 1.01 * spacing / 2.0 * (1.0 + GAP_MARGIN);
        let grown: Vec<BBox> = boxes
            .iter()
            .map(|b| BBox {
                min_x: b.min_x - grow,
                min_y: b.min_y - grow,
                max_x: b.max_x + grow,
                max_y: b.max_y + grow,
            })
            .collect();
        let near = |a: Pt, b: Pt| {
            grown.iter().any(|g| {
                a.x.max(b.x) >= g.min_x
                    && a.x.min(b.x) <= g.max_x
                    && a.y.max(b.y) >= g.min_y
                    && a.y.min(b.y) <= g.max_y
            })
        };
        Self::of_index(SegIndex::filtered(rings, near), spacing)
    }

    /// The pieces of `pts` (a closed loop or an open polyline) farther than the reach from the
    /// ring, into `out` as (points, closed). Segments `i` with `skip[i]` lie within reach by
    /// construction and are not checked.
    pub(crate) fn far_runs(
        &self,
        pts: &[Pt],
        closed: bool,
        skip: Option<&[bool]>,
        out: &mut Vec<(Vec<Pt>, bool)>,
    ) {
        let m = pts.len();
        if m < 2 {
            return;
        }
        let segs = if closed { m } else { m - 1 };
        let mut near: Vec<u32> = Vec::new();
        let mut sc = Scratch::default();
        // polylines of far parts; `open` says whether the last one reaches its segment's end
        let mut runs: Vec<Vec<Pt>> = Vec::new();
        let mut open = false;
        let mut first_from_start = false;
        let mut all_far = true;
        for i in 0..segs {
            let (a, b) = (pts[i], pts[(i + 1) % m]);
            if skip.and_then(|s| s.get(i)).copied().unwrap_or(false) {
                sc.far.clear();
                near.clear();
            } else {
                self.index
                    .far_parts(a, b, self.reach_mm, &mut near, &mut sc);
            }
            let parts = &sc.far;
            if !(parts.len() == 1 && parts[0].0 == 0.0 && parts[0].1 == 1.0) {
                all_far = false;
            }
            // a part from the segment's start continues the run that reached its end
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
            if polyline_length(pts, closed) >= self.min_len_mm {
                out.push((pts.to_vec(), closed));
            }
            return;
        }
        // on a loop, the last run reaches the start and the first run starts there: one run
        if closed && open && first_from_start && runs.len() > 1 {
            let first = runs.remove(0);
            if let Some(last) = runs.last_mut() {
                last.extend(first.into_iter().skip(1));
            }
        }
        out.extend(
            runs.into_iter()
                .filter(|r| polyline_length(r, false) >= self.min_len_mm)
                .map(|r| (r, false)),
        );
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
        Self::filtered(loops, |_, _| true)
    }

    /// The segments for which `keep` holds; neighbours along a loop are linked where both are
    /// kept (else a segment is its own neighbour).
    fn filtered(loops: &[Vec<Pt>], keep: impl Fn(Pt, Pt) -> bool) -> Self {
        let mut segs = Vec::new();
        let (mut next, mut prev) = (Vec::new(), Vec::new());
        for l in loops {
            let m = l.len();
            // indexes of the kept segments of this loop, by loop position
            let mut id: Vec<Option<u32>> = Vec::with_capacity(m);
            for i in 0..m {
                let (a, b) = (l[i], l[(i + 1) % m]);
                if keep(a, b) {
                    id.push(Some(segs.len() as u32));
                    segs.push((a, b));
                } else {
                    id.push(None);
                }
            }
            for i in 0..m {
                if let Some(me) = id[i] {
                    next.push(id[(i + 1) % m].unwrap_or(me));
                    prev.push(id[(i + m - 1) % m].unwrap_or(me));
                }
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
