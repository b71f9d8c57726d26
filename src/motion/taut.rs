//! The taut string: the shortest stage path through a tube, one axis at a time.
//!
//! For on-the-fly marking the tool-centre point `p(t)` is fixed by the marking order and speeds,
//! and the stage `s(t)` must keep the scanner offset inside the field less a margin: per axis
//! `|p(t) − s(t)| ≤ h`. Sampled at times `t_k`, that is a *tube* of intervals
//! `[lower_k, upper_k]`, and among all piecewise-linear paths with vertices at the sample times
//! that pass through every interval, the **taut string** is the shortest one in the `(t, x)`
//! plane. It is at the same time the minimiser of `Σ Δt·f(Δx/Δt)` for *every* convex `f`
//! (classical; the optimality conditions below do not depend on `f`): least total variation
//! (`f = |s|`, the travel of the axis), least energy (`f = s²`) and, as the limit of `f = |s|^p`,
//! least peak speed.
//!
//! # Optimality certificate
//!
//! A feasible path is optimal for every convex `f` when it bends only where the tube pushes it:
//! at an interior vertex where the slope **decreases** (a `∧`) it lies on the **lower** bound,
//! where the slope **increases** (a `∨`) on the **upper** bound (KKT: the multiplier of the
//! active bound equals the jump of `f'` at the vertex, with the bound's sign). A free end is a
//! vertical segment `[lower, upper]`: the path leaves (or reaches) it horizontally or at one of
//! its ends — a free start with a rising first segment lies on `upper_0`, with a falling one on
//! `lower_0`; a free end reached rising lies on `lower_{n−1}`, reached falling on
//! `upper_{n−1}`. The tests check exactly this on random tubes, and compare with a brute-force
//! dynamic programme.
//!
//! # Algorithm: the funnel (string pulling), O(n)
//!
//! The path is known up to an *apex* (the last vertex emitted). From the apex two chains span
//! the *funnel* of directions the string can still take:
//! * the lower chain: lower-bound points, concave (slopes decreasing) — the string wrapped over
//!   the lower pegs;
//! * the upper chain: upper-bound points, convex (slopes increasing) — the string wrapped under
//!   the upper pegs.
//!
//! A new upper point that falls below the lower chain (seen from the apex) *crosses* it: the
//! string must bend over the lower chain's next point, which becomes the apex (emitted), and so
//! on until the new point is visible; the upper chain then restarts as `[apex, point]`.
//! Otherwise the point joins the back of its own chain after popping the points it makes
//! non-convex. Lower points are the mirror image. Every point is pushed and popped at most once
//! per chain: linear time.
//!
//! A **free start** is the vertical segment `[lower_0, upper_0]`; its apex lies at infinity to
//! the left (horizontal direction). Until the first crossing the chains are the hulls seen
//! horizontally (the lower chain starts at the highest lower point so far, the upper chain at the
//! lowest upper point), and a point crosses when it is below the highest lower point (upper
//! point) or above the lowest upper point (lower point). At the first crossing the string starts
//! horizontally at the height of the chain head it bends on. A **fixed start** is the same with
//! `lower_0 = upper_0`. A **free end** is handled the same way with an apex at infinity to the
//! right: a last "upper point at infinity" crosses the lower chain while its slopes are
//! positive, a last "lower point at infinity" crosses the upper chain while its slopes are
//! negative, and the string leaves the last apex horizontally. A fixed end is `lower = upper`.
//! When nothing ever crosses (both ends free) every height in `[max lower, min upper]` is
//! optimal: the string is the horizontal line at the middle of that band.
//!
//! # Numerics
//!
//! The only decisions are the signs of 2-D cross products of coordinate differences (no
//! division; every time difference is positive), compared with **zero**, no epsilon: a sign can
//! come out wrong only when the three points are collinear to within a few ulps of the
//! differences, and then both branches give a path that differs from the exact taut string, and
//! from feasibility, by about that rounding (≈ 1e-15 relative to the coordinates' magnitude).
//! An epsilon would buy nothing but a tolerance to document. Ties (exact collinearity) never
//! create a vertex: chains pop collinear points and a crossing must be strict, so straight
//! stretches of the tube give no vertices. Vertex heights are copied from the input (a bound,
//! a fixed end, or a bound carried horizontally to a free end) or are the exact midpoint of a
//! band, so no arithmetic error accumulates along the path; a sample between vertices is in
//! the tube up to the rounding of linear interpolation and of the sign tests (the tests accept
//! `1e-9 · (1 + |x|)` mm and see far less).

use std::collections::VecDeque;
use std::fmt;

/// A path vertex: (time s, position mm).
type Pt = (f64, f64);

/// One axis of a tube: at strictly increasing times `t_s[k]` the stage must lie in
/// `[lower_mm[k], upper_mm[k]]`.
#[derive(Debug, Clone, Copy)]
pub struct Tube<'a> {
    /// Sample times (s), finite and strictly increasing.
    pub t_s: &'a [f64],
    /// Lower bound of the stage position at each sample (mm).
    pub lower_mm: &'a [f64],
    /// Upper bound of the stage position at each sample (mm).
    pub upper_mm: &'a [f64],
}

/// Which end of the path an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PathEnd {
    /// The start, at `t_s[0]`.
    Start,
    /// The end, at the last time.
    End,
}

impl fmt::Display for PathEnd {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PathEnd::Start => f.write_str("start"),
            PathEnd::End => f.write_str("end"),
        }
    }
}

/// Why a tube has no taut string.
#[derive(Debug, Clone, PartialEq)]
pub enum TautError {
    /// `t_s`, `lower_mm` and `upper_mm` have different lengths.
    LengthMismatch {
        /// Length of `t_s`.
        times: usize,
        /// Length of `lower_mm`.
        lower: usize,
        /// Length of `upper_mm`.
        upper: usize,
    },
    /// The tube has no sample.
    Empty,
    /// A time or a bound is NaN or infinite.
    NotFinite {
        /// Sample index.
        k: usize,
    },
    /// `t_s[k]` is not greater than `t_s[k - 1]`.
    TimesNotIncreasing {
        /// Sample index.
        k: usize,
    },
    /// `lower_mm[k] > upper_mm[k]`: the tube is empty at sample `k`.
    EmptyInterval {
        /// Sample index.
        k: usize,
        /// The lower bound (mm).
        lower_mm: f64,
        /// The upper bound (mm).
        upper_mm: f64,
    },
    /// A fixed end lies outside its interval (for a single sample: the start and end differ).
    EndOutside {
        /// Which end.
        end: PathEnd,
        /// The requested position (mm).
        value_mm: f64,
        /// The interval's lower bound (mm).
        lower_mm: f64,
        /// The interval's upper bound (mm).
        upper_mm: f64,
    },
}

impl fmt::Display for TautError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TautError::LengthMismatch {
                times,
                lower,
                upper,
            } => write!(
                f,
                "tube lengths differ: {times} times, {lower} lower bounds, {upper} upper bounds"
            ),
            TautError::Empty => f.write_str("tube has no sample"),
            TautError::NotFinite { k } => write!(f, "tube sample {k}: time or bound not finite"),
            TautError::TimesNotIncreasing { k } => {
                write!(f, "tube sample {k}: time not after the previous sample's")
            }
            TautError::EmptyInterval {
                k,
                lower_mm,
                upper_mm,
            } => write!(
                f,
                "tube sample {k}: lower bound {lower_mm} mm above upper bound {upper_mm} mm"
            ),
            TautError::EndOutside {
                end,
                value_mm,
                lower_mm,
                upper_mm,
            } => write!(
                f,
                "fixed {end} {value_mm} mm outside its interval [{lower_mm}, {upper_mm}] mm"
            ),
        }
    }
}

impl std::error::Error for TautError {}

/// The taut string: the shortest (in the `(t, x)` plane, equivalently least total variation and
/// least of every convex function of the slope) piecewise-linear path through the tube from
/// `start_mm` at `t_s[0]` to `end_mm` at the last time (each `None` = free, chosen inside that
/// end's interval as the taut string would: the path leaves or reaches a free end horizontally
/// or at one of its bounds). Returns its vertices (time, position), the first at `t_s[0]` and
/// the last at `t_s[n-1]` (a single vertex when `n = 1`), at strictly increasing sample times;
/// it lies within the tube at every `t_s[k]` (linear between samples). When both ends are free
/// and the whole tube admits a constant position, the path is constant at the middle of the
/// band `[max lower, min upper]`.
///
/// Linear time and memory. See the module documentation for the algorithm and the numerics.
pub fn taut_string(
    tube: &Tube,
    start_mm: Option<f64>,
    end_mm: Option<f64>,
) -> Result<Vec<(f64, f64)>, TautError> {
    let bounds = Bounds::new(tube, start_mm, end_mm)?;
    let n = tube.t_s.len();
    let mut funnel = Funnel::new(tube.t_s[0], bounds.at(0));
    for k in 1..n {
        let (lower_mm, upper_mm) = bounds.at(k);
        let t_s = tube.t_s[k];
        funnel.add(Side::Upper, (t_s, upper_mm));
        funnel.add(Side::Lower, (t_s, lower_mm));
    }
    Ok(funnel.finish(tube.t_s[n - 1]))
}

/// Peak `|slope|` of a piecewise-linear path (mm/s); 0 for fewer than two vertices. Segments
/// of zero duration are skipped.
pub fn peak_speed_mm_s(path: &[(f64, f64)]) -> f64 {
    path.windows(2)
        .filter(|w| w[1].0 > w[0].0)
        .map(|w| ((w[1].1 - w[0].1) / (w[1].0 - w[0].0)).abs())
        .fold(0.0, f64::max)
}

/// Position of the path at time `t_s` (clamped to the first and last vertex), by binary search
/// and linear interpolation; NaN for an empty path.
pub fn position_at(path: &[(f64, f64)], t_s: f64) -> f64 {
    let (Some(first), Some(last)) = (path.first(), path.last()) else {
        return f64::NAN;
    };
    if t_s <= first.0 {
        return first.1;
    }
    if t_s >= last.0 {
        return last.1;
    }
    // first index with time > t_s: 1 ≤ i ≤ len − 1 by the clamps above
    let i = path.partition_point(|v| v.0 <= t_s);
    let (a, b) = (path[i - 1], path[i]);
    let u = (t_s - a.0) / (b.0 - a.0);
    a.1 + u * (b.1 - a.1)
}

/// Length of the path's projection on the position axis (`Σ |Δx|`), mm.
pub fn travel_mm(path: &[(f64, f64)]) -> f64 {
    path.windows(2).map(|w| (w[1].1 - w[0].1).abs()).sum()
}

/// The tube's intervals with the fixed ends folded in (a fixed end is a one-point interval).
struct Bounds<'a> {
    tube: &'a Tube<'a>,
    first: (f64, f64),
    last: (f64, f64),
}

impl<'a> Bounds<'a> {
    /// Validates the tube and the ends.
    fn new(
        tube: &'a Tube<'a>,
        start_mm: Option<f64>,
        end_mm: Option<f64>,
    ) -> Result<Self, TautError> {
        validate(tube)?;
        let n = tube.t_s.len();
        let first = fix_end(
            PathEnd::Start,
            (tube.lower_mm[0], tube.upper_mm[0]),
            start_mm,
        )?;
        let last_free = if n == 1 {
            first
        } else {
            (tube.lower_mm[n - 1], tube.upper_mm[n - 1])
        };
        let last = fix_end(PathEnd::End, last_free, end_mm)?;
        let first = if n == 1 { last } else { first };
        Ok(Self { tube, first, last })
    }

    /// `(lower, upper)` at sample `k`.
    fn at(&self, k: usize) -> (f64, f64) {
        let n = self.tube.t_s.len();
        if k + 1 == n {
            self.last
        } else if k == 0 {
            self.first
        } else {
            (self.tube.lower_mm[k], self.tube.upper_mm[k])
        }
    }
}

/// Checks lengths, finiteness, increasing times and non-empty intervals.
fn validate(tube: &Tube) -> Result<(), TautError> {
    let (times, lower, upper) = (tube.t_s.len(), tube.lower_mm.len(), tube.upper_mm.len());
    if times != lower || times != upper {
        return Err(TautError::LengthMismatch {
            times,
            lower,
            upper,
        });
    }
    if times == 0 {
        return Err(TautError::Empty);
    }
    for k in 0..times {
        let (t_s, lower_mm, upper_mm) = (tube.t_s[k], tube.lower_mm[k], tube.upper_mm[k]);
        if !(t_s.is_finite() && lower_mm.is_finite() && upper_mm.is_finite()) {
            return Err(TautError::NotFinite { k });
        }
        if k > 0 && t_s <= tube.t_s[k - 1] {
            return Err(TautError::TimesNotIncreasing { k });
        }
        if lower_mm > upper_mm {
            return Err(TautError::EmptyInterval {
                k,
                lower_mm,
                upper_mm,
            });
        }
    }
    Ok(())
}

/// The interval of an end: unchanged when free, the fixed point when inside.
fn fix_end(
    end: PathEnd,
    (lower_mm, upper_mm): (f64, f64),
    value: Option<f64>,
) -> Result<(f64, f64), TautError> {
    match value {
        None => Ok((lower_mm, upper_mm)),
        Some(v) if lower_mm <= v && v <= upper_mm => Ok((v, v)),
        Some(value_mm) => Err(TautError::EndOutside {
            end,
            value_mm,
            lower_mm,
            upper_mm,
        }),
    }
}

/// Twice the signed area of the triangle `a, b, c`: > 0 when `c` lies above the line `a → b`
/// (for `t_a < t_b` and `t_a < t_c`: the slope `a → c` exceeds the slope `a → b`, and the turn
/// `a → b → c` bends up). Exact sign up to the rounding of the differences; see the module doc.
fn turn(a: Pt, b: Pt, c: Pt) -> f64 {
    (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
}

/// A side of the tube. The upper side's tests are the lower side's mirrored in `x`: every
/// comparison below is written for the upper side and multiplied by [`Side::sign`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Side {
    Lower = 0,
    Upper = 1,
}

impl Side {
    /// +1 for the upper side, −1 for the lower (mirror in `x`).
    fn sign(self) -> f64 {
        match self {
            Side::Lower => -1.0,
            Side::Upper => 1.0,
        }
    }

    /// The opposite side.
    fn other(self) -> Side {
        match self {
            Side::Lower => Side::Upper,
            Side::Upper => Side::Lower,
        }
    }
}

/// The funnel of the string-pulling algorithm (see the module documentation).
struct Funnel {
    /// `chains[Side::Lower]`: concave chain of lower points; `chains[Side::Upper]`: convex chain
    /// of upper points. With an apex both start at it; before it (free start) each starts at
    /// its head as seen horizontally (highest lower point, lowest upper point).
    chains: [VecDeque<Pt>; 2],
    /// The vertices emitted so far; the last one is the apex (when not `free`).
    path: Vec<Pt>,
    /// Time of the first sample.
    t0_s: f64,
    /// No apex yet: the start is still the vertical segment at `t0_s`.
    free: bool,
}

impl Funnel {
    /// The funnel of the first sample's interval (a vertical segment).
    fn new(t0_s: f64, (lower_mm, upper_mm): (f64, f64)) -> Self {
        Self {
            chains: [
                VecDeque::from([(t0_s, lower_mm)]),
                VecDeque::from([(t0_s, upper_mm)]),
            ],
            path: Vec::new(),
            t0_s,
            free: true,
        }
    }

    /// Adds the bound point `p` of `side` (later than every point so far).
    fn add(&mut self, side: Side, p: Pt) {
        let s = side.sign();
        let other = side.other();
        let mut crossed = false;
        if self.free {
            let head = self.chains[other as usize][0];
            if s * (p.1 - head.1) < 0.0 {
                self.leave_start(other);
                crossed = true;
            }
        }
        if !self.free {
            crossed |= self.advance(other, |a, b| s * turn(a, b, p) < 0.0);
        }
        if crossed {
            let apex = self.apex();
            let own = &mut self.chains[side as usize];
            own.clear();
            own.push_back(apex);
            own.push_back(p);
        } else {
            self.push_hull(side, p);
        }
    }

    /// Appends `p` to its own chain, popping the points it makes non-convex (upper) or
    /// non-concave (lower); collinear points are popped too. The apex is never popped; the head
    /// of a free start's chain is popped when `p` is at least as far out (virtual horizontal
    /// incoming direction).
    fn push_hull(&mut self, side: Side, p: Pt) {
        let s = side.sign();
        let chain = &mut self.chains[side as usize];
        while chain.len() >= 2 && s * turn(chain[chain.len() - 2], chain[chain.len() - 1], p) <= 0.0
        {
            chain.pop_back();
        }
        if self.free && chain.len() == 1 && s * (p.1 - chain[0].1) <= 0.0 {
            chain.pop_back();
        }
        chain.push_back(p);
    }

    /// The string leaves the free start: horizontally at the height of `side`'s chain head,
    /// which becomes the apex.
    fn leave_start(&mut self, side: Side) {
        let head = self.chains[side as usize][0];
        self.path.push((self.t0_s, head.1));
        if head.0 > self.t0_s {
            self.path.push(head);
        }
        self.free = false;
    }

    /// Moves the apex along `side`'s chain while `crosses(apex, next)`, emitting each new apex.
    /// Returns whether it moved.
    fn advance(&mut self, side: Side, crosses: impl Fn(Pt, Pt) -> bool) -> bool {
        let chain = &mut self.chains[side as usize];
        let mut moved = false;
        while chain.len() >= 2 && crosses(chain[0], chain[1]) {
            chain.pop_front();
            self.path.push(chain[0]);
            moved = true;
        }
        moved
    }

    /// The current apex (the last vertex emitted); only meaningful when not `free`.
    fn apex(&self) -> Pt {
        self.path.last().copied().unwrap_or((self.t0_s, 0.0))
    }

    /// Completes the path to the last sample time `t_end_s` with a free end (a fixed end has
    /// already been folded in as a one-point interval, and then ends the same way).
    fn finish(mut self, t_end_s: f64) -> Vec<Pt> {
        if self.free {
            let lower = self.chains[Side::Lower as usize][0].1;
            let upper = self.chains[Side::Upper as usize][0].1;
            let mid_mm = 0.5 * (lower + upper);
            self.path.push((self.t0_s, mid_mm));
            if t_end_s > self.t0_s {
                self.path.push((t_end_s, mid_mm));
            }
            return self.path;
        }
        // an upper point at +∞ (slope 0 from anywhere) crosses the lower chain while it rises;
        // if it did not, a lower point at +∞ crosses the upper chain while that one falls
        if !self.advance(Side::Lower, |a, b| b.1 > a.1) {
            self.advance(Side::Upper, |a, b| b.1 < a.1);
        }
        let apex = self.apex();
        if apex.0 < t_end_s {
            self.path.push((t_end_s, apex.1));
        }
        self.path
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]

    use super::*;
    use proptest::prelude::*;

    /// Owned tube for the tests.
    #[derive(Debug, Clone)]
    struct Owned {
        t_s: Vec<f64>,
        lower_mm: Vec<f64>,
        upper_mm: Vec<f64>,
    }

    impl Owned {
        fn tube(&self) -> Tube<'_> {
            Tube {
                t_s: &self.t_s,
                lower_mm: &self.lower_mm,
                upper_mm: &self.upper_mm,
            }
        }

        /// Tube of half-width `h_mm` around `p` sampled at `t_s`.
        fn around(t_s: Vec<f64>, p: impl Fn(f64) -> f64, h_mm: f64) -> Self {
            let centre: Vec<f64> = t_s.iter().map(|&t| p(t)).collect();
            Self {
                lower_mm: centre.iter().map(|c| c - h_mm).collect(),
                upper_mm: centre.iter().map(|c| c + h_mm).collect(),
                t_s,
            }
        }

        fn n(&self) -> usize {
            self.t_s.len()
        }
    }

    fn tol(x: f64) -> f64 {
        1e-9 * (1.0 + x.abs())
    }

    /// The path's position at every sample.
    fn at_samples(tube: &Owned, path: &[(f64, f64)]) -> Vec<f64> {
        tube.t_s.iter().map(|&t| position_at(path, t)).collect()
    }

    /// Vertices at strictly increasing sample times from the first to the last sample; every
    /// sample inside its interval; fixed ends kept.
    fn assert_feasible(tube: &Owned, path: &[(f64, f64)], start: Option<f64>, end: Option<f64>) {
        let n = tube.n();
        assert!(!path.is_empty());
        assert_eq!(path[0].0, tube.t_s[0]);
        assert_eq!(path[path.len() - 1].0, tube.t_s[n - 1]);
        assert!(path.windows(2).all(|w| w[0].0 < w[1].0), "{path:?}");
        for v in path {
            assert!(tube.t_s.binary_search_by(|t| t.total_cmp(&v.0)).is_ok());
        }
        for (k, x) in at_samples(tube, path).into_iter().enumerate() {
            let (lo, hi) = (tube.lower_mm[k], tube.upper_mm[k]);
            assert!(
                x >= lo - tol(lo) && x <= hi + tol(hi),
                "k={k}: {x} ∉ [{lo}, {hi}]"
            );
        }
        if let Some(a) = start {
            assert!((path[0].1 - a).abs() <= tol(a));
        }
        if let Some(b) = end {
            assert!((path[path.len() - 1].1 - b).abs() <= tol(b));
        }
    }

    fn slope(a: (f64, f64), b: (f64, f64)) -> f64 {
        (b.1 - a.1) / (b.0 - a.0)
    }

    /// Asserts `x` is on `bound` (what = description for the message).
    fn assert_on(x: f64, bound: f64, what: &str) {
        assert!(
            (x - bound).abs() <= tol(bound),
            "{what}: {x} not on {bound}"
        );
    }

    /// The optimality certificate of the module doc: bends only on the bound that pushes,
    /// free ends horizontal or on the right bound.
    fn assert_taut(tube: &Owned, path: &[(f64, f64)], start: Option<f64>, end: Option<f64>) {
        let n = tube.n();
        let k_of = |t: f64| tube.t_s.binary_search_by(|x| x.total_cmp(&t)).unwrap();
        for w in path.windows(3) {
            let (s0, s1) = (slope(w[0], w[1]), slope(w[1], w[2]));
            let k = k_of(w[1].0);
            let eps = 1e-9 * (1.0 + s0.abs() + s1.abs());
            if s1 > s0 + eps {
                assert_on(w[1].1, tube.upper_mm[k], "∨ vertex");
            } else if s1 < s0 - eps {
                assert_on(w[1].1, tube.lower_mm[k], "∧ vertex");
            }
        }
        if path.len() < 2 {
            return;
        }
        let eps = |s: f64| 1e-9 * (1.0 + s.abs());
        let s_first = slope(path[0], path[1]);
        if start.is_none() && s_first.abs() > eps(s_first) {
            let b = if s_first > 0.0 {
                tube.upper_mm[0]
            } else {
                tube.lower_mm[0]
            };
            assert_on(path[0].1, b, "free start");
        }
        let s_last = slope(path[path.len() - 2], path[path.len() - 1]);
        if end.is_none() && s_last.abs() > eps(s_last) {
            let b = if s_last > 0.0 {
                tube.lower_mm[n - 1]
            } else {
                tube.upper_mm[n - 1]
            };
            assert_on(path[path.len() - 1].1, b, "free end");
        }
    }

    /// Brute force: the least `Σ cost` (or `max cost` when `peak`) over paths through a grid of
    /// `m` positions per interval (a fixed end: its one point), by dynamic programming.
    fn grid_dp(
        tube: &Owned,
        ends: (Option<f64>, Option<f64>),
        m: usize,
        cost: impl Fn(f64, f64) -> f64,
        peak: bool,
    ) -> f64 {
        let n = tube.n();
        let grid = |k: usize| -> Vec<f64> {
            let fixed =
                if k == 0 { ends.0 } else { None }.or(if k + 1 == n { ends.1 } else { None });
            if let Some(x) = fixed {
                return vec![x];
            }
            let (lo, hi) = (tube.lower_mm[k], tube.upper_mm[k]);
            (0..m)
                .map(|j| lo + (hi - lo) * j as f64 / (m - 1) as f64)
                .collect()
        };
        let mut xs = grid(0);
        let mut best = vec![0.0_f64; xs.len()];
        for k in 1..n {
            let next = grid(k);
            let dt = tube.t_s[k] - tube.t_s[k - 1];
            let nb: Vec<f64> = next
                .iter()
                .map(|&y| {
                    xs.iter()
                        .zip(&best)
                        .map(|(&x, &b)| {
                            let c = cost(dt, y - x);
                            if peak {
                                b.max(c)
                            } else {
                                b + c
                            }
                        })
                        .fold(f64::INFINITY, f64::min)
                })
                .collect();
            xs = next;
            best = nb;
        }
        best.into_iter().fold(f64::INFINITY, f64::min)
    }

    /// The four objectives of a path given by its sample positions.
    fn objectives(tube: &Owned, xs: &[f64]) -> [f64; 4] {
        let mut o = [0.0; 4];
        for k in 1..tube.n() {
            let (dt, dx) = (tube.t_s[k] - tube.t_s[k - 1], xs[k] - xs[k - 1]);
            o[0] += dt.hypot(dx);
            o[1] += dx.abs();
            o[2] += dx * dx / dt;
            o[3] = o[3].max(dx.abs() / dt);
        }
        o
    }

    /// Random small tubes: n ≤ 12, random steps, some zero-width intervals.
    fn small_tube() -> impl Strategy<Value = Owned> {
        let sample = (
            0.05f64..2.0,
            -3.0f64..3.0,
            prop_oneof![Just(0.0), 0.0f64..2.0, 0.0f64..0.2],
        );
        prop::collection::vec(sample, 1..=12).prop_map(walk_tube)
    }

    /// A tube around a random walk: per sample (time step, centre step, half-width).
    fn walk_tube(steps: Vec<(f64, f64, f64)>) -> Owned {
        let (mut t, mut c) = (0.0, 0.0);
        let mut tube = Owned {
            t_s: vec![],
            lower_mm: vec![],
            upper_mm: vec![],
        };
        for (dt, dc, h) in steps {
            t += dt;
            c += dc;
            tube.t_s.push(t);
            tube.lower_mm.push(c - h);
            tube.upper_mm.push(c + h);
        }
        tube
    }

    /// A tube with ends: each free or fixed at a fraction of its interval.
    fn tube_with_ends() -> impl Strategy<Value = (Owned, Option<f64>, Option<f64>)> {
        let frac = || prop::option::of(prop_oneof![Just(0.0), Just(1.0), 0.0f64..=1.0]);
        (small_tube(), frac(), frac()).prop_map(|(tube, a, b)| {
            let n = tube.n();
            let at = |k: usize, f: f64| {
                let (lo, hi) = (tube.lower_mm[k], tube.upper_mm[k]);
                (lo + f * (hi - lo)).clamp(lo, hi)
            };
            let start = a.map(|f| at(0, f));
            // one sample: a fixed end must equal a fixed start
            let end = if n == 1 {
                b.map(|f| start.unwrap_or(at(0, f)))
            } else {
                b.map(|f| at(n - 1, f))
            };
            (tube, start, end)
        })
    }

    /// Long tubes: random walks (n ≤ 400), or small integers on integer times (many exact
    /// ties and collinear points).
    fn long_tube() -> impl Strategy<Value = (Owned, Option<f64>, Option<f64>)> {
        let walk = prop::collection::vec((0.01f64..1.0, -1.0f64..1.0, 0.0f64..0.5), 1..400)
            .prop_map(walk_tube);
        let ints = prop::collection::vec((-3i32..=3, 0i32..=2), 1..400).prop_map(|v| Owned {
            t_s: (0..v.len()).map(|k| k as f64).collect(),
            lower_mm: v.iter().map(|&(c, _)| f64::from(c)).collect(),
            upper_mm: v.iter().map(|&(c, w)| f64::from(c + w)).collect(),
        });
        let ends = (any::<bool>(), any::<bool>());
        (prop_oneof![walk, ints], ends).prop_map(|(tube, (fix_a, fix_b))| {
            let n = tube.n();
            let start = fix_a.then(|| tube.upper_mm[0]);
            let end = if n == 1 {
                fix_b.then_some(start.unwrap_or(tube.lower_mm[0]))
            } else {
                fix_b.then(|| tube.lower_mm[n - 1])
            };
            (tube, start, end)
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        #[test]
        fn feasible_and_taut_on_random_tubes((tube, start, end) in tube_with_ends()) {
            let path = taut_string(&tube.tube(), start, end).unwrap();
            assert_feasible(&tube, &path, start, end);
            assert_taut(&tube, &path, start, end);
        }

        #[test]
        fn feasible_and_taut_on_long_tubes((tube, start, end) in long_tube()) {
            let path = taut_string(&tube.tube(), start, end).unwrap();
            assert_feasible(&tube, &path, start, end);
            assert_taut(&tube, &path, start, end);
        }

        #[test]
        fn no_grid_path_beats_it((tube, start, end) in tube_with_ends()) {
            let m = 101;
            let path = taut_string(&tube.tube(), start, end).unwrap();
            let taut = objectives(&tube, &at_samples(&tube, &path));
            let ends = (start, end);
            let dp = [
                grid_dp(&tube, ends, m, |dt, dx| dt.hypot(dx), false),
                grid_dp(&tube, ends, m, |_, dx| dx.abs(), false),
                grid_dp(&tube, ends, m, |dt, dx| dx * dx / dt, false),
                grid_dp(&tube, ends, m, |dt, dx| dx.abs() / dt, true),
            ];
            for i in 0..4 {
                prop_assert!(taut[i] <= dp[i] + tol(dp[i]), "objective {i}: taut {} > grid {}", taut[i], dp[i]);
            }
            // rounding the taut string to the grid moves each sample by ≤ half a grid step δ_k
            let half_step: Vec<f64> = (0..tube.n())
                .map(|k| 0.5 * (tube.upper_mm[k] - tube.lower_mm[k]) / (m - 1) as f64)
                .collect();
            let sum_err: f64 = half_step.iter().sum::<f64>() * 2.0;
            let peak_err = (1..tube.n())
                .map(|k| (half_step[k] + half_step[k - 1]) / (tube.t_s[k] - tube.t_s[k - 1]))
                .fold(0.0, f64::max);
            prop_assert!(dp[0] <= taut[0] + sum_err + 1e-9);
            prop_assert!(dp[1] <= taut[1] + sum_err + 1e-9);
            prop_assert!(dp[3] <= taut[3] + peak_err + 1e-9);
        }

        #[test]
        fn time_reversal_gives_the_same_string((tube, start, end) in tube_with_ends()) {
            let path = taut_string(&tube.tube(), start, end).unwrap();
            let rev = Owned {
                t_s: tube.t_s.iter().rev().map(|t| -t).collect(),
                lower_mm: tube.lower_mm.iter().rev().copied().collect(),
                upper_mm: tube.upper_mm.iter().rev().copied().collect(),
            };
            let back = taut_string(&rev.tube(), end, start).unwrap();
            // unique unless both ends are free and the string is horizontal (any height of the band)
            let flat = path.len() == 2 && path[0].1 == path[1].1;
            if !(start.is_none() && end.is_none() && (flat || path.len() == 1)) {
                for (k, &t) in tube.t_s.iter().enumerate() {
                    let (x, y) = (position_at(&path, t), position_at(&back, -t));
                    prop_assert!((x - y).abs() <= 1e-9 * (1.0 + x.abs()), "k={k}: {x} vs {y}");
                }
            }
        }
    }

    #[test]
    fn constant_tube_gives_a_straight_line() {
        let n = 100;
        let tube = Owned::around((0..n).map(|k| k as f64 * 0.1).collect(), |_| 3.0, 1.0);
        let t_end = tube.t_s[n - 1];
        let free = taut_string(&tube.tube(), None, None).unwrap();
        assert_eq!(free, vec![(0.0, 3.0), (t_end, 3.0)]);
        let from = taut_string(&tube.tube(), Some(2.5), None).unwrap();
        assert_eq!(from, vec![(0.0, 2.5), (t_end, 2.5)]);
        let to = taut_string(&tube.tube(), None, Some(3.75)).unwrap();
        assert_eq!(to, vec![(0.0, 3.75), (t_end, 3.75)]);
        let both = taut_string(&tube.tube(), Some(2.5), Some(3.5)).unwrap();
        assert_eq!(both, vec![(0.0, 2.5), (t_end, 3.5)]);
    }

    #[test]
    fn linear_tube_free_ends_cut_the_corners() {
        // p = 2t ± 0.5 on [0, 10]: with free ends the string runs from the upper start to the
        // lower end; with both ends fixed on p it is p itself
        let tube = Owned::around(
            (0..=1000).map(|k| k as f64 * 0.01).collect(),
            |t| 2.0 * t,
            0.5,
        );
        let free = taut_string(&tube.tube(), None, None).unwrap();
        assert_eq!(free.len(), 2);
        assert_eq!(free[0], (0.0, 0.5));
        assert!((free[1].0 - 10.0).abs() < 1e-12 && (free[1].1 - 19.5).abs() < 1e-12);
        let fixed = taut_string(&tube.tube(), Some(0.0), Some(20.0)).unwrap();
        assert_eq!(fixed.len(), 2, "{fixed:?}");
        assert!((travel_mm(&fixed) - 20.0).abs() < 1e-12);
    }

    #[test]
    fn single_sample() {
        let tube = Owned {
            t_s: vec![2.0],
            lower_mm: vec![1.0],
            upper_mm: vec![3.0],
        };
        let t = tube.tube();
        assert_eq!(taut_string(&t, None, None).unwrap(), vec![(2.0, 2.0)]);
        assert_eq!(taut_string(&t, Some(1.5), None).unwrap(), vec![(2.0, 1.5)]);
        assert_eq!(taut_string(&t, None, Some(3.0)).unwrap(), vec![(2.0, 3.0)]);
        assert_eq!(
            taut_string(&t, Some(1.5), Some(1.5)).unwrap(),
            vec![(2.0, 1.5)]
        );
        assert!(matches!(
            taut_string(&t, Some(1.5), Some(2.5)),
            Err(TautError::EndOutside {
                end: PathEnd::End,
                ..
            })
        ));
        let point = Owned {
            t_s: vec![0.0],
            lower_mm: vec![4.0],
            upper_mm: vec![4.0],
        };
        assert_eq!(
            taut_string(&point.tube(), None, None).unwrap(),
            vec![(0.0, 4.0)]
        );
    }

    #[test]
    fn equal_bounds_force_every_sample() {
        let t_s: Vec<f64> = (0..200).map(|k| k as f64 * 0.05).collect();
        let tube = Owned::around(t_s, |t| (3.0 * t).sin() + 0.3 * t, 0.0);
        let path = taut_string(&tube.tube(), None, None).unwrap();
        assert_feasible(&tube, &path, None, None);
        for (k, x) in at_samples(&tube, &path).into_iter().enumerate() {
            assert!((x - tube.lower_mm[k]).abs() < 1e-12, "k={k}");
        }
    }

    #[test]
    fn long_flat_stretches_give_few_vertices() {
        // [0, 1] for 1000 samples, then [5, 6] for 1000: flat at 1, a ramp, flat at 5
        let n = 2000;
        let tube = Owned {
            t_s: (0..n).map(|k| k as f64).collect(),
            lower_mm: (0..n).map(|k| if k < 1000 { 0.0 } else { 5.0 }).collect(),
            upper_mm: (0..n).map(|k| if k < 1000 { 1.0 } else { 6.0 }).collect(),
        };
        let path = taut_string(&tube.tube(), None, None).unwrap();
        assert_eq!(
            path,
            vec![(0.0, 1.0), (999.0, 1.0), (1000.0, 5.0), (1999.0, 5.0)]
        );
        assert_eq!(travel_mm(&path), 4.0);
        assert_eq!(peak_speed_mm_s(&path), 4.0);
        let fixed = taut_string(&tube.tube(), Some(0.0), Some(6.0)).unwrap();
        assert_feasible(&tube, &fixed, Some(0.0), Some(6.0));
        assert_taut(&tube, &fixed, Some(0.0), Some(6.0));
        assert_eq!(travel_mm(&fixed), 6.0);
    }

    #[test]
    fn sine_tube_travel_is_total_variation_less_the_tube() {
        // p = A cos t on [0, Nπ], half-width h < A, free ends, samples on every extremum: the
        // string starts flat on the first peak's lower bound (A − h), wraps each peak's lower
        // bound and each trough's upper bound (−A + h) and is monotone in between, so its travel
        // is N (2A − 2h) exactly: the sine's total variation 2AN less 2h per half period
        let (a_mm, h_mm, halves, per_half) = (10.0, 2.0, 6, 1000);
        let n = halves * per_half + 1;
        let t_s = (0..n)
            .map(|k| k as f64 * std::f64::consts::PI / per_half as f64)
            .collect();
        let tube = Owned::around(t_s, |t| a_mm * t.cos(), h_mm);
        let path = taut_string(&tube.tube(), None, None).unwrap();
        assert_feasible(&tube, &path, None, None);
        assert_taut(&tube, &path, None, None);
        let expected = halves as f64 * (2.0 * a_mm - 2.0 * h_mm);
        assert!(
            (travel_mm(&path) - expected).abs() < 1e-9,
            "{}",
            travel_mm(&path)
        );
        // p itself is feasible, so the least peak speed is at most p's (A at ω = 1)
        assert!(peak_speed_mm_s(&path) < a_mm);
    }

    #[test]
    fn errors_name_the_cause() {
        let t = |t_s: &[f64], lo: &[f64], hi: &[f64]| -> TautError {
            let tube = Tube {
                t_s,
                lower_mm: lo,
                upper_mm: hi,
            };
            taut_string(&tube, None, None).unwrap_err()
        };
        assert!(matches!(
            t(&[0.0, 1.0], &[0.0], &[1.0, 1.0]),
            TautError::LengthMismatch { .. }
        ));
        assert_eq!(t(&[], &[], &[]), TautError::Empty);
        assert_eq!(
            t(&[0.0, f64::NAN], &[0.0; 2], &[1.0; 2]),
            TautError::NotFinite { k: 1 }
        );
        assert_eq!(
            t(&[0.0, 1.0], &[0.0, f64::NEG_INFINITY], &[1.0; 2]),
            TautError::NotFinite { k: 1 }
        );
        assert_eq!(
            t(&[0.0, 1.0, 1.0], &[0.0; 3], &[1.0; 3]),
            TautError::TimesNotIncreasing { k: 2 }
        );
        let e = t(&[0.0, 1.0, 2.0], &[0.0, 2.0, 0.0], &[1.0; 3]);
        assert_eq!(
            e,
            TautError::EmptyInterval {
                k: 1,
                lower_mm: 2.0,
                upper_mm: 1.0
            }
        );
        assert!(e.to_string().contains("sample 1"), "{e}");
        let tube = Tube {
            t_s: &[0.0, 1.0],
            lower_mm: &[0.0; 2],
            upper_mm: &[1.0; 2],
        };
        let e = taut_string(&tube, Some(-0.5), None).unwrap_err();
        assert!(matches!(
            e,
            TautError::EndOutside {
                end: PathEnd::Start,
                ..
            }
        ));
        assert!(e.to_string().contains("start"), "{e}");
        let e = taut_string(&tube, None, Some(f64::NAN)).unwrap_err();
        assert!(matches!(
            e,
            TautError::EndOutside {
                end: PathEnd::End,
                ..
            }
        ));
        let _: &dyn std::error::Error = &e;
    }

    #[test]
    fn path_helpers() {
        let path = [(0.0, 0.0), (1.0, 2.0), (3.0, 1.0)];
        assert_eq!(peak_speed_mm_s(&path), 2.0);
        assert_eq!(travel_mm(&path), 3.0);
        assert_eq!(position_at(&path, -1.0), 0.0);
        assert_eq!(position_at(&path, 0.5), 1.0);
        assert_eq!(position_at(&path, 1.0), 2.0);
        assert_eq!(position_at(&path, 2.0), 1.5);
        assert_eq!(position_at(&path, 3.0), 1.0);
        assert_eq!(position_at(&path, 9.0), 1.0);
        assert!(position_at(&[], 0.0).is_nan());
        assert_eq!(position_at(&[(1.0, 5.0)], 0.0), 5.0);
        assert_eq!(peak_speed_mm_s(&[(1.0, 5.0)]), 0.0);
        assert_eq!(travel_mm(&[]), 0.0);
    }

    #[test]
    fn million_samples_lissajous() {
        // one axis of a lissajous-like tool path through a 70 mm field less a 1 mm margin:
        // 10^6 samples over 100 s; prints the time (no assertion on it)
        let n = 1_000_000;
        let t_s: Vec<f64> = (0..n).map(|k| k as f64 * 1e-4).collect();
        let p = |t: f64| {
            150.0 + 120.0 * (0.3 * t).sin() + 40.0 * (2.3 * t + 0.4).sin() + 8.0 * (17.0 * t).cos()
        };
        let tube = Owned::around(t_s, p, 34.0);
        let start = std::time::Instant::now();
        let path = taut_string(&tube.tube(), Some(p(0.0)), None).unwrap();
        let elapsed = start.elapsed();
        println!(
            "taut_string: {n} samples in {:.1} ms, {} vertices, travel {:.1} mm, peak {:.1} mm/s",
            elapsed.as_secs_f64() * 1e3,
            path.len(),
            travel_mm(&path),
            peak_speed_mm_s(&path)
        );
        assert_feasible(&tube, &path, Some(p(0.0)), None);
        assert_taut(&tube, &path, Some(p(0.0)), None);
        let outside_mm = at_samples(&tube, &path)
            .iter()
            .enumerate()
            .map(|(k, &x)| (tube.lower_mm[k] - x).max(x - tube.upper_mm[k]))
            .fold(f64::NEG_INFINITY, f64::max);
        println!("largest excursion outside the tube: {outside_mm:e} mm");
    }
}
