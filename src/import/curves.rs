//! Curves of the DXF import, flattened within a chord tolerance with a guarantee, as for SVG:
//! elliptical arcs (circles, arcs, bulges and ellipses under any affine map) and NURBS.
//!
//! * An elliptical arc `C(t) = c + u·cos t + v·sin t` has `‖C''(t)‖ ≤ σ`, the largest singular
//!   value of `[u v]`, so `n ≥ |Δt| · √(σ / (8·tol))` equal parameter steps keep every curve point
//!   within `tol` of its chord (`dev ≤ h²/8 · max‖C''‖`, as in [`crate::geom`]'s Béziers).
//! * A NURBS curve is split into rational Bézier pieces by knot insertion; a piece is cut in
//!   halves until all its control points lie within `tol` of the chord between its ends. With
//!   positive weights the piece lies in the convex hull of its control points, and the distance
//!   to the chord is convex, so then the whole piece is within `tol` of the chord.

use crate::geom::{point_segment_dist, Pt};

/// Upper bound on the chords of one arc (guards against absurd inputs; with coordinates under
/// [`super::dxf`]'s 1 km limit and a chord tolerance of 1 µm a full circle needs ~2.2 · 10⁶).
const MAX_ARC_CHORDS: f64 = 4.0e6;
/// Depth limit of the Bézier halving (2⁻³⁰ of a piece: far below any tolerance met in mm).
const MAX_SPLIT_DEPTH: u32 = 30;

/// A 2-D affine map `(x, y) ↦ (a·x + c·y + e, b·x + d·y + f)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    /// Linear part, column-major `[a, b, c, d]`, then the translation `[e, f]`.
    pub m: [f64; 6],
}

impl Affine {
    /// The identity.
    pub const IDENTITY: Affine = Affine {
        m: [1.0, 0.0, 0.0, 1.0, 0.0, 0.0],
    };
    /// A translation.
    pub fn translate(dx: f64, dy: f64) -> Affine {
        Affine {
            m: [1.0, 0.0, 0.0, 1.0, dx, dy],
        }
    }
    /// A scaling about the origin.
    pub fn scale(sx: f64, sy: f64) -> Affine {
        Affine {
            m: [sx, 0.0, 0.0, sy, 0.0, 0.0],
        }
    }
    /// A rotation about the origin, counter-clockwise (y up) by `rad`.
    pub fn rotate(rad: f64) -> Affine {
        let (s, c) = rad.sin_cos();
        Affine {
            m: [c, s, -s, c, 0.0, 0.0],
        }
    }
    /// `self ∘ o`: first `o`, then `self`.
    pub fn then(self, o: Affine) -> Affine {
        let [a, b, c, d, e, f] = self.m;
        let [p, q, r, s, t, u] = o.m;
        Affine {
            m: [
                a * p + c * q,
                b * p + d * q,
                a * r + c * s,
                b * r + d * s,
                a * t + c * u + e,
                b * t + d * u + f,
            ],
        }
    }
    /// Maps a point.
    pub fn apply(&self, p: Pt) -> Pt {
        let [a, b, c, d, e, f] = self.m;
        Pt::new(a * p.x + c * p.y + e, b * p.x + d * p.y + f)
    }
    /// Maps a vector (no translation).
    pub fn apply_vec(&self, p: Pt) -> Pt {
        let [a, b, c, d, _, _] = self.m;
        Pt::new(a * p.x + c * p.y, b * p.x + d * p.y)
    }
}

/// Largest singular value of the 2 × 2 matrix with columns `u`, `v`.
fn max_singular(u: Pt, v: Pt) -> f64 {
    let s = u.dot(u) + v.dot(v);
    let det = u.x * v.y - u.y * v.x;
    ((s + (s * s - 4.0 * det * det).max(0.0).sqrt()) / 2.0).sqrt()
}

/// An elliptical arc `c + u·cos t + v·sin t` for `t` from `t0` to `t1` (either direction).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConicArc {
    /// Centre.
    pub c: Pt,
    /// First semi-axis vector (not necessarily orthogonal to `v` after an affine map).
    pub u: Pt,
    /// Second semi-axis vector.
    pub v: Pt,
    /// Start parameter, rad.
    pub t0: f64,
    /// End parameter, rad.
    pub t1: f64,
}

impl ConicArc {
    /// A circular arc of radius `r` from angle `a0` sweeping `sweep` (rad, counter-clockwise
    /// positive, y up).
    pub fn circle(c: Pt, r: f64, a0: f64, sweep: f64) -> ConicArc {
        ConicArc {
            c,
            u: Pt::new(r, 0.0),
            v: Pt::new(0.0, r),
            t0: a0,
            t1: a0 + sweep,
        }
    }
    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> Pt {
        let (s, c) = t.sin_cos();
        self.c.plus(self.u.scale(c)).plus(self.v.scale(s))
    }
    /// The arc under an affine map (an ellipse stays an ellipse).
    pub fn mapped(&self, a: &Affine) -> ConicArc {
        ConicArc {
            c: a.apply(self.c),
            u: a.apply_vec(self.u),
            v: a.apply_vec(self.v),
            ..*self
        }
    }
    /// Appends the flattened arc to `out`, excluding its start point.
    pub fn flatten(&self, tol_mm: f64, out: &mut Vec<Pt>) {
        let sigma = max_singular(self.u, self.v);
        let dt = self.t1 - self.t0;
        let n = (dt.abs() * (sigma / (8.0 * tol_mm.max(1e-9))).sqrt()).ceil();
        let n = if n.is_finite() {
            n.clamp(1.0, MAX_ARC_CHORDS) as usize
        } else {
            1
        };
        for i in 1..=n {
            out.push(self.at(self.t0 + dt * i as f64 / n as f64));
        }
    }
}

/// The circular arc of a polyline bulge from `p0` to `p1` (`bulge = tan(θ/4)`, counter-clockwise
/// positive): `None` for a straight segment.
pub fn bulge_arc(p0: Pt, p1: Pt, bulge: f64) -> Option<ConicArc> {
    let chord = p1.minus(p0);
    let d = chord.norm();
    if bulge == 0.0 || !bulge.is_finite() || d == 0.0 {
        return None;
    }
    let sweep = 4.0 * bulge.atan();
    let half = sweep / 2.0;
    let r = d / (2.0 * half.sin().abs());
    // the centre lies on the chord's left normal, (d/2)/tan(θ/2) from its midpoint
    let normal = Pt::new(-chord.y / d, chord.x / d);
    let c = p0
        .plus(p1)
        .scale(0.5)
        .plus(normal.scale(d / 2.0 / half.tan()));
    let a0 = (p0.y - c.y).atan2(p0.x - c.x);
    Some(ConicArc::circle(c, r, a0, sweep))
}

/// A NURBS curve in homogeneous coordinates `(w·x, w·y, w)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Nurbs {
    /// Degree ≥ 1.
    pub degree: usize,
    /// Knot vector, `control.len() + degree + 1` non-decreasing values.
    pub knots: Vec<f64>,
    /// Weighted control points.
    pub control: Vec<[f64; 3]>,
}

/// Why a spline cannot be used.
pub type SplineProblem = &'static str;

impl Nurbs {
    /// Checks the definition: degree, counts, knot order, positive finite weights.
    pub fn new(
        degree: usize,
        knots: Vec<f64>,
        points: &[Pt],
        weights: &[f64],
    ) -> Result<Nurbs, SplineProblem> {
        if degree == 0 {
            return Err("degree 0");
        }
        if points.len() <= degree {
            return Err("fewer control points than degree + 1");
        }
        if knots.len() != points.len() + degree + 1 {
            return Err("knot count is not control points + degree + 1");
        }
        if knots.iter().any(|k| !k.is_finite()) || knots.windows(2).any(|w| w[1] < w[0]) {
            return Err("knots are not finite and non-decreasing");
        }
        if !weights.is_empty() && weights.len() != points.len() {
            return Err("weight count differs from control point count");
        }
        if weights.iter().any(|w| !(w.is_finite() && *w > 0.0)) {
            return Err("a weight is not a positive number");
        }
        if knots[degree] >= knots[points.len()] {
            return Err("empty parameter domain");
        }
        let control = points
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let w = weights.get(i).copied().unwrap_or(1.0);
                [p.x * w, p.y * w, w]
            })
            .collect();
        Ok(Nurbs {
            degree,
            knots,
            control,
        })
    }

    /// The point at `u` in the domain (de Boor), for tests.
    #[cfg(test)]
    pub fn at(&self, u: f64) -> Pt {
        let p = self.degree;
        let n = self.control.len();
        let u = u.clamp(self.knots[p], self.knots[n]);
        let k = self.span(u);
        let mut d: Vec<[f64; 3]> = (0..=p).map(|j| self.control[j + k - p]).collect();
        for r in 1..=p {
            for j in (r..=p).rev() {
                let i = j + k - p;
                let den = self.knots[i + p + 1 - r] - self.knots[i];
                let a = if den > 0.0 {
                    (u - self.knots[i]) / den
                } else {
                    0.0
                };
                d[j] = lerp3(d[j - 1], d[j], a);
            }
        }
        dehom(d[p])
    }

    /// The last non-empty knot span `[u_k, u_k+1)` of the domain starting at or before `u` (the
    /// domain's end belongs to the last span).
    fn span(&self, u: f64) -> usize {
        let p = self.degree;
        (p..self.control.len())
            .rev()
            .find(|&j| self.knots[j] <= u && self.knots[j] < self.knots[j + 1])
            .unwrap_or(p)
    }

    /// Inserts knot `u` once (Boehm).
    fn insert(&mut self, u: f64) {
        let p = self.degree;
        let n = self.control.len();
        let k = self.span(u);
        let mut q = Vec::with_capacity(n + 1);
        q.extend_from_slice(&self.control[..=k - p]);
        for i in k - p + 1..=k {
            let den = self.knots[i + p] - self.knots[i];
            let a = if den > 0.0 {
                (u - self.knots[i]) / den
            } else {
                0.0
            };
            q.push(lerp3(self.control[i - 1], self.control[i], a));
        }
        q.extend_from_slice(&self.control[k..]);
        self.control = q;
        self.knots.insert(k + 1, u);
    }

    /// The rational Bézier pieces of the curve over its domain, in order: each non-empty knot
    /// span is cut out with its own `p + 1` control points and `2p + 2` knots and its knots
    /// raised to multiplicity `p` there, so the cost is linear in the number of spans.
    pub fn bezier_pieces(&self) -> Vec<Vec<[f64; 3]>> {
        let p = self.degree;
        (p..self.control.len())
            .filter(|&k| self.knots[k] < self.knots[k + 1])
            .filter_map(|k| {
                let mut local = Nurbs {
                    degree: p,
                    knots: self.knots[k - p..=k + p + 1].to_vec(),
                    control: self.control[k - p..=k].to_vec(),
                };
                for v in [local.knots[p], local.knots[p + 1]] {
                    let mult = local.knots.iter().filter(|&&x| x == v).count();
                    for _ in mult..p {
                        local.insert(v);
                    }
                }
                let k = local.span(local.knots[p]);
                local.control.get(k - p..=k).map(<[_]>::to_vec)
            })
            .collect()
    }

    /// The flattened curve: one polyline, or several where the knots make it jump (a knot of
    /// multiplicity above the degree; CAD programs do not write those, but files may hold them).
    /// More than `max_points` vertices is an error (absurd weights or tolerances).
    pub fn flatten(&self, tol_mm: f64, max_points: usize) -> Result<Vec<Vec<Pt>>, &'static str> {
        let mut paths: Vec<Vec<Pt>> = Vec::new();
        let mut budget = Budget {
            left: max_points,
            tol: tol_mm.max(1e-9),
        };
        for piece in self.bezier_pieces() {
            let Some(&start) = piece.first() else {
                continue;
            };
            let start = dehom(start);
            let joined = paths
                .last()
                .and_then(|p| p.last())
                .is_some_and(|q| q.dist(start) <= 1e-9);
            if !joined {
                paths.push(vec![start]);
            }
            if let Some(path) = paths.last_mut() {
                flatten_rational_bezier(&piece, &mut budget, 0, path)?;
            }
        }
        Ok(paths)
    }
}

/// What a NURBS flattening may still spend.
struct Budget {
    left: usize,
    tol: f64,
}

fn lerp3(a: [f64; 3], b: [f64; 3], t: f64) -> [f64; 3] {
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

fn dehom(h: [f64; 3]) -> Pt {
    Pt::new(h[0] / h[2], h[1] / h[2])
}

/// Appends the piece's end, or its halves', until it is within the tolerance of its chord.
fn flatten_rational_bezier(
    ctrl: &[[f64; 3]],
    budget: &mut Budget,
    depth: u32,
    out: &mut Vec<Pt>,
) -> Result<(), &'static str> {
    let (Some(&first), Some(&last)) = (ctrl.first(), ctrl.last()) else {
        return Ok(());
    };
    let (a, b) = (dehom(first), dehom(last));
    let flat = ctrl
        .iter()
        .all(|&h| point_segment_dist(dehom(h), a, b) <= budget.tol);
    if flat || depth >= MAX_SPLIT_DEPTH {
        budget.left = budget
            .left
            .checked_sub(1)
            .ok_or("the spline needs too many vertices")?;
        out.push(b);
        return Ok(());
    }
    // de Casteljau at t = 1/2 in homogeneous coordinates
    let mut left = Vec::with_capacity(ctrl.len());
    let mut right = Vec::with_capacity(ctrl.len());
    let mut row = ctrl.to_vec();
    while let Some(&h) = row.first() {
        left.push(h);
        if let Some(&t) = row.last() {
            right.push(t);
        }
        row = row.windows(2).map(|w| lerp3(w[0], w[1], 0.5)).collect();
    }
    right.reverse();
    flatten_rational_bezier(&left, budget, depth + 1, out)?;
    flatten_rational_bezier(&right, budget, depth + 1, out)
}

/// The cubic interpolating spline through `fit_points` (repeated points dropped) (chord-length parameters, C²), with end
/// tangent directions when given (else natural ends), as Bézier control points per span:
/// `[p0, p1, p2, p3]`.
pub fn fit_point_spline(
    fit_points: &[Pt],
    start_tangent: Option<Pt>,
    end_tangent: Option<Pt>,
) -> Vec<[Pt; 4]> {
    // repeated fit points would make a zero-length parameter step
    let mut fit: Vec<Pt> = Vec::with_capacity(fit_points.len());
    for &p in fit_points {
        if fit.last().is_none_or(|q| q.dist(p) > 1e-9) {
            fit.push(p);
        }
    }
    let n = fit.len();
    if n < 2 {
        return Vec::new();
    }
    let h: Vec<f64> = fit.windows(2).map(|w| w[0].dist(w[1])).collect();
    // tridiagonal system in the first derivatives m_i (per coordinate, shared matrix)
    let mut lower = vec![0.0; n];
    let mut diag = vec![0.0; n];
    let mut upper = vec![0.0; n];
    let mut rhs = vec![Pt::default(); n];
    let slope = |i: usize| fit[i + 1].minus(fit[i]).scale(1.0 / h[i]);
    match start_tangent {
        Some(t) => (diag[0], rhs[0]) = (1.0, unit(t)),
        None => (diag[0], upper[0], rhs[0]) = (2.0, 1.0, slope(0).scale(3.0)),
    }
    for i in 1..n - 1 {
        lower[i] = h[i];
        diag[i] = 2.0 * (h[i - 1] + h[i]);
        upper[i] = h[i - 1];
        rhs[i] = slope(i - 1)
            .scale(3.0 * h[i])
            .plus(slope(i).scale(3.0 * h[i - 1]));
    }
    match end_tangent {
        Some(t) => (diag[n - 1], rhs[n - 1]) = (1.0, unit(t)),
        None => (lower[n - 1], diag[n - 1], rhs[n - 1]) = (1.0, 2.0, slope(n - 2).scale(3.0)),
    }
    let m = solve_tridiagonal(&lower, &diag, &upper, rhs);
    (0..n - 1)
        .map(|i| {
            let k = h[i] / 3.0;
            [
                fit[i],
                fit[i].plus(m[i].scale(k)),
                fit[i + 1].minus(m[i + 1].scale(k)),
                fit[i + 1],
            ]
        })
        .collect()
}

fn unit(p: Pt) -> Pt {
    let n = p.norm();
    if n > 0.0 {
        p.scale(1.0 / n)
    } else {
        p
    }
}

/// Thomas algorithm (diagonally dominant systems here, so no pivoting).
fn solve_tridiagonal(lower: &[f64], diag: &[f64], upper: &[f64], mut rhs: Vec<Pt>) -> Vec<Pt> {
    let n = diag.len();
    let mut c = vec![0.0; n];
    let mut d = diag.to_vec();
    for i in 1..n {
        let w = lower[i] / d[i - 1];
        d[i] -= w * upper[i - 1];
        rhs[i] = rhs[i].minus(rhs[i - 1].scale(w));
    }
    let mut x = vec![Pt::default(); n];
    x[n - 1] = rhs[n - 1].scale(1.0 / d[n - 1]);
    for i in (0..n - 1).rev() {
        c[i] = upper[i];
        x[i] = rhs[i].minus(x[i + 1].scale(c[i])).scale(1.0 / d[i]);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn dist_to_polyline(p: Pt, pts: &[Pt]) -> f64 {
        pts.windows(2)
            .map(|w| point_segment_dist(p, w[0], w[1]))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn bulge_one_is_a_semicircle_to_the_right() {
        let a = bulge_arc(Pt::new(0.0, 0.0), Pt::new(2.0, 0.0), 1.0).unwrap();
        assert!(a.c.dist(Pt::new(1.0, 0.0)) < 1e-12);
        // counter-clockwise from (0,0) to (2,0) passes below the chord (y up)
        assert!(a.at((a.t0 + a.t1) / 2.0).dist(Pt::new(1.0, -1.0)) < 1e-12);
        assert!(a.at(a.t1).dist(Pt::new(2.0, 0.0)) < 1e-12);
    }

    #[test]
    fn clamped_cubic_is_its_bezier() {
        let pts = [
            Pt::new(0.0, 0.0),
            Pt::new(1.0, 2.0),
            Pt::new(3.0, 2.0),
            Pt::new(4.0, 0.0),
        ];
        let s = Nurbs::new(3, vec![0., 0., 0., 0., 1., 1., 1., 1.], &pts, &[]).unwrap();
        let (t, u) = (0.3, 0.7);
        let b = pts[0]
            .scale(u * u * u)
            .plus(pts[1].scale(3.0 * u * u * t))
            .plus(pts[2].scale(3.0 * u * t * t))
            .plus(pts[3].scale(t * t * t));
        assert!(s.at(0.3).dist(b) < 1e-12);
        assert_eq!(s.bezier_pieces().len(), 1);
    }

    #[test]
    fn fit_spline_passes_through_its_points() {
        let fit = [
            Pt::new(0.0, 0.0),
            Pt::new(10.0, 5.0),
            Pt::new(20.0, 0.0),
            Pt::new(25.0, 10.0),
        ];
        let spans = fit_point_spline(&fit, None, Some(Pt::new(0.0, 1.0)));
        assert_eq!(spans.len(), 3);
        for (i, s) in spans.iter().enumerate() {
            assert_eq!(s[0], fit[i]);
            assert_eq!(s[3], fit[i + 1]);
        }
        // C¹ at the joints, end tangent as asked
        let d = spans[0][3].minus(spans[0][2]);
        let e = spans[1][1].minus(spans[1][0]);
        assert!((d.x * e.y - d.y * e.x).abs() < 1e-9 && d.dot(e) > 0.0);
        let end = spans[2][3].minus(spans[2][2]);
        assert!(end.x.abs() < 1e-12 && end.y > 0.0);
    }

    fn coord() -> impl Strategy<Value = f64> {
        -100.0f64..100.0
    }

    proptest! {
        #[test]
        fn arcs_stay_within_tolerance(
            c in proptest::array::uniform6(coord()),
            t0 in -7.0f64..7.0,
            sweep in -7.0f64..7.0,
            tol in 0.001f64..1.0,
        ) {
            let arc = ConicArc {
                c: Pt::new(c[0], c[1]),
                u: Pt::new(c[2], c[3]),
                v: Pt::new(c[4], c[5]),
                t0,
                t1: t0 + sweep,
            };
            let mut out = vec![arc.at(t0)];
            arc.flatten(tol, &mut out);
            for i in 0..=500 {
                let q = arc.at(t0 + sweep * i as f64 / 500.0);
                let d = dist_to_polyline(q, &out);
                prop_assert!(d <= tol * (1.0 + 1e-9) + 1e-9, "deviation {} > {}", d, tol);
            }
        }

        #[test]
        fn nurbs_stay_within_tolerance(
            pts in proptest::collection::vec((coord(), coord(), 0.2f64..5.0), 4..9),
            degree in 1usize..4,
            gaps in proptest::collection::vec(0u8..3, 12),
            tol in 0.001f64..1.0,
        ) {
            let ctrl: Vec<Pt> = pts.iter().map(|p| Pt::new(p.0, p.1)).collect();
            let weights: Vec<f64> = pts.iter().map(|p| p.2).collect();
            // unclamped knots with repeated values (gap 0)
            let mut knots = vec![0.0];
            for i in 1..ctrl.len() + degree + 1 {
                let last = knots[i - 1];
                knots.push(last + f64::from(gaps[i % gaps.len()]));
            }
            let Ok(s) = Nurbs::new(degree, knots, &ctrl, &weights) else {
                return Ok(());
            };
            let paths = s.flatten(tol, 1_000_000).unwrap();
            let (lo, hi) = (s.knots[degree], s.knots[ctrl.len()]);
            let (first, last) = (&paths[0], &paths[paths.len() - 1]);
            prop_assert!(first[0].dist(s.at(lo)) < 1e-6);
            prop_assert!(last[last.len() - 1].dist(s.at(hi)) < 1e-6);
            for i in 0..=500 {
                let q = s.at(lo + (hi - lo) * i as f64 / 500.0);
                let d = paths
                    .iter()
                    .map(|p| if p.len() == 1 { q.dist(p[0]) } else { dist_to_polyline(q, p) })
                    .fold(f64::INFINITY, f64::min);
                prop_assert!(d <= tol * (1.0 + 1e-9) + 1e-7, "deviation {} > {}", d, tol);
            }
        }
    }
}
