//! Plane geometry helpers: points, bounding boxes, distances and curve flattening.
//!
//! All coordinates are millimetres in machine coordinates (x right, y down, as in SVG).

mod flatten;
pub(crate) mod grid;
pub mod seam;
pub mod tiling;

pub use flatten::{cubic_chords, flatten_cubic, flatten_quad, quad_chords};

use serde::{Deserialize, Serialize};

/// Largest coordinate (|x| and |y|) galvoplan takes from any file, mm: 1 km, beyond any machine.
/// The importers (SVG after its transforms, DXF), the project loader and the profile check
/// refuse a point, radius or size past it, naming where; with it, flattening a curve takes a
/// number of chords bounded by the tolerance alone ([`flatten`]'s module note).
pub const MAX_COORD_MM: f64 = 1.0e6;

/// True when both coordinates are within ±[`MAX_COORD_MM`] (and so finite).
pub fn within_reach_bound(p: Pt) -> bool {
    p.x.abs() <= MAX_COORD_MM && p.y.abs() <= MAX_COORD_MM
}

/// A point (or vector) in millimetres.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pt {
    /// x in mm.
    pub x: f64,
    /// y in mm.
    pub y: f64,
}

impl Pt {
    /// Makes a point.
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }
    /// Euclidean distance to `o`, in mm.
    pub fn dist(self, o: Pt) -> f64 {
        // plain sqrt: libm's hypot guards against overflow we cannot meet in mm and is several
        // times slower (it dominated the solvers' profiles)
        self.dist2(o).sqrt()
    }
    /// Squared distance to `o`, in mm².
    pub fn dist2(self, o: Pt) -> f64 {
        let (dx, dy) = (self.x - o.x, self.y - o.y);
        dx * dx + dy * dy
    }
    /// Vector difference `self - o`.
    pub fn minus(self, o: Pt) -> Pt {
        Pt::new(self.x - o.x, self.y - o.y)
    }
    /// Vector sum `self + o`.
    pub fn plus(self, o: Pt) -> Pt {
        Pt::new(self.x + o.x, self.y + o.y)
    }
    /// Scales by `k`.
    pub fn scale(self, k: f64) -> Pt {
        Pt::new(self.x * k, self.y * k)
    }
    /// Dot product.
    pub fn dot(self, o: Pt) -> f64 {
        self.x * o.x + self.y * o.y
    }
    /// Length of the vector.
    pub fn norm(self) -> f64 {
        (self.x * self.x + self.y * self.y).sqrt()
    }
    /// True when both coordinates are finite.
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

/// An axis-aligned bounding box in mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BBox {
    /// Smallest x.
    pub min_x: f64,
    /// Smallest y.
    pub min_y: f64,
    /// Largest x.
    pub max_x: f64,
    /// Largest y.
    pub max_y: f64,
}

impl BBox {
    /// The empty box (inverted, so that any point extends it).
    pub const EMPTY: BBox = BBox {
        min_x: f64::INFINITY,
        min_y: f64::INFINITY,
        max_x: f64::NEG_INFINITY,
        max_y: f64::NEG_INFINITY,
    };
    /// The box of a set of points (`EMPTY` for none).
    pub fn of(points: &[Pt]) -> BBox {
        let mut b = BBox::EMPTY;
        for &p in points {
            b.extend(p);
        }
        b
    }
    /// A box centred on `c` with size `w` × `h`.
    pub fn centered(c: Pt, w: f64, h: f64) -> BBox {
        BBox {
            min_x: c.x - w / 2.0,
            min_y: c.y - h / 2.0,
            max_x: c.x + w / 2.0,
            max_y: c.y + h / 2.0,
        }
    }
    /// Grows the box to hold `p`.
    pub fn extend(&mut self, p: Pt) {
        self.min_x = self.min_x.min(p.x);
        self.min_y = self.min_y.min(p.y);
        self.max_x = self.max_x.max(p.x);
        self.max_y = self.max_y.max(p.y);
    }
    /// The union of two boxes.
    pub fn union(self, o: BBox) -> BBox {
        BBox {
            min_x: self.min_x.min(o.min_x),
            min_y: self.min_y.min(o.min_y),
            max_x: self.max_x.max(o.max_x),
            max_y: self.max_y.max(o.max_y),
        }
    }
    /// Width in mm.
    pub fn width(&self) -> f64 {
        self.max_x - self.min_x
    }
    /// Height in mm.
    pub fn height(&self) -> f64 {
        self.max_y - self.min_y
    }
    /// Centre point.
    pub fn center(&self) -> Pt {
        Pt::new(
            (self.min_x + self.max_x) / 2.0,
            (self.min_y + self.max_y) / 2.0,
        )
    }
    /// True when `o` lies wholly inside `self`, allowing `eps` mm of slack.
    pub fn contains_box(&self, o: &BBox, eps: f64) -> bool {
        o.min_x >= self.min_x - eps
            && o.max_x <= self.max_x + eps
            && o.min_y >= self.min_y - eps
            && o.max_y <= self.max_y + eps
    }
    /// True when `p` lies inside, allowing `eps` mm of slack.
    pub fn contains_pt(&self, p: Pt, eps: f64) -> bool {
        p.x >= self.min_x - eps
            && p.x <= self.max_x + eps
            && p.y >= self.min_y - eps
            && p.y <= self.max_y + eps
    }
    /// Area in mm² (0 for an empty box).
    pub fn area(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            self.width() * self.height()
        }
    }
    /// True for the empty box.
    pub fn is_empty(&self) -> bool {
        self.min_x > self.max_x || self.min_y > self.max_y
    }
}

/// A star-shaped closed polygon around `c`: vertex `i` of `radii.len()` at distance `radii[i]`,
/// at angle `rot + i · 2π / n` (radians, counter-clockwise). Equal radii make a regular polygon.
pub fn star_polygon(c: Pt, radii: &[f64], rot: f64) -> Vec<Pt> {
    let n = radii.len();
    (0..n)
        .map(|i| {
            let a = rot + i as f64 / n as f64 * std::f64::consts::TAU;
            Pt::new(c.x + radii[i] * a.cos(), c.y + radii[i] * a.sin())
        })
        .collect()
}

/// A dot: a mark of one point (the laser fired in place for its pen's dwell, as a dotted
/// code's module), not a line.
pub fn is_dot(points: &[Pt]) -> bool {
    points.len() == 1
}

/// Length of a polyline in mm; `closed` adds the segment back to the first point.
pub fn polyline_length(points: &[Pt], closed: bool) -> f64 {
    let open: f64 = points.windows(2).map(|w| w[0].dist(w[1])).sum();
    match (closed, points.first(), points.last()) {
        (true, Some(&a), Some(&b)) if points.len() > 1 => open + a.dist(b),
        _ => open,
    }
}

/// Distance from `p` to the segment `a`–`b`, in mm.
pub fn point_segment_dist(p: Pt, a: Pt, b: Pt) -> f64 {
    let ab = b.minus(a);
    let len2 = ab.dot(ab);
    if len2 <= 0.0 {
        return p.dist(a);
    }
    let t = (p.minus(a).dot(ab) / len2).clamp(0.0, 1.0);
    p.dist(a.plus(ab.scale(t)))
}

/// A length in mm with `decimals` decimals, trailing zeros trimmed and no negative zero
/// (`-15.5000` → `-15.5`, `-0.0000` → `0`): how G-code words and messages write a coordinate.
pub fn format_mm(v: f64, decimals: usize) -> String {
    let mut s = String::new();
    push_mm(&mut s, v, decimals);
    s
}

/// [`format_mm`] appended to `out` (no allocation once `out` has room: G-code writes millions).
pub fn push_mm(out: &mut String, v: f64, decimals: usize) {
    use std::fmt::Write;
    let start = out.len();
    // writing to a String cannot fail
    let _ = write!(out, "{v:.decimals$}");
    if out[start..].contains('.') {
        let kept = out[start..]
            .trim_end_matches('0')
            .trim_end_matches('.')
            .len();
        out.truncate(start + kept);
    }
    if &out[start..] == "-0" {
        out.truncate(start);
        out.push('0');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lengths_are_written_without_trailing_zeros_or_negative_zero() {
        assert_eq!(format_mm(-15.5, 4), "-15.5");
        assert_eq!(format_mm(170.0, 4), "170");
        assert_eq!(format_mm(-0.00001, 4), "0");
        assert_eq!(format_mm(0.12345, 3), "0.123");
        assert_eq!(format_mm(-0.0, 0), "0");
        assert_eq!(format_mm(120.0, 0), "120");
        let mut s = String::from("X");
        push_mm(&mut s, 2.50, 3);
        push_mm(&mut s, -0.0001, 3);
        assert_eq!(s, "X2.50");
    }

    #[test]
    fn bbox_and_length() {
        let pts = [Pt::new(0.0, 0.0), Pt::new(3.0, 0.0), Pt::new(3.0, 4.0)];
        let b = BBox::of(&pts);
        assert_eq!((b.width(), b.height()), (3.0, 4.0));
        assert!((polyline_length(&pts, false) - 7.0).abs() < 1e-12);
        assert!((polyline_length(&pts, true) - 12.0).abs() < 1e-12);
        assert!(b.contains_pt(Pt::new(1.0, 1.0), 0.0));
        assert!(!b.contains_pt(Pt::new(-0.1, 1.0), 0.0));
        assert!(BBox::EMPTY.is_empty());
    }

    #[test]
    fn segment_distance() {
        let d = point_segment_dist(Pt::new(1.0, 1.0), Pt::new(0.0, 0.0), Pt::new(2.0, 0.0));
        assert!((d - 1.0).abs() < 1e-12);
        let d = point_segment_dist(Pt::new(-1.0, 0.0), Pt::new(0.0, 0.0), Pt::new(2.0, 0.0));
        assert!((d - 1.0).abs() < 1e-12);
    }
}
