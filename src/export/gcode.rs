//! G-code from the lowered toolpath, in two dialects (docs/DESIGN.md, docs/GCODE.md):
//!
//! * `tcp`: the tool-centre-point path on X/Y — `G0` to each stroke's start, the laser-on word,
//!   `G1` marks (feed on the first), the laser-off word; a comment at every field change;
//! * `stage-scanner`: at every field change a `G0 X.. Y..` positions the stage at the field's
//!   centre; scanner jumps (`G0`) and marks (`G1`) are field-local offsets on the two scanner
//!   axis words (default `U`, `V`), with the same laser words.
//!
//! A machine with axes beyond X/Y (document/axes.rs) turns them at every field change: its
//! stage words carry `Z`, `A`, `B` for the axes it has (`stage-scanner`, LinuxCNC), a
//! tool-centre program a `G0 Z.. A.. B..` line. A flat machine's programs are unchanged.

use crate::document::{ExtraAxisId, GcodeMode, Layer, MachineProfile, Plan, Pose};
use crate::geom::Pt;
use crate::motion::Toolpath;
use std::fmt::Write;
use thiserror::Error;

/// A toolpath the dialect cannot express.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum GcodeError {
    /// The stage moves while marking (on the fly): no per-field stage position to write.
    #[error("the stage-scanner G-code needs step-and-scan motion (the stage moves while marking on the fly): use the tcp dialect or the trajectory")]
    StageScannerOnTheFly,
    /// A stroke without points (lowering never makes one).
    #[error("stroke {stroke} of the toolpath has no points")]
    EmptyStroke {
        /// Stroke index in marking order.
        stroke: usize,
    },
    /// A segment the dialect has no words for (lowering never makes one).
    #[error("the LinuxCNC program cannot express a {kind:?} segment of this kind of motion")]
    Unwritable {
        /// The segment's kind.
        kind: crate::motion::SegmentKind,
    },
    /// The output could not be written.
    #[error("cannot write the G-code: {0}")]
    Write(String),
    /// A stroke names a layer the plan does not have (lowering never does).
    #[error("stroke {stroke} of the toolpath names layer {layer}, which the plan does not have")]
    NoLayer {
        /// Stroke index in marking order.
        stroke: usize,
        /// Layer index.
        layer: usize,
    },
}

/// The laser-on line, power, feed and layer comment of one pen.
pub(super) struct PenWords {
    pub(super) on: String,
    pub(super) power: Option<f64>,
    pub(super) feed: String,
    /// The feed, mm/min.
    pub(super) feed_mm_min: f64,
    pub(super) comment: Option<String>,
    /// A dot's dwell (`G4 P`, seconds as RS274NGC reads it).
    pub(super) dot_dwell: String,
}

impl PenWords {
    pub(super) fn of(w: &Words<'_>, layer: Option<&Layer>) -> Self {
        let profile = w.profile;
        let d = &profile.gcode;
        let pen = layer.map(|l| &l.pen);
        let power = pen.map_or(d.power, |p| p.power(profile));
        let feed = pen.map_or(d.feed_mm_min, |p| p.feed_mm_min(profile));
        let on = match power {
            Some(s) => format!("{} {}{}", d.laser_on, d.power_word, w.num(s)),
            None => d.laser_on.clone(),
        };
        let comment = layer.map(|l| {
            let speed = l.pen.mark_speed_mm_s(profile);
            let freq = l.pen.frequency_khz.map_or(String::new(), |f| {
                format!(", pulse frequency {} kHz", w.num(f))
            });
            format!(
                "; layer {}: mark speed {} mm/s, passes {}{freq}",
                l.name.replace('\n', " "),
                w.num(speed),
                l.pen.passes
            )
        });
        let dot_dwell_s = pen.map_or(profile.laser.dot_dwell_s, |p| p.dot_dwell_s(profile));
        Self {
            on,
            power,
            feed: w.num(feed),
            feed_mm_min: feed,
            comment,
            dot_dwell: crate::geom::format_mm(dot_dwell_s, 7),
        }
    }
}

/// Number formatting and the Y mirror of a dialect.
pub(super) struct Words<'a> {
    pub(super) profile: &'a MachineProfile,
    pub(super) page_height_mm: f64,
}

impl Words<'_> {
    /// A number with the dialect's decimals, trailing zeros trimmed, no negative zero.
    pub(super) fn num(&self, v: f64) -> String {
        crate::geom::format_mm(v, self.profile.gcode.decimals)
    }
    /// A machine position (mirrored about the page height when the dialect flips Y).
    pub(super) fn position(&self, p: Pt) -> Pt {
        if self.profile.gcode.flip_y {
            Pt::new(p.x, self.page_height_mm - p.y)
        } else {
            p
        }
    }
    /// A scanner offset (mirrored with the positions).
    pub(super) fn offset(&self, o: Pt) -> Pt {
        if self.profile.gcode.flip_y {
            Pt::new(o.x, -o.y)
        } else {
            o
        }
    }
    /// `X.. Y..`, or the scanner words for an offset in stage-scanner mode.
    pub(super) fn xy(&self, axes: [&str; 2], p: Pt) -> String {
        let mut out = String::new();
        self.push_xy(&mut out, axes, p);
        out
    }
    /// The stage's words for a placement at `p` with `pose`: `X.. Y..`, then `Z..`, `A..`,
    /// `B..` for the axes the machine has (a flat machine: `X.. Y..` alone; a rotary machine
    /// without Y: no `Y`). Mirroring Y turns A the other way (a rotation about X mirrored in Y
    /// is the opposite rotation); Z and B are unchanged by it.
    pub(super) fn stage_words(&self, p: Pt, pose: &Pose) -> String {
        let p = self.position(p);
        let decimals = self.profile.gcode.decimals;
        let mut out = String::from("X");
        crate::geom::push_mm(&mut out, p.x, decimals);
        if self.profile.has_y() {
            out.push_str(" Y");
            crate::geom::push_mm(&mut out, p.y, decimals);
        }
        for id in self.profile.extra_axes() {
            let mut v = pose.values()[id.index()];
            if id == ExtraAxisId::A && self.profile.gcode.flip_y {
                v = -v;
            }
            out.push(' ');
            out.push_str(id.word());
            crate::geom::push_mm(&mut out, v, decimals);
        }
        out
    }
    /// The pose's words alone (`Z.. A.. B..` for the axes the machine has; empty on a flat
    /// machine): a tool-centre program turns them at a field change.
    pub(super) fn pose_words(&self, pose: &Pose) -> String {
        let all = self.stage_words(Pt::default(), pose);
        let skip = if self.profile.has_y() { 2 } else { 1 };
        all.split(' ').skip(skip).collect::<Vec<_>>().join(" ")
    }
    /// [`Words::xy`] appended to `out`.
    pub(super) fn push_xy(&self, out: &mut String, axes: [&str; 2], p: Pt) {
        let decimals = self.profile.gcode.decimals;
        out.push_str(axes[0]);
        crate::geom::push_mm(out, p.x, decimals);
        out.push(' ');
        out.push_str(axes[1]);
        crate::geom::push_mm(out, p.y, decimals);
    }
}

/// The G-code is handed to the writer in pieces of about this many bytes.
pub(super) const CHUNK_BYTES: usize = 1 << 16;

/// Any writer, sized or not, as a `dyn Write` (the LinuxCNC writer keeps one).
struct Sink<'a, W: std::io::Write + ?Sized>(&'a mut W);

impl<W: std::io::Write + ?Sized> std::io::Write for Sink<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0.write(buf)
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}

/// Writes the toolpath of `plan` as G-code in the dialect of the plan's profile; Y is mirrored
/// about `page_height_mm` when the dialect says `flip_y`. Fields are numbered 1…n in visiting
/// order (the plan's field order), as everywhere else.
pub fn write_gcode(
    toolpath: &Toolpath,
    plan: &Plan,
    page_height_mm: f64,
    title: &str,
) -> Result<String, GcodeError> {
    let mut out = Vec::with_capacity(toolpath.strokes.len() * 64);
    write_gcode_to(&mut out, toolpath, plan, page_height_mm, title)?;
    String::from_utf8(out).map_err(|e| GcodeError::Write(e.to_string()))
}

/// [`write_gcode`] streamed to `sink` in pieces (a million strokes make about 100 MB of
/// G-code, which is never held whole).
pub fn write_gcode_to(
    sink: &mut (impl std::io::Write + ?Sized),
    toolpath: &Toolpath,
    plan: &Plan,
    page_height_mm: f64,
    title: &str,
) -> Result<(), GcodeError> {
    let profile = &plan.profile;
    let d = &profile.gcode;
    let w = Words {
        profile,
        page_height_mm,
    };
    if d.mode == GcodeMode::Linuxcnc {
        let mut head = String::new();
        header(&mut head, toolpath, plan, title, true);
        return super::linuxcnc::write_program(&mut Sink(sink), toolpath, plan, &w, &head);
    }
    let mut flush = |buf: &mut String| -> Result<(), GcodeError> {
        sink.write_all(buf.as_bytes())
            .map_err(|e| GcodeError::Write(e.to_string()))?;
        buf.clear();
        Ok(())
    };
    // one set of words per layer of the plan, and the profile's for strokes without a pen
    let pens: Vec<PenWords> = plan
        .layers
        .iter()
        .map(|l| PenWords::of(&w, Some(l)))
        .collect();
    let profile_pen = PenWords::of(&w, None);
    // a layer comment where the layer changes, when the plan's layers have pens of their own
    let comment_layers = plan.layers.iter().any(|l| !l.pen.marks_as_profile());
    let mut current_layer = None;
    let stage_scanner = d.mode == GcodeMode::StageScanner;
    if stage_scanner && toolpath.route.is_some() {
        return Err(GcodeError::StageScannerOnTheFly);
    }
    let scan_axes = [d.scanner_axes[0].as_str(), d.scanner_axes[1].as_str()];
    let mut out = String::with_capacity(CHUNK_BYTES + 4096);
    header(&mut out, toolpath, plan, title, false);
    let _ = writeln!(out, "{}", d.laser_off);
    let number: std::collections::HashMap<usize, usize> = plan
        .fields
        .iter()
        .enumerate()
        .map(|(k, f)| (f.id, k + 1))
        .collect();
    let pose_of: std::collections::HashMap<usize, Pose> =
        plan.fields.iter().map(|f| (f.id, f.pose)).collect();
    let mut current_field = None;
    for (k, stroke) in toolpath.strokes.iter().enumerate() {
        if current_field != Some(stroke.field) {
            current_field = Some(stroke.field);
            let c = w.position(stroke.stage);
            let label = match number.get(&stroke.field) {
                Some(n) => n.to_string(),
                None => format!("[id {}]", stroke.field),
            };
            // a mixed job says how each field runs
            let how = match (
                plan.step_fields.is_empty(),
                plan.step_fields.contains(&stroke.field),
            ) {
                (true, _) => "",
                (false, true) => ", step-and-scan (the stage at rest)",
                (false, false) => ", on the fly",
            };
            let _ = writeln!(
                out,
                "; field {label} centre {} {}{how}",
                w.num(c.x),
                w.num(c.y)
            );
            let pose = pose_of.get(&stroke.field).copied().unwrap_or_default();
            if stage_scanner {
                let _ = writeln!(out, "G0 {}", w.stage_words(stroke.stage, &pose));
            } else {
                let turn = w.pose_words(&pose);
                if !turn.is_empty() {
                    let _ = writeln!(out, "G0 {turn}");
                }
            }
        }
        let points = toolpath.stroke_points(k);
        let place = |out: &mut String, p: Pt| {
            if stage_scanner {
                w.push_xy(out, scan_axes, w.offset(p.minus(stroke.stage)));
            } else {
                w.push_xy(out, ["X", "Y"], w.position(p));
            }
        };
        let Some((&first, rest)) = points.split_first() else {
            return Err(GcodeError::EmptyStroke { stroke: k });
        };
        let pen = match stroke.layer {
            None => &profile_pen,
            Some(l) => pens.get(l).ok_or(GcodeError::NoLayer {
                stroke: k,
                layer: l,
            })?,
        };
        if comment_layers && current_layer != Some(stroke.layer) {
            current_layer = Some(stroke.layer);
            if let Some(c) = &pen.comment {
                let _ = writeln!(out, "{c}");
            }
        }
        out.push_str("G0 ");
        place(&mut out, first);
        out.push('\n');
        out.push_str(&pen.on);
        out.push('\n');
        if rest.is_empty() {
            // a dot: fired in place for its pen's dwell
            out.push_str("G4 P");
            out.push_str(&pen.dot_dwell);
            out.push('\n');
        }
        // around a cylinder each edge has its own feed: the one that marks the surface at the
        // pen's (slower by cos φ across the strip)
        let around = plan.settings.cylinder.map(|c| {
            let a_deg = pose_of.get(&stroke.field).map_or(0.0, |p| p.a_deg);
            (c, a_deg)
        });
        let mut from = first;
        for (j, &p) in rest.iter().enumerate() {
            out.push_str("G1 ");
            place(&mut out, p);
            if let Some((c, a_deg)) = around {
                let ratio = c.scanner_speed_mm_s(from, p, a_deg, stroke.stage.y, 1.0);
                out.push_str(" F");
                out.push_str(&w.num(pen.feed_mm_min * ratio));
            } else if j == 0 {
                out.push_str(" F");
                out.push_str(&pen.feed);
            }
            out.push('\n');
            from = p;
        }
        out.push_str(&d.laser_off);
        out.push('\n');
        if out.len() >= CHUNK_BYTES {
            flush(&mut out)?;
        }
    }
    out.push_str("; end\n");
    flush(&mut out)
}

/// The comment lines at the top: `; ..` lines, or `(..)` for LinuxCNC (`parens`).
fn header(out: &mut String, toolpath: &Toolpath, plan: &Plan, title: &str, parens: bool) {
    let m = &plan.metrics;
    let mut lines = vec![format!(
        "galvoplan {} — {}",
        env!("CARGO_PKG_VERSION"),
        title.replace('\n', " ")
    )];
    if !plan.name.is_empty() {
        lines.push(format!("plan {}", plan.name.replace('\n', " ")));
    }
    lines.push(format!(
        "{} strokes in {} fields, marked {:.3} mm, idle {:.3} mm, base {:.3} mm, job time {:.3} s",
        toolpath.strokes.len(),
        plan.fields.len(),
        m.marked_mm,
        m.idle_mm,
        m.base_mm,
        toolpath.duration_s()
    ));
    for l in lines {
        if parens {
            let _ = writeln!(out, "({})", l.replace(['(', ')'], ""));
        } else {
            let _ = writeln!(out, "; {l}");
        }
    }
    if !parens {
        out.push_str("G21\nG90\n");
    }
}
