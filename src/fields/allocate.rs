//! Allocation: each geometry to exactly one of the fields that hold it.
//!
//! Geometries held by one field go to it. For a geometry held by several, seed 000 §3.1's rule:
//! the field that already holds the geometry nearest to it (centroid distance), so that neighbours
//! are marked together; when none of its fields holds anything yet, the field with the nearest
//! centre. A uniform grid over the allocated centroids keeps the nearest search local.

use super::INSIDE_EPS_MM;
use crate::document::{Geometry, ScanField};
use crate::geom::grid::{expand, BucketGrid, SCAN_MAX_ITEMS};
use crate::geom::{BBox, Pt};
use std::collections::HashMap;

/// The outcome of an allocation.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Allocation {
    /// Geometries no field holds.
    pub uncovered: Vec<usize>,
}

struct Grid {
    cell_mm: f64,
    cells: HashMap<(i64, i64), Vec<(usize, usize)>>,
}

impl Grid {
    fn key(&self, p: Pt) -> (i64, i64) {
        (
            (p.x / self.cell_mm).floor() as i64,
            (p.y / self.cell_mm).floor() as i64,
        )
    }
    fn insert(&mut self, p: Pt, geometry: usize, field_slot: usize) {
        let k = self.key(p);
        self.cells
            .entry(k)
            .or_default()
            .push((geometry, field_slot));
    }
    /// Nearest allocated geometry (within `max_mm`) lying in one of `slots`: its field slot.
    fn nearest(&self, p: Pt, slots: &[usize], centroids: &[Pt], max_mm: f64) -> Option<usize> {
        let (cx, cy) = self.key(p);
        let max_ring = (max_mm / self.cell_mm).ceil() as i64 + 1;
        let mut best: Option<(f64, usize, usize)> = None;
        for ring in 0..=max_ring {
            // every cell on this ring is at least (ring - 1) cells away
            if let Some((d, _, _)) = best {
                if d.sqrt() < (ring - 1).max(0) as f64 * self.cell_mm {
                    break;
                }
            }
            for dx in -ring..=ring {
                for dy in -ring..=ring {
                    if dx.abs() != ring && dy.abs() != ring {
                        continue;
                    }
                    let Some(list) = self.cells.get(&(cx + dx, cy + dy)) else {
                        continue;
                    };
                    for &(g, slot) in list {
                        if slots.contains(&slot) {
                            let d = p.dist2(centroids[g]);
                            let cand = (d, g, slot);
                            if best.is_none_or(|b| (cand.0, cand.1) < (b.0, b.1)) {
                                best = Some(cand);
                            }
                        }
                    }
                }
            }
        }
        best.map(|b| b.2)
    }
}

/// Margin of the field look-up, mm (well above [`INSIDE_EPS_MM`]).
const LOOKUP_MARGIN_MM: f64 = 1e-6;

/// Fields (slots into `fields`, ascending) holding each geometry wholly. With many fields, the
/// fields that may hold a geometry are looked up in a grid over the field squares (by the
/// geometry's bounding-box corner); a geometry without a finite box checks every field.
pub fn holders(geometries: &[Geometry], fields: &[ScanField]) -> Vec<Vec<usize>> {
    let boxes: Vec<BBox> = fields.iter().map(ScanField::bbox).collect();
    if boxes.len() <= SCAN_MAX_ITEMS {
        return geometries
            .iter()
            .map(|g| {
                let b = g.bbox();
                (0..boxes.len())
                    .filter(|&k| boxes[k].contains_box(&b, INSIDE_EPS_MM))
                    .collect()
            })
            .collect();
    }
    let bounds = boxes.iter().fold(BBox::EMPTY, |acc, b| acc.union(*b));
    let cell_mm = fields.iter().fold([0.0f64; 2], |acc, f| {
        [acc[0].max(f.size[0]), acc[1].max(f.size[1])]
    });
    let mut grid = BucketGrid::new(
        (bounds.min_x, bounds.max_x),
        (bounds.min_y, bounds.max_y),
        cell_mm,
    );
    for (k, fb) in boxes.iter().enumerate() {
        grid.insert(
            k,
            expand((fb.min_x, fb.max_x), LOOKUP_MARGIN_MM),
            expand((fb.min_y, fb.max_y), LOOKUP_MARGIN_MM),
        );
    }
    let all: Vec<usize> = (0..boxes.len()).collect();
    let mut near = Vec::new();
    geometries
        .iter()
        .map(|g| {
            let b = g.bbox();
            let candidates = if b.min_x.is_finite() && b.min_y.is_finite() {
                grid.query((b.min_x, b.min_x), (b.min_y, b.min_y), &mut near);
                &near
            } else {
                &all
            };
            candidates
                .iter()
                .copied()
                .filter(|&k| boxes[k].contains_box(&b, INSIDE_EPS_MM))
                .collect()
        })
        .collect()
}

/// Allocates every geometry to one field holding it (rule above), rewriting
/// `ScanField::geometries`; returns the geometries no field holds.
pub fn allocate(geometries: &[Geometry], fields: &mut [ScanField]) -> Allocation {
    for f in fields.iter_mut() {
        f.geometries.clear();
    }
    let held = holders(geometries, fields);
    let centroids: Vec<Pt> = geometries.iter().map(Geometry::centroid).collect();
    let cell_mm = fields
        .first()
        .map(|f| (f.size[0].max(f.size[1]) / 8.0).max(0.5))
        .unwrap_or(10.0);
    let mut grid = Grid {
        cell_mm,
        cells: HashMap::new(),
    };
    let mut out = Allocation::default();
    let mut multi = Vec::new();
    for (g, h) in held.iter().enumerate() {
        match h.len() {
            0 => out.uncovered.push(g),
            1 => {
                fields[h[0]].geometries.push(g);
                grid.insert(centroids[g], g, h[0]);
            }
            _ => multi.push(g),
        }
    }
    let reach = fields
        .first()
        .map(|f| f.size[0].hypot(f.size[1]))
        .unwrap_or(100.0);
    for g in multi {
        let slots = &held[g];
        let slot = grid
            .nearest(centroids[g], slots, &centroids, reach)
            .unwrap_or_else(|| {
                *slots
                    .iter()
                    .min_by(|&&a, &&b| {
                        centroids[g]
                            .dist2(fields[a].center)
                            .total_cmp(&centroids[g].dist2(fields[b].center))
                            .then(a.cmp(&b))
                    })
                    .unwrap_or(&slots[0])
            });
        fields[slot].geometries.push(g);
        grid.insert(centroids[g], g, slot);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::tests_support::rect;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The previous [`holders`]: every field checked for every geometry.
    fn holders_reference(geometries: &[Geometry], fields: &[ScanField]) -> Vec<Vec<usize>> {
        let boxes: Vec<BBox> = fields.iter().map(ScanField::bbox).collect();
        geometries
            .iter()
            .map(|g| {
                let b = g.bbox();
                boxes
                    .iter()
                    .enumerate()
                    .filter(|(_, fb)| fb.contains_box(&b, INSIDE_EPS_MM))
                    .map(|(k, _)| k)
                    .collect()
            })
            .collect()
    }

    #[test]
    fn holders_with_the_grid_match_checking_every_field() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for round in 0..20 {
            let f = rng.random_range(2..80) as f64;
            // coarse positions: geometries often touch field borders exactly
            let c = |rng: &mut ChaCha8Rng| rng.random_range(-20..320) as f64 * 0.5;
            let mut gs: Vec<Geometry> = (0..200)
                .map(|_| {
                    let (x, y) = (c(&mut rng), c(&mut rng));
                    let w = rng.random_range(0..=(f as i32)) as f64 * 0.5;
                    rect(x, y, w, w * 0.5)
                })
                .collect();
            gs.push(Geometry::new(Vec::new(), false, Default::default()));
            let mut fs: Vec<ScanField> = (0..rng.random_range(1..150))
                .map(|k| field(k, c(&mut rng), c(&mut rng)))
                .collect();
            for fl in &mut fs {
                fl.size = [
                    f,
                    f * if rng.random_range(0..2) == 0 {
                        1.0
                    } else {
                        0.5
                    },
                ];
            }
            assert_eq!(
                holders(&gs, &fs),
                holders_reference(&gs, &fs),
                "round {round}"
            );
            assert_eq!(holders(&gs, &[]), holders_reference(&gs, &[]));
        }
    }

    fn field(id: usize, x: f64, y: f64) -> ScanField {
        ScanField {
            id,
            center: Pt::new(x, y),
            size: [70.0, 70.0],
            locked: false,
            geometries: vec![],
            pose: Default::default(),
        }
    }

    #[test]
    fn shared_geometry_goes_to_its_neighbours_field() {
        // fields side by side overlapping in x 50..90; geometry 2 sits in the overlap, next to 1
        let gs = vec![
            rect(20.0, 10.0, 2.0, 2.0),
            rect(95.0, 10.0, 2.0, 2.0),
            rect(80.0, 10.0, 2.0, 2.0),
            rect(300.0, 300.0, 1.0, 1.0),
        ];
        let mut fs = vec![field(0, 50.0, 35.0), field(1, 85.0, 35.0)];
        let a = allocate(&gs, &mut fs);
        assert_eq!(a.uncovered, vec![3]);
        assert_eq!(fs[0].geometries, vec![0]);
        assert_eq!(fs[1].geometries, vec![1, 2]);
    }
}
