//! The LinuxCNC dialect (docs/GCODE.md, *LinuxCNC*): one program for a machine whose stage
//! axes (X, Y) and scanner axes (the profile's words, default U, V) are coordinated axes of one
//! LinuxCNC machine (trivkins XYUV; [`super::linuxcnc_config`] writes its configuration).
//!
//! Written from the toolpath's segments, one after another, so that the program runs the
//! toolpath's motion and nothing else:
//!
//! * **step-and-scan**: a stage move is `G0 X.. Y..` (with the scanner words when the scanner
//!   jumps during it), a scanner jump `G0 U.. V..`, a mark `G1 U.. V..` through the stroke's
//!   points at its pen's feed; settling, jump and laser delays are dwells (`G4 P<s>`), those
//!   next to each other one dwell of their own times added (the toolpath's pauses last what
//!   LinuxCNC's task adds to them too: [`crate::motion::controller`]);
//! * **on the fly**: the whole job in inverse time (`G93`), `G1 X.. Y.. U.. V.. F<1/min>`, each
//!   line lasting what the toolpath takes between its two ends; the toolpath is sampled every
//!   millisecond (and at every segment end and mark vertex) and consecutive samples are merged
//!   while the path between them stays within `path_tol_mm` of the straight line
//!   ([`otf_lines`]).
//!
//! The laser is a digital output: `M62 P<n>` before the first move of a mark (it switches at
//! that move's start), `M63 P<n>` before the first move after it; `M65 P<n>` (at once) at the
//! start and the end, then `M2`. Power goes to an analog output (`M67 E<n> Q<power>`,
//! synchronised) or, without one, on the profile's power word.

use super::gcode::{GcodeError, PenWords, Words, CHUNK_BYTES};
use crate::document::{MachineProfile, MarkTiming, Plan, Pose};
use crate::geom::Pt;
use crate::motion::controller::otf_lines;
use crate::motion::{ScanMotion, SegmentKind, StageMotion, Toolpath};
use std::fmt::Write;

/// Dwells shorter than this are not written, s (LinuxCNC's `G4` takes at least a servo period).
const MIN_DWELL_S: f64 = 1e-7;

/// Writes `toolpath` as a LinuxCNC program (see the module documentation) to `sink`, in
/// pieces of about [`CHUNK_BYTES`] as the other dialects are written: a million strokes make
/// hundreds of MB of program, never held whole.
pub(super) fn write_program(
    sink: &mut dyn std::io::Write,
    toolpath: &Toolpath,
    plan: &Plan,
    w: &Words<'_>,
    header: &str,
) -> Result<(), GcodeError> {
    let profile = &plan.profile;
    let mut p = Program::new(profile, w, sink);
    p.out.push_str(header);
    if toolpath.route.is_some() && profile.controller.streamed(plan.motion) {
        p.start(false);
        p.hand_over(toolpath);
        p.end();
        return p.spill(0);
    }
    p.start(toolpath.route.is_some());
    if toolpath.route.is_some() {
        p.on_the_fly(toolpath, plan)?;
    } else {
        p.step_and_scan(toolpath, plan)?;
    }
    p.end();
    p.spill(0)
}

/// A program being written, and the machine state its lines leave.
struct Program<'a, 'w> {
    profile: &'a MachineProfile,
    w: &'a Words<'w>,
    /// Where the program goes; `out` holds the lines not yet written there.
    sink: &'a mut dyn std::io::Write,
    out: String,
    /// The laser output is (or will be, at the next move) on.
    lit: bool,
    /// Dwell not yet written, s.
    dwell_s: f64,
    /// The settling of the last stage move, s.
    settle_s: f64,
    /// The pen whose power and feed were last written (layer index; none: the profile's).
    pen: Option<Option<usize>>,
    /// That pen's feed (F), mm/min.
    feed: String,
    /// That pen's mark speed, mm/s.
    speed: f64,
    /// Layer comments are written (the plan's layers have pens of their own).
    comment_layers: bool,
}

impl<'a, 'w> Program<'a, 'w> {
    fn new(
        profile: &'a MachineProfile,
        w: &'a Words<'w>,
        sink: &'a mut dyn std::io::Write,
    ) -> Self {
        Self {
            profile,
            w,
            sink,
            out: String::with_capacity(CHUNK_BYTES + 4096),
            lit: false,
            dwell_s: 0.0,
            settle_s: 0.0,
            pen: None,
            feed: String::new(),
            speed: 0.0,
            comment_layers: false,
        }
    }

    /// Units, absolute positions, the path mode, the laser off. Step-and-scan runs in exact
    /// path mode (`G61`): LinuxCNC blends moves of the U/V axes only parabolically, without
    /// the `G64 P` bound, so blended marks would cut their corners. On the fly the moves blend
    /// (`G64 P`), or the stage would stop at every line.
    fn start(&mut self, blend: bool) {
        let d = &self.profile.gcode;
        let path_mode = if blend {
            format!("G64 P{}", self.w.num(d.path_tol_mm))
        } else {
            "G61".to_string()
        };
        let _ = writeln!(
            self.out,
            "G21 G90 G94 G17 G40 G49\n{path_mode}\nM65 P{}",
            d.laser_output
        );
    }

    fn end(&mut self) {
        self.flush_dwell();
        let d = &self.profile.gcode;
        let _ = writeln!(self.out, "M65 P{}", d.laser_output);
        if let Some(e) = d.power_output {
            let _ = writeln!(self.out, "M68 E{e} Q0");
        }
        self.out.push_str("G94\n(end)\nM2\n");
    }

    /// A streamed on-the-fly job: the machine to the stream's first sample, the joints handed
    /// to the stream (`M64` on the stream's output), a wait for its last sample (`M66` on its
    /// end input; the program is aborted when it does not come), motion taken to the last
    /// sample while the stream still holds the joints (so that nothing jumps), and the joints
    /// handed back (`M65`).
    fn hand_over(&mut self, toolpath: &Toolpath) {
        let d = &self.profile.gcode;
        let [u, v] = [d.scanner_axes[0].trim(), d.scanner_axes[1].trim()];
        let sel = super::linuxcnc_config::stream_output(self.profile);
        let end = super::linuxcnc_config::STREAM_END_INPUT;
        let first = toolpath.state_at(0.0);
        let last = toolpath.state_at(toolpath.duration_s());
        let at = |m: &crate::motion::MachineState| {
            format!(
                "X{} Y{} {u}{} {v}{}",
                self.w.num(m.stage.x),
                self.w.num(m.stage.y),
                self.w.num(m.scan.x),
                self.w.num(m.scan.y)
            )
        };
        let (from, to) = (at(&first), at(&last));
        // the wait is bounded: the job's time and 10 s for the stream to start
        let wait_s = toolpath.duration_s() + 10.0;
        let _ = write!(
            self.out,
            "(streamed on the fly: the stream moves X Y {u} {v} and the laser, one sample a period)
G0 {from}
M66 P{end} L0
M64 P{sel}
M66 P{end} L3 Q{wait}
o100 if [#5399 LT 0]
(abort, the stream did not reach its last sample: it ran dry or its feeder stopped)
o100 endif
G0 {to}
M66 P{end} L0
M65 P{sel}
",
            wait = fmt_s(wait_s)
        );
    }

    /// Writes the lines held to the sink once they are `at_least` bytes (0: whatever is held).
    fn spill(&mut self, at_least: usize) -> Result<(), GcodeError> {
        if self.out.len() >= at_least && !self.out.is_empty() {
            self.sink
                .write_all(self.out.as_bytes())
                .map_err(|e| GcodeError::Write(e.to_string()))?;
            self.out.clear();
        }
        Ok(())
    }

    /// A pause at rest of `kind`, written as one dwell with the pauses next to it: its own
    /// time (the profile's delay, the stage move's settling), not the segment's, which holds
    /// what the controller adds to the dwell as well.
    fn dwell(&mut self, kind: SegmentKind) {
        let laser = &self.profile.laser;
        self.dwell_s += match kind {
            SegmentKind::Settle => self.settle_s,
            SegmentKind::JumpDelay => laser.jump_delay_s,
            SegmentKind::LaserOnDelay => laser.on_delay_s,
            SegmentKind::LaserOffDelay => laser.off_delay_s,
            _ => 0.0,
        };
    }

    fn flush_dwell(&mut self) {
        if self.dwell_s >= MIN_DWELL_S {
            let _ = writeln!(self.out, "G4 P{}", fmt_s(self.dwell_s));
        }
        self.dwell_s = 0.0;
    }

    /// A dot: the laser switched on at once where the scanner stands (`M64`: task waits for
    /// the motion before it to end), `G4` for the dwell, and off at once (`M65`). `M62` would
    /// wait for a next move, and a dot has none.
    fn dot(&mut self, dwell_s: f64) {
        self.before_move(false);
        let n = self.profile.gcode.laser_output;
        let _ = writeln!(self.out, "M64 P{n}\nG4 P{}\nM65 P{n}", fmt_s(dwell_s));
    }

    /// Before a move: the dwell before it, and the laser switched for it.
    fn before_move(&mut self, lit: bool) {
        self.flush_dwell();
        if lit != self.lit {
            let n = self.profile.gcode.laser_output;
            let _ = writeln!(self.out, "{} P{n}", if lit { "M62" } else { "M63" });
            self.lit = lit;
        }
    }

    /// The feed (F) of a stroke's pen; where the pen changes, its layer comment and power
    /// first.
    fn pen_for(
        &mut self,
        plan: &Plan,
        layer: Option<usize>,
        stroke: usize,
    ) -> Result<String, GcodeError> {
        if self.pen == Some(layer) {
            return Ok(self.feed.clone());
        }
        let pen_layer = match layer {
            None => None,
            Some(l) => Some(
                plan.layers
                    .get(l)
                    .ok_or(GcodeError::NoLayer { stroke, layer: l })?,
            ),
        };
        let words = PenWords::of(self.w, pen_layer);
        self.pen = Some(layer);
        if self.comment_layers {
            if let Some(c) = &words.comment {
                let _ = writeln!(self.out, "({})", comment_text(c.trim_start_matches("; ")));
            }
        }
        if let Some(power) = words.power {
            let d = &self.profile.gcode;
            let _ = match d.power_output {
                Some(e) => writeln!(self.out, "M67 E{e} Q{}", self.w.num(power)),
                None => writeln!(self.out, "{}{}", d.power_word, self.w.num(power)),
            };
        }
        // the feed the toolpath was timed with: the pen's mark speed (the other dialects' feed
        // word may differ from it in a profile; this program runs what was planned)
        let speed = pen_layer.map_or(self.profile.scanner.mark_speed_mm_s, |l| {
            l.pen.mark_speed_mm_s(self.profile)
        });
        self.feed = self.w.num(speed * 60.0);
        self.speed = speed;
        Ok(self.feed.clone())
    }

    fn scan_words(&self, offset: Pt) -> String {
        let a = &self.profile.gcode.scanner_axes;
        self.w
            .xy([a[0].as_str(), a[1].as_str()], self.w.offset(offset))
    }

    fn stage_words(&self, p: Pt, pose: &Pose) -> String {
        self.w.stage_words(p, pose)
    }

    fn field_comment(&mut self, plan: &Plan, field: usize, centre: Pt) {
        let number = plan
            .fields
            .iter()
            .position(|f| f.id == field)
            .map_or(format!("[id {field}]"), |k| (k + 1).to_string());
        let c = self.w.position(centre);
        let _ = writeln!(
            self.out,
            "(field {number} centre {} {})",
            self.w.num(c.x),
            self.w.num(c.y)
        );
    }

    /// Step-and-scan: the segments as moves and dwells.
    fn step_and_scan(&mut self, toolpath: &Toolpath, plan: &Plan) -> Result<(), GcodeError> {
        self.comment_layers = plan.layers.iter().any(|l| !l.pen.marks_as_profile());
        let mut field = None;
        // a cylinder's strips by field id: the angle their marks are pre-distorted for
        let angle: std::collections::HashMap<usize, f64> = match plan.settings.cylinder {
            Some(_) => plan.fields.iter().map(|f| (f.id, f.pose.a_deg)).collect(),
            None => Default::default(),
        };
        // the lowering places stage and scanner at the first stroke's start: move there
        if let (Some(first), Some(&start)) =
            (toolpath.strokes.first(), toolpath.stroke_points(0).first())
        {
            self.field_comment(plan, first.field, first.stage);
            field = Some(first.field);
            let _ = writeln!(
                self.out,
                "G0 {} {}",
                self.stage_words(first.stage, &toolpath.start_pose),
                self.scan_words(start.minus(first.stage))
            );
        }
        // strokes whose marking has been written
        let mut marked = 0;
        for seg in &toolpath.segments {
            self.spill(CHUNK_BYTES)?;
            match (seg.kind, seg.stage, seg.scan) {
                (SegmentKind::StageMove, StageMotion::Move(m), scan) => {
                    let Some(mv) = toolpath.stage_moves.get(m) else {
                        return Err(GcodeError::Unwritable { kind: seg.kind });
                    };
                    self.before_move(false);
                    self.settle_s = mv.settle_s;
                    let to = mv.position(seg.duration_s);
                    // the field of the next stroke marked (a cylinder's strips share a stage
                    // position); on a flat job where the move ends exactly on its centre
                    let next = toolpath.strokes.get(marked);
                    let arrived = |s: &&crate::motion::Stroke| {
                        plan.settings.cylinder.is_some() || s.stage == to
                    };
                    if let Some(s) = next.filter(arrived) {
                        if field != Some(s.field) {
                            field = Some(s.field);
                            self.field_comment(plan, s.field, to);
                        }
                    }
                    let jump = match scan {
                        ScanMotion::Line { to, .. } => format!(" {}", self.scan_words(to)),
                        _ => String::new(),
                    };
                    let pose = mv.pose(seg.duration_s);
                    let _ = writeln!(self.out, "G0 {}{jump}", self.stage_words(to, &pose));
                }
                (SegmentKind::Jump, _, ScanMotion::Line { to, .. }) => {
                    self.before_move(false);
                    let _ = writeln!(self.out, "G0 {}", self.scan_words(to));
                }
                (
                    SegmentKind::Mark,
                    StageMotion::Hold(stage),
                    ScanMotion::Mark {
                        stroke, start_frac, ..
                    },
                ) => {
                    let layer = toolpath.strokes.get(stroke).and_then(|s| s.layer);
                    let feed = self.pen_for(plan, layer, stroke)?;
                    let points = toolpath.stroke_points(stroke);
                    if points.is_empty() {
                        return Err(GcodeError::EmptyStroke { stroke });
                    }
                    if crate::geom::is_dot(points) {
                        marked += 1;
                        let pen = layer.and_then(|l| plan.layers.get(l)).map(|l| &l.pen);
                        self.dot(MarkTiming::of(pen, self.profile).dot_dwell_s);
                        continue;
                    }
                    if start_frac > 0.0 {
                        // a cylinder's edge by edge: the stroke's first part wrote them all
                        continue;
                    }
                    marked += 1;
                    self.before_move(true);
                    let around = plan.settings.cylinder.map(|c| {
                        let field = toolpath.strokes.get(stroke).map(|s| s.field);
                        let a_deg = field.and_then(|f| angle.get(&f)).copied();
                        (c, a_deg.unwrap_or(0.0))
                    });
                    for (j, w) in points.windows(2).enumerate() {
                        let words = self.scan_words(w[1].minus(stage));
                        if let Some((c, a_deg)) = around {
                            // the feed the lowering timed this edge with
                            let speed =
                                c.scanner_speed_mm_s(w[0], w[1], a_deg, stage.y, self.speed);
                            let _ = writeln!(self.out, "G1 {words} F{}", self.w.num(speed * 60.0));
                        } else if j == 0 {
                            let _ = writeln!(self.out, "G1 {words} F{feed}");
                        } else {
                            let _ = writeln!(self.out, "G1 {words}");
                        }
                    }
                }
                (
                    SegmentKind::Settle
                    | SegmentKind::JumpDelay
                    | SegmentKind::LaserOnDelay
                    | SegmentKind::LaserOffDelay,
                    _,
                    _,
                ) => self.dwell(seg.kind),
                _ => return Err(GcodeError::Unwritable { kind: seg.kind }),
            }
        }
        Ok(())
    }

    /// On the fly: the job as timed lines in inverse time, each lasting its planned time
    /// ([`otf_lines`]; a toolpath stretched to the controller's pace is written as planned:
    /// LinuxCNC itself runs it at that pace).
    fn on_the_fly(&mut self, toolpath: &Toolpath, plan: &Plan) -> Result<(), GcodeError> {
        self.comment_layers = plan.layers.iter().any(|l| !l.pen.marks_as_profile());
        let (start, lines) = otf_lines(toolpath, self.profile.gcode.path_tol_mm);
        if lines.is_empty() {
            return Ok(());
        }
        let _ = writeln!(
            self.out,
            "G0 {} {}",
            self.stage_words(start.stage, &Pose::default()),
            self.scan_words(start.scan)
        );
        self.out.push_str("G93\n");
        for line in &lines {
            self.spill(CHUNK_BYTES)?;
            if let Some(stroke) = line.stroke {
                let layer = toolpath.strokes.get(stroke).and_then(|s| s.layer);
                let _ = self.pen_for(plan, layer, stroke)?;
            }
            self.before_move(line.lit);
            let duration_min = line.duration_s / 60.0;
            let _ = writeln!(
                self.out,
                "G1 {} {} F{}",
                self.stage_words(line.stage, &Pose::default()),
                self.scan_words(line.scan),
                fmt_inverse_time(1.0 / duration_min)
            );
        }
        Ok(())
    }
}

/// Seconds for `G4 P`: to 0.1 µs, trailing zeros trimmed.
fn fmt_s(v: f64) -> String {
    crate::geom::format_mm(v, 7)
}

/// An inverse-time feed (1/min) with nine significant digits.
fn fmt_inverse_time(f: f64) -> String {
    let digits = f.abs().log10().floor().max(0.0) as usize + 1;
    crate::geom::format_mm(f, 9usize.saturating_sub(digits).max(1))
}

/// Text that fits inside a LinuxCNC comment (no parentheses).
fn comment_text(s: &str) -> String {
    s.replace(['(', ')'], "").replace('\n', " ")
}
