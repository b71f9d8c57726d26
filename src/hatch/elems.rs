//! Matching the boundary elements of two offset levels: offsets move line segments parallel
//! and keep the centres of arcs, so an element of one level and its image in another are found
//! by hashing (direction and distance of lines, centres of arcs).

use super::region::{ArcGeom, Elem, Region};
use crate::geom::Pt;
use rustc_hash::FxHashMap as HashMap;

/// The boundary elements of ring `k + 1`, to recognise the elements of an outer boundary (the
/// half-step loop at `d = s/2`, or ring `k` at `d = s`) that lie exactly `d` from one of them: an
/// arc concentric with an arc of ring `k + 1` at radius difference `d` and within its angular
/// span, or a line segment parallel to one of ring `k + 1` at `d` and within its extent.
pub(crate) struct ElemTable {
    arcs: HashMap<(i64, i64), Vec<ArcGeom>>,
    /// Line segments by (direction angle, signed distance of the line from the origin).
    lines: HashMap<(i64, i64), Vec<LineKey>>,
    /// The distance `d`, frame units.
    dist_units: f64,
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
/// Radii or line distances that differ from `d` by less than this (frame units) are `d` apart.
const SAME_DIST_UNITS: f64 = 1e-4;
/// Directions closer than this (radians) are the same.
const SAME_ANGLE: f64 = 1e-9;
/// Slack at the element ends, as a fraction of `d` of length.
const END_SLACK: f64 = 1e-3;
/// Hash cells (much larger than the tolerances above, so a lookup usually probes one cell):
/// arc centres, frame units.
const ARC_CELL: f64 = 1.0;
/// Line directions, radians.
const LINE_CELL_ANGLE: f64 = 1e-6;
/// Line distances from the origin, frame units.
const LINE_CELL_DIST: f64 = 1.0;

impl ElemTable {
    /// The table of `next`'s elements for matches at `dist_units`.
    pub(crate) fn new(next: &Region, dist_units: f64) -> Self {
        let mut arcs: HashMap<(i64, i64), Vec<ArcGeom>> = HashMap::default();
        let mut lines: HashMap<(i64, i64), Vec<LineKey>> = HashMap::default();
        for &e in next.loop_elems().iter().flatten() {
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
            dist_units,
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

    /// True when all of `e` lies exactly `d` from ring `k + 1`.
    pub(crate) fn covers(&self, e: &Elem) -> bool {
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
                // the matching line of ring k + 1 lies d further to the left
                let d = h.dist + self.dist_units;
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

    /// The parameter intervals (in 0..=1 along `e`) of the parts of `e` that lie exactly `d`
    /// from ring `k + 1`, into `out` (unsorted, may overlap).
    pub(crate) fn covered(&self, e: &Elem, out: &mut Vec<(f64, f64)>) {
        out.clear();
        match e {
            Elem::Arc(a) => {
                let (c, t) = (a.center, SAME_POS_UNITS);
                for k in cells(
                    Self::arc_cell(Pt::new(c.x - t, c.y - t)),
                    Self::arc_cell(Pt::new(c.x + t, c.y + t)),
                ) {
                    for b in self.arcs.get(&k).into_iter().flatten() {
                        if self.concentric(b, a) {
                            arc_overlap(a, b, out);
                        }
                    }
                }
            }
            Elem::Line(p, q) => {
                let Some(h) = LineKey::of(*p, *q) else {
                    out.push((0.0, 1.0));
                    return;
                };
                let d = h.dist + self.dist_units;
                let (ta, td) = (SAME_ANGLE, SAME_DIST_UNITS);
                let len = h.hi - h.lo;
                for k in cells(
                    Self::line_cell(h.angle - ta, d - td),
                    Self::line_cell(h.angle + ta, d + td),
                ) {
                    for b in self.lines.get(&k).into_iter().flatten() {
                        if (b.angle - h.angle).abs() <= SAME_ANGLE
                            && (b.dist - d).abs() <= SAME_DIST_UNITS
                        {
                            let (lo, hi) = (h.lo.max(b.lo), h.hi.min(b.hi));
                            if lo < hi {
                                out.push(((lo - h.lo) / len, (hi - h.lo) / len));
                            }
                        }
                    }
                }
            }
        }
    }

    /// Same centre, radius difference `d`, same orientation.
    fn concentric(&self, b: &ArcGeom, a: &ArcGeom) -> bool {
        b.center.dist2(a.center) <= SAME_POS_UNITS * SAME_POS_UNITS
            && ((b.radius - a.radius).abs() - self.dist_units).abs() <= SAME_DIST_UNITS
            && (a.sweep > 0.0) == (b.sweep > 0.0)
    }

    fn line_covers(&self, b: &LineKey, h: &LineKey) -> bool {
        let slack = END_SLACK * self.dist_units;
        (b.angle - h.angle).abs() <= SAME_ANGLE
            && (b.dist - h.dist - self.dist_units).abs() <= SAME_DIST_UNITS
            && h.lo >= b.lo - slack
            && h.hi <= b.hi + slack
    }

    fn arc_covers(&self, b: &ArcGeom, a: &ArcGeom) -> bool {
        if !self.concentric(b, a) {
            return false;
        }
        let ((a0, al), (b0, bl)) = (ccw_span(a), ccw_span(b));
        let slack = END_SLACK * self.dist_units / b.radius.max(a.radius);
        let d = (a0 - b0 + slack).rem_euclid(std::f64::consts::TAU) - slack;
        d + al <= bl + slack
    }
}

/// The cells from `lo` to `hi` (inclusive; usually one).
fn cells(lo: (i64, i64), hi: (i64, i64)) -> impl Iterator<Item = (i64, i64)> {
    (lo.0..=hi.0).flat_map(move |x| (lo.1..=hi.1).map(move |y| (x, y)))
}

/// An arc's span counter-clockwise: (start angle, length).
fn ccw_span(g: &ArcGeom) -> (f64, f64) {
    if g.sweep >= 0.0 {
        (g.start, g.sweep)
    } else {
        (g.start + g.sweep, -g.sweep)
    }
}

/// The parameter intervals (along `a`, 0..=1) where the concentric arc `b` spans the same
/// angles, into `out`.
fn arc_overlap(a: &ArcGeom, b: &ArcGeom, out: &mut Vec<(f64, f64)>) {
    let tau = std::f64::consts::TAU;
    let ((a0, al), (b0, bl)) = (ccw_span(a), ccw_span(b));
    if al <= 0.0 {
        out.push((0.0, 1.0));
        return;
    }
    let d = (b0 - a0).rem_euclid(tau);
    for start in [d, d - tau] {
        let (lo, hi) = (start.max(0.0), (start + bl).min(al));
        if lo < hi {
            // counter-clockwise coordinate → parameter along the arc's own direction
            let (t0, t1) = (lo / al, hi / al);
            out.push(if a.sweep >= 0.0 {
                (t0, t1)
            } else {
                (1.0 - t1, 1.0 - t0)
            });
        }
    }
}
