//! The half-step boundary of a contour level computed only where it can matter.
//!
//! A point `p` of `∂H_k` (`H_k = Q_k ⊖ s/2`) is at `s/2` from its foot `x` on ring `k`, along the
//! inward normal `n`. Where ring `k + 1` covers `x` at exactly `s` (the offset of `x`'s element
//! reaches `x + s·n`), `p` lies `s/2` from ring `k + 1` and is no gap. So gaps have their feet
//! in the parts of ring `k` that ring `k + 1` does not cover: the trimmed ends at convex corners
//! and the elements that vanish. Ends trimmed by a shallow corner (turning below
//! [`SHALLOW_DEG`], trimmed no more than such a corner trims) leave a wedge thinner than the gap
//! margin and are skipped; every other uncovered piece is a *spot*. Every gap point lies within
//! `s/2` of a spot, so inside a box `B'` around the spots grown by more than `s/2`; and inside
//! `B'` the half-step boundary of `Q_k ∩ B` (with `B = B' ⊕ (s/2 + ε)`) is exactly `∂H_k`,
//! because the box edges are farther than `s/2` from `B'`. That small offset replaces the offset
//! of the whole level.

use super::clip::clip_region;
use super::elems::ElemTable;
use super::region::{offset_loop_flattened, resolve, Elem, Region};
use crate::document::FillRule;
use crate::geom::{BBox, Pt};

/// Corners turning less than this (degrees) trim their neighbours harmlessly.
const SHALLOW_DEG: f64 = 3.0;
/// A spot's box is grown by `s/2` and this many spacings (room for skipped shallow trims).
const SPOT_GROW_SPACING: f64 = 0.2;
/// The clip box is the spot box grown by `s/2` and this many spacings.
const CLIP_GROW_SPACING: f64 = 0.05;
/// Above this share of the level's bounding box the whole level is offset instead (the local
/// offsets' clipping then costs more than they save).
pub(crate) const MAX_BOX_SHARE: f64 = 0.3;
/// At most this many boxes per level; beyond, the whole level is offset.
const MAX_BOXES: usize = 64;

/// The pieces of `∂H_k` that can hold gaps, with their boxes, or `None` when the
/// clip boxes cover more than `max_share` of the level's bounding box (offsetting all of `Q_k`
/// is then cheaper; see [`MAX_BOX_SHARE`]).
///
/// `q` is `Q_k`, `ring_k` its flattened boundary (mm), `table` holds ring `k + 1`'s elements
/// for matches at one spacing.
pub(crate) fn half_step_near_spots(
    q: &Region,
    ring_k: &[Vec<Pt>],
    table: &ElemTable,
    spacing: f64,
    tol_mm: f64,
    max_share: f64,
) -> Option<HalfStepPieces> {
    let s_units = q.frame.len_units(spacing);
    let spots = spot_boxes(q, table, s_units);
    if spots.is_empty() {
        return Some(HalfStepPieces::default());
    }
    // boxes in mm
    let grow = spacing * (0.5 + SPOT_GROW_SPACING);
    let boxes = merge_boxes(
        spots
            .into_iter()
            .map(|b| {
                let (lo, hi) = (
                    q.frame.mm_of(b.min_x, b.min_y),
                    q.frame.mm_of(b.max_x, b.max_y),
                );
                grown(BBox::of(&[lo, hi]), grow)
            })
            .collect(),
    );
    let all = ring_k
        .iter()
        .map(|l| BBox::of(l))
        .fold(BBox::EMPTY, BBox::union);
    let clip_grow = spacing * (0.5 + CLIP_GROW_SPACING);
    let area: f64 = boxes.iter().map(|b| grown(*b, clip_grow).area()).sum();
    if boxes.len() > MAX_BOXES || area > max_share * all.area() {
        return None;
    }
    let mut out = Vec::new();
    for &inner in &boxes {
        let clip = grown(inner, clip_grow);
        let half_step = match clip_region(q, &q.frame.box_units(&clip)) {
            // one loop (the usual case): offset as a polyline, without a shape's indexes
            Some(mut loops) if loops.len() == 1 => loops
                .pop()
                .map(|l| offset_loop_flattened(l, spacing / 2.0, tol_mm, q.frame))
                .unwrap_or_default(),
            Some(loops) => Region::from_plines(loops, q.frame)
                .offset(spacing / 2.0)
                .flatten(tol_mm),
            None => polygon_clip(q, ring_k, &clip)
                .offset(spacing / 2.0)
                .flatten(tol_mm),
        };
        for l in half_step {
            clip_polyline(&l, &inner, &mut out);
        }
    }
    Some(HalfStepPieces { pieces: out, boxes })
}

/// The pieces of `∂H_k` near the spots and the boxes (mm) they lie in.
#[derive(Debug, Default)]
pub(crate) struct HalfStepPieces {
    /// (points in mm, closed).
    pub(crate) pieces: Vec<(Vec<Pt>, bool)>,
    pub(crate) boxes: Vec<BBox>,
}

/// `Q_k ∩ clip` from the flattened ring `k` (Sutherland–Hodgman and a fill-rule resolution): the
/// fallback when the exact clip fails.
fn polygon_clip(q: &Region, ring_k: &[Vec<Pt>], clip: &BBox) -> Region {
    let pieces: Vec<Vec<Pt>> = ring_k
        .iter()
        .filter(|l| overlaps(&BBox::of(l), clip))
        .map(|l| clip_loop(l, clip))
        .filter(|l| l.len() >= 3)
        .collect();
    Region::new(&resolve(&pieces, FillRule::NonZero), q.frame)
}

/// Bounding boxes (frame units) of the spots of `q`: the parts of its boundary that ring
/// `k + 1` does not cover at exactly one spacing, less the harmless shallow-corner trims.
fn spot_boxes(q: &Region, table: &ElemTable, s_units: f64) -> Vec<BBox> {
    let shallow = SHALLOW_DEG.to_radians();
    let mut cover: Vec<(f64, f64)> = Vec::new();
    let mut out = Vec::new();
    for elems in q.loop_elems() {
        let m = elems.len();
        for (i, e) in elems.iter().enumerate() {
            table.covered(e, &mut cover);
            let len = elem_len(e);
            if len <= 0.0 {
                continue;
            }
            let eps = 1e-3 * s_units / len;
            for (t0, t1) in complement(&mut cover, eps) {
                let piece = (t1 - t0) * len;
                let at_start = t0 <= eps;
                let at_end = t1 >= 1.0 - eps;
                // a shallow corner trims the end of each of its two elements by s · tan(θ/2)
                let harmless = |theta: f64| {
                    theta.abs() < shallow
                        && piece <= 1.5 * s_units * (theta.abs() / 2.0).tan() + 1e-3 * s_units
                };
                let benign = match (at_start, at_end) {
                    (true, false) => harmless(turn(&elems[(i + m - 1) % m], e)),
                    (false, true) => harmless(turn(e, &elems[(i + 1) % m])),
                    _ => false,
                };
                if !benign {
                    out.push(piece_box(e, t0, t1));
                }
            }
        }
    }
    out
}

/// The parts of 0..=1 not in the union of `cover`, ignoring gaps shorter than `eps`.
fn complement(cover: &mut [(f64, f64)], eps: f64) -> Vec<(f64, f64)> {
    cover.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out = Vec::new();
    let mut t = 0.0;
    for &(lo, hi) in cover.iter() {
        if lo > t + eps {
            out.push((t, lo));
        }
        t = t.max(hi);
    }
    if t < 1.0 - eps {
        out.push((t, 1.0));
    }
    out
}

fn elem_len(e: &Elem) -> f64 {
    match e {
        Elem::Line(a, b) => a.dist(*b),
        Elem::Arc(g) => g.radius * g.sweep.abs(),
    }
}

/// Unit tangent at the start (`end` false) or end of an element.
fn tangent(e: &Elem, end: bool) -> Pt {
    match e {
        Elem::Line(a, b) => {
            let d = b.minus(*a);
            d.scale(1.0 / d.norm().max(1e-300))
        }
        Elem::Arc(g) => {
            let ang = if end { g.start + g.sweep } else { g.start };
            let t = Pt::new(-ang.sin(), ang.cos());
            if g.sweep >= 0.0 {
                t
            } else {
                t.scale(-1.0)
            }
        }
    }
}

/// Signed turning angle from `a` into `b` (positive: left, a convex corner of the region).
fn turn(a: &Elem, b: &Elem) -> f64 {
    let (t1, t2) = (tangent(a, true), tangent(b, false));
    (t1.x * t2.y - t1.y * t2.x).atan2(t1.dot(t2))
}

/// Bounding box of the piece `t0..t1` of `e` (arcs: the ends and the axis extremes between).
fn piece_box(e: &Elem, t0: f64, t1: f64) -> BBox {
    let mut b = BBox::of(&[e.at(t0), e.at(t1)]);
    if let Elem::Arc(g) = e {
        let (a0, a1) = (g.start + t0 * g.sweep, g.start + t1 * g.sweep);
        let (lo, hi) = (a0.min(a1), a0.max(a1));
        let quarter = std::f64::consts::FRAC_PI_2;
        let mut k = (lo / quarter).ceil();
        while k * quarter <= hi {
            b.extend(g.point(k * quarter));
            k += 1.0;
        }
    }
    b
}

fn grown(b: BBox, d: f64) -> BBox {
    BBox {
        min_x: b.min_x - d,
        min_y: b.min_y - d,
        max_x: b.max_x + d,
        max_y: b.max_y + d,
    }
}

fn overlaps(a: &BBox, b: &BBox) -> bool {
    a.min_x <= b.max_x && b.min_x <= a.max_x && a.min_y <= b.max_y && b.min_y <= a.max_y
}

/// Merges overlapping or touching boxes until none overlap.
fn merge_boxes(mut boxes: Vec<BBox>) -> Vec<BBox> {
    loop {
        let mut merged: Vec<BBox> = Vec::with_capacity(boxes.len());
        let mut changed = false;
        for b in boxes {
            match merged.iter_mut().find(|m| overlaps(m, &b)) {
                Some(m) => {
                    *m = m.union(b);
                    changed = true;
                }
                None => merged.push(b),
            }
        }
        boxes = merged;
        if !changed {
            return boxes;
        }
    }
}

/// Sutherland–Hodgman: the closed loop `l` clipped to the box (may leave zero-width bridges
/// along the box edges; the fill-rule resolution removes them).
fn clip_loop(l: &[Pt], b: &BBox) -> Vec<Pt> {
    // the first pass keeps the vertical strip (both x edges at once), which drops most points
    let mut pts = clip_strip(
        l,
        b.min_x,
        b.max_x,
        |p| p.x,
        |p, q, v| {
            let t = (v - p.x) / (q.x - p.x);
            Pt::new(v, p.y + (q.y - p.y) * t)
        },
    );
    pts = clip_strip(
        &pts,
        b.min_y,
        b.max_y,
        |p| p.y,
        |p, q, v| {
            let t = (v - p.y) / (q.y - p.y);
            Pt::new(p.x + (q.x - p.x) * t, v)
        },
    );
    pts
}

/// One Sutherland–Hodgman pass against `lo ≤ c(p)` followed by one against `c(p) ≤ hi`.
fn clip_strip(
    l: &[Pt],
    lo: f64,
    hi: f64,
    c: impl Fn(&Pt) -> f64,
    cut: impl Fn(Pt, Pt, f64) -> Pt,
) -> Vec<Pt> {
    let mut out = Vec::new();
    for (v, keep_above) in [(lo, true), (hi, false)] {
        let src: Vec<Pt> = if keep_above {
            l.to_vec()
        } else {
            std::mem::take(&mut out)
        };
        let n = src.len();
        if n == 0 {
            return Vec::new();
        }
        let inside = |p: &Pt| if keep_above { c(p) >= v } else { c(p) <= v };
        let mut prev = src[n - 1];
        let mut prev_in = inside(&prev);
        for &p in &src {
            let p_in = inside(&p);
            if p_in != prev_in {
                out.push(cut(prev, p, v));
            }
            if p_in {
                out.push(p);
            }
            prev = p;
            prev_in = p_in;
        }
    }
    out
}

/// The parts of the closed loop `l` inside the box, into `out`: the loop itself (closed) when it
/// lies inside, else open polylines.
fn clip_polyline(l: &[Pt], b: &BBox, out: &mut Vec<(Vec<Pt>, bool)>) {
    let inside = |p: &Pt| b.contains_pt(*p, 0.0);
    let n = l.len();
    let Some(start) = (0..n).find(|&i| !inside(&l[i])) else {
        out.push((l.to_vec(), true));
        return;
    };
    let mut run: Vec<Pt> = Vec::new();
    for k in 0..n {
        let (p, q) = (l[(start + k) % n], l[(start + k + 1) % n]);
        match clip_segment(p, q, b) {
            Some((t0, t1)) => {
                let (a, c) = (p.plus(q.minus(p).scale(t0)), p.plus(q.minus(p).scale(t1)));
                if run.is_empty() || t0 > 0.0 {
                    if run.len() >= 2 {
                        out.push((std::mem::take(&mut run), false));
                    }
                    run = vec![a];
                }
                run.push(c);
                if t1 < 1.0 {
                    out.push((std::mem::take(&mut run), false));
                }
            }
            None => {
                if run.len() >= 2 {
                    out.push((std::mem::take(&mut run), false));
                }
                run.clear();
            }
        }
    }
    if run.len() >= 2 {
        out.push((run, false));
    }
}

/// Liang–Barsky: the parameter interval of the segment `p`–`q` inside the box.
fn clip_segment(p: Pt, q: Pt, b: &BBox) -> Option<(f64, f64)> {
    let d = q.minus(p);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (den, num) in [
        (-d.x, p.x - b.min_x),
        (d.x, b.max_x - p.x),
        (-d.y, p.y - b.min_y),
        (d.y, b.max_y - p.y),
    ] {
        if den == 0.0 {
            if num < 0.0 {
                return None;
            }
        } else {
            let t = num / den;
            if den < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    (t0 <= t1).then_some((t0, t1))
}
