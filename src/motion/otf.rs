//! On-the-fly lowering: the stage moves on a continuous route while the scanner marks.
//!
//! 1. The tool-centre point's time law comes from the plan's stroke order as in step-and-scan
//!    (marks at mark speed, jumps at jump speed, the laser and jump delays), as *pieces*.
//! 2. Per axis the stage must keep `|tcp − stage| ≤ h` with `h` = half the field less the
//!    profile's `otf_margin_mm` less a smoothing allowance `δ` ([`SMOOTHING_SHARE`] of the
//!    reach), and stay inside its stroke. Through that tube the **taut string** is the shortest
//!    route and has the least peak speed of any route ([`super::taut`]).
//! 3. Where its speed exceeds the axis cap `v = min(v_max, √(2 a_max δ))`, the pieces under that
//!    stretch of the route are slowed (the scanner waits, marks run slower) by the excess, and
//!    the route is computed again; rounds repeat until no stretch is too fast (after
//!    [`RETIME_ROUNDS`] the whole job is slowed by what is left). Slowing any piece never raises
//!    the taut string's peak speed (the old route, reparametrised, stays feasible), so the rounds
//!    and the controller clock alignment keep the cap.
//! 4. The route is smoothed by a moving average of window `2 v / a_max` ([`super::route`]):
//!    speed ≤ `v`, acceleration ≤ `a_max`, departure ≤ `v² / (2 a_max)` ≤ `δ`: the scanner
//!    offset stays within half the field less the margin. The job starts with the stage at rest:
//!    the tool waits at its first point for half a window while the stage gets under way.

use super::clock::{ceil_to_tick, MarkClock};
use super::route::{AxisRoute, StageRoute};
use super::taut::{peak_speed_mm_s, taut_string, TautError, Tube};
use super::toolpath::{ScanMotion, Segment, SegmentKind, StageMotion, Toolpath};
use crate::document::{AxisLimits, Geometry, MachineProfile, Plan};
use crate::geom::Pt;
use crate::job::{Cancelled, JobCtx};
use thiserror::Error;

/// Share of the scanner's reach kept for smoothing the route by the guaranteed fallback.
pub const SMOOTHING_SHARE: f64 = 0.5;

/// Share of the reach the first tube leaves free (the smoothing cuts corners inwards and out).
pub const TIGHT_SHARE: f64 = 0.02;

/// Rounds of narrowing the tube where the smoothed route overshoots, before the fallback.
pub const SHRINK_ROUNDS: usize = 24;

/// Grid on which the scanner offset is checked (besides every knot), s. Between two checked
/// instants the tool moves straight and the stage's acceleration is at most `a_max`, so the
/// offset leaves the straight line between its checked values by at most `a_max · Δt² / 8`
/// (0.6 µm at 5,000 mm/s² and 1 ms), which [`CHECK_SLACK`] covers.
pub const CHECK_PERIOD_S: f64 = 1e-3;

/// Share of the reach kept as slack by the check (3.5 µm of a 35 mm reach).
const CHECK_SLACK: f64 = 1e-4;

/// How much of an overshoot a round takes off the tube near it.
const SHRINK_GAIN: f64 = 0.5;

/// Each retiming round slows a bit more than the excess it sees, so that the rounds settle
/// quickly (the route changes as the tool slows).
const RETIME_OVERSHOOT: f64 = 0.02;

/// Narrowing rounds without a smaller worst overshoot before the fallback takes over.
const STALLED_ROUNDS: usize = 3;

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
    /// The route could not be computed.
    #[error("stage route: {0}")]
    Route(#[from] TautError),
    /// The operator cancelled.
    #[error("cancelled")]
    Cancelled(#[from] Cancelled),
}

/// What the tool-centre point does during a piece.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Tool {
    Hold(Pt),
    Line(Pt, Pt),
    Stroke(usize),
}

/// A piece of the tool's time law.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Piece {
    kind: SegmentKind,
    duration_s: f64,
    tool: Tool,
    geometry: usize,
    /// Half-width of the route's tube at this piece's knots, mm.
    tube_mm: f64,
    /// Index of the piece it comes from before the clock alignment.
    origin: usize,
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
    let mut path = Toolpath::default();
    let tube_mm = reach_mm * (1.0 - TIGHT_SHARE);
    let mut pieces = tool_pieces(geometries, plan, profile, tube_mm, &mut path)?;
    let full_speed = [
        profile.axis_x.max_velocity_mm_s,
        profile.axis_y.max_velocity_mm_s,
    ];
    let (mut best_excess_mm, mut stalled) = (f64::INFINITY, 0);
    for _ in 0..SHRINK_ROUNDS {
        ctx.check()?;
        retime(&mut pieces, &path, profile, full_speed)?;
        let run = clocked(&pieces, &path, clock_s);
        build(&mut path, &run, profile, clock_s)?;
        let over = overshoots(&path, reach_mm);
        if over.is_empty() {
            return Ok(path);
        }
        let worst_mm = over.iter().map(|o| o.1).fold(0.0, f64::max);
        if worst_mm < best_excess_mm {
            (best_excess_mm, stalled) = (worst_mm, 0);
        } else {
            stalled += 1;
            if stalled >= STALLED_ROUNDS {
                break;
            }
        }
        shrink(&mut pieces, &run, &path, &over);
    }
    // the tube never settled: the guaranteed route (a share of the reach for the smoothing, the
    // speed capped so that the smoothing stays inside it)
    let allowance_mm = SMOOTHING_SHARE * reach_mm;
    let cap = [&profile.axis_x, &profile.axis_y].map(|a| speed_cap_mm_s(a, allowance_mm));
    for piece in &mut pieces {
        piece.tube_mm = reach_mm - allowance_mm;
    }
    retime(&mut pieces, &path, profile, cap)?;
    let run = clocked(&pieces, &path, clock_s);
    build(&mut path, &run, profile, clock_s)?;
    Ok(path)
}

/// The pieces as run: on the controller clock when there is one.
fn clocked(pieces: &[Piece], path: &Toolpath, clock_s: Option<f64>) -> Vec<Piece> {
    match clock_s {
        Some(period_s) => on_clock(pieces, path, period_s),
        None => pieces.to_vec(),
    }
}

/// Routes, smoothing and segments of `pieces` into `path` (replacing earlier ones).
fn build(
    path: &mut Toolpath,
    pieces: &[Piece],
    profile: &MachineProfile,
    clock_s: Option<f64>,
) -> Result<(), OtfError> {
    let [rx, ry] = routes(pieces, path, profile)?;
    let x = AxisRoute::smooth(rx, profile.axis_x.max_accel_mm_s2);
    let y = AxisRoute::smooth(ry, profile.axis_y.max_accel_mm_s2);
    let half_reach_s = x.reach_s().max(y.reach_s()) / 2.0;
    let pad_s = clock_s.map_or(half_reach_s, |p| ceil_to_tick(half_reach_s, p));
    path.route = Some(StageRoute {
        x,
        y,
        offset_s: pad_s,
    });
    path.segments.clear();
    push_segments(path, pieces, pad_s);
    Ok(())
}

/// Instants (job time) where the scanner offset exceeds `reach_mm` on an axis, with the excess:
/// checked every [`CHECK_PERIOD_S`] and at every knot of the tool (segment ends and stroke
/// vertices). Between two such instants the offset can grow by at most `a_max · Δt² / 8` (the
/// stage's curvature; the tool moves straight between knots): below a micrometre.
fn overshoots(path: &Toolpath, reach_mm: f64) -> Vec<(f64, f64)> {
    let mut times: Vec<f64> = Vec::new();
    for seg in &path.segments {
        times.push(seg.start_s);
        if let ScanMotion::Mark { stroke } = seg.scan {
            times.extend(
                stroke_knots(path, stroke)
                    .iter()
                    .map(|(u, _)| seg.start_s + u * seg.duration_s),
            );
        }
    }
    let end_s = path.duration_s();
    let grid = (end_s / CHECK_PERIOD_S).ceil() as usize;
    times.extend((0..=grid).map(|k| (k as f64 * CHECK_PERIOD_S).min(end_s)));
    times
        .into_iter()
        .filter_map(|t| {
            let o = path.state_at(t).scan;
            let excess = o.x.abs().max(o.y.abs()) - reach_mm * (1.0 - CHECK_SLACK);
            (excess > 0.0).then_some((t, excess))
        })
        .collect()
}

/// Narrows the tube of every piece within half a smoothing window of an overshoot by 1.5 × the
/// largest excess near it (at least a hundredth of a millimetre).
fn shrink(pieces: &mut [Piece], run: &[Piece], path: &Toolpath, over: &[(f64, f64)]) {
    let Some(route) = &path.route else {
        return;
    };
    let half_window_s = route.x.reach_s().max(route.y.reach_s()) / 2.0;
    let mut starts = Vec::with_capacity(run.len());
    let mut t_s = route.offset_s;
    for p in run {
        starts.push(t_s);
        t_s += p.duration_s;
    }
    let mut worst = vec![0.0f64; pieces.len()];
    for &(t, excess) in over {
        let (lo, hi) = (t - half_window_s, t + half_window_s);
        let first = starts.partition_point(|&s| s <= lo).saturating_sub(1);
        for j in first..run.len() {
            if starts[j] > hi {
                break;
            }
            let w = &mut worst[run[j].origin];
            *w = w.max(excess);
        }
    }
    for (piece, excess) in pieces.iter_mut().zip(worst) {
        if excess > 0.0 {
            piece.tube_mm = (piece.tube_mm - (SHRINK_GAIN * excess).max(0.01)).max(0.0);
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

/// The fastest route speed whose smoothing departs at most `allowance_mm`: `v² / (2a) ≤ δ`.
fn speed_cap_mm_s(axis: &AxisLimits, allowance_mm: f64) -> f64 {
    axis.max_velocity_mm_s
        .min((2.0 * axis.max_accel_mm_s2 * allowance_mm).sqrt())
}

/// The tool's time law: per stroke a jump (from the second on), the jump delay, the laser-on
/// delay, the mark, the laser-off delay. Adds the strokes to `path`.
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
        let mut piece = |kind, duration_s: f64, tool| {
            if duration_s > 0.0 {
                pieces.push(Piece {
                    kind,
                    duration_s,
                    tool,
                    geometry,
                    tube_mm,
                    origin: pieces.len(),
                });
            }
        };
        if let Some(from) = last_end {
            let jump_s = from.dist(start) / scanner.jump_speed_mm_s;
            piece(SegmentKind::Jump, jump_s, Tool::Line(from, start));
            piece(
                SegmentKind::JumpDelay,
                laser.jump_delay_s,
                Tool::Hold(start),
            );
        }
        piece(
            SegmentKind::LaserOnDelay,
            laser.on_delay_s,
            Tool::Hold(start),
        );
        let mark_s = path.strokes[stroke].length_mm / plan.mark_speed_mm_s(g, profile);
        piece(SegmentKind::Mark, mark_s, Tool::Stroke(stroke));
        piece(
            SegmentKind::LaserOffDelay,
            laser.off_delay_s,
            Tool::Hold(end),
        );
        last_end = Some(end);
    }
    Ok(pieces)
}

/// The tool's knots: times (strictly increasing), points, the geometry of each and its tube
/// half-width (the narrowest of the pieces meeting there).
struct Knots {
    times: Vec<f64>,
    points: Vec<Pt>,
    owners: Vec<usize>,
    tube_mm: Vec<f64>,
}

impl Knots {
    fn push(&mut self, t_s: f64, p: Pt, owner: usize, tube_mm: f64) {
        let mut tube_mm = tube_mm;
        if self
            .times
            .last()
            .is_some_and(|&last| t_s - last <= KNOT_EPS_S)
        {
            self.times.pop();
            self.points.pop();
            self.owners.pop();
            tube_mm = tube_mm.min(self.tube_mm.pop().unwrap_or(tube_mm));
        }
        self.times.push(t_s);
        self.points.push(p);
        self.owners.push(owner);
        self.tube_mm.push(tube_mm);
    }
}

fn knots(pieces: &[Piece], path: &Toolpath) -> Knots {
    let mut k = Knots {
        times: Vec::new(),
        points: Vec::new(),
        owners: Vec::new(),
        tube_mm: Vec::new(),
    };
    let mut t_s = 0.0;
    for piece in pieces {
        let (g, w) = (piece.geometry, piece.tube_mm);
        match piece.tool {
            Tool::Hold(p) => {
                k.push(t_s, p, g, w);
                k.push(t_s + piece.duration_s, p, g, w);
            }
            Tool::Line(a, b) => {
                k.push(t_s, a, g, w);
                k.push(t_s + piece.duration_s, b, g, w);
            }
            Tool::Stroke(s) => {
                for (u, p) in stroke_knots(path, s) {
                    k.push(t_s + u * piece.duration_s, p, g, w);
                }
            }
        }
        t_s += piece.duration_s;
    }
    k
}

/// The vertices of stroke `s` with their fraction of its length.
fn stroke_knots(path: &Toolpath, s: usize) -> Vec<(f64, Pt)> {
    let pts = path.stroke_points(s);
    let length_mm = path.strokes[s].length_mm;
    let mut arc_mm = 0.0;
    pts.iter()
        .enumerate()
        .map(|(j, &p)| {
            if j > 0 {
                arc_mm += p.dist(pts[j - 1]);
            }
            let u = if length_mm > 0.0 {
                arc_mm / length_mm
            } else {
                1.0
            };
            (u, p)
        })
        .collect()
}

/// The taut string of each axis through the tube around the tool (each piece's half-width),
/// clipped to the stage's stroke.
fn routes(
    pieces: &[Piece],
    path: &Toolpath,
    profile: &MachineProfile,
) -> Result<[Vec<(f64, f64)>; 2], OtfError> {
    let Knots {
        times,
        points,
        owners,
        tube_mm,
    } = knots(pieces, path);
    let mut out: [Vec<(f64, f64)>; 2] = Default::default();
    for (k, axis) in ['x', 'y'].into_iter().enumerate() {
        let coord = |p: &Pt| if k == 0 { p.x } else { p.y };
        let stroke_mm = profile.stroke_mm[k];
        let lower: Vec<f64> = points
            .iter()
            .zip(&tube_mm)
            .map(|(p, h)| (coord(p) - h).max(0.0))
            .collect();
        let upper: Vec<f64> = points
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
        let tube = Tube {
            t_s: &times,
            lower_mm: &lower,
            upper_mm: &upper,
        };
        out[k] = taut_string(&tube, None, None)?;
    }
    Ok(out)
}

/// Slows the pieces under every stretch of the route faster than its axis cap, until none is.
fn retime(
    pieces: &mut [Piece],
    path: &Toolpath,
    profile: &MachineProfile,
    cap_mm_s: [f64; 2],
) -> Result<(), OtfError> {
    for _ in 0..RETIME_ROUNDS {
        let routes = routes(pieces, path, profile)?;
        let factors = stretch_factors(pieces, &routes, cap_mm_s);
        if factors.iter().all(|&f| f <= 1.0) {
            return Ok(());
        }
        for (piece, f) in pieces.iter_mut().zip(factors) {
            piece.duration_s *= f;
        }
    }
    // what is left: the whole job slower by the worst excess (slopes scale exactly)
    let routes = routes(pieces, path, profile)?;
    let worst = [0, 1]
        .map(|k| peak_speed_mm_s(&routes[k]) / cap_mm_s[k])
        .into_iter()
        .fold(1.0, f64::max);
    for piece in pieces.iter_mut() {
        piece.duration_s *= worst * (1.0 + SPEED_TOLERANCE);
    }
    Ok(())
}

/// Per piece, how much it must be slowed: the largest excess of a route stretch over it.
fn stretch_factors(
    pieces: &[Piece],
    routes: &[Vec<(f64, f64)>; 2],
    cap_mm_s: [f64; 2],
) -> Vec<f64> {
    let mut starts = Vec::with_capacity(pieces.len());
    let mut t_s = 0.0;
    for p in pieces {
        starts.push(t_s);
        t_s += p.duration_s;
    }
    let mut factors = vec![1.0f64; pieces.len()];
    for (route, cap) in routes.iter().zip(cap_mm_s) {
        for w in route.windows(2) {
            let ((ta, xa), (tb, xb)) = (w[0], w[1]);
            let slope = (xb - xa).abs() / (tb - ta);
            if slope <= cap * (1.0 + SPEED_TOLERANCE) {
                continue;
            }
            let first = starts.partition_point(|&s| s <= ta).saturating_sub(1);
            for j in first..pieces.len() {
                if starts[j] >= tb {
                    break;
                }
                factors[j] = factors[j].max(slope / cap * (1.0 + RETIME_OVERSHOOT));
            }
        }
    }
    factors
}

/// The pieces on a controller clock: marks start and end on ticks (a wait at the mark's start
/// before it, the mark slower to fill whole ticks), one laser-off tick between marks.
fn on_clock(pieces: &[Piece], path: &Toolpath, period_s: f64) -> Vec<Piece> {
    let mut out = Vec::with_capacity(pieces.len() * 2);
    let (mut t_s, mut clock) = (0.0, MarkClock::new(period_s));
    for piece in pieces {
        let Tool::Stroke(s) = piece.tool else {
            out.push(*piece);
            t_s += piece.duration_s;
            continue;
        };
        let (start_s, duration_s) = clock.place(t_s, piece.duration_s);
        if start_s > t_s {
            let at = path.stroke_points(s).first().copied().unwrap_or_default();
            out.push(Piece {
                kind: SegmentKind::LaserOnDelay,
                duration_s: start_s - t_s,
                tool: Tool::Hold(at),
                ..*piece
            });
        }
        out.push(Piece {
            duration_s,
            ..*piece
        });
        t_s = start_s + duration_s;
    }
    out
}

/// The toolpath's segments: the wait while the stage gets under way, then the pieces, all with
/// the stage on its route; each stroke notes where the stage is when it starts.
fn push_segments(path: &mut Toolpath, pieces: &[Piece], pad_s: f64) {
    let first = pieces.first().map(|p| match p.tool {
        Tool::Hold(q) | Tool::Line(q, _) => q,
        Tool::Stroke(s) => path.stroke_points(s).first().copied().unwrap_or_default(),
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
            Tool::Line(from, to) => ScanMotion::TcpLine {
                from,
                to,
                move_s: piece.duration_s,
            },
            Tool::Stroke(stroke) => {
                if let Some(route) = &path.route {
                    path.strokes[stroke].stage = route.position(t_s);
                }
                ScanMotion::Mark { stroke }
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
