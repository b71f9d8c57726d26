//! Which geometry is under the pointer: a uniform grid over the geometries' boxes, built once
//! per artwork, so that hovering a job of 10⁵ strokes looks at the few geometries near the
//! pointer, not at all of them every frame (a 239,200-stroke job spent most of its UI time in
//! that scan).

use crate::document::Geometry;
use crate::geom::{point_segment_dist, BBox, Pt};

/// A geometry whose box spans more cells than this is kept in a list every query reads, not in
/// its cells (a page-sized outline would otherwise fill the whole grid).
const CELLS_PER_GEOMETRY_MAX: usize = 64;

/// Most cells of a grid (about one per geometry up to this).
const CELLS_MAX: usize = 1 << 20;

/// The grid: cell `(i, j)` lists the geometries whose box meets it.
#[derive(Debug, Default)]
pub struct HitIndex {
    origin: Pt,
    cell_mm: f64,
    cols: usize,
    rows: usize,
    /// Cell `c` holds `items[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    items: Vec<u32>,
    /// Geometries too large for the cells.
    large: Vec<u32>,
    boxes: Vec<BBox>,
}

impl HitIndex {
    /// The index of `geometries`.
    pub fn new(geometries: &[Geometry]) -> Self {
        let boxes: Vec<BBox> = geometries.iter().map(Geometry::bbox).collect();
        let all = boxes
            .iter()
            .copied()
            .filter(|b| !b.is_empty() && b.width().is_finite() && b.height().is_finite())
            .fold(BBox::EMPTY, BBox::union);
        if all.is_empty() {
            return Self {
                boxes,
                ..Self::default()
            };
        }
        let n = boxes.len().clamp(1, CELLS_MAX) as f64;
        let (w, h) = (all.width().max(1e-6), all.height().max(1e-6));
        let cell_mm = (w * h / n)
            .sqrt()
            .max(w.max(h) / CELLS_MAX as f64)
            .max(1e-6);
        let cols = ((w / cell_mm).ceil() as usize).max(1);
        let rows = ((h / cell_mm).ceil() as usize).max(1);
        let mut index = Self {
            origin: Pt::new(all.min_x, all.min_y),
            cell_mm,
            cols,
            rows,
            boxes,
            ..Self::default()
        };
        // counting sort of (cell, geometry) pairs: two passes over the boxes
        let mut counts = vec![0_u32; cols * rows + 1];
        let mut large = Vec::new();
        for (k, b) in index.boxes.iter().enumerate() {
            match index.cell_range(b, 0.0) {
                Some((i0, i1, j0, j1))
                    if (i1 - i0 + 1) * (j1 - j0 + 1) <= CELLS_PER_GEOMETRY_MAX =>
                {
                    for j in j0..=j1 {
                        for i in i0..=i1 {
                            counts[j * cols + i + 1] += 1;
                        }
                    }
                }
                Some(_) => large.push(k as u32),
                None => {}
            }
        }
        for c in 1..counts.len() {
            counts[c] += counts[c - 1];
        }
        let mut items = vec![0_u32; counts[cols * rows] as usize];
        let mut next = counts.clone();
        for (k, b) in index.boxes.iter().enumerate() {
            if let Some((i0, i1, j0, j1)) = index.cell_range(b, 0.0) {
                if (i1 - i0 + 1) * (j1 - j0 + 1) > CELLS_PER_GEOMETRY_MAX {
                    continue;
                }
                for j in j0..=j1 {
                    for i in i0..=i1 {
                        let slot = &mut next[j * cols + i];
                        items[*slot as usize] = k as u32;
                        *slot += 1;
                    }
                }
            }
        }
        index.starts = counts;
        index.items = items;
        index.large = large;
        index
    }

    /// The cells (columns i0..=i1, rows j0..=j1) that box `b` grown by `tol_mm` meets, none when
    /// it misses the grid or is empty.
    fn cell_range(&self, b: &BBox, tol_mm: f64) -> Option<(usize, usize, usize, usize)> {
        if self.cols == 0 || b.is_empty() {
            return None;
        }
        let cell = |v: f64, o: f64, n: usize| -> Option<usize> {
            let c = ((v - o) / self.cell_mm).floor();
            c.is_finite().then(|| c.clamp(0.0, (n - 1) as f64) as usize)
        };
        let (x0, x1) = (b.min_x - tol_mm, b.max_x + tol_mm);
        let (y0, y1) = (b.min_y - tol_mm, b.max_y + tol_mm);
        let max_x = self.origin.x + self.cell_mm * self.cols as f64;
        let max_y = self.origin.y + self.cell_mm * self.rows as f64;
        if x1 < self.origin.x || y1 < self.origin.y || x0 > max_x || y0 > max_y {
            return None;
        }
        Some((
            cell(x0, self.origin.x, self.cols)?,
            cell(x1, self.origin.x, self.cols)?,
            cell(y0, self.origin.y, self.rows)?,
            cell(y1, self.origin.y, self.rows)?,
        ))
    }

    /// The geometry of `geometries` (the ones indexed) nearest to `p` within `tol_mm`.
    pub fn nearest(&self, geometries: &[Geometry], p: Pt, tol_mm: f64) -> Option<usize> {
        let probe = BBox {
            min_x: p.x,
            min_y: p.y,
            max_x: p.x,
            max_y: p.y,
        };
        let mut best: Option<(f64, usize)> = None;
        let mut consider = |k: usize| {
            let (Some(g), Some(b)) = (geometries.get(k), self.boxes.get(k)) else {
                return;
            };
            if p.x < b.min_x - tol_mm
                || p.x > b.max_x + tol_mm
                || p.y < b.min_y - tol_mm
                || p.y > b.max_y + tol_mm
            {
                return;
            }
            let d = distance_mm(g, p);
            // ties to the lower index, whatever order the cells give
            let better = best.is_none_or(|(bd, bk)| d < bd || (d == bd && k < bk));
            if d <= tol_mm && better {
                best = Some((d, k));
            }
        };
        self.large.iter().for_each(|&k| consider(k as usize));
        if let Some((i0, i1, j0, j1)) = self.cell_range(&probe, tol_mm) {
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let c = j * self.cols + i;
                    let (a, z) = (self.starts[c] as usize, self.starts[c + 1] as usize);
                    self.items[a..z].iter().for_each(|&k| consider(k as usize));
                }
            }
        }
        best.map(|b| b.1)
    }
}

/// Distance from `p` to geometry `g` (its points; closed: with the closing segment), mm.
pub fn distance_mm(g: &Geometry, p: Pt) -> f64 {
    let n = g.points.len();
    match n {
        0 => f64::INFINITY,
        1 => p.dist(g.points[0]),
        _ => {
            let segs = if g.closed { n } else { n - 1 };
            (0..segs)
                .map(|i| point_segment_dist(p, g.points[i], g.points[(i + 1) % n]))
                .fold(f64::INFINITY, f64::min)
        }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used)]
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The grid finds what a scan of every geometry finds: small strokes, a page-sized outline
    /// (kept apart from the cells), dots, pointers outside the artwork.
    #[test]
    fn nearest_is_the_brute_force_answer() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut geoms: Vec<Geometry> = (0..2000)
            .map(|_| {
                let a = Pt::new(rng.random_range(0.0..100.0), rng.random_range(0.0..100.0));
                let b = Pt::new(
                    a.x + rng.random_range(-2.0..2.0),
                    a.y + rng.random_range(-2.0..2.0),
                );
                Geometry::new(vec![a, b], false, Default::default())
            })
            .collect();
        geoms.push(Geometry::new(
            vec![
                Pt::new(-5.0, -5.0),
                Pt::new(105.0, -5.0),
                Pt::new(105.0, 105.0),
                Pt::new(-5.0, 105.0),
            ],
            true,
            Default::default(),
        ));
        geoms.push(Geometry::new(
            vec![Pt::new(50.0, 50.0)],
            false,
            Default::default(),
        ));
        let index = HitIndex::new(&geoms);
        assert!(!index.large.is_empty());
        for _ in 0..3000 {
            let p = Pt::new(
                rng.random_range(-20.0..120.0),
                rng.random_range(-20.0..120.0),
            );
            let tol = rng.random_range(0.01..3.0);
            let brute = geoms
                .iter()
                .enumerate()
                .map(|(k, g)| (distance_mm(g, p), k))
                .filter(|&(d, _)| d <= tol)
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
                .map(|(_, k)| k);
            assert_eq!(
                index.nearest(&geoms, p, tol),
                brute,
                "at {p:?} within {tol}"
            );
        }
        assert_eq!(
            HitIndex::new(&[]).nearest(&[], Pt::new(0.0, 0.0), 1.0),
            None
        );
    }
}
