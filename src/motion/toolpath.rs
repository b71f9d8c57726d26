//! The lowered toolpath: timed segments with the stage position, the scanner offset and the
//! laser state known at any instant.

use super::axis::StageMove;
use super::clock::MarkClock;
use super::route::StageRoute;
use crate::document::{Motion, MotionFigures, MotionRegion, Pose, TimeBreakdown};
use crate::geom::Pt;
use std::ops::Range;

/// Instants closer than this are the same instant (s): segment ends meet at sums of floats.
pub const TIME_EPS_S: f64 = 1e-9;

/// What a segment does (the job-time breakdown adds their durations by kind).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SegmentKind {
    /// The stage moves to the next field (the scanner may jump to its next start meanwhile).
    StageMove,
    /// The stage settles after a move.
    Settle,
    /// The scanner jumps (laser off) at jump speed.
    Jump,
    /// The scanner settles after a jump.
    JumpDelay,
    /// Waiting at a mark's start before it (laser-on delay).
    LaserOnDelay,
    /// Marking at mark speed (laser on).
    Mark,
    /// Waiting at a mark's end after it (laser-off delay).
    LaserOffDelay,
}

/// What the stage does during a segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StageMotion {
    /// At rest at a position (mm).
    Hold(Pt),
    /// A rest-to-rest move starting with the segment: index into [`Toolpath::stage_moves`]
    /// (kept apart so that a segment stays small: a million strokes make five million
    /// segments, and only field changes move the stage).
    Move(usize),
    /// On the toolpath's continuous route ([`Toolpath::route`], on the fly).
    Route,
}

/// What the scanner does during a segment; offsets are tool-centre point − stage, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ScanMotion {
    /// Holds an offset.
    Hold(Pt),
    /// Straight from one offset to another at constant speed over the first `move_s` of the
    /// segment, then holds.
    Line {
        /// Offset at the segment's start.
        from: Pt,
        /// Offset reached after `move_s`.
        to: Pt,
        /// Duration of the straight move, s.
        move_s: f64,
    },
    /// Marks the part `[start_frac, end_frac]` (fractions of its length) of stroke `stroke`
    /// at constant speed over the whole segment; the offset is the stroke's point less the
    /// stage. Step-and-scan marks a stroke in one segment (`0..1`); on the fly a stroke may
    /// run as consecutive parts at different speeds (the laser stays on between them).
    Mark {
        /// Index into [`Toolpath::strokes`].
        stroke: usize,
        /// Where the segment starts along the stroke (fraction of its length).
        start_frac: f64,
        /// Where it ends (fraction of its length).
        end_frac: f64,
    },
    /// Holds the tool-centre point (the offset follows the moving stage; on the fly).
    TcpHold(Pt),
    /// Moves the tool-centre point straight at constant speed over the first `move_s`, then
    /// holds it (on the fly).
    TcpLine {
        /// Tool-centre point at the segment's start.
        from: Pt,
        /// Tool-centre point reached after `move_s`.
        to: Pt,
        /// Duration of the straight move, s.
        move_s: f64,
    },
}

/// One timed piece of the job.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// What it does.
    pub kind: SegmentKind,
    /// Start time from the job's start, s.
    pub start_s: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Stage motion.
    pub stage: StageMotion,
    /// Scanner motion.
    pub scan: ScanMotion,
}

impl Segment {
    /// End time, s.
    pub fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }
}

/// One marked stroke: the tool-centre points in marking order.
#[derive(Debug, Clone, PartialEq)]
pub struct Stroke {
    /// Index of the plan step it marks.
    pub step: usize,
    /// Geometry index.
    pub geometry: usize,
    /// Field id.
    pub field: usize,
    /// Where the stage stands while it is marked, mm.
    pub stage: Pt,
    /// Its points in [`Toolpath`]'s point list.
    pub points: Range<usize>,
    /// Marked length, mm.
    pub length_mm: f64,
    /// Index of its geometry's layer in the plan's layers (none: the profile's pen).
    pub layer: Option<usize>,
}

/// The machine's state at an instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MachineState {
    /// Stage position, mm.
    pub stage: Pt,
    /// Scanner offset (tool-centre point − stage), mm.
    pub scan: Pt,
    /// Laser on.
    pub laser: bool,
}

impl MachineState {
    /// The tool-centre point, mm.
    pub fn tcp(&self) -> Pt {
        self.stage.plus(self.scan)
    }
}

/// Where Z, A and B stand over a toolpath: the stage moves that turn them, by start time
/// ([`Toolpath::pose_track`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PoseTrack {
    start: Pose,
    /// (start time, stage move) of every stage move, in time order.
    moves: Vec<(f64, StageMove)>,
}

impl PoseTrack {
    /// The pose at `t_s`.
    pub fn at(&self, t_s: f64) -> Pose {
        let k = self.moves.partition_point(|(start_s, _)| *start_s <= t_s);
        match k.checked_sub(1).and_then(|k| self.moves.get(k)) {
            Some((start_s, mv)) => mv.pose(t_s - start_s),
            None => self.start,
        }
    }
}

/// A job as the machine runs it: contiguous segments from t = 0, and the marked strokes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Toolpath {
    /// Segments in time order; each starts where the previous one ends.
    pub segments: Vec<Segment>,
    /// The stage moves [`StageMotion::Move`] segments make.
    pub stage_moves: Vec<StageMove>,
    /// Marked strokes in marking order.
    pub strokes: Vec<Stroke>,
    /// The stage's continuous route (on the fly), which [`StageMotion::Route`] segments follow.
    pub route: Option<StageRoute>,
    /// The controller runs this on-the-fly job this many times slower than it was planned
    /// ([`Toolpath::stretched`]); none: as planned.
    pub stretch: Option<f64>,
    /// A mixed job (on the fly): the ids of the fields whose strokes are marked with the stage
    /// at rest, ascending ([`crate::document::Plan::step_fields`]); empty: one motion.
    pub still_fields: Vec<usize>,
    /// Where Z, A and B stand at the start (the first field's pose); stage moves carry them
    /// from there ([`Toolpath::pose_track`]).
    pub start_pose: Pose,
    /// Tool-centre points of all strokes, concatenated.
    points: Vec<Pt>,
    /// Arc length from each stroke's first point to each point, mm (parallel to `points`).
    arc_mm: Vec<f64>,
}

impl Toolpath {
    /// Room for `strokes` strokes of `points` points in all and `segments` segments: a
    /// lowering that knows its sizes asks once (on a million strokes the segment list is
    /// about 500 MB; grown by doubling it would briefly need half as much again).
    pub(crate) fn reserve(&mut self, strokes: usize, points: usize, segments: usize) {
        self.strokes.reserve_exact(strokes);
        self.points.reserve_exact(points);
        self.arc_mm.reserve_exact(points);
        self.segments.reserve_exact(segments);
    }
    /// Where Z, A and B stand at any instant (one pass over the segments; then
    /// O(log moves) per instant).
    pub fn pose_track(&self) -> PoseTrack {
        let moves = self
            .segments
            .iter()
            .filter_map(|s| match s.stage {
                StageMotion::Move(k) => self.stage_moves.get(k).map(|m| (s.start_s, *m)),
                _ => None,
            })
            .collect();
        PoseTrack {
            start: self.start_pose,
            moves,
        }
    }
    /// The job turns or lifts an axis beyond X/Y somewhere.
    pub fn moves_extra_axes(&self) -> bool {
        !self.start_pose.is_rest()
            || self
                .stage_moves
                .iter()
                .any(|m| m.extra.iter().any(|e| e.distance_mm != 0.0))
    }

    /// Adds a stroke's points; returns its index.
    pub(crate) fn push_stroke(
        &mut self,
        step: usize,
        geometry: usize,
        field: usize,
        stage: Pt,
        path: &[Pt],
    ) -> usize {
        let first = self.points.len();
        let mut arc = 0.0;
        for (k, &p) in path.iter().enumerate() {
            if k > 0 {
                arc += p.dist(path[k - 1]);
            }
            self.points.push(p);
            self.arc_mm.push(arc);
        }
        self.strokes.push(Stroke {
            step,
            geometry,
            field,
            stage,
            points: first..self.points.len(),
            length_mm: arc,
            layer: None,
        });
        self.strokes.len() - 1
    }

    /// A copy whose strokes' points are mapped by `f(stroke, point)`: the job seen on another
    /// surface (a cylinder's unrolled one, for the canvas); the strokes' lengths follow the new
    /// points, the segments are kept.
    pub fn with_points_mapped(&self, f: impl Fn(&Stroke, Pt) -> Pt) -> Toolpath {
        let mut out = self.clone();
        for st in &mut out.strokes {
            let mut arc = 0.0;
            let mut last: Option<Pt> = None;
            for k in st.points.clone() {
                let p = f(st, self.points[k]);
                if let Some(q) = last {
                    arc += p.dist(q);
                }
                out.points[k] = p;
                out.arc_mm[k] = arc;
                last = Some(p);
            }
            st.length_mm = arc;
        }
        out
    }

    /// The same job run on a controller clock of `period_s`, where the laser can switch only on
    /// a tick: each mark starts on a tick (the wait before it, at its start with the laser off,
    /// grows to the next tick) and lasts whole ticks (marked slightly slower when its length at
    /// mark speed is not whole ticks); between two marks at least one tick has the laser off.
    /// Everything else keeps its timing. A sampled trajectory at that period then holds every
    /// mark's start and end point, and never shows a jump as a mark.
    pub fn on_clock(&self, period_s: f64) -> Toolpath {
        if self.route.is_some() {
            // an on-the-fly route is a function of time: it is clocked when it is lowered
            return self.clone();
        }
        let mut out = Toolpath {
            segments: Vec::with_capacity(self.segments.len() + self.strokes.len()),
            stage_moves: self.stage_moves.clone(),
            strokes: self.strokes.clone(),
            route: None,
            stretch: None,
            still_fields: self.still_fields.clone(),
            start_pose: self.start_pose,
            points: self.points.clone(),
            arc_mm: self.arc_mm.clone(),
        };
        let mut t_s = 0.0;
        let mut clock = MarkClock::new(period_s);
        for seg in &self.segments {
            if seg.kind != SegmentKind::Mark {
                out.segments.push(Segment {
                    start_s: t_s,
                    ..*seg
                });
                t_s += seg.duration_s;
                continue;
            }
            let (start_s, duration_s) = clock.place(t_s, seg.duration_s);
            if start_s > t_s {
                let at_start = self.state_in(seg, seg.start_s);
                out.segments.push(Segment {
                    kind: SegmentKind::LaserOnDelay,
                    start_s: t_s,
                    duration_s: start_s - t_s,
                    stage: StageMotion::Hold(at_start.stage),
                    scan: ScanMotion::Hold(at_start.scan),
                });
            }
            out.segments.push(Segment {
                start_s,
                duration_s,
                ..*seg
            });
            t_s = start_s + duration_s;
        }
        out
    }

    /// The same job run `k` (≥ 1) times slower, everywhere alike: every segment lasts `k` times
    /// as long and the route is read at the planned instant `t / k`. Positions along the job are
    /// the same; speeds divide by `k`, accelerations by `k²`. What a controller that cannot
    /// keep the planned pace does on the whole (motion/controller.rs).
    pub fn stretched(mut self, k: f64) -> Toolpath {
        if !(k.is_finite() && k > 1.0) {
            return self;
        }
        for seg in &mut self.segments {
            seg.start_s *= k;
            seg.duration_s *= k;
            match &mut seg.scan {
                ScanMotion::Line { move_s, .. } | ScanMotion::TcpLine { move_s, .. } => {
                    *move_s *= k;
                }
                _ => {}
            }
        }
        self.stretch = Some(self.stretch.unwrap_or(1.0) * k);
        self
    }

    /// The factor by which the job runs slower than planned (1: as planned).
    pub fn stretch(&self) -> f64 {
        self.stretch.unwrap_or(1.0)
    }

    /// The tool-centre points of stroke `k` in marking order.
    pub fn stroke_points(&self, k: usize) -> &[Pt] {
        self.strokes
            .get(k)
            .map_or(&[][..], |s| &self.points[s.points.clone()])
    }

    /// The arc length (mm) from stroke `k`'s start to each of its points.
    pub fn stroke_arc_mm(&self, k: usize) -> &[f64] {
        self.strokes
            .get(k)
            .map_or(&[][..], |s| &self.arc_mm[s.points.clone()])
    }

    /// Total duration, s.
    pub fn duration_s(&self) -> f64 {
        self.segments.last().map_or(0.0, Segment::end_s)
    }

    /// Durations added up by kind.
    pub fn breakdown(&self) -> TimeBreakdown {
        let mut b = TimeBreakdown::default();
        for s in &self.segments {
            let slot = match s.kind {
                SegmentKind::StageMove => &mut b.stage,
                SegmentKind::Settle => &mut b.settle,
                SegmentKind::Jump | SegmentKind::JumpDelay => &mut b.jump,
                SegmentKind::Mark => &mut b.mark,
                SegmentKind::LaserOnDelay | SegmentKind::LaserOffDelay => &mut b.laser_delays,
            };
            *slot += s.duration_s;
        }
        b
    }

    /// The stage's route, speeds and the scanner's reach, sampled every `period_s` from 0 to the
    /// end (docs/DESIGN.md: the total variation of the stage speed over the samples).
    pub fn motion_figures(&self, period_s: f64) -> MotionFigures {
        let n = (self.duration_s() / period_s).ceil() as usize;
        let mut f = MotionFigures::default();
        let mut last: Option<(Pt, f64)> = None;
        for k in 0..=n {
            let m = self.state_at(k as f64 * period_s);
            f.scan_peak_offset_mm = f
                .scan_peak_offset_mm
                .max(m.scan.x.abs())
                .max(m.scan.y.abs());
            let speed_mm_s = last.map_or(0.0, |(p, _)| m.stage.dist(p) / period_s);
            if let Some((p, previous_mm_s)) = last {
                f.stage_route_mm += m.stage.dist(p);
                f.stage_peak_speed_mm_s = f.stage_peak_speed_mm_s.max(speed_mm_s);
                if k >= 2 {
                    f.stage_speed_variation_mm_s += (speed_mm_s - previous_mm_s).abs();
                }
            }
            last = Some((m.stage, speed_mm_s));
        }
        f
    }

    /// Whether the strokes of field `id` are marked with the stage at rest inside an
    /// on-the-fly job (a mixed job's step-and-scan field).
    pub fn marks_still(&self, id: usize) -> bool {
        self.still_fields.binary_search(&id).is_ok()
    }

    /// When each stroke's last mark ends, s (strokes in marking order; a stroke with no mark,
    /// none in practice, ends where the one before did).
    pub fn mark_ends_s(&self) -> Vec<f64> {
        let mut ends_s = vec![0.0; self.strokes.len()];
        for seg in &self.segments {
            if let ScanMotion::Mark { stroke, .. } = seg.scan {
                if let Some(e) = ends_s.get_mut(stroke) {
                    *e = seg.end_s();
                }
            }
        }
        for k in 1..ends_s.len() {
            ends_s[k] = ends_s[k].max(ends_s[k - 1]);
        }
        ends_s
    }

    /// The stretches of a mixed job ([`Toolpath::still_fields`] marked step-and-scan, the rest
    /// on the fly), in job order; empty when it runs one motion.
    pub fn motion_regions(&self) -> Vec<MotionRegion> {
        if self.still_fields.is_empty() {
            return Vec::new();
        }
        let ends_s = self.mark_ends_s();
        let mut regions: Vec<MotionRegion> = Vec::new();
        for (k, stroke) in self.strokes.iter().enumerate() {
            let motion = match self.marks_still(stroke.field) {
                true => Motion::Step,
                false => Motion::OnTheFly,
            };
            // a still field is a region of its own; strokes on the fly run together
            let joins = regions.last().is_some_and(|r| {
                r.motion == motion
                    && (motion == Motion::OnTheFly || r.fields.last() == Some(&stroke.field))
            });
            match regions.last_mut() {
                Some(r) if joins => {
                    if r.fields.last() != Some(&stroke.field) {
                        r.fields.push(stroke.field);
                    }
                    r.strokes[1] = k + 1;
                    r.end_s = ends_s[k];
                }
                _ => {
                    let start_s = regions.last().map_or(0.0, |r| r.end_s);
                    regions.push(MotionRegion {
                        motion,
                        fields: vec![stroke.field],
                        strokes: [k, k + 1],
                        start_s,
                        end_s: ends_s[k],
                    });
                }
            }
        }
        if let Some(last) = regions.last_mut() {
            last.end_s = self.duration_s();
        }
        regions
    }

    /// The index of the segment running at `t_s` (the last one starting at or before it;
    /// clamped to the job).
    pub fn segment_at(&self, t_s: f64) -> usize {
        self.segments
            .partition_point(|s| s.start_s <= t_s)
            .saturating_sub(1)
    }

    /// The machine's state at `t_s` (clamped to the job). An instant where a mark begins or
    /// ends belongs to the mark, laser on.
    pub fn state_at(&self, t_s: f64) -> MachineState {
        let Some(last) = self.segments.len().checked_sub(1) else {
            return MachineState {
                stage: Pt::default(),
                scan: Pt::default(),
                laser: false,
            };
        };
        let k = self.segment_at(t_s);
        let on_mark = |i: usize| {
            self.segments.get(i).is_some_and(|s| {
                s.kind == SegmentKind::Mark
                    && t_s >= s.start_s - TIME_EPS_S
                    && t_s <= s.end_s() + TIME_EPS_S
            })
        };
        let k = if on_mark(k) {
            k
        } else if k > 0 && on_mark(k - 1) {
            k - 1
        } else if k < last && on_mark(k + 1) {
            k + 1
        } else {
            k
        };
        self.state_in(&self.segments[k], t_s)
    }

    fn state_in(&self, seg: &Segment, t_s: f64) -> MachineState {
        let local_s = (t_s - seg.start_s).clamp(0.0, seg.duration_s);
        let stage = match &seg.stage {
            StageMotion::Hold(p) => *p,
            StageMotion::Move(m) => self
                .stage_moves
                .get(*m)
                .map_or(Pt::default(), |m| m.position(local_s / self.stretch())),
            // the route goes on past the job's end (the stage comes to rest on it)
            StageMotion::Route => self
                .route
                .as_ref()
                .map_or(Pt::default(), |r| r.position(t_s.max(0.0) / self.stretch())),
        };
        let (scan, laser) = match seg.scan {
            ScanMotion::Hold(o) => (o, false),
            ScanMotion::TcpHold(p) => (p.minus(stage), false),
            ScanMotion::TcpLine { from, to, move_s } => {
                let u = if move_s > 0.0 {
                    (local_s / move_s).min(1.0)
                } else {
                    1.0
                };
                (from.plus(to.minus(from).scale(u)).minus(stage), false)
            }
            ScanMotion::Line { from, to, move_s } => {
                let u = if move_s > 0.0 {
                    (local_s / move_s).min(1.0)
                } else {
                    1.0
                };
                (from.plus(to.minus(from).scale(u)), false)
            }
            ScanMotion::Mark {
                stroke,
                start_frac,
                end_frac,
            } => {
                let u = if seg.duration_s > 0.0 {
                    local_s / seg.duration_s
                } else {
                    1.0
                };
                let along = start_frac + (end_frac - start_frac) * u;
                (self.point_along(stroke, along).minus(stage), true)
            }
        };
        MachineState { stage, scan, laser }
    }

    /// The point at fraction `u` (0..=1) of stroke `k`'s length.
    pub(crate) fn point_along(&self, k: usize, u: f64) -> Pt {
        let Some(s) = self.strokes.get(k) else {
            return Pt::default();
        };
        let pts = &self.points[s.points.clone()];
        let arc = &self.arc_mm[s.points.clone()];
        let Some(&first) = pts.first() else {
            return Pt::default();
        };
        let target = u.clamp(0.0, 1.0) * s.length_mm;
        // first point whose arc length reaches the target
        let j = arc.partition_point(|&a| a < target);
        if j == 0 {
            return first;
        }
        if j >= pts.len() {
            return pts[pts.len() - 1];
        }
        let span = arc[j] - arc[j - 1];
        let w = if span > 0.0 {
            (target - arc[j - 1]) / span
        } else {
            1.0
        };
        pts[j - 1].plus(pts[j].minus(pts[j - 1]).scale(w))
    }
}
