//! Regions: contours resolved by a fill rule (i_overlay), inward offsets (cavalier_contours) and
//! flattening of the offset arcs back into polylines in mm.
//!
//! cavalier_contours works with absolute tolerances (1e-5 for equal positions), so offsets run
//! in a scaled frame where one hatch spacing is [`UNITS_PER_SPACING`] units; results are mapped
//! back to mm when flattened.

use crate::document::FillRule;
use crate::geom::Pt;
use cavalier_contours::polyline::{
    seg_arc_radius_and_center, PlineSource, PlineSourceMut, PlineVertex, Polyline,
};
use cavalier_contours::shape_algorithms::{IndexedPolyline, Shape, ShapeOffsetOptions};
use cavalier_contours::static_aabb2d_index::StaticAABB2DIndexBuilder;
use i_overlay::core::fill_rule::FillRule as OverlayRule;
use i_overlay::float::simplify::SimplifyShape;
use std::sync::OnceLock;

/// Scale of the offset frame: one hatch spacing is this many units.
pub(crate) const UNITS_PER_SPACING: f64 = 64.0;
/// Positions closer than this (units) are one position when cleaning offset results.
const SAME_POS_UNITS: f64 = 1e-5;
/// Offset loops with less area than this fraction of spacing² are dropped as offset debris.
const MIN_AREA_SPACING2: f64 = 1e-6;
/// Loops with at least this area (frame units², one spacing is 64 units) have their redundant
/// vertices removed.
const TIDY_MIN_AREA_UNITS2: f64 = 1e-2;
/// Input loops with less area than this fraction of spacing² are dropped as degenerate. Much
/// smaller than the debris limit: a tiny hole of the input (a sliver where two contours almost
/// touch) still keeps the offset region `d` away from its outline.
const MIN_INPUT_AREA_SPACING2: f64 = 1e-12;

/// Resolves contours (mm) with a fill rule into clean loops: outer boundaries counter-clockwise
/// (positive signed area in x-right, y-up terms), holes clockwise, no self-intersections.
pub(crate) fn resolve(contours: &[Vec<Pt>], rule: FillRule) -> Vec<Vec<Pt>> {
    let input: Vec<Vec<[f64; 2]>> = contours
        .iter()
        .filter(|c| c.len() >= 3)
        .map(|c| c.iter().map(|p| [p.x, p.y]).collect())
        .collect();
    if input.is_empty() {
        return Vec::new();
    }
    let rule = match rule {
        FillRule::EvenOdd => OverlayRule::EvenOdd,
        FillRule::NonZero => OverlayRule::NonZero,
    };
    let shapes = input.simplify_shape(rule);
    shapes
        .into_iter()
        .flatten()
        .filter(|c| c.len() >= 3)
        .map(|c| c.into_iter().map(|[x, y]| Pt::new(x, y)).collect())
        .collect()
}

#[cfg(test)]
/// Signed area of a closed loop (positive when counter-clockwise in x-right, y-up terms), by
/// geo's [`geo::Area`].
pub(crate) fn signed_area(pts: &[Pt]) -> f64 {
    use geo::Area;
    let ring: geo::LineString<f64> = pts.iter().map(|p| geo::coord! { x: p.x, y: p.y }).collect();
    geo::Polygon::new(ring, vec![]).signed_area()
}

/// The scaled frame of one region: `units = (mm - origin) * k`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    origin: Pt,
    k: f64,
}

impl Frame {
    /// A frame centred on `loops` where `spacing_mm` is [`UNITS_PER_SPACING`] units.
    pub(crate) fn new(loops: &[Vec<Pt>], spacing_mm: f64) -> Self {
        let b = crate::geom::BBox::of(&loops.iter().flatten().copied().collect::<Vec<_>>());
        let origin = if b.is_empty() {
            Pt::default()
        } else {
            b.center()
        };
        Self {
            origin,
            k: UNITS_PER_SPACING / spacing_mm,
        }
    }
    /// mm → units for a length.
    pub(crate) fn len_units(&self, mm: f64) -> f64 {
        mm * self.k
    }
    fn units_of(self, p: Pt) -> (f64, f64) {
        (
            (p.x - self.origin.x) * self.k,
            (p.y - self.origin.y) * self.k,
        )
    }
    /// mm → units for a box.
    pub(crate) fn box_units(self, b: &crate::geom::BBox) -> crate::geom::BBox {
        let (min_x, min_y) = self.units_of(Pt::new(b.min_x, b.min_y));
        let (max_x, max_y) = self.units_of(Pt::new(b.max_x, b.max_y));
        crate::geom::BBox {
            min_x,
            min_y,
            max_x,
            max_y,
        }
    }
    /// Units → mm for a point.
    pub(crate) fn mm_of(self, x: f64, y: f64) -> Pt {
        Pt::new(x / self.k + self.origin.x, y / self.k + self.origin.y)
    }
}

/// A region in the scaled frame: cavalier_contours shape (counter-clockwise outer boundaries,
/// clockwise holes; the region lies left of every loop).
pub(crate) struct Region {
    pub(crate) shape: Shape<f64>,
    pub(crate) frame: Frame,
    /// The boundary elements by loop, made on first use (a level's region is looked at as ring
    /// `k` and as ring `k + 1`).
    elems: OnceLock<Vec<Vec<Elem>>>,
}

impl Region {
    /// Builds the region from clean loops (see [`resolve`]).
    pub(crate) fn new(loops: &[Vec<Pt>], frame: Frame) -> Self {
        let plines = loops.iter().map(|l| {
            let mut p = Polyline::new_closed();
            for &q in l {
                let (x, y) = frame.units_of(q);
                p.add(x, y, 0.0);
            }
            p
        });
        Self::of_shape(clean(plines, MIN_INPUT_AREA_SPACING2), frame)
    }
    fn of_shape(shape: Shape<f64>, frame: Frame) -> Self {
        Self {
            shape,
            frame,
            elems: OnceLock::new(),
        }
    }
    /// The region bounded by closed polylines in frame units (region on their left).
    pub(crate) fn from_plines(plines: Vec<Polyline<f64>>, frame: Frame) -> Self {
        Self::of_shape(clean(plines.into_iter(), MIN_INPUT_AREA_SPACING2), frame)
    }
    /// True when nothing is left.
    pub(crate) fn is_empty(&self) -> bool {
        self.shape.ccw_plines.is_empty() && self.shape.cw_plines.is_empty()
    }
    /// Inward offset by `mm` (erosion by a disc); arcs are exact.
    pub(crate) fn offset(&self, mm: f64) -> Region {
        if mm <= 0.0 || self.is_empty() {
            return Region::of_shape(
                clean(self.plines().cloned(), MIN_INPUT_AREA_SPACING2),
                self.frame,
            );
        }
        let opts = ShapeOffsetOptions::default();
        let out = self.shape.parallel_offset(self.frame.len_units(mm), &opts);
        Region::of_shape(
            clean_indexed(
                out.ccw_plines.into_iter().chain(out.cw_plines),
                MIN_AREA_SPACING2,
            ),
            self.frame,
        )
    }
    /// The loops of the inward offset by `mm`, flattened within `tol_mm` like [`Self::flatten`]
    /// (without building the offset's spatial indexes: for offsets that are only looked at),
    /// each with one flag per segment (segment `i` runs from point `i` to point `i + 1`, the last
    /// one back to the first): true where the segment comes from a boundary element (line or arc)
    /// for which `covered` returns true.
    pub(crate) fn offset_flattened_marked(
        &self,
        mm: f64,
        tol_mm: f64,
        covered: impl Fn(&Elem) -> bool,
    ) -> Vec<(Vec<Pt>, Vec<bool>)> {
        if self.is_empty() {
            return Vec::new();
        }
        let opts = ShapeOffsetOptions::default();
        let out = self.shape.parallel_offset(self.frame.len_units(mm), &opts);
        let tol = self.frame.len_units(tol_mm);
        out.ccw_plines
            .iter()
            .chain(out.cw_plines.iter())
            .map(|p| &p.polyline)
            .filter(|p| p.vertex_count() >= 2 && p.area().abs() > min_area())
            .map(|pl| flatten_pline_marked(pl, tol, &self.frame, &covered))
            .filter(|(l, _)| l.len() >= 2)
            .collect()
    }
    /// The elements of each boundary loop in order (counter-clockwise loops first, as in the
    /// shape), in frame units.
    pub(crate) fn loop_elems(&self) -> &[Vec<Elem>] {
        self.elems.get_or_init(|| {
            self.plines()
                .map(|pl| {
                    let n = pl.vertex_count();
                    (0..n)
                        .map(|i| Elem::of(pl.at(i), pl.at((i + 1) % n)))
                        .collect()
                })
                .collect()
        })
    }
    fn plines(&self) -> impl Iterator<Item = &Polyline<f64>> {
        self.shape
            .ccw_plines
            .iter()
            .chain(self.shape.cw_plines.iter())
            .map(|p| &p.polyline)
    }
    /// The loops as polylines in mm, arcs flattened within `tol_mm` so that the polygon lies
    /// inside the exact region: arcs bulging out of the region (convex) get inscribed chords,
    /// arcs bulging into it (around a reflex corner) get circumscribed tangent polygons.
    pub(crate) fn flatten(&self, tol_mm: f64) -> Vec<Vec<Pt>> {
        let tol = self.frame.len_units(tol_mm);
        self.plines()
            .map(|pl| flatten_pline(pl, tol, &self.frame))
            .filter(|l| l.len() >= 2)
            .collect()
    }
}

/// The inward offset by `mm` of the region bounded by one counter-clockwise loop `pl` (frame
/// units), flattened like [`Region::flatten`]: [`Region::offset`] without the shape and the
/// spatial indexes of its result.
pub(crate) fn offset_loop_flattened(
    pl: Polyline<f64>,
    mm: f64,
    tol_mm: f64,
    frame: Frame,
) -> Vec<Vec<Pt>> {
    let input_min = MIN_INPUT_AREA_SPACING2 * UNITS_PER_SPACING * UNITS_PER_SPACING;
    let pl = match tidied(&pl, input_min) {
        Some((Some(q), area)) if area > 0.0 => q,
        Some((None, area)) if area > 0.0 => pl,
        _ => return Vec::new(),
    };
    let tol = frame.len_units(tol_mm);
    pl.parallel_offset(frame.len_units(mm))
        .iter()
        .filter(|p| p.vertex_count() >= 2 && p.area() > min_area())
        .map(|p| flatten_pline(p, tol, &frame))
        .filter(|l| l.len() >= 2)
        .collect()
}

/// A loop with its redundant vertices removed, as `(the new loop if any vertex went, signed
/// area)`, or `None` when it has fewer than two vertices or no more than `min_area` (units²).
fn tidied(pl: &Polyline<f64>, min_area: f64) -> Option<(Option<Polyline<f64>>, f64)> {
    // (two vertices make a loop of two arcs, a circle)
    if pl.vertex_count() < 2 || pl.area().abs() <= min_area {
        return None;
    }
    // remove_redundant indexes past the end of loops that collapse to fewer than two vertices;
    // only loops of some size are tidied (the offset removes repeated positions itself, so the
    // others are used as they are)
    let q = if pl.area().abs() > TIDY_MIN_AREA_UNITS2 {
        pl.remove_redundant(SAME_POS_UNITS)
    } else {
        None
    };
    let kept = q.as_ref().unwrap_or(pl);
    let area = kept.area();
    (kept.vertex_count() >= 2 && area.abs() > min_area).then_some((q, area))
}

/// Offset loops with less area than this (units²) are debris.
fn min_area() -> f64 {
    MIN_AREA_SPACING2 * UNITS_PER_SPACING * UNITS_PER_SPACING
}

/// Removes redundant vertices and loops with less area than `min_area_spacing2` · spacing², and
/// rebuilds the shape.
fn clean(plines: impl Iterator<Item = Polyline<f64>>, min_area_spacing2: f64) -> Shape<f64> {
    clean_indexed(plines.map(IndexedPolyline::new), min_area_spacing2)
}

/// Like [`clean`] for polylines that already carry their spatial index (offset results): the
/// index is rebuilt only for the polylines that lost vertices.
fn clean_indexed(
    plines: impl Iterator<Item = IndexedPolyline<f64>>,
    min_area_spacing2: f64,
) -> Shape<f64> {
    let min_area = min_area_spacing2 * UNITS_PER_SPACING * UNITS_PER_SPACING;
    let (mut ccw, mut cw) = (Vec::new(), Vec::new());
    for p in plines {
        let (p, area) = match tidied(&p.polyline, min_area) {
            None => continue,
            Some((None, area)) => (p, area),
            Some((Some(q), area)) => (IndexedPolyline::new(q), area),
        };
        if area > 0.0 {
            ccw.push(p);
        } else {
            cw.push(p);
        }
    }
    if ccw.is_empty() && cw.is_empty() {
        return Shape::empty();
    }
    let mut b = StaticAABB2DIndexBuilder::new(ccw.len() + cw.len());
    for p in ccw.iter().chain(cw.iter()) {
        match p.spatial_index.bounds() {
            Some(r) => b.add(r.min_x, r.min_y, r.max_x, r.max_y),
            None => b.add(0.0, 0.0, 0.0, 0.0),
        };
    }
    match b.build() {
        Ok(plines_index) => Shape {
            ccw_plines: ccw,
            cw_plines: cw,
            plines_index,
        },
        // not reached (the builder got exactly the announced count); rebuild the plain way
        Err(_) => Shape::from_plines(ccw.into_iter().chain(cw).map(|p| p.polyline)),
    }
}

/// An arc segment of a boundary loop in frame units: centre, radius, start angle and signed
/// sweep (radians, positive counter-clockwise).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ArcGeom {
    pub(crate) center: Pt,
    pub(crate) radius: f64,
    pub(crate) start: f64,
    pub(crate) sweep: f64,
}

/// One element of a boundary loop in frame units; the region lies to its left.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Elem {
    /// A line segment from the first point to the second.
    Line(Pt, Pt),
    /// An arc.
    Arc(ArcGeom),
}

impl ArcGeom {
    /// The point of the arc's circle at angle `ang`.
    pub(crate) fn point(&self, ang: f64) -> Pt {
        Pt::new(
            self.center.x + self.radius * ang.cos(),
            self.center.y + self.radius * ang.sin(),
        )
    }
}

impl Elem {
    /// The point at parameter `t` (0 at the start, 1 at the end; arcs: linear in angle).
    pub(crate) fn at(&self, t: f64) -> Pt {
        match self {
            Elem::Line(a, b) => a.plus(b.minus(*a).scale(t)),
            Elem::Arc(g) => g.point(g.start + t * g.sweep),
        }
    }
    /// The element from `v1` to `v2` (a degenerate arc counts as its chord).
    pub(crate) fn of(v1: PlineVertex<f64>, v2: PlineVertex<f64>) -> Self {
        let line = Elem::Line(Pt::new(v1.x, v1.y), Pt::new(v2.x, v2.y));
        if v1.bulge.abs() < 1e-12 {
            return line;
        }
        let (r, c) = seg_arc_radius_and_center(v1, v2);
        if !(r.is_finite() && r > 0.0) {
            return line;
        }
        Elem::Arc(ArcGeom {
            center: Pt::new(c.x, c.y),
            radius: r,
            start: (v1.y - c.y).atan2(v1.x - c.x),
            sweep: 4.0 * v1.bulge.atan(),
        })
    }
}

fn flatten_pline(pl: &Polyline<f64>, tol: f64, frame: &Frame) -> Vec<Pt> {
    flatten_pline_marked(pl, tol, frame, &|_| false).0
}

/// Flattens a closed polyline; the flags say, per segment, whether `covered` holds for the
/// element the segment comes from.
fn flatten_pline_marked(
    pl: &Polyline<f64>,
    tol: f64,
    frame: &Frame,
    covered: &impl Fn(&Elem) -> bool,
) -> (Vec<Pt>, Vec<bool>) {
    let n = pl.vertex_count();
    let mut pts: Vec<Pt> = Vec::with_capacity(n);
    let mut flags: Vec<bool> = Vec::with_capacity(n);
    let mut arc_pts: Vec<Pt> = Vec::new();
    for i in 0..n {
        let v1 = pl.at(i);
        let v2 = pl.at((i + 1) % n);
        let flag = covered(&Elem::of(v1, v2));
        arc_pts.clear();
        arc_pts.push(frame.mm_of(v1.x, v1.y));
        if v1.bulge.abs() >= 1e-12 {
            arc_points(v1, v2, tol, frame, &mut arc_pts);
        }
        // drop repeated points: the segment that follows a dropped point starts at the kept one
        for &p in &arc_pts {
            match pts.last() {
                Some(q) if q.dist2(p) < 1e-24 => {
                    if let Some(f) = flags.last_mut() {
                        *f = flag;
                    }
                }
                _ => {
                    pts.push(p);
                    flags.push(flag);
                }
            }
        }
    }
    // a last point equal to the first
    while pts.len() > 1 && pts[0].dist2(pts[pts.len() - 1]) < 1e-24 {
        pts.pop();
        flags.pop();
    }
    (pts, flags)
}

/// Interior points of the arc v1→v2 (v1 pushed by the caller, v2 by the next segment).
fn arc_points(
    v1: PlineVertex<f64>,
    v2: PlineVertex<f64>,
    tol: f64,
    frame: &Frame,
    out: &mut Vec<Pt>,
) {
    let (r, c) = seg_arc_radius_and_center(v1, v2);
    if !(r.is_finite() && r > tol) {
        return;
    }
    let sweep = 4.0 * v1.bulge.atan();
    let a0 = (v1.y - c.y).atan2(v1.x - c.x);
    let step_max = 2.0 * (1.0 - tol / r).clamp(-1.0, 1.0).acos();
    let count = (sweep.abs() / step_max.max(1e-9)).ceil().clamp(1.0, 1e6) as usize;
    let step = sweep / count as f64;
    if v1.bulge > 0.0 {
        // the region is on the arc's centre side: chords stay inside it
        for k in 1..count {
            let a = a0 + step * k as f64;
            out.push(frame.mm_of(c.x + r * a.cos(), c.y + r * a.sin()));
        }
    } else {
        // the region is outside the circle: tangents at the sub-arc ends meet outside the circle
        let rr = r / (step / 2.0).cos();
        for k in 0..count {
            let a = a0 + step * (k as f64 + 0.5);
            out.push(frame.mm_of(c.x + rr * a.cos(), c.y + rr * a.sin()));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, w: f64) -> Vec<Pt> {
        vec![
            Pt::new(x0, y0),
            Pt::new(x0 + w, y0),
            Pt::new(x0 + w, y0 + w),
            Pt::new(x0, y0 + w),
        ]
    }

    #[test]
    fn fill_rules_resolve_nesting() {
        // two squares, the small one inside: even-odd makes a hole, non-zero (same direction) not
        let c = vec![square(0.0, 0.0, 10.0), square(3.0, 3.0, 4.0)];
        let eo = resolve(&c, FillRule::EvenOdd);
        let area: f64 = eo.iter().map(|l| signed_area(l)).sum();
        assert!((area - 84.0).abs() < 1e-6, "{area}");
        let nz = resolve(&c, FillRule::NonZero);
        let area: f64 = nz.iter().map(|l| signed_area(l)).sum();
        assert!((area - 100.0).abs() < 1e-6, "{area}");
    }

    #[test]
    fn offset_square_with_hole() {
        let c = vec![square(0.0, 0.0, 10.0), square(3.0, 3.0, 4.0)];
        let loops = resolve(&c, FillRule::EvenOdd);
        let r = Region::new(&loops, Frame::new(&loops, 0.5));
        let o = r.offset(1.0);
        let flat = o.flatten(1e-4);
        assert_eq!(flat.len(), 2);
        // outer 8×8 minus the hole grown by 1 mm with rounded corners: 64 − (36 − 4 + π)
        let area: f64 = flat.iter().map(|l| signed_area(l)).sum();
        let want = 64.0 - (36.0 - 4.0 + std::f64::consts::PI);
        assert!((area - want).abs() < 1e-2, "{area} vs {want}");
        // every flattened point is at least 1 mm from the original boundary (inner approximation)
        for l in &flat {
            for p in l {
                let d_outer = p.x.min(p.y).min(10.0 - p.x).min(10.0 - p.y);
                let dx = (3.0 - p.x).max(p.x - 7.0).max(0.0);
                let dy = (3.0 - p.y).max(p.y - 7.0).max(0.0);
                let d_hole = dx.hypot(dy);
                assert!(d_outer.min(d_hole) > 1.0 - 1e-9, "{p:?}");
            }
        }
        assert!(r.offset(6.0).is_empty());
    }
}
