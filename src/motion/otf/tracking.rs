//! The tracked stage route: each axis follows the tool through its exact reachable sets
//! ([`crate::motion::track`]), and the tool is slowed only where a set runs empty.
//!
//! The tube is sampled at every knot of the tool (piece ends, stroke vertices) and at least
//! every [`MAX_STEP_S`] of nominal time; between samples the tool moves straight. Where the
//! stage cannot follow (an empty set at sample `j`, time `t_j`), the window `[t_j − W, t_j]` is
//! made [`FIX_FACTOR`] times longer, the time added to its laser-off waits (the scanner waits
//! for the stage between marks) where it has any, else to all its pieces (marks run slower),
//! and the sets are propagated again from the first of them (the sets before are unchanged:
//! they depend only on earlier pieces). `W`
//! starts at the longest time an axis takes to reach full speed and grows by half each time the
//! same spot fails again. Job time is what this spends, and only near spots where the stage
//! cannot keep up, in steps of [`FIX_FACTOR`]; route length and corners cost nothing.

use super::TUBE_SLACK;
use super::{clocked, install, overshoots, piece_knots, Piece};
use crate::document::MachineProfile;
use crate::job::JobCtx;
use crate::motion::route::AxisRoute;
use crate::motion::track::{Limits, Reachable, TrackedAxis};
use crate::motion::{SegmentKind, Toolpath};

use super::OtfError;

/// Longest nominal time between two samples of the tube, s. The acceleration between samples
/// narrows the tube by `a·Δt²/8` (2.5 µm at 5,000 mm/s² and 2 ms).
const MAX_STEP_S: f64 = 2e-3;

/// Samples closer than this are one, s.
const MIN_GAP_S: f64 = 1e-9;

/// How much one fix slows the pieces before a sample the stage cannot reach.
const FIX_FACTOR: f64 = 1.1;

/// How much the fix window grows when the same spot fails again.
const WINDOW_GROWTH: f64 = 1.5;

/// Fixes before tracking gives up and the taut route takes over (the benchmarks need at most
/// 1,265, texture-10's band sweep).
const MAX_FIXES: usize = 5_000;

/// Most time the fixes may add (summed over fixes), as a share of the tool's time when
/// tracking starts: beyond it the stage is crawling from spot to spot (texture.toml's 2 mm
/// reach gets there after about 1,000 fixes), and the taut route, which waits where it must,
/// is the better bet. The benchmarks that track add at most 0.96 of it (texture-10's band
/// sweep), most add less than 0.3.
const SLOWING_BUDGET: f64 = 1.0;

/// Rounds of clock alignment and checking before tracking gives up.
const ROUNDS: usize = 8;

/// One sample of the tube: a point of piece `piece` at fraction `u` of its duration, and the
/// interval each axis must keep there, mm.
#[derive(Debug, Clone, Copy)]
struct Sample {
    piece: usize,
    u: f64,
    lower: [f64; 2],
    upper: [f64; 2],
}

/// The samples of the whole tool, with the sample each piece starts at.
struct Samples {
    samples: Vec<Sample>,
    first: Vec<usize>,
}

/// Share of the reach a long step may sag by (see [`Limits::sag_mm`]).
const SAG_SHARE: f64 = 0.01;

/// The axis limits of `profile`, with the sag allowed in a reach of `reach_mm`.
fn limits(profile: &MachineProfile, reach_mm: f64) -> [Limits; 2] {
    [&profile.axis_x, &profile.axis_y].map(|a| Limits {
        v_max_mm_s: a.max_velocity_mm_s,
        a_max_mm_s2: a.max_accel_mm_s2,
        sag_mm: SAG_SHARE * reach_mm,
    })
}

impl Samples {
    /// Samples the tube of half-width `tube_mm` around `pieces` (clipped to the stroke).
    fn new(
        pieces: &[Piece],
        path: &Toolpath,
        profile: &MachineProfile,
        tube_mm: f64,
    ) -> Result<Self, OtfError> {
        let mut samples: Vec<Sample> = Vec::new();
        let mut first = Vec::with_capacity(pieces.len());
        for (j, piece) in pieces.iter().enumerate() {
            // the sample the piece starts at: the last of the piece before
            first.push(samples.len().saturating_sub(1));
            let knots = piece_knots(piece, path);
            for (k, &(u, p)) in knots.iter().enumerate() {
                let fill = match k.checked_sub(1).map(|i| knots[i]) {
                    Some((u0, _)) => {
                        let span_s = (u - u0) * piece.nominal_s.max(piece.duration_s);
                        ((span_s / MAX_STEP_S).ceil() as usize).max(1)
                    }
                    None => 1,
                };
                let (u0, p0) = k.checked_sub(1).map_or((u, p), |i| knots[i]);
                for m in 1..=fill {
                    let s = m as f64 / fill as f64;
                    let (us, ps) = (u0 + s * (u - u0), p0.plus(p.minus(p0).scale(s)));
                    // the first knot of a piece is the last of the one before
                    let joins = us == 0.0 && j > 0;
                    let repeats = samples.last().is_some_and(|l: &Sample| {
                        l.piece == j && (us - l.u) * piece.duration_s <= MIN_GAP_S
                    });
                    if joins || repeats {
                        continue;
                    }
                    let (lower, upper) = bounds(piece, ps, tube_mm, profile)?;
                    samples.push(Sample {
                        piece: j,
                        u: us,
                        lower,
                        upper,
                    });
                }
            }
        }
        Ok(Self { samples, first })
    }

    /// Time from sample `k` to `k + 1` at the pieces' current durations, s.
    fn gap_s(&self, pieces: &[Piece], k: usize) -> f64 {
        let (a, b) = (self.samples[k], self.samples[k + 1]);
        if a.piece == b.piece {
            return (b.u - a.u) * pieces[a.piece].duration_s;
        }
        let between: f64 = pieces[a.piece + 1..b.piece]
            .iter()
            .map(|p| p.duration_s)
            .sum();
        (1.0 - a.u) * pieces[a.piece].duration_s + between + b.u * pieces[b.piece].duration_s
    }
}

/// The interval `(lower, upper)` each axis must keep at the tool's point `p` of `piece`.
fn bounds(
    piece: &Piece,
    p: crate::geom::Pt,
    tube_mm: f64,
    profile: &MachineProfile,
) -> Result<([f64; 2], [f64; 2]), OtfError> {
    let mut lower = [0.0; 2];
    let mut upper = [0.0; 2];
    for (k, axis) in ['x', 'y'].into_iter().enumerate() {
        let coord = if k == 0 { p.x } else { p.y };
        lower[k] = (coord - tube_mm).max(0.0);
        upper[k] = (coord + tube_mm).min(profile.stroke_mm[k]);
        if lower[k] > upper[k] {
            return Err(OtfError::OutOfStroke {
                geometry: piece.geometry,
                axis,
            });
        }
    }
    Ok((lower, upper))
}

/// The slowing of the pieces before spots the stage cannot reach (see the module
/// documentation), within its budget.
struct Fixes {
    base_window_s: f64,
    window_s: f64,
    last_fail_s: f64,
    count: usize,
    added_s: f64,
    budget_s: f64,
}

impl Fixes {
    fn new(limits: &[Limits; 2], pieces: &[Piece]) -> Self {
        let base_window_s = limits
            .iter()
            .map(|l| l.v_max_mm_s / l.a_max_mm_s2)
            .fold(0.0, f64::max);
        let tool_s: f64 = pieces.iter().map(|p| p.duration_s).sum();
        Self {
            base_window_s,
            window_s: base_window_s,
            last_fail_s: f64::NEG_INFINITY,
            count: 0,
            added_s: 0.0,
            budget_s: SLOWING_BUDGET * tool_s,
        }
    }

    /// Slows the pieces in the window before sample `k` (reached at `t_s[k]`); returns the
    /// sample to propagate again from, `None` past the budget.
    fn slow(
        &mut self,
        pieces: &mut [Piece],
        samples: &Samples,
        t_s: &[f64],
        k: usize,
    ) -> Option<usize> {
        self.count += 1;
        if self.count > MAX_FIXES || self.added_s > self.budget_s {
            return None;
        }
        let fail_s = t_s[k];
        self.window_s = if fail_s <= self.last_fail_s + self.base_window_s {
            (self.window_s * WINDOW_GROWTH).min(fail_s.max(self.base_window_s))
        } else {
            self.base_window_s
        };
        self.last_fail_s = fail_s;
        let from = t_s[..=k].partition_point(|&t| t < fail_s - self.window_s);
        let first_piece = samples.samples[from.min(k)].piece;
        self.added_s += add_time(&mut pieces[first_piece..=samples.samples[k].piece]);
        Some(samples.first[first_piece])
    }
}

/// Makes `window` last [`FIX_FACTOR`] times longer, the added time given to what it does
/// between marks, laser off (jumps and delays: the scanner waits for the stage, as
/// step-and-scan does) where it has any, else spread over all its pieces (marks run slower).
/// Returns the time added, s.
fn add_time(window: &mut [Piece]) -> f64 {
    let is_wait = |p: &Piece| p.kind != SegmentKind::Mark;
    let total_s: f64 = window.iter().map(|p| p.duration_s).sum();
    let waits_s: f64 = window
        .iter()
        .filter(|p| is_wait(p))
        .map(|p| p.duration_s)
        .sum();
    let added_s = total_s * (FIX_FACTOR - 1.0);
    if waits_s > 0.0 {
        let stretch = 1.0 + added_s / waits_s;
        for p in window.iter_mut().filter(|p| is_wait(p)) {
            p.duration_s *= stretch;
        }
    } else {
        for p in window.iter_mut() {
            p.duration_s *= FIX_FACTOR;
        }
    }
    added_s
}

/// Propagates both axes' sets to sample `k` (`t_s[k]` set on the way); false where one runs
/// empty.
fn step_both(
    sets: &mut [Reachable; 2],
    samples: &Samples,
    pieces: &[Piece],
    limits: &[Limits; 2],
    t_s: &mut [f64],
    k: usize,
) -> bool {
    let dt = samples.gap_s(pieces, k - 1);
    let next = if k + 1 < t_s.len() {
        samples.gap_s(pieces, k)
    } else {
        0.0
    };
    t_s[k] = t_s[k - 1] + dt;
    let s = samples.samples[k];
    let mut reached = true;
    for (axis, set) in sets.iter_mut().enumerate() {
        let l = limits[axis];
        let eps = l.narrowing_mm(dt).max(l.narrowing_mm(next));
        reached &= set
            .step(dt, s.lower[axis] + eps, s.upper[axis] - eps, l)
            .is_ok();
    }
    reached
}

/// The tracked routes of `pieces` (slowing them where needed), with the number of fixes; `None`
/// past the fix budget.
fn track(
    pieces: &mut [Piece],
    samples: &Samples,
    limits: [Limits; 2],
    ctx: &JobCtx,
) -> Result<Option<(usize, [TrackedAxis; 2])>, OtfError> {
    let n = samples.samples.len();
    let Some(&first) = samples.samples.first() else {
        return Ok(None);
    };
    let mut sets = [Reachable::default(), Reachable::default()];
    let mut t_s = vec![0.0; n];
    let mut fixes = Fixes::new(&limits, pieces);
    let mut k = 0;
    while k < n {
        if k == 0 {
            for (axis, set) in sets.iter_mut().enumerate() {
                if set.start(first.lower[axis], first.upper[axis]).is_err() {
                    return Ok(None);
                }
            }
        } else if !step_both(&mut sets, samples, pieces, &limits, &mut t_s, k) {
            let Some(from) = fixes.slow(pieces, samples, &t_s, k) else {
                return Ok(None);
            };
            if fixes.count % 64 == 0 {
                ctx.check()?;
            }
            for set in &mut sets {
                set.truncate(from);
            }
            k = from;
            continue;
        }
        if k % 65_536 == 0 {
            ctx.check()?;
        }
        k += 1;
    }
    let dt: Vec<f64> = (0..n.saturating_sub(1))
        .map(|k| samples.gap_s(pieces, k))
        .collect();
    let [sx, sy] = &sets;
    Ok(Some((
        fixes.count,
        [sx.route(&dt, limits[0]), sy.route(&dt, limits[1])],
    )))
}

/// Lowers `pieces` with tracked stage routes into `path`: `None` when tracking did not settle
/// (the caller falls back on the taut route).
pub(super) fn lower_tracked(
    mut pieces: Vec<Piece>,
    path: &mut Toolpath,
    profile: &MachineProfile,
    reach_mm: f64,
    clock_s: Option<f64>,
    ctx: &JobCtx,
) -> Result<Option<()>, OtfError> {
    let tube_mm = reach_mm * (1.0 - TUBE_SLACK);
    let limits = limits(profile, reach_mm);
    for _ in 0..ROUNDS {
        ctx.check()?;
        let mut run = clocked(&pieces, path, clock_s);
        let before: Vec<f64> = run.iter().map(|p| p.duration_s).collect();
        let samples = Samples::new(&run, path, profile, tube_mm)?;
        let Some((fixes, [x, y])) = track(&mut run, &samples, limits, ctx)? else {
            return Ok(None);
        };
        // on a clock, fixes move marks off their ticks: carry them back and align again
        if fixes == 0 || clock_s.is_none() {
            let (x, y) = (AxisRoute::Tracked(x), AxisRoute::Tracked(y));
            install(path, &run, x, y, clock_s);
            let over = overshoots(path, reach_mm, profile.stroke_mm);
            if over.is_empty() {
                return Ok(Some(()));
            }
            // rounding at the edge of the reach: slow the pieces there a little, track again
            let starts = super::piece_starts(&run);
            for (t, _) in over {
                let j = starts.partition_point(|&s| s <= t).saturating_sub(1);
                if let Some(p) = run.get_mut(j) {
                    p.duration_s *= FIX_FACTOR;
                }
            }
        }
        carry_back(&mut pieces, &run, &before);
    }
    Ok(None)
}

/// Carries the slowing of `run` (durations `before` it) to the pieces it came from.
fn carry_back(pieces: &mut [Piece], run: &[Piece], before: &[f64]) {
    for (p, &was) in run.iter().zip(before) {
        if was > 0.0 && p.nominal_s > 0.0 && p.duration_s > was {
            if let Some(origin) = pieces.get_mut(p.origin) {
                origin.duration_s *= p.duration_s / was;
            }
        }
    }
}
