//! `--split-oversize`: geometries larger than a field are cut into pieces that each fit one field.
//!
//! The cut lines form one grid of field-sized cells anchored at the corner of all the oversize
//! geometries (so pieces of different geometries share cells, and fields);
//! the polyline is split exactly where it crosses a cell border, so the pieces together mark
//! exactly the original (nothing lost, nothing twice). A closed geometry becomes open pieces; its
//! first and last piece are joined when they lie in the same cell.

use super::INSIDE_EPS_MM;
use crate::document::Warning;
use crate::document::{Geometry, Source};
use crate::geom::Pt;

/// Pieces shorter than this (mm) are dropped: below the resolution of the exported G-code.
pub const MIN_PIECE_MM: f64 = 1e-3;

/// The words of a cut's warning ("geometry 3 (… mm) is larger than the scan field: split into
/// 4 strokes at field borders"), by which the cut's warnings are found again.
pub const SPLIT_WORDS: &str = "is larger than the scan field: split into";

/// True when the geometry does not fit a field of `field_mm`.
pub fn is_oversize(g: &Geometry, field_mm: [f64; 2]) -> bool {
    let b = g.bbox();
    b.width() > field_mm[0] + INSIDE_EPS_MM || b.height() > field_mm[1] + INSIDE_EPS_MM
}

/// Cuts one geometry at the borders of a grid of cells of `pitch_mm` (per axis) anchored at
/// `origin`.
pub fn split_geometry(g: &Geometry, origin: Pt, pitch_mm: [f64; 2]) -> Vec<Geometry> {
    let cell = |p: Pt| -> (i64, i64) {
        (
            ((p.x - origin.x) / pitch_mm[0]).floor() as i64,
            ((p.y - origin.y) / pitch_mm[1]).floor() as i64,
        )
    };
    let mut path = g.points.clone();
    if g.closed {
        if let Some(&f) = path.first() {
            path.push(f);
        }
    }
    // pieces as (cell, points)
    let mut pieces: Vec<((i64, i64), Vec<Pt>)> = Vec::new();
    for w in path.windows(2) {
        let (a, z) = (w[0], w[1]);
        let d = z.minus(a);
        let mut ts = vec![0.0, 1.0];
        for (axis, (da, oa, pa)) in [(d.x, origin.x, a.x), (d.y, origin.y, a.y)]
            .into_iter()
            .enumerate()
        {
            if da == 0.0 {
                continue;
            }
            let pitch = pitch_mm[axis];
            let (lo, hi) = if da > 0.0 {
                (pa, pa + da)
            } else {
                (pa + da, pa)
            };
            let mut k = ((lo - oa) / pitch).ceil() as i64;
            while oa + k as f64 * pitch < hi {
                let t = (oa + k as f64 * pitch - pa) / da;
                if t > 0.0 && t < 1.0 {
                    ts.push(t);
                }
                k += 1;
            }
        }
        ts.sort_by(f64::total_cmp);
        ts.dedup();
        for tw in ts.windows(2) {
            let (p, q) = (a.plus(d.scale(tw[0])), a.plus(d.scale(tw[1])));
            if p.dist(q) <= 0.0 {
                continue;
            }
            let c = cell(a.plus(d.scale((tw[0] + tw[1]) / 2.0)));
            match pieces.last_mut() {
                Some((pc, pts)) if *pc == c => pts.push(q),
                _ => pieces.push((c, vec![p, q])),
            }
        }
    }
    if g.closed && pieces.len() > 1 {
        let same = pieces.first().map(|f| f.0) == pieces.last().map(|l| l.0);
        if same {
            if let Some((_, mut last)) = pieces.pop() {
                let first = std::mem::take(&mut pieces[0].1);
                last.extend(first.into_iter().skip(1));
                pieces[0].1 = last;
            }
        }
    }
    // a cut through a cell corner can leave a crumb shorter than the G-code resolution: drop it
    pieces.retain(|(_, pts)| crate::geom::polyline_length(pts, false) >= MIN_PIECE_MM);
    let closed_whole = g.closed && pieces.len() == 1;
    pieces
        .into_iter()
        .enumerate()
        .map(|(k, (_, pts))| {
            let source = Source {
                element: format!("{} (piece {})", g.source.element, k + 1),
                subpath: g.source.subpath,
                layer: g.source.layer.clone(),
            };
            Geometry::new(pts, closed_whole, source).with_layer(&g.layer)
        })
        .collect()
}

/// Replaces every oversize geometry by its pieces (in place, keeping document order) and returns
/// a warning per split geometry.
pub fn split_oversize(geometries: &mut Vec<Geometry>, field_mm: [f64; 2]) -> Vec<Warning> {
    let pitch = [field_mm[0] - 1e-6, field_mm[1] - 1e-6];
    let corner = geometries
        .iter()
        .filter(|g| is_oversize(g, field_mm))
        .fold(crate::geom::BBox::EMPTY, |b, g| b.union(g.bbox()));
    let origin = Pt::new(corner.min_x, corner.min_y);
    let mut out = Vec::with_capacity(geometries.len());
    let mut warnings = Vec::new();
    for (i, g) in std::mem::take(geometries).into_iter().enumerate() {
        if is_oversize(&g, field_mm) {
            let pieces = split_geometry(&g, origin, pitch);
            warnings.push(Warning {
                element: g.source.element.clone(),
                line: None,
                message: format!(
                    "geometry {} ({:.2} × {:.2} mm) {SPLIT_WORDS} {} strokes at field borders",
                    i + 1,
                    g.bbox().width(),
                    g.bbox().height(),
                    pieces.len()
                ),
            });
            out.extend(pieces);
        } else {
            out.push(g);
        }
    }
    *geometries = out;
    warnings
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::tests_support::rect;
    use proptest::prelude::*;

    #[test]
    fn big_rectangle_becomes_open_pieces_of_the_same_length() {
        let g = rect(0.0, 0.0, 150.0, 20.0);
        let pieces = split_geometry(&g, Pt::new(0.0, 0.0), [70.0, 70.0]);
        // cells x: [0,70) [70,140) [140,150]: top and bottom edges cut twice, joined around the ends
        assert_eq!(pieces.len(), 4);
        let total: f64 = pieces.iter().map(Geometry::length_mm).sum();
        assert!((total - g.length_mm()).abs() < 1e-9);
        for p in &pieces {
            assert!(!p.closed);
            assert!(!is_oversize(p, [70.0, 70.0]));
        }
    }

    proptest! {
        #[test]
        fn pieces_fit_and_keep_length(
            pts in proptest::collection::vec((0.0f64..400.0, 0.0f64..400.0), 2..30),
            closed in any::<bool>(),
        ) {
            let pts: Vec<Pt> = pts.into_iter().map(|(x, y)| Pt::new(x, y)).collect();
            let g = Geometry::new(pts, closed, Source::default());
            let pieces = split_geometry(&g, Pt::new(-3.0, 5.0), [70.0 - 1e-6, 70.0 - 1e-6]);
            let total: f64 = pieces.iter().map(Geometry::length_mm).sum();
            prop_assert!((total - g.length_mm()).abs() < 1e-6 * g.length_mm().max(1.0) + MIN_PIECE_MM * 4.0 * pieces.len() as f64);
            for p in &pieces {
                prop_assert!(!is_oversize(p, [70.0, 70.0]));
            }
        }
    }
}
