//! The tracked stage route: each axis follows the tool through its exact reachable sets
//! ([`crate::motion::track`]), and the tool is slowed only where a set runs empty.
//!
//! The tube is sampled at every knot of the tool (piece ends, stroke vertices) and at least
//! every [`MAX_STEP_S`] of nominal time; between samples the tool moves straight. Where the
//! stage cannot follow (an empty set at sample `j`, time `t_j`), the tool is slowed before
//! `j` and the sets are propagated again from the first piece slowed (the sets before are
//! unchanged: they depend only on earlier pieces). Two rules ([`FixRule`]) say where:
//!
//! * **window**: the window `[t_j − W, t_j]` is made [`FIX_FACTOR`] times longer, the time
//!   added to its laser-off waits (the scanner waits for the stage between marks) where it has
//!   any, else to all its pieces (marks run slower). `W` starts at the longest time an axis
//!   takes to reach full speed and grows by half each time the same spot fails again.
//! * **wait first**: the scanner waits on the last jump before `j`, from 1 ms and
//!   [`WAIT_GROWTH`] times more each time the spot fails again (a spot just after one fixed on
//!   the same jump goes on from there). Where a wait of [`WAIT_CAP_WINDOWS`] windows does not
//!   get the stage past, it is taken back and the jump before is tried, up to [`WAIT_DEPTH`]
//!   jumps back, then the window rule. Its jumps are sampled at least [`JUMP_SAMPLES`] times,
//!   so that a long wait does not cap the stage's acceleration.
//!
//! The window rule spreads the slowing over the tool's laser-off time; where a small reach
//! makes the scanner wait at every cell, that adds more than the tool's own time before the
//! stage gets through (texture.toml: the taut fallback, slower than step-and-scan), and the
//! wait-first rule spends the time only where the stage needs it. Neither wins everywhere, so
//! the caller tracks with both and keeps the shorter job. Job time is what this spends, and
//! only near spots where the stage cannot keep up; route length and corners cost nothing.

use super::TUBE_SLACK;
use super::{clocked, install, overshoots, piece_knots, Piece, PieceStage};
use crate::document::MachineProfile;
use crate::job::JobCtx;
use crate::motion::route::AxisRoute;
use crate::motion::track::{Limits, Reachable, TrackedAxis};
use crate::motion::{SegmentKind, Toolpath};

use super::OtfError;
use std::sync::atomic::{AtomicU64, Ordering};

/// Longest nominal time between two samples of the tube, s. The acceleration between samples
/// narrows the tube by `a·Δt²/8` (2.5 µm at 5,000 mm/s² and 2 ms).
const MAX_STEP_S: f64 = 2e-3;

/// Least samples on a jump under [`FixRule::WaitFirst`]: a jump the scanner waits on is
/// longer than its nominal time, and a long step between samples caps the acceleration
/// ([`Limits::accel_mm_s2`]); 16 samples keep the full acceleration up to a wait of 0.2 s in
/// a 2 mm reach at 900 mm/s².
const JUMP_SAMPLES: usize = 16;

/// Samples closer than this are one, s.
const MIN_GAP_S: f64 = 1e-9;

/// How much one fix slows the pieces before a sample the stage cannot reach.
const FIX_FACTOR: f64 = 1.1;

/// The first wait a spot the stage cannot reach adds to the jump before it, s.
const WAIT_STEP_S: f64 = 1e-3;

/// How much the wait on that jump grows each time the spot fails again.
const WAIT_GROWTH: f64 = 1.25;

/// The longest wait tried on one jump, in fix windows (the time an axis takes to reach full
/// speed): 0.12 s on seed 002's axes, about a rest-to-rest move across texture.toml's 4 mm
/// field. Longer waits there only meant the stage had to brake before the jump.
const WAIT_CAP_WINDOWS: f64 = 0.5;

/// Jumps back from a spot tried for the wait.
const WAIT_DEPTH: usize = 4;

/// How much the fix window grows when the same spot fails again.
const WINDOW_GROWTH: f64 = 1.5;

/// Fixes before the window rule gives up (the benchmarks need at most 1,265, texture-10's band
/// sweep).
const MAX_FIXES: usize = 5_000;

/// Fixes before [`FixRule::WaitFirst`] gives up: its waits grow from a millisecond, so a spot
/// takes some ten fixes where the window rule takes one or two.
const MAX_WAIT_FIXES: usize = 1_000_000;

/// Most time the window rule's fixes may add (summed over fixes), as a share of the tool's
/// time when tracking starts: beyond it the stage is crawling from spot to spot (texture.toml's
/// 2 mm reach gets there after about 1,000 fixes). The benchmarks that track add at most 0.96
/// of it (texture-10's band sweep), most add less than 0.3.
const SLOWING_BUDGET: f64 = 1.0;

/// [`SLOWING_BUDGET`] of [`FixRule::WaitFirst`]: its waits are spent only where the stage
/// needs them, and on texture.toml's 2 mm reach it settles after adding 1.6 times the tool's
/// time, a job of 0.61 times its step-and-scan time (BENCHMARKS, issue 26).
const WAIT_SLOWING_BUDGET: f64 = 3.0;

/// Rounds of clock alignment and checking before tracking gives up.
const ROUNDS: usize = 8;

/// One sample of the tube: a point of piece `piece` at fraction `u` of its duration, the
/// interval each axis must keep there, mm, and whether the stage must be at rest there (a
/// field marked step-and-scan in a mixed job).
#[derive(Debug, Clone, Copy)]
struct Sample {
    piece: usize,
    u: f64,
    lower: [f64; 2],
    upper: [f64; 2],
    still: bool,
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
        least_jump_samples: usize,
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
                        let least = match piece.kind {
                            SegmentKind::Jump => least_jump_samples,
                            _ => 1,
                        };
                        ((span_s / MAX_STEP_S).ceil() as usize).max(least)
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
                    // a jump into or out of a still stretch is tied to the tool at its ends
                    // only (the scanner jumps in its own frame meanwhile)
                    let free = piece.stage == PieceStage::FreeJump && us < 1.0;
                    let (lower, upper) = if free {
                        ([0.0; 2], profile.stroke_mm)
                    } else {
                        bounds(piece, ps, tube_mm, profile)?
                    };
                    // the last sample of a piece is the first of the next
                    let next_still = us >= 1.0
                        && pieces
                            .get(j + 1)
                            .is_some_and(|p| p.stage == PieceStage::Still);
                    samples.push(Sample {
                        piece: j,
                        u: us,
                        lower,
                        upper,
                        still: piece.stage == PieceStage::Still || next_still,
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

/// How a spot the stage cannot reach is fixed. Both are tried, and the faster job is kept
/// ([`super::lower_on_the_fly`]): neither wins everywhere (BENCHMARKS, issue 26).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum FixRule {
    /// The window before the spot is made [`FIX_FACTOR`] times longer, its laser-off time
    /// first (the module documentation).
    Window,
    /// The scanner waits on the last jump before the spot, longer each time the spot fails
    /// again; where that does not get the stage past, on each of the [`WAIT_DEPTH`] jumps
    /// before it in turn; then the window rule.
    WaitFirst,
}

/// A window-rule job at most this much longer than the tool's time slowed nothing (the rest is
/// rounding in the sums of durations), s: the wait-first rule stops and its job is not
/// compared ([`super::lower_tracked_faster`]).
pub(super) const NO_SLOWING_S: f64 = 1e-9;

/// How often (in samples) a tracking that slows nothing looks whether the window rule's
/// tracking beside it has finished without slowing anything.
const CAP_CHECK_SAMPLES: usize = 1_024;

/// The most time a tracking may add before it gives up, shared between threads: the
/// wait-first rule runs beside the window rule and stops once the time it has added for good
/// ([`Fixes::kept_s`]) exceeds the window rule's whole slowing (a job it could then only make
/// slower). That time never decreases, so the cap ends only runs that would lose: the job
/// kept does not depend on which thread finishes first.
#[derive(Debug)]
pub(super) struct SlowingCap(AtomicU64);

impl SlowingCap {
    /// No cap.
    pub(super) fn none() -> Self {
        Self(AtomicU64::new(f64::INFINITY.to_bits()))
    }

    /// The cap, s.
    fn get_s(&self) -> f64 {
        f64::from_bits(self.0.load(Ordering::Relaxed))
    }

    /// Sets the cap to `cap_s`.
    pub(super) fn set_s(&self, cap_s: f64) {
        self.0.store(cap_s.to_bits(), Ordering::Relaxed);
    }
}

impl FixRule {
    /// Fixes before tracking gives up.
    fn max_fixes(self) -> usize {
        match self {
            Self::Window => MAX_FIXES,
            Self::WaitFirst => MAX_WAIT_FIXES,
        }
    }

    /// Most time the fixes may add, as a share of the tool's time.
    fn slowing_budget(self) -> f64 {
        match self {
            Self::Window => SLOWING_BUDGET,
            Self::WaitFirst => WAIT_SLOWING_BUDGET,
        }
    }

    /// Least samples on a jump (the window rule's jumps keep their nominal sampling).
    fn least_jump_samples(self) -> usize {
        match self {
            Self::Window => 1,
            Self::WaitFirst => JUMP_SAMPLES,
        }
    }
}

/// The slowing of the pieces before spots the stage cannot reach (see the module
/// documentation), within its budget.
struct Fixes {
    rule: FixRule,
    /// The controller clock's period, s: waits are whole ticks, so that the marks after them
    /// stay on their ticks.
    tick_s: Option<f64>,
    /// Fixes made by the window rule (they move marks off their ticks).
    window_count: usize,
    base_window_s: f64,
    window_s: f64,
    last_fail_s: f64,
    count: usize,
    added_s: f64,
    budget_s: f64,
    /// The spot being fixed: the first sample found unreachable there, and the wait tried.
    spot: Option<Spot>,
}

/// A spot the stage could not reach, and how it is being fixed.
#[derive(Debug, Clone, Copy)]
struct Spot {
    /// The first sample found unreachable there.
    sample: usize,
    /// The jump the scanner waits on for the stage; `None` once waiting has not helped (the
    /// window before is slowed instead).
    wait: Option<Wait>,
    /// How many jumps back from the spot the wait is.
    depth: usize,
}

/// A wait on a jump for the stage.
#[derive(Debug, Clone, Copy)]
struct Wait {
    /// The jump's piece.
    piece: usize,
    /// Its duration before this spot's wait, s (restored exactly where the wait is taken
    /// back).
    before_s: f64,
    /// Time added to it for this spot, s.
    waited_s: f64,
    /// The next time to add, s: from [`WAIT_STEP_S`], times [`WAIT_GROWTH`] each time the
    /// spot fails again; a spot just after one fixed on the same jump goes on from its step.
    step_s: f64,
}

impl Fixes {
    fn new(limits: &[Limits; 2], pieces: &[Piece], rule: FixRule, tick_s: Option<f64>) -> Self {
        let base_window_s = limits
            .iter()
            .map(|l| l.v_max_mm_s / l.a_max_mm_s2)
            .fold(0.0, f64::max);
        let tool_s: f64 = pieces.iter().map(|p| p.duration_s).sum();
        Self {
            rule,
            tick_s,
            window_count: 0,
            base_window_s,
            window_s: base_window_s,
            last_fail_s: f64::NEG_INFINITY,
            count: 0,
            added_s: 0.0,
            budget_s: rule.slowing_budget() * tool_s,
            spot: None,
        }
    }

    /// Slows the tool before sample `k` (reached at `t_s[k]`) by the rule; returns the sample
    /// to propagate again from, `None` past the budget.
    fn slow(
        &mut self,
        pieces: &mut [Piece],
        samples: &Samples,
        t_s: &[f64],
        k: usize,
    ) -> Option<usize> {
        self.count += 1;
        if self.count > self.rule.max_fixes() || self.added_s > self.budget_s {
            return None;
        }
        if self.rule == FixRule::Window {
            return Some(self.slow_window(pieces, samples, t_s, k));
        }
        let spot = self.spot_at(pieces, samples, t_s, k);
        let Some(wait) = spot.wait else {
            return Some(self.slow_window(pieces, samples, t_s, k));
        };
        if wait.waited_s < WAIT_CAP_WINDOWS * self.base_window_s {
            return Some(self.wait_longer(pieces, samples, spot, wait));
        }
        // waiting there does not get the stage past: take it back, wait on the jump before
        pieces[wait.piece].duration_s = wait.before_s;
        self.added_s -= wait.waited_s;
        let before = (0..wait.piece)
            .rev()
            .find(|&j| pieces[j].kind == SegmentKind::Jump)
            .filter(|_| spot.depth < WAIT_DEPTH);
        if let Some(before) = before {
            let earlier = Spot {
                wait: Some(Wait {
                    piece: before,
                    before_s: pieces[before].duration_s,
                    waited_s: 0.0,
                    step_s: WAIT_STEP_S,
                }),
                depth: spot.depth + 1,
                ..spot
            };
            let from = self.wait_longer(pieces, samples, earlier, earlier.wait?);
            return Some(from);
        }
        self.spot = Some(Spot { wait: None, ..spot });
        let window_from = self.slow_window(pieces, samples, t_s, k);
        Some(samples.first[wait.piece].min(window_from))
    }

    /// The spot sample `k` belongs to: the one being fixed where `k` is not past it, else a
    /// new spot waiting on the last jump before `k` (going on from the step of the spot before
    /// where that waited on the same jump).
    fn spot_at(&mut self, pieces: &[Piece], samples: &Samples, t_s: &[f64], k: usize) -> Spot {
        let spot = match self.spot {
            Some(spot) if k <= spot.sample => spot,
            previous => {
                let piece = last_jump(pieces, samples, t_s, k, self.base_window_s);
                let step_s = previous
                    .and_then(|p| p.wait)
                    .filter(|w| Some(w.piece) == piece)
                    .map_or(WAIT_STEP_S, |w| w.step_s);
                Spot {
                    sample: k,
                    wait: piece.map(|piece| Wait {
                        piece,
                        before_s: pieces[piece].duration_s,
                        waited_s: 0.0,
                        step_s,
                    }),
                    depth: 0,
                }
            }
        };
        self.spot = Some(spot);
        spot
    }

    /// Adds the next step of `wait` (on whole ticks) to its jump and makes `spot` wait so;
    /// returns the sample to propagate again from.
    fn wait_longer(
        &mut self,
        pieces: &mut [Piece],
        samples: &Samples,
        spot: Spot,
        wait: Wait,
    ) -> usize {
        let add_s = self.on_ticks(wait.step_s);
        pieces[wait.piece].duration_s += add_s;
        self.added_s += add_s;
        self.spot = Some(Spot {
            wait: Some(Wait {
                waited_s: wait.waited_s + add_s,
                step_s: wait.step_s * WAIT_GROWTH,
                ..wait
            }),
            ..spot
        });
        samples.first[wait.piece]
    }

    /// The time added that no later fix takes back, s: all but the wait being tried at the
    /// current spot. It never decreases, and the job ends at least this much above the tool's
    /// time, so a cap on it ends only runs that would lose (a cap on all the time added could
    /// end a run just before a wait is taken back, and which run it ends would then depend on
    /// when the other thread sets the cap).
    fn kept_s(&self) -> f64 {
        let trying_s = self.spot.and_then(|s| s.wait).map_or(0.0, |w| w.waited_s);
        self.added_s - trying_s
    }

    /// A wait of `wait_s`, rounded up to whole ticks on a clock.
    fn on_ticks(&self, wait_s: f64) -> f64 {
        self.tick_s
            .map_or(wait_s, |p| super::ceil_to_tick(wait_s, p).max(p))
    }

    /// Makes the window before sample `k` [`FIX_FACTOR`] times longer; returns the sample to
    /// propagate again from.
    fn slow_window(
        &mut self,
        pieces: &mut [Piece],
        samples: &Samples,
        t_s: &[f64],
        k: usize,
    ) -> usize {
        self.window_count += 1;
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
        samples.first[first_piece]
    }
}

/// The last jump at or before sample `k` that starts within `window_s` of it: where the
/// scanner can wait for the stage just before the spot it cannot reach.
fn last_jump(
    pieces: &[Piece],
    samples: &Samples,
    t_s: &[f64],
    k: usize,
    window_s: f64,
) -> Option<usize> {
    let last = samples.samples[k].piece;
    let jump = (0..=last)
        .rev()
        .find(|&j| pieces[j].kind == SegmentKind::Jump)?;
    let starts_s = t_s[samples.first[jump]];
    (starts_s >= t_s[k] - window_s).then_some(jump)
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
            .step(dt, s.lower[axis] + eps, s.upper[axis] - eps, l, s.still)
            .is_ok();
    }
    reached
}

/// The tracked routes of `pieces` (slowing them where needed), with the number of fixes that
/// moved marks off their ticks (the window rule's: waits on a clock are whole ticks); `None`
/// past the fix budget.
fn track(
    pieces: &mut [Piece],
    samples: &Samples,
    limits: [Limits; 2],
    rule: FixRule,
    cap: &SlowingCap,
    tick_s: Option<f64>,
    ctx: &JobCtx,
) -> Result<Option<(usize, [TrackedAxis; 2])>, OtfError> {
    let n = samples.samples.len();
    let Some(&first) = samples.samples.first() else {
        return Ok(None);
    };
    let mut sets = [Reachable::default(), Reachable::default()];
    let mut t_s = vec![0.0; n];
    let mut fixes = Fixes::new(&limits, pieces, rule, tick_s);
    let mut k = 0;
    while k < n {
        if k == 0 {
            for (axis, set) in sets.iter_mut().enumerate() {
                if set.start(first.lower[axis], first.upper[axis]).is_err() {
                    return Ok(None);
                }
            }
        } else if !step_both(&mut sets, samples, pieces, &limits, &mut t_s, k) {
            if fixes.kept_s() > cap.get_s() {
                return Ok(None);
            }
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
        // the window rule kept up without slowing anything: nothing can be shorter
        if k % CAP_CHECK_SAMPLES == 0 && cap.get_s() <= NO_SLOWING_S {
            return Ok(None);
        }
        k += 1;
    }
    let dt: Vec<f64> = (0..n.saturating_sub(1))
        .map(|k| samples.gap_s(pieces, k))
        .collect();
    let [sx, sy] = &sets;
    Ok(Some((
        fixes.window_count,
        [sx.route(&dt, limits[0]), sy.route(&dt, limits[1])],
    )))
}

/// Lowers `pieces` with tracked stage routes into `path`, fixing spots the stage cannot reach
/// by `rule`, giving up once its fixes add more than `cap` (besides the rule's budget): `None`
/// when tracking did not settle (the caller falls back on the taut route).
#[allow(clippy::too_many_arguments)]
pub(super) fn lower_tracked(
    mut pieces: Vec<Piece>,
    path: &mut Toolpath,
    profile: &MachineProfile,
    reach_mm: f64,
    clock_s: Option<f64>,
    rule: FixRule,
    cap: &SlowingCap,
    ctx: &JobCtx,
) -> Result<Option<()>, OtfError> {
    let tube_mm = reach_mm * (1.0 - TUBE_SLACK);
    let limits = limits(profile, reach_mm);
    for _ in 0..ROUNDS {
        ctx.check()?;
        let mut run = clocked(&pieces, path, clock_s);
        let before: Vec<f64> = run.iter().map(|p| p.duration_s).collect();
        let samples = Samples::new(&run, path, profile, tube_mm, rule.least_jump_samples())?;
        // fixes that move marks off their ticks (waits are whole ticks)
        let Some((off_tick, [x, y])) = track(&mut run, &samples, limits, rule, cap, clock_s, ctx)?
        else {
            return Ok(None);
        };
        // on a clock, fixes move marks off their ticks: carry them back and align again
        if off_tick == 0 || clock_s.is_none() {
            let (x, y) = (AxisRoute::Tracked(x), AxisRoute::Tracked(y));
            install(path, &run, x, y, clock_s);
            let over = overshoots(path, reach_mm, profile.stroke_mm);
            let fast = fast_free_jumps(path, &run, profile.scanner.jump_speed_mm_s);
            if over.is_empty() && fast.is_empty() {
                return Ok(Some(()));
            }
            // a jump into or out of a still stretch the scanner cannot make in its time
            for (j, factor) in fast {
                run[j].duration_s *= factor;
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

/// Relative slack of the scanner's speed on a free jump (rounding in the route's positions).
const JUMP_SPEED_SLACK: f64 = 1e-6;

/// The free jumps ([`PieceStage::FreeJump`]) of `path`, laid out from `pieces`, on which the
/// scanner moves faster than `jump_speed_mm_s` (the stage moved against the jump): each
/// piece's index and how much longer it must last (with a little to spare, as the stage's
/// route changes with it).
fn fast_free_jumps(path: &Toolpath, pieces: &[Piece], jump_speed_mm_s: f64) -> Vec<(usize, f64)> {
    // the segments are the pieces, after the wait while the stage gets under way
    let first = path.segments.len().saturating_sub(pieces.len());
    let mut out = Vec::new();
    for (j, piece) in pieces.iter().enumerate() {
        if piece.stage != PieceStage::FreeJump {
            continue;
        }
        let Some(seg) = path.segments.get(first + j) else {
            continue;
        };
        if let crate::motion::ScanMotion::Line { from, to, move_s } = seg.scan {
            let speed_mm_s = from.dist(to) / move_s;
            if move_s > 0.0 && speed_mm_s > jump_speed_mm_s * (1.0 + JUMP_SPEED_SLACK) {
                out.push((j, speed_mm_s / jump_speed_mm_s * (1.0 + 1e-3)));
            }
        }
    }
    out
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
