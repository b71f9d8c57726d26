//! Positions for fields whose groups are fixed: least overlap first, then most centred.
//!
//! Each field may sit anywhere in its group's feasible rectangle. Coordinate descent moves one
//! field at a time to the best position against the others held still. The overlap of one square
//! with its neighbours is piecewise bilinear in the centre, with breaks where the squares' edges
//! meet (`c ± size`) or centres align, so its minimum over the rectangle lies on the grid of those
//! breaks and the rectangle's bounds; the content centre joins the grid so that, among the
//! least-overlap positions, the one nearest the centre of the field's geometries is found too.

use super::cover::FRect;
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

/// Moves each centre within its rectangle to reduce overlap, then towards its target (the centre
/// of its content). Deterministic; at most `rounds` passes.
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
            let mut xs = vec![r.x.lo, r.x.hi, targets[i].x];
            let mut ys = vec![r.y.lo, r.y.hi, targets[i].y];
            for &j in &near {
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
                (ov, p.dist2(targets[i]))
            };
            let better = |a: (f64, f64), b: (f64, f64)| {
                a.0 < b.0 - 1e-6 || (a.0 <= b.0 + 1e-6 && a.1 < b.1 - 1e-9)
            };
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
            if best.1 != c[i] {
                c[i] = best.1;
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
