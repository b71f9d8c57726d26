//! Clipping of imported outlines (SVG `clip-path`, and masks that are clips): a clip region is a
//! set of resolved loops in mm (i_overlay: outer loops and holes, never overlapping); strokes
//! are cut exactly where they cross its boundary, fills are intersected with it.

use crate::geom::Pt;
use i_overlay::core::fill_rule::FillRule as OverlayFill;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::simplify::SimplifyShape;
use i_overlay::float::single::SingleFloatOverlay;

/// A point this close to the region's boundary (mm) counts as inside: a stroke running along
/// the clip edge is kept, as a renderer keeps it.
const ON_EDGE_MM: f64 = 1e-7;
/// Pieces of a segment shorter than this fraction of it are not classified on their own.
const MIN_PIECE_T: f64 = 1e-12;

/// How overlapping contours fill (SVG's `fill-rule`, `clip-rule`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    /// Non-zero winding.
    NonZero,
    /// Even-odd.
    EvenOdd,
}

impl Rule {
    fn overlay(self) -> OverlayFill {
        match self {
            Rule::NonZero => OverlayFill::NonZero,
            Rule::EvenOdd => OverlayFill::EvenOdd,
        }
    }
}

/// A clip region: loops that do not overlap (outer boundaries and holes), in mm.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Region {
    loops: Vec<Vec<Pt>>,
}

fn to_xy(loops: &[Vec<Pt>]) -> Vec<Vec<[f64; 2]>> {
    loops
        .iter()
        .filter(|l| l.len() >= 3)
        .map(|l| l.iter().map(|p| [p.x, p.y]).collect())
        .collect()
}

fn from_shapes(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Vec<Vec<Pt>> {
    shapes
        .into_iter()
        .flatten()
        .filter(|c| c.len() >= 3)
        .map(|c| c.into_iter().map(|[x, y]| Pt::new(x, y)).collect())
        .collect()
}

impl Region {
    /// The region filled by closed contours under `rule`.
    pub fn filled(contours: &[Vec<Pt>], rule: Rule) -> Region {
        let xy = to_xy(contours);
        if xy.is_empty() {
            return Region::default();
        }
        Region {
            loops: from_shapes(xy.simplify_shape(rule.overlay())),
        }
    }

    /// The quadrilateral with these corners in order (the image of a rectangle).
    pub fn quad(corners: [Pt; 4]) -> Region {
        Region::filled(&[corners.to_vec()], Rule::NonZero)
    }

    /// True when nothing is inside.
    pub fn is_empty(&self) -> bool {
        self.loops.is_empty()
    }

    /// The loops of the region.
    #[cfg(test)]
    pub fn loops(&self) -> &[Vec<Pt>] {
        &self.loops
    }

    fn combine(&self, other: &Region, rule: OverlayRule) -> Region {
        let (a, b) = (to_xy(&self.loops), to_xy(&other.loops));
        Region {
            // resolved loops have consistent orientations: non-zero combines them exactly
            loops: from_shapes(a.overlay(&b, rule, OverlayFill::NonZero)),
        }
    }

    /// Points in both regions.
    pub fn intersect(&self, other: &Region) -> Region {
        if self.is_empty() || other.is_empty() {
            return Region::default();
        }
        self.combine(other, OverlayRule::Intersect)
    }

    /// Points in either region.
    pub fn union(&self, other: &Region) -> Region {
        if self.is_empty() {
            return other.clone();
        }
        if other.is_empty() {
            return self.clone();
        }
        self.combine(other, OverlayRule::Union)
    }

    /// Even-odd ray test, with points on the boundary inside.
    pub fn contains(&self, p: Pt) -> bool {
        let mut inside = false;
        let mut near = f64::INFINITY;
        for l in &self.loops {
            let n = l.len();
            for i in 0..n {
                let (a, b) = (l[i], l[(i + 1) % n]);
                near = near.min(crate::geom::point_segment_dist(p, a, b));
                if (a.y > p.y) != (b.y > p.y) {
                    let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
                    if x > p.x {
                        inside = !inside;
                    }
                }
            }
        }
        inside || near <= ON_EDGE_MM
    }

    /// Parameters `t ∈ (0, 1)` where the segment `a → b` crosses or touches the boundary.
    fn crossings(&self, a: Pt, b: Pt, out: &mut Vec<f64>) {
        let (lo_x, hi_x) = (a.x.min(b.x), a.x.max(b.x));
        let (lo_y, hi_y) = (a.y.min(b.y), a.y.max(b.y));
        let r = Pt::new(b.x - a.x, b.y - a.y);
        for l in &self.loops {
            let n = l.len();
            for i in 0..n {
                let (c, d) = (l[i], l[(i + 1) % n]);
                if c.x.max(d.x) < lo_x
                    || c.x.min(d.x) > hi_x
                    || c.y.max(d.y) < lo_y
                    || c.y.min(d.y) > hi_y
                {
                    continue;
                }
                let s = Pt::new(d.x - c.x, d.y - c.y);
                let denom = r.x * s.y - r.y * s.x;
                if denom.abs() <= f64::EPSILON * (r.norm() * s.norm()) {
                    // parallel: overlapping runs are classified by their midpoints
                    continue;
                }
                let q = Pt::new(c.x - a.x, c.y - a.y);
                let t = (q.x * s.y - q.y * s.x) / denom;
                let u = (q.x * r.y - q.y * r.x) / denom;
                if (0.0..=1.0).contains(&u) && t > 0.0 && t < 1.0 {
                    out.push(t);
                }
            }
        }
    }

    /// The parts of a polyline inside the region, cut exactly at the boundary, in order. A
    /// closed polyline is cut as a ring: a piece running through its first vertex stays one
    /// piece. `None` when all of it is inside (keep it as it is).
    pub fn clip_stroke(&self, pts: &[Pt], closed: bool) -> Option<Vec<Vec<Pt>>> {
        let n = pts.len();
        if n < 2 {
            return Some(Vec::new());
        }
        let segs = if closed { n } else { n - 1 };
        let mut pieces: Vec<Vec<Pt>> = Vec::new();
        let mut cur: Vec<Pt> = Vec::new();
        let mut cut = false;
        let mut ts = Vec::new();
        for i in 0..segs {
            let (a, b) = (pts[i], pts[(i + 1) % n]);
            ts.clear();
            ts.push(0.0);
            self.crossings(a, b, &mut ts);
            ts.push(1.0);
            ts.sort_by(f64::total_cmp);
            ts.dedup_by(|x, y| (*x - *y).abs() < MIN_PIECE_T);
            let at = |t: f64| Pt::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t);
            for w in ts.windows(2) {
                let (t0, t1) = (w[0], w[1]);
                let inside = self.contains(at((t0 + t1) / 2.0));
                if inside {
                    if cur.is_empty() {
                        cur.push(at(t0));
                    }
                    cur.push(at(t1));
                } else {
                    cut = true;
                    if cur.len() > 1 {
                        pieces.push(std::mem::take(&mut cur));
                    }
                    cur.clear();
                }
            }
        }
        if !cut {
            return None;
        }
        if cur.len() > 1 {
            // a ring whose first vertex is inside: its last piece runs on into its first
            if closed && pieces.first().and_then(|p| p.first()) == Some(&pts[0]) {
                let first = pieces.remove(0);
                cur.extend(first.into_iter().skip(1));
            }
            pieces.push(cur);
        }
        Some(pieces)
    }

    /// The filled area of closed contours (under `rule`) inside the region, as loops. `None`
    /// when the contours lie inside the region (keep them as they are).
    pub fn clip_fill(&self, contours: &[Vec<Pt>], rule: Rule) -> Option<Vec<Vec<Pt>>> {
        let all_inside = contours.iter().all(|c| {
            self.clip_stroke(c, true).is_none() && c.first().is_none_or(|&p| self.contains(p))
        });
        if all_inside {
            return None;
        }
        let subject = to_xy(contours);
        let clip = to_xy(&self.loops);
        if subject.is_empty() || clip.is_empty() {
            return Some(Vec::new());
        }
        // the region's loops are resolved, so the subject's rule serves both
        Some(from_shapes(subject.overlay(
            &clip,
            OverlayRule::Intersect,
            rule.overlay(),
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rect(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<Pt> {
        vec![
            Pt::new(x0, y0),
            Pt::new(x1, y0),
            Pt::new(x1, y1),
            Pt::new(x0, y1),
        ]
    }

    fn length(p: &[Pt]) -> f64 {
        p.windows(2).map(|w| w[0].dist(w[1])).sum()
    }

    fn area(l: &[Pt]) -> f64 {
        use geo::Area;
        let ring: geo::LineString<f64> = l.iter().map(|p| geo::coord! { x: p.x, y: p.y }).collect();
        geo::Polygon::new(ring, vec![]).unsigned_area()
    }

    #[test]
    fn strokes_are_cut_exactly_at_the_boundary() {
        let clip = Region::filled(&[rect(0.0, 0.0, 10.0, 10.0)], Rule::NonZero);
        // a line crossing the clip: the part from x = 0 to 10
        let cut = clip
            .clip_stroke(&[Pt::new(-5.0, 5.0), Pt::new(15.0, 5.0)], false)
            .unwrap();
        assert_eq!(cut, vec![vec![Pt::new(0.0, 5.0), Pt::new(10.0, 5.0)]]);
        // a square ring half inside, starting inside: one piece through its first vertex
        let ring = rect(5.0, 2.0, 15.0, 8.0);
        let cut = clip.clip_stroke(&ring, true).unwrap();
        assert_eq!(cut.len(), 1);
        assert!((length(&cut[0]) - (5.0 + 6.0 + 5.0)).abs() < 1e-12);
        assert_eq!(cut[0][0], Pt::new(10.0, 8.0));
        assert_eq!(*cut[0].last().unwrap(), Pt::new(10.0, 2.0));
        // inside (also along the boundary): kept whole; outside: nothing
        assert_eq!(clip.clip_stroke(&rect(0.0, 0.0, 10.0, 10.0), true), None);
        assert_eq!(clip.clip_stroke(&rect(2.0, 2.0, 3.0, 3.0), true), None);
        assert_eq!(
            clip.clip_stroke(&rect(20.0, 2.0, 30.0, 3.0), true),
            Some(Vec::new())
        );
    }

    #[test]
    fn holes_and_fill_rules_are_honoured() {
        // a frame: 0…10 with a hole 3…7 (even-odd)
        let frame = Region::filled(
            &[rect(0.0, 0.0, 10.0, 10.0), rect(3.0, 3.0, 7.0, 7.0)],
            Rule::EvenOdd,
        );
        assert!(frame.contains(Pt::new(1.0, 1.0)) && !frame.contains(Pt::new(5.0, 5.0)));
        let cut = frame
            .clip_stroke(&[Pt::new(-1.0, 5.0), Pt::new(11.0, 5.0)], false)
            .unwrap();
        assert_eq!(cut.len(), 2);
        assert!((cut.iter().map(|p| length(p)).sum::<f64>() - 6.0).abs() < 1e-12);
        // the same contours non-zero, same orientation: no hole
        let solid = Region::filled(
            &[rect(0.0, 0.0, 10.0, 10.0), rect(3.0, 3.0, 7.0, 7.0)],
            Rule::NonZero,
        );
        assert!(solid.contains(Pt::new(5.0, 5.0)));
        // a fill clipped: the intersection's area
        let fill = frame
            .clip_fill(&[rect(5.0, -5.0, 15.0, 15.0)], Rule::NonZero)
            .unwrap();
        let a: f64 = fill.iter().map(|l| area(l)).sum();
        assert!((a - (50.0 - 8.0)).abs() < 1e-6, "{a}");
        // a fill inside the clip stays as it is
        assert_eq!(
            solid.clip_fill(&[rect(1.0, 1.0, 2.0, 2.0)], Rule::NonZero),
            None
        );
        // a fill around the clip becomes the clip
        let around = Region::filled(&[rect(2.0, 2.0, 4.0, 4.0)], Rule::NonZero)
            .clip_fill(&[rect(0.0, 0.0, 10.0, 10.0)], Rule::NonZero)
            .unwrap();
        assert!((around.iter().map(|l| area(l)).sum::<f64>() - 4.0).abs() < 1e-9);
    }

    #[test]
    fn regions_combine() {
        let a = Region::filled(&[rect(0.0, 0.0, 10.0, 10.0)], Rule::NonZero);
        let b = Region::filled(&[rect(5.0, 5.0, 15.0, 15.0)], Rule::NonZero);
        let i = a.intersect(&b);
        assert!((i.loops().iter().map(|l| area(l)).sum::<f64>() - 25.0).abs() < 1e-9);
        let u = a.union(&b);
        assert!((u.loops().iter().map(|l| area(l)).sum::<f64>() - 175.0).abs() < 1e-9);
        assert!(a.intersect(&Region::default()).is_empty());
        assert_eq!(Region::default().union(&a), a);
    }
}
