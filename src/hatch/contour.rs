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

use super::region::Region;
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use cavalier_contours::static_aabb2d_index::{StaticAABB2DIndex, StaticAABB2DIndexBuilder};
use std::cell::OnceCell;
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

/// Rings and gaps of `region` (already offset by the edge distance), `spacing` apart.
///
/// The chain of offsets `Q_k → Q_{k+1}` runs on the calling thread; as soon as `Q_{k+1}` exists a
/// task flattens it and finds the gaps of level `k`, so the two run side by side.
pub(crate) fn contour_levels(
    region: &Region,
    spacing: f64,
    tol_mm: f64,
    max_levels: usize,
    ctx: &JobCtx,
) -> Result<Vec<Level>, Cancelled> {
    if region.is_empty() {
        return Ok(Vec::new());
    }
    // slot k: rings of level k (set by task k − 1, or for k = 0 below) and gaps of level k
    let rings: Slots<Vec<Vec<Pt>>> = Mutex::new(Vec::new());
    let gaps: Slots<Vec<(Vec<Pt>, bool)>> = Mutex::new(Vec::new());
    let first = Arc::new(Region {
        shape: region.shape.clone(),
        frame: region.frame,
    });
    let mut result: Result<(), Cancelled> = Ok(());
    rayon::scope(|sc| {
        let level0 = first.clone();
        let rings_ref = &rings;
        sc.spawn(move |_| store(rings_ref, 0, level0.flatten(tol_mm)));
        let mut cur = first;
        for k in 0..max_levels {
            if let Err(e) = ctx.check() {
                result = Err(e);
                return;
            }
            let next = cur.offset(spacing);
            let next = (!next.is_empty()).then(|| Arc::new(next));
            let (q, n) = (cur.clone(), next.clone());
            let (rings_ref, gaps_ref) = (&rings, &gaps);
            sc.spawn(move |_| {
                let next_rings = n.map(|n| n.flatten(tol_mm));
                let half = q.offset(spacing / 2.0);
                let g = if half.is_empty() {
                    Vec::new()
                } else {
                    let loops = half.flatten(tol_mm);
                    match &next_rings {
                        Some(nr) if !nr.is_empty() => gap_strokes(&loops, nr, spacing),
                        _ => loops.into_iter().map(|l| (l, true)).collect(),
                    }
                };
                store(gaps_ref, k, g);
                if let Some(nr) = next_rings {
                    store(rings_ref, k + 1, nr);
                }
            });
            match next {
                Some(n) => cur = n,
                None => break,
            }
        }
    });
    result?;
    let mut rings = rings.into_inner().unwrap_or_default().into_iter();
    let mut gaps = gaps.into_inner().unwrap_or_default().into_iter();
    let mut levels = Vec::new();
    loop {
        match (rings.next(), gaps.next()) {
            (None, None) => break,
            (r, g) => levels.push(Level {
                rings: r.flatten().unwrap_or_default(),
                gaps: g.flatten().unwrap_or_default(),
            }),
        }
    }
    Ok(levels)
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
    /// every indexed segment, into `far`. `near` holds the segments that reached the previous
    /// segment of the same loop: along parallel loops they and the next ones usually cover this
    /// one too, which saves the index query; they are tried first, then their neighbours, then
    /// the index. `buf` is scratch space.
    fn far_parts(
        &self,
        a: Pt,
        b: Pt,
        r: f64,
        near: &mut Vec<u32>,
        buf: &mut Vec<(f64, f64)>,
        far: &mut Vec<(f64, f64)>,
    ) {
        let mut tried: Vec<u32> = Vec::with_capacity(16);
        let mut hit: Vec<u32> = Vec::with_capacity(16);
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
        near.extend_from_slice(&hit);
    }
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

/// The pieces of the half-step loops farther than `s/2` (plus the margin) from the next rings.
fn gap_strokes(half: &[Vec<Pt>], next: &[Vec<Pt>], spacing: f64) -> Vec<(Vec<Pt>, bool)> {
    let index = SegIndex::new(next);
    let r = spacing / 2.0 * (1.0 + GAP_MARGIN);
    let mut out = Vec::new();
    let mut near: Vec<u32> = Vec::new();
    let mut parts: Vec<(f64, f64)> = Vec::new();
    let mut buf: Vec<(f64, f64)> = Vec::new();
    for l in half {
        let m = l.len();
        // polylines of far parts; `open` says whether the last one reaches its edge's end
        let mut runs: Vec<Vec<Pt>> = Vec::new();
        let mut open = false;
        let mut first_from_start = false;
        let mut all_far = true;
        for i in 0..m {
            let (a, b) = (l[i], l[(i + 1) % m]);
            index.far_parts(a, b, r, &mut near, &mut buf, &mut parts);
            if !(parts.len() == 1 && parts[0].0 == 0.0 && parts[0].1 == 1.0) {
                all_far = false;
            }
            // a part from the edge's start continues the run that reached the edge's end
            let mut joins = open;
            open = false;
            for &(lo, hi) in &parts {
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
        let levels = contour_levels(&r, 1.0, 1e-4, 100, &JobCtx::default()).unwrap();
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
        let levels = contour_levels(&r, 1.0, 1e-4, 100, &JobCtx::default()).unwrap();
        // radii 5.3, 4.3, .., 0.3: six rings
        assert_eq!(levels.len(), 6);
        assert!(levels.iter().all(|l| l.gaps.is_empty()));
    }
}
