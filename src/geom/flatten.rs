//! Flattening of quadratic and cubic Bézier segments into polylines within a chord tolerance.
//!
//! The number of chords comes from the classic bound on the distance between a curve and its
//! chord over a parameter interval of length `h`: `dev ≤ h²/8 · max‖B''‖`. For a cubic
//! `‖B''‖ ≤ 6·max(‖p0−2p1+p2‖, ‖p1−2p2+p3‖)`, for a quadratic `B'' = 2(p0−2p1+p2)`. Splitting the
//! parameter range into `n` equal steps with `n ≥ sqrt(max‖B''‖ / (8·tol))` therefore keeps every
//! point of the curve within `tol` of the polyline (a guarantee, not an estimate).

//!
//! The count depends on the curve's size: with every control point within ±`C` mm, the second
//! differences are at most `4√2·C`, so `n ≤ sqrt(6·4√2·C / (8·tol)) ≈ 2.06·sqrt(C/tol)`. With the
//! import's bound `C = 10⁶` mm that is `2,100/√tol` (21,000 chords at 0.01 mm). Callers with a
//! budget ask [`quad_chords`] / [`cubic_chords`] first and refuse a curve that would exceed it;
//! [`MAX_CHORDS`] is only the last guard for callers without one.

use super::Pt;

/// Last-resort cap on the chords of one segment, above what any curve within ±10⁶ mm needs at
/// a 10⁻⁶ mm tolerance (2.1·10⁶): bounded input never reaches it, so the tolerance holds.
pub const MAX_CHORDS: usize = 4_000_000;

/// Chords for a second-derivative bound; `usize::MAX` when it is not finite.
fn chords_for(second_derivative_bound: f64, tol_mm: f64) -> usize {
    let tol = tol_mm.max(1e-9);
    let n = (second_derivative_bound / (8.0 * tol)).sqrt().ceil();
    if n.is_finite() {
        (n as usize).max(1)
    } else {
        usize::MAX
    }
}

/// The chords a flattening makes: one (the end point) for a curve that is not finite, at most
/// [`MAX_CHORDS`].
fn capped(n: usize) -> usize {
    if n == usize::MAX {
        1
    } else {
        n.min(MAX_CHORDS)
    }
}

/// Chords [`flatten_quad`] makes for this quadratic (before its [`MAX_CHORDS`] cap).
pub fn quad_chords(p0: Pt, p1: Pt, p2: Pt, tol_mm: f64) -> usize {
    chords_for(p0.minus(p1.scale(2.0)).plus(p2).norm() * 2.0, tol_mm)
}

/// Chords [`flatten_cubic`] makes for this cubic (before its [`MAX_CHORDS`] cap).
pub fn cubic_chords(p0: Pt, p1: Pt, p2: Pt, p3: Pt, tol_mm: f64) -> usize {
    let a = p0.minus(p1.scale(2.0)).plus(p2).norm();
    let b = p1.minus(p2.scale(2.0)).plus(p3).norm();
    chords_for(6.0 * a.max(b), tol_mm)
}

/// Appends the flattened quadratic Bézier `p0`–`p1`–`p2` to `out`, excluding `p0`.
pub fn flatten_quad(p0: Pt, p1: Pt, p2: Pt, tol_mm: f64, out: &mut Vec<Pt>) {
    let n = capped(quad_chords(p0, p1, p2, tol_mm));
    for i in 1..=n {
        let t = i as f64 / n as f64;
        let u = 1.0 - t;
        out.push(
            p0.scale(u * u)
                .plus(p1.scale(2.0 * u * t))
                .plus(p2.scale(t * t)),
        );
    }
}

/// Appends the flattened cubic Bézier `p0`–`p1`–`p2`–`p3` to `out`, excluding `p0`.
pub fn flatten_cubic(p0: Pt, p1: Pt, p2: Pt, p3: Pt, tol_mm: f64, out: &mut Vec<Pt>) {
    let n = capped(cubic_chords(p0, p1, p2, p3, tol_mm));
    for i in 1..=n {
        out.push(cubic_at(p0, p1, p2, p3, i as f64 / n as f64));
    }
}

/// Point of the cubic Bézier at parameter `t`.
pub fn cubic_at(p0: Pt, p1: Pt, p2: Pt, p3: Pt, t: f64) -> Pt {
    let u = 1.0 - t;
    p0.scale(u * u * u)
        .plus(p1.scale(3.0 * u * u * t))
        .plus(p2.scale(3.0 * u * t * t))
        .plus(p3.scale(t * t * t))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::point_segment_dist;
    use proptest::prelude::*;

    fn dist_to_polyline(p: Pt, start: Pt, pts: &[Pt]) -> f64 {
        let mut prev = start;
        let mut best = f64::INFINITY;
        for &q in pts {
            best = best.min(point_segment_dist(p, prev, q));
            prev = q;
        }
        best
    }

    fn coord() -> impl Strategy<Value = f64> {
        -200.0f64..200.0
    }

    proptest! {
        #[test]
        fn cubic_flattening_stays_within_tolerance(
            c in proptest::array::uniform8(coord()),
            tol in 0.001f64..1.0,
        ) {
            let [x0, y0, x1, y1, x2, y2, x3, y3] = c;
            let (p0, p1, p2, p3) = (Pt::new(x0, y0), Pt::new(x1, y1), Pt::new(x2, y2), Pt::new(x3, y3));
            let mut out = Vec::new();
            flatten_cubic(p0, p1, p2, p3, tol, &mut out);
            prop_assert!(out.last().map(|q| q.dist(p3) < 1e-9).unwrap_or(false));
            for i in 0..=400 {
                let q = cubic_at(p0, p1, p2, p3, i as f64 / 400.0);
                let d = dist_to_polyline(q, p0, &out);
                prop_assert!(d <= tol * 1.0001 + 1e-9, "deviation {} > tol {}", d, tol);
            }
        }

        #[test]
        fn quad_flattening_stays_within_tolerance(
            c in proptest::array::uniform6(coord()),
            tol in 0.001f64..1.0,
        ) {
            let [x0, y0, x1, y1, x2, y2] = c;
            let (p0, p1, p2) = (Pt::new(x0, y0), Pt::new(x1, y1), Pt::new(x2, y2));
            let mut out = Vec::new();
            flatten_quad(p0, p1, p2, tol, &mut out);
            for i in 0..=400 {
                let t = i as f64 / 400.0;
                let u = 1.0 - t;
                let q = p0.scale(u * u).plus(p1.scale(2.0 * u * t)).plus(p2.scale(t * t));
                prop_assert!(dist_to_polyline(q, p0, &out) <= tol * 1.0001 + 1e-9);
            }
        }
    }
}
