//! A uniform grid of buckets over the plane, for local queries on boxes and points (mm).
//!
//! An item is registered in every cell its (closed) box touches; a query returns every item
//! registered in a cell the query box touches — a superset of the items whose boxes meet the
//! query box, which the caller filters with its exact test. The cell of a coordinate is a
//! monotone function of it (values outside the grid fall into the border cells), so two boxes
//! that share a point always share a cell: no item is missed, whatever the rounding.

/// Up to this many items a scan of all of them costs less than building and asking a grid.
pub(crate) const SCAN_MAX_ITEMS: usize = 64;
/// Most cells along one axis (larger extents get larger cells).
const MAX_CELLS_PER_AXIS: usize = 256;
/// Smallest cell side, mm.
const MIN_CELL_MM: f64 = 1e-6;

/// Closed interval `[lo, hi]` of one axis (either order is accepted).
pub(crate) type Range1 = (f64, f64);

fn ordered((a, b): Range1) -> Range1 {
    if a <= b {
        (a, b)
    } else {
        (b, a)
    }
}

/// The interval `r` (either order) grown by `margin` on both sides, low end first.
pub(crate) fn expand(r: Range1, margin: f64) -> Range1 {
    let (lo, hi) = ordered(r);
    (lo - margin, hi + margin)
}

/// Uniform grid of buckets holding item ids.
#[derive(Debug, Clone)]
pub(crate) struct BucketGrid {
    x0: f64,
    y0: f64,
    cell_x_mm: f64,
    cell_y_mm: f64,
    nx: usize,
    ny: usize,
    buckets: Vec<Vec<usize>>,
}

impl BucketGrid {
    /// An empty grid over `x` × `y` with cells of about `cell_mm` (enlarged so that no axis has
    /// more than [`MAX_CELLS_PER_AXIS`] cells). Non-finite input gives a single cell.
    pub(crate) fn new(x: Range1, y: Range1, cell_mm: [f64; 2]) -> Self {
        let axis = |r: Range1, cell: f64| -> (f64, f64, usize) {
            let (lo, hi) = ordered(r);
            let extent = hi - lo;
            if !lo.is_finite() || !extent.is_finite() {
                return (0.0, 1.0, 1);
            }
            let cell = if cell.is_finite() { cell } else { extent };
            let cell = cell
                .max(extent / MAX_CELLS_PER_AXIS as f64)
                .max(MIN_CELL_MM);
            let n = ((extent / cell).floor() as usize + 1).clamp(1, MAX_CELLS_PER_AXIS);
            (lo, cell, n)
        };
        let (x0, cell_x_mm, nx) = axis(x, cell_mm[0]);
        let (y0, cell_y_mm, ny) = axis(y, cell_mm[1]);
        BucketGrid {
            x0,
            y0,
            cell_x_mm,
            cell_y_mm,
            nx,
            ny,
            buckets: vec![Vec::new(); nx * ny],
        }
    }

    /// A grid of one cell holding everything.
    pub(crate) fn single() -> Self {
        BucketGrid::new((0.0, 0.0), (0.0, 0.0), [1.0, 1.0])
    }

    /// Column of `x` (monotone in `x`).
    pub(crate) fn col(&self, x: f64) -> usize {
        Self::index(x, self.x0, self.cell_x_mm, self.nx)
    }

    /// Row of `y` (monotone in `y`).
    pub(crate) fn row(&self, y: f64) -> usize {
        Self::index(y, self.y0, self.cell_y_mm, self.ny)
    }

    fn index(v: f64, v0: f64, cell: f64, n: usize) -> usize {
        let k = ((v - v0) / cell).floor();
        if k.is_nan() || k <= 0.0 {
            0
        } else {
            (k as usize).min(n - 1)
        }
    }

    /// Number of cells.
    pub(crate) fn len(&self) -> usize {
        self.buckets.len()
    }

    /// Cell id of column `c`, row `r`.
    pub(crate) fn cell(&self, c: usize, r: usize) -> usize {
        r * self.nx + c
    }

    /// Column and row of cell `id`.
    pub(crate) fn col_row(&self, id: usize) -> (usize, usize) {
        (id % self.nx, id / self.nx)
    }

    /// Cells touched by the box `x` × `y`, in increasing id order.
    pub(crate) fn cells_of(&self, x: Range1, y: Range1) -> impl Iterator<Item = usize> + '_ {
        let (x, y) = (ordered(x), ordered(y));
        let (c0, c1) = (self.col(x.0), self.col(x.1));
        let (r0, r1) = (self.row(y.0), self.row(y.1));
        (r0..=r1).flat_map(move |r| (c0..=c1).map(move |c| self.cell(c, r)))
    }

    /// Registers `id` in every cell the box touches.
    pub(crate) fn insert(&mut self, id: usize, x: Range1, y: Range1) {
        let cells: Vec<usize> = self.cells_of(x, y).collect();
        for k in cells {
            self.buckets[k].push(id);
        }
    }

    /// Unregisters `id` from the cells of the box it was inserted with.
    pub(crate) fn remove(&mut self, id: usize, x: Range1, y: Range1) {
        let cells: Vec<usize> = self.cells_of(x, y).collect();
        for k in cells {
            if let Some(p) = self.buckets[k].iter().position(|&q| q == id) {
                self.buckets[k].swap_remove(p);
            }
        }
    }

    /// Items registered in cell `id`.
    pub(crate) fn bucket(&self, id: usize) -> &[usize] {
        &self.buckets[id]
    }

    /// Mutable items of cell `id`.
    pub(crate) fn bucket_mut(&mut self, id: usize) -> &mut Vec<usize> {
        &mut self.buckets[id]
    }

    /// Every item registered in a cell the box touches, ascending, without repeats (`out` is
    /// cleared first).
    pub(crate) fn query(&self, x: Range1, y: Range1, out: &mut Vec<usize>) {
        out.clear();
        for k in self.cells_of(x, y) {
            out.extend_from_slice(&self.buckets[k]);
        }
        out.sort_unstable();
        out.dedup();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn meets(a: (Range1, Range1), b: (Range1, Range1)) -> bool {
        let ((ax, ay), (bx, by)) = ((ordered(a.0), ordered(a.1)), (ordered(b.0), ordered(b.1)));
        ax.0 <= bx.1 && bx.0 <= ax.1 && ay.0 <= by.1 && by.0 <= ay.1
    }

    #[test]
    fn query_finds_every_meeting_box() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for round in 0..20 {
            let cell = [rng.random_range(0.5..20.0), rng.random_range(0.5..20.0)];
            // coarse coordinates so that boxes often touch exactly at cell borders
            let coord = |rng: &mut ChaCha8Rng| (rng.random_range(-40..340) as f64) * 0.5;
            let boxes: Vec<(Range1, Range1)> = (0..300)
                .map(|_| {
                    let (x, y) = (coord(&mut rng), coord(&mut rng));
                    let (w, h) = (
                        rng.random_range(0..30) as f64,
                        rng.random_range(0..30) as f64,
                    );
                    ((x, x + w), (y + h, y)) // y given high-low on purpose
                })
                .collect();
            let mut g = BucketGrid::new((0.0, 150.0), (10.0, 140.0), cell);
            for (i, b) in boxes.iter().enumerate() {
                g.insert(i, b.0, b.1);
            }
            // moving some of them keeps the answers right
            for i in (0..boxes.len()).step_by(7) {
                g.remove(i, boxes[i].0, boxes[i].1);
            }
            let live = |i: usize| i % 7 != 0;
            let mut out = Vec::new();
            for _ in 0..200 {
                let (x, y) = (coord(&mut rng), coord(&mut rng));
                let q = ((x, x + rng.random_range(0..10) as f64), (y, y));
                g.query(q.0, q.1, &mut out);
                let brute: Vec<usize> = (0..boxes.len())
                    .filter(|&i| live(i) && meets(boxes[i], q))
                    .collect();
                let found: Vec<usize> = out
                    .iter()
                    .copied()
                    .filter(|&i| meets(boxes[i], q))
                    .collect();
                assert_eq!(found, brute, "round {round}");
                assert!(out.iter().all(|&i| live(i)));
            }
        }
    }
}
