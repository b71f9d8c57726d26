//! Tracking a moving interval with bounded speed and acceleration: exact reachable sets.
//!
//! One axis of the stage must stay inside `[lower_k, upper_k]` at sample times `t_k` (the
//! scanner's reach around the tool), with `|v| ≤ v_max` and `|a| ≤ a_max`, starting at rest.
//! Between samples the acceleration is constant. The set of states `(x, v)` the axis can be in
//! at `t_k` while having kept every constraint so far is convex (the dynamics are linear and
//! the constraints convex); it is propagated exactly:
//!
//! `S_{k+1} = clip( shear(S_k) ⊕ [−d, d] )`, with `shear(x, v) = (x + v·Δt, v)`,
//! `d = (a_max·Δt²/2, a_max·Δt)` and the clip to the interval and the speed band.
//!
//! The Minkowski sum with a segment adds at most two vertices per step; where a set has more
//! than [`MAX_VERTICES`], the vertex whose removal loses the least area goes (a convex hull of
//! some of the vertices lies inside the set: every state kept is still reachable, the
//! approximation is from inside). An empty set is the first sample the tool cannot be followed
//! at ([`Unreachable`]): the caller slows the tool before it and propagates again from there.
//!
//! The route is read backwards: from a state of the last set with the least speed, each
//! earlier state is the one of `S_k` that reaches the later one with the acceleration nearest
//! to zero (the states reaching `(x', v')` from `S_k` form a segment in `u ∈ [−a, a]`). Every
//! step then keeps `|a| ≤ a_max` by construction, and `(x, v)` at each sample lies in its set.
//!
//! **Between samples.** The tool moves straight between two samples (the caller puts a sample at
//! every vertex and piece end) and the axis follows a parabola, so the offset between them
//! leaves the straight line joining its values at the samples by at most `a·Δt²/8`. The
//! interval is narrowed by that much at both its samples, so the offset stays inside
//! everywhere, not only at the samples. Where a step is long (the tool slowed, or waiting),
//! the acceleration on it is capped so that this stays within [`Limits::sag_mm`]: a long step
//! never eats the tube.

use geo::ConvexHull;
use std::fmt;

/// Most vertices a reachable set keeps (see the module documentation).
const MAX_VERTICES: usize = 24;

/// How far outside a set (state units: mm and mm/s) the backward pass still counts as inside:
/// rounding in the clip and the shear (a nanometre, below the half micrometre the tube keeps
/// free).
const ROUNDING_SLACK: f64 = 1e-6;

/// A state `(x mm, v mm/s)`.
type State = [f64; 2];

/// The axis' limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Largest speed, mm/s.
    pub v_max_mm_s: f64,
    /// Largest acceleration, mm/s².
    pub a_max_mm_s2: f64,
    /// Most the axis may leave the straight line between two samples, mm: the interval is
    /// narrowed by [`Limits::narrowing_mm`], and over a long step the acceleration is capped
    /// ([`Limits::accel_mm_s2`]) so that the parabola stays within this.
    pub sag_mm: f64,
}

impl Limits {
    /// The acceleration allowed over a step of `dt_s`: `a_max`, or less where `a·Δt²/8` would
    /// exceed the sag.
    pub fn accel_mm_s2(&self, dt_s: f64) -> f64 {
        if dt_s <= 0.0 {
            return self.a_max_mm_s2;
        }
        self.a_max_mm_s2.min(8.0 * self.sag_mm / (dt_s * dt_s))
    }

    /// How much the interval at a sample is narrowed for the parabola on a step of `dt_s` next
    /// to it: `a·Δt²/8` at the step's allowed acceleration (at most the sag).
    pub fn narrowing_mm(&self, dt_s: f64) -> f64 {
        self.accel_mm_s2(dt_s) * dt_s * dt_s / 8.0
    }
}

/// Where the tool cannot be followed: the first sample whose reachable set is empty.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unreachable {
    /// Index of the sample.
    pub sample: usize,
}

impl fmt::Display for Unreachable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the stage cannot follow the tool at sample {}",
            self.sample
        )
    }
}

/// A tracked axis: position, speed and the constant acceleration up to the next sample, at
/// every sample time. At rest at its first position before the first sample; after the last it
/// brakes at its acceleration limit.
#[derive(Debug, Clone, PartialEq)]
pub struct TrackedAxis {
    t_s: Vec<f64>,
    x_mm: Vec<f64>,
    v_mm_s: Vec<f64>,
    a_mm_s2: Vec<f64>,
    a_max_mm_s2: f64,
}

impl TrackedAxis {
    /// Position at `t_s`, mm.
    pub fn position_mm(&self, t_s: f64) -> f64 {
        let (Some(&t0), Some(&x0)) = (self.t_s.first(), self.x_mm.first()) else {
            return 0.0;
        };
        if t_s <= t0 {
            return x0;
        }
        let k = self.t_s.partition_point(|&t| t <= t_s) - 1;
        let tau = t_s - self.t_s[k];
        if k + 1 < self.t_s.len() {
            return self.x_mm[k] + self.v_mm_s[k] * tau + 0.5 * self.a_mm_s2[k] * tau * tau;
        }
        // braking after the last sample
        let (x, v) = (self.x_mm[k], self.v_mm_s[k]);
        if v == 0.0 || self.a_max_mm_s2 <= 0.0 {
            return x;
        }
        let stop_s = v.abs() / self.a_max_mm_s2;
        let tau = tau.min(stop_s);
        x + v * tau - 0.5 * v.signum() * self.a_max_mm_s2 * tau * tau
    }
}

/// The reachable sets of one axis, propagated sample by sample (see the module documentation).
#[derive(Debug, Clone, Default)]
pub struct Reachable {
    /// Vertices of all sets, counter-clockwise, one set after another.
    vertices: Vec<State>,
    /// Where each set starts in `vertices` (one more entry than sets).
    starts: Vec<usize>,
}

#[allow(clippy::len_without_is_empty)]
impl Reachable {
    /// Number of sets computed so far.
    pub fn len(&self) -> usize {
        self.starts.len().saturating_sub(1)
    }

    fn set(&self, k: usize) -> &[State] {
        &self.vertices[self.starts[k]..self.starts[k + 1]]
    }

    /// Keeps the first `n` sets.
    pub fn truncate(&mut self, n: usize) {
        if n < self.len() {
            self.starts.truncate(n + 1);
            self.vertices.truncate(self.starts[n]);
        }
    }

    fn push(&mut self, set: &[State]) {
        if self.starts.is_empty() {
            self.starts.push(0);
        }
        self.vertices.extend_from_slice(set);
        self.starts.push(self.vertices.len());
    }

    /// The first set: at rest anywhere in `[lower, upper]`.
    pub fn start(&mut self, lower_mm: f64, upper_mm: f64) -> Result<(), Unreachable> {
        self.truncate(0);
        self.vertices.clear();
        self.starts.clear();
        if lower_mm > upper_mm {
            return Err(Unreachable { sample: 0 });
        }
        self.push(&[[lower_mm, 0.0], [upper_mm, 0.0]]);
        Ok(())
    }

    /// Adds the set after `dt_s` more, inside `[lower, upper]` (already narrowed for the
    /// parabola between samples); `still`: at rest there (the set is clipped to speed zero:
    /// from one still sample to the next the acceleration is zero too, so the axis does not
    /// move at all between them).
    pub fn step(
        &mut self,
        dt_s: f64,
        lower_mm: f64,
        upper_mm: f64,
        limits: Limits,
        still: bool,
    ) -> Result<(), Unreachable> {
        let sample = self.len();
        let Some(last) = self.len().checked_sub(1) else {
            return Err(Unreachable { sample });
        };
        let a = limits.accel_mm_s2(dt_s);
        let d = [0.5 * a * dt_s * dt_s, a * dt_s];
        let sheared: Vec<State> = self
            .set(last)
            .iter()
            .map(|&[x, v]| [x + v * dt_s, v])
            .collect();
        let mut set = sum_with_segment(&sheared, d);
        set = clip(set, 0, lower_mm, true);
        set = clip(set, 0, upper_mm, false);
        let v_max_mm_s = if still { 0.0 } else { limits.v_max_mm_s };
        set = clip(set, 1, -v_max_mm_s, true);
        set = clip(set, 1, v_max_mm_s, false);
        if set.is_empty() {
            return Err(Unreachable { sample });
        }
        simplify(&mut set, MAX_VERTICES);
        self.push(&set);
        Ok(())
    }

    /// The route through all sets (`dt_s[k]` between sets `k` and `k + 1`): backwards from the
    /// slowest state of the last set, the acceleration nearest to zero at each step.
    pub fn route(&self, dt_s: &[f64], limits: Limits) -> TrackedAxis {
        let n = self.len();
        let mut t_s = Vec::with_capacity(n);
        let mut t = 0.0;
        for k in 0..n {
            t_s.push(t);
            t += dt_s.get(k).copied().unwrap_or(0.0);
        }
        let mut x_mm = vec![0.0; n];
        let mut v_mm_s = vec![0.0; n];
        let mut a_mm_s2 = vec![0.0; n];
        if n > 0 {
            let [x, v] = slowest(self.set(n - 1));
            (x_mm[n - 1], v_mm_s[n - 1]) = (x, v);
        }
        for k in (0..n.saturating_sub(1)).rev() {
            let (x1, v1, dt) = (x_mm[k + 1], v_mm_s[k + 1], dt_s[k]);
            let before = |u: f64| [x1 - v1 * dt + 0.5 * u * dt * dt, v1 - u * dt];
            let u = preimage_accel(self.set(k), before, limits.accel_mm_s2(dt));
            let [x, v] = before(u);
            (x_mm[k], v_mm_s[k], a_mm_s2[k]) = (x, v, u);
        }
        TrackedAxis {
            t_s,
            x_mm,
            v_mm_s,
            a_mm_s2,
            a_max_mm_s2: limits.a_max_mm_s2,
        }
    }
}

/// The state of `set` with the least speed (on the line `v = 0` where the set crosses it, the
/// middle of that chord).
fn slowest(set: &[State]) -> State {
    let lo = set.iter().map(|s| s[1]).fold(f64::INFINITY, f64::min);
    let hi = set.iter().map(|s| s[1]).fold(f64::NEG_INFINITY, f64::max);
    if lo <= 0.0 && hi >= 0.0 {
        let chord = clip(clip(set.to_vec(), 1, 0.0, true), 1, 0.0, false);
        let xs = chord.iter().map(|s| s[0]);
        let (a, b) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        if a <= b {
            return [(a + b) / 2.0, 0.0];
        }
    }
    set.iter()
        .copied()
        .min_by(|p, q| p[1].abs().total_cmp(&q[1].abs()))
        .unwrap_or([0.0, 0.0])
}

/// The acceleration `u ∈ [−a, a]` nearest zero with `before(u)` in `set` (an exact interval for
/// a proper polygon; where rounding leaves the interval empty, the middle of the crossed bounds;
/// otherwise the `u` that puts `before(u)` nearest the set).
fn preimage_accel(set: &[State], before: impl Fn(f64) -> State, a_max: f64) -> f64 {
    let (p0, p1) = (before(0.0), before(1.0));
    let dir = [p1[0] - p0[0], p1[1] - p0[1]];
    if dir == [0.0, 0.0] {
        // no time between the samples: the state is the same whatever the acceleration
        return 0.0;
    }
    if set.len() >= 3 {
        let (mut lo, mut hi) = (-a_max, a_max);
        for (i, &a) in set.iter().enumerate() {
            let b = set[(i + 1) % set.len()];
            let e = [b[0] - a[0], b[1] - a[1]];
            // inside: cross(e, p − a) ≥ 0, linear in u
            let c0 = e[0] * (p0[1] - a[1]) - e[1] * (p0[0] - a[0]);
            let c1 = e[0] * dir[1] - e[1] * dir[0];
            if c1 > 0.0 {
                lo = lo.max(-c0 / c1);
            } else if c1 < 0.0 {
                hi = hi.min(-c0 / c1);
            }
        }
        if lo <= hi {
            return 0.0f64.clamp(lo, hi);
        }
        // rounding: a state reached at the edge of the set (or at full acceleration) comes
        // back a few bits outside; between the crossed bounds is as near as it gets
        let mid = ((lo + hi) / 2.0).clamp(-a_max, a_max);
        if distance(set, before(mid)) <= ROUNDING_SLACK {
            return mid;
        }
    }
    // nearest: the distance from a point moving on a line to a convex set is convex in u
    let gap = |u: f64| distance(set, before(u));
    let (mut lo, mut hi) = (-a_max, a_max);
    for _ in 0..60 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if gap(m1) <= gap(m2) {
            hi = m2;
        } else {
            lo = m1;
        }
    }
    (lo + hi) / 2.0
}

/// Distance from `p` to the convex polygon `set` (0 inside), in state units.
fn distance(set: &[State], p: State) -> f64 {
    let seg = |a: State, b: State| {
        let e = [b[0] - a[0], b[1] - a[1]];
        let len2 = e[0] * e[0] + e[1] * e[1];
        let s = if len2 > 0.0 {
            (((p[0] - a[0]) * e[0] + (p[1] - a[1]) * e[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (dx, dy) = (p[0] - a[0] - s * e[0], p[1] - a[1] - s * e[1]);
        (dx * dx + dy * dy).sqrt()
    };
    match set.len() {
        0 => f64::INFINITY,
        1 => seg(set[0], set[0]),
        2 => seg(set[0], set[1]),
        n => {
            let inside = (0..n).all(|i| {
                let (a, b) = (set[i], set[(i + 1) % n]);
                (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) >= 0.0
            });
            if inside {
                0.0
            } else {
                (0..n)
                    .map(|i| seg(set[i], set[(i + 1) % n]))
                    .fold(f64::INFINITY, f64::min)
            }
        }
    }
}

fn cross(o: State, a: State, b: State) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// `poly ⊕ [−d, d]` for a convex counter-clockwise `poly`, in O(n): a vertex moves by `+d`
/// where the outward normals of its edges face `d` (`cross(d, e) ≥ 0`), by `−d` where they face
/// away, and by both (the sum's two new edges `±2d`) where they turn from one side to the other.
fn sum_with_segment(poly: &[State], d: State) -> Vec<State> {
    let plus = |p: State| [p[0] + d[0], p[1] + d[1]];
    let minus = |p: State| [p[0] - d[0], p[1] - d[1]];
    let n = poly.len();
    let side = |i: usize| {
        let (a, b) = (poly[i % n], poly[(i + 1) % n]);
        d[0] * (b[1] - a[1]) - d[1] * (b[0] - a[0]) >= 0.0
    };
    match n {
        0 => return Vec::new(),
        1 => return vec![minus(poly[0]), plus(poly[0])],
        2 if cross(poly[0], poly[1], plus(poly[0])) == 0.0 => {
            // a segment along d: its hull with the shifted copies is a longer segment
            return convex_hull(vec![
                minus(poly[0]),
                plus(poly[0]),
                minus(poly[1]),
                plus(poly[1]),
            ]);
        }
        _ => {}
    }
    let mut out = Vec::with_capacity(n + 2);
    for (i, &p) in poly.iter().enumerate() {
        match (side(i + n - 1), side(i)) {
            (true, true) => out.push(plus(p)),
            (false, false) => out.push(minus(p)),
            (false, true) => out.extend([minus(p), plus(p)]),
            (true, false) => out.extend([plus(p), minus(p)]),
        }
    }
    out
}

/// Convex hull, counter-clockwise from the least point (least x, then least y), without
/// collinear points: geo's [`ConvexHull`] (quickhull on robust orientation predicates), its
/// ring opened and started at the least point so that equal sets give equal lists. Collinear
/// points give the two ends; one or two distinct points stay as they are, in that order.
fn convex_hull(mut points: Vec<State>) -> Vec<State> {
    let least = |p: &State, q: &State| p[0].total_cmp(&q[0]).then(p[1].total_cmp(&q[1]));
    points.sort_by(least);
    points.dedup();
    if points.len() <= 2 {
        return points;
    }
    let set: geo::MultiPoint<f64> = points.iter().map(|p| geo::Point::new(p[0], p[1])).collect();
    let mut ring: Vec<State> = set
        .convex_hull()
        .exterior()
        .coords()
        .map(|c| [c.x, c.y])
        .collect();
    if ring.len() > 1 && ring.first() == ring.last() {
        ring.pop();
    }
    ring.dedup();
    if let Some(start) = (0..ring.len()).min_by(|&i, &j| least(&ring[i], &ring[j])) {
        ring.rotate_left(start);
    }
    ring
}

/// The part of `poly` (convex, in order) with coordinate `axis` at least `bound` (`keep_above`)
/// or at most `bound` (Sutherland–Hodgman against one line); `poly` itself where it lies
/// inside (most steps: no copy).
fn clip(poly: Vec<State>, axis: usize, bound: f64, keep_above: bool) -> Vec<State> {
    let inside = |p: &State| {
        if keep_above {
            p[axis] >= bound
        } else {
            p[axis] <= bound
        }
    };
    if poly.iter().all(inside) {
        return poly;
    }
    let n = poly.len();
    let mut out = Vec::with_capacity(n + 2);
    let edges = if n == 2 { 1 } else { n };
    if n == 1 {
        return Vec::new();
    }
    for i in 0..edges {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let (ia, ib) = (inside(&a), inside(&b));
        if ia {
            out.push(a);
        }
        if ia != ib {
            let s = (bound - a[axis]) / (b[axis] - a[axis]);
            let mut p = [a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])];
            p[axis] = bound;
            out.push(p);
        }
        if n == 2 && ib {
            out.push(b);
        }
    }
    out.dedup();
    if out.len() > 1 && out.first() == out.last() {
        out.pop();
    }
    out
}

/// Removes vertices, least area lost first, until at most `max` are left (the hull of the rest
/// lies inside the set).
fn simplify(set: &mut Vec<State>, max: usize) {
    while set.len() > max {
        let n = set.len();
        let k = (0..n)
            .min_by(|&i, &j| {
                let area = |k: usize| cross(set[(k + n - 1) % n], set[k], set[(k + 1) % n]).abs();
                area(i).total_cmp(&area(j))
            })
            .unwrap_or(0);
        set.remove(k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMITS: Limits = Limits {
        v_max_mm_s: 100.0,
        a_max_mm_s2: 1000.0,
        sag_mm: 0.01,
    };

    /// Tracks a tube around `centre(t)` of half-width `h`, sampled every `dt`.
    fn track(
        centre: impl Fn(f64) -> f64,
        h: f64,
        dt: f64,
        n: usize,
    ) -> Result<TrackedAxis, Unreachable> {
        let mut sets = Reachable::default();
        let eps = LIMITS.narrowing_mm(dt);
        sets.start(centre(0.0) - h + eps, centre(0.0) + h - eps)?;
        for k in 1..n {
            let c = centre(k as f64 * dt);
            sets.step(dt, c - h + eps, c + h - eps, LIMITS, false)?;
        }
        Ok(sets.route(&vec![dt; n - 1], LIMITS))
    }

    fn check(route: &TrackedAxis, centre: impl Fn(f64) -> f64, h: f64, end_s: f64) {
        let dt = 1e-4;
        let steps = (end_s / dt) as usize;
        let p: Vec<f64> = (0..=steps)
            .map(|k| route.position_mm(k as f64 * dt))
            .collect();
        for (k, &x) in p.iter().enumerate() {
            let off = x - centre(k as f64 * dt);
            assert!(off.abs() <= h + 1e-9, "offset {off} at {}", k as f64 * dt);
        }
        for w in p.windows(3) {
            let v = (w[1] - w[0]) / dt;
            let a = (w[2] - 2.0 * w[1] + w[0]) / (dt * dt);
            assert!(v.abs() <= LIMITS.v_max_mm_s * (1.0 + 1e-6), "speed {v}");
            assert!(a.abs() <= LIMITS.a_max_mm_s2 * 1.001 + 1e-3, "accel {a}");
        }
    }

    #[test]
    fn follows_a_zigzag_within_limits() {
        // a tool sweeping ±3 mm at 40 mm/s while drifting at 50 mm/s: the stage can follow it
        let centre = |t: f64| 50.0 * t + 3.0 * (t * 13.0).sin();
        let route = track(centre, 2.0, 2e-3, 1000).unwrap();
        check(&route, centre, 2.0, 1.998);
        // starts at rest
        assert_eq!(route.position_mm(-1.0), route.position_mm(0.0));
    }

    #[test]
    fn a_jump_beyond_reach_is_unreachable() {
        // the tube jumps 50 mm in one sample: no axis follows that
        let centre = |t: f64| if t < 0.5 { 0.0 } else { 50.0 };
        let err = track(centre, 2.0, 1e-3, 1000).unwrap_err();
        assert_eq!(err.sample, 500);
    }

    #[test]
    fn a_ramp_faster_than_the_speed_limit_is_unreachable() {
        let centre = |t: f64| 150.0 * t;
        assert!(track(centre, 2.0, 1e-3, 1000).is_err());
        let centre = |t: f64| 80.0 * t;
        let route = track(centre, 2.0, 1e-3, 1000).unwrap();
        check(&route, centre, 2.0, 0.998);
    }

    #[test]
    fn sum_with_a_segment_is_the_hull_of_both_shifts() {
        let square = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        for d in [[1.0, 0.0], [0.3, 0.7], [-0.2, 0.5], [0.0, -1.0]] {
            let sum = sum_with_segment(&square, d);
            let both: Vec<State> = square
                .iter()
                .flat_map(|p| [[p[0] - d[0], p[1] - d[1]], [p[0] + d[0], p[1] + d[1]]])
                .collect();
            assert_eq!(convex_hull(sum.clone()), convex_hull(both), "d {d:?}");
        }
        let seg = sum_with_segment(&[[0.0, 0.0], [1.0, 0.0]], [0.0, -1.0]);
        assert_eq!(seg, vec![[0.0, 1.0], [0.0, -1.0], [1.0, -1.0], [1.0, 1.0]]);
        assert_eq!(
            sum_with_segment(&[[0.0, 0.0], [1.0, 0.0]], [1.0, 0.0]).len(),
            2
        );
    }

    #[test]
    fn hull_and_clip_keep_convex_sets() {
        let hull = convex_hull(vec![
            [0.0, 0.0],
            [1.0, 0.0],
            [1.0, 1.0],
            [0.0, 1.0],
            [0.5, 0.5],
        ]);
        assert_eq!(hull.len(), 4);
        let half = clip(hull.clone(), 0, 0.5, true);
        assert!(half.iter().all(|p| p[0] >= 0.5));
        assert_eq!(half.len(), 4);
        let seg = clip(vec![[0.0, 0.0], [2.0, 0.0]], 0, 1.0, false);
        assert_eq!(seg, vec![[0.0, 0.0], [1.0, 0.0]]);
        let mut many: Vec<State> = (0..40)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 40.0;
                [a.cos(), a.sin()]
            })
            .collect();
        simplify(&mut many, 10);
        assert_eq!(many.len(), 10);
    }
}
