//! Cutting hatch strokes larger than a scan field at a grid of field-sized cells.
//!
//! Cuts only split strokes (nothing is added, nothing overlaps): every piece lies in one closed
//! grid cell, so it fits in one scan field.

use crate::geom::{polyline_length, BBox, Pt};

/// Cells are smaller than the field by this much on each side, mm, so pieces fit with slack.
pub(crate) const FIT_MARGIN_MM: f64 = 1e-3;
/// Pieces shorter than this are dropped, mm.
const MIN_PIECE_MM: f64 = 1e-7;

/// A grid of equal cells covering a box, each at most `field - 2·FIT_MARGIN_MM` wide and high.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Grid {
    origin: Pt,
    cell: [f64; 2],
}

impl Grid {
    /// The grid for `bbox`: as few cells as fit, split evenly.
    pub(crate) fn new(bbox: &BBox, field_mm: [f64; 2]) -> Self {
        let fit = |extent: f64, field: f64| {
            let max = (field - 2.0 * FIT_MARGIN_MM).max(field * 0.5);
            let n = (extent / max).ceil().max(1.0);
            (extent / n).max(1e-9)
        };
        Self {
            origin: Pt::new(bbox.min_x, bbox.min_y),
            cell: [
                fit(bbox.width(), field_mm[0]),
                fit(bbox.height(), field_mm[1]),
            ],
        }
    }
}

/// True when a polyline's box fits in a field with [`FIT_MARGIN_MM`] to spare (grid cells leave
/// twice that).
pub(crate) fn fits(points: &[Pt], field_mm: [f64; 2]) -> bool {
    let b = BBox::of(points);
    b.width() <= field_mm[0] - FIT_MARGIN_MM && b.height() <= field_mm[1] - FIT_MARGIN_MM
}

/// Cuts a polyline where it crosses the grid lines; returns open pieces, each in one cell. A
/// closed polyline is walked back to its first point.
pub(crate) fn cut(points: &[Pt], closed: bool, grid: &Grid) -> Vec<Vec<Pt>> {
    let mut path: Vec<Pt> = points.to_vec();
    if closed {
        if let Some(&p) = points.first() {
            path.push(p);
        }
    }
    let mut pieces: Vec<Vec<Pt>> = Vec::new();
    let mut cur: Vec<Pt> = path.first().copied().into_iter().collect();
    for w in path.windows(2) {
        let (a, b) = (w[0], w[1]);
        let mut ts: Vec<f64> = Vec::new();
        for axis in 0..2 {
            let (pa, pb, o, c) = if axis == 0 {
                (a.x, b.x, grid.origin.x, grid.cell[0])
            } else {
                (a.y, b.y, grid.origin.y, grid.cell[1])
            };
            if pa == pb {
                continue;
            }
            let (lo, hi) = (pa.min(pb), pa.max(pb));
            let mut k = ((lo - o) / c).ceil();
            while o + k * c < hi {
                let t = (o + k * c - pa) / (pb - pa);
                if t > 0.0 && t < 1.0 {
                    ts.push(t);
                }
                k += 1.0;
            }
        }
        ts.sort_by(f64::total_cmp);
        for t in ts {
            let p = a.plus(b.minus(a).scale(t));
            cur.push(p);
            pieces.push(std::mem::take(&mut cur));
            cur.push(p);
        }
        cur.push(b);
    }
    pieces.push(cur);
    let mut pieces: Vec<Vec<Pt>> = pieces
        .into_iter()
        .map(|mut p| {
            p.dedup_by(|a, b| a.dist2(*b) < 1e-24);
            p
        })
        .filter(|p| p.len() >= 2 && polyline_length(p, false) > MIN_PIECE_MM)
        .collect();
    // a closed stroke: the last piece runs into the first one; join them when in one cell
    if closed && pieces.len() > 1 {
        let first = &pieces[0];
        let last = &pieces[pieces.len() - 1];
        let touch = last
            .last()
            .zip(first.first())
            .is_some_and(|(a, b)| a.dist(*b) < 1e-9);
        let joined = BBox::of(first).union(BBox::of(last));
        let one_cell =
            joined.width() <= grid.cell[0] + 1e-9 && joined.height() <= grid.cell[1] + 1e-9;
        if touch && one_cell {
            let first = pieces.remove(0);
            if let Some(last) = pieces.last_mut() {
                last.extend(first.into_iter().skip(1));
            }
        }
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cuts_keep_length_and_fit() {
        let zig: Vec<Pt> = (0..20)
            .flat_map(|i| {
                let y = i as f64;
                if i % 2 == 0 {
                    [Pt::new(0.0, y), Pt::new(150.0, y)]
                } else {
                    [Pt::new(150.0, y), Pt::new(0.0, y)]
                }
            })
            .collect();
        let field = [70.0, 70.0];
        assert!(!fits(&zig, field));
        let grid = Grid::new(&BBox::of(&zig), field);
        let pieces = cut(&zig, false, &grid);
        let total: f64 = pieces.iter().map(|p| polyline_length(p, false)).sum();
        assert!((total - polyline_length(&zig, false)).abs() < 1e-9);
        for p in &pieces {
            assert!(fits(p, field), "{:?}", BBox::of(p));
        }
        // three columns of 50 mm: 20 lines cut twice each
        assert!(pieces.len() >= 40);
    }

    #[test]
    fn closed_ring_is_cut_into_open_pieces() {
        let ring = vec![
            Pt::new(0.0, 0.0),
            Pt::new(100.0, 0.0),
            Pt::new(100.0, 30.0),
            Pt::new(0.0, 30.0),
        ];
        let grid = Grid::new(&BBox::of(&ring), [70.0, 70.0]);
        let pieces = cut(&ring, true, &grid);
        assert_eq!(pieces.len(), 2, "{pieces:?}");
        let total: f64 = pieces.iter().map(|p| polyline_length(p, false)).sum();
        assert!((total - 260.0).abs() < 1e-9);
        for p in &pieces {
            assert!(fits(p, [70.0, 70.0]));
        }
    }
}
