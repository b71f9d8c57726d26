//! [`lower`]: the one place where a plan becomes machine motion.

use super::axis::StageDynamics;
use super::controller::LinuxcncClock;
use super::toolpath::{ScanMotion, Segment, SegmentKind, StageMotion, Toolpath};
use crate::document::{
    Geometry, MachineProfile, MarkTiming, Plan, Pose, PoseError, ScanField, LANDING_TOL_MM,
};
use crate::geom::{is_dot, Pt};
use thiserror::Error;

/// How far a marked point may lie outside its field's reach before lowering refuses the plan,
/// mm: the import's 10 nm grid and float sums of field centres stay far below it.
pub const REACH_TOLERANCE_MM: f64 = 1e-6;

/// Why a plan cannot be lowered.
#[derive(Debug, Error, PartialEq)]
pub enum LowerError {
    /// A step names a geometry the document does not have.
    #[error("plan step {step} names geometry {geometry}, which the document does not have")]
    NoGeometry {
        /// Step index in marking order.
        step: usize,
        /// The geometry index.
        geometry: usize,
    },
    /// A step names a field the plan does not have.
    #[error("plan step {step} names scan field {field}, which the plan does not have")]
    NoField {
        /// Step index in marking order.
        step: usize,
        /// The field id.
        field: usize,
    },
    /// A step names a geometry without points (the import and the hatch never make one).
    #[error("plan step {step} names geometry {geometry}, which has no points")]
    Empty {
        /// Step index in marking order.
        step: usize,
        /// The geometry index.
        geometry: usize,
    },
    /// A geometry reaches outside its field.
    #[error("geometry {geometry} reaches {excess_mm:.4} mm outside scan field {field}")]
    OutOfReach {
        /// The geometry index.
        geometry: usize,
        /// The field id.
        field: usize,
        /// How far beyond the field edge, mm.
        excess_mm: f64,
    },
    /// A field's pose the machine cannot take.
    #[error(transparent)]
    Pose(Box<PoseError>),
}

/// Lowers a step-and-scan plan to the machine's motion.
///
/// The stage starts at rest at the first field's centre with the scanner at the first stroke's
/// start (no homing move). Per stroke: a scanner jump (laser off, jump speed) and the jump delay,
/// the laser-on delay, the mark (at its pen's mark speed in the plan, else the profile's), the
/// laser-off delay. On a field change the stage
/// moves (both axes at once, trapezoids, the slower sets the time) and settles; the scanner jumps
/// to the next start offset during the move when the jump and its delay fit in the move, after
/// the settling otherwise. The job ends with the last laser-off delay.
pub fn lower(
    geometries: &[Geometry],
    plan: &Plan,
    profile: &MachineProfile,
) -> Result<Toolpath, LowerError> {
    let mut b = Builder::new(profile);
    // per stroke: a jump, its delay, the laser delays and the mark; per field change a move
    // and its settling
    let points: usize = plan
        .order
        .iter()
        .filter_map(|s| geometries.get(s.geometry))
        .map(|g| g.points.len() + usize::from(g.closed))
        .sum();
    let n = plan.order.len();
    b.path.reserve(n, points, 5 * n + 2 * plan.fields.len());
    let mut field_at: Option<&ScanField> = None;
    for (k, step) in plan.order.iter().enumerate() {
        let g = geometries
            .get(step.geometry)
            .ok_or(LowerError::NoGeometry {
                step: k,
                geometry: step.geometry,
            })?;
        let field = match field_at {
            Some(f) if f.id == step.field => f,
            _ => plan
                .fields
                .iter()
                .find(|f| f.id == step.field)
                .ok_or(LowerError::NoField {
                    step: k,
                    field: step.field,
                })?,
        };
        if field_at.is_none_or(|f| f.id != field.id) {
            profile
                .check_pose(field.id, &field.pose)
                .map_err(|e| LowerError::Pose(Box::new(e)))?;
        }
        field_at = Some(field);
        let path = g.marking_path(step.start_vertex, step.reversed);
        check_reach(&path, field.center, field.size).map_err(|excess_mm| {
            LowerError::OutOfReach {
                geometry: step.geometry,
                field: step.field,
                excess_mm,
            }
        })?;
        let Some(&start) = path.first() else {
            return Err(LowerError::Empty {
                step: k,
                geometry: step.geometry,
            });
        };
        let stage = field.pose.stage_point(field.center);
        let timing = plan.mark_timing(g, profile);
        let Some(cylinder) = plan.settings.cylinder else {
            b.go_to(stage, &field.pose, start.minus(stage), k == 0);
            let stroke = b
                .path
                .push_stroke(k, step.geometry, step.field, stage, &path);
            b.mark(stroke, timing);
            continue;
        };
        // around a cylinder: the scanner marks the path pre-distorted by the strip's angle,
        // each edge at the speed that marks the surface at the pen's
        let a_deg = field.pose.a_deg;
        let scan = cylinder.predistort(&path, a_deg, stage.y, LANDING_TOL_MM);
        // a path with points stays one (never a stroke dropped without a word)
        let (Some(&start), Some(last)) = (scan.scanner.first(), scan.surface.len().checked_sub(1))
        else {
            return Err(LowerError::Empty {
                step: k,
                geometry: step.geometry,
            });
        };
        b.go_to(stage, &field.pose, start.minus(stage), k == 0);
        let stroke = b
            .path
            .push_stroke(k, step.geometry, step.field, stage, &scan.scanner);
        let surface_s = |j: usize| scan.surface[j].dist(scan.surface[j + 1]) / timing.speed_mm_s;
        if last == 0 {
            b.mark(stroke, timing);
        } else {
            b.mark_edges(stroke, &|j| {
                let (p, q) = (scan.scanner[j], scan.scanner[j + 1]);
                (
                    surface_s(j),
                    cylinder.scanner_speed_mm_s(p, q, a_deg, stage.y, timing.speed_mm_s),
                )
            });
        }
    }
    b.end_pauses();
    Ok(b.path)
}

/// `Err(excess)` when a point lies outside the field of `size` centred at `center`.
fn check_reach(path: &[Pt], center: Pt, size: [f64; 2]) -> Result<(), f64> {
    let excess = path
        .iter()
        .map(|p| {
            let o = p.minus(center);
            (o.x.abs() - size[0] / 2.0).max(o.y.abs() - size[1] / 2.0)
        })
        .fold(f64::NEG_INFINITY, f64::max);
    if excess > REACH_TOLERANCE_MM {
        Err(excess)
    } else {
        Ok(())
    }
}

/// Appends segments while tracking where the stage and scanner are.
struct Builder<'a> {
    profile: &'a MachineProfile,
    stage: StageDynamics,
    path: Toolpath,
    t_s: f64,
    stage_at: Pt,
    /// Where Z, A and B stand.
    pose_at: Pose,
    scan_at: Pt,
    /// The controller's clock (LinuxCNC), which times moves and task's commands; none: the
    /// scan head's own timing.
    clock: Option<LinuxcncClock>,
    /// On a controller clock: the pauses since the last move or dot, not yet pushed (one dwell
    /// on the controller, timed when it ends).
    pauses: Vec<(SegmentKind, f64)>,
    /// On a controller clock: the last thing done was a move (or nothing yet: the program
    /// moves to the start), so that the next dwell or dot is the first command task runs after
    /// it.
    moved: bool,
    /// On a controller clock: the laser output as the last move (or dot) left it.
    lit: bool,
}

impl<'a> Builder<'a> {
    fn new(profile: &'a MachineProfile) -> Self {
        Self {
            profile,
            stage: StageDynamics::of(profile),
            path: Toolpath::default(),
            t_s: 0.0,
            stage_at: Pt::default(),
            pose_at: Pose::default(),
            scan_at: Pt::default(),
            clock: LinuxcncClock::of(profile),
            pauses: Vec::new(),
            moved: true,
            lit: false,
        }
    }

    fn push(&mut self, kind: SegmentKind, duration_s: f64, stage: StageMotion, scan: ScanMotion) {
        self.path.segments.push(Segment {
            kind,
            start_s: self.t_s,
            duration_s,
            stage,
            scan,
        });
        self.t_s += duration_s;
    }

    /// A pause with stage and scanner at rest (skipped when zero); on a controller clock, pauses
    /// next to each other are one dwell, pushed when it ends ([`Builder::end_pauses`]).
    fn hold(&mut self, kind: SegmentKind, duration_s: f64) {
        if duration_s <= 0.0 {
            return;
        }
        if self.clock.is_some() {
            self.pauses.push((kind, duration_s));
        } else {
            self.push_hold(kind, duration_s);
        }
    }

    fn push_hold(&mut self, kind: SegmentKind, duration_s: f64) {
        let (stage, scan) = (self.stage_at, self.scan_at);
        self.push(
            kind,
            duration_s,
            StageMotion::Hold(stage),
            ScanMotion::Hold(scan),
        );
    }

    /// On a controller clock, before a move, a dot or the end: the pauses held since the last
    /// move or dot as one dwell, timed by the clock; its first pause carries what the clock
    /// adds, the others their own time.
    fn end_pauses(&mut self) {
        let Some(clock) = &self.clock else {
            return;
        };
        if self.pauses.is_empty() {
            return;
        }
        let total_s: f64 = self.pauses.iter().map(|p| p.1).sum();
        let dwell_s = clock.dwell_s(total_s, self.moved);
        let rest_s: f64 = self.pauses[1..].iter().map(|p| p.1).sum();
        let mut pauses = std::mem::take(&mut self.pauses);
        for (k, &(kind, p_s)) in pauses.iter().enumerate() {
            self.push_hold(kind, if k == 0 { dwell_s - rest_s } else { p_s });
        }
        pauses.clear();
        self.pauses = pauses;
        self.moved = false;
    }

    /// On a controller clock, before a move (`lit`: a mark): the pauses held since the last
    /// move or dot as one dwell; after such task-level commands a move that switches the laser
    /// (`M62`/`M63` before it) waits for that output too, added to the last of them.
    fn before_move(&mut self, lit: bool) {
        let Some(output_s) = self.clock.as_ref().map(LinuxcncClock::output_s) else {
            return;
        };
        self.end_pauses();
        if !self.moved && lit != self.lit {
            if let Some(last) = self.path.segments.last_mut() {
                last.duration_s += output_s;
                self.t_s += output_s;
            }
        }
        self.moved = true;
        self.lit = lit;
    }

    /// A scanner jump to `offset` and its delay, the stage at rest.
    fn jump(&mut self, offset: Pt) {
        let d = offset.minus(self.scan_at);
        let move_s = match &self.clock {
            Some(c) => c.move_s([0.0, 0.0, d.x, d.y], None),
            None => d.norm() / self.profile.scanner.jump_speed_mm_s,
        };
        if move_s > 0.0 {
            self.before_move(false);
            let from = self.scan_at;
            let stage = StageMotion::Hold(self.stage_at);
            let scan = ScanMotion::Line {
                from,
                to: offset,
                move_s,
            };
            self.push(SegmentKind::Jump, move_s, stage, scan);
            self.scan_at = offset;
        }
        self.hold(SegmentKind::JumpDelay, self.profile.laser.jump_delay_s);
    }

    /// Brings the stage to `center` at `pose` and the scanner to `offset` (the first stroke:
    /// places them).
    fn go_to(&mut self, center: Pt, pose: &Pose, offset: Pt, first: bool) {
        if first {
            self.stage_at = center;
            self.pose_at = *pose;
            self.path.start_pose = *pose;
            self.scan_at = offset;
            return;
        }
        if center == self.stage_at && *pose == self.pose_at {
            self.jump(offset);
            return;
        }
        let mv = self
            .stage
            .plan_pose_move(self.stage_at, &self.pose_at, center, pose);
        let jump_s = offset.dist(self.scan_at) / self.profile.scanner.jump_speed_mm_s;
        // on a controller clock the jump is part of the stage's move (one coordinated G0),
        // which comes to rest on both
        let hidden = self.clock.is_some()
            || (jump_s <= mv.move_s && jump_s + self.profile.laser.jump_delay_s <= mv.total_s());
        let move_s = match &self.clock {
            Some(c) => {
                let (d, j) = (center.minus(self.stage_at), offset.minus(self.scan_at));
                let turn = self.pose_at.turn_to(pose);
                // never shorter than the axes' own trapezoids (the stage's position is timed by them)
                c.move_axes_s([d.x, d.y, j.x, j.y], turn, None)
                    .max(mv.move_s)
            }
            None => mv.move_s,
        };
        let scan = if hidden {
            ScanMotion::Line {
                from: self.scan_at,
                to: offset,
                move_s: jump_s,
            }
        } else {
            ScanMotion::Hold(self.scan_at)
        };
        self.before_move(false);
        self.path.stage_moves.push(mv);
        let moving = StageMotion::Move(self.path.stage_moves.len() - 1);
        self.push(SegmentKind::StageMove, move_s, moving, scan);
        self.stage_at = center;
        self.pose_at = *pose;
        if hidden {
            self.scan_at = offset;
        }
        self.hold(SegmentKind::Settle, mv.settle_s);
        if !hidden {
            self.jump(offset);
        }
    }

    /// Marks stroke `stroke` (not a dot) edge by edge (a cylinder's pre-distorted path): on
    /// delay, one mark part per edge, off delay. `edge(j)` is edge `j`'s time at the pen's speed on the
    /// surface, s, and the scanner's speed along it, mm/s (on a controller clock, the `G1`'s
    /// feed, whose exact-stop move the clock times).
    fn mark_edges(&mut self, stroke: usize, edge: &dyn Fn(usize) -> (f64, f64)) {
        let laser = &self.profile.laser;
        let (on_s, off_s) = (laser.on_delay_s, laser.off_delay_s);
        self.hold(SegmentKind::LaserOnDelay, on_s);
        self.before_move(true);
        let points = self.path.stroke_points(stroke).to_vec();
        let length_mm = self.path.strokes[stroke].length_mm;
        let mut along = 0.0;
        for (j, w) in points.windows(2).enumerate() {
            let (surface_s, scanner_mm_s) = edge(j);
            let d = w[1].minus(w[0]);
            let duration_s = match &self.clock {
                Some(c) => c.move_s([0.0, 0.0, d.x, d.y], Some(scanner_mm_s)),
                None => surface_s,
            };
            let start_frac = if length_mm > 0.0 {
                along / length_mm
            } else {
                0.0
            };
            along += d.norm();
            let end_frac = if j + 2 == points.len() || length_mm <= 0.0 {
                1.0
            } else {
                (along / length_mm).min(1.0)
            };
            let stage = StageMotion::Hold(self.stage_at);
            let scan = ScanMotion::Mark {
                stroke,
                start_frac,
                end_frac,
            };
            self.push(SegmentKind::Mark, duration_s, stage, scan);
        }
        if let Some(&end) = points.last() {
            self.scan_at = end.minus(self.stage_at);
        }
        self.hold(SegmentKind::LaserOffDelay, off_s);
    }

    /// Marks stroke `stroke` as its pen says (`timing`) from where the scanner stands: on
    /// delay, mark (or a dot's dwell), off delay.
    fn mark(&mut self, stroke: usize, timing: MarkTiming) {
        let laser = &self.profile.laser;
        let (on_s, off_s) = (laser.on_delay_s, laser.off_delay_s);
        self.hold(SegmentKind::LaserOnDelay, on_s);
        let dot = is_dot(self.path.stroke_points(stroke));
        if dot {
            self.end_pauses();
        } else {
            self.before_move(true);
        }
        let length_mm = self.path.strokes[stroke].length_mm;
        let points = self.path.stroke_points(stroke);
        let duration_s = match &self.clock {
            // M64, G4, M65: task-level commands, like a dwell
            Some(c) if dot => c.dot_s(timing.dot_dwell_s, self.moved),
            Some(c) => c.polyline_s(points, timing.speed_mm_s),
            None => timing.mark_s(points, length_mm),
        };
        if dot {
            // the program switches the laser off (M63) before a dot where a mark left it on
            self.moved = false;
            self.lit = false;
        }
        let stage = StageMotion::Hold(self.stage_at);
        self.push(
            SegmentKind::Mark,
            duration_s,
            stage,
            ScanMotion::Mark {
                stroke,
                start_frac: 0.0,
                end_frac: 1.0,
            },
        );
        if let Some(&end) = self.path.stroke_points(stroke).last() {
            self.scan_at = end.minus(self.stage_at);
        }
        self.hold(SegmentKind::LaserOffDelay, off_s);
    }
}
