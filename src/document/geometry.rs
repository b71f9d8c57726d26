//! One continuous stroke of the artwork.

use super::DEFAULT_LAYER;
use crate::geom::{polyline_length, BBox, Pt};
use serde::{Deserialize, Serialize};

/// Where a geometry came from in the source file.
#[derive(Debug, Clone, Default, Serialize, Deserialize, PartialEq)]
pub struct Source {
    /// The element's `id`, or a description such as `path #12` when it has none.
    pub element: String,
    /// Index of the subpath inside the element (0 for the first).
    pub subpath: usize,
    /// Layer name: the DXF layer; for SVG the `inkscape:label` (else the `id`) of the top-level
    /// group holding the element, else its stroke colour as `#rrggbb` (`fill #rrggbb` when it
    /// has only a fill, `none` when neither).
    pub layer: String,
    /// The tray part it belongs to (from 1; 0: not a tray's part).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub part: u32,
}

/// One continuous stroke: a polyline in mm.
///
/// A closed geometry does not repeat its first point; it may start at any vertex and is
/// marked back to that vertex. An open one starts at either end.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Geometry {
    /// Vertices in mm (machine coordinates).
    pub points: Vec<Pt>,
    /// True when the stroke returns to its first vertex.
    pub closed: bool,
    /// Origin in the source file.
    pub source: Source,
    /// The layer it belongs to (its pen says how it is marked): the import's `source.layer`
    /// (SVG top-level group label or id, else stroke colour; DXF layer), [`DEFAULT_LAYER`] when
    /// the import gave none. Hatch output keeps its region's layer.
    #[serde(default = "default_layer")]
    pub layer: String,
    /// 0: marked as many times as its pen's passes. k ≥ 1: pass k of a pen with shifted passes,
    /// cut on that pass's own tiling and marked once.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub pass: u32,
    /// The run of strokes it belongs to, when a fill fixes their marking order (see [`Run`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run: Option<Run>,
}

/// A run: strokes of one fill whose marking order the fill already fixes, so that planning
/// may treat them as one node ([`super::runs`]). The members of a run are consecutive in the
/// geometry list and share the run's id, their source element, layer and pass; they are listed
/// in marking order.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, Hash)]
pub struct Run {
    /// Tells consecutive runs of one fill apart.
    pub id: u32,
    /// How its members follow one another.
    pub order: RunOrder,
}

/// How the members of a [`Run`] follow one another.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, PartialEq, Eq, Hash)]
pub enum RunOrder {
    /// Pieces of a closed loop, each running along it: the run may be entered at any member and
    /// is marked round to the one before it (or, cut short, from either end).
    Loop,
    /// Parallel chords swept back and forth: every other member is marked reversed, from
    /// either end of the run.
    Sweep,
}

fn is_zero(v: &u32) -> bool {
    *v == 0
}

fn default_layer() -> String {
    DEFAULT_LAYER.to_string()
}

/// Hatch output geometries have a layer starting with this (then the region's own layer).
pub const HATCH_LAYER_PREFIX: &str = "hatch:";

/// True for a geometry made by the hatch (see [`HATCH_LAYER_PREFIX`]).
pub fn is_hatch_output(g: &Geometry) -> bool {
    g.source.layer.starts_with(HATCH_LAYER_PREFIX)
}

impl Geometry {
    /// Makes a geometry on the layer its source names ([`DEFAULT_LAYER`] when none); for a
    /// closed one a repeated last point is dropped.
    pub fn new(mut points: Vec<Pt>, closed: bool, source: Source) -> Self {
        if closed && points.len() > 1 {
            if let (Some(a), Some(b)) = (points.first(), points.last()) {
                if a.dist(*b) < 1e-9 {
                    points.pop();
                }
            }
        }
        // the import's layer name (DXF layer, SVG group or stroke colour)
        let layer = if source.layer.is_empty() {
            default_layer()
        } else {
            source.layer.clone()
        };
        Self {
            points,
            closed,
            source,
            layer,
            pass: 0,
            run: None,
        }
    }
    /// The same geometry on layer `name`.
    pub fn with_layer(mut self, name: &str) -> Self {
        self.layer = name.to_string();
        self
    }
    /// The same geometry as pass `pass` of a pen with shifted passes (see [`Geometry::pass`]).
    pub fn with_pass(mut self, pass: u32) -> Self {
        self.pass = pass;
        self
    }
    /// The same geometry as a member of `run`.
    pub fn with_run(mut self, run: Option<Run>) -> Self {
        self.run = run;
        self
    }
    /// Bounding box.
    pub fn bbox(&self) -> BBox {
        BBox::of(&self.points)
    }
    /// Marked length in mm.
    pub fn length_mm(&self) -> f64 {
        polyline_length(&self.points, self.closed)
    }
    /// Centroid of the vertices (used as the geometry's representative point).
    pub fn centroid(&self) -> Pt {
        let n = self.points.len().max(1) as f64;
        let s = self.points.iter().fold(Pt::default(), |a, &p| a.plus(p));
        s.scale(1.0 / n)
    }
    /// Number of possible start choices: every vertex of a closed geometry, both ends of an open one.
    pub fn start_choices(&self) -> usize {
        if self.closed {
            self.points.len()
        } else {
            2
        }
    }
    /// The (start, end) points of the stroke for a start choice `c < start_choices()`:
    /// closed geometries start and end at vertex `c`; open ones run forwards (`c == 0`) or backwards.
    pub fn ends(&self, choice: usize) -> (Pt, Pt) {
        let first = self.points.first().copied().unwrap_or_default();
        let last = self.points.last().copied().unwrap_or_default();
        if self.closed {
            let p = self.points.get(choice).copied().unwrap_or(first);
            (p, p)
        } else if choice == 0 {
            (first, last)
        } else {
            (last, first)
        }
    }
    /// A short human description: element, subpath and size.
    pub fn describe(&self) -> String {
        let b = self.bbox();
        format!(
            "{} (subpath {}, {:.2} × {:.2} mm at x {:.2}, y {:.2})",
            self.source.element,
            self.source.subpath,
            b.width(),
            b.height(),
            b.min_x,
            b.min_y
        )
    }
    /// What the stroke is, in an operator's words: "circle ⌀6.00 mm", "rectangle 20.00 × 10.00
    /// mm", "line 12.50 mm", "dot", "closed outline 30.00 × 12.00 mm", "open path 48.20 mm long".
    /// A circle is a closed stroke of 8 or more vertices all within 1 % of their mean distance
    /// r from their centroid, no edge longer than 0.8 r and a perimeter within 2 % of 2πr; a
    /// rectangle, 4 vertices with square corners (cosine below 1e-6).
    pub fn shape_words(&self) -> String {
        let b = self.bbox();
        let n = self.points.len();
        if crate::geom::is_dot(&self.points) {
            return "dot".into();
        }
        if !self.closed {
            return match n {
                2 => format!("line {:.2} mm", self.length_mm()),
                _ => format!("open path {:.2} mm long", self.length_mm()),
            };
        }
        let c = self
            .points
            .iter()
            .fold(Pt::default(), |a, p| a.plus(*p))
            .scale(1.0 / n as f64);
        let r: Vec<f64> = self.points.iter().map(|p| p.dist(c)).collect();
        let mean = r.iter().sum::<f64>() / n as f64;
        let round = r.iter().all(|d| (d - mean).abs() <= 0.01 * mean);
        // no long edge (a rounded rectangle's vertices are all at its corners) and the
        // perimeter of a circle
        let short_edges =
            (0..n).all(|k| self.points[k].dist(self.points[(k + 1) % n]) <= 0.8 * mean);
        let perimeter = self.length_mm();
        let circular = (perimeter - std::f64::consts::TAU * mean).abs() <= 0.02 * perimeter;
        if n >= 8 && mean > 0.0 && round && short_edges && circular {
            return format!("circle ⌀{:.2} mm", 2.0 * mean);
        }
        let square = |k: usize| {
            let (a, o, z) = (
                self.points[(k + 3) % 4],
                self.points[k],
                self.points[(k + 1) % 4],
            );
            let (u, v) = (a.minus(o), z.minus(o));
            u.dot(v).abs() <= 1e-6 * u.norm() * v.norm()
        };
        if n == 4 && (0..4).all(square) {
            let s = [
                self.points[0].dist(self.points[1]),
                self.points[1].dist(self.points[2]),
            ];
            return format!("rectangle {:.2} × {:.2} mm", s[0], s[1]);
        }
        format!("closed outline {:.2} × {:.2} mm", b.width(), b.height())
    }
    /// The points in marking order for a start vertex and direction.
    ///
    /// Closed: `start_vertex` onwards (or backwards when `reversed`) and back to it.
    /// Open: as stored, or reversed.
    pub fn marking_path(&self, start_vertex: usize, reversed: bool) -> Vec<Pt> {
        let n = self.points.len();
        if n == 0 {
            return Vec::new();
        }
        if !self.closed {
            let mut v = self.points.clone();
            if reversed {
                v.reverse();
            }
            return v;
        }
        let s = start_vertex % n;
        (0..=n)
            .map(|i| {
                let k = if reversed {
                    (s + n - i % n) % n
                } else {
                    (s + i) % n
                };
                self.points[k]
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sq() -> Geometry {
        let pts = vec![
            Pt::new(0.0, 0.0),
            Pt::new(1.0, 0.0),
            Pt::new(1.0, 1.0),
            Pt::new(0.0, 1.0),
            Pt::new(0.0, 0.0),
        ];
        Geometry::new(pts, true, Source::default())
    }

    #[test]
    fn a_stroke_says_what_shape_it_is() {
        assert_eq!(sq().shape_words(), "rectangle 1.00 × 1.00 mm");
        let circle: Vec<Pt> = (0..64)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 64.0;
                Pt::new(10.0 + 3.0 * a.cos(), 5.0 + 3.0 * a.sin())
            })
            .collect();
        let g = Geometry::new(circle, true, Source::default());
        assert_eq!(g.shape_words(), "circle ⌀6.00 mm");
        let line = vec![Pt::new(0.0, 0.0), Pt::new(3.0, 4.0)];
        let g = Geometry::new(line.clone(), false, Source::default());
        assert_eq!(g.shape_words(), "line 5.00 mm");
        let g = Geometry::new(vec![Pt::new(1.0, 1.0)], false, Source::default());
        assert_eq!(g.shape_words(), "dot");
        let tri = vec![Pt::new(0.0, 0.0), Pt::new(4.0, 0.0), Pt::new(0.0, 2.0)];
        let g = Geometry::new(tri, true, Source::default());
        assert_eq!(g.shape_words(), "closed outline 4.00 × 2.00 mm");
    }

    #[test]
    fn closed_drops_repeated_point_and_walks_back() {
        let g = sq();
        assert_eq!(g.points.len(), 4);
        assert!((g.length_mm() - 4.0).abs() < 1e-12);
        let p = g.marking_path(2, false);
        assert_eq!(p.len(), 5);
        assert_eq!(p[0], Pt::new(1.0, 1.0));
        assert_eq!(p[4], Pt::new(1.0, 1.0));
        assert_eq!(p[1], Pt::new(0.0, 1.0));
        let r = g.marking_path(2, true);
        assert_eq!(r[1], Pt::new(1.0, 0.0));
        assert_eq!(g.ends(3), (Pt::new(0.0, 1.0), Pt::new(0.0, 1.0)));
    }

    #[test]
    fn open_ends() {
        let g = Geometry::new(
            vec![Pt::new(0.0, 0.0), Pt::new(2.0, 0.0)],
            false,
            Source::default(),
        );
        assert_eq!(g.start_choices(), 2);
        assert_eq!(g.ends(1), (Pt::new(2.0, 0.0), Pt::new(0.0, 0.0)));
        assert_eq!(g.marking_path(0, true)[0], Pt::new(2.0, 0.0));
    }
}
