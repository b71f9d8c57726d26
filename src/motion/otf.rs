//! On-the-fly lowering: the stage moves on a continuous route while the scanner marks.
//!
//! 1. The tool-centre point's time law comes from the plan's stroke order as in step-and-scan
//!    (marks at mark speed, jumps at jump speed, the laser and jump delays), as *pieces*; a
//!    long stroke is cut into parts of at least [`PART_MM`] so that it can be slowed locally.
//! 2. Per axis the stage must keep `|tcp − stage| ≤ h` with `h` = half the field less the
//!    profile's `otf_margin_mm`, and stay inside its stroke. With a seed 001 route (`lsa`,
//!    `cetsp-ga`) each knot's interval is narrowed to [`FOLLOW_MM`] around the route's position
//!    at that knot's nominal time.
//! 3. **Tracked route** (first choice without a seed 001 route, [`tracking`]): each axis follows
//!    that tube through its
//!    exact reachable sets at the axis' speed and acceleration limits ([`super::track`]); the
//!    tool is slowed only where no admissible stage motion keeps up with it, by two rules
//!    tracked side by side, the shorter job kept ([`tracking::FixRule`]). Job time is what
//!    this minimises: nothing is slowed to keep a route short or its corners small.
//! 4. **Taut route** (where tracking does not settle within its fix budget: a reach too small
//!    for motion and marking to overlap): through the tube the **taut string** is the shortest
//!    route and has the least peak speed of any route ([`super::taut`]). Retiming: where the
//!    string is faster than the axis limit, or where one of its corners would depart from it by
//!    more than [`CORNER_SHARE`] of the reach once blended at the axis acceleration
//!    (`Δv² / (8 a)`), the pieces under that stretch are slowed (the scanner waits, marks run
//!    slower), and the string is computed again, until none is.
//! 5. The taut route's corners are blended at the axis acceleration ([`super::blend`]): the
//!    speed stays within the string's, the acceleration within the limit. A blend departs from
//!    the string's corner *outwards* (it cuts the corner the tube pushed the string round), so
//!    the blended route is checked on a 1 ms grid and at every knot; where it leaves the reach or
//!    the stroke, the tube there is narrowed by the excess (the string then bends that much
//!    further inside and its blend comes back to the edge), or where that would leave less
//!    than [`MIN_TUBE_SHARE`] of the reach, and where overlapping blends exceed the
//!    acceleration, the pieces there are slowed by [`SLOW_FACTOR`] (a slowdown by `f` divides
//!    a corner's departure by `f²`). Rounds repeat until the route is clean; after
//!    [`SLOW_ROUNDS`] the guaranteed route takes over (half the reach kept for a moving-average
//!    smoothing and the speed capped so that it stays inside; it has never been needed on the
//!    benchmarks).
//!
//! Either route is checked on a 1 ms grid and at every knot of the tool before it is kept.
//! The taut route starts with the stage at rest, waiting half the longest blend at the first
//! point; the tracked route starts at rest inside the first point's reach.

use super::blend::CornerBlends;
use super::cetsp::{TimedRoute, ToolKnot};
use super::clock::{ceil_to_tick, MarkClock};
use super::route::{AxisRoute, StageRoute};
use super::taut::{peak_speed_mm_s, taut_string, TautError, Tube};
use super::toolpath::{ScanMotion, Segment, SegmentKind, StageMotion, Toolpath};
use crate::document::{AxisLimits, Geometry, MachineProfile, Plan};
use crate::geom::{is_dot, Pt};
use crate::job::{Cancelled, JobCtx};
use thiserror::Error;

mod tracking;

/// Share of the scanner's reach kept for smoothing the route by the guaranteed fallback.
pub const SMOOTHING_SHARE: f64 = 0.5;

/// Share of the reach the tube leaves free: the string touches the tube at its contacts, and
/// the check allows only [`CHECK_SLACK`] beyond the reach.
const TUBE_SLACK: f64 = 2.0 * CHECK_SLACK;

/// How closely the stage follows a seed 001 route (`lsa`, `cetsp-ga`), per axis, mm: the
/// route's polyline is the paper's; the band lets the blends round its corners.
const FOLLOW_MM: f64 = 1.0;

/// A long stroke is retimed in parts of at least this length, mm (cut at its vertices).
const PART_MM: f64 = 2.0;

/// Share of the reach kept for the blends' departure from the string's corners: corners that
/// would depart further are slowed until they do not.
const CORNER_SHARE: f64 = 0.1;

/// Rounds of slowing the tool where the blended route overshoots or over-accelerates, before
/// the guaranteed fallback (each round divides the departures there by [`SLOW_FACTOR`]²).
pub const SLOW_ROUNDS: usize = 48;

/// How much one round slows the pieces under a trouble spot.
const SLOW_FACTOR: f64 = 1.25;

/// The narrowest tube a repair makes before it slows the tool instead (share of the reach).
const MIN_TUBE_SHARE: f64 = 0.9;

/// The least a repair narrows the tube by, mm (so that rounds make progress).
const MIN_NARROWING_MM: f64 = 0.01;

/// Grid on which the scanner offset is checked (besides every knot), s. Between two checked
/// instants the tool moves straight and the stage's acceleration is at most `a_max`, so the
/// offset leaves the straight line between its checked values by at most `a_max · Δt² / 8`
/// (0.6 µm at 5,000 mm/s² and 1 ms), which [`CHECK_SLACK`] covers.
pub const CHECK_PERIOD_S: f64 = 1e-3;

/// Share of the reach kept as slack by the check (3.5 µm of a 35 mm reach).
const CHECK_SLACK: f64 = 1e-4;

/// Each retiming round slows a bit more than the excess it sees, so that the rounds settle
/// quickly (the route changes as the tool slows).
const RETIME_OVERSHOOT: f64 = 0.02;

/// Retiming rounds before the whole job is slowed uniformly.
pub const RETIME_ROUNDS: usize = 32;

/// A route slope this much above the cap (relative) counts as too fast: durations are float
/// sums, and a slope exactly at the cap must not trigger another round.
const SPEED_TOLERANCE: f64 = 1e-9;

/// Instants closer than this are one knot of the tool's time law, s.
const KNOT_EPS_S: f64 = 1e-12;

/// Why a plan cannot be run on the fly.
#[derive(Debug, Error, PartialEq)]
pub enum OtfError {
    /// A step names a geometry the document does not have.
    #[error("plan step {step} names geometry {geometry}, which the document does not have")]
    NoGeometry {
        /// Step index in marking order.
        step: usize,
        /// The geometry index.
        geometry: usize,
    },
    /// The margin leaves the scanner no reach.
    #[error("otf_margin_mm = {margin_mm} leaves no scanner reach in a {field_mm} mm field (it must be less than half the field)")]
    NoReach {
        /// The margin, mm.
        margin_mm: f64,
        /// The smaller field side, mm.
        field_mm: f64,
    },
    /// A point the stage cannot bring within the scanner's reach.
    #[error(
        "geometry {geometry} lies beyond the stage's stroke plus the scanner's reach ({axis} axis)"
    )]
    OutOfStroke {
        /// The geometry index.
        geometry: usize,
        /// `x` or `y`.
        axis: char,
    },
    /// A mixed job (fields marked step-and-scan inside it) whose stage could not be tracked:
    /// only the tracked route stops the stage for a field.
    #[error(
        "the stage cannot be tracked through the job with {fields} fields marked step-and-scan"
    )]
    MixedNotTracked {
        /// How many fields the plan marks step-and-scan.
        fields: usize,
    },
    /// The route could not be computed.
    #[error("stage route: {0}")]
    Route(#[from] TautError),
    /// Seed 001's route settings are not usable.
    #[error("stage route settings: {0}")]
    RouteSettings(#[from] super::cetsp::CetspError),
    /// The operator cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// What the tool-centre point does during a piece.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Tool {
    Hold(Pt),
    Line(Pt, Pt),
    /// Part `[start_frac, end_frac]` of a stroke (fractions of its length).
    Stroke {
        stroke: usize,
        start_frac: f64,
        end_frac: f64,
    },
}

/// What the stage may do during a piece: a mixed job marks some fields step-and-scan
/// ([`Plan::step_fields`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum PieceStage {
    /// On its route, keeping the tool within the scanner's reach.
    #[default]
    Moving,
    /// At rest: a piece of a field marked step-and-scan (its laser delays, marks, the jumps
    /// between its strokes and the settle after the stage stopped).
    Still,
    /// A jump into or out of a still stretch, in the scanner's own frame as step-and-scan
    /// jumps while the stage moves: only its ends are tied to the tool, the scanner moves
    /// straight between its offsets there, at most at jump speed.
    FreeJump,
}

/// A piece of the tool's time law.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    kind: SegmentKind,
    duration_s: f64,
    tool: Tool,
    /// What the stage may do meanwhile.
    stage: PieceStage,
    geometry: usize,
    /// Half-width of the route's tube at this piece's knots, mm.
    tube_mm: f64,
    /// Index of the piece it comes from before the clock alignment.
    origin: usize,
    /// Start in the tool's nominal time law (before any retiming), s.
    nominal_start_s: f64,
    /// Duration in the nominal time law, s (0 for waits the clock adds).
    nominal_s: f64,
}

/// Lowers a plan for on-the-fly marking (see the module documentation). With `clock_s`, every
/// mark starts and ends on a tick of that controller clock (as [`Toolpath::on_clock`] does for
/// step-and-scan), with one laser-off tick between marks. `ctx` is checked for a cancel between
/// rounds.
pub fn lower_on_the_fly(
    geometries: &[Geometry],
    plan: &Plan,
    profile: &MachineProfile,
    clock_s: Option<f64>,
    ctx: &JobCtx,
) -> Result<Toolpath, OtfError> {
    let reach_mm = reach_mm(profile)?;
    let on_ticks;
    let profile = match clock_s {
        Some(period_s) => {
            on_ticks = switches_on_ticks(profile, period_s);
            &on_ticks
        }
        None => profile,
    };
    let mut path = Toolpath::default();
    let corner_mm = CORNER_SHARE * reach_mm;
    let tube_mm = reach_mm * (1.0 - TUBE_SLACK);
    let mut pieces = tool_pieces(geometries, plan, profile, tube_mm, &mut path)?;
    let mixed = pieces.iter().any(|p| p.stage != PieceStage::Moving);
    if mixed {
        path.still_fields = plan.step_fields.clone();
        path.still_fields.sort_unstable();
        path.still_fields.dedup();
    }
    let follow = plan.stage_route.as_ref();
    // seed 001's routes are followed on the taut route, as measured for the paper's benchmark
    // (docs/BENCHMARKS.md); tracking inside their ±1 mm band is not measured
    if follow.is_none() {
        if let Some(tracked) =
            lower_tracked_faster(&pieces, &path, profile, reach_mm, clock_s, ctx)?
        {
            return Ok(tracked);
        }
    }
    if mixed {
        return Err(OtfError::MixedNotTracked {
            fields: plan.step_fields.len(),
        });
    }
    let full_speed = [
        profile.axis_x.max_velocity_mm_s,
        profile.axis_y.max_velocity_mm_s,
    ];
    for _ in 0..SLOW_ROUNDS {
        ctx.check()?;
        let retimed = retime(
            &mut pieces,
            &path,
            profile,
            full_speed,
            Some(corner_mm),
            follow,
        )?;
        let run = clocked(&pieces, &path, clock_s);
        // without a clock the pieces run as retimed: their routes are known
        let strings = match clock_s {
            None => retimed,
            Some(_) => routes(&run, &path, profile, follow)?,
        };
        let trouble = match blend(strings, profile) {
            Err(spans) => spans
                .into_iter()
                .map(|span| Trouble {
                    span,
                    excess_mm: None,
                })
                .collect(),
            Ok([x, y]) => {
                install(&mut path, &run, x, y, clock_s);
                let trouble = overshoot_spans(&path, reach_mm, profile);
                if trouble.is_empty() {
                    return Ok(path);
                }
                trouble
            }
        };
        repair(&mut pieces, &run, &trouble, reach_mm);
    }
    // the blends never settled: the guaranteed route (a share of the reach for the smoothing,
    // the speed capped so that the smoothing stays inside it)
    let allowance_mm = SMOOTHING_SHARE * reach_mm;
    let cap = [&profile.axis_x, &profile.axis_y].map(|a| speed_cap_mm_s(a, allowance_mm));
    for piece in &mut pieces {
        piece.tube_mm = reach_mm - allowance_mm;
    }
    retime(&mut pieces, &path, profile, cap, None, follow)?;
    let run = clocked(&pieces, &path, clock_s);
    let [rx, ry] = routes(&run, &path, profile, follow)?;
    let x = AxisRoute::smooth(rx, profile.axis_x.max_accel_mm_s2);
    let y = AxisRoute::smooth(ry, profile.axis_y.max_accel_mm_s2);
    install(&mut path, &run, x, y, clock_s);
    Ok(path)
}

/// `profile` on a controller clock of `period_s`: the laser switches on a tick, so switching it
/// on or off takes at least one (its delays are at least a period). Without that, marks that
/// follow each other with no delay (a stroke cut at a seam and its next piece, on a profile
/// with zero delays) have their laser-off tick inserted only once tracked, which moves them off
/// their ticks round after round: the tracking then never settles and the marks are slowed
/// (oversize.svg on a 0.1 ms clock: 4.083 s with zero delays, 3.07 s with them).
fn switches_on_ticks(profile: &MachineProfile, period_s: f64) -> MachineProfile {
    let mut p = profile.clone();
    p.laser.on_delay_s = p.laser.on_delay_s.max(period_s);
    p.laser.off_delay_s = p.laser.off_delay_s.max(period_s);
    p
}

/// The tracked lowering of `pieces`, the shorter job of the two [`tracking::FixRule`]s (in
/// parallel; on a tie the window rule's): `None` when neither settles. The wait-first rule
/// gives up once it has added more than the window rule's slowing.
fn lower_tracked_faster(
    pieces: &[Piece],
    path: &Toolpath,
    profile: &MachineProfile,
    reach_mm: f64,
    clock_s: Option<f64>,
    ctx: &JobCtx,
) -> Result<Option<Toolpath>, OtfError> {
    let by = |rule, cap: &tracking::SlowingCap| -> Result<Option<Toolpath>, OtfError> {
        let mut path = path.clone();
        let tracked = tracking::lower_tracked(
            pieces.to_vec(),
            &mut path,
            profile,
            reach_mm,
            clock_s,
            rule,
            cap,
            ctx,
        )?;
        Ok(tracked.map(|()| path))
    };
    let (no_cap, cap) = (tracking::SlowingCap::none(), tracking::SlowingCap::none());
    // LinuxCNC times its own program, and its timing of the wait-first rule's long jumps
    // departs from the toolpath's (oversize.svg: 26.764 s against 26.736 s): not used there.
    // A streamed plan runs sample by sample as planned: both rules, as on a scan head.
    let own_pace = profile.controller.kind != crate::document::ControllerKind::Ideal
        && !profile
            .controller
            .streamed(crate::document::Motion::OnTheFly);
    if own_pace {
        return by(tracking::FixRule::Window, &no_cap);
    }
    let tool_s: f64 = pieces.iter().map(|p| p.duration_s).sum();
    let (window, wait_first) = rayon::join(
        || {
            let window = by(tracking::FixRule::Window, &no_cap);
            if let Ok(Some(w)) = &window {
                cap.set_s(w.duration_s() - tool_s);
            }
            window
        },
        || by(tracking::FixRule::WaitFirst, &cap),
    );
    Ok(match (window?, wait_first?) {
        // nothing slowed: the wait-first rule stops as soon as it sees that, and whether it
        // had finished first must not decide the job (a rounding difference could)
        (Some(w), _) if w.duration_s() - tool_s <= tracking::NO_SLOWING_S => Some(w),
        (Some(w), Some(f)) if f.duration_s() < w.duration_s() => Some(f),
        (Some(w), _) => Some(w),
        (None, f) => f,
    })
}

/// The pieces as run: on the controller clock when there is one.
fn clocked(pieces: &[Piece], path: &Toolpath, clock_s: Option<f64>) -> Vec<Piece> {
    match clock_s {
        Some(period_s) => on_clock(pieces, path, period_s),
        None => pieces.to_vec(),
    }
}

/// Both axes blended, or the spans (route time) where overlapping blends exceed the
/// acceleration.
type Blended = Result<[AxisRoute; 2], Vec<(f64, f64)>>;

/// The taut strings `[rx, ry]` with their corners blended at each axis' acceleration; where
/// blends overlap beyond it, the spans (route time) to slow down.
fn blend([rx, ry]: [Vec<(f64, f64)>; 2], profile: &MachineProfile) -> Blended {
    let x = CornerBlends::new(&rx, profile.axis_x.max_accel_mm_s2);
    let y = CornerBlends::new(&ry, profile.axis_y.max_accel_mm_s2);
    match (x, y) {
        (Ok(x), Ok(y)) => Ok([AxisRoute::Blends(x), AxisRoute::Blends(y)]),
        (x, y) => Err([x.err(), y.err()]
            .into_iter()
            .flatten()
            .flat_map(|o| o.spans)
            .collect()),
    }
}

/// Installs the route `x`, `y` of `pieces` in `path` and lays out its segments: the stage
/// starts at rest, half the longest blend before the route's time 0 (on a tick with a clock).
fn install(
    path: &mut Toolpath,
    pieces: &[Piece],
    x: AxisRoute,
    y: AxisRoute,
    clock_s: Option<f64>,
) {
    let half_reach_s = x.reach_s().max(y.reach_s()) / 2.0;
    let pad_s = clock_s.map_or(half_reach_s, |p| ceil_to_tick(half_reach_s, p));
    path.route = Some(StageRoute {
        x,
        y,
        offset_s: pad_s,
    });
    path.segments.clear();
    push_segments(path, pieces, pad_s);
}

/// A stretch of the route (route time, s) to repair: where the blended stage overshoots the
/// scanner's reach or the stroke (by `excess_mm`), or where blends overlap beyond the
/// acceleration (`None`).
#[derive(Debug, Clone, Copy)]
struct Trouble {
    span: (f64, f64),
    excess_mm: Option<f64>,
}

/// Instants (job time) where the scanner offset exceeds `reach_mm` on an axis or the stage
/// leaves its stroke, with the excess (mm): checked every [`CHECK_PERIOD_S`] and at every knot
/// of the tool (segment ends and stroke vertices). Between two such instants the offset can
/// grow by at most `a_max · Δt² / 8` (the stage's curvature; the tool moves straight between
/// knots): below a micrometre.
fn overshoots(path: &Toolpath, reach_mm: f64, stroke_mm: [f64; 2]) -> Vec<(f64, f64)> {
    let mut times: Vec<f64> = Vec::new();
    for seg in &path.segments {
        times.push(seg.start_s);
        if let ScanMotion::Mark {
            stroke,
            start_frac,
            end_frac,
        } = seg.scan
        {
            times.extend(
                part_knots(path, stroke, start_frac, end_frac)
                    .iter()
                    .map(|(u, _)| seg.start_s + u * seg.duration_s),
            );
        }
    }
    let end_s = path.duration_s();
    let grid = (end_s / CHECK_PERIOD_S).ceil() as usize;
    times.extend((0..=grid).map(|k| (k as f64 * CHECK_PERIOD_S).min(end_s)));
    let limit_mm = reach_mm * (1.0 - CHECK_SLACK);
    times
        .into_iter()
        .filter_map(|t| {
            let state = path.state_at(t);
            let (offset, stage) = (state.scan, state.stage);
            let excess_mm = [
                offset.x.abs().max(offset.y.abs()) - limit_mm,
                -stage.x,
                -stage.y,
                stage.x - stroke_mm[0],
                stage.y - stroke_mm[1],
            ]
            .into_iter()
            .fold(0.0, f64::max);
            (excess_mm > 0.0).then_some((t, excess_mm))
        })
        .collect()
}

/// The overshoots as stretches of the route: the ramps running at each (a centred ramp moves
/// the position only while it runs; a tiny span around it when none runs).
fn overshoot_spans(path: &Toolpath, reach_mm: f64, profile: &MachineProfile) -> Vec<Trouble> {
    let Some(route) = &path.route else {
        return Vec::new();
    };
    overshoots(path, reach_mm, profile.stroke_mm)
        .into_iter()
        .map(|(t, excess_mm)| {
            let tau = t - route.offset_s;
            let spans = [route.x.active_span(tau), route.y.active_span(tau)];
            let span = spans
                .into_iter()
                .flatten()
                .reduce(|a, b| (a.0.min(b.0), a.1.max(b.1)))
                .unwrap_or((tau - CHECK_PERIOD_S, tau + CHECK_PERIOD_S));
            Trouble {
                span,
                excess_mm: Some(excess_mm),
            }
        })
        .collect()
}

/// Repairs the pieces under each trouble (run `run`, route time): an overshoot narrows their
/// tube by the excess (a blend departs from the string's corner outwards, by `Δv² / (8 a)`,
/// so a string kept that much inside is followed within reach), unless the tube would drop
/// below [`MIN_TUBE_SHARE`] of the reach; then, and where blends overlap, the pieces are slowed
/// by [`SLOW_FACTOR`] (their corners' speed changes, hence blend widths and departures, shrink
/// while the time between corners grows).
fn repair(pieces: &mut [Piece], run: &[Piece], trouble: &[Trouble], reach_mm: f64) {
    let starts = piece_starts(run);
    let mut narrow_mm = vec![0.0f64; pieces.len()];
    let mut slow = vec![false; pieces.len()];
    for t in trouble {
        for j in pieces_under(&starts, t.span) {
            let k = run[j].origin;
            match t.excess_mm {
                Some(e)
                    if pieces[k].tube_mm - e.max(MIN_NARROWING_MM) >= MIN_TUBE_SHARE * reach_mm =>
                {
                    narrow_mm[k] = narrow_mm[k].max(e.max(MIN_NARROWING_MM));
                }
                _ => slow[k] = true,
            }
        }
    }
    for (k, piece) in pieces.iter_mut().enumerate() {
        if slow[k] {
            piece.duration_s *= SLOW_FACTOR;
        } else {
            piece.tube_mm -= narrow_mm[k];
        }
    }
}

/// Half the field less the margin, mm (the smaller side).
fn reach_mm(profile: &MachineProfile) -> Result<f64, OtfError> {
    let field_mm = profile.field_mm[0].min(profile.field_mm[1]);
    let reach_mm = field_mm / 2.0 - profile.otf_margin_mm;
    if reach_mm > 0.0 {
        Ok(reach_mm)
    } else {
        Err(OtfError::NoReach {
            margin_mm: profile.otf_margin_mm,
            field_mm,
        })
    }
}

/// Half-width of the box the tool may cover on each axis while the stage stands still on the
/// fly (a field marked step-and-scan in a mixed job), mm: the tracked route's tube. None: the
/// profile leaves no reach.
pub fn still_reach_mm(profile: &MachineProfile) -> Option<f64> {
    reach_mm(profile).ok().map(|r| r * (1.0 - TUBE_SLACK))
}

/// The fastest route speed whose smoothing departs at most `allowance_mm`: `v² / (2a) ≤ δ`.
fn speed_cap_mm_s(axis: &AxisLimits, allowance_mm: f64) -> f64 {
    axis.max_velocity_mm_s
        .min((2.0 * axis.max_accel_mm_s2 * allowance_mm).sqrt())
}

/// The tool's time law: per stroke a jump (from the second on), the jump delay, the laser-on
/// delay, the mark, the laser-off delay. Adds the strokes to `path`. The strokes of
/// [`Plan::step_fields`] are [`PieceStage::Still`] (with the profile's settle time after the
/// jump into each stretch of them), the jumps into and out of such a stretch
/// [`PieceStage::FreeJump`].
fn tool_pieces(
    geometries: &[Geometry],
    plan: &Plan,
    profile: &MachineProfile,
    tube_mm: f64,
    path: &mut Toolpath,
) -> Result<Vec<Piece>, OtfError> {
    let (laser, scanner) = (&profile.laser, &profile.scanner);
    let mut pieces = Vec::new();
    let mut last_end: Option<Pt> = None;
    // the field of the stroke before, and whether it was marked still
    let mut last_still: Option<(usize, bool)> = None;
    let settle_s = profile.axis_x.settle_s.max(profile.axis_y.settle_s);
    for (k, step) in plan.order.iter().enumerate() {
        let geometry = step.geometry;
        let g = geometries
            .get(geometry)
            .ok_or(OtfError::NoGeometry { step: k, geometry })?;
        let points = g.marking_path(step.start_vertex, step.reversed);
        let (Some(&start), Some(&end)) = (points.first(), points.last()) else {
            continue;
        };
        let stroke = path.push_stroke(k, geometry, step.field, Pt::default(), &points);
        let still = plan.step_fields.contains(&step.field);
        let stage = if still {
            PieceStage::Still
        } else {
            PieceStage::Moving
        };
        // the jump to this stroke: within a still field still, into or out of one free
        let jump_stage = match last_still {
            Some((field, true)) if still && field == step.field => PieceStage::Still,
            Some((_, was_still)) if was_still || still => PieceStage::FreeJump,
            _ => stage,
        };
        let entering = still && last_end.is_some() && jump_stage != PieceStage::Still;
        last_still = Some((step.field, still));
        let mut piece = |kind, duration_s: f64, tool, stage| {
            if duration_s > 0.0 {
                let nominal_start_s = pieces
                    .last()
                    .map_or(0.0, |p: &Piece| p.nominal_start_s + p.nominal_s);
                pieces.push(Piece {
                    kind,
                    duration_s,
                    tool,
                    stage,
                    geometry,
                    tube_mm,
                    origin: pieces.len(),
                    nominal_start_s,
                    nominal_s: duration_s,
                });
            }
        };
        if let Some(from) = last_end {
            let jump_s = from.dist(start) / scanner.jump_speed_mm_s;
            piece(
                SegmentKind::Jump,
                jump_s,
                Tool::Line(from, start),
                jump_stage,
            );
        }
        if entering {
            // the stage settles where it stopped, as step-and-scan's does after a move
            piece(SegmentKind::Settle, settle_s, Tool::Hold(start), stage);
        }
        if last_end.is_some() {
            let hold = Tool::Hold(start);
            piece(SegmentKind::JumpDelay, laser.jump_delay_s, hold, stage);
        }
        piece(
            SegmentKind::LaserOnDelay,
            laser.on_delay_s,
            Tool::Hold(start),
            stage,
        );
        let timing = plan.mark_timing(g, profile);
        if is_dot(path.stroke_points(stroke)) {
            // a dot: its one point marked for the dwell (the scanner holds the tool on it
            // while the stage moves on)
            let dot = Tool::Stroke {
                stroke,
                start_frac: 0.0,
                end_frac: 1.0,
            };
            piece(SegmentKind::Mark, timing.dot_dwell_s, dot, stage);
        }
        let mark_speed_mm_s = timing.speed_mm_s;
        let zones = stream_corners(path, stroke, mark_speed_mm_s, profile);
        for (start_frac, end_frac) in stroke_parts(path, stroke) {
            for (a, b, speed_mm_s) in at_speeds(start_frac, end_frac, &zones, mark_speed_mm_s) {
                let part_mm = (b - a) * path.strokes[stroke].length_mm;
                let tool = Tool::Stroke {
                    stroke,
                    start_frac: a,
                    end_frac: b,
                };
                piece(SegmentKind::Mark, part_mm / speed_mm_s, tool, stage);
            }
        }
        piece(
            SegmentKind::LaserOffDelay,
            laser.off_delay_s,
            Tool::Hold(end),
            stage,
        );
        last_end = Some(end);
    }
    Ok(pieces)
}

/// The tool's knots: times (strictly increasing), points, the geometry of each and its tube
/// half-width (the narrowest of the pieces meeting there).
struct Knots {
    times: Vec<f64>,
    /// The same instants in the tool's nominal time law, s.
    nominal_s: Vec<f64>,
    points: Vec<Pt>,
    owners: Vec<usize>,
    tube_mm: Vec<f64>,
}

impl Knots {
    fn push(&mut self, (t_s, nominal_s): (f64, f64), p: Pt, owner: usize, tube_mm: f64) {
        let mut tube_mm = tube_mm;
        if self
            .times
            .last()
            .is_some_and(|&last| t_s - last <= KNOT_EPS_S)
        {
            self.times.pop();
            self.nominal_s.pop();
            self.points.pop();
            self.owners.pop();
            tube_mm = tube_mm.min(self.tube_mm.pop().unwrap_or(tube_mm));
        }
        self.times.push(t_s);
        self.nominal_s.push(nominal_s);
        self.points.push(p);
        self.owners.push(owner);
        self.tube_mm.push(tube_mm);
    }
}

fn knots(pieces: &[Piece], path: &Toolpath) -> Knots {
    let mut k = Knots {
        times: Vec::new(),
        nominal_s: Vec::new(),
        points: Vec::new(),
        owners: Vec::new(),
        tube_mm: Vec::new(),
    };
    let mut t_s = 0.0;
    for piece in pieces {
        let (g, w) = (piece.geometry, piece.tube_mm);
        let at = |u: f64| {
            (
                t_s + u * piece.duration_s,
                piece.nominal_start_s + u * piece.nominal_s,
            )
        };
        for (u, p) in piece_knots(piece, path) {
            k.push(at(u), p, g, w);
        }
        t_s += piece.duration_s;
    }
    k
}

/// The knots of one piece: fractions of its duration and the tool's point there.
fn piece_knots(piece: &Piece, path: &Toolpath) -> Vec<(f64, Pt)> {
    match piece.tool {
        Tool::Hold(p) => vec![(0.0, p), (1.0, p)],
        Tool::Line(a, b) => vec![(0.0, a), (1.0, b)],
        Tool::Stroke {
            stroke,
            start_frac,
            end_frac,
        } => part_knots(path, stroke, start_frac, end_frac),
    }
}

/// The tool's nominal time law of a plan on the fly (marks at mark speed, jumps at jump
/// speed, the laser and jump delays), as the knots seed 001's routes are planned on.
pub fn nominal_tool_knots(
    geometries: &[Geometry],
    plan: &Plan,
    profile: &MachineProfile,
) -> Result<Vec<ToolKnot>, OtfError> {
    let mut path = Toolpath::default();
    let pieces = tool_pieces(geometries, plan, profile, 0.0, &mut path)?;
    let mut out = Vec::new();
    for piece in &pieces {
        let marking = piece.kind == SegmentKind::Mark;
        for (u, at) in piece_knots(piece, &path) {
            let t_s = piece.nominal_start_s + u * piece.nominal_s;
            // a knot's flag says what follows it: the last knot of a mark part is followed by
            // the next piece, which pushes its own first knot at the same instant
            out.push(ToolKnot {
                t_s,
                at,
                marking: marking && u < 1.0,
            });
        }
    }
    Ok(out)
}

/// A stroke cut at its vertices into parts of at least [`PART_MM`] (the last part may be
/// shorter): `(start_frac, end_frac)` fractions of its length. Retiming slows whole pieces, so
/// a long stroke is slowed only where its route needs it.
fn stroke_parts(path: &Toolpath, stroke: usize) -> Vec<(f64, f64)> {
    let length_mm = path.strokes[stroke].length_mm;
    let mut parts = Vec::new();
    let mut start_mm = 0.0;
    for &arc_mm in path.stroke_arc_mm(stroke) {
        if arc_mm - start_mm >= PART_MM {
            parts.push((start_mm / length_mm, arc_mm / length_mm));
            start_mm = arc_mm;
        }
    }
    if start_mm < length_mm || parts.is_empty() {
        let start_frac = if length_mm > 0.0 {
            start_mm / length_mm
        } else {
            0.0
        };
        parts.push((start_frac, 1.0));
    }
    parts
}

/// Share of the path tolerance a streamed corner is cut by at most (the rest: the sample
/// intervals are not centred on the vertex).
const CORNER_TOL_SHARE: f64 = 0.8;

/// A streamed plan's slow zones on stroke `stroke` marked at `speed_mm_s` (fractions of its
/// length, with the speed in them; none unless the profile streams on the fly).
///
/// Between two samples of a stream (period `T`) the joints move in a straight line, while the
/// mark follows the stroke: over one sample's travel `s = v·T` centred on a vertex, the path
/// strays from that chord by [`window_cut_mm`] (at a corner whose edges meet at the inner angle
/// `ψ`, `(s/2)·cos(ψ/2)`: half the travel at a hairpin; on a curve of radius `r`, `s²/8r`).
/// Where that exceeds [`CORNER_TOL_SHARE`] of the profile's path tolerance the mark slows
/// (halving its travel until it does not) over that travel either side of the vertex: the
/// sample intervals around the vertex then lie inside the zone, their chords within the
/// tolerance. A corner costs at most a few periods.
fn stream_corners(
    path: &Toolpath,
    stroke: usize,
    speed_mm_s: f64,
    profile: &MachineProfile,
) -> Vec<(f64, f64, f64)> {
    let Some(period_s) = profile.controller.stream_period_s else {
        return Vec::new();
    };
    if !profile
        .controller
        .streamed(crate::document::Motion::OnTheFly)
    {
        return Vec::new();
    }
    let tol_mm = CORNER_TOL_SHARE * profile.gcode.path_tol_mm;
    let points = path.stroke_points(stroke);
    let arc = path.stroke_arc_mm(stroke);
    let length_mm = path.strokes[stroke].length_mm;
    if length_mm <= 0.0 || points.len() < 3 || arc.len() != points.len() {
        return Vec::new();
    }
    let mut zones: Vec<(f64, f64, f64)> = Vec::new();
    for i in 1..points.len() - 1 {
        let mut travel_mm = speed_mm_s * period_s;
        if window_cut_mm(points, arc, arc[i], travel_mm) <= tol_mm {
            continue;
        }
        // at most 20 halvings: a millionth of the travel
        for _ in 0..20 {
            travel_mm /= 2.0;
            if window_cut_mm(points, arc, arc[i], travel_mm) <= tol_mm {
                break;
            }
        }
        let slow = travel_mm / period_s;
        let reach_mm = travel_mm * 1.05;
        let (a, b) = (
            ((arc[i] - reach_mm) / length_mm).max(0.0),
            ((arc[i] + reach_mm) / length_mm).min(1.0),
        );
        match zones.last_mut() {
            // overlapping zones merge, at the slower speed
            Some(z) if a <= z.1 => {
                z.1 = z.1.max(b);
                z.2 = z.2.min(slow);
            }
            _ => zones.push((a, b, slow)),
        }
    }
    zones
}

/// How far the polyline `points` (arc lengths `arc`) strays from the chord of its stretch
/// `[at_mm − travel_mm/2, at_mm + travel_mm/2]`, mm: the largest distance of its vertices
/// inside from the line through the stretch's ends.
fn window_cut_mm(points: &[Pt], arc: &[f64], at_mm: f64, travel_mm: f64) -> f64 {
    let point_at = |d: f64| {
        let d = d.clamp(0.0, arc[arc.len() - 1]);
        let k = arc.partition_point(|&x| x <= d).clamp(1, arc.len() - 1);
        let span = arc[k] - arc[k - 1];
        let f = if span > 0.0 {
            (d - arc[k - 1]) / span
        } else {
            0.0
        };
        points[k - 1].plus(points[k].minus(points[k - 1]).scale(f))
    };
    let (lo, hi) = (at_mm - travel_mm / 2.0, at_mm + travel_mm / 2.0);
    let (p, q) = (point_at(lo), point_at(hi));
    let first = arc.partition_point(|&x| x <= lo);
    let last = arc.partition_point(|&x| x < hi);
    (first..last)
        .map(|k| crate::geom::point_segment_dist(points[k], p, q))
        .fold(0.0, f64::max)
}

/// Part `[a, b]` of a stroke cut at the slow `zones` it crosses: each piece with its speed
/// (`speed_mm_s` outside the zones).
fn at_speeds(a: f64, b: f64, zones: &[(f64, f64, f64)], speed_mm_s: f64) -> Vec<(f64, f64, f64)> {
    let mut out = Vec::new();
    let mut at = a;
    for &(za, zb, slow) in zones.iter().filter(|z| z.1 > a && z.0 < b) {
        if za > at {
            out.push((at, za, speed_mm_s));
        }
        let (from, to) = (za.max(at), zb.min(b));
        if to > from {
            out.push((from, to, slow));
            at = to;
        }
    }
    if b > at || out.is_empty() {
        out.push((at, b, speed_mm_s));
    }
    out
}

/// The knots of part `[start_frac, end_frac]` of stroke `s`: its ends and the vertices between,
/// with their fraction of the part (0 to 1). Finds the vertices by bisection on the arc
/// lengths: a long stroke's many parts cost no more than its vertices.
fn part_knots(path: &Toolpath, s: usize, start_frac: f64, end_frac: f64) -> Vec<(f64, Pt)> {
    let length_mm = path.strokes[s].length_mm;
    let (start_mm, end_mm) = (start_frac * length_mm, end_frac * length_mm);
    let (pts, arc) = (path.stroke_points(s), path.stroke_arc_mm(s));
    let first = arc.partition_point(|&a| a <= start_mm);
    let last = arc.partition_point(|&a| a < end_mm);
    let span_mm = end_mm - start_mm;
    let mut out = vec![(0.0, path.point_along(s, start_frac))];
    if first < last {
        out.extend(
            arc[first..last]
                .iter()
                .zip(&pts[first..last])
                .map(|(&a, &p)| (((a - start_mm) / span_mm).clamp(0.0, 1.0), p)),
        );
    }
    out.push((1.0, path.point_along(s, end_frac)));
    out
}

/// The taut string of each axis through the tube around the tool (each piece's half-width),
/// clipped to the stage's stroke.
fn routes(
    pieces: &[Piece],
    path: &Toolpath,
    profile: &MachineProfile,
    follow: Option<&TimedRoute>,
) -> Result<[Vec<(f64, f64)>; 2], OtfError> {
    let Knots {
        times,
        nominal_s,
        points,
        owners,
        tube_mm,
    } = knots(pieces, path);
    let targets: Option<Vec<Pt>> =
        follow.map(|route| nominal_s.iter().map(|&t| route.position(t)).collect());
    let mut out: [Vec<(f64, f64)>; 2] = Default::default();
    for (k, axis) in ['x', 'y'].into_iter().enumerate() {
        let coord = |p: &Pt| if k == 0 { p.x } else { p.y };
        let stroke_mm = profile.stroke_mm[k];
        let mut lower: Vec<f64> = points
            .iter()
            .zip(&tube_mm)
            .map(|(p, h)| (coord(p) - h).max(0.0))
            .collect();
        let mut upper: Vec<f64> = points
            .iter()
            .zip(&tube_mm)
            .map(|(p, h)| (coord(p) + h).min(stroke_mm))
            .collect();
        if let Some(j) = (0..lower.len()).find(|&j| lower[j] > upper[j]) {
            return Err(OtfError::OutOfStroke {
                geometry: owners[j],
                axis,
            });
        }
        if let Some(targets) = &targets {
            follow_band(&mut lower, &mut upper, targets.iter().map(coord));
        }
        let tube = Tube {
            t_s: &times,
            lower_mm: &lower,
            upper_mm: &upper,
        };
        out[k] = taut_string(&tube, None, None)?;
    }
    Ok(out)
}

/// Narrows each knot's interval to within [`FOLLOW_MM`] of the route's position at that knot
/// (seed 001's routes), where the two meet; where they do not (the route would put the tool
/// out of reach), the interval stays the scanner's reach.
fn follow_band(lower: &mut [f64], upper: &mut [f64], targets: impl Iterator<Item = f64>) {
    for ((lo, hi), target) in lower.iter_mut().zip(upper.iter_mut()).zip(targets) {
        let (band_lo, band_hi) = (lo.max(target - FOLLOW_MM), hi.min(target + FOLLOW_MM));
        if band_lo <= band_hi {
            (*lo, *hi) = (band_lo, band_hi);
        }
    }
}

/// Slows the pieces under every stretch of the route faster than its axis cap, and (with
/// `corner_mm`) under every corner whose blend would depart from it by more than that, until
/// none is. Returns the taut strings of the retimed pieces.
fn retime(
    pieces: &mut [Piece],
    path: &Toolpath,
    profile: &MachineProfile,
    cap_mm_s: [f64; 2],
    corner_mm: Option<f64>,
    follow: Option<&TimedRoute>,
) -> Result<[Vec<(f64, f64)>; 2], OtfError> {
    let accel = [
        profile.axis_x.max_accel_mm_s2,
        profile.axis_y.max_accel_mm_s2,
    ];
    for _ in 0..RETIME_ROUNDS {
        let strings = routes(pieces, path, profile, follow)?;
        let mut factors = stretch_factors(pieces, &strings, cap_mm_s);
        if let Some(corner_mm) = corner_mm {
            let starts = piece_starts(pieces);
            for (route, a) in strings.iter().zip(accel) {
                corner_factors(&starts, route, a, corner_mm, &mut factors);
            }
        }
        if factors.iter().all(|&f| f <= 1.0) {
            return Ok(strings);
        }
        for (piece, f) in pieces.iter_mut().zip(factors) {
            piece.duration_s *= f;
        }
    }
    // what is left: the whole job slower by the worst excess (slopes scale exactly)
    let strings = routes(pieces, path, profile, follow)?;
    let worst = [0, 1]
        .map(|k| peak_speed_mm_s(&strings[k]) / cap_mm_s[k])
        .into_iter()
        .fold(1.0, f64::max);
    for piece in pieces.iter_mut() {
        piece.duration_s *= worst * (1.0 + SPEED_TOLERANCE);
    }
    routes(pieces, path, profile, follow)
}

/// The start time of each piece.
fn piece_starts(pieces: &[Piece]) -> Vec<f64> {
    let mut starts = Vec::with_capacity(pieces.len());
    let mut t_s = 0.0;
    for p in pieces {
        starts.push(t_s);
        t_s += p.duration_s;
    }
    starts
}

/// The pieces (starting at `starts`, in time order) that run during `(lo, hi)`: from the one
/// running at `lo` to the last starting before `hi`.
fn pieces_under(starts: &[f64], (lo, hi): (f64, f64)) -> std::ops::Range<usize> {
    let first = starts.partition_point(|&s| s <= lo).saturating_sub(1);
    let end = starts.partition_point(|&s| s < hi).max(first);
    first..end
}

/// Raises `factors` (per piece, starting at `starts`) under every corner of `route` whose
/// blend at `accel_mm_s2` would depart from it by more than `corner_mm`: a corner's speed
/// change `Δv` departs by `Δv² / (8 a)` over `|Δv| / a` around it, and slowing the pieces
/// there by `f` divides `Δv` by `f` (the start and the end count as corners from rest).
fn corner_factors(
    starts: &[f64],
    route: &[(f64, f64)],
    accel_mm_s2: f64,
    corner_mm: f64,
    factors: &mut [f64],
) {
    let slope = |k: usize| -> f64 {
        match (route.get(k), route.get(k + 1)) {
            (Some(&(ta, xa)), Some(&(tb, xb))) => (xb - xa) / (tb - ta),
            _ => 0.0,
        }
    };
    for (k, &(t_s, _)) in route.iter().enumerate() {
        let before = if k == 0 { 0.0 } else { slope(k - 1) };
        let dv = (slope(k) - before).abs();
        let departure_mm = dv * dv / (8.0 * accel_mm_s2);
        if departure_mm <= corner_mm * (1.0 + SPEED_TOLERANCE) {
            continue;
        }
        let f = (departure_mm / corner_mm).sqrt() * (1.0 + RETIME_OVERSHOOT);
        let half_s = dv / (2.0 * accel_mm_s2);
        for j in pieces_under(starts, (t_s - half_s, t_s + half_s)) {
            factors[j] = factors[j].max(f);
        }
    }
}

/// Per piece, how much it must be slowed: the largest excess of a route stretch over it.
fn stretch_factors(
    pieces: &[Piece],
    routes: &[Vec<(f64, f64)>; 2],
    cap_mm_s: [f64; 2],
) -> Vec<f64> {
    let starts = piece_starts(pieces);
    let mut factors = vec![1.0f64; pieces.len()];
    for (route, cap) in routes.iter().zip(cap_mm_s) {
        for w in route.windows(2) {
            let ((ta, xa), (tb, xb)) = (w[0], w[1]);
            let slope = (xb - xa).abs() / (tb - ta);
            if slope <= cap * (1.0 + SPEED_TOLERANCE) {
                continue;
            }
            for j in pieces_under(&starts, (ta, tb)) {
                factors[j] = factors[j].max(slope / cap * (1.0 + RETIME_OVERSHOOT));
            }
        }
    }
    factors
}

/// The pieces on a controller clock: marks (all the parts of a stroke together) start and end
/// on ticks (a wait at the mark's start before it, the parts slower to fill whole ticks), one
/// laser-off tick between marks.
fn on_clock(pieces: &[Piece], path: &Toolpath, period_s: f64) -> Vec<Piece> {
    let mut out = Vec::with_capacity(pieces.len() * 2);
    let (mut t_s, mut clock) = (0.0, MarkClock::new(period_s));
    let mut k = 0;
    while k < pieces.len() {
        let piece = pieces[k];
        let Tool::Stroke { stroke, .. } = piece.tool else {
            out.push(piece);
            t_s += piece.duration_s;
            k += 1;
            continue;
        };
        let parts = pieces[k..]
            .iter()
            .take_while(|p| matches!(p.tool, Tool::Stroke { stroke: s, .. } if s == stroke))
            .count();
        let mark_s: f64 = pieces[k..k + parts].iter().map(|p| p.duration_s).sum();
        let (start_s, duration_s) = clock.place(t_s, mark_s);
        if start_s > t_s {
            let at = path
                .stroke_points(stroke)
                .first()
                .copied()
                .unwrap_or_default();
            out.push(Piece {
                kind: SegmentKind::LaserOnDelay,
                duration_s: start_s - t_s,
                tool: Tool::Hold(at),
                nominal_s: 0.0,
                ..piece
            });
        }
        let stretch = if mark_s > 0.0 {
            duration_s / mark_s
        } else {
            1.0
        };
        out.extend(pieces[k..k + parts].iter().map(|p| Piece {
            duration_s: p.duration_s * stretch,
            ..*p
        }));
        t_s = start_s + duration_s;
        k += parts;
    }
    out
}

/// The toolpath's segments: the wait while the stage gets under way, then the pieces, all with
/// the stage on its route; each stroke notes where the stage is when it starts.
fn push_segments(path: &mut Toolpath, pieces: &[Piece], pad_s: f64) {
    let first = pieces.first().map(|p| match p.tool {
        Tool::Hold(q) | Tool::Line(q, _) => q,
        Tool::Stroke {
            stroke, start_frac, ..
        } => path.point_along(stroke, start_frac),
    });
    let mut t_s = 0.0;
    if let (Some(at), true) = (first, pad_s > 0.0) {
        path.segments.push(Segment {
            kind: SegmentKind::StageMove,
            start_s: 0.0,
            duration_s: pad_s,
            stage: StageMotion::Route,
            scan: ScanMotion::TcpHold(at),
        });
        t_s = pad_s;
    }
    for piece in pieces {
        let scan = match piece.tool {
            Tool::Hold(p) => ScanMotion::TcpHold(p),
            // in the scanner's frame: straight between the offsets at its ends
            Tool::Line(from, to) if piece.stage == PieceStage::FreeJump => {
                let stage_at =
                    |t: f64| path.route.as_ref().map_or(Pt::default(), |r| r.position(t));
                ScanMotion::Line {
                    from: from.minus(stage_at(t_s)),
                    to: to.minus(stage_at(t_s + piece.duration_s)),
                    move_s: piece.duration_s,
                }
            }
            Tool::Line(from, to) => ScanMotion::TcpLine {
                from,
                to,
                move_s: piece.duration_s,
            },
            Tool::Stroke {
                stroke,
                start_frac,
                end_frac,
            } => {
                if let (Some(route), true) = (&path.route, start_frac == 0.0) {
                    path.strokes[stroke].stage = route.position(t_s);
                }
                ScanMotion::Mark {
                    stroke,
                    start_frac,
                    end_frac,
                }
            }
        };
        path.segments.push(Segment {
            kind: piece.kind,
            start_s: t_s,
            duration_s: piece.duration_s,
            stage: StageMotion::Route,
            scan,
        });
        t_s += piece.duration_s;
    }
}

#[cfg(test)]
mod corner_tests {
    use super::*;

    #[test]
    fn a_chord_through_a_hairpin_strays_half_the_travel_and_a_straight_line_none() {
        let hairpin = [Pt::new(0.0, 0.0), Pt::new(1.0, 0.0), Pt::new(0.0, 1e-9)];
        let arc = [0.0, 1.0, 2.0];
        assert!((window_cut_mm(&hairpin, &arc, 1.0, 0.1) - 0.05).abs() < 1e-6);
        let right = [Pt::new(0.0, 0.0), Pt::new(1.0, 0.0), Pt::new(1.0, 1.0)];
        // (s/2)·cos(ψ/2), ψ = 90°
        let want = 0.05 * std::f64::consts::FRAC_1_SQRT_2;
        assert!((window_cut_mm(&right, &arc, 1.0, 0.1) - want).abs() < 1e-9);
        let line = [Pt::new(0.0, 0.0), Pt::new(1.0, 0.0), Pt::new(2.0, 0.0)];
        assert!(window_cut_mm(&line, &arc, 1.0, 0.1) < 1e-12);
    }

    #[test]
    fn a_part_is_cut_at_the_slow_zones_it_crosses() {
        let zones = [(0.2, 0.3, 100.0), (0.5, 0.6, 50.0)];
        let parts = at_speeds(0.0, 0.55, &zones, 1000.0);
        assert_eq!(
            parts,
            [
                (0.0, 0.2, 1000.0),
                (0.2, 0.3, 100.0),
                (0.3, 0.5, 1000.0),
                (0.5, 0.55, 50.0)
            ]
        );
        assert_eq!(at_speeds(0.7, 0.9, &zones, 1000.0), [(0.7, 0.9, 1000.0)]);
    }
}
