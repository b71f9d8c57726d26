//! Positions for fields whose groups are fixed: least overlap first, then most centred.
//!
//! Each field may sit anywhere in its group's feasible rectangle. Coordinate descent moves one
//! field at a time to the best position against the others held still. The overlap of one square
//! with its neighbours is piecewise bilinear in the centre, with breaks where the squares' edges
//! meet (`c ± size`) or centres align, so its minimum over the rectangle lies on the grid of those
//! breaks and the rectangle's bounds; the content centre joins the grid so that, among the
//! least-overlap positions, the one nearest the centre of the field's geometries is found too.

use super::cover::FRect;
use crate::geom::grid::{expand, BucketGrid, SCAN_MAX_ITEMS};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};

/// Overlap area of two squares of size `f` with centres `a`, `b`, mm².
fn pair_overlap(a: Pt, b: Pt, f: [f64; 2]) -> f64 {
    (f[0] - (a.x - b.x).abs()).max(0.0) * (f[1] - (a.y - b.y).abs()).max(0.0)
}

/// Total pairwise overlap of the fields, mm².
pub fn total_overlap(centers: &[Pt], f: [f64; 2]) -> f64 {
    let mut s = 0.0;
    for i in 0..centers.len() {
        for j in i + 1..centers.len() {
            s += pair_overlap(centers[i], centers[j], f);
        }
    }
    s
}

/// The best position for field `i` in its rectangle `r` against its neighbours `near` held
/// still: least overlap (within 10⁻⁶ mm²), then nearest to `target`; the current position when
/// nothing is strictly better. The candidates are the grid of overlap breaks (see the module).
fn best_spot(i: usize, c: &[Pt], near: &[usize], r: &FRect, target: Pt, field: [f64; 2]) -> Pt {
    let mut xs = vec![r.x.lo, r.x.hi, target.x];
    let mut ys = vec![r.y.lo, r.y.hi, target.y];
    for &j in near {
        xs.extend([c[j].x - field[0], c[j].x, c[j].x + field[0]]);
        ys.extend([c[j].y - field[1], c[j].y, c[j].y + field[1]]);
    }
    let mut xs: Vec<f64> = xs.into_iter().map(|v| r.x.clamp(v)).collect();
    let mut ys: Vec<f64> = ys.into_iter().map(|v| r.y.clamp(v)).collect();
    xs.sort_by(f64::total_cmp);
    xs.dedup();
    ys.sort_by(f64::total_cmp);
    ys.dedup();
    let score = |p: Pt| -> (f64, f64) {
        let ov: f64 = near.iter().map(|&j| pair_overlap(p, c[j], field)).sum();
        (ov, p.dist2(target))
    };
    let better =
        |a: (f64, f64), b: (f64, f64)| a.0 < b.0 - 1e-6 || (a.0 <= b.0 + 1e-6 && a.1 < b.1 - 1e-9);
    let mut best = (score(c[i]), c[i]);
    for &x in &xs {
        for &y in &ys {
            let p = Pt::new(x, y);
            let s = score(p);
            if better(s, best.0) {
                best = (s, p);
            }
        }
    }
    best.1
}

/// Relative slack of the grid look-up window, so that rounding never hides a neighbour.
const WINDOW_SLACK: f64 = 1e-9;
/// Absolute slack of the grid look-up window, mm.
const WINDOW_SLACK_MM: f64 = 1e-9;

/// Moves each centre within its rectangle to reduce overlap, then towards its target (the centre
/// of its content). Deterministic; at most `rounds` passes. The fields near the one moving are
/// looked up in a grid over the current centres.
pub fn place(
    rects: &[FRect],
    targets: &[Pt],
    field: [f64; 2],
    rounds: usize,
    ctx: &JobCtx,
) -> Result<Vec<Pt>, Cancelled> {
    let clamp = |r: &FRect, p: Pt| Pt::new(r.x.clamp(p.x), r.y.clamp(p.y));
    let mut c: Vec<Pt> = rects
        .iter()
        .zip(targets)
        .map(|(r, &t)| clamp(r, t))
        .collect();
    let n = c.len();
    let bounds = c.iter().fold(
        (
            (f64::INFINITY, f64::NEG_INFINITY),
            (f64::INFINITY, f64::NEG_INFINITY),
        ),
        |(x, y), p| ((x.0.min(p.x), x.1.max(p.x)), (y.0.min(p.y), y.1.max(p.y))),
    );
    // few fields are scanned instead
    let mut grid = (n > SCAN_MAX_ITEMS).then(|| {
        let mut grid = BucketGrid::new(bounds.0, bounds.1, [2.0 * field[0], 2.0 * field[1]]);
        for (i, p) in c.iter().enumerate() {
            grid.insert(i, (p.x, p.x), (p.y, p.y));
        }
        grid
    });
    let mut cand = Vec::new();
    for _ in 0..rounds {
        ctx.check()?;
        let mut moved = false;
        for i in 0..n {
            let r = &rects[i];
            let reach = [
                2.0 * field[0] + (r.x.hi - r.x.lo),
                2.0 * field[1] + (r.y.hi - r.y.lo),
            ];
            let window = |v: f64, w: f64| {
                expand((v, v), w.max(0.0) * (1.0 + WINDOW_SLACK) + WINDOW_SLACK_MM)
            };
            match &grid {
                Some(grid) => grid.query(
                    window(c[i].x, reach[0]),
                    window(c[i].y, reach[1]),
                    &mut cand,
                ),
                None => {
                    cand.clear();
                    cand.extend(0..n);
                }
            }
            let near: Vec<usize> = cand
                .iter()
                .copied()
                .filter(|&j| {
                    j != i
                        && (c[j].x - c[i].x).abs() < reach[0]
                        && (c[j].y - c[i].y).abs() < reach[1]
                })
                .collect();
            let best = best_spot(i, &c, &near, r, targets[i], field);
            if best != c[i] {
                if let Some(grid) = &mut grid {
                    grid.remove(i, (c[i].x, c[i].x), (c[i].y, c[i].y));
                    grid.insert(i, (best.x, best.x), (best.y, best.y));
                }
                c[i] = best;
                moved = true;
            }
        }
        if !moved {
            break;
        }
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::reach::Span;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The previous [`place`]: every other field checked for nearness.
    /// Moves each centre within its rectangle to reduce overlap, then towards its target (the centre
    /// of its content). Deterministic; at most `rounds` passes.
    fn place_reference(
        rects: &[FRect],
        targets: &[Pt],
        field: [f64; 2],
        rounds: usize,
        ctx: &JobCtx,
    ) -> Result<Vec<Pt>, Cancelled> {
        let clamp = |r: &FRect, p: Pt| Pt::new(r.x.clamp(p.x), r.y.clamp(p.y));
        let mut c: Vec<Pt> = rects
            .iter()
            .zip(targets)
            .map(|(r, &t)| clamp(r, t))
            .collect();
        let n = c.len();
        for _ in 0..rounds {
            ctx.check()?;
            let mut moved = false;
            for i in 0..n {
                let r = &rects[i];
                let near: Vec<usize> = (0..n)
                    .filter(|&j| {
                        j != i
                            && (c[j].x - c[i].x).abs() < 2.0 * field[0] + (r.x.hi - r.x.lo)
                            && (c[j].y - c[i].y).abs() < 2.0 * field[1] + (r.y.hi - r.y.lo)
                    })
                    .collect();
                let best = best_spot(i, &c, &near, r, targets[i], field);
                if best != c[i] {
                    c[i] = best;
                    moved = true;
                }
            }
            if !moved {
                break;
            }
        }
        Ok(c)
    }

    #[test]
    fn place_with_the_grid_matches_checking_every_field() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let ctx = JobCtx::default();
        for round in 0..30 {
            let f = rng.random_range(1..40) as f64;
            let n = rng.random_range(1..120);
            let span = |rng: &mut ChaCha8Rng| {
                let lo = rng.random_range(0..300) as f64;
                Span {
                    lo,
                    hi: lo + rng.random_range(0..=(f as i32)) as f64 * 0.5,
                }
            };
            let rects: Vec<FRect> = (0..n)
                .map(|_| FRect {
                    x: span(&mut rng),
                    y: span(&mut rng),
                })
                .collect();
            let targets: Vec<Pt> = rects
                .iter()
                .map(|r| {
                    Pt::new(
                        r.x.lo + rng.random_range(-2.0..2.0) * f,
                        r.y.lo + rng.random_range(-2.0..2.0) * f,
                    )
                })
                .collect();
            let fast = place(&rects, &targets, [f, f * 0.75], 30, &ctx).unwrap();
            let slow = place_reference(&rects, &targets, [f, f * 0.75], 30, &ctx).unwrap();
            assert_eq!(fast, slow, "round {round}");
        }
    }

    #[test]
    fn two_fields_slide_apart_then_centre() {
        let rect = |lo: f64, hi: f64| FRect {
            x: Span { lo, hi },
            y: Span { lo: 50.0, hi: 50.0 },
        };
        // both want to sit at x = 60 (overlap 70 × 70), each can slide 20 mm
        let rects = [rect(40.0, 60.0), rect(60.0, 80.0)];
        let targets = [Pt::new(60.0, 50.0), Pt::new(60.0, 50.0)];
        let c = place(&rects, &targets, [70.0, 70.0], 10, &JobCtx::default()).unwrap();
        assert_eq!((c[0].x, c[1].x), (40.0, 80.0));
        assert!(total_overlap(&c, [70.0, 70.0]) < 30.0 * 70.0 + 1e-9);
    }
}
