//! A region clipped to an axis-aligned box, exactly: the boundary elements (lines and arcs) inside
//! the box, joined along the box edges into clean loops.
//!
//! Each loop of the region is cut where it crosses the box boundary; the pieces inside run from
//! an entry point to an exit point on the box. The region lies left of every loop, so the clipped
//! boundary leaves a piece at its exit and follows the box boundary counter-clockwise to the next
//! crossing, which is the entry of the next piece. Loops without crossings are kept whole when
//! inside the box, and the box itself is a loop when it lies inside the region without crossing
//! its boundary. Only the elements whose (approximate) boxes meet the clip box are looked at.

use super::region::{Elem, Region};
use crate::geom::{BBox, Pt};
use cavalier_contours::polyline::{PlineSource, PlineSourceMut, PlineVertex, Polyline};
use std::f64::consts::TAU;

/// Relative distance (to the box size) within which a vertex counts as on the box boundary; the
/// box is then grown a little and the clip retried.
const ON_EDGE_REL: f64 = 1e-9;
/// Retries with a grown box before giving up.
const MAX_NUDGES: usize = 4;

/// The part of `q` inside `b` (frame units) as closed polylines (region on their left), or
/// `None` when the crossings do not pair up (the caller then clips another way).
pub(crate) fn clip_region(q: &Region, b: &BBox) -> Option<Vec<Polyline<f64>>> {
    let mut b = *b;
    for _ in 0..MAX_NUDGES {
        match clip_once(q, &b) {
            Clip::Done(loops) => return Some(loops),
            Clip::Failed => return None,
            Clip::OnEdge => {
                let d = 1e2 * ON_EDGE_REL * (b.width() + b.height()) + 1e-12;
                b = BBox {
                    min_x: b.min_x - d,
                    min_y: b.min_y - 0.7 * d,
                    max_x: b.max_x + 0.9 * d,
                    max_y: b.max_y + 1.1 * d,
                };
            }
        }
    }
    None
}

enum Clip {
    Done(Vec<Polyline<f64>>),
    /// A vertex lies on the box boundary.
    OnEdge,
    Failed,
}

/// An inside piece of a loop: from an entry to an exit on the box boundary.
struct Piece {
    /// Vertices (the last one is the exit point, with bulge 0).
    verts: Vec<PlineVertex<f64>>,
    entry: f64,
    exit: f64,
}

fn clip_once(q: &Region, b: &BBox) -> Clip {
    let eps = ON_EDGE_REL * (b.width() + b.height());
    let mut loops: Vec<Polyline<f64>> = Vec::new();
    let mut pieces: Vec<Piece> = Vec::new();
    let mut any_crossing = false;
    let all = q.shape.ccw_plines.iter().chain(q.shape.cw_plines.iter());
    for (ip, elems) in all.zip(q.loop_elems()) {
        let pl = &ip.polyline;
        let n = pl.vertex_count();
        let Some(lb) = ip.spatial_index.bounds() else {
            continue;
        };
        if lb.max_x < b.min_x || lb.min_x > b.max_x || lb.max_y < b.min_y || lb.min_y > b.max_y {
            continue;
        }
        let mut idx =
            ip.spatial_index
                .query(b.min_x - eps, b.min_y - eps, b.max_x + eps, b.max_y + eps);
        if idx.is_empty() {
            continue;
        }
        idx.sort_unstable();
        for &i in &idx {
            let v = pl.at(i);
            if near_edge(v.x, v.y, b, eps) {
                return Clip::OnEdge;
            }
        }
        let inside_box =
            lb.min_x > b.min_x && lb.max_x < b.max_x && lb.min_y > b.min_y && lb.max_y < b.max_y;
        if inside_box {
            loops.push(pl.clone());
            continue;
        }
        match loop_pieces(elems, &idx, b) {
            Some(mut p) if !p.is_empty() => {
                any_crossing = true;
                pieces.append(&mut p);
            }
            Some(_) => {
                // no crossing: the loop is inside the box only if a vertex is
                if idx.len() == n && b.contains_pt(pt(pl.at(0)), 0.0) {
                    loops.push(pl.clone());
                }
            }
            None => return Clip::Failed,
        }
    }
    if !any_crossing {
        if box_inside(q, b) {
            loops.push(box_loop(b));
        }
        return Clip::Done(loops);
    }
    match join_pieces(pieces, b) {
        Some(mut l) => {
            loops.append(&mut l);
            Clip::Done(loops)
        }
        None => Clip::Failed,
    }
}

fn pt(v: PlineVertex<f64>) -> Pt {
    Pt::new(v.x, v.y)
}

fn near_edge(x: f64, y: f64, b: &BBox, eps: f64) -> bool {
    let in_x = x >= b.min_x - eps && x <= b.max_x + eps;
    let in_y = y >= b.min_y - eps && y <= b.max_y + eps;
    (in_y && ((x - b.min_x).abs() <= eps || (x - b.max_x).abs() <= eps))
        || (in_x && ((y - b.min_y).abs() <= eps || (y - b.max_y).abs() <= eps))
}

/// True when the box (which meets no boundary) lies inside the region.
fn box_inside(q: &Region, b: &BBox) -> bool {
    let c = cavalier_contours::core::math::Vector2::new(b.min_x, b.min_y);
    let w: i32 = q
        .shape
        .ccw_plines
        .iter()
        .chain(q.shape.cw_plines.iter())
        .map(|p| p.polyline.winding_number(c))
        .sum();
    w > 0
}

fn box_loop(b: &BBox) -> Polyline<f64> {
    let mut p = Polyline::new_closed();
    for (x, y) in [
        (b.min_x, b.min_y),
        (b.max_x, b.min_y),
        (b.max_x, b.max_y),
        (b.min_x, b.max_y),
    ] {
        p.add(x, y, 0.0);
    }
    p
}

/// Bulge of the piece `t0..t1` of an element.
fn piece_bulge(e: &Elem, t0: f64, t1: f64) -> f64 {
    match e {
        Elem::Line(..) => 0.0,
        Elem::Arc(g) => ((t1 - t0) * g.sweep / 4.0).tan(),
    }
}

/// Parameters in (0, 1), sorted, where element `e` meets the lines of the box edges.
fn box_cuts(e: &Elem, b: &BBox, out: &mut Vec<f64>) {
    out.clear();
    match e {
        Elem::Line(p, q) => {
            for (c, o, d) in [
                (b.min_x, p.x, q.x - p.x),
                (b.max_x, p.x, q.x - p.x),
                (b.min_y, p.y, q.y - p.y),
                (b.max_y, p.y, q.y - p.y),
            ] {
                if d != 0.0 {
                    out.push((c - o) / d);
                }
            }
        }
        Elem::Arc(g) => {
            let mut add = |ang: f64| {
                // parameter of `ang` along the sweep
                let rel = if g.sweep >= 0.0 {
                    (ang - g.start).rem_euclid(TAU)
                } else {
                    (g.start - ang).rem_euclid(TAU)
                };
                out.push(rel / g.sweep.abs());
            };
            for c in [b.min_x, b.max_x] {
                let u = (c - g.center.x) / g.radius;
                if u.abs() < 1.0 {
                    let a = u.acos();
                    add(a);
                    add(-a);
                }
            }
            for c in [b.min_y, b.max_y] {
                let u = (c - g.center.y) / g.radius;
                if u.abs() < 1.0 {
                    let a = u.asin();
                    add(a);
                    add(std::f64::consts::PI - a);
                }
            }
        }
    }
    out.retain(|t| *t > 1e-12 && *t < 1.0 - 1e-12);
    out.sort_by(f64::total_cmp);
    out.dedup();
}

fn inside(b: &BBox, p: Pt) -> bool {
    let (x, y) = (p.x, p.y);
    x > b.min_x && x < b.max_x && y > b.min_y && y < b.max_y
}

/// Position of a boundary point along the box boundary, counter-clockwise from the lower left
/// corner: 0..1 bottom, 1..2 right, 2..3 top, 3..4 left.
fn perimeter(b: &BBox, (x, y): (f64, f64)) -> f64 {
    let (w, h) = (b.width().max(1e-300), b.height().max(1e-300));
    let d = [
        (y - b.min_y).abs(),
        (x - b.max_x).abs(),
        (y - b.max_y).abs(),
        (x - b.min_x).abs(),
    ];
    let mut e = 0;
    for k in 1..4 {
        if d[k] < d[e] {
            e = k;
        }
    }
    let f = match e {
        0 => (x - b.min_x) / w,
        1 => (y - b.min_y) / h,
        2 => (b.max_x - x) / w,
        _ => (b.max_y - y) / h,
    };
    e as f64 + f.clamp(0.0, 1.0)
}

/// The point at perimeter position `u`.
fn perimeter_point(b: &BBox, u: f64) -> (f64, f64) {
    let (e, f) = (u.floor() as i64 % 4, u - u.floor());
    match e {
        0 => (b.min_x + f * b.width(), b.min_y),
        1 => (b.max_x, b.min_y + f * b.height()),
        2 => (b.max_x - f * b.width(), b.max_y),
        _ => (b.min_x, b.max_y - f * b.height()),
    }
}

/// The inside pieces of a loop of elements `elems`, walking those in `idx` (sorted; the others lie outside
/// the box). `None` when the loop's pieces are inconsistent.
fn loop_pieces(elems: &[Elem], idx: &[usize], b: &BBox) -> Option<Vec<Piece>> {
    let n = elems.len();
    let mut cuts = Vec::new();
    // open piece: vertices so far, entry position (None: started at the walk's start while
    // inside, to be joined with the walk's last piece)
    let mut pieces: Vec<Piece> = Vec::new();
    let mut cur: Option<(Vec<PlineVertex<f64>>, Option<f64>)> = None;
    let mut head: Option<Vec<PlineVertex<f64>>> = None;
    let mut prev: Option<usize> = None;
    for &i in idx {
        if let Some(p) = prev {
            // elements skipped between p and i lie outside the box: an open piece must have
            // ended before them
            if i != p + 1 && cur.is_some() {
                return None;
            }
        }
        prev = Some(i);
        let seg = elems[i];
        box_cuts(&seg, b, &mut cuts);
        let mut t0 = 0.0;
        for &t1 in cuts.iter().chain(std::iter::once(&1.0)) {
            let mid = seg.at(0.5 * (t0 + t1));
            let is_in = inside(b, mid);
            match (&mut cur, is_in) {
                (Some((verts, _)), true) => {
                    let Pt { x, y } = seg.at(t0);
                    verts.push(PlineVertex::new(x, y, piece_bulge(&seg, t0, t1)));
                }
                (Some(_), false) => {
                    // exit at t0
                    let Pt { x, y } = seg.at(t0);
                    let (mut verts, entry) = cur.take()?;
                    verts.push(PlineVertex::new(x, y, 0.0));
                    let exit = perimeter(b, (x, y));
                    match entry {
                        Some(entry) => pieces.push(Piece { verts, entry, exit }),
                        None => {
                            // the walk started inside: this piece continues the last one
                            head = Some(verts);
                            pieces.push(Piece {
                                verts: Vec::new(),
                                entry: f64::NAN,
                                exit,
                            });
                        }
                    }
                }
                (None, true) => {
                    let Pt { x, y } = seg.at(t0);
                    let entry = if t0 == 0.0 && i == idx[0] && pieces.is_empty() {
                        // the walk starts inside (the loop wraps around to here)
                        None
                    } else if t0 == 0.0 {
                        // an element start inside the box without a crossing before it
                        return None;
                    } else {
                        Some(perimeter(b, (x, y)))
                    };
                    cur = Some((
                        vec![PlineVertex::new(x, y, piece_bulge(&seg, t0, t1))],
                        entry,
                    ));
                }
                (None, false) => {}
            }
            t0 = t1;
        }
    }
    match (cur, head) {
        (None, None) => Some(pieces),
        (Some((mut verts, Some(entry))), Some(h)) => {
            // the last piece runs on into the first one (through the loop's wrap)
            if idx.first() != Some(&0) || idx.last() != Some(&(n - 1)) {
                return None;
            }
            verts.extend(h);
            let k = pieces.iter().position(|p| p.entry.is_nan())?;
            pieces[k].verts = verts;
            pieces[k].entry = entry;
            Some(pieces)
        }
        (Some((_, None)), None) => {
            // inside all along (no crossing): no pieces
            Some(Vec::new())
        }
        _ => None,
    }
}

/// Joins the pieces along the box boundary into closed loops.
fn join_pieces(pieces: Vec<Piece>, b: &BBox) -> Option<Vec<Polyline<f64>>> {
    let m = pieces.len();
    // crossing events by perimeter position: (position, piece, is_entry)
    let mut ev: Vec<(f64, usize, bool)> = Vec::with_capacity(2 * m);
    for (k, p) in pieces.iter().enumerate() {
        ev.push((p.entry, k, true));
        ev.push((p.exit, k, false));
    }
    ev.sort_by(|a, c| a.0.total_cmp(&c.0));
    // the entry that follows each exit counter-clockwise
    let mut next = vec![usize::MAX; m];
    for (j, &(_, k, is_entry)) in ev.iter().enumerate() {
        if !is_entry {
            let (_, k2, e2) = ev[(j + 1) % ev.len()];
            if !e2 {
                return None;
            }
            next[k] = k2;
        }
    }
    let mut used = vec![false; m];
    let mut out = Vec::new();
    for start in 0..m {
        if used[start] {
            continue;
        }
        let mut pl = Polyline::new_closed();
        let mut k = start;
        loop {
            if used[k] {
                return None;
            }
            used[k] = true;
            let p = &pieces[k];
            for v in &p.verts {
                pl.add(v.x, v.y, v.bulge);
            }
            let k2 = next[k];
            if k2 == usize::MAX {
                return None;
            }
            // box corners passed from this exit to the next entry
            let (u0, mut u1) = (p.exit, pieces[k2].entry);
            if u1 < u0 {
                u1 += 4.0;
            }
            let mut c = u0.floor() + 1.0;
            while c < u1 {
                let (x, y) = perimeter_point(b, c);
                pl.add(x, y, 0.0);
                c += 1.0;
            }
            k = k2;
            if k == start {
                break;
            }
        }
        out.push(pl);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::super::region::{resolve, Frame};
    use super::*;
    use crate::document::FillRule;
    use crate::geom::Pt;

    fn area(loops: &[Polyline<f64>]) -> f64 {
        loops.iter().map(|p| p.area()).sum()
    }

    /// The region of `c` in a frame of 1 unit per mm centred on its box.
    fn region(c: &[Vec<Pt>]) -> Region {
        let loops = resolve(c, FillRule::EvenOdd);
        Region::new(&loops, Frame::new(&loops, 64.0))
    }

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Pt> {
        vec![
            Pt::new(x0, y0),
            Pt::new(x1, y0),
            Pt::new(x1, y1),
            Pt::new(x0, y1),
        ]
    }

    fn bbox(x0: f64, y0: f64, x1: f64, y1: f64) -> BBox {
        BBox {
            min_x: x0,
            min_y: y0,
            max_x: x1,
            max_y: y1,
        }
    }

    #[test]
    fn square_with_hole_clipped_by_boxes() {
        // units: the square is [-5, 5]², the hole [-1, 1]²
        let r = region(&[rect(0.0, 0.0, 10.0, 10.0), rect(4.0, 4.0, 6.0, 6.0)]);
        let cases = [
            ((-7.0, -7.0, 7.0, 7.0), 96.0),
            ((-7.0, -7.0, 0.0, 0.0), 24.0),
            // inside the hole, inside the region: no crossings
            ((-0.5, -0.5, 0.5, 0.5), 0.0),
            ((2.0, 2.0, 3.0, 3.0), 1.0),
            ((-3.0, -0.5, -0.5, 0.5), 2.0),
            ((-6.0, 4.0, 6.0, 8.0), 10.0),
            ((-2.0, -2.0, 0.0, 2.0), 6.0),
            ((-6.0, -0.5, 0.5, 0.5), 4.0),
            // a box edge through the hole's edge (nudged)
            ((-1.0, -3.0, 3.0, 3.0), 20.0),
            // beside the region
            ((6.0, 6.0, 8.0, 8.0), 0.0),
        ];
        for ((x0, y0, x1, y1), want) in cases {
            let b = bbox(x0, y0, x1, y1);
            let got = area(&clip_region(&r, &b).unwrap());
            // (1e-4: the nudged box)
            assert!((got - want).abs() < 1e-4, "box {b:?}: {got} vs {want}");
        }
    }

    #[test]
    fn arcs_are_clipped_exactly() {
        // offset by 1 mm: the outer square becomes [-4, 4]², the hole a rounded square (arcs of
        // radius 1 around (±1, ±1)); area 64 - (12 + π)
        let r = region(&[rect(0.0, 0.0, 10.0, 10.0), rect(4.0, 4.0, 6.0, 6.0)]).offset(1.0);
        let pi = std::f64::consts::PI;
        let whole = 52.0 - pi;
        // below y = -1.5: 8 × 2.5 less the hole's cap (a 2 × 0.5 strip and two circle segments)
        let cap = 1.0 + 2.0 * (pi / 6.0 - 3f64.sqrt() / 8.0);
        for (b, want) in [
            (bbox(-7.0, -7.0, 7.0, 7.0), whole),
            (bbox(-7.0, -7.0, 0.0, 0.0), whole / 4.0),
            (bbox(-7.0, -7.0, 7.0, -1.5), 20.0 - cap),
            (bbox(-1.5, -7.0, 7.0, 7.0), whole - (20.0 - cap)),
        ] {
            let got = area(&clip_region(&r, &b).unwrap());
            assert!((got - want).abs() < 1e-9, "box {b:?}: {got} vs {want}");
        }
    }

    /// On the contest's nested contours offset (arcs at every reflex corner), the exact clip has
    /// the area of the flattened boundary clipped with a polygon overlay.
    #[test]
    fn clip_matches_a_polygon_clip_on_the_contest_shape() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/data/hatch/attachment2_graph2.csv");
        let c = crate::bench::hatch::read_contours(&path).unwrap();
        let loops = resolve(&c, FillRule::EvenOdd);
        let frame = Frame::new(&loops, 1.0);
        let q = Region::new(&loops, frame).offset(1.5);
        let flat = q.flatten(1e-6);
        let mut rng = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        let all = BBox::of(&flat.iter().flatten().copied().collect::<Vec<_>>());
        for _ in 0..200 {
            let (w, h) = (
                next() * 0.3 * all.width(),
                next() * 0.3 * (all.max_y - all.min_y),
            );
            let x0 = all.min_x - 2.0 + next() * (all.width() + 4.0 - w);
            let y0 = all.min_y - 2.0 + next() * (all.max_y - all.min_y + 4.0 - h);
            let b_mm = bbox(x0, y0, x0 + w, y0 + h);
            let (lo, hi) = (
                (x0 - frame_origin(&frame).x) * 64.0,
                (y0 - frame_origin(&frame).y) * 64.0,
            );
            let b = bbox(lo, hi, lo + w * 64.0, hi + h * 64.0);
            let got = area(&clip_region(&q, &b).unwrap()) / (64.0 * 64.0);
            let want = polygon_clip_area(&flat, &b_mm);
            assert!(
                (got - want).abs() <= 1e-4 * (1.0 + want.abs()),
                "box {b_mm:?}: {got} vs {want}"
            );
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig {
            cases: std::env::var("HATCH_PROPTEST_CASES")
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(256),
            failure_persistence: None,
            ..Default::default()
        })]
        /// Random stars with star holes, offset (arcs at the reflex corners), clipped by random
        /// boxes: the exact clip never fails and has the polygon clip's area.
        #[test]
        fn random_regions_clip_like_polygons(
            outer in proptest::collection::vec(6.0f64..12.0, 5..30),
            holes in proptest::collection::vec(
                ((-4.0f64..4.0, -4.0f64..4.0), proptest::collection::vec(1.0f64..3.0, 3..10)),
                0..3,
            ),
            d in 0.0f64..2.0,
            (bx, by, bw, bh) in (-14.0f64..14.0, -14.0f64..14.0, 0.5f64..12.0, 0.5f64..12.0),
        ) {
            let mut c = vec![crate::geom::star_polygon(Pt::new(0.0, 0.0), &outer, 0.0)];
            for ((x, y), r) in holes {
                c.push(crate::geom::star_polygon(Pt::new(x, y), &r, 0.3));
            }
            let loops = resolve(&c, FillRule::EvenOdd);
            let frame = Frame::new(&loops, 1.0);
            let q = Region::new(&loops, frame).offset(d);
            let flat = q.flatten(1e-7);
            let b_mm = bbox(bx, by, bx + bw, by + bh);
            let got = clip_region(&q, &frame.box_units(&b_mm));
            proptest::prop_assert!(got.is_some(), "clip failed for {b_mm:?}");
            let got = area(&got.unwrap_or_default()) / (64.0 * 64.0);
            let want = polygon_clip_area(&flat, &b_mm);
            proptest::prop_assert!(
                (got - want).abs() <= 1e-5 * (1.0 + want.abs()),
                "box {b_mm:?}: {got} vs {want}"
            );
        }
    }

    fn frame_origin(f: &Frame) -> Pt {
        f.mm_of(0.0, 0.0)
    }

    /// Area of the flattened loops clipped to the box, by i_overlay.
    fn polygon_clip_area(loops: &[Vec<Pt>], b: &BBox) -> f64 {
        use i_overlay::core::fill_rule::FillRule as R;
        use i_overlay::core::overlay_rule::OverlayRule;
        use i_overlay::float::single::SingleFloatOverlay;
        let subj: Vec<Vec<[f64; 2]>> = loops
            .iter()
            .map(|l| l.iter().map(|p| [p.x, p.y]).collect())
            .collect();
        let clip = vec![vec![
            [b.min_x, b.min_y],
            [b.max_x, b.min_y],
            [b.max_x, b.max_y],
            [b.min_x, b.max_y],
        ]];
        let shapes = subj.overlay(&clip, OverlayRule::Intersect, R::NonZero);
        shapes
            .iter()
            .flatten()
            .map(|c| {
                let n = c.len();
                (0..n)
                    .map(|i| {
                        let (p, q) = (c[i], c[(i + 1) % n]);
                        p[0] * q[1] - q[0] * p[1]
                    })
                    .sum::<f64>()
                    / 2.0
            })
            .sum()
    }
}
