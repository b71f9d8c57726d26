//! Tilings: the grid of cells that cuts artwork larger than a scan field into field-sized
//! pieces, chosen for the fewest cuts.
//!
//! A tiling is a list of cell borders per axis. Its inner borders are the *seams*: every cut of
//! an oversize stroke lies on one (or within its band, see [`super::seam`]). The cells are
//! never wider than `cell_max_mm`, so a field centred on a cell holds every piece in it.
//!
//! # Choice
//! The number of cells per axis is the fewest that fit, `n = ⌈extent / cell_max⌉`, so the grid
//! has the fewest fields a grid can have. The `n − 1` seams of an axis are then placed by dynamic
//! programming over positions `TILING_STEPS` apart across the extent: the cost of a seam at `c`
//! is the number of stroke segments it crosses (each a cut) plus [`SMALL_CROSS_WEIGHT`] per
//! geometry that would have to be marked whole across it, plus a tie-break of
//! [`CENTRING_WEIGHT_PER_MM`] per mm from the even split. Consecutive seams are at most
//! `cell_max` apart. A vertical seam's cost depends on x alone and a horizontal one's on y alone,
//! so the two axes are chosen apart and the sum is the grid's least cost (over the positions
//! tried: the step is `extent / TILING_STEPS`, at most 0.015 mm on a 300 mm stroke).
//! Seams so fall in gaps — between glyphs, between islands of a fill — and, in a solid fill,
//! split the cells evenly.

use super::{BBox, Pt};
use serde::{Deserialize, Serialize};

/// Positions tried per axis.
pub const TILING_STEPS: usize = 20_000;
/// Cost of a seam through a geometry that is not cut (it must be marked whole in one field, which
/// may cost a field of its own), in cuts.
pub const SMALL_CROSS_WEIGHT: f64 = 20.0;
/// Tie-break between seams of equal cuts: cost per mm away from the even split, in cuts (a cut
/// saved is worth 1 m of shift).
pub const CENTRING_WEIGHT_PER_MM: f64 = 1e-3;

/// Cell borders per axis (ascending; the first and last are the tiled extent).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tiling {
    /// Column borders (x, mm).
    pub xs: Vec<f64>,
    /// Row borders (y, mm).
    pub ys: Vec<f64>,
}

/// What a tiling is chosen over: a polyline and how it weighs a seam through it.
#[derive(Debug, Clone, Copy)]
pub struct TilingInput<'a> {
    /// Vertices, mm.
    pub points: &'a [Pt],
    /// Whether it returns to its first vertex.
    pub closed: bool,
    /// True: it is cut at seams (each crossing costs one cut). False: it is marked whole, and a
    /// seam through its box costs [`SMALL_CROSS_WEIGHT`].
    pub cut: bool,
}

impl Tiling {
    /// The grid of cells `cell_mm` wide anchored at the extent's lower corner (the last cell of
    /// each axis takes what is left): a tiling chosen by nothing but its corner.
    pub fn anchored(extent: BBox, cell_mm: [f64; 2]) -> Tiling {
        let axis = |lo: f64, hi: f64, cell: f64| -> Vec<f64> {
            let mut v = vec![lo];
            if cell > 0.0 && cell.is_finite() {
                let mut k = 1.0;
                while lo + k * cell < hi {
                    v.push(lo + k * cell);
                    k += 1.0;
                }
            }
            v.push(hi);
            v
        };
        Tiling {
            xs: axis(extent.min_x, extent.max_x, cell_mm[0]),
            ys: axis(extent.min_y, extent.max_y, cell_mm[1]),
        }
    }

    /// Borders of `axis` (0: x, 1: y).
    pub fn borders(&self, axis: usize) -> &[f64] {
        if axis == 0 {
            &self.xs
        } else {
            &self.ys
        }
    }

    /// The inner borders of `axis`: its seams.
    pub fn seams(&self, axis: usize) -> &[f64] {
        let b = self.borders(axis);
        if b.len() <= 2 {
            &[]
        } else {
            &b[1..b.len() - 1]
        }
    }

    /// The tiled extent.
    pub fn extent(&self) -> BBox {
        let first = |v: &[f64]| v.first().copied().unwrap_or(0.0);
        let last = |v: &[f64]| v.last().copied().unwrap_or(0.0);
        BBox {
            min_x: first(&self.xs),
            min_y: first(&self.ys),
            max_x: last(&self.xs),
            max_y: last(&self.ys),
        }
    }

    /// Cells per axis.
    pub fn cells(&self) -> [usize; 2] {
        [
            self.xs.len().saturating_sub(1).max(1),
            self.ys.len().saturating_sub(1).max(1),
        ]
    }

    /// The seams moved by `shift_mm` per axis: a shifted pass's tiling. Seams pushed off one
    /// end come back at the other end, one mean cell width beyond the last; a gap still wider
    /// than `cell_max_mm` is split evenly. The extent is unchanged.
    pub fn shifted(&self, shift_mm: [f64; 2], cell_max_mm: [f64; 2]) -> Tiling {
        let axis = |v: &[f64], d: f64, cmax: f64| -> Vec<f64> {
            let (Some(&lo), Some(&hi)) = (v.first(), v.last()) else {
                return v.to_vec();
            };
            let cells = v.len().saturating_sub(1).max(1);
            let pitch = (hi - lo) / cells as f64;
            if d == 0.0 || cells == 1 || pitch.is_nan() || pitch <= 0.0 {
                return v.to_vec();
            }
            let mut seams: Vec<f64> = v[1..v.len() - 1].iter().map(|s| s + d).collect();
            while let Some(&f) = seams.first().filter(|&&f| f - pitch > lo) {
                seams.insert(0, f - pitch);
            }
            while let Some(&l) = seams.last().filter(|&&l| l + pitch < hi) {
                seams.push(l + pitch);
            }
            seams.retain(|&s| s > lo && s < hi);
            let mut out = vec![lo];
            seams.push(hi);
            for s in seams {
                let last = out.last().copied().unwrap_or(lo);
                let parts = ((s - last) / cmax).ceil().max(1.0) as usize;
                for k in 1..parts {
                    out.push(last + (s - last) * k as f64 / parts as f64);
                }
                out.push(s);
            }
            out
        };
        Tiling {
            xs: axis(&self.xs, shift_mm[0], cell_max_mm[0]),
            ys: axis(&self.ys, shift_mm[1], cell_max_mm[1]),
        }
    }
}

/// Chooses the tiling of `extent` with cells at most `cell_max_mm` that cuts `inputs` least (see
/// the module notes).
pub fn choose_tiling(inputs: &[TilingInput], extent: BBox, cell_max_mm: [f64; 2]) -> Tiling {
    let xs = choose_axis(inputs, extent.min_x, extent.max_x, cell_max_mm[0], 0);
    let ys = choose_axis(inputs, extent.min_y, extent.max_y, cell_max_mm[1], 1);
    Tiling { xs, ys }
}

/// The cost of a seam at each of the positions `lo + i·h`, `i < bins`.
fn seam_costs(inputs: &[TilingInput], axis: usize, lo: f64, h: f64, bins: usize) -> Vec<f64> {
    // difference array over bins: an interval (a, b) strictly crossed adds weight to every
    // position inside it
    let mut diff = vec![0.0; bins + 1];
    let coord = |p: Pt| if axis == 0 { p.x } else { p.y };
    let mut add = |a: f64, b: f64, w: f64| {
        let (a, b) = (a.min(b), a.max(b));
        // positions p with a < p ≤ b (a vertex on a seam is cut once, at its first segment)
        let first = (((a - lo) / h).floor() + 1.0).max(0.0);
        let last = ((b - lo) / h).floor().min((bins - 1) as f64);
        if first <= last {
            diff[first as usize] += w;
            diff[last as usize + 1] -= w;
        }
    };
    for input in inputs {
        if input.cut {
            let n = input.points.len();
            let segs = if input.closed { n } else { n.saturating_sub(1) };
            for k in 0..segs {
                let (a, b) = (input.points[k], input.points[(k + 1) % n]);
                add(coord(a), coord(b), 1.0);
            }
        } else {
            let b = BBox::of(input.points);
            let (a, z) = if axis == 0 {
                (b.min_x, b.max_x)
            } else {
                (b.min_y, b.max_y)
            };
            add(a, z, SMALL_CROSS_WEIGHT);
        }
    }
    let mut run = 0.0;
    diff[..bins]
        .iter()
        .map(|d| {
            run += d;
            run
        })
        .collect()
}

/// The borders of one axis (see the module notes).
fn choose_axis(inputs: &[TilingInput], lo: f64, hi: f64, cell_max: f64, axis: usize) -> Vec<f64> {
    let width = hi - lo;
    // NaN-safe: anything but a finite extent wider than a positive cell is one cell
    if !matches!(
        width.partial_cmp(&cell_max),
        Some(std::cmp::Ordering::Greater)
    ) || !matches!(
        cell_max.partial_cmp(&0.0),
        Some(std::cmp::Ordering::Greater)
    ) {
        return vec![lo, hi];
    }
    let n = (width / cell_max).ceil() as usize;
    let bins = TILING_STEPS + 1;
    let h = width / TILING_STEPS as f64;
    // whole steps within a cell (rounded down: a cell is never wider than cell_max)
    let reach = ((cell_max / h) * (1.0 - 1e-12)).floor() as usize;
    if reach == 0 {
        return vec![lo, hi];
    }
    let costs = seam_costs(inputs, axis, lo, h, bins);
    // best[k][i]: least cost of seams 1..=k with seam k at position i; from[k][i]: seam k-1's
    const NONE: f64 = f64::INFINITY;
    let mut prev = vec![NONE; bins];
    prev[0] = 0.0;
    let mut from: Vec<Vec<u32>> = Vec::with_capacity(n - 1);
    for k in 1..n {
        let ideal = k as f64 * width / n as f64;
        let mut cur = vec![NONE; bins];
        let mut back = vec![0u32; bins];
        // sliding minimum of prev over j in [i - reach, i - 1]
        let mut window: std::collections::VecDeque<usize> = std::collections::VecDeque::new();
        for i in 1..bins - 1 {
            let j = i - 1;
            while window.back().is_some_and(|&b| prev[b] >= prev[j]) {
                window.pop_back();
            }
            window.push_back(j);
            while window.front().is_some_and(|&f| f + reach < i) {
                window.pop_front();
            }
            let Some(&best) = window.front() else {
                continue;
            };
            if prev[best].is_finite() {
                let off = (i as f64 * h - ideal).abs();
                cur[i] = prev[best] + costs[i] + CENTRING_WEIGHT_PER_MM * off;
                back[i] = best as u32;
            }
        }
        from.push(back);
        prev = cur;
    }
    // the last seam within one cell of the far end
    let last = bins - 1;
    let end = (last.saturating_sub(reach)..last)
        .filter(|&i| prev[i].is_finite())
        .min_by(|&a, &b| prev[a].total_cmp(&prev[b]));
    let Some(mut i) = end else {
        // unreachable for n = ⌈width / cell_max⌉ cells; even cells as the fallback
        return (0..=n).map(|k| lo + k as f64 * width / n as f64).collect();
    };
    let mut seams = Vec::with_capacity(n - 1);
    for back in from.iter().rev() {
        seams.push(lo + i as f64 * h);
        i = back[i] as usize;
    }
    seams.reverse();
    let mut borders = Vec::with_capacity(n + 1);
    borders.push(lo);
    borders.extend(seams);
    borders.push(hi);
    borders
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line(a: (f64, f64), b: (f64, f64)) -> Vec<Pt> {
        vec![Pt::new(a.0, a.1), Pt::new(b.0, b.1)]
    }

    #[test]
    fn solid_fill_is_split_evenly_with_the_fewest_cells() {
        // 240 mm of horizontal lines: 4 columns of 60 mm
        let lines: Vec<Vec<Pt>> = (0..100)
            .map(|k| line((0.0, k as f64), (240.0, k as f64)))
            .collect();
        let inputs: Vec<TilingInput> = lines
            .iter()
            .map(|p| TilingInput {
                points: p,
                closed: false,
                cut: true,
            })
            .collect();
        let ext = BBox {
            min_x: 0.0,
            min_y: 0.0,
            max_x: 240.0,
            max_y: 99.0,
        };
        let t = choose_tiling(&inputs, ext, [69.0, 69.0]);
        assert_eq!(t.cells(), [4, 2]);
        for (k, s) in t.seams(0).iter().enumerate() {
            assert!((s - 60.0 * (k + 1) as f64).abs() < 0.05, "{:?}", t.xs);
        }
        for w in t.xs.windows(2).chain(t.ys.windows(2)) {
            assert!(w[1] - w[0] <= 69.0 + 1e-9);
        }
    }

    #[test]
    fn seams_fall_in_gaps() {
        // two blocks of short strokes with a gap at x ∈ (42.5, 45), off the even split at 55: the seam goes there
        let mut strokes = Vec::new();
        for k in 0..110 {
            let x = k as f64;
            if (42.0..45.0).contains(&x) {
                continue;
            }
            strokes.push(line((x, 2.0), (x + 1.5, 8.0)));
        }
        // plus a long horizontal line that is cut wherever the seam is
        strokes.push(line((0.0, 5.0), (110.0, 5.0)));
        let inputs: Vec<TilingInput> = strokes
            .iter()
            .enumerate()
            .map(|(k, p)| TilingInput {
                points: p,
                closed: false,
                cut: k + 1 == strokes.len(),
            })
            .collect();
        let ext = BBox {
            min_x: 0.0,
            min_y: 0.0,
            max_x: 110.0,
            max_y: 10.0,
        };
        let t = choose_tiling(&inputs, ext, [69.0, 69.0]);
        assert_eq!(t.seams(0).len(), 1);
        let s = t.seams(0)[0];
        assert!((42.5..=45.0).contains(&s), "{s}");
    }

    #[test]
    fn a_shift_moves_every_seam_and_keeps_the_extent() {
        let t = Tiling {
            xs: vec![0.0, 60.0, 120.0, 180.0],
            ys: vec![0.0, 50.0],
        };
        let s = t.shifted([30.0, 0.0], [69.0, 69.0]);
        assert_eq!(s.xs, vec![0.0, 30.0, 90.0, 150.0, 180.0]);
        assert_eq!(s.ys, t.ys);
    }
}
