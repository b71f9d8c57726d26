//! Which geometry is under the pointer: the geometries' boxes in a [`BucketGrid`], built once per
//! artwork, so that hovering a job of 10⁵ strokes looks at the few geometries near the pointer,
//! not at all of them every frame (a 239,200-stroke job spent most of its UI time in that scan).

use crate::document::Geometry;
use crate::geom::grid::{expand, BucketGrid};
use crate::geom::{point_segment_dist, BBox, Pt};

/// The geometries' boxes and the grid over them.
#[derive(Debug)]
pub struct HitIndex {
    grid: BucketGrid,
    boxes: Vec<BBox>,
}

impl HitIndex {
    /// The index of `geometries` (cells of about the mean spacing of the geometries).
    pub fn new(geometries: &[Geometry]) -> Self {
        let boxes: Vec<BBox> = geometries.iter().map(Geometry::bbox).collect();
        let all = boxes
            .iter()
            .copied()
            .filter(|b| !b.is_empty())
            .fold(BBox::EMPTY, BBox::union);
        let mut grid = if all.is_empty() {
            BucketGrid::single()
        } else {
            let cell_mm = (all.width() * all.height() / boxes.len().max(1) as f64).sqrt();
            BucketGrid::new((all.min_x, all.max_x), (all.min_y, all.max_y), [cell_mm; 2])
        };
        for (k, b) in boxes.iter().enumerate().filter(|(_, b)| !b.is_empty()) {
            grid.insert(k, (b.min_x, b.max_x), (b.min_y, b.max_y));
        }
        Self { grid, boxes }
    }

    /// The geometry of `geometries` (the ones indexed) nearest to `p` within `tol_mm`.
    pub fn nearest(&self, geometries: &[Geometry], p: Pt, tol_mm: f64) -> Option<usize> {
        let mut near = Vec::new();
        self.grid.query(
            expand((p.x, p.x), tol_mm),
            expand((p.y, p.y), tol_mm),
            &mut near,
        );
        let mut best: Option<(f64, usize)> = None;
        // ascending indices: a tie goes to the lower one
        for k in near {
            let (Some(g), Some(b)) = (geometries.get(k), self.boxes.get(k)) else {
                continue;
            };
            if p.x < b.min_x - tol_mm
                || p.x > b.max_x + tol_mm
                || p.y < b.min_y - tol_mm
                || p.y > b.max_y + tol_mm
            {
                continue;
            }
            let d = distance_mm(g, p);
            if d <= tol_mm && best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, k));
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

    /// The grid finds what a scan of every geometry finds: small strokes, a page-sized outline,
    /// dots, pointers outside the artwork.
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
